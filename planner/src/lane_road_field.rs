//! The road terms of the potential field (paper Eqs. 1–3) on a road made of lanes
//! ([`LaneRoad`](mergesim_types::lanes::LaneRoad)), with their world gradients for Eq. 7: what the planners step in. On the
//! straight merge road they give today's straight-road field (`road_field.rs`,
//! `attractive_field.rs`, kept as the reference of the tests in
//! `planner/tests/lane_road_field.rs`). The formulas are in planner/README.md, "The road terms
//! in the lane frame".
//!
//! - **Eq. 1** ([`LaneAttraction`], and through the prepared frames
//!   `PotentialField::moving_target_gradient`): U_AT = ½ λ (s − s_tar)², s along the target
//!   lane's centreline ([`LaneRoadGeometry::target_lane`]: never a lane that ends), the target
//!   at (s_tar, d = 0) with s_tar = s_ego + look-ahead. Like the straight road's
//!   ½ λ (X − X_tar)² it measures only the distance along the road. The moving target's pull is
//!   −λ·look-ahead·∇s.
//! - **Eq. 2**: for each divider between same-direction lanes ([`LaneRoad::dividers`](mergesim_types::lanes::LaneRoad::dividers)), in the
//!   frame of the lane whose bound it is, U_LD = A exp(−(d − d_div(s))² / 2σ²) where the divider
//!   exists (its s range; continued beyond the road's open start or end, as the frame is).
//! - **Eq. 3**: for each outer edge of the drivable area ([`LaneRoad::outer_edges`](mergesim_types::lanes::LaneRoad::outer_edges), a closed
//!   lane end included), e(g) with the clearance g = δ − l_w/2, δ the signed Euclidean distance
//!   to the edge (positive on the road), e the straight road's ½ ξ/g² with its linear
//!   continuation below g_c (`road_field.rs`).
//! - **Lane-end rule**: a vehicle in a lane that goes on sees the divider towards a neighbour
//!   that ends as Eq. 3's edge, cut off at `LANE_END_WALL_CUTOFF_M` (`wall_term`,
//!   `LaneRoadGeometry::lane_end_walls`).
//! - **Eq. 7**: ∇U = ∂U/∂s ∇s + ∂U/∂d ∇d (`lane_frame.rs`); the edge term's gradient is the
//!   distance's own, e'(g)·∇δ.
//!
//! Cost: straight lanes are projected in O(1) and constant bounds need no interpolation
//! (`lane_road_frames.rs`); an edge that is one straight line is one dot product, an edge of a
//! few segments is searched without its bounding boxes (`lane_road_edges.rs`).

use mergesim_types::VehicleState;
use mergesim_types::lanes::{Centreline, Lane};

use crate::attractive_field::AttractionParams;
use crate::lane_frame::{FrameJacobian, frame_jacobian, to_world_gradient};
use crate::lane_road_edges::{EdgeDistance, EdgeGeometry};
use crate::road_field::{RoadFieldParams, edge_term};

mod geometry;

pub use geometry::LaneRoadGeometry;

/// The lane-end rule's wall acts only at body clearances below this (m): beyond it its term is
/// zero, so a vehicle near its lane's centre (clearance (w − l_w)/2 = 0.945 m for a 1.61 m car
/// in a 3.5 m lane) sees the same field as without the rule, and only a path pushed towards
/// the lane that ends meets it.
pub(crate) const LANE_END_WALL_CUTOFF_M: f64 = 0.5;

/// The lane-end wall's term at body clearance g and its slope: Eq. 3's e(g) (with its linear
/// continuation below g_c) less its tangent at the cut-off g_w = [`LANE_END_WALL_CUTOFF_M`],
/// zero beyond g_w: e(g) − e(g_w) − e'(g_w)(g − g_w), C¹ at g_w.
pub(crate) fn wall_term(gain_m2: f64, clamp_m: f64, clearance_m: f64) -> (f64, f64) {
    let cut = LANE_END_WALL_CUTOFF_M;
    if clearance_m >= cut {
        return (0.0, 0.0);
    }
    let (e, de) = edge_term(gain_m2, clamp_m, clearance_m);
    let (e_cut, de_cut) = edge_term(gain_m2, clamp_m, cut);
    (e - e_cut - de_cut * (clearance_m - cut), de - de_cut)
}

/// The road terms (Eqs. 2–3) of one vehicle on a road of lanes: [`RoadField`](crate::road_field::RoadField)
/// generalised through the lane frame, with the same parameters.
#[derive(Clone, Debug)]
pub struct LaneRoadField<'g> {
    /// The road, prepared.
    pub geometry: &'g LaneRoadGeometry,
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
    /// The dividers this vehicle sees as walls (lane-end rule): (divider index, sign of δ).
    pub walls: Vec<(usize, f64)>,
}

impl<'g> LaneRoadField<'g> {
    /// The field with the planner's parameters (the same as `PotentialField`'s road field),
    /// without lane-end walls.
    pub fn new(
        geometry: &'g LaneRoadGeometry,
        params: &RoadFieldParams,
        half_width_m: f64,
    ) -> Self {
        Self {
            geometry,
            lane_amplitude: params.lane_amplitude,
            lane_sigma_m: params.lane_sigma_m,
            edge_gain_m2: params.edge_gain_m2,
            edge_clamp_distance_m: params.edge_clamp_distance_m,
            half_width_m,
            walls: Vec::new(),
        }
    }

    /// The field of a vehicle in `state`, with the lane-end rule's walls when
    /// `lane_end_walls` ([`LaneRoadGeometry::lane_end_walls`] without a previous cycle:
    /// walls only if the vehicle is settled now): [`wall_term`] along each, in d − d_div(s).
    pub(crate) fn for_vehicle(
        geometry: &'g LaneRoadGeometry,
        params: &RoadFieldParams,
        lane_end_walls: bool,
        half_width_m: f64,
        state: &VehicleState,
    ) -> Self {
        let walls = if lane_end_walls {
            geometry.lane_end_walls(state, half_width_m, None).0
        } else {
            Vec::new()
        };
        Self {
            walls,
            ..Self::new(geometry, params, half_width_m)
        }
    }

    /// Visits each divider that holds at the point: (its index, frame jacobian,
    /// δ = d − d_div, d_div', U_LD of it).
    #[inline]
    fn divider_terms(
        &self,
        x_m: f64,
        y_m: f64,
        mut visit: impl FnMut(usize, &FrameJacobian, f64, f64, f64),
    ) {
        let lanes = self.geometry.road.lanes();
        let s2 = self.lane_sigma_m * self.lane_sigma_m;
        for (k, dg) in self.geometry.dividers.iter().enumerate() {
            let lane = &lanes[dg.lane];
            let j = self.geometry.frames[dg.lane].jacobian(lane.centreline(), [x_m, y_m]);
            let s = j.frame.s_m;
            if !(s >= dg.s_range_m[0] && s < dg.s_range_m[1]) {
                continue;
            }
            let (d_div, slope) = dg.offset.at(lane, dg.side, s);
            let delta = j.frame.d_m - d_div;
            let u = self.lane_amplitude * (-delta * delta / (2.0 * s2)).exp();
            visit(k, &j, delta, slope, u);
        }
    }

    fn wall_sign(&self, k: usize) -> Option<f64> {
        self.walls.iter().find(|w| w.0 == k).map(|w| w.1)
    }

    /// U_LD at (x, y), Eq. 2 in the lane frame: the sum over the dividers that hold there.
    pub fn lane_value(&self, x_m: f64, y_m: f64) -> f64 {
        let mut v = 0.0;
        self.divider_terms(x_m, y_m, |_, _, _, _, u| v += u);
        v
    }

    /// ∇U_LD: ∂U/∂d = −U δ/σ², ∂U/∂s = U δ/σ² · d_div'(s), mapped through the frame.
    pub fn lane_gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let s2 = self.lane_sigma_m * self.lane_sigma_m;
        let mut g = [0.0, 0.0];
        self.divider_terms(x_m, y_m, |_, j, delta, slope, u| {
            let du_dd = -u * delta / s2;
            let w = to_world_gradient(j, -du_dd * slope, du_dd);
            g[0] += w[0];
            g[1] += w[1];
        });
        g
    }

    /// The lane-end walls' term at (x, y): [`wall_term`] of the body clearance
    /// g = sign·(d − d_div) − l_w/2 per wall (Eq. 3's edge, cut off at [`LANE_END_WALL_CUTOFF_M`]).
    pub(crate) fn wall_value(&self, x_m: f64, y_m: f64) -> f64 {
        if self.walls.is_empty() {
            return 0.0;
        }
        let mut v = 0.0;
        self.divider_terms(x_m, y_m, |k, _, delta, _, _| {
            if let Some(sign) = self.wall_sign(k) {
                let g = sign * delta - self.half_width_m;
                v += wall_term(self.edge_gain_m2, self.edge_clamp_distance_m, g).0;
            }
        });
        v
    }

    /// ∇ of `LaneRoadField::wall_value`: w'(g)·sign·(∇d − d_div'·∇s).
    pub fn wall_gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let mut g = [0.0, 0.0];
        if self.walls.is_empty() {
            return g;
        }
        self.divider_terms(x_m, y_m, |k, j, delta, slope, _| {
            if let Some(sign) = self.wall_sign(k) {
                let clearance = sign * delta - self.half_width_m;
                let (_, de) = wall_term(self.edge_gain_m2, self.edge_clamp_distance_m, clearance);
                let w = to_world_gradient(j, -de * sign * slope, de * sign);
                g[0] += w[0];
                g[1] += w[1];
            }
        });
        g
    }

    /// U_RE at (x, y), Eq. 3: e(δ_k − l_w/2) summed over the outer edges k.
    pub fn edge_value(&self, x_m: f64, y_m: f64) -> f64 {
        let q = [
            x_m - self.geometry.origin_m[0],
            y_m - self.geometry.origin_m[1],
        ];
        let mut drivable = None;
        self.geometry
            .edges
            .iter()
            .map(|e| {
                let d = self.on_road_distance(e, q, [x_m, y_m], &mut drivable);
                let g = d.distance_m - self.half_width_m;
                edge_term(self.edge_gain_m2, self.edge_clamp_distance_m, g).0
            })
            .sum()
    }

    /// The signed distance to edge `e` (local point `q`, world point `p_m`), positive on its
    /// drivable side — and positive on any drivable point: an edge bounds its own lanes, and a
    /// point of another lane beyond it (the main road seen across the gore from a ramp's left
    /// bound) is not off the road. Whether `p_m` is drivable is asked only when some edge
    /// gives a negative distance, once per point (`drivable` caches it).
    #[inline]
    fn on_road_distance(
        &self,
        e: &EdgeGeometry,
        q: [f64; 2],
        p_m: [f64; 2],
        drivable: &mut Option<bool>,
    ) -> EdgeDistance {
        let mut d = e.distance(q);
        if d.distance_m < 0.0
            && *drivable.get_or_insert_with(|| self.geometry.road().is_drivable(p_m))
        {
            d.distance_m = -d.distance_m;
            d.gradient = [-d.gradient[0], -d.gradient[1]];
        }
        d
    }

    /// ∇U_RE = Σ_k e'(g_k) ∇δ_k.
    pub fn edge_gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let q = [
            x_m - self.geometry.origin_m[0],
            y_m - self.geometry.origin_m[1],
        ];
        let mut out = [0.0, 0.0];
        let mut drivable = None;
        for e in &self.geometry.edges {
            let d = self.on_road_distance(e, q, [x_m, y_m], &mut drivable);
            let g = d.distance_m - self.half_width_m;
            let (_, de) = edge_term(self.edge_gain_m2, self.edge_clamp_distance_m, g);
            out[0] += de * d.gradient[0];
            out[1] += de * d.gradient[1];
        }
        out
    }

    /// U_LD + U_RE (+ the lane-end walls).
    pub fn value(&self, x_m: f64, y_m: f64) -> f64 {
        self.lane_value(x_m, y_m) + self.edge_value(x_m, y_m) + self.wall_value(x_m, y_m)
    }

    /// ∇(U_LD + U_RE) (+ the lane-end walls), one frame projection per divider.
    pub fn gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let s2 = self.lane_sigma_m * self.lane_sigma_m;
        let mut g = self.edge_gradient(x_m, y_m);
        self.divider_terms(x_m, y_m, |k, j, delta, slope, u| {
            let mut du_dd = -u * delta / s2;
            if let Some(sign) = self.wall_sign(k) {
                let clearance = sign * delta - self.half_width_m;
                let (_, de) = wall_term(self.edge_gain_m2, self.edge_clamp_distance_m, clearance);
                du_dd += de * sign;
            }
            let w = to_world_gradient(j, -du_dd * slope, du_dd);
            g[0] += w[0];
            g[1] += w[1];
        });
        g
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
    /// The target `params.lookahead_m` ahead of the point (x, y) (the ego) along the target
    /// lane `lane`.
    pub fn ahead_of(lane: &'a Lane, params: &AttractionParams, x_m: f64, y_m: f64) -> Self {
        let c = lane.centreline();
        Self {
            centreline: c,
            gain_per_m2: params.gain_per_m2,
            target_s_m: c.project([x_m, y_m]).s_m + params.lookahead_m,
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
