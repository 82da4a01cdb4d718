//! Vehicle–road-edge checks of one body at one instant: contact with the upper edge and the
//! piecewise lower edge (taper included), or lying entirely beyond it.

use parry3d::math::{Pose, Vector};
use parry3d::query;
use parry3d::shape::Segment;

use super::pair_checks::local_box;
use super::{BodyState, EdgeContactEvent, EdgeState, RoadEdge, SafetyError, SafetyMonitor};

impl SafetyMonitor {
    pub(super) fn check_edges(
        &mut self,
        t_s: f64,
        previous_t_s: Option<f64>,
        body: &BodyState,
    ) -> Result<(), SafetyError> {
        let radius_m = body.bounding_radius_m();
        let (pose, cuboid) = local_box(body, body.x_m, body.y_m);
        let z_mid = (0.5 * body.height_m) as f32;
        for edge in [RoadEdge::Upper, RoadEdge::Lower] {
            // Entirely beyond the edge: the centre is off the road (and no segment touches).
            let mut contact = match edge {
                RoadEdge::Upper => body.y_m > self.road.y_upper_m(),
                RoadEdge::Lower => body.y_m < self.road.lower_edge_y_m(body.x_m),
            };
            for segment in self.edges.iter().filter(|s| s.edge == edge) {
                if contact {
                    break;
                }
                let centre = [body.x_m, body.y_m];
                if point_segment_distance_m(centre, segment.a, segment.b) > radius_m {
                    continue;
                }
                // Only the part of the edge within the bounding circle's reach can touch the
                // box; clipping to it keeps GJK's f32 tolerance at the box's scale (the whole
                // 100 m taper would blur contacts by ~5 mm).
                let Some((a, b)) = clip_segment_near(centre, radius_m, segment.a, segment.b) else {
                    continue;
                };
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
    fn clipped_segment_keeps_the_near_part() {
        let (a, b) = clip_segment_near([50.0, 1.0], 2.0, [0.0, 0.0], [100.0, 0.0]).unwrap();
        assert_eq!((a, b), ([48.0, 0.0], [52.0, 0.0]));
        let (a, b) = clip_segment_near([99.0, 1.0], 2.0, [0.0, 0.0], [100.0, 0.0]).unwrap();
        assert_eq!((a, b), ([97.0, 0.0], [100.0, 0.0]));
        assert!(clip_segment_near([110.0, 0.0], 2.0, [0.0, 0.0], [100.0, 0.0]).is_none());
    }
}
