//! A prescribed time → speed profile, and a plan re-timed to follow it: the prescribed-speed
//! driver takes its path from a potential-field planner and its speeds from the profile, which
//! tests the paper's causal claim ("slowing down in advance reduces the winding") without the
//! speed optimiser.

use serde::{Deserialize, Serialize};

use crate::error::PlannerError;
use crate::types::{PathPoint, Plan, SharedLocalPath};

/// Slowest speed a profile may prescribe (m/s): the speed optimiser's own v_min, so every
/// segment has a finite travel time.
pub const MIN_PROFILE_SPEED_MPS: f64 = 0.5;

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

/// Re-times `path` (its first point's time kept) to `profile`: segment k (point k to point
/// k + 1) is driven at the profile's speed at the time the path reaches point k, and the times
/// follow, t_{k+1} = t_k + Δs_k / v_k.
pub fn retime_path(path: &mut [PathPoint], profile: &SpeedProfile) {
    let n = path.len();
    for k in 0..n {
        let t_s = path[k].t_s;
        let v_mps = profile
            .speed_at(t_s)
            .clamp(MIN_PROFILE_SPEED_MPS, MAX_PROFILE_SPEED_MPS);
        path[k].speed_mps = v_mps;
        if k + 1 < n {
            let (a, b) = (path[k], path[k + 1]);
            let ds_m = (b.x_m - a.x_m).hypot(b.y_m - a.y_m);
            path[k + 1].t_s = t_s + ds_m / v_mps;
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
    use crate::types::{PathPoint, SharedLocalPath, VehicleShape};

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
            (vec![[0.0, 0.0]], "speed_profile[0] speed"),
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
}
