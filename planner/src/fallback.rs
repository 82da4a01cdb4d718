//! The fallback plan: a comfortable deceleration along the last good path.
//!
//! Used whenever a planning cycle cannot produce a trustworthy plan (solver status other than
//! Solved / AlmostSolved, a non-finite number, waypoints a cubic cannot hold). The geometry is
//! the part of the last good plan's path still ahead of the vehicle (the vehicle's position is
//! projected on it); without one, a straight line along the vehicle's heading. Along it the
//! speed falls at `fallback_decel_mps2` from the current speed:
//! v(s) = √(max(v0² − 2 a s, 0)), reached at t(s) = (v0 − v(s)) / a.

use crate::Plan;
use crate::params::PlannerParams;
use crate::polyline::Polyline;
use mergesim_types::{
    FallbackReason, PathPoint, SharedLocalPath, TimedWaypoint, VehicleId, VehicleShape,
    VehicleState,
};

/// Everything the fallback needs about the vehicle.
#[derive(Clone, Copy, Debug)]
pub struct FallbackInput<'a> {
    /// Planning time (s).
    pub time_s: f64,
    /// Vehicle id.
    pub ego_id: VehicleId,
    /// Vehicle state (finite).
    pub ego: &'a VehicleState,
    /// Vehicle shape.
    pub ego_shape: &'a VehicleShape,
    /// The last plan that was not a fallback.
    pub last_good: Option<&'a Plan>,
    /// This cycle's potential-field waypoints, if they were computed and finite.
    pub waypoints: Option<&'a [[f64; 2]]>,
}

/// Points of `path` still ahead of `p`: those after the segment closest to `p`.
fn remaining_points(path: &[PathPoint], p: [f64; 2]) -> Vec<[f64; 2]> {
    if path.len() < 2 {
        return Vec::new();
    }
    let mut best = (f64::INFINITY, 0usize);
    for (k, w) in path.windows(2).enumerate() {
        let (a, b) = ([w[0].x_m, w[0].y_m], [w[1].x_m, w[1].y_m]);
        let d = [b[0] - a[0], b[1] - a[1]];
        let len2 = d[0] * d[0] + d[1] * d[1];
        let f = if len2 > 0.0 {
            (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [a[0] + f * d[0], a[1] + f * d[1]];
        let dist2 = (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
        if dist2 <= best.0 {
            best = (dist2, k);
        }
    }
    path[best.1 + 1..]
        .iter()
        .map(|q| [q.x_m, q.y_m])
        .filter(|q| q.iter().all(|v| v.is_finite()))
        .collect()
}

/// The fallback plan (module doc), flagged with `reason`.
pub fn fallback_plan(
    params: &PlannerParams,
    input: &FallbackInput<'_>,
    reason: FallbackReason,
) -> Plan {
    let ego = input.ego;
    let start = [ego.x_m, ego.y_m];
    let (sin_yaw, cos_yaw) = ego.yaw_rad.sin_cos();
    let n = params.waypoint_count;
    let step_m = params.step_length_m(ego.speed_mps);
    let mut ahead = input
        .last_good
        .map(|last| remaining_points(&last.path, start))
        .unwrap_or_default();
    if ahead.is_empty() {
        ahead = (1..=n)
            .map(|k| {
                let d = k as f64 * step_m;
                [ego.x_m + d * cos_yaw, ego.y_m + d * sin_yaw]
            })
            .collect();
    }
    let line = Polyline::with_start(start, ahead);
    let v0 = ego.speed_mps.max(0.0);
    let a = params.fallback_decel_mps2;
    let t_stop = v0 / a;
    let s_stop = v0 * v0 / (2.0 * a);
    let speed_at = |s: f64| (v0 * v0 - 2.0 * a * s).max(0.0).sqrt();
    let path: Vec<PathPoint> = line
        .points()
        .iter()
        .zip(line.arc_lengths_m())
        .map(|(p, &s)| {
            let v = speed_at(s);
            // Past the stopping point the vehicle never arrives: those points carry speed 0
            // and the stopping time.
            let t = if s < s_stop { (v0 - v) / a } else { t_stop };
            PathPoint {
                x_m: p[0],
                y_m: p[1],
                speed_mps: v,
                t_s: input.time_s + t,
            }
        })
        .collect();
    // The broadcast: where the vehicle will be on a time grid (standing still after t_stop).
    let shared_waypoints = (0..=n)
        .map(|k| {
            let t = (k as f64 * params.step_time_s).min(t_stop);
            let s = v0 * t - 0.5 * a * t * t;
            let (p, _) = line.point_and_tangent(s, [cos_yaw, sin_yaw]);
            TimedWaypoint {
                t_s: input.time_s + k as f64 * params.step_time_s,
                x_m: p[0],
                y_m: p[1],
            }
        })
        .collect();
    let waypoints = input
        .waypoints
        .map(<[[f64; 2]]>::to_vec)
        .unwrap_or_else(|| line.points()[1..].to_vec());
    Plan {
        waypoints,
        path,
        cubic: [0.0; 4],
        cubic_x_scale_m: 1.0,
        shared: SharedLocalPath {
            vehicle_id: input.ego_id,
            stamp_s: input.time_s,
            shape: *input.ego_shape,
            speed_mps: v0,
            waypoints: shared_waypoints,
        },
        fallback: Some(reason),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decelerates_comfortably_along_a_straight_line_without_history() {
        let params = PlannerParams::default();
        let ego = VehicleState {
            x_m: 5.0,
            y_m: 1.75,
            yaw_rad: 0.0,
            speed_mps: 6.0,
        };
        let shape = VehicleShape::default();
        let input = FallbackInput {
            time_s: 2.0,
            ego_id: 3,
            ego: &ego,
            ego_shape: &shape,
            last_good: None,
            waypoints: None,
        };
        let plan = fallback_plan(&params, &input, FallbackReason::SolverFailed("test".into()));
        assert!(plan.fallback.is_some());
        assert_eq!(plan.path[0].x_m, 5.0);
        assert_eq!(plan.path[0].t_s, 2.0);
        let a = params.fallback_decel_mps2;
        for p in &plan.path {
            let s = p.x_m - 5.0;
            let expected = (36.0 - 2.0 * a * s).max(0.0).sqrt();
            assert!((p.speed_mps - expected).abs() < 1e-12);
        }
        // Times never decrease and the broadcast stops at v0²/(2a).
        assert!(plan.path.windows(2).all(|w| w[1].t_s >= w[0].t_s));
        let last = plan.shared.waypoints.last().unwrap();
        assert!((last.x_m - (5.0 + 36.0 / (2.0 * a))).abs() < 1e-9);
    }
}
