//! Physical parameters of a vehicle and of its tyres.
//!
//! Every field carries its unit in its name. The default is the BMW 320i of CommonRoad's
//! published vehicle models (see [`crate::presets`]), so a bare `VehicleParams::default()` is a
//! real car, not a made-up one.

use serde::{Deserialize, Serialize};

use crate::error::VehicleError;

/// Magic-Formula tyre coefficients (PAC2002 naming) plus the transient / low-speed terms.
///
/// The steady-state coefficients are those of CommonRoad's `parameters_tire.yaml`
/// (commonroad-vehicle-models 3.0.2, "tire parameters from ADAMS handbook"; Althoff &
/// Würsching, *CommonRoad: Vehicle Models*, 2020, Tab. 7). Only the camber-free subset is kept:
/// this vehicle model has no camber (γ = 0), so `p_dx3`, `p_dy3`, `p_hy1`, `p_hy3`, `p_vy1`,
/// `p_vy3` (all multiplied by γ or `sign(γ)` in CommonRoad's `tire_model.py`) vanish, and the
/// κ-induced lateral force `S_Vyκ` (`r_vy*`) is left out on purpose: CommonRoad applies it with
/// the same sign to left and right tyres, which makes a car braking in a straight line pull to
/// one side, whereas a real axle mounts its two tyres mirrored so the effect cancels.
///
/// Friction scaling: the road friction coefficient μ replaces the peak factors, i.e. the
/// PAC2002 scaling factors are λ_μx = μ / p_dx1 and λ_μy = μ / p_dy1, so both pure-slip curves
/// peak at exactly μ·Fz, while the slip stiffnesses K_x = p_kx1·Fz and K_y = p_ky1·Fz stay
/// independent of μ (as in PAC2002, where K does not contain λ_μ).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TireParams {
    /// Longitudinal shape factor C_x (−).
    pub p_cx1: f64,
    /// Longitudinal peak friction at nominal conditions (−); only used for λ_μx = μ / p_dx1.
    pub p_dx1: f64,
    /// Longitudinal curvature factor E_x (−).
    pub p_ex1: f64,
    /// Longitudinal slip stiffness per unit load, K_x / Fz (−).
    pub p_kx1: f64,
    /// Horizontal shift of the longitudinal curve S_Hx (−).
    pub p_hx1: f64,
    /// Vertical shift of the longitudinal curve per unit load, S_Vx / Fz (−).
    pub p_vx1: f64,
    /// Combined slip: slope factor of G_xα, first term (−).
    pub r_bx1: f64,
    /// Combined slip: variation of the G_xα slope with κ (−).
    pub r_bx2: f64,
    /// Combined slip: shape factor of G_xα (−).
    pub r_cx1: f64,
    /// Combined slip: curvature factor of G_xα (−).
    pub r_ex1: f64,
    /// Combined slip: horizontal shift of G_xα (rad).
    pub r_hx1: f64,
    /// Lateral shape factor C_y (−).
    pub p_cy1: f64,
    /// Lateral peak friction at nominal conditions (−); only used for λ_μy = μ / p_dy1.
    pub p_dy1: f64,
    /// Lateral curvature factor E_y (−).
    pub p_ey1: f64,
    /// Cornering stiffness per unit load, K_y / Fz (1/rad). Negative in CommonRoad's sign
    /// convention: a positive slip angle (contact patch sliding to the left) gives a force to
    /// the right.
    pub p_ky1: f64,
    /// Combined slip: slope factor of G_yκ, first term (−).
    pub r_by1: f64,
    /// Combined slip: variation of the G_yκ slope with α (−).
    pub r_by2: f64,
    /// Combined slip: shift of α in the G_yκ slope (rad).
    pub r_by3: f64,
    /// Combined slip: shape factor of G_yκ (−).
    pub r_cy1: f64,
    /// Combined slip: curvature factor of G_yκ (−).
    pub r_ey1: f64,
    /// Combined slip: horizontal shift of G_yκ (−).
    pub r_hy1: f64,
    /// Lateral relaxation length σ_α (m): the slip angle the tyre feels lags the kinematic one
    /// by a first-order filter with time constant σ_α / |v_x| (PAC2002's transient model;
    /// passenger-car tyres have σ_α of roughly 0.3–0.7 m). It also makes the low-speed lateral
    /// force a finite spring instead of an infinitely stiff damper.
    pub relaxation_length_lat_m: f64,
    /// Speed floor in the slip-ratio denominator (m/s): κ = (ω r − v_x) / max(|v_x|, this).
    /// Raised automatically to keep the locked-wheel friction damper stable at large steps
    /// (see `crate::tire::slip_speed_floor_mps`).
    pub low_speed_floor_mps: f64,
    /// Below this forward speed a lateral damper fades in (m/s); PAC2002's `VXLOW` idea.
    pub low_speed_fade_mps: f64,
    /// Damping ratio of that low-speed lateral damper, relative to the tyre's lateral
    /// relaxation spring on the wheel's share of the mass (−).
    pub low_speed_damping_ratio: f64,
}

impl Default for TireParams {
    fn default() -> Self {
        // CommonRoad parameters_tire.yaml (commonroad-vehicle-models 3.0.2).
        Self {
            p_cx1: 1.6411,
            p_dx1: 1.1739,
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
            p_ey1: -0.0074722,
            p_ky1: -21.92,
            r_by1: 7.1433,
            r_by2: 9.1916,
            r_by3: -0.027856,
            r_cy1: 1.0719,
            r_ey1: -0.27572,
            r_hy1: 5.7448e-06,
            relaxation_length_lat_m: 0.5,
            low_speed_floor_mps: 0.5,
            low_speed_fade_mps: 2.0,
            low_speed_damping_ratio: 0.5,
        }
    }
}

impl TireParams {
    /// Checks every coefficient; the error names the field and its value.
    pub(crate) fn validate(&self) -> Result<(), VehicleError> {
        let all = [
            ("p_cx1", self.p_cx1),
            ("p_dx1", self.p_dx1),
            ("p_ex1", self.p_ex1),
            ("p_kx1", self.p_kx1),
            ("p_hx1", self.p_hx1),
            ("p_vx1", self.p_vx1),
            ("r_bx1", self.r_bx1),
            ("r_bx2", self.r_bx2),
            ("r_cx1", self.r_cx1),
            ("r_ex1", self.r_ex1),
            ("r_hx1", self.r_hx1),
            ("p_cy1", self.p_cy1),
            ("p_dy1", self.p_dy1),
            ("p_ey1", self.p_ey1),
            ("p_ky1", self.p_ky1),
            ("r_by1", self.r_by1),
            ("r_by2", self.r_by2),
            ("r_by3", self.r_by3),
            ("r_cy1", self.r_cy1),
            ("r_ey1", self.r_ey1),
            ("r_hy1", self.r_hy1),
            ("relaxation_length_lat_m", self.relaxation_length_lat_m),
            ("low_speed_floor_mps", self.low_speed_floor_mps),
            ("low_speed_fade_mps", self.low_speed_fade_mps),
            ("low_speed_damping_ratio", self.low_speed_damping_ratio),
        ];
        for (name, value) in all {
            if !value.is_finite() {
                return Err(VehicleError::invalid(
                    format!("tire.{name}"),
                    value,
                    "must be finite",
                ));
            }
        }
        // A saturating Magic Formula needs 1 < C < 2: the curve then peaks at D.
        for (name, value) in [("p_cx1", self.p_cx1), ("p_cy1", self.p_cy1)] {
            if !(value > 1.0 && value < 2.0) {
                return Err(VehicleError::invalid(
                    format!("tire.{name}"),
                    value,
                    "shape factor must lie in (1, 2) for the curve to peak at mu*Fz",
                ));
            }
        }
        for (name, value) in [("p_ex1", self.p_ex1), ("p_ey1", self.p_ey1)] {
            if value > 1.0 {
                return Err(VehicleError::invalid(
                    format!("tire.{name}"),
                    value,
                    "curvature factor must be <= 1 (otherwise the curve folds back)",
                ));
            }
        }
        let positive = [
            ("p_dx1", self.p_dx1),
            ("p_dy1", self.p_dy1),
            ("p_kx1", self.p_kx1),
            ("r_cx1", self.r_cx1),
            ("r_cy1", self.r_cy1),
            ("relaxation_length_lat_m", self.relaxation_length_lat_m),
            ("low_speed_floor_mps", self.low_speed_floor_mps),
            ("low_speed_fade_mps", self.low_speed_fade_mps),
        ];
        for (name, value) in positive {
            if value <= 0.0 {
                return Err(VehicleError::invalid(
                    format!("tire.{name}"),
                    value,
                    "must be > 0",
                ));
            }
        }
        if self.p_ky1 == 0.0 {
            return Err(VehicleError::invalid(
                "tire.p_ky1",
                self.p_ky1,
                "cornering stiffness must be non-zero",
            ));
        }
        if self.low_speed_damping_ratio < 0.0 {
            return Err(VehicleError::invalid(
                "tire.low_speed_damping_ratio",
                self.low_speed_damping_ratio,
                "must be >= 0",
            ));
        }
        Ok(())
    }
}

/// Physical parameters of a four-wheeled car (world frame: X forward, Y left, Z up).
///
/// Defaults: CommonRoad vehicle 2, BMW 320i (`crate::presets::bmw_320i`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct VehicleParams {
    /// Body length (m); also the length of the chassis collider.
    pub length_m: f64,
    /// Body width (m); also the width of the chassis collider.
    pub width_m: f64,
    /// Overall body height above the ground (m); top of the chassis collider.
    pub body_height_m: f64,
    /// Height of the chassis collider's underside above the ground at rest (m).
    pub ground_clearance_m: f64,
    /// Total mass m (kg).
    pub mass_kg: f64,
    /// Roll moment of inertia about the CoG (kg·m²).
    pub roll_inertia_kgm2: f64,
    /// Pitch moment of inertia about the CoG (kg·m²).
    pub pitch_inertia_kgm2: f64,
    /// Yaw moment of inertia about the CoG, I_z (kg·m²).
    pub yaw_inertia_kgm2: f64,
    /// Distance from the CoG to the front axle, l_f (m).
    pub cog_to_front_axle_m: f64,
    /// Distance from the CoG to the rear axle, l_r (m).
    pub cog_to_rear_axle_m: f64,
    /// Height of the CoG above the ground at rest (m).
    pub cog_height_m: f64,
    /// Front track width (m).
    pub track_front_m: f64,
    /// Rear track width (m).
    pub track_rear_m: f64,
    /// Effective rolling radius of the wheels r (m).
    pub wheel_radius_m: f64,
    /// Spin inertia of one wheel J (kg·m²).
    pub wheel_inertia_kgm2: f64,
    /// Suspension spring rate per front corner (N/m).
    pub spring_rate_front_npm: f64,
    /// Suspension spring rate per rear corner (N/m).
    pub spring_rate_rear_npm: f64,
    /// Suspension damping rate per front corner (N·s/m).
    pub damping_rate_front_nspm: f64,
    /// Suspension damping rate per rear corner (N·s/m).
    pub damping_rate_rear_nspm: f64,
    /// Largest road-wheel steering angle (rad).
    pub max_steer_rad: f64,
    /// Largest road-wheel steering rate (rad/s).
    pub max_steer_rate_radps: f64,
    /// Largest total drive torque at the wheels (N·m).
    pub max_drive_torque_nm: f64,
    /// Share of the drive torque sent to the front axle (CommonRoad `T_se`; 1 = front-wheel
    /// drive, 0 = rear-wheel drive).
    pub drive_torque_front_share: f64,
    /// Largest total brake torque over the four wheels (N·m).
    pub max_brake_torque_nm: f64,
    /// Share of the largest brake torque on the front axle (CommonRoad `T_sb`).
    pub brake_torque_front_share: f64,
    /// Anti-lock braking: a braked wheel's slip ratio is held at the tyre's peak slip.
    pub abs_enabled: bool,
    /// Traction control: a driven wheel's slip ratio is held at the tyre's peak slip.
    pub traction_control_enabled: bool,
    /// Tyre model coefficients.
    pub tire: TireParams,
}

impl Default for VehicleParams {
    fn default() -> Self {
        crate::presets::bmw_320i()
    }
}

impl VehicleParams {
    /// Wheelbase L = l_f + l_r (m).
    pub fn wheelbase_m(&self) -> f64 {
        self.cog_to_front_axle_m + self.cog_to_rear_axle_m
    }

    /// Static normal load on one front wheel, m·g·l_r / (2 L) (N).
    pub(crate) fn static_load_front_n(&self, gravity_mps2: f64) -> f64 {
        self.mass_kg * gravity_mps2 * self.cog_to_rear_axle_m / (2.0 * self.wheelbase_m())
    }

    /// Static normal load on one rear wheel, m·g·l_f / (2 L) (N).
    pub(crate) fn static_load_rear_n(&self, gravity_mps2: f64) -> f64 {
        self.mass_kg * gravity_mps2 * self.cog_to_front_axle_m / (2.0 * self.wheelbase_m())
    }

    /// The largest braking deceleration the car can reach on a road of friction `mu` (m/s²):
    /// min(μ·g, the brakes' torque limit / (R_w·m)). The tyre's peak is μ in every vehicle
    /// model (docs/vehicle_models.md, "The braking the planners rely on").
    pub fn braking_limit_mps2(&self, mu: f64) -> f64 {
        let brakes_mps2 = self.max_brake_torque_nm / (self.wheel_radius_m * self.mass_kg);
        (mu * crate::physics_world::GRAVITY_MPS2).min(brakes_mps2)
    }

    /// Largest drive torque on one wheel (N·m), index in FL, FR, RL, RR order.
    pub fn max_drive_torque_wheel_nm(&self, wheel: usize) -> f64 {
        let share = if wheel < 2 {
            self.drive_torque_front_share
        } else {
            1.0 - self.drive_torque_front_share
        };
        0.5 * share * self.max_drive_torque_nm
    }

    /// Largest brake torque on one wheel (N·m), index in FL, FR, RL, RR order.
    pub fn max_brake_torque_wheel_nm(&self, wheel: usize) -> f64 {
        let share = if wheel < 2 {
            self.brake_torque_front_share
        } else {
            1.0 - self.brake_torque_front_share
        };
        0.5 * share * self.max_brake_torque_nm
    }

    /// Checks every field: non-finite values and non-positive physical quantities are errors
    /// naming the field and its value.
    pub fn validate(&self) -> Result<(), VehicleError> {
        let positive = [
            ("length_m", self.length_m),
            ("width_m", self.width_m),
            ("body_height_m", self.body_height_m),
            ("mass_kg", self.mass_kg),
            ("roll_inertia_kgm2", self.roll_inertia_kgm2),
            ("pitch_inertia_kgm2", self.pitch_inertia_kgm2),
            ("yaw_inertia_kgm2", self.yaw_inertia_kgm2),
            ("cog_to_front_axle_m", self.cog_to_front_axle_m),
            ("cog_to_rear_axle_m", self.cog_to_rear_axle_m),
            ("cog_height_m", self.cog_height_m),
            ("track_front_m", self.track_front_m),
            ("track_rear_m", self.track_rear_m),
            ("wheel_radius_m", self.wheel_radius_m),
            ("wheel_inertia_kgm2", self.wheel_inertia_kgm2),
            ("spring_rate_front_npm", self.spring_rate_front_npm),
            ("spring_rate_rear_npm", self.spring_rate_rear_npm),
            ("max_steer_rad", self.max_steer_rad),
            ("max_steer_rate_radps", self.max_steer_rate_radps),
        ];
        for (name, value) in positive {
            if !value.is_finite() {
                return Err(VehicleError::invalid(
                    format!("vehicle.{name}"),
                    value,
                    "must be finite",
                ));
            }
            if value <= 0.0 {
                return Err(VehicleError::invalid(
                    format!("vehicle.{name}"),
                    value,
                    "must be > 0",
                ));
            }
        }
        let non_negative = [
            ("ground_clearance_m", self.ground_clearance_m),
            ("damping_rate_front_nspm", self.damping_rate_front_nspm),
            ("damping_rate_rear_nspm", self.damping_rate_rear_nspm),
            ("max_drive_torque_nm", self.max_drive_torque_nm),
            ("max_brake_torque_nm", self.max_brake_torque_nm),
        ];
        for (name, value) in non_negative {
            if !value.is_finite() {
                return Err(VehicleError::invalid(
                    format!("vehicle.{name}"),
                    value,
                    "must be finite",
                ));
            }
            if value < 0.0 {
                return Err(VehicleError::invalid(
                    format!("vehicle.{name}"),
                    value,
                    "must be >= 0",
                ));
            }
        }
        for (name, value) in [
            ("drive_torque_front_share", self.drive_torque_front_share),
            ("brake_torque_front_share", self.brake_torque_front_share),
        ] {
            if !(0.0..=1.0).contains(&value) {
                return Err(VehicleError::invalid(
                    format!("vehicle.{name}"),
                    value,
                    "must lie in [0, 1]",
                ));
            }
        }
        if self.max_steer_rad >= 1.5 {
            return Err(VehicleError::invalid(
                "vehicle.max_steer_rad",
                self.max_steer_rad,
                "must be < 1.5 rad",
            ));
        }
        if self.ground_clearance_m >= self.body_height_m {
            return Err(VehicleError::invalid(
                "vehicle.ground_clearance_m",
                self.ground_clearance_m,
                format!(
                    "must be below vehicle.body_height_m = {}",
                    self.body_height_m
                ),
            ));
        }
        if self.cog_height_m >= self.body_height_m {
            return Err(VehicleError::invalid(
                "vehicle.cog_height_m",
                self.cog_height_m,
                format!(
                    "must be below vehicle.body_height_m = {}",
                    self.body_height_m
                ),
            ));
        }
        self.tire.validate()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn braking_limit_is_friction_or_brakes_whichever_is_less() {
        for p in [VehicleParams::default(), crate::presets::vw_vanagon()] {
            let brakes = p.max_brake_torque_nm / (p.wheel_radius_m * p.mass_kg);
            assert!((brakes - 11.5).abs() < 1e-9, "{brakes}");
            assert!((p.braking_limit_mps2(0.8) - 0.8 * 9.81).abs() < 1e-12);
            assert!((p.braking_limit_mps2(1.5) - 11.5).abs() < 1e-9);
        }
    }

    #[test]
    fn partial_config_fills_defaults_and_unknown_fields_are_rejected() {
        let params: VehicleParams =
            serde_json::from_str(r#"{ "mass_kg": 1500.0, "tire": { "p_dy1": 0.9 } }"#).unwrap();
        assert_eq!(params.mass_kg, 1500.0);
        assert_eq!(params.tire.p_dy1, 0.9);
        assert_eq!(
            params.yaw_inertia_kgm2,
            VehicleParams::default().yaw_inertia_kgm2
        );
        assert_eq!(params.tire.p_ky1, TireParams::default().p_ky1);
        let err = serde_json::from_str::<VehicleParams>(r#"{ "mass": 1500.0 }"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("mass"), "{err}");
        let round_trip: VehicleParams =
            serde_json::from_str(&serde_json::to_string(&params).unwrap()).unwrap();
        assert_eq!(round_trip, params);
    }

    #[test]
    fn presets_are_valid_and_torque_shares_add_up() {
        for name in crate::PRESET_NAMES {
            let p = VehicleParams::preset(name).unwrap();
            p.validate().unwrap();
            let drive: f64 = (0..4).map(|i| p.max_drive_torque_wheel_nm(i)).sum();
            let brake: f64 = (0..4).map(|i| p.max_brake_torque_wheel_nm(i)).sum();
            assert!((drive - p.max_drive_torque_nm).abs() < 1e-9);
            assert!((brake - p.max_brake_torque_nm).abs() < 1e-9);
            // Static loads carry the weight: 2 (F_f + F_r) = m g.
            let g = 9.81;
            let total = 2.0 * (p.static_load_front_n(g) + p.static_load_rear_n(g));
            assert!((total - p.mass_kg * g).abs() < 1e-9 * total);
        }
    }
}
