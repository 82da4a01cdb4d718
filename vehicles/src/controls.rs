//! Physical inputs of a vehicle.

use serde::{Deserialize, Serialize};

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
