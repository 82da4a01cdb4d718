//! What a vehicle's motion looks like from outside: pose, velocities, accelerations.

use serde::{Deserialize, Serialize};

/// Motion state of a vehicle's centre of gravity.
///
/// Velocities and accelerations are resolved in the heading frame (x along the body's
/// heading projected on the ground, y to its left, ISO 8855's intermediate axis system); for the
/// small roll and pitch angles of road driving it agrees with the body frame to within
/// 1 − cos(angle).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Kinematics {
    /// Position of the CoG (m).
    pub x_m: f64,
    /// Position of the CoG (m).
    pub y_m: f64,
    /// Height of the CoG (m).
    pub z_m: f64,
    /// Heading ψ (rad, counter-clockwise from +X, in (−π, π]).
    pub yaw_rad: f64,
    /// Pitch θ (rad, positive nose down, ZYX Euler angles).
    pub pitch_rad: f64,
    /// Roll φ (rad, positive right side down, ZYX Euler angles).
    pub roll_rad: f64,
    /// Horizontal speed over ground (m/s).
    pub speed_mps: f64,
    /// Longitudinal velocity (m/s).
    pub vx_body_mps: f64,
    /// Lateral velocity (m/s, positive to the left).
    pub vy_body_mps: f64,
    /// Yaw rate r (rad/s, positive counter-clockwise).
    pub yaw_rate_radps: f64,
    /// Sideslip angle at the CoG, β = atan2(v_y, v_x) (rad); 0 below 0.1 m/s where it is
    /// undefined.
    pub sideslip_rad: f64,
    /// Longitudinal acceleration over the last physics step (m/s²).
    pub accel_long_mps2: f64,
    /// Lateral acceleration over the last physics step (m/s², positive to the left); v·r in a
    /// steady turn.
    pub accel_lat_mps2: f64,
    /// Actual road-wheel steering angle of the front wheels (rad).
    pub steer_rad: f64,
}

/// The planner's view of a vehicle's state: the pose and speed of its centre of gravity,
/// without the velocities, accelerations and angles only the physics knows.
impl From<&Kinematics> for mergesim_types::VehicleState {
    fn from(k: &Kinematics) -> Self {
        Self {
            x_m: k.x_m,
            y_m: k.y_m,
            yaw_rad: k.yaw_rad,
            speed_mps: k.speed_mps,
        }
    }
}
