//! Real-car parameter sets: CommonRoad's published vehicle models.
//!
//! Source: `commonroad-vehicle-models` 3.0.2 (PyPI), files `parameters_vehicle1.yaml` (Ford
//! Escort), `parameters_vehicle2.yaml` (BMW 320i) and `parameters_vehicle3.yaml` (VW Vanagon),
//! "parameter set of the multi-body vehicle dynamics based on the DOT vehicle dynamics"; see
//! Althoff, M. and Würsching, G., *CommonRoad: Vehicle Models*, 2020, Tab. 6. Tyres:
//! `parameters_tire.yaml` (same for all three, [`TireParams::default`]).
//!
//! Mapping of CommonRoad names: `m` → mass, `I_Phi_s`/`I_y_s`/`I_z` → roll/pitch/yaw inertia,
//! `a`/`b` → l_f/l_r, `h_cg` → CoG height, `T_f`/`T_r` → track, `R_w` → wheel radius,
//! `I_y_w` → wheel inertia, `K_sf`/`K_sr` → spring rates, `K_sdf`/`K_sdr` → damping rates,
//! `steering.max`/`steering.v_max` → steering angle/rate limits, `T_se`/`T_sb` → drive/brake
//! front shares. The torque limits follow CommonRoad's own conversion of its acceleration limit
//! (`T = m·R_w·a`, `longitudinal.a_max` = 11.5 m/s² for all three cars).
//!
//! Not in CommonRoad, so chosen here: the body height (rounded manufacturer figures), the
//! height of the chassis collider's underside (0.2 m, so that the body never scrapes the road
//! while pitching), and ABS + traction control switched on (as on any car sold today).

use crate::error::VehicleError;
use crate::params::{TireParams, VehicleParams};

/// Names accepted by [`VehicleParams::preset`], the default first.
pub const PRESET_NAMES: [&str; 3] = ["bmw_320i", "ford_escort", "vw_vanagon"];

/// CommonRoad's `longitudinal.a_max` (m/s²), identical for vehicles 1–3.
const COMMONROAD_MAX_ACCEL_MPS2: f64 = 11.5;

/// Collider underside height used for every preset (m).
const COLLIDER_GROUND_CLEARANCE_M: f64 = 0.2;

/// BMW 320i: CommonRoad vehicle 2 (`parameters_vehicle2.yaml`). Rear-wheel drive.
pub(crate) fn bmw_320i() -> VehicleParams {
    let mass_kg = 1093.2952334674046;
    let wheel_radius_m = 0.344;
    VehicleParams {
        length_m: 4.508,
        width_m: 1.61,
        body_height_m: 1.39,
        ground_clearance_m: COLLIDER_GROUND_CLEARANCE_M,
        mass_kg,
        roll_inertia_kgm2: 207.26524557936952,
        pitch_inertia_kgm2: 1565.8178787125541,
        yaw_inertia_kgm2: 1791.5995300122856,
        cog_to_front_axle_m: 1.1561957064,
        cog_to_rear_axle_m: 1.4227170936,
        cog_height_m: 0.5748689544000001,
        track_front_m: 1.38684,
        track_rear_m: 1.36398,
        wheel_radius_m,
        wheel_inertia_kgm2: 1.7,
        spring_rate_front_npm: 24453.137879749014,
        spring_rate_rear_npm: 19635.504745231297,
        damping_rate_front_nspm: 1786.2441002440723,
        damping_rate_rear_nspm: 1649.0833034887382,
        max_steer_rad: 1.066,
        max_steer_rate_radps: 0.4,
        max_drive_torque_nm: mass_kg * wheel_radius_m * COMMONROAD_MAX_ACCEL_MPS2,
        drive_torque_front_share: 0.0,
        max_brake_torque_nm: mass_kg * wheel_radius_m * COMMONROAD_MAX_ACCEL_MPS2,
        brake_torque_front_share: 0.66,
        abs_enabled: true,
        traction_control_enabled: true,
        tire: TireParams::default(),
    }
}

/// Ford Escort: CommonRoad vehicle 1 (`parameters_vehicle1.yaml`). Front-wheel drive.
pub(crate) fn ford_escort() -> VehicleParams {
    let mass_kg = 1225.8878467253344;
    let wheel_radius_m = 0.344;
    VehicleParams {
        length_m: 4.298,
        width_m: 1.674,
        body_height_m: 1.40,
        ground_clearance_m: COLLIDER_GROUND_CLEARANCE_M,
        mass_kg,
        roll_inertia_kgm2: 244.04723069965206,
        pitch_inertia_kgm2: 1342.2597688480864,
        yaw_inertia_kgm2: 1538.8533713561394,
        cog_to_front_axle_m: 0.88392,
        cog_to_rear_axle_m: 1.50876,
        cog_height_m: 0.5577840000000001,
        track_front_m: 1.389888,
        track_rear_m: 1.423416,
        wheel_radius_m,
        wheel_inertia_kgm2: 1.7,
        spring_rate_front_npm: 21898.332429625985,
        spring_rate_rear_npm: 21898.332429625985,
        damping_rate_front_nspm: 1459.3902937206362,
        damping_rate_rear_nspm: 1459.3902937206362,
        max_steer_rad: 0.91,
        max_steer_rate_radps: 0.4,
        max_drive_torque_nm: mass_kg * wheel_radius_m * COMMONROAD_MAX_ACCEL_MPS2,
        drive_torque_front_share: 1.0,
        max_brake_torque_nm: mass_kg * wheel_radius_m * COMMONROAD_MAX_ACCEL_MPS2,
        brake_torque_front_share: 0.76,
        abs_enabled: true,
        traction_control_enabled: true,
        tire: TireParams::default(),
    }
}

/// VW Vanagon: CommonRoad vehicle 3 (`parameters_vehicle3.yaml`). Rear-wheel drive.
pub(crate) fn vw_vanagon() -> VehicleParams {
    let mass_kg = 1478.8979637767998;
    let wheel_radius_m = 0.344;
    VehicleParams {
        length_m: 4.569,
        width_m: 1.844,
        body_height_m: 1.96,
        ground_clearance_m: COLLIDER_GROUND_CLEARANCE_M,
        mass_kg,
        roll_inertia_kgm2: 479.88430581318335,
        pitch_inertia_kgm2: 2204.322715845899,
        yaw_inertia_kgm2: 2473.1176915564442,
        cog_to_front_axle_m: 1.1507916024,
        cog_to_rear_axle_m: 1.3211363976000001,
        cog_height_m: 0.7478167416,
        track_front_m: 1.574292,
        track_rear_m: 1.5438120000000002,
        wheel_radius_m,
        wheel_inertia_kgm2: 1.7,
        spring_rate_front_npm: 33577.44305875984,
        spring_rate_rear_npm: 39125.020607598424,
        damping_rate_front_nspm: 2405.564099800005,
        damping_rate_rear_nspm: 2769.727219182409,
        max_steer_rad: 1.023,
        max_steer_rate_radps: 0.4,
        max_drive_torque_nm: mass_kg * wheel_radius_m * COMMONROAD_MAX_ACCEL_MPS2,
        drive_torque_front_share: 0.0,
        max_brake_torque_nm: mass_kg * wheel_radius_m * COMMONROAD_MAX_ACCEL_MPS2,
        brake_torque_front_share: 0.64,
        abs_enabled: true,
        traction_control_enabled: true,
        tire: TireParams::default(),
    }
}

impl VehicleParams {
    /// The parameter set of a named car (one of [`PRESET_NAMES`]). The error names the bad value
    /// and lists the valid names.
    pub fn preset(name: &str) -> Result<VehicleParams, VehicleError> {
        match name {
            "bmw_320i" => Ok(bmw_320i()),
            "ford_escort" => Ok(ford_escort()),
            "vw_vanagon" => Ok(vw_vanagon()),
            _ => Err(VehicleError::UnknownPreset {
                name: name.to_owned(),
                valid: PRESET_NAMES.join(", "),
            }),
        }
    }
}
