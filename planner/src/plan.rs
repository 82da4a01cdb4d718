//! The planner's output: a plan (and, when it is a fallback, why).

use mergesim_types::{FallbackReason, PathPoint, SharedLocalPath, VehicleState};
use serde::{Deserialize, Serialize};

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
    /// then the planned speed of the segment (the speed its end point carries). A plan with fewer than two points leaves `now`
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
            now.speed_mps + f * (b.speed_mps - now.speed_mps)
        } else {
            b.speed_mps
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
    use mergesim_types::VehicleShape;

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
            (0.0, 0.0, 0.0, 8.0),
            (1.0, 10.0, 0.0, 10.0),
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
