//! The assembly of the lane road field: [`LaneRoadGeometry`], what Eqs. 1–3 need of a
//! [`LaneRoad`] prepared once per road (each lane's frame, the dividers in their lanes' frames,
//! the outer edges with their drivable sides, which lanes end), with the lane look-ups of the
//! planner (the lane at a point, Eq. 1's target lane, a route's lanes, the lane-end rule's walls).

use std::sync::Arc;

use mergesim_types::VehicleState;
use mergesim_types::lanes::{Divider, FramePoint, Lane, LaneId, LaneRoad, Side};

use super::LANE_END_WALL_CUTOFF_M;
use crate::lane_frame::FrameJacobian;
use crate::lane_road_edges::EdgeGeometry;
use crate::lane_road_frames::{BoundOffset, FastFrame};
/// One divider prepared for Eq. 2: the lane whose bound it is, which bound, and where it holds.
#[derive(Clone, Debug)]
pub(super) struct DividerGeometry {
    /// Index into [`LaneRoad::lanes`].
    pub(super) lane: usize,
    /// The lane's bound that is the divider.
    pub(super) side: Side,
    /// s range on that lane (m); ±∞ where it reaches the road's open start or end.
    pub(super) s_range_m: [f64; 2],
    /// d_div(s), prepared.
    pub(super) offset: BoundOffset,
    /// Index of the lane to the divider's left and to its right.
    pub(super) left_lane: usize,
    pub(super) right_lane: usize,
}

/// What Eqs. 1–3 need of a [`LaneRoad`], prepared once per road: each lane's frame (straight
/// lanes in O(1)), the dividers in their lanes' frames, the outer edges with their drivable
/// sides, and which lanes end.
#[derive(Clone, Debug)]
pub struct LaneRoadGeometry {
    pub(super) road: Arc<LaneRoad>,
    pub(super) origin_m: [f64; 2],
    pub(super) frames: Vec<FastFrame>,
    pub(super) dividers: Vec<DividerGeometry>,
    pub(super) edges: Vec<EdgeGeometry>,
    /// Per lane: it ends closed beside a lane that goes on ([`LaneRoad::lane_end`]).
    pub(super) ends: Vec<bool>,
}

/// Slack on s-range ends when deciding that a divider reaches a lane's end (m).
const RANGE_END_M: f64 = 1e-9;

fn divider_geometry(road: &LaneRoad, d: &Divider) -> Option<DividerGeometry> {
    let index = |id: LaneId| road.lanes().iter().position(|l| l.id() == id);
    // As built by the road: the right lane's left bound, or the left lane's right bound when
    // only the left lane names the neighbour.
    let right = road.lane(d.right_lane)?;
    let (lane, side) = if right.left_neighbour() == Some(d.left_lane) {
        (index(d.right_lane)?, Side::Left)
    } else {
        (index(d.left_lane)?, Side::Right)
    };
    let l: &Lane = &road.lanes()[lane];
    let [mut a, mut b] = d.s_range_m;
    if a <= RANGE_END_M && l.predecessors().is_empty() {
        a = f64::NEG_INFINITY;
    }
    let open_end = l.successors().is_empty() && road.lane_end(l.id()).is_some_and(|e| !e.closed);
    if b >= l.length_m() - RANGE_END_M && open_end {
        b = f64::INFINITY;
    }
    Some(DividerGeometry {
        lane,
        side,
        s_range_m: [a, b],
        offset: BoundOffset::of(l, side),
        left_lane: index(d.left_lane)?,
        right_lane: index(d.right_lane)?,
    })
}

impl LaneRoadGeometry {
    /// Prepares the road's frames, dividers and outer edges (a copy of `road` is kept).
    pub fn new(road: &LaneRoad) -> Self {
        Self::shared(Arc::new(road.clone()))
    }

    /// Prepares a shared road.
    pub fn shared(road: Arc<LaneRoad>) -> Self {
        let origin_m = road
            .lanes()
            .first()
            .map_or([0.0, 0.0], |l| l.centreline().origin_m());
        let frames = road
            .lanes()
            .iter()
            .map(|l| FastFrame::of(l.centreline()))
            .collect();
        let dividers = road
            .dividers()
            .iter()
            .filter_map(|d| divider_geometry(&road, d))
            .collect();
        let edges = EdgeGeometry::all(&road, origin_m);
        let ends = road
            .lanes()
            .iter()
            .map(|l| road.lane_end(l.id()).is_some_and(|e| e.closed))
            .collect();
        Self {
            road,
            origin_m,
            frames,
            dividers,
            edges,
            ends,
        }
    }

    /// The road.
    pub(crate) fn road(&self) -> &LaneRoad {
        &self.road
    }

    /// The road, shared.
    pub(crate) fn shared_road(&self) -> &Arc<LaneRoad> {
        &self.road
    }

    /// Number of outer edges the edge term sums over.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// Number of dividers the divider term sums over.
    pub fn divider_count(&self) -> usize {
        self.dividers.len()
    }

    /// Signed distance to each outer edge (m, positive on the drivable side), in edge order.
    pub fn edge_distances_m(&self, x_m: f64, y_m: f64) -> Vec<f64> {
        let q = [x_m - self.origin_m[0], y_m - self.origin_m[1]];
        self.edges
            .iter()
            .map(|e| e.distance(q).distance_m)
            .collect()
    }

    /// (s, d) of a point in lane `lane` (index into [`LaneRoad::lanes`]) with ∇s and ∇d.
    #[inline]
    pub fn jacobian(&self, lane: usize, p_m: [f64; 2]) -> FrameJacobian {
        self.frames[lane].jacobian(self.road.lanes()[lane].centreline(), p_m)
    }

    /// Arc length s of a point in lane `lane`'s frame (m).
    #[inline]
    pub(crate) fn s_m(&self, lane: usize, p_m: [f64; 2]) -> f64 {
        self.frames[lane]
            .project(self.road.lanes()[lane].centreline(), p_m)
            .s_m
    }

    /// Index of the lane holding the point and the point's (s, d) in it: as
    /// [`LaneRoad::nearest_lane`] (smallest frame excess, ties to the smaller |d|, then to the
    /// description order), through the prepared frames.
    pub(crate) fn lane_at(&self, p_m: [f64; 2]) -> (usize, FramePoint) {
        let mut best: Option<(usize, FramePoint, f64)> = None;
        for (i, l) in self.road.lanes().iter().enumerate() {
            let fp = self.frames[i].project(l.centreline(), p_m);
            let excess = l.frame_excess_m(fp);
            let better = best
                .is_none_or(|(_, b, e)| excess < e || (excess == e && fp.d_m.abs() < b.d_m.abs()));
            if better {
                best = Some((i, fp, excess));
            }
        }
        best.map_or((0, FramePoint { s_m: 0.0, d_m: 0.0 }), |(i, fp, _)| (i, fp))
    }

    /// Index of the lane holding the point ([`LaneRoadGeometry::lane_at`]).
    pub(crate) fn lane_index_at(&self, p_m: [f64; 2]) -> usize {
        self.lane_at(p_m).0
    }

    /// The smoothed heading of lane `lane` at `s_m` (rad; a straight lane's direction).
    pub(crate) fn lane_heading_rad(&self, lane: usize, s_m: f64) -> f64 {
        match &self.frames[lane] {
            FastFrame::Straight { tangent, .. } => tangent[1].atan2(tangent[0]),
            FastFrame::General => self.road.lanes()[lane].heading_rad(s_m),
        }
    }

    /// On which side of lane `lane` its neighbour `other` lies (across a divider).
    pub(crate) fn side_of_neighbour(&self, lane: usize, other: usize) -> Option<Side> {
        self.dividers.iter().find_map(|dg| {
            if dg.right_lane == lane && dg.left_lane == other {
                Some(Side::Left)
            } else if dg.left_lane == lane && dg.right_lane == other {
                Some(Side::Right)
            } else {
                None
            }
        })
    }

    /// The unit tangent of lane `lane` if its centreline is straight.
    pub(crate) fn straight_tangent(&self, lane: usize) -> Option<[f64; 2]> {
        match &self.frames[lane] {
            FastFrame::Straight { tangent, .. } => Some(*tangent),
            FastFrame::General => None,
        }
    }

    /// The heading of the lane holding the point, at the point's s (rad): Eq. 4's reference
    /// for an obstacle's heading.
    pub(crate) fn lane_heading_at_rad(&self, p_m: [f64; 2]) -> f64 {
        let (lane, fp) = self.lane_at(p_m);
        self.lane_heading_rad(lane, fp.s_m)
    }

    /// Whether lane `lane` ends ahead (closed, beside a lane that goes on): never a target.
    pub fn lane_ends(&self, lane: usize) -> bool {
        self.ends.get(lane).copied().unwrap_or(false)
    }

    /// The target lane of a vehicle in lane `lane` (lane-end rule): its own lane, unless that
    /// ends; then the first neighbour across one of its dividers that does not end (the lane
    /// it must merge into); its own lane if there is none.
    pub fn target_lane(&self, lane: usize) -> usize {
        if !self.lane_ends(lane) {
            return lane;
        }
        self.dividers
            .iter()
            .filter_map(|dg| {
                if dg.left_lane == lane {
                    Some(dg.right_lane)
                } else if dg.right_lane == lane {
                    Some(dg.left_lane)
                } else {
                    None
                }
            })
            .find(|&other| !self.lane_ends(other))
            .unwrap_or(lane)
    }

    /// The lane indices of a route given as lane ids (ids the road does not have are dropped).
    pub fn route_indices(&self, route: &[LaneId]) -> Vec<usize> {
        route
            .iter()
            .filter_map(|id| self.road.lanes().iter().position(|l| l.id() == *id))
            .collect()
    }

    /// The target lane of a vehicle at `p_m` that follows `route` (lane indices in driving
    /// order, e.g. to a goal), with Eq. 1's look-ahead `lookahead_m`:
    /// - where a lane of the route holds the point (the latest such lane, so that at a fork the
    ///   route's branch wins): the route's next lane if that is a neighbour across a divider
    ///   (the lane change the route asks for), or a successor whose start lies within the
    ///   look-ahead; else that lane;
    /// - else a neighbour of the lane holding the point that is on the route;
    /// - otherwise (or with an empty route) the lane-end rule, [`LaneRoadGeometry::target_lane`].
    pub fn route_target_lane(&self, p_m: [f64; 2], route: &[usize], lookahead_m: f64) -> usize {
        let lanes = self.road.lanes();
        let neighbours = |a: usize, b: usize| self.side_of_neighbour(a, b).is_some();
        let on_route = route.iter().enumerate().rev().find_map(|(k, &i)| {
            let fp = self.frames[i].project(lanes[i].centreline(), p_m);
            (lanes[i].frame_excess_m(fp) == 0.0).then_some((k, i, fp.s_m))
        });
        if let Some((k, lane, s_m)) = on_route {
            return match route.get(k + 1) {
                Some(&next) if neighbours(lane, next) => next,
                Some(&next)
                    if lanes[lane].successors().contains(&lanes[next].id())
                        && lanes[lane].length_m() - s_m <= lookahead_m =>
                {
                    next
                }
                _ => lane,
            };
        }
        let lane = self.lane_index_at(p_m);
        route
            .iter()
            .copied()
            .find(|&r| neighbours(lane, r))
            .unwrap_or_else(|| self.target_lane(lane))
    }

    /// The dividers that a vehicle in `state` (half-width `half_width_m`) sees as walls under
    /// the lane-end rule, with the sign that makes δ = sign·(d − d_div) positive on its side,
    /// and the lane it is settled in (to pass back on its next cycle as `settled_lane`).
    ///
    /// The walls are the dividers between its lane, if that goes on, and a neighbour that ends
    /// ahead. They apply once the vehicle is *settled* in its lane: its body's clearance to each
    /// of them at least [`LANE_END_WALL_CUTOFF_M`] now (where the wall's term is zero, so it
    /// appears without a jolt: a vehicle that has just merged meets no wall pushing at it), or
    /// settled at its previous cycle in the same lane (`settled_lane`, the lane index) — then
    /// they stay while its centre is in that lane, however close a push brings it.
    pub(crate) fn lane_end_walls(
        &self,
        state: &VehicleState,
        half_width_m: f64,
        settled_lane: Option<usize>,
    ) -> (Vec<(usize, f64)>, Option<usize>) {
        let p = [state.x_m, state.y_m];
        let lane = self.lane_index_at(p);
        if self.lane_ends(lane) {
            return (Vec::new(), None);
        }
        let lanes = self.road.lanes();
        let mut walls = Vec::new();
        let mut clear = true;
        for (k, dg) in self.dividers.iter().enumerate() {
            let (sign, other) = if dg.left_lane == lane {
                (1.0, dg.right_lane)
            } else if dg.right_lane == lane {
                (-1.0, dg.left_lane)
            } else {
                continue;
            };
            if !self.lane_ends(other) {
                continue;
            }
            let l = &lanes[dg.lane];
            let s = self.frames[dg.lane].project(l.centreline(), p);
            if s.s_m.is_nan() || s.s_m >= dg.s_range_m[1] {
                continue;
            }
            let (d_div, _) = dg.offset.at(l, dg.side, s.s_m);
            let clearance = sign * (s.d_m - d_div) - half_width_m;
            clear &= clearance >= LANE_END_WALL_CUTOFF_M;
            walls.push((k, sign));
        }
        if walls.is_empty() {
            return (walls, None);
        }
        if settled_lane == Some(lane) || clear {
            (walls, Some(lane))
        } else {
            (Vec::new(), None)
        }
    }
}
