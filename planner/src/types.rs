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
    /// Planned speed on the segment from this point to the next (m/s): the times follow
    /// t_{k+1} = t_k + Δs_k / v_k. The tracker aims at the speed of the point ahead of the
    /// vehicle, i.e. the next segment's, which previews the profile by one segment.
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

impl Plan {
    /// The state at `t_s` of an ideal vehicle that follows this plan exactly, starting from
    /// `now` (kinematic roll-outs in tests and examples; the simulator moves its vehicles with
    /// a tracker and tyres instead): position and heading interpolated along the timed path,
    /// speed ramping from `now`'s speed to the first planned speed over the first segment and
    /// then the planned speed of the segment. A plan with fewer than two points leaves `now`
    /// unchanged.
    pub fn kinematic_state_at(&self, now: &VehicleState, t_s: f64) -> VehicleState {
        let path = &self.path;
        if path.len() < 2 {
            return *now;
        }
        let k = path
            .partition_point(|p| p.t_s <= t_s)
            .clamp(1, path.len() - 1);
        let (a, b) = (path[k - 1], path[k]);
        let f = ((t_s - a.t_s) / (b.t_s - a.t_s)).clamp(0.0, 1.0);
        let speed_mps = if k == 1 {
            now.speed_mps + f * (a.speed_mps - now.speed_mps)
        } else {
            a.speed_mps
        };
        VehicleState {
            x_m: a.x_m + f * (b.x_m - a.x_m),
            y_m: a.y_m + f * (b.y_m - a.y_m),
            yaw_rad: (b.y_m - a.y_m).atan2(b.x_m - a.x_m),
            speed_mps,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan_through(points: &[(f64, f64, f64, f64)]) -> Plan {
        Plan {
            waypoints: Vec::new(),
            path: points
                .iter()
                .map(|&(t_s, x_m, y_m, speed_mps)| PathPoint {
                    x_m,
                    y_m,
                    speed_mps,
                    t_s,
                })
                .collect(),
            cubic: [0.0; 4],
            cubic_x_scale_m: 1.0,
            shared: SharedLocalPath {
                vehicle_id: 0,
                stamp_s: 0.0,
                shape: VehicleShape::default(),
                speed_mps: 0.0,
                waypoints: Vec::new(),
            },
            fallback: None,
        }
    }

    #[test]
    fn kinematic_state_follows_the_timed_path() {
        let now = VehicleState {
            x_m: 0.0,
            y_m: 0.0,
            yaw_rad: 0.0,
            speed_mps: 8.0,
        };
        let plan = plan_through(&[
            (0.0, 0.0, 0.0, 10.0),
            (1.0, 10.0, 0.0, 12.0),
            (2.0, 20.0, 10.0, 12.0),
        ]);
        // First segment: halfway in position, speed halfway from 8 to the first planned 10.
        let s = plan.kinematic_state_at(&now, 0.5);
        assert_eq!((s.x_m, s.y_m, s.yaw_rad, s.speed_mps), (5.0, 0.0, 0.0, 9.0));
        // Second segment: its own planned speed, heading along it (45°).
        let s = plan.kinematic_state_at(&now, 1.5);
        assert_eq!((s.x_m, s.y_m, s.speed_mps), (15.0, 5.0, 12.0));
        assert!((s.yaw_rad - std::f64::consts::FRAC_PI_4).abs() < 1e-12);
        // Past the end: held at the last point.
        let s = plan.kinematic_state_at(&now, 9.0);
        assert_eq!((s.x_m, s.y_m), (20.0, 10.0));
        // A plan without a segment leaves the state alone.
        assert_eq!(plan_through(&[]).kinematic_state_at(&now, 1.0), now);
    }
}
