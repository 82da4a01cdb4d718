//! Where the other vehicles will be: their shared local path (SLP) interpolated in time, or a
//! constant-velocity prediction from their perceived state (PF-ISO-PRED, and PF-ISO for a
//! vehicle whose SLP is missing or stale).

use crate::types::{SharedLocalPath, TimedWaypoint, VehicleState};

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

    /// Pose at absolute time `t_s`.
    pub fn pose_at(&self, t_s: f64) -> PredictedPose {
        match self {
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
