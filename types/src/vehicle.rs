//! A vehicle as the planners see it: its state, its footprint and braking, and a perceived
//! neighbour.

use serde::{Deserialize, Serialize};

/// Identifier of a vehicle in a scenario (index order is the deterministic visiting order).
pub type VehicleId = u32;

/// What the planner knows about a vehicle at planning time (world frame, SI).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct VehicleState {
    /// Position of the centre of gravity along the road (m).
    pub x_m: f64,
    /// Lateral position of the centre of gravity (m).
    pub y_m: f64,
    /// Heading of the body x axis (rad, counter-clockwise from +X).
    pub yaw_rad: f64,
    /// Speed over ground (m/s).
    pub speed_mps: f64,
}

/// Footprint and braking capability of a vehicle, used by the obstacle field (Eq. 4).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct VehicleShape {
    /// Body length (m).
    pub length_m: f64,
    /// Body width (m).
    pub width_m: f64,
    /// Wheelbase l_fr (m).
    pub wheelbase_m: f64,
    /// Maximum braking deceleration a_b (m/s², positive).
    pub max_brake_decel_mps2: f64,
}

impl Default for VehicleShape {
    fn default() -> Self {
        // BMW 320i (CommonRoad vehicle 2): 4.508 m × 1.610 m, wheelbase 2.578 m; a_b = 7 m/s²,
        // friction-limited braking at μ = 0.8 (0.9·μg).
        Self {
            length_m: 4.508,
            width_m: 1.61,
            wheelbase_m: 2.578,
            max_brake_decel_mps2: 7.0,
        }
    }
}

/// Another vehicle as currently perceived (position, heading, speed, shape).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Neighbour {
    /// Its id.
    pub id: VehicleId,
    /// Its state.
    pub state: VehicleState,
    /// Its footprint.
    pub shape: VehicleShape,
}
