//! Vehicle–vehicle checks of one pair at one instant: intersection, exact gap, TTC by shape
//! cast, with the bounding-circle culling of the module doc.

use parry3d::math::{Pose, Vector};
use parry3d::query::{self, ShapeCastOptions, ShapeCastStatus};
use parry3d::shape::Cuboid;

use std::collections::btree_map::Entry;

use super::{
    BodyState, CollisionEvent, PairBounds, PairInstant, PairState, SafetyError, SafetyMonitor,
};

/// The two boxes of a pair as parry sees them, expressed around the pair's midpoint (module
/// doc, "Precision"); built on first use, since most instants need no exact query.
struct PairBoxes<'a> {
    a: &'a BodyState,
    b: &'a BodyState,
    built: Option<[(Pose, Cuboid); 2]>,
}

impl<'a> PairBoxes<'a> {
    /// The boxes of `a` and `b`, not built yet.
    fn new(a: &'a BodyState, b: &'a BodyState) -> Self {
        Self { a, b, built: None }
    }

    /// Poses and cuboids of `a` and `b`, built on the first call.
    fn get(&mut self) -> [(Pose, Cuboid); 2] {
        let (a, b) = (self.a, self.b);
        *self.built.get_or_insert_with(|| {
            let mid_x_m = 0.5 * (a.x_m + b.x_m);
            let mid_y_m = 0.5 * (a.y_m + b.y_m);
            [
                local_box(a, mid_x_m, mid_y_m),
                local_box(b, mid_x_m, mid_y_m),
            ]
        })
    }
}

impl SafetyMonitor {
    /// Checks the followed pair (`a`, `b`) with its bounding-circle `bounds` at instant `t_s`.
    pub(super) fn check_pair(
        &mut self,
        t_s: f64,
        previous_t_s: Option<f64>,
        dt_s: f64,
        a: &BodyState,
        b: &BodyState,
        bounds: PairBounds,
    ) -> Result<(), SafetyError> {
        let ttc_horizon_s = self.params.ttc_horizon_s;
        let ttc_threshold_s = self.params.ttc_threshold_s;
        let PairBounds {
            gap_lower_bound_m,
            relative_speed_mps,
        } = bounds;
        // Pure; computed before the map entry borrows `self.pairs`.
        let caused_by_replay = self.caused_by_replay(a, b);

        let key = (a.id, b.id);
        // One look-up: the entry is read now and written at the end.
        let entry = self.pairs.entry(key);
        let state = match &entry {
            Entry::Occupied(occupied) => Some(*occupied.get()),
            Entry::Vacant(_) => None,
        };
        // Continuity with the previous instant: only if the pair was visited then.
        let continuing = state.filter(|s| previous_t_s == Some(s.last_seen_t_s));

        let mut boxes = PairBoxes::new(a, b);

        let tolerance_m = self.params.contact_tolerance_m;
        let overlapping = if gap_lower_bound_m <= 0.0 {
            let [(pose_a, box_a), (pose_b, box_b)] = boxes.get();
            query::intersection_test(&pose_a, &box_a, &pose_b, &box_b)
                .map_err(|e| SafetyError::Unsupported(format!("{e:?}")))?
                .intersecting
        } else {
            false
        };

        let current_min_gap_m = state.map_or(f64::INFINITY, |s| s.min_gap_m);
        let (gap_m, gap_is_lower_bound) = if overlapping {
            (0.0, false)
        } else if (gap_lower_bound_m < current_min_gap_m
            && centre_axis_gap_lower_bound_m(a, b) <= current_min_gap_m + AXIS_CULL_MARGIN_M)
            || gap_lower_bound_m <= tolerance_m
        {
            let [(pose_a, box_a), (pose_b, box_b)] = boxes.get();
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
            let [(pose_a, box_a), (pose_b, box_b)] = boxes.get();
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
                caused_by_replay,
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
        match entry {
            Entry::Occupied(mut occupied) => *occupied.get_mut() = s,
            Entry::Vacant(vacant) => {
                vacant.insert(s);
            }
        }

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

/// Margin (m) by which the boxes must clear the pair's smallest gap so far before the exact
/// gap query is skipped: far above parry's f32 error at a box's scale (micrometres), so a
/// skipped query could not have lowered that gap, and no result changes.
const AXIS_CULL_MARGIN_M: f64 = 1e-4;

/// A lower bound of the gap (m) between the footprints of `a` and `b`: their separation along
/// the line through their centres (a separating-axis bound), the centre distance less each
/// box's half-extent along it, at least 0. Tighter than the bounding circles' for cars in
/// line (exact for two aligned boxes one behind the other), so a pair following at a steady
/// gap needs no exact query at every instant. Both boxes rest on the road plane, so their
/// gap in 3-D is their footprints' gap.
fn centre_axis_gap_lower_bound_m(a: &BodyState, b: &BodyState) -> f64 {
    let d = [b.x_m - a.x_m, b.y_m - a.y_m];
    let distance_m = d[0].hypot(d[1]);
    if distance_m <= 0.0 {
        return 0.0;
    }
    let u = [d[0] / distance_m, d[1] / distance_m];
    (distance_m - a.half_extent_along_m(u) - b.half_extent_along_m(u)).max(0.0)
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

#[cfg(test)]
mod tests {
    use super::*;

    fn body(x_m: f64, y_m: f64, yaw_rad: f64) -> BodyState {
        BodyState::standing(0, [x_m, y_m, yaw_rad], [4.0, 2.0, 1.5])
    }

    /// parry's exact gap of the two boxes.
    fn exact_gap_m(a: &BodyState, b: &BodyState) -> f64 {
        let (pa, ba) = local_box(a, 0.0, 0.0);
        let (pb, bb) = local_box(b, 0.0, 0.0);
        f64::from(query::distance(&pa, &ba, &pb, &bb).unwrap().distance)
    }

    #[test]
    fn centre_axis_bound_is_exact_in_line_and_never_above_the_gap() {
        // One behind the other, aligned: 10 − 2 − 2.
        let lb = centre_axis_gap_lower_bound_m(&body(0.0, 0.0, 0.0), &body(10.0, 0.0, 0.0));
        assert!((lb - 6.0).abs() < 1e-12, "{lb}");
        assert!((exact_gap_m(&body(0.0, 0.0, 0.0), &body(10.0, 0.0, 0.0)) - 6.0).abs() < 1e-5);
        // Overlapping: 0.
        assert_eq!(
            centre_axis_gap_lower_bound_m(&body(0.0, 0.0, 0.0), &body(3.0, 0.5, 0.3)),
            0.0
        );
        // Any placement: at most the exact gap (parry's f32 within 1e-5 m).
        for k in 0..400 {
            let t = k as f64;
            let a = body(0.0, 0.0, 0.37 * t);
            let b = body(
                6.0 * (0.11 * t).cos() + 0.5,
                7.0 * (0.07 * t).sin(),
                0.91 * t,
            );
            let lb = centre_axis_gap_lower_bound_m(&a, &b);
            let gap = exact_gap_m(&a, &b);
            assert!(lb <= gap + 1e-5, "{k}: bound {lb} above the gap {gap}");
        }
    }
}
