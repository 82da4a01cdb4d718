//! A prescribed time → speed profile, and a plan re-timed to follow it: the prescribed-speed
//! driver takes its path from a potential-field planner and its speeds from the profile, which
//! tests the paper's causal claim ("slowing down in advance reduces the winding") without the
//! speed optimiser.

use serde::{Deserialize, Serialize};

use crate::Plan;
use crate::error::PlannerError;
use mergesim_types::{PathPoint, SharedLocalPath};

/// Slowest speed a profile may prescribe (m/s): a standstill (stop and go, `stop_and_go`).
pub const MIN_PROFILE_SPEED_MPS: f64 = 0.0;

/// Below this speed at its start (m/s) a segment is timed by the profile itself (the time at
/// which the distance driven along the profile reaches the segment's length), not at its start
/// speed: a standstill followed by a start is then timed when the profile starts. 0.5 m/s, the
/// slowest speed profiles could prescribe before stop and go, so faster profiles are timed as
/// before, bit for bit.
pub const RETIME_SLOW_SPEED_MPS: f64 = 0.5;

/// Speed floor of the re-timed path's *times* (m/s): a segment the profile never finishes (it
/// ends standing) is timed as if driven at this speed, so every time is finite (`stop_and_go`
/// module doc, item 4); the speeds themselves go down to 0.
pub const RETIME_SPEED_FLOOR_MPS: f64 = crate::stop_and_go::STANDSTILL_TIMING_SPEED_MPS;

/// Fastest speed a profile may prescribe (m/s).
pub const MAX_PROFILE_SPEED_MPS: f64 = 60.0;

/// Largest number of points of a profile.
pub const MAX_PROFILE_POINTS: usize = 10_000;

/// Speeds over absolute time: `[t_s, speed_mps]` points with increasing times, linear in
/// between, held before the first and after the last.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct SpeedProfile {
    /// `[t_s, speed_mps]` points.
    #[serde(deserialize_with = "points_of_two")]
    pub points: Vec<[f64; 2]>,
}

/// Reads `[[t_s, speed_mps], …]`: exactly two numbers per point (serde's arrays would
/// silently ignore a third).
fn points_of_two<'de, D: serde::Deserializer<'de>>(
    deserializer: D,
) -> Result<Vec<[f64; 2]>, D::Error> {
    let points = Vec::<Vec<f64>>::deserialize(deserializer)?;
    points
        .into_iter()
        .enumerate()
        .map(|(i, point)| match point.as_slice() {
            [t_s, speed_mps] => Ok([*t_s, *speed_mps]),
            _ => Err(serde::de::Error::custom(format!(
                "speed_profile point {i}: expected exactly two numbers [t_s, speed_mps], got {}",
                point.len()
            ))),
        })
        .collect()
}

impl SpeedProfile {
    /// Checks the points; the error names the offending point (`what` prefixes the name).
    pub fn validate(&self, what: &str) -> Result<(), PlannerError> {
        let bad =
            |name: String, value: f64, reason: &str| PlannerError::invalid(name, value, reason);
        if self.points.is_empty() || self.points.len() > MAX_PROFILE_POINTS {
            return Err(bad(
                format!("{what}.speed_profile"),
                self.points.len() as f64,
                &format!("needs 1 to {MAX_PROFILE_POINTS} [t_s, speed_mps] points"),
            ));
        }
        let mut previous_t_s = f64::NEG_INFINITY;
        for (i, [t_s, v_mps]) in self.points.iter().copied().enumerate() {
            if !(t_s.is_finite() && t_s >= 0.0 && t_s > previous_t_s) {
                return Err(bad(
                    format!("{what}.speed_profile[{i}] time"),
                    t_s,
                    "times must be finite, >= 0 and increasing",
                ));
            }
            if !(v_mps.is_finite()
                && (MIN_PROFILE_SPEED_MPS..=MAX_PROFILE_SPEED_MPS).contains(&v_mps))
            {
                return Err(bad(
                    format!("{what}.speed_profile[{i}] speed"),
                    v_mps,
                    &format!("must lie in [{MIN_PROFILE_SPEED_MPS}, {MAX_PROFILE_SPEED_MPS}] m/s"),
                ));
            }
            previous_t_s = t_s;
        }
        Ok(())
    }

    /// The speed at `t_s` (m/s). An empty profile gives [`MIN_PROFILE_SPEED_MPS`].
    pub fn speed_at(&self, t_s: f64) -> f64 {
        let points = &self.points;
        let Some(first) = points.first() else {
            return MIN_PROFILE_SPEED_MPS;
        };
        let k = points.partition_point(|p| p[0] <= t_s);
        if k == 0 {
            return first[1];
        }
        if k == points.len() {
            return points[k - 1][1];
        }
        let (a, b) = (points[k - 1], points[k]);
        a[1] + (t_s - a[0]) / (b[0] - a[0]) * (b[1] - a[1])
    }
}

/// Time (s) at which a vehicle driving at `profile`'s speeds from `t0_s` has covered `ds_m`:
/// the piecewise-linear profile integrated exactly; beyond its last point at its last speed,
/// floored at [`RETIME_SPEED_FLOOR_MPS`] (so finite when the profile ends standing).
fn time_to_cover_s(profile: &SpeedProfile, t0_s: f64, ds_m: f64) -> f64 {
    let mut t_s = t0_s;
    let mut left_m = ds_m.max(0.0);
    let first = profile.points.partition_point(|p| p[0] <= t0_s);
    for point in &profile.points[first..] {
        let t_next_s = point[0];
        let (va, vb) = (profile.speed_at(t_s).max(0.0), point[1].max(0.0));
        let span_s = t_next_s - t_s;
        let covered_m = 0.5 * (va + vb) * span_s;
        if covered_m >= left_m && span_s > 0.0 {
            // va τ + ½ a τ² = left, in the form without cancellation.
            let accel = (vb - va) / span_s;
            let root = (va * va + 2.0 * accel * left_m).max(0.0).sqrt();
            let denominator = va + root;
            return if denominator > 0.0 {
                t_s + (2.0 * left_m / denominator).min(span_s)
            } else {
                t_s
            };
        }
        left_m -= covered_m;
        t_s = t_next_s;
    }
    t_s + left_m / profile.speed_at(t_s).max(RETIME_SPEED_FLOOR_MPS)
}

/// Re-times `path` (its first point's time kept) to `profile`: segment k (point k to point
/// k + 1) is driven at the profile's speed at the time the path reaches point k, and the times
/// follow, t_{k+1} = t_k + Δs_k / v_k; a segment starting slower than
/// [`RETIME_SLOW_SPEED_MPS`] (a stop, a start) is timed by the profile itself
/// (`time_to_cover_s`) and its end carries the speed at its start (the tracker reads the next
/// point's speed as the speed to drive now; replanned every cycle, the car follows the profile
/// one planning period late).
pub fn retime_path(path: &mut [PathPoint], profile: &SpeedProfile) {
    let n = path.len();
    let mut carried_mps = None;
    for k in 0..n {
        let t_s = path[k].t_s;
        let v_mps = profile
            .speed_at(t_s)
            .clamp(MIN_PROFILE_SPEED_MPS, MAX_PROFILE_SPEED_MPS);
        path[k].speed_mps = carried_mps.take().unwrap_or(v_mps);
        if k + 1 < n {
            let (a, b) = (path[k], path[k + 1]);
            let ds_m = (b.x_m - a.x_m).hypot(b.y_m - a.y_m);
            path[k + 1].t_s = if v_mps >= RETIME_SLOW_SPEED_MPS {
                t_s + ds_m / v_mps
            } else {
                // The tracker aims at the next point's speed now: a slow segment's end carries
                // the speed at its start, not the one the profile reaches there (after a
                // standstill that may be seconds later).
                carried_mps = Some(v_mps);
                time_to_cover_s(profile, t_s, ds_m)
            };
        }
    }
}

impl Plan {
    /// The same path with the speeds of `profile` ([`retime_path`]); the shared path gets the
    /// same times.
    pub fn with_speed_profile(&self, profile: &SpeedProfile) -> Plan {
        let mut plan = self.clone();
        retime_path(&mut plan.path, profile);
        let shared = &plan.shared;
        plan.shared = SharedLocalPath::from_path(
            shared.vehicle_id,
            shared.stamp_s,
            shared.shape,
            shared.speed_mps,
            &plan.path,
        );
        plan
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mergesim_types::{PathPoint, SharedLocalPath, VehicleShape};

    fn profile() -> SpeedProfile {
        SpeedProfile {
            points: vec![[0.0, 15.0], [3.1, 15.0], [14.9, 9.4], [20.0, 15.0]],
        }
    }

    #[test]
    fn speed_is_linear_between_points_and_held_outside() {
        let p = profile();
        assert_eq!(p.speed_at(-1.0), 15.0);
        assert_eq!(p.speed_at(2.0), 15.0);
        assert!((p.speed_at(9.0) - (15.0 - 5.6 * (5.9 / 11.8))).abs() < 1e-12);
        assert_eq!(p.speed_at(14.9), 9.4);
        assert_eq!(p.speed_at(99.0), 15.0);
        p.validate("vehicles[obstacle].driver").unwrap();
    }

    #[test]
    fn bad_profiles_are_refused_by_point() {
        let cases = [
            (vec![], "speed_profile"),
            (vec![[0.0, 15.0], [0.0, 14.0]], "speed_profile[1] time"),
            (vec![[0.0, -0.1]], "speed_profile[0] speed"),
            (vec![[f64::NAN, 10.0]], "speed_profile[0] time"),
            (
                vec![[0.0, 10.0], [1.0, f64::INFINITY]],
                "speed_profile[1] speed",
            ),
        ];
        for (points, field) in cases {
            let err = SpeedProfile { points }
                .validate("x")
                .unwrap_err()
                .to_string();
            assert!(err.contains(field), "{err}");
        }
    }

    #[test]
    fn a_plan_is_retimed_along_the_same_path() {
        let points = [(0.0, 0.0), (10.0, 0.0), (20.0, 0.0), (30.0, 0.0)];
        let plan = Plan {
            waypoints: Vec::new(),
            path: points
                .iter()
                .enumerate()
                .map(|(k, &(x_m, y_m))| PathPoint {
                    x_m,
                    y_m,
                    speed_mps: 20.0,
                    t_s: 5.0 + 0.5 * k as f64,
                })
                .collect(),
            cubic: [0.0; 4],
            cubic_x_scale_m: 1.0,
            shared: SharedLocalPath {
                vehicle_id: 0,
                stamp_s: 5.0,
                shape: VehicleShape::default(),
                speed_mps: 20.0,
                waypoints: Vec::new(),
            },
            fallback: None,
        };
        let slow = SpeedProfile {
            points: vec![[0.0, 10.0]],
        };
        let retimed = plan.with_speed_profile(&slow);
        for (k, p) in retimed.path.iter().enumerate() {
            assert_eq!((p.x_m, p.y_m), points[k]);
            assert_eq!(p.speed_mps, 10.0);
            assert!((p.t_s - (5.0 + k as f64)).abs() < 1e-12);
        }
        assert_eq!(retimed.shared.waypoints.len(), 4);
        assert!((retimed.shared.waypoints[3].t_s - 8.0).abs() < 1e-12);
    }

    /// A standstill is a valid profile: speeds 0 while it stands, and the path is reached when
    /// the profile starts (the distance under the profile), never before; a profile that ends
    /// standing gives finite times.
    #[test]
    fn a_standstill_profile_is_timed_by_the_distance_it_drives() {
        // Stands until 10 s, then 0 → 10 m/s at 2 m/s²: s(t) = (t − 10)² m for t in [10, 15].
        let stop = SpeedProfile {
            points: vec![[0.0, 0.0], [10.0, 0.0], [15.0, 10.0]],
        };
        stop.validate("x").unwrap();
        let path_at = |t0_s: f64| -> Vec<PathPoint> {
            let mut path: Vec<PathPoint> = (0..4)
                .map(|k| PathPoint {
                    x_m: k as f64,
                    y_m: 0.0,
                    speed_mps: 5.0,
                    t_s: t0_s,
                })
                .collect();
            retime_path(&mut path, &stop);
            path
        };
        let path = path_at(2.0);
        // The first metre, from standing: covered at 11 s, its end carries the speed at its
        // start (0: the tracker holds the car); then at the profile's speed (2 m/s at 11 s).
        assert_eq!((path[0].speed_mps, path[1].speed_mps), (0.0, 0.0));
        assert!((path[1].t_s - 11.0).abs() < 1e-9, "{path:?}");
        assert!((path[2].t_s - 11.5).abs() < 1e-9, "{path:?}");
        assert!((path[2].speed_mps - 3.0).abs() < 1e-9, "{path:?}");
        assert!((path[3].t_s - (11.5 + 1.0 / 3.0)).abs() < 1e-9, "{path:?}");
        // Just before the start the first point ahead still says stand; just after, go.
        assert_eq!(path_at(9.9)[1].speed_mps, 0.0);
        assert!((path_at(10.1)[1].speed_mps - 0.2).abs() < 1e-9);
        // Ending standing: finite, at the timing floor.
        let parked = SpeedProfile {
            points: vec![[0.0, 0.0]],
        };
        let mut path = path_at(2.0);
        retime_path(&mut path, &parked);
        for (k, p) in path.iter().enumerate() {
            assert_eq!(p.speed_mps, 0.0);
            let t_s = 2.0 + k as f64 / RETIME_SPEED_FLOOR_MPS;
            assert!((p.t_s - t_s).abs() < 1e-9, "{p:?}");
        }
    }
}
