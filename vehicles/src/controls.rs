//! Physical inputs of a vehicle.

use serde::{Deserialize, Serialize};

use crate::params::VehicleParams;

/// Wheel order used everywhere in this crate.
pub const WHEEL_NAMES: [&str; 4] = ["FL", "FR", "RL", "RR"];

/// Driver / controller inputs: road-wheel steering angle and wheel torques.
///
/// Wheel order FL, FR, RL, RR. [`crate::Vehicle::set_controls`] clamps every value to the
/// vehicle's physical limits (non-finite values become 0, or keep the current steering target).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Controls {
    /// Commanded road-wheel steering angle of the front wheels (rad, positive = left).
    /// The actual angle follows at most at `max_steer_rate_radps`.
    pub steer_rad: f64,
    /// Drive torque per wheel (N·m, ≥ 0; non-driven wheels get 0).
    pub drive_torque_nm: [f64; 4],
    /// Brake torque per wheel (N·m, ≥ 0).
    pub brake_torque_nm: [f64; 4],
}

impl Controls {
    /// These controls within the limits of `params`: steering to ±`max_steer_rad`, drive torque
    /// to [0, the wheel's share of `max_drive_torque_nm`] (0 on non-driven wheels), brake torque
    /// to [0, the wheel's share of `max_brake_torque_nm`]. Non-finite torques become 0; a
    /// non-finite steering angle becomes `previous_steer_rad` (the current target).
    pub fn clamped(&self, params: &VehicleParams, previous_steer_rad: f64) -> Controls {
        let p = params;
        let steer = if self.steer_rad.is_finite() {
            self.steer_rad.clamp(-p.max_steer_rad, p.max_steer_rad)
        } else {
            previous_steer_rad
        };
        let clamp = |v: f64, max: f64| {
            if v.is_finite() {
                v.clamp(0.0, max)
            } else {
                0.0
            }
        };
        let mut clamped = Controls {
            steer_rad: steer,
            ..Controls::default()
        };
        for i in 0..4 {
            clamped.drive_torque_nm[i] =
                clamp(self.drive_torque_nm[i], p.max_drive_torque_wheel_nm(i));
            clamped.brake_torque_nm[i] =
                clamp(self.brake_torque_nm[i], p.max_brake_torque_wheel_nm(i));
        }
        clamped
    }
}
