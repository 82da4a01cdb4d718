//! The car of a [`VehicleParams`] in CommonRoad's terms, on a road of friction μ
//! ([`crate::CommonRoadVehicle`], "The car").

use crate::commonroad_models::{
    CommonRoadLongitudinalLimits, CommonRoadSteeringLimits, CommonRoadTireParams,
    CommonRoadVehicleParams,
};
use crate::params::VehicleParams;
use crate::physics_world::GRAVITY_MPS2;

use super::CommonRoadModel;

/// Top speed of the models here (m/s): no limit in practice, as for a `rapier` car.
const COMMONROAD_VEHICLE_MAX_SPEED_MPS: f64 = 100.0;

impl CommonRoadVehicleParams {
    /// The car of `p` in CommonRoad's terms on a road of friction `mu`, for `model` (the doc of
    /// [`crate::CommonRoadVehicle`]).
    pub fn from_vehicle_params(p: &VehicleParams, model: CommonRoadModel, mu: f64) -> Self {
        let drive_limit_mps2 = p.max_drive_torque_nm / (p.wheel_radius_m * p.mass_kg);
        let brake_limit_mps2 = p.max_brake_torque_nm / (p.wheel_radius_m * p.mass_kg);
        let mut max_acceleration_mps2 = drive_limit_mps2.max(brake_limit_mps2);
        if model != CommonRoadModel::Std {
            max_acceleration_mps2 = max_acceleration_mps2.min(mu * GRAVITY_MPS2);
        }
        let t = &p.tire;
        let reference = CommonRoadTireParams::default();
        Self {
            length_m: p.length_m,
            width_m: p.width_m,
            mass_kg: p.mass_kg,
            yaw_inertia_kgm2: p.yaw_inertia_kgm2,
            cog_to_front_axle_m: p.cog_to_front_axle_m,
            cog_to_rear_axle_m: p.cog_to_rear_axle_m,
            cog_height_m: p.cog_height_m,
            sprung_cog_height_m: p.cog_height_m,
            wheel_inertia_kgm2: p.wheel_inertia_kgm2,
            wheel_radius_m: p.wheel_radius_m,
            brake_torque_front_share: p.brake_torque_front_share,
            drive_torque_front_share: p.drive_torque_front_share,
            steering: CommonRoadSteeringLimits {
                min_angle_rad: -p.max_steer_rad,
                max_angle_rad: p.max_steer_rad,
                min_steering_velocity_radps: -p.max_steer_rate_radps,
                max_steering_velocity_radps: p.max_steer_rate_radps,
            },
            longitudinal: CommonRoadLongitudinalLimits {
                min_speed_mps: 0.0,
                max_speed_mps: COMMONROAD_VEHICLE_MAX_SPEED_MPS,
                switching_speed_mps: COMMONROAD_VEHICLE_MAX_SPEED_MPS,
                max_acceleration_mps2,
            },
            tire: CommonRoadTireParams {
                p_cx1: t.p_cx1,
                p_dx1: mu,
                p_ex1: t.p_ex1,
                p_kx1: t.p_kx1,
                p_hx1: t.p_hx1,
                p_vx1: t.p_vx1,
                r_bx1: t.r_bx1,
                r_bx2: t.r_bx2,
                r_cx1: t.r_cx1,
                r_ex1: t.r_ex1,
                r_hx1: t.r_hx1,
                p_cy1: t.p_cy1,
                p_dy1: mu,
                p_ey1: t.p_ey1,
                p_ky1: t.p_ky1,
                r_by1: t.r_by1,
                r_by2: t.r_by2,
                r_by3: t.r_by3,
                r_cy1: t.r_cy1,
                r_ey1: t.r_ey1,
                r_hy1: t.r_hy1,
                ..reference
            },
        }
    }
}
