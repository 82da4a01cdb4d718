//! Plain data exchanged between the planner, the tracker, the V2V bus and the simulator.

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
        // BMW 320i (CommonRoad vehicle 2): 4.508 m × 1.610 m, wheelbase 2.578 m.
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

/// One waypoint of a shared local path with the time at which the sender expects to be there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimedWaypoint {
    /// Absolute time (s) at which the sender plans to reach the waypoint.
    pub t_s: f64,
    /// Position (m).
    pub x_m: f64,
    /// Position (m).
    pub y_m: f64,
}

/// The shared local path (SLP) message a connected vehicle broadcasts over V2V (paper Sec. IV).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SharedLocalPath {
    /// Sender.
    pub vehicle_id: VehicleId,
    /// Time the plan was made (s).
    pub stamp_s: f64,
    /// Sender's footprint, for the receiver's obstacle field.
    pub shape: VehicleShape,
    /// The sender's speed at `stamp_s` (m/s).
    pub speed_mps: f64,
    /// Planned waypoints X_pf^i, Y_pf^i (Eq. 7) with their planned times.
    pub waypoints: Vec<TimedWaypoint>,
}

/// One point of the path handed to the tracker.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathPoint {
    /// Position (m).
    pub x_m: f64,
    /// Position (m).
    pub y_m: f64,
    /// Speed to hold from here to the next point (m/s).
    pub speed_mps: f64,
    /// Planned absolute arrival time (s).
    pub t_s: f64,
}

/// Why a plan is a fallback rather than the optimiser's answer.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum FallbackReason {
    /// The convex solver did not converge.
    SolverFailed(String),
    /// A non-finite number appeared.
    NonFinite(String),
}

/// The output of one planning cycle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// Potential-field waypoints (Eq. 7), world frame, starting after the current position.
    pub waypoints: Vec<[f64; 2]>,
    /// Path to track: the fitted cubic (Eqs. 8–9) sampled at the waypoints, with speeds (Eq. 10)
    /// and times. The first point is the vehicle's position at planning time.
    pub path: Vec<PathPoint>,
    /// The cubic coefficients a0..a3 in the vehicle frame at planning time, x scaled by
    /// `cubic_x_scale_m` (y = Σ a_k (x / scale)^k).
    pub cubic: [f64; 4],
    /// Scale of x in the cubic (m).
    pub cubic_x_scale_m: f64,
    /// The message to broadcast.
    pub shared: SharedLocalPath,
    /// Set when this plan is a fallback (comfortable deceleration along the last good path).
    pub fallback: Option<FallbackReason>,
}
