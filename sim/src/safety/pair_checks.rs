//! Vehicle–vehicle checks of one pair at one instant: intersection, exact gap, TTC by shape
//! cast, with the bounding-circle culling of the module doc.

use parry3d::math::{Pose, Vector};
use parry3d::query::{self, ShapeCastOptions, ShapeCastStatus};
use parry3d::shape::Cuboid;

use super::{
    BodyState, CollisionEvent, PairInstant, PairState, SafetyError, SafetyMonitor, pair_bounds,
};

impl SafetyMonitor {
    pub(super) fn check_pair(
        &mut self,
        t_s: f64,
        previous_t_s: Option<f64>,
        dt_s: f64,
        a: &BodyState,
        b: &BodyState,
    ) -> Result<(), SafetyError> {
        let ttc_horizon_s = self.params.ttc_horizon_s;
        let ttc_threshold_s = self.params.ttc_threshold_s;
        let (gap_lower_bound_m, relative_speed_mps) = pair_bounds(a, b);

        let key = (a.id, b.id);
        let state = self.pairs.get(&key).copied();
        // Continuity with the previous instant: only if the pair was visited then.
        let continuing = state.filter(|s| previous_t_s == Some(s.last_seen_t_s));

        // Both boxes expressed around the pair's midpoint (see "Precision").
        let mid_x_m = 0.5 * (a.x_m + b.x_m);
        let mid_y_m = 0.5 * (a.y_m + b.y_m);
        let (pose_a, box_a) = local_box(a, mid_x_m, mid_y_m);
        let (pose_b, box_b) = local_box(b, mid_x_m, mid_y_m);

        let tolerance_m = self.params.contact_tolerance_m;
        let overlapping = if gap_lower_bound_m <= 0.0 {
            query::intersection_test(&pose_a, &box_a, &pose_b, &box_b)
                .map_err(|e| SafetyError::Unsupported(format!("{e:?}")))?
                .intersecting
        } else {
            false
        };

        let current_min_gap_m = state.map_or(f64::INFINITY, |s| s.min_gap_m);
        let (gap_m, gap_is_lower_bound) = if overlapping {
            (0.0, false)
        } else if gap_lower_bound_m < current_min_gap_m || gap_lower_bound_m <= tolerance_m {
            let d = query::distance(&pose_a, &box_a, &pose_b, &box_b)
                .map_err(|e| SafetyError::Unsupported(format!("{e:?}")))?
                .distance;
            (f64::from(d), false)
        } else {
            (gap_lower_bound_m, true)
        };
        // Touching within the tolerance is contact (see `contact_tolerance_m`).
        let intersecting = overlapping || (!gap_is_lower_bound && gap_m <= tolerance_m);

        let ttc_s = if intersecting {
            Some(0.0)
        } else if gap_lower_bound_m > relative_speed_mps * ttc_horizon_s {
            None
        } else {
            let options = ShapeCastOptions {
                max_time_of_impact: ttc_horizon_s as f32,
                target_distance: 0.0,
                stop_at_penetration: true,
                compute_impact_geometry_on_penetration: false,
            };
            let hit = query::cast_shapes(
                &pose_a,
                Vector::new(a.vx_mps as f32, a.vy_mps as f32, 0.0),
                &box_a,
                &pose_b,
                Vector::new(b.vx_mps as f32, b.vy_mps as f32, 0.0),
                &box_b,
                options,
            )
            .map_err(|e| SafetyError::Unsupported(format!("{e:?}")))?;
            match hit {
                Some(hit) => {
                    if matches!(
                        hit.status,
                        ShapeCastStatus::OutOfIterations | ShapeCastStatus::Failed
                    ) {
                        self.ttc_not_converged += 1;
                    }
                    Some(f64::from(hit.time_of_impact))
                }
                None => None,
            }
        };

        let was_in_contact = continuing.is_some_and(|s| s.in_contact);
        let mut s = state.unwrap_or(PairState {
            last_seen_t_s: t_s,
            in_contact: false,
            ttc_at_last_seen_s: None,
            min_gap_m: f64::INFINITY,
            t_min_gap_s: t_s,
            min_ttc_s: None,
            t_min_ttc_s: None,
            tet_s: 0.0,
            collisions: 0,
        });

        if intersecting && !was_in_contact {
            // The TTC seen at the previous instant dates the first contact, if it fell
            // inside the interval since then.
            let t_contact_estimate_s = continuing
                .and_then(|c| c.ttc_at_last_seen_s.map(|ttc| c.last_seen_t_s + ttc))
                .filter(|t| *t <= t_s + 1e-9);
            s.collisions += 1;
            self.report.new_collisions.push(CollisionEvent {
                t_s,
                id_a: a.id,
                id_b: b.id,
                t_contact_estimate_s,
                relative_speed_mps,
                caused_by_replay: self.caused_by_replay(a, b),
            });
        }
        if !gap_is_lower_bound && gap_m < s.min_gap_m {
            s.min_gap_m = gap_m;
            s.t_min_gap_s = t_s;
        }
        if let Some(ttc) = ttc_s {
            if s.min_ttc_s.is_none_or(|m| ttc < m) {
                s.min_ttc_s = Some(ttc);
                s.t_min_ttc_s = Some(t_s);
            }
            if ttc < ttc_threshold_s {
                s.tet_s += dt_s;
            }
            if self.report.min_ttc_s.is_none_or(|m| ttc < m) {
                self.report.min_ttc_s = Some(ttc);
            }
        }
        s.in_contact = intersecting;
        s.ttc_at_last_seen_s = ttc_s;
        s.last_seen_t_s = t_s;
        self.pairs.insert(key, s);

        self.report.pairs.push(PairInstant {
            id_a: a.id,
            id_b: b.id,
            intersecting,
            gap_m,
            gap_is_lower_bound,
            ttc_s,
        });
        Ok(())
    }
}

/// The body's cuboid and its pose relative to the origin (`origin_x_m`, `origin_y_m`, 0):
/// resting on the road plane, rotated by the yaw about +Z.
pub(super) fn local_box(body: &BodyState, origin_x_m: f64, origin_y_m: f64) -> (Pose, Cuboid) {
    let half = Vector::new(
        (0.5 * body.length_m) as f32,
        (0.5 * body.width_m) as f32,
        (0.5 * body.height_m) as f32,
    );
    let pose = Pose::new(
        Vector::new(
            (body.x_m - origin_x_m) as f32,
            (body.y_m - origin_y_m) as f32,
            half.z,
        ),
        Vector::new(0.0, 0.0, body.yaw_rad as f32),
    );
    (pose, Cuboid::new(half))
}
