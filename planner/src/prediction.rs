//! Where the other vehicles will be: their shared local path (SLP) interpolated in time, or a
//! prediction from their perceived state (PF-ISO-PRED, PF-SP, and PF-ISO for a vehicle whose
//! SLP is missing or stale): straight along the heading at constant velocity, or following the
//! road ([`PredictionModel`]).

use serde::{Deserialize, Serialize};

use crate::road::MergeRoad;
use crate::types::{SharedLocalPath, TimedWaypoint, VehicleState};

/// How a vehicle without a fresh shared path is predicted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PredictionModel {
    /// Straight along its current heading at its current speed. A car 0.02 rad off the road
    /// axis is predicted 3.2 m — a lane — off its lane after 160 m.
    ConstantVelocity,
    /// Along the road at its current speed, keeping its lateral position; in the ending lane
    /// it is lifted to stay half a lane above the tapering edge, so a merging car is predicted
    /// to merge where the lane ends.
    LaneFollowing,
}

impl PredictionModel {
    /// The prediction of a vehicle in `state` at `time_s`.
    pub fn trajectory(self, state: VehicleState, time_s: f64, road: &MergeRoad) -> Trajectory {
        match self {
            PredictionModel::ConstantVelocity => Trajectory::ConstantVelocity { state, time_s },
            PredictionModel::LaneFollowing => Trajectory::LaneFollowing {
                state,
                time_s,
                road: road.clone(),
            },
        }
    }
}

/// A predicted pose: position and unit heading vector (cos ψ, sin ψ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PredictedPose {
    /// Position (m).
    pub xy_m: [f64; 2],
    /// (cos ψ, sin ψ).
    pub heading: [f64; 2],
}

/// A motion prediction of another vehicle.
#[derive(Clone, Debug, PartialEq)]
pub enum Trajectory {
    /// Timed waypoints of a received SLP, strictly increasing in time, linearly interpolated
    /// and extrapolated with the velocity of the first / last segment.
    Shared {
        /// The waypoints.
        waypoints: Vec<TimedWaypoint>,
        /// Heading used where the path has no direction (coincident points).
        fallback_heading: [f64; 2],
    },
    /// Straight line at the current speed and yaw.
    ConstantVelocity {
        /// State at `time_s`.
        state: VehicleState,
        /// Time of the state (s).
        time_s: f64,
    },
    /// Along the road (+X) at the current speed, lateral position kept, but at least half a
    /// lane above the lower edge where the ending lane tapers.
    LaneFollowing {
        /// State at `time_s`.
        state: VehicleState,
        /// Time of the state (s).
        time_s: f64,
        /// The road it follows.
        road: MergeRoad,
    },
}

impl Trajectory {
    /// The SLP of `message` (points not later than their predecessor are dropped). `None` if it
    /// holds no usable waypoint.
    pub fn from_shared(message: &SharedLocalPath, fallback_yaw_rad: f64) -> Option<Self> {
        let mut waypoints: Vec<TimedWaypoint> = Vec::with_capacity(message.waypoints.len());
        for w in &message.waypoints {
            if !(w.t_s.is_finite() && w.x_m.is_finite() && w.y_m.is_finite()) {
                return None;
            }
            if waypoints.last().is_none_or(|last| w.t_s > last.t_s) {
                waypoints.push(*w);
            }
        }
        if waypoints.is_empty() {
            return None;
        }
        let (s, c) = fallback_yaw_rad.sin_cos();
        Some(Self::Shared {
            waypoints,
            fallback_heading: [c, s],
        })
    }

    /// Whether this is a prediction (not a received shared path).
    pub fn is_predicted(&self) -> bool {
        !matches!(self, Self::Shared { .. })
    }

    /// Speed along the trajectory at absolute time `t_s` (m/s): the state's speed for a
    /// prediction, the speed of the segment of a shared path.
    pub fn speed_at(&self, t_s: f64) -> f64 {
        match self {
            Self::ConstantVelocity { state, .. } | Self::LaneFollowing { state, .. } => {
                state.speed_mps
            }
            Self::Shared { waypoints, .. } => {
                let n = waypoints.len();
                if n < 2 {
                    return 0.0;
                }
                let k = waypoints
                    .partition_point(|w| w.t_s <= t_s)
                    .saturating_sub(1)
                    .min(n - 2);
                let (a, b) = (waypoints[k], waypoints[k + 1]);
                (b.x_m - a.x_m).hypot(b.y_m - a.y_m) / (b.t_s - a.t_s)
            }
        }
    }

    /// Pose at absolute time `t_s`.
    pub fn pose_at(&self, t_s: f64) -> PredictedPose {
        match self {
            Self::LaneFollowing {
                state,
                time_s,
                road,
            } => {
                let x_m = state.x_m + state.speed_mps * (t_s - time_s);
                let half_lane_m = 0.5 * road.lane_width_m;
                let lifted_y_m = road.lower_edge_y_m(x_m) + half_lane_m;
                if state.y_m < road.y_lane_m() && lifted_y_m > state.y_m {
                    let slope = road.lower_edge_slope(x_m);
                    let norm = slope.hypot(1.0);
                    PredictedPose {
                        xy_m: [x_m, lifted_y_m],
                        heading: [1.0 / norm, slope / norm],
                    }
                } else {
                    PredictedPose {
                        xy_m: [x_m, state.y_m],
                        heading: [1.0, 0.0],
                    }
                }
            }
            Self::ConstantVelocity { state, time_s } => {
                let (s, c) = state.yaw_rad.sin_cos();
                let d = state.speed_mps * (t_s - time_s);
                PredictedPose {
                    xy_m: [state.x_m + d * c, state.y_m + d * s],
                    heading: [c, s],
                }
            }
            Self::Shared {
                waypoints,
                fallback_heading,
            } => {
                let n = waypoints.len();
                if n == 1 {
                    return PredictedPose {
                        xy_m: [waypoints[0].x_m, waypoints[0].y_m],
                        heading: *fallback_heading,
                    };
                }
                let k = waypoints
                    .partition_point(|w| w.t_s <= t_s)
                    .saturating_sub(1)
                    .min(n - 2);
                let a = waypoints[k];
                let b = waypoints[k + 1];
                let f = (t_s - a.t_s) / (b.t_s - a.t_s);
                let xy_m = [a.x_m + f * (b.x_m - a.x_m), a.y_m + f * (b.y_m - a.y_m)];
                // Heading: the nearest segment with a direction.
                let heading = (k..n - 1)
                    .chain((0..k).rev())
                    .find_map(|j| {
                        let dx = waypoints[j + 1].x_m - waypoints[j].x_m;
                        let dy = waypoints[j + 1].y_m - waypoints[j].y_m;
                        let len = (dx * dx + dy * dy).sqrt();
                        (len > 1e-6).then(|| [dx / len, dy / len])
                    })
                    .unwrap_or(*fallback_heading);
                PredictedPose { xy_m, heading }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::types::VehicleShape;

    #[test]
    fn shared_path_is_interpolated_and_extrapolated_in_time() {
        let message = SharedLocalPath {
            vehicle_id: 1,
            stamp_s: 10.0,
            shape: VehicleShape::default(),
            speed_mps: 10.0,
            waypoints: vec![
                TimedWaypoint {
                    t_s: 10.0,
                    x_m: 0.0,
                    y_m: 0.0,
                },
                TimedWaypoint {
                    t_s: 11.0,
                    x_m: 10.0,
                    y_m: 0.0,
                },
                TimedWaypoint {
                    t_s: 11.0,
                    x_m: 99.0,
                    y_m: 99.0,
                }, // not later: dropped
                TimedWaypoint {
                    t_s: 12.0,
                    x_m: 20.0,
                    y_m: 5.0,
                },
            ],
        };
        let trajectory = Trajectory::from_shared(&message, 0.0).unwrap();
        let mid = trajectory.pose_at(10.5);
        assert_eq!(mid.xy_m, [5.0, 0.0]);
        assert_eq!(mid.heading, [1.0, 0.0]);
        let late = trajectory.pose_at(13.0);
        assert!((late.xy_m[0] - 30.0).abs() < 1e-12 && (late.xy_m[1] - 10.0).abs() < 1e-12);
    }

    #[test]
    fn lane_following_keeps_the_lane_and_merges_with_the_taper() {
        let road = MergeRoad::default();
        // An upper-lane car slightly yawed: stays at its lateral position along the road.
        let upper = VehicleState {
            x_m: 0.0,
            y_m: 5.3,
            yaw_rad: 0.03,
            speed_mps: 15.0,
        };
        let t = PredictionModel::LaneFollowing.trajectory(upper, 2.0, &road);
        let pose = t.pose_at(10.0);
        assert_eq!(pose.xy_m, [120.0, 5.3]);
        assert_eq!(pose.heading, [1.0, 0.0]);
        assert!(t.is_predicted());
        assert_eq!(t.speed_at(5.0), 15.0);
        // A lower-lane car: on its lane centre before the taper, lifted by the tapering edge,
        // on the through lane's centre after the merge section.
        let lower = VehicleState {
            x_m: 100.0,
            y_m: road.lane_center_y_m(crate::road::Lane::Lower),
            yaw_rad: 0.0,
            speed_mps: 20.0,
        };
        let t = PredictionModel::LaneFollowing.trajectory(lower, 0.0, &road);
        assert_eq!(t.pose_at(2.0).xy_m[1], lower.y_m);
        let mid_x = 0.5 * (road.merge_start_x_m + road.merge_end_x_m);
        let mid = t.pose_at((mid_x - 100.0) / 20.0);
        let expected = road.lower_edge_y_m(mid_x) + 0.5 * road.lane_width_m;
        assert!((mid.xy_m[1] - expected).abs() < 1e-9 && mid.xy_m[1] > lower.y_m);
        assert!(mid.heading[1] > 0.0, "heading along the taper");
        let after = t.pose_at((road.merge_end_x_m + 20.0 - 100.0) / 20.0);
        let upper_centre = road.lane_center_y_m(crate::road::Lane::Upper);
        assert!((after.xy_m[1] - upper_centre).abs() < 1e-9);
    }

    #[test]
    fn shared_path_speed_is_the_segment_speed() {
        let message = SharedLocalPath {
            vehicle_id: 1,
            stamp_s: 0.0,
            shape: VehicleShape::default(),
            speed_mps: 10.0,
            waypoints: vec![
                TimedWaypoint {
                    t_s: 0.0,
                    x_m: 0.0,
                    y_m: 0.0,
                },
                TimedWaypoint {
                    t_s: 1.0,
                    x_m: 3.0,
                    y_m: 4.0,
                },
                TimedWaypoint {
                    t_s: 3.0,
                    x_m: 13.0,
                    y_m: 4.0,
                },
            ],
        };
        let t = Trajectory::from_shared(&message, 0.0).unwrap();
        assert_eq!(t.speed_at(0.5), 5.0);
        assert_eq!(t.speed_at(2.0), 5.0);
        assert_eq!(t.speed_at(9.0), 5.0);
        assert!(!t.is_predicted());
    }

    #[test]
    fn constant_velocity_moves_along_the_yaw() {
        let state = VehicleState {
            x_m: 1.0,
            y_m: 2.0,
            yaw_rad: std::f64::consts::FRAC_PI_2,
            speed_mps: 4.0,
        };
        let trajectory = Trajectory::ConstantVelocity { state, time_s: 3.0 };
        let pose = trajectory.pose_at(5.0);
        assert!((pose.xy_m[0] - 1.0).abs() < 1e-12 && (pose.xy_m[1] - 10.0).abs() < 1e-12);
    }
}
