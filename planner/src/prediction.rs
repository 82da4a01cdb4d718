//! Where the other vehicles will be: their shared local path (SLP) interpolated in time, or a
//! prediction from their perceived state (PF-ISO-PRED, PF-SP, and PF-ISO for a vehicle whose
//! SLP is missing or stale): straight along the heading at constant velocity, or following the
//! road ([`PredictionModel`]).

use serde::{Deserialize, Serialize};

use std::sync::Arc;

use mergesim_types::lanes::{LaneRoad, Side};

use crate::lane_road_field::LaneRoadGeometry;
use mergesim_types::{SharedLocalPath, TimedWaypoint, VehicleState};

/// How a vehicle without a fresh shared path is predicted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PredictionModel {
    /// Straight along its current heading at its current speed. A car 0.02 rad off the road
    /// axis is predicted 3.2 m — a lane — off its lane after 160 m.
    ConstantVelocity,
    /// Along its lane at its current speed, keeping its lateral offset d in the lane frame;
    /// in a lane that ends it is lifted to stay half the lane's starting width inside the
    /// closing bound, so a merging car is predicted to merge where the lane ends.
    LaneFollowing,
}

impl PredictionModel {
    /// The prediction of a vehicle in `state` at `time_s` on `road`.
    pub(crate) fn trajectory(
        self,
        state: VehicleState,
        time_s: f64,
        road: &LaneRoadGeometry,
    ) -> Trajectory {
        match self {
            PredictionModel::ConstantVelocity => Trajectory::ConstantVelocity { state, time_s },
            PredictionModel::LaneFollowing => {
                Trajectory::LaneFollowing(LaneFollowing::new(state, time_s, road))
            }
        }
    }
}

/// A vehicle predicted along its lane (the `lane-following` model) in the lane frame.
#[derive(Clone, Debug)]
pub struct LaneFollowing {
    /// State at `time_s`.
    pub state: VehicleState,
    /// Time of the state (s).
    pub time_s: f64,
    road: Arc<LaneRoad>,
    /// Index of its lane in the road.
    lane: usize,
    /// (s, d) now in its lane's frame (m).
    s0_m: f64,
    d0_m: f64,
    /// ds/dt per unit speed at its offset: 1/(1 − κ d) (1 on a straight lane).
    ds_per_m: f64,
    /// The closing bound of its lane if that ends (the side away from the lane it merges into),
    /// and half the lane's starting width (m).
    lift: Option<(Side, f64)>,
    /// The tangent of a straight lane (its pose is then the state moved along it, exactly).
    straight_tangent: Option<[f64; 2]>,
}

impl PartialEq for LaneFollowing {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.road, &other.road)
            && self.state == other.state
            && self.time_s == other.time_s
            && self.lane == other.lane
    }
}

impl LaneFollowing {
    /// The prediction of a vehicle in `state` at `time_s` on `road`.
    pub(crate) fn new(state: VehicleState, time_s: f64, road: &LaneRoadGeometry) -> Self {
        let p = [state.x_m, state.y_m];
        let (lane, fp) = road.lane_at(p);
        let l = &road.road().lanes()[lane];
        let q = 1.0 - l.curvature_1pm(fp.s_m) * fp.d_m;
        let ds_per_m = if q > 0.1 { 1.0 / q } else { 10.0 };
        let lift = if road.lane_ends(lane) {
            let target = road.target_lane(lane);
            road.side_of_neighbour(lane, target).map(|side| {
                let closing = match side {
                    Side::Left => Side::Right,
                    Side::Right => Side::Left,
                };
                (closing, 0.5 * l.width_m(0.0))
            })
        } else {
            None
        };
        Self {
            state,
            time_s,
            road: road.shared_road().clone(),
            lane,
            s0_m: fp.s_m,
            d0_m: fp.d_m,
            ds_per_m,
            lift,
            straight_tangent: road.straight_tangent(lane),
        }
    }

    /// Pose at absolute time `t_s`.
    pub(crate) fn pose_at(&self, t_s: f64) -> PredictedPose {
        let travelled_m = self.state.speed_mps * (t_s - self.time_s);
        let l = &self.road.lanes()[self.lane];
        let s_m = self.s0_m + travelled_m * self.ds_per_m;
        // Lifted by the closing bound: d and its slope along s.
        let lifted = self.lift.and_then(|(side, half_m)| {
            let (bound, slope) = l.bound_d_and_slope(side, s_m);
            match side {
                Side::Right => (bound + half_m > self.d0_m).then_some((bound + half_m, slope)),
                Side::Left => (bound - half_m < self.d0_m).then_some((bound - half_m, slope)),
            }
        });
        match (lifted, self.straight_tangent) {
            (None, Some(t)) => PredictedPose {
                xy_m: [
                    self.state.x_m + travelled_m * t[0],
                    self.state.y_m + travelled_m * t[1],
                ],
                heading: t,
            },
            (lifted, _) => {
                let (d_m, slope) = lifted.unwrap_or((self.d0_m, 0.0));
                let axes = l.centreline().axes(s_m, d_m);
                let dir = [
                    axes.dp_ds[0] + slope * axes.dp_dd[0],
                    axes.dp_ds[1] + slope * axes.dp_dd[1],
                ];
                let norm = dir[0].hypot(dir[1]);
                PredictedPose {
                    xy_m: axes.point_m,
                    heading: if norm > 0.0 {
                        [dir[0] / norm, dir[1] / norm]
                    } else {
                        [1.0, 0.0]
                    },
                }
            }
        }
    }
}

/// A predicted pose: position and unit heading vector (cos ψ, sin ψ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PredictedPose {
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
    /// Along its lane at the current speed, lateral offset kept, but at least half a lane
    /// inside the closing bound of a lane that ends.
    LaneFollowing(LaneFollowing),
}

impl Trajectory {
    /// The SLP of `message` (points not later than their predecessor are dropped). `None` if it
    /// holds no usable waypoint.
    pub(crate) fn from_shared(message: &SharedLocalPath, fallback_yaw_rad: f64) -> Option<Self> {
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
    pub(crate) fn is_predicted(&self) -> bool {
        !matches!(self, Self::Shared { .. })
    }

    /// Speed along the trajectory at absolute time `t_s` (m/s): the state's speed for a
    /// prediction, the speed of the segment of a shared path.
    pub(crate) fn speed_at(&self, t_s: f64) -> f64 {
        match self {
            Self::ConstantVelocity { state, .. } => state.speed_mps,
            Self::LaneFollowing(f) => f.state.speed_mps,
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
    pub(crate) fn pose_at(&self, t_s: f64) -> PredictedPose {
        match self {
            Self::LaneFollowing(f) => f.pose_at(t_s),
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
    use mergesim_types::VehicleShape;

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
        let road = mergesim_types::MergeRoad::default();
        let geometry = LaneRoadGeometry::new(&road.lane_road().unwrap());
        // An upper-lane car slightly yawed: stays at its lateral position along the road.
        let upper = VehicleState {
            x_m: 0.0,
            y_m: 5.3,
            yaw_rad: 0.03,
            speed_mps: 15.0,
        };
        let t = PredictionModel::LaneFollowing.trajectory(upper, 2.0, &geometry);
        let pose = t.pose_at(10.0);
        assert_eq!(pose.xy_m, [120.0, 5.3]);
        assert_eq!(pose.heading, [1.0, 0.0]);
        assert!(t.is_predicted());
        assert_eq!(t.speed_at(5.0), 15.0);
        // A lower-lane car: on its lane centre before the taper, lifted by the tapering edge,
        // on the through lane's centre after the merge section.
        let lower = VehicleState {
            x_m: 100.0,
            y_m: road.lane_center_y_m(mergesim_types::Lane::Lower),
            yaw_rad: 0.0,
            speed_mps: 20.0,
        };
        let t = PredictionModel::LaneFollowing.trajectory(lower, 0.0, &geometry);
        assert_eq!(t.pose_at(2.0).xy_m[1], lower.y_m);
        let mid_x = 0.5 * (road.merge_start_x_m + road.merge_end_x_m);
        let mid = t.pose_at((mid_x - 100.0) / 20.0);
        let expected = road.lower_edge_y_m(mid_x) + 0.5 * road.lane_width_m;
        assert!((mid.xy_m[1] - expected).abs() < 1e-9 && mid.xy_m[1] > lower.y_m);
        assert!(mid.heading[1] > 0.0, "heading along the taper");
        let after = t.pose_at((road.merge_end_x_m + 20.0 - 100.0) / 20.0);
        let upper_centre = road.lane_center_y_m(mergesim_types::Lane::Upper);
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
