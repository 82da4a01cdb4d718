//! Paths: the points a tracker follows, and the shared local path (SLP) a connected vehicle
//! broadcasts over V2V (paper Sec. IV).

use serde::{Deserialize, Serialize};

use crate::vehicle::{VehicleId, VehicleShape};

/// One point of the path handed to the tracker.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathPoint {
    /// Position (m).
    pub x_m: f64,
    /// Position (m).
    pub y_m: f64,
    /// Planned speed on reaching this point (m/s): the first point carries the vehicle's speed
    /// v_0 at the plan's time, point k the speed v_k of the step ending at it (the segment to
    /// it is driven at v_k: t_k = t_{k−1} + Δs / v_k); linear in time in between, the profile
    /// starts where the vehicle is. The tracker aims at the speed of the point ahead of the
    /// vehicle, i.e. the end of its segment.
    pub speed_mps: f64,
    /// Planned absolute arrival time (s).
    pub t_s: f64,
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

impl SharedLocalPath {
    /// The message of `path` (its points with their planned times) sent by `vehicle_id` at
    /// `stamp_s`.
    pub fn from_path(
        vehicle_id: VehicleId,
        stamp_s: f64,
        shape: VehicleShape,
        speed_mps: f64,
        path: &[PathPoint],
    ) -> Self {
        Self {
            vehicle_id,
            stamp_s,
            shape,
            speed_mps,
            waypoints: path
                .iter()
                .map(|p| TimedWaypoint {
                    t_s: p.t_s,
                    x_m: p.x_m,
                    y_m: p.y_m,
                })
                .collect(),
        }
    }
}
