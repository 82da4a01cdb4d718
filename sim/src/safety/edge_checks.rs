//! Vehicle–road-edge checks of one body at one instant: contact with an outer edge of the
//! drivable area (left/upper or right/lower, closed lane ends and the merge taper included),
//! or lying entirely beyond it.

use parry3d::math::{Pose, Vector};
use parry3d::query;
use parry3d::shape::Segment;

use super::pair_checks::local_box;
use super::{
    BodyState, EdgeChunk, EdgeContactEvent, EdgeState, RoadEdge, SafetyError, SafetyMonitor,
};

/// Distance from `p` to the axis-aligned box `[lo, hi]` (0 inside).
fn box_distance_m(p: [f64; 2], lo: [f64; 2], hi: [f64; 2]) -> f64 {
    let dx = (lo[0] - p[0]).max(p[0] - hi[0]).max(0.0);
    let dy = (lo[1] - p[1]).max(p[1] - hi[1]).max(0.0);
    dx.hypot(dy)
}

impl SafetyMonitor {
    /// The edge piece nearest to `p` (index into `edges`), if the road has edges.
    fn nearest_edge_segment(&self, p: [f64; 2]) -> Option<usize> {
        let mut best: Option<(usize, f64)> = None;
        for chunk in &self.edge_chunks {
            let EdgeChunk { lo, hi, segments } = chunk;
            if best.is_some_and(|(_, d)| box_distance_m(p, *lo, *hi) >= d) {
                continue;
            }
            for k in segments.clone() {
                let seg = &self.edges[k];
                let d = point_segment_distance_m(p, seg.a, seg.b);
                if best.is_none_or(|(_, bd)| d < bd) {
                    best = Some((k, d));
                }
            }
        }
        best.map(|(k, _)| k)
    }

    /// True if `p` lies off the drivable area beyond the edge piece nearest to it (on the side
    /// away from the road; beyond the road's open start or end it is not).
    fn beyond_edge(&self, p: [f64; 2]) -> Option<RoadEdge> {
        let seg = self.edges[self.nearest_edge_segment(p)?];
        let cross =
            (seg.b[0] - seg.a[0]) * (p[1] - seg.a[1]) - (seg.b[1] - seg.a[1]) * (p[0] - seg.a[0]);
        // Upper (left-hand) pieces have the road on their right, lower ones on their left.
        let outside = match seg.edge {
            RoadEdge::Upper => cross > 0.0,
            RoadEdge::Lower => cross < 0.0,
        };
        (outside && !self.lanes.is_drivable(p)).then_some(seg.edge)
    }

    pub(super) fn check_edges(
        &mut self,
        t_s: f64,
        previous_t_s: Option<f64>,
        body: &BodyState,
    ) -> Result<(), SafetyError> {
        let radius_m = body.bounding_radius_m();
        let (pose, cuboid) = local_box(body, body.x_m, body.y_m);
        let z_mid = (0.5 * body.height_m) as f32;
        let centre = [body.x_m, body.y_m];
        // Entirely beyond an edge: the centre is off the road, beyond its nearest edge piece.
        let beyond = self.beyond_edge(centre);
        for edge in [RoadEdge::Upper, RoadEdge::Lower] {
            let mut contact = beyond == Some(edge);
            let near_chunks = self
                .edge_chunks
                .iter()
                .filter(|c| box_distance_m(centre, c.lo, c.hi) <= radius_m);
            for k in near_chunks.flat_map(|c| c.segments.clone()) {
                let segment = self.edges[k];
                if contact {
                    break;
                }
                if segment.edge != edge
                    || point_segment_distance_m(centre, segment.a, segment.b) > radius_m
                {
                    continue;
                }
                // Only the part of the edge within the bounding circle's reach can touch the
                // box; clipping to it keeps GJK's f32 tolerance at the box's scale (the whole
                // 100 m taper would blur contacts by ~5 mm).
                let Some((a, b)) = clip_segment_near(centre, radius_m, segment.a, segment.b) else {
                    continue;
                };
                // No parry query where the box is, with a margin, farther from the segment's
                // line than the contact tolerance: the outcome is "no contact" either way.
                if box_line_gap_lower_bound_m(body, a, b)
                    > self.params.contact_tolerance_m + LINE_CULL_MARGIN_M
                {
                    continue;
                }
                let shape = Segment::new(
                    Vector::new((a[0] - body.x_m) as f32, (a[1] - body.y_m) as f32, z_mid),
                    Vector::new((b[0] - body.x_m) as f32, (b[1] - body.y_m) as f32, z_mid),
                );
                contact = if self.params.contact_tolerance_m > 0.0 {
                    let d = query::distance(&pose, &cuboid, &Pose::identity(), &shape)
                        .map_err(|e| SafetyError::Unsupported(format!("{e:?}")))?
                        .distance;
                    f64::from(d) <= self.params.contact_tolerance_m
                } else {
                    query::intersection_test(&pose, &cuboid, &Pose::identity(), &shape)
                        .map_err(|e| SafetyError::Unsupported(format!("{e:?}")))?
                        .intersecting
                };
            }

            let key = (body.id, edge);
            let was_in_contact = self
                .edge_states
                .get(&key)
                .is_some_and(|s| s.in_contact && previous_t_s == Some(s.last_seen_t_s));
            if contact && !was_in_contact {
                self.report.new_edge_contacts.push(EdgeContactEvent {
                    t_s,
                    id: body.id,
                    edge,
                });
            }
            self.edge_states.insert(
                key,
                EdgeState {
                    last_seen_t_s: t_s,
                    in_contact: contact,
                },
            );
        }
        Ok(())
    }
}

/// The part of segment `a`–`b` whose projection on the segment's line lies within `radius_m`
/// of the projection of `p` (a superset of the points within `radius_m` of `p`); `None` if
/// that part is empty.
fn clip_segment_near(
    p: [f64; 2],
    radius_m: f64,
    a: [f64; 2],
    b: [f64; 2],
) -> Option<([f64; 2], [f64; 2])> {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let length_m = ab[0].hypot(ab[1]);
    if length_m <= 0.0 {
        return Some((a, b));
    }
    let d = [ab[0] / length_m, ab[1] / length_m];
    let u_p = (p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1];
    let u0 = (u_p - radius_m).max(0.0);
    let u1 = (u_p + radius_m).min(length_m);
    (u0 <= u1).then(|| {
        (
            [a[0] + u0 * d[0], a[1] + u0 * d[1]],
            [a[0] + u1 * d[0], a[1] + u1 * d[1]],
        )
    })
}

/// Margin (m) by which the box must clear an edge's line before the exact query is skipped:
/// far above parry's f32 error at a box's scale (micrometres), far below any contact tolerance
/// that matters, so skipping never changes an outcome.
const LINE_CULL_MARGIN_M: f64 = 1e-3;

/// A lower bound of the distance (m) from the body's box (in the road plane) to the segment
/// `a`–`b`: its distance to the segment's line, |n·(c − a)| minus the box's half-extent along
/// the line's normal n, at least 0. For a degenerate segment, 0 (no bound).
fn box_line_gap_lower_bound_m(body: &BodyState, a: [f64; 2], b: [f64; 2]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let length_m = ab[0].hypot(ab[1]);
    if length_m <= 0.0 {
        return 0.0;
    }
    let n = [-ab[1] / length_m, ab[0] / length_m];
    let extent_m = body.half_extent_along_m(n);
    let centre_m = (n[0] * (body.x_m - a[0]) + n[1] * (body.y_m - a[1])).abs();
    (centre_m - extent_m).max(0.0)
}

/// Euclidean distance from point `p` to the segment `a`–`b` (closed form).
fn point_segment_distance_m(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let ap = [p[0] - a[0], p[1] - a[1]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    let u = if len2 > 0.0 {
        ((ap[0] * ab[0] + ap[1] * ab[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (ap[0] - u * ab[0]).hypot(ap[1] - u * ab[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_segment_distance_matches_closed_forms() {
        // Perpendicular foot inside the segment.
        assert!((point_segment_distance_m([1.0, 2.0], [0.0, 0.0], [4.0, 0.0]) - 2.0).abs() < 1e-12);
        // Beyond the end: distance to the end point.
        assert!((point_segment_distance_m([7.0, 4.0], [0.0, 0.0], [4.0, 0.0]) - 5.0).abs() < 1e-12);
        // Degenerate segment.
        assert!((point_segment_distance_m([3.0, 4.0], [0.0, 0.0], [0.0, 0.0]) - 5.0).abs() < 1e-12);
    }

    #[test]
    fn box_line_bound_is_the_gap_to_the_line() {
        let body = |x_m: f64, y_m: f64, yaw_rad: f64| {
            BodyState::standing(0, [x_m, y_m, yaw_rad], [4.0, 2.0, 1.5])
        };
        // Along the line, 3 m from it: 3 − 1 (half-width).
        let lb = box_line_gap_lower_bound_m(&body(0.0, 3.0, 0.0), [-10.0, 0.0], [10.0, 0.0]);
        assert!((lb - 2.0).abs() < 1e-12, "{lb}");
        // Across it: 3 − 2 (half-length); the side it lies on does not matter.
        let lb = box_line_gap_lower_bound_m(
            &body(0.0, -3.0, std::f64::consts::FRAC_PI_2),
            [-10.0, 0.0],
            [10.0, 0.0],
        );
        assert!((lb - 1.0).abs() < 1e-12, "{lb}");
        // Turned by 45°: the corner reaches (2 + 1)/√2 towards the line.
        let lb = box_line_gap_lower_bound_m(
            &body(0.0, 3.0, std::f64::consts::FRAC_PI_4),
            [-10.0, 0.0],
            [10.0, 0.0],
        );
        assert!((lb - (3.0 - 3.0 / 2f64.sqrt())).abs() < 1e-12, "{lb}");
        // Touching or crossing: 0.
        assert_eq!(
            box_line_gap_lower_bound_m(&body(0.0, 0.5, 0.0), [-10.0, 0.0], [10.0, 0.0]),
            0.0
        );
    }

    #[test]
    fn clipped_segment_keeps_the_near_part() {
        let (a, b) = clip_segment_near([50.0, 1.0], 2.0, [0.0, 0.0], [100.0, 0.0]).unwrap();
        assert_eq!((a, b), ([48.0, 0.0], [52.0, 0.0]));
        let (a, b) = clip_segment_near([99.0, 1.0], 2.0, [0.0, 0.0], [100.0, 0.0]).unwrap();
        assert_eq!((a, b), ([97.0, 0.0], [100.0, 0.0]));
        assert!(clip_segment_near([110.0, 0.0], 2.0, [0.0, 0.0], [100.0, 0.0]).is_none());
    }
}
