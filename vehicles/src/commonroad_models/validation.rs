//! Checks of a [`CommonRoadVehicleParams`] before the models divide by its values.

use thiserror::Error;

use super::params::CommonRoadVehicleParams;

/// A parameter set that the models cannot use, named by its field.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum CommonRoadParamsError {
    /// A value that must be finite and > 0 is not.
    #[error("commonroad vehicle parameter `{name}` must be finite and > 0, got {value}")]
    NotPositive {
        /// The field's name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A value that must be finite is not.
    #[error("commonroad vehicle parameter `{name}` must be finite, got {value}")]
    NotFinite {
        /// The field's name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A lower limit is not below its upper limit.
    #[error(
        "commonroad vehicle parameter `{lower}` ({lower_value}) must be below `{upper}` ({upper_value})"
    )]
    EmptyRange {
        /// The lower limit's name.
        lower: &'static str,
        /// Its value.
        lower_value: f64,
        /// The upper limit's name.
        upper: &'static str,
        /// Its value.
        upper_value: f64,
    },
    /// A torque share is outside [0, 1].
    #[error("commonroad vehicle parameter `{name}` must lie in [0, 1], got {value}")]
    NotAShare {
        /// The field's name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
}

impl CommonRoadVehicleParams {
    /// Checks that masses, inertias, lengths, radii and the tyre's peak and stiffness are finite
    /// and > 0, that every limit is finite with min < max, and that the torque shares lie in
    /// [0, 1]. The models divide by these values; the error names the first field that fails.
    pub fn validate(&self) -> Result<(), CommonRoadParamsError> {
        let positive = [
            ("length_m", self.length_m),
            ("width_m", self.width_m),
            ("mass_kg", self.mass_kg),
            ("yaw_inertia_kgm2", self.yaw_inertia_kgm2),
            ("cog_to_front_axle_m", self.cog_to_front_axle_m),
            ("cog_to_rear_axle_m", self.cog_to_rear_axle_m),
            ("cog_height_m", self.cog_height_m),
            ("sprung_cog_height_m", self.sprung_cog_height_m),
            ("wheel_inertia_kgm2", self.wheel_inertia_kgm2),
            ("wheel_radius_m", self.wheel_radius_m),
            (
                "steering.max_steering_velocity_radps",
                self.steering.max_steering_velocity_radps,
            ),
            (
                "longitudinal.switching_speed_mps",
                self.longitudinal.switching_speed_mps,
            ),
            (
                "longitudinal.max_acceleration_mps2",
                self.longitudinal.max_acceleration_mps2,
            ),
            ("tire.p_cx1", self.tire.p_cx1),
            ("tire.p_dx1", self.tire.p_dx1),
            ("tire.p_kx1", self.tire.p_kx1),
            ("tire.p_cy1", self.tire.p_cy1),
            ("tire.p_dy1", self.tire.p_dy1),
            ("tire.-p_ky1", -self.tire.p_ky1),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(CommonRoadParamsError::NotPositive { name, value });
            }
        }
        let t = &self.tire;
        let finite = [
            ("tire.p_dx3", t.p_dx3),
            ("tire.p_ex1", t.p_ex1),
            ("tire.p_hx1", t.p_hx1),
            ("tire.p_vx1", t.p_vx1),
            ("tire.r_bx1", t.r_bx1),
            ("tire.r_bx2", t.r_bx2),
            ("tire.r_cx1", t.r_cx1),
            ("tire.r_ex1", t.r_ex1),
            ("tire.r_hx1", t.r_hx1),
            ("tire.p_dy3", t.p_dy3),
            ("tire.p_ey1", t.p_ey1),
            ("tire.p_hy1", t.p_hy1),
            ("tire.p_hy3", t.p_hy3),
            ("tire.p_vy1", t.p_vy1),
            ("tire.p_vy3", t.p_vy3),
            ("tire.r_by1", t.r_by1),
            ("tire.r_by2", t.r_by2),
            ("tire.r_by3", t.r_by3),
            ("tire.r_cy1", t.r_cy1),
            ("tire.r_ey1", t.r_ey1),
            ("tire.r_hy1", t.r_hy1),
            ("tire.r_vy1", t.r_vy1),
            ("tire.r_vy3", t.r_vy3),
            ("tire.r_vy4", t.r_vy4),
            ("tire.r_vy5", t.r_vy5),
            ("tire.r_vy6", t.r_vy6),
        ];
        for (name, value) in finite {
            if !value.is_finite() {
                return Err(CommonRoadParamsError::NotFinite { name, value });
            }
        }
        let ranges = [
            (
                ("steering.min_angle_rad", self.steering.min_angle_rad),
                ("steering.max_angle_rad", self.steering.max_angle_rad),
            ),
            (
                (
                    "steering.min_steering_velocity_radps",
                    self.steering.min_steering_velocity_radps,
                ),
                (
                    "steering.max_steering_velocity_radps",
                    self.steering.max_steering_velocity_radps,
                ),
            ),
            (
                (
                    "longitudinal.min_speed_mps",
                    self.longitudinal.min_speed_mps,
                ),
                (
                    "longitudinal.max_speed_mps",
                    self.longitudinal.max_speed_mps,
                ),
            ),
        ];
        for ((lower, lower_value), (upper, upper_value)) in ranges {
            if !lower_value.is_finite() {
                return Err(CommonRoadParamsError::NotFinite {
                    name: lower,
                    value: lower_value,
                });
            }
            if !upper_value.is_finite() {
                return Err(CommonRoadParamsError::NotFinite {
                    name: upper,
                    value: upper_value,
                });
            }
            if lower_value >= upper_value {
                return Err(CommonRoadParamsError::EmptyRange {
                    lower,
                    lower_value,
                    upper,
                    upper_value,
                });
            }
        }
        for (name, value) in [
            ("brake_torque_front_share", self.brake_torque_front_share),
            ("drive_torque_front_share", self.drive_torque_front_share),
        ] {
            if !(0.0..=1.0).contains(&value) {
                return Err(CommonRoadParamsError::NotAShare { name, value });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validate_names_the_field() {
        let p = CommonRoadVehicleParams {
            wheel_radius_m: 0.0,
            ..CommonRoadVehicleParams::default()
        };
        let e = p.validate().unwrap_err();
        assert!(e.to_string().contains("wheel_radius_m"), "{e}");
        let mut p = CommonRoadVehicleParams::default();
        p.steering.min_angle_rad = 2.0;
        assert!(matches!(
            p.validate(),
            Err(CommonRoadParamsError::EmptyRange { .. })
        ));
        let p = CommonRoadVehicleParams {
            drive_torque_front_share: 1.5,
            ..CommonRoadVehicleParams::default()
        };
        assert!(matches!(
            p.validate(),
            Err(CommonRoadParamsError::NotAShare { .. })
        ));
        let mut p = CommonRoadVehicleParams::default();
        p.tire.r_vy6 = f64::NAN;
        assert!(matches!(
            p.validate(),
            Err(CommonRoadParamsError::NotFinite { .. })
        ));
    }
}
