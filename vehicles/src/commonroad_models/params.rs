//! Parameters of CommonRoad's vehicle models: one struct with everything the ks, st and std
//! models read, and CommonRoad's vehicles 1–3.
//!
//! The values of [`CommonRoadVehicleParams::ford_escort`], [`CommonRoadVehicleParams::bmw_320i`],
//! [`CommonRoadVehicleParams::vw_vanagon`] and [`CommonRoadTireParams::default`] are data from
//! the Python package `commonroad-vehicle-models` 3.0.2 (files
//! `parameters/parameters_vehicle{1,2,3}.yaml` and `parameters/parameters_tire.yaml`),
//! copyright 2020 Technical University of Munich, Professorship of Cyber-Physical Systems,
//! distributed under the BSD 3-Clause licence reproduced in `LICENSE-commonroad-vehicle-models`
//! beside this file. Their source: Althoff, M. and Würsching, G., *CommonRoad: Vehicle Models*,
//! 2020, tables 6 and 7.
//!
//! CommonRoad's names are given on each field (`m`, `I_z`, `a`, `b`, `h_s`, …), so a yaml file of
//! the package maps onto this struct field by field.

use serde::{Deserialize, Serialize};

/// Limits of the steering angle and of its rate (CommonRoad's `steering` group).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CommonRoadSteeringLimits {
    /// Smallest front-wheel steering angle δ_min (rad); CommonRoad `steering.min`.
    pub min_angle_rad: f64,
    /// Largest front-wheel steering angle δ_max (rad); CommonRoad `steering.max`.
    pub max_angle_rad: f64,
    /// Smallest steering velocity v_δ,min (rad/s, negative); CommonRoad `steering.v_min`.
    pub min_steering_velocity_radps: f64,
    /// Largest steering velocity v_δ,max (rad/s); CommonRoad `steering.v_max`.
    pub max_steering_velocity_radps: f64,
}

/// Limits of the speed and of the longitudinal acceleration (CommonRoad's `longitudinal` group).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CommonRoadLongitudinalLimits {
    /// Smallest speed v_min (m/s, negative: reversing); CommonRoad `longitudinal.v_min`.
    pub min_speed_mps: f64,
    /// Largest speed v_max (m/s); CommonRoad `longitudinal.v_max`.
    pub max_speed_mps: f64,
    /// Speed v_S above which the engine's power, not the tyres, limits the acceleration (m/s);
    /// CommonRoad `longitudinal.v_switch`.
    pub switching_speed_mps: f64,
    /// Largest magnitude of the longitudinal acceleration a_max (m/s²); CommonRoad
    /// `longitudinal.a_max`.
    pub max_acceleration_mps2: f64,
}

/// Magic-Formula (Pacejka 2002 / ADAMS) tyre coefficients of the std model, all dimensionless
/// and named as in CommonRoad's `tire` group. Lateral and longitudinal pure-slip curves, and the
/// weighting functions that reduce each force under combined slip.
///
/// The models run at zero camber γ, where `p_dx3`, `p_dy3`, `p_hy1`, `p_hy3`, `p_vy1`, `p_vy3`
/// and `r_vy3` have no effect; they are kept so that the set is CommonRoad's whole tyre table.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CommonRoadTireParams {
    /// Shape factor C of the longitudinal force.
    pub p_cx1: f64,
    /// Longitudinal friction coefficient μ_x at nominal load.
    pub p_dx1: f64,
    /// Variation of μ_x with camber².
    pub p_dx3: f64,
    /// Longitudinal curvature E.
    pub p_ex1: f64,
    /// Longitudinal slip stiffness K_x / F_z.
    pub p_kx1: f64,
    /// Horizontal shift of the longitudinal curve.
    pub p_hx1: f64,
    /// Vertical shift of the longitudinal curve, per unit load.
    pub p_vx1: f64,
    /// Slope factor of the combined-slip reduction of F_x.
    pub r_bx1: f64,
    /// Variation of that slope with the slip ratio.
    pub r_bx2: f64,
    /// Shape factor of the combined-slip reduction of F_x.
    pub r_cx1: f64,
    /// Curvature factor of the combined-slip reduction of F_x.
    pub r_ex1: f64,
    /// Shift factor of the combined-slip reduction of F_x.
    pub r_hx1: f64,
    /// Shape factor C of the lateral force.
    pub p_cy1: f64,
    /// Lateral friction coefficient μ_y at nominal load (also the st model's μ).
    pub p_dy1: f64,
    /// Variation of μ_y with camber².
    pub p_dy3: f64,
    /// Lateral curvature E.
    pub p_ey1: f64,
    /// Cornering stiffness K_y / F_z (negative in CommonRoad's sign convention).
    pub p_ky1: f64,
    /// Horizontal shift of the lateral curve (acts with camber only).
    pub p_hy1: f64,
    /// Variation of that shift with camber.
    pub p_hy3: f64,
    /// Vertical shift of the lateral curve per unit load (acts with camber only).
    pub p_vy1: f64,
    /// Variation of that shift with camber.
    pub p_vy3: f64,
    /// Slope factor of the combined-slip reduction of F_y.
    pub r_by1: f64,
    /// Variation of that slope with the slip angle.
    pub r_by2: f64,
    /// Slip-angle shift of that slope.
    pub r_by3: f64,
    /// Shape factor of the combined-slip reduction of F_y.
    pub r_cy1: f64,
    /// Curvature factor of the combined-slip reduction of F_y.
    pub r_ey1: f64,
    /// Shift factor of the combined-slip reduction of F_y.
    pub r_hy1: f64,
    /// Slip-ratio-induced side force per unit μ_y·F_z.
    pub r_vy1: f64,
    /// Variation of that side force with camber.
    pub r_vy3: f64,
    /// Variation of that side force with the slip angle.
    pub r_vy4: f64,
    /// Variation of that side force with the slip ratio (outer factor).
    pub r_vy5: f64,
    /// Variation of that side force with the slip ratio (inside the arctangent).
    pub r_vy6: f64,
}

impl Default for CommonRoadTireParams {
    /// CommonRoad's `parameters_tire.yaml` (one tyre for every vehicle).
    fn default() -> Self {
        Self {
            p_cx1: 1.6411,
            p_dx1: 1.1739,
            p_dx3: 0.0,
            p_ex1: 0.46403,
            p_kx1: 22.303,
            p_hx1: 0.0012297,
            p_vx1: -8.8098e-06,
            r_bx1: 13.276,
            r_bx2: -13.778,
            r_cx1: 1.2568,
            r_ex1: 0.65225,
            r_hx1: 0.0050722,
            p_cy1: 1.3507,
            p_dy1: 1.0489,
            p_dy3: -2.8821,
            p_ey1: -0.0074722,
            p_ky1: -21.92,
            p_hy1: 0.0026747,
            p_hy3: 0.031415,
            p_vy1: 0.037318,
            p_vy3: -0.32931,
            r_by1: 7.1433,
            r_by2: 9.1916,
            r_by3: -0.027856,
            r_cy1: 1.0719,
            r_ey1: -0.27572,
            r_hy1: 5.7448e-06,
            r_vy1: -0.027825,
            r_vy3: -0.27568,
            r_vy4: 12.12,
            r_vy5: 1.9,
            r_vy6: -10.704,
        }
    }
}

/// Everything CommonRoad's ks, st and std models read about a car (SI units).
///
/// [`Default`] is CommonRoad vehicle 2, the BMW 320i ([`CommonRoadVehicleParams::bmw_320i`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CommonRoadVehicleParams {
    /// Body length (m); CommonRoad `l`. Not read by the dynamics (the footprint's size).
    pub length_m: f64,
    /// Body width (m); CommonRoad `w`. Not read by the dynamics.
    pub width_m: f64,
    /// Total mass m (kg); CommonRoad `m`.
    pub mass_kg: f64,
    /// Yaw moment of inertia I_z (kg·m²); CommonRoad `I_z`.
    pub yaw_inertia_kgm2: f64,
    /// Centre of mass to front axle l_f (m); CommonRoad `a`.
    pub cog_to_front_axle_m: f64,
    /// Centre of mass to rear axle l_r (m); CommonRoad `b`.
    pub cog_to_rear_axle_m: f64,
    /// Height of the centre of mass of the total mass (m); CommonRoad `h_cg`. Kept for
    /// conversions; the st and std models use [`Self::sprung_cog_height_m`].
    pub cog_height_m: f64,
    /// Height of the sprung mass's centre of mass h_s (m); CommonRoad `h_s`. The st and std
    /// models take their longitudinal load transfer, m·a·h_s / L, from it.
    pub sprung_cog_height_m: f64,
    /// Spin inertia of one wheel about its axle I_w (kg·m²); CommonRoad `I_y_w` (std only).
    pub wheel_inertia_kgm2: f64,
    /// Effective wheel radius R_w (m); CommonRoad `R_w` (std only).
    pub wheel_radius_m: f64,
    /// Share of the brake torque on the front axle, in [0, 1]; CommonRoad `T_sb` (std only).
    pub brake_torque_front_share: f64,
    /// Share of the engine torque on the front axle, in [0, 1]; CommonRoad `T_se` (std only:
    /// 0 rear-wheel drive, 1 front-wheel drive).
    pub drive_torque_front_share: f64,
    /// Steering-angle and steering-velocity limits.
    pub steering: CommonRoadSteeringLimits,
    /// Speed and acceleration limits.
    pub longitudinal: CommonRoadLongitudinalLimits,
    /// Magic-Formula tyre (std; the st model reads its μ = `p_dy1` and `p_ky1`).
    pub tire: CommonRoadTireParams,
}

impl Default for CommonRoadVehicleParams {
    /// CommonRoad vehicle 2, the BMW 320i.
    fn default() -> Self {
        Self::bmw_320i()
    }
}

/// Steering limits of CommonRoad's vehicles 1–3: a symmetric angle range, ±0.4 rad/s.
fn steering(max_angle_rad: f64) -> CommonRoadSteeringLimits {
    CommonRoadSteeringLimits {
        min_angle_rad: -max_angle_rad,
        max_angle_rad,
        min_steering_velocity_radps: -0.4,
        max_steering_velocity_radps: 0.4,
    }
}

/// Longitudinal limits of CommonRoad's vehicles 1–3 (a_max = 11.5 m/s² for all three).
fn longitudinal(
    min_speed_mps: f64,
    max_speed_mps: f64,
    switching_speed_mps: f64,
) -> CommonRoadLongitudinalLimits {
    CommonRoadLongitudinalLimits {
        min_speed_mps,
        max_speed_mps,
        switching_speed_mps,
        max_acceleration_mps2: 11.5,
    }
}

impl CommonRoadVehicleParams {
    /// CommonRoad vehicle 1, a Ford Escort (`parameters_vehicle1.yaml`; front-wheel drive).
    pub fn ford_escort() -> Self {
        Self {
            length_m: 4.298,
            width_m: 1.674,
            mass_kg: 1225.8878467253344,
            yaw_inertia_kgm2: 1538.8533713561394,
            cog_to_front_axle_m: 0.88392,
            cog_to_rear_axle_m: 1.50876,
            cog_height_m: 0.5577840000000001,
            sprung_cog_height_m: 0.59436,
            wheel_inertia_kgm2: 1.7,
            wheel_radius_m: 0.344,
            brake_torque_front_share: 0.76,
            drive_torque_front_share: 1.0,
            steering: steering(0.91),
            longitudinal: longitudinal(-13.9, 45.8, 4.755),
            tire: CommonRoadTireParams::default(),
        }
    }

    /// CommonRoad vehicle 2, a BMW 320i (`parameters_vehicle2.yaml`; rear-wheel drive).
    pub fn bmw_320i() -> Self {
        Self {
            length_m: 4.508,
            width_m: 1.61,
            mass_kg: 1093.2952334674046,
            yaw_inertia_kgm2: 1791.5995300122856,
            cog_to_front_axle_m: 1.1561957064,
            cog_to_rear_axle_m: 1.4227170936,
            cog_height_m: 0.5748689544000001,
            sprung_cog_height_m: 0.61373004,
            wheel_inertia_kgm2: 1.7,
            wheel_radius_m: 0.344,
            brake_torque_front_share: 0.66,
            drive_torque_front_share: 0.0,
            steering: steering(1.066),
            longitudinal: longitudinal(-13.9, 50.8, 7.319),
            tire: CommonRoadTireParams::default(),
        }
    }

    /// CommonRoad vehicle 3, a VW Vanagon (`parameters_vehicle3.yaml`; rear-wheel drive).
    pub fn vw_vanagon() -> Self {
        Self {
            length_m: 4.569,
            width_m: 1.844,
            mass_kg: 1478.8979637767998,
            yaw_inertia_kgm2: 2473.1176915564442,
            cog_to_front_axle_m: 1.1507916024,
            cog_to_rear_axle_m: 1.3211363976000001,
            cog_height_m: 0.7478167416,
            sprung_cog_height_m: 0.804490644,
            wheel_inertia_kgm2: 1.7,
            wheel_radius_m: 0.344,
            brake_torque_front_share: 0.64,
            drive_torque_front_share: 0.0,
            steering: steering(1.023),
            longitudinal: longitudinal(-11.2, 41.7, 7.824),
            tire: CommonRoadTireParams::default(),
        }
    }

    /// CommonRoad vehicle `id` (1 Ford Escort, 2 BMW 320i, 3 VW Vanagon); `None` for any other
    /// id (vehicle 4 of the package is a truck with a trailer, which these models do not cover).
    pub fn commonroad_vehicle(id: u32) -> Option<Self> {
        match id {
            1 => Some(Self::ford_escort()),
            2 => Some(Self::bmw_320i()),
            3 => Some(Self::vw_vanagon()),
            _ => None,
        }
    }

    /// Wheelbase L = l_f + l_r (m).
    pub fn wheelbase_m(&self) -> f64 {
        self.cog_to_front_axle_m + self.cog_to_rear_axle_m
    }

    /// Friction coefficient μ of the st model: the tyre's lateral peak, `p_dy1`.
    pub fn st_friction_coefficient(&self) -> f64 {
        self.tire.p_dy1
    }

    /// Normalised cornering stiffness C_S of the st model, the same for both axles:
    /// −`p_ky1` / `p_dy1` (1/rad). An axle's cornering stiffness is μ·C_S·F_z.
    pub fn st_cornering_stiffness_per_rad(&self) -> f64 {
        -self.tire.p_ky1 / self.tire.p_dy1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_vehicle_2_and_all_three_validate() {
        assert_eq!(
            CommonRoadVehicleParams::default(),
            CommonRoadVehicleParams::bmw_320i()
        );
        for id in 1..=3 {
            let p = CommonRoadVehicleParams::commonroad_vehicle(id);
            assert!(p.is_some_and(|p| p.validate().is_ok()), "vehicle {id}");
        }
        assert!(CommonRoadVehicleParams::commonroad_vehicle(4).is_none());
    }

    #[test]
    fn st_tyre_constants_of_the_bmw() {
        let p = CommonRoadVehicleParams::default();
        assert_eq!(p.st_friction_coefficient(), 1.0489);
        assert!((p.st_cornering_stiffness_per_rad() - 21.92 / 1.0489).abs() < 1e-12);
        assert!((p.wheelbase_m() - 2.5789128).abs() < 1e-12);
    }
}
