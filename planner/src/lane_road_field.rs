//! The road terms of the potential field (paper Eqs. 1–3) on a road made of lanes
//! ([`LaneRoad`]), with their world gradients for Eq. 7. Not yet used by the planners (they run
//! on [`MergeRoad`](crate::road::MergeRoad) through `road_field.rs` and `attractive_field.rs`);
//! on the straight merge road both give the same values (tests in
//! `planner/tests/lane_road_field.rs`). The formulas are in planner/README.md, "The road terms
//! in the lane frame".
//!
//! - **Eq. 1** ([`LaneAttraction`]): U_AT = ½ λ (s − s_tar)², s along the target lane's
//!   centreline, the target at (s_tar, d = 0) with s_tar = s_ego + look-ahead. Like the straight
//!   road's ½ λ (X − X_tar)² it measures only the distance along the road (no lateral spring:
//!   lateral placement is the divider's and the edges' job). The moving target's pull is
//!   −λ·look-ahead·∇s.
//! - **Eq. 2**: for each divider between same-direction lanes ([`LaneRoad::dividers`]), in the
//!   frame of the lane whose bound it is, U_LD = A exp(−(d − d_div(s))² / 2σ²) where the divider
//!   exists (its s range; continued beyond the road's open start or end, as the frame is).
//! - **Eq. 3**: for each outer edge of the drivable area ([`LaneRoad::outer_edges`], a closed
//!   lane end included), e(g) with the clearance g = δ − l_w/2, δ the signed Euclidean distance
//!   to the edge (positive on the road), e the straight road's ½ ξ/g² with its linear
//!   continuation below g_c (`road_field.rs`).
//! - **Eq. 7**: ∇U = ∂U/∂s ∇s + ∂U/∂d ∇d (`lane_frame.rs`); the edge term's gradient is the
//!   distance's own, e'(g)·∇δ.

use mergesim_types::lanes::{Centreline, Divider, Lane, LaneId, LaneRoad, Side};

use crate::lane_frame::{FrameJacobian, frame_jacobian, to_world_gradient};
use crate::lane_road_edges::EdgeGeometry;
use crate::params::PlannerParams;
use crate::road_field::edge_term;

/// One divider prepared for Eq. 2: the lane whose bound it is, which bound, and where it holds.
#[derive(Clone, Debug)]
struct DividerGeometry {
    /// Index into [`LaneRoad::lanes`].
    lane: usize,
    /// The lane's bound that is the divider.
    side: Side,
    /// s range on that lane (m); ±∞ where it reaches the road's open start or end.
    s_range_m: [f64; 2],
}

/// What Eqs. 2–3 need of a [`LaneRoad`], prepared once per road: the dividers in their lanes'
/// frames and the outer edges with their drivable sides.
#[derive(Clone, Debug)]
pub struct LaneRoadGeometry<'a> {
    road: &'a LaneRoad,
    origin_m: [f64; 2],
    dividers: Vec<DividerGeometry>,
    edges: Vec<EdgeGeometry>,
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
    })
}

impl<'a> LaneRoadGeometry<'a> {
    /// Prepares the road's dividers and outer edges.
    pub fn new(road: &'a LaneRoad) -> Self {
        let origin_m = road
            .lanes()
            .first()
            .map_or([0.0, 0.0], |l| l.centreline().origin_m());
        Self {
            road,
            origin_m,
            dividers: road
                .dividers()
                .iter()
                .filter_map(|d| divider_geometry(road, d))
                .collect(),
            edges: EdgeGeometry::all(road, origin_m),
        }
    }

    /// The road.
    pub fn road(&self) -> &'a LaneRoad {
        self.road
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
}

/// The road terms (Eqs. 2–3) of one vehicle on a road of lanes: [`RoadField`](crate::road_field::RoadField)
/// generalised through the lane frame, with the same parameters.
#[derive(Clone, Copy, Debug)]
pub struct LaneRoadField<'g, 'a> {
    /// The road, prepared.
    pub geometry: &'g LaneRoadGeometry<'a>,
    /// A_lane.
    pub lane_amplitude: f64,
    /// σ of the divider (m).
    pub lane_sigma_m: f64,
    /// ξ (m²).
    pub edge_gain_m2: f64,
    /// Clearance g_c below which the edge field is linear (m).
    pub edge_clamp_distance_m: f64,
    /// l_w / 2 of the vehicle (m).
    pub half_width_m: f64,
}

impl<'g, 'a> LaneRoadField<'g, 'a> {
    /// The field with the planner's parameters (the same as `PotentialField`'s road field).
    pub fn new(
        geometry: &'g LaneRoadGeometry<'a>,
        params: &PlannerParams,
        half_width_m: f64,
    ) -> Self {
        Self {
            geometry,
            lane_amplitude: params.lane_amplitude,
            lane_sigma_m: params.lane_sigma_m,
            edge_gain_m2: params.edge_gain_m2,
            edge_clamp_distance_m: params.edge_clamp_distance_m,
            half_width_m,
        }
    }

    /// Each divider's (frame jacobian, d − d_div, d_div') where it holds at the point.
    fn divider_terms(
        &self,
        x_m: f64,
        y_m: f64,
        mut visit: impl FnMut(&FrameJacobian, f64, f64, f64),
    ) {
        let lanes = self.geometry.road.lanes();
        for dg in &self.geometry.dividers {
            let lane = &lanes[dg.lane];
            let c: &Centreline = lane.centreline();
            let j = frame_jacobian(c, [x_m, y_m]);
            let s = j.frame.s_m;
            if !(s >= dg.s_range_m[0] && s < dg.s_range_m[1]) {
                continue;
            }
            let (d_div, slope) = lane.bound_d_and_slope(dg.side, s);
            let delta = j.frame.d_m - d_div;
            let s2 = self.lane_sigma_m * self.lane_sigma_m;
            let u = self.lane_amplitude * (-delta * delta / (2.0 * s2)).exp();
            visit(&j, delta, slope, u);
        }
    }

    /// U_LD at (x, y), Eq. 2 in the lane frame: the sum over the dividers that hold there.
    pub fn lane_value(&self, x_m: f64, y_m: f64) -> f64 {
        let mut v = 0.0;
        self.divider_terms(x_m, y_m, |_, _, _, u| v += u);
        v
    }

    /// ∇U_LD: ∂U/∂d = −U δ/σ², ∂U/∂s = U δ/σ² · d_div'(s), mapped through the frame.
    pub fn lane_gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let s2 = self.lane_sigma_m * self.lane_sigma_m;
        let mut g = [0.0, 0.0];
        self.divider_terms(x_m, y_m, |j, delta, slope, u| {
            let du_dd = -u * delta / s2;
            let w = to_world_gradient(j, -du_dd * slope, du_dd);
            g[0] += w[0];
            g[1] += w[1];
        });
        g
    }

    /// U_RE at (x, y), Eq. 3: e(δ_k − l_w/2) summed over the outer edges k.
    pub fn edge_value(&self, x_m: f64, y_m: f64) -> f64 {
        let q = [
            x_m - self.geometry.origin_m[0],
            y_m - self.geometry.origin_m[1],
        ];
        self.geometry
            .edges
            .iter()
            .map(|e| {
                let g = e.distance(q).distance_m - self.half_width_m;
                edge_term(self.edge_gain_m2, self.edge_clamp_distance_m, g).0
            })
            .sum()
    }

    /// ∇U_RE = Σ_k e'(g_k) ∇δ_k.
    pub fn edge_gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let q = [
            x_m - self.geometry.origin_m[0],
            y_m - self.geometry.origin_m[1],
        ];
        let mut out = [0.0, 0.0];
        for e in &self.geometry.edges {
            let d = e.distance(q);
            let g = d.distance_m - self.half_width_m;
            let (_, de) = edge_term(self.edge_gain_m2, self.edge_clamp_distance_m, g);
            out[0] += de * d.gradient[0];
            out[1] += de * d.gradient[1];
        }
        out
    }

    /// U_LD + U_RE.
    pub fn value(&self, x_m: f64, y_m: f64) -> f64 {
        self.lane_value(x_m, y_m) + self.edge_value(x_m, y_m)
    }

    /// ∇(U_LD + U_RE).
    pub fn gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let lane = self.lane_gradient(x_m, y_m);
        let edge = self.edge_gradient(x_m, y_m);
        [lane[0] + edge[0], lane[1] + edge[1]]
    }
}

/// Eq. 1 on a road of lanes: U_AT = ½ λ (s − s_tar)² along the target lane's centreline.
#[derive(Clone, Copy, Debug)]
pub struct LaneAttraction<'a> {
    /// The target lane's centreline.
    pub centreline: &'a Centreline,
    /// λ (1/m²).
    pub gain_per_m2: f64,
    /// s_tar on the target lane (m).
    pub target_s_m: f64,
}

impl<'a> LaneAttraction<'a> {
    /// The target `params.target_lookahead_m` ahead of the point (x, y) (the ego) along the
    /// target lane `lane`.
    pub fn ahead_of(lane: &'a Lane, params: &PlannerParams, x_m: f64, y_m: f64) -> Self {
        let c = lane.centreline();
        Self {
            centreline: c,
            gain_per_m2: params.attractive_gain_per_m2,
            target_s_m: c.project([x_m, y_m]).s_m + params.target_lookahead_m,
        }
    }

    /// U_AT at (x, y).
    pub fn value(&self, x_m: f64, y_m: f64) -> f64 {
        let ds = self.centreline.project([x_m, y_m]).s_m - self.target_s_m;
        0.5 * self.gain_per_m2 * ds * ds
    }

    /// ∇U_AT = λ (s − s_tar) ∇s.
    pub fn gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let j = frame_jacobian(self.centreline, [x_m, y_m]);
        to_world_gradient(&j, self.gain_per_m2 * (j.frame.s_m - self.target_s_m), 0.0)
    }

    /// ∇U_AT with the target re-anchored `lookahead_m` ahead of (x, y) along the lane:
    /// −λ·look-ahead·∇s (on a straight lane along +x, today's constant [−λ·look-ahead, 0]).
    pub fn moving_target_gradient(
        centreline: &Centreline,
        gain_per_m2: f64,
        lookahead_m: f64,
        x_m: f64,
        y_m: f64,
    ) -> [f64; 2] {
        let j = frame_jacobian(centreline, [x_m, y_m]);
        to_world_gradient(&j, -gain_per_m2 * lookahead_m, 0.0)
    }
}
