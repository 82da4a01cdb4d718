//! The road made of lanes: building and checking it from its description, and the queries on
//! it (which lanes hold a point, the nearest lane, the drivable area).

use std::collections::BTreeMap;
use std::f64::consts::PI;

use rstar::primitives::{GeomWithData, Line, Rectangle};
use rstar::{AABB, RTree, RTreeObject};

use super::error::LaneError;
use super::lane::{Lane, Side};
use super::polyline::FramePoint;
use super::spec::{LaneId, LaneRoadSpec, LaneTolerances};

/// A piece of the drivable area's outer boundary (a wall for the planners' edge term and for
/// barriers): a polyline in world coordinates (m), in the direction of travel along lane bounds
/// and from right to left across a lane's closed end.
#[derive(Clone, Debug, PartialEq)]
pub struct OuterEdge {
    /// The vertices (m).
    pub polyline_m: Vec<[f64; 2]>,
}

/// A divider between two same-direction lanes side by side (the lane-divider term of Eq. 2):
/// the stretch of the right lane's left bound that the left lane covers.
#[derive(Clone, Debug, PartialEq)]
pub struct Divider {
    /// The lane on the left of the divider.
    pub left_lane: LaneId,
    /// The lane on the right of the divider.
    pub right_lane: LaneId,
    /// The divider's vertices (world, m), in the direction of travel.
    pub polyline_m: Vec<[f64; 2]>,
    /// Where along the lane it was taken from (s range, m): the right lane's left bound, or the
    /// left lane's right bound when only the left lane names the neighbour.
    pub s_range_m: [f64; 2],
}

/// The end of a lane without successors.
#[derive(Clone, Debug, PartialEq)]
pub struct LaneEnd {
    /// The lane.
    pub lane: LaneId,
    /// Where it ends (its length, m).
    pub s_m: f64,
    /// True if the lane ends while a neighbouring lane goes on (a lane drop or an acceleration
    /// lane): its end is closed by an edge across it. False at the road's end (open).
    pub closed: bool,
    /// The edge across the end, from the right bound to the left bound (world, m); of zero
    /// length at the tip of a taper.
    pub edge_m: [[f64; 2]; 2],
}

/// A point's place in one lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LaneHit {
    /// The lane.
    pub lane: LaneId,
    /// The point in the lane's frame.
    pub frame: FramePoint,
    /// How far the point lies outside the lane in its frame (0 inside, m).
    pub excess_m: f64,
}

/// Gaps between lanes narrower than this are closed (m): two polylines approximating one curve
/// with vertices at different places differ by up to the chord's sagitta c²/(8R) (0.4 mm for
/// 1 m chords on a 300 m radius), so a bound shared in the data may leave a sliver, or bounds
/// may overlap by as much. A point within this of a lane and farther than this from every outer
/// edge counts as drivable; an outer edge is a bound with no lane within this beyond it.
/// (The road's open start and end are no edges, so a point up to this beyond them, between the
/// side edges, counts as drivable too.)
pub const SLIVER_M: f64 = 5e-3;

type LaneBox = GeomWithData<Rectangle<[f64; 2]>, usize>;
type EdgeSegment = GeomWithData<Line<[f64; 2]>, usize>;

/// A road made of lanes: the union of its lanes is the drivable area.
#[derive(Clone, Debug)]
pub struct LaneRoad {
    pub(crate) lanes: Vec<Lane>,
    pub(crate) by_id: BTreeMap<LaneId, usize>,
    pub(crate) tolerances: LaneTolerances,
    pub(crate) lane_boxes: RTree<LaneBox>,
    /// Local origin of the edge index (the first lane's first vertex).
    pub(crate) origin_m: [f64; 2],
    pub(crate) outer_edges: Vec<OuterEdge>,
    pub(crate) edge_tree: RTree<EdgeSegment>,
    pub(crate) dividers: Vec<Divider>,
    pub(crate) lane_ends: Vec<LaneEnd>,
}

fn check_tolerances(t: &LaneTolerances) -> Result<(), LaneError> {
    let bad = |field, value, reason| {
        Err(LaneError::BadTolerance {
            field,
            value,
            reason,
        })
    };
    if !(t.vertex_merge_m.is_finite() && (0.0..=1.0).contains(&t.vertex_merge_m)) {
        return bad("vertex_merge_m", t.vertex_merge_m, "must lie in [0, 1] m");
    }
    if !(t.link_m.is_finite() && t.link_m > 0.0 && t.link_m <= 5.0) {
        return bad("link_m", t.link_m, "must lie in (0, 5] m");
    }
    if !(t.smoothing_half_window_m.is_finite()
        && (0.0..=100.0).contains(&t.smoothing_half_window_m))
    {
        return bad(
            "smoothing_half_window_m",
            t.smoothing_half_window_m,
            "must lie in [0, 100] m",
        );
    }
    Ok(())
}

impl LaneRoad {
    /// Builds the road, or refuses inconsistent data naming the lane and the field.
    pub fn new(spec: &LaneRoadSpec) -> Result<Self, LaneError> {
        check_tolerances(&spec.tolerances)?;
        if spec.lanes.is_empty() {
            return Err(LaneError::NoLanes);
        }
        let tol = spec.tolerances.clone();
        let mut lanes = Vec::with_capacity(spec.lanes.len());
        let mut by_id = BTreeMap::new();
        for (i, ls) in spec.lanes.iter().enumerate() {
            if by_id.insert(ls.id, i).is_some() {
                return Err(LaneError::DuplicateId { lane: ls.id });
            }
            lanes.push(Lane::new(ls, &tol)?);
        }
        // Links name existing lanes other than the lane itself.
        for l in &lanes {
            let single = [("left", l.left), ("right", l.right)];
            let lists = [
                ("successors", &l.successors),
                ("predecessors", &l.predecessors),
            ];
            let all = single
                .iter()
                .filter_map(|(f, t)| t.map(|t| (*f, t)))
                .chain(lists.iter().flat_map(|(f, ts)| ts.iter().map(|t| (*f, *t))));
            for (field, target) in all {
                if target == l.id {
                    return Err(LaneError::SelfLink { lane: l.id, field });
                }
                if !by_id.contains_key(&target) {
                    return Err(LaneError::UnknownLink {
                        lane: l.id,
                        field,
                        target,
                    });
                }
            }
        }
        let mut road = Self {
            lanes,
            by_id,
            tolerances: tol,
            lane_boxes: RTree::new(),
            origin_m: [0.0, 0.0],
            outer_edges: Vec::new(),
            edge_tree: RTree::new(),
            dividers: Vec::new(),
            lane_ends: Vec::new(),
        };
        road.check_joins()?;
        road.check_neighbours()?;
        road.complete_links();
        road.origin_m = road.lanes[0].centreline.origin_m();
        road.lane_boxes = RTree::bulk_load(
            road.lanes
                .iter()
                .enumerate()
                .map(|(i, l)| {
                    let [lo, hi] = l.centreline.bounding_box_m();
                    let reach = l
                        .left_d_m
                        .iter()
                        .chain(&l.right_d_m)
                        .fold(0.0_f64, |a, d| a.max(d.abs()))
                        * l.centreline.max_normal_length()
                        + 1.0;
                    GeomWithData::new(
                        Rectangle::from_corners(
                            [lo[0] - reach, lo[1] - reach],
                            [hi[0] + reach, hi[1] + reach],
                        ),
                        i,
                    )
                })
                .collect(),
        );
        road.build_drivable_area();
        Ok(road)
    }

    /// Every successor link (as given on either side) joins the upstream lane's end to the
    /// downstream lane's start cross-section within `tolerances.link_m`.
    fn check_joins(&self) -> Result<(), LaneError> {
        let tol = self.tolerances.link_m;
        for l in &self.lanes {
            let links = l
                .successors
                .iter()
                .map(|s| ("successors", l.id, *s))
                .chain(l.predecessors.iter().map(|p| ("predecessors", *p, l.id)));
            for (field, from, to) in links {
                let (f, t) = (&self.lanes[self.by_id[&from]], &self.lanes[self.by_id[&to]]);
                let end = f.point(f.length_m(), 0.0);
                let fp = t.project(end);
                let lateral = (fp.d_m - t.left_d_m(0.0))
                    .max(t.right_d_m(0.0) - fp.d_m)
                    .max(0.0);
                let gap_m = fp.s_m.abs().max(lateral);
                if gap_m > tol {
                    return Err(LaneError::LinkDoesNotMeet {
                        lane: l.id,
                        field,
                        from,
                        to,
                        gap_m,
                        tolerance_m: tol,
                    });
                }
            }
        }
        Ok(())
    }

    /// A neighbour's facing bound meets the lane's bound somewhere, in the same direction.
    fn check_neighbours(&self) -> Result<(), LaneError> {
        let tol = self.tolerances.link_m;
        for l in &self.lanes {
            for (side, other_side, field, other_name) in [
                (Side::Left, Side::Right, "left", "right"),
                (Side::Right, Side::Left, "right", "left"),
            ] {
                let Some(nid) = l.neighbour(side) else {
                    continue;
                };
                let nb = &self.lanes[self.by_id[&nid]];
                let vs = l.centreline.vertex_s_m();
                let mut samples: Vec<f64> = vs.to_vec();
                samples.extend(vs.windows(2).map(|w| 0.5 * (w[0] + w[1])));
                samples.extend(
                    nb.bound_polyline(other_side)
                        .iter()
                        .map(|p| l.project(*p).s_m)
                        .filter(|s| (0.0..=l.length_m()).contains(s)),
                );
                let beside = samples.iter().any(|&s| {
                    let b = l.point(s, l.bound_d_m(side, s));
                    let fp = nb.project(b);
                    fp.s_m >= -tol
                        && fp.s_m <= nb.length_m() + tol
                        && (fp.d_m - nb.bound_d_m(other_side, fp.s_m)).abs() <= tol
                        && crate::angle::angle_between_rad(l.heading_rad(s), nb.heading_rad(fp.s_m))
                            < 0.5 * PI
                });
                if !beside {
                    return Err(LaneError::NeighbourNotBeside {
                        lane: l.id,
                        field,
                        neighbour: nid,
                        other_side: other_name,
                        tolerance_m: tol,
                    });
                }
            }
        }
        Ok(())
    }

    /// A link given on one side only is added on the other.
    fn complete_links(&mut self) {
        let mut pairs = Vec::new();
        for l in &self.lanes {
            pairs.extend(l.successors.iter().map(|s| (l.id, *s)));
            pairs.extend(l.predecessors.iter().map(|p| (*p, l.id)));
        }
        for (from, to) in pairs {
            let (fi, ti) = (self.by_id[&from], self.by_id[&to]);
            if !self.lanes[fi].successors.contains(&to) {
                self.lanes[fi].successors.push(to);
            }
            if !self.lanes[ti].predecessors.contains(&from) {
                self.lanes[ti].predecessors.push(from);
            }
        }
    }

    /// The lanes, in the order of the description.
    pub fn lanes(&self) -> &[Lane] {
        &self.lanes
    }

    /// A lane by id.
    pub fn lane(&self, id: LaneId) -> Option<&Lane> {
        self.by_id.get(&id).map(|&i| &self.lanes[i])
    }

    /// The tolerances the road was built with.
    pub fn tolerances(&self) -> &LaneTolerances {
        &self.tolerances
    }

    /// Indices of the lanes whose padded box holds the point, in description order.
    pub(crate) fn candidate_lanes(&self, p_m: [f64; 2]) -> Vec<usize> {
        let mut c: Vec<usize> = self
            .lane_boxes
            .locate_all_at_point(p_m)
            .map(|b| b.data)
            .collect();
        c.sort_unstable();
        c
    }

    /// Index of the first lane other than `exclude` that holds the point.
    pub(crate) fn other_lane_at(&self, p_m: [f64; 2], exclude: usize) -> Option<usize> {
        self.candidate_lanes(p_m)
            .into_iter()
            .find(|&i| i != exclude && self.lanes[i].contains(p_m))
    }

    /// The lanes holding the point (bounds included), in description order.
    pub fn lanes_at(&self, p_m: [f64; 2]) -> Vec<LaneHit> {
        self.candidate_lanes(p_m)
            .into_iter()
            .filter_map(|i| {
                let l = &self.lanes[i];
                let frame = l.project(p_m);
                l.contains_frame(frame).then_some(LaneHit {
                    lane: l.id,
                    frame,
                    excess_m: 0.0,
                })
            })
            .collect()
    }

    /// True if the point lies on the drivable area: in a lane (bounds included), or in a sliver
    /// between lanes (within [`SLIVER_M`] of a lane and farther than that from every outer edge).
    pub fn is_drivable(&self, p_m: [f64; 2]) -> bool {
        let mut near = false;
        for i in self.candidate_lanes(p_m) {
            let l = &self.lanes[i];
            let fp = l.project(p_m);
            if l.contains_frame(fp) {
                return true;
            }
            near |= l.frame_excess_m(fp) <= SLIVER_M;
        }
        near && self
            .nearest_outer_edge_point(p_m)
            .is_none_or(|(_, d)| d > SLIVER_M)
    }

    /// The lane nearest to the point, by the frame excess ([`Lane::frame_excess_m`]; 0 inside,
    /// ties to the smaller |d|, then to description order).
    pub fn nearest_lane(&self, p_m: [f64; 2]) -> LaneHit {
        let mut best: Option<LaneHit> = None;
        for (i, l) in self.lanes.iter().enumerate() {
            let frame = l.project(p_m);
            let hit = LaneHit {
                lane: self.lanes[i].id,
                frame,
                excess_m: l.frame_excess_m(frame),
            };
            let better = match best {
                None => true,
                Some(b) => {
                    hit.excess_m < b.excess_m
                        || (hit.excess_m == b.excess_m && frame.d_m.abs() < b.frame.d_m.abs())
                }
            };
            if better {
                best = Some(hit);
            }
        }
        // `new` refuses a road without lanes, so `best` is set; fall back to a harmless value.
        best.unwrap_or(LaneHit {
            lane: LaneId(0),
            frame: FramePoint { s_m: 0.0, d_m: 0.0 },
            excess_m: f64::INFINITY,
        })
    }

    /// The nearest point of the drivable area's outer boundary and its distance (m); `None` on a
    /// road without outer edges.
    pub fn nearest_outer_edge_point(&self, p_m: [f64; 2]) -> Option<([f64; 2], f64)> {
        let q = [p_m[0] - self.origin_m[0], p_m[1] - self.origin_m[1]];
        let seg = self.edge_tree.nearest_neighbor(q)?;
        let (a, b) = (seg.geom().from, seg.geom().to);
        let e = [b[0] - a[0], b[1] - a[1]];
        let l2 = e[0] * e[0] + e[1] * e[1];
        let t = if l2 > 0.0 {
            (((q[0] - a[0]) * e[0] + (q[1] - a[1]) * e[1]) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let foot = [a[0] + t * e[0], a[1] + t * e[1]];
        let dist = (q[0] - foot[0]).hypot(q[1] - foot[1]);
        Some((
            [foot[0] + self.origin_m[0], foot[1] + self.origin_m[1]],
            dist,
        ))
    }

    /// Signed distance to the drivable area's outer boundary (m): positive on the drivable
    /// area, negative off it (the edge term of Eq. 3 is a function of it). Bounds shared with or
    /// lying inside a neighbouring lane are not part of that boundary; a closed lane end is.
    /// The road's own start and end are open (no edge): there the distance is to the side edges.
    pub fn signed_distance_to_edge_m(&self, p_m: [f64; 2]) -> f64 {
        let d = self
            .nearest_outer_edge_point(p_m)
            .map_or(f64::INFINITY, |(_, d)| d);
        if self.is_drivable(p_m) { d } else { -d }
    }

    /// The drivable area's outer edges (chained polylines).
    pub fn outer_edges(&self) -> &[OuterEdge] {
        &self.outer_edges
    }

    /// The dividers between same-direction lanes side by side.
    pub fn dividers(&self) -> &[Divider] {
        &self.dividers
    }

    /// The ends of the lanes without successors (open at the road's end, closed where a lane
    /// ends beside one that goes on).
    pub fn lane_ends(&self) -> &[LaneEnd] {
        &self.lane_ends
    }

    /// The end of one lane, if it has no successor.
    pub fn lane_end(&self, id: LaneId) -> Option<&LaneEnd> {
        self.lane_ends.iter().find(|e| e.lane == id)
    }

    /// How far ahead (m, along the centrelines) the lane holding `s_m` on lane `id` must be
    /// left: following the successors, every branch ends closed ([`LaneEnd::closed`]), and this
    /// is the longest such branch. `None` if some branch goes on to the road's open end (or
    /// loops), or the lane does not exist. For the lane rule "a lane that ends ahead is never a
    /// target" (issue 21, item 4).
    pub fn distance_to_closed_end_m(&self, id: LaneId, s_m: f64) -> Option<f64> {
        let mut on_path = Vec::new();
        self.closed_end_from(id, &mut on_path)
            .map(|d| d - s_m.clamp(0.0, self.lane(id).map_or(0.0, Lane::length_m)))
    }

    /// Distance from the start of lane `id` to its closed end, as above.
    fn closed_end_from(&self, id: LaneId, on_path: &mut Vec<LaneId>) -> Option<f64> {
        if on_path.contains(&id) {
            return None;
        }
        let lane = self.lane(id)?;
        if lane.successors.is_empty() {
            return self
                .lane_end(id)
                .filter(|e| e.closed)
                .map(|_| lane.length_m());
        }
        on_path.push(id);
        let mut longest: f64 = 0.0;
        for next in &lane.successors {
            let d = self.closed_end_from(*next, on_path);
            match d {
                Some(d) => longest = longest.max(d),
                None => {
                    on_path.pop();
                    return None;
                }
            }
        }
        on_path.pop();
        Some(lane.length_m() + longest)
    }

    /// Index tree query used by the drivable-area builder: lanes whose boxes overlap lane `i`'s.
    pub(crate) fn overlapping_lanes(&self, i: usize) -> Vec<usize> {
        let Some(b) = self.lane_boxes.iter().find(|b| b.data == i) else {
            return Vec::new();
        };
        let env: AABB<[f64; 2]> = b.geom().envelope();
        let mut c: Vec<usize> = self
            .lane_boxes
            .locate_in_envelope_intersecting(env)
            .map(|b| b.data)
            .filter(|&j| j != i)
            .collect();
        c.sort_unstable();
        c
    }
}
