//! Exact safety checks between vehicle bodies and against the road edges, with
//! parry3d 0.31.
//!
//! What is measured, at every instant the world loop hands to [`SafetyMonitor::check`]:
//! - **collision**: exact intersection of two vehicles' oriented boxes (parry's SAT for
//!   cuboids); one [`CollisionEvent`] per pair and *contact episode* (a pair that stays in
//!   contact over many instants counts once; separating and touching again counts again);
//! - **road-edge contact**: a box touching an outer edge of the road's drivable area
//!   ([`LaneRoad::outer_edges`]: on the merge road the straight upper edge and the piecewise
//!   lower edge of Eq. 3, taper included; on any road of lanes, curved or not, the left and
//!   right outer edges and the closed lane ends) or lying entirely beyond it; one
//!   [`EdgeContactEvent`] per vehicle, edge ([`RoadEdge`]: left/upper or right/lower) and
//!   episode;
//! - **gap**: exact distance between two boxes (GJK), minimum over the run and per pair;
//! - **TTC** (time to collision): the time until two boxes touch if both keep their current
//!   world-frame velocity and heading — a parry shape cast of the boxes
//!   ([`parry3d::query::cast_shapes`]); `None` when they do not touch within
//!   [`SafetyParams::ttc_horizon_s`]. This is the constant-velocity TTC of FHWA SSAM, extended
//!   from points on a line to oriented boxes moving in the plane;
//! - **near miss**: min TTC below [`SafetyParams::ttc_threshold_s`] (1.5 s, SSAM) or min gap
//!   below [`SafetyParams::near_miss_gap_m`], without a collision;
//! - **TET** (time exposed to TTC): the time during which at least one pair has a TTC below the
//!   threshold (per pair as well). Each checked instant stands for the interval `dt_s` that
//!   follows it. A pair in contact has TTC 0 and so counts as exposed.
//!
//! # 2.5D geometry with 3D shapes
//! Every body is a 3D cuboid resting on the road plane (Z from 0 to its height) and every road
//! edge a segment at the body's mid-height. Because all Z ranges overlap, the Minkowski
//! difference of two bodies contains the Z = 0 plane across its whole planar extent, so
//! intersection, distance and time of impact are *exactly* the planar ones. Using parry3d
//! rather than parry2d reuses the crate rapier already compiles and keeps one set of types.
//!
//! # Precision
//! parry3d computes in `f32`. Poses are expressed relative to the midpoint of the two bodies
//! (or to the body centre for edge checks) before the conversion, so the coordinates handed to
//! parry are a few metres, not hundreds: the resolution is ~1 µm rather than ~60 µm at X = 700 m.
//!
//! # Which pairs are followed
//! A pair is *followed* at an instant when its bounding-circle gap bound (centre distance minus
//! both circles' radii) is at most [`SafetyParams::pair_range_m`] (250 m) or at most the distance
//! it closes at its current relative speed over [`SafetyParams::ttc_horizon_s`]. Only followed
//! pairs are checked, have figures and appear in the reports. That loses nothing the monitor
//! reports: a pair not followed cannot touch (its gap exceeds the range, ≥ 10 m, which is above
//! the contact tolerance and the near-miss gap) and has no TTC (the shape cast could not hit
//! within the horizon), so it cannot start a collision, lower a TTC or add exposure time; and a
//! pair's minimum gap is exact whenever it falls below the range (the instant of the minimum is
//! followed, every other instant has a larger gap). A pair that is never followed is not
//! listed in [`SafetySummary::pairs`]; the run's minimum gap is the smallest of the listed ones
//! (`None` when no two vehicles ever came within the range).
//!
//! The followed pairs are found by sweeping the bodies sorted by X (`crate::spatial`) with a
//! window that bounds the test: `2 r_max + max(pair_range, |Δv|_max · horizon)`, where
//! `|Δv|_max` is the diagonal of the instant's velocity bounding box, widened by a relative
//! 1e-9 and 1e-6 m against rounding. Every candidate then goes through the same test as with
//! `broad_phase = false`, which visits all pairs; the two give identical results (tests), in
//! id order. Cost: O(N log N + k) for k candidate pairs, instead of N(N − 1)/2.
//!
//! # Cost of a pair
//! Followed pairs are culled further with bounding circles, and the culling never changes a
//! result:
//! - the exact intersection test runs only when the circles overlap;
//! - the exact distance runs only when the circle bound could lower the pair's minimum gap
//!   (otherwise the instant's gap is reported as a lower bound);
//! - the shape cast runs only when the circles could meet within the horizon at the pair's
//!   relative speed (`gap_lower_bound ≤ |v_b − v_a| · horizon`).

mod edge_checks;
mod events;
mod pair_checks;
mod params;
mod recorded_pairs;

use std::collections::BTreeMap;

use std::sync::Arc;

use mergesim_types::VehicleId;
use mergesim_types::lanes::LaneRoad;
use vehicles::road_collider::{RoadSide, road_side_of};

use crate::spatial::XSweep;

/// Up to this many bodies the broad phase tests every pair's X distance directly, which gives
/// the sweep's pairs in the same order at less cost than sorting (measured: README
/// "Performance").
const SMALL_FLEET: usize = 48;

pub use crate::body_state::BodyState;
pub use events::{
    CollisionEvent, EdgeContactEvent, PairInstant, PairSafety, RoadEdge, SafetyStepReport,
    SafetySummary,
};
pub use params::{DEFAULT_PAIR_RANGE_M, SAFETY_BOUNDS, SafetyError, SafetyParams};
pub use recorded_pairs::recorded_is_behind;

/// The bounding-circle figures of a pair at one instant: what decides whether the pair is
/// followed, and which exact queries it needs.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PairBounds {
    /// Centre distance minus both bounding radii, floored at 0 (m): a lower bound of the gap.
    gap_lower_bound_m: f64,
    /// Norm of the relative world-frame velocity (m/s).
    relative_speed_mps: f64,
}

/// [`PairBounds`] of `a` and `b`, given their bounding radii `radius_a_m` and `radius_b_m`
/// ([`BodyState::bounding_radius_m`], computed once per body and instant by the caller).
fn pair_bounds(a: &BodyState, radius_a_m: f64, b: &BodyState, radius_b_m: f64) -> PairBounds {
    let centre_distance_m = (b.x_m - a.x_m).hypot(b.y_m - a.y_m);
    let gap_lower_bound_m = (centre_distance_m - radius_a_m - radius_b_m).max(0.0);
    let relative_speed_mps = (b.vx_mps - a.vx_mps).hypot(b.vy_mps - a.vy_mps);
    PairBounds {
        gap_lower_bound_m,
        relative_speed_mps,
    }
}

/// One straight piece of a road edge, in world coordinates.
#[derive(Clone, Copy, Debug)]
struct EdgeSegment {
    edge: RoadEdge,
    a: [f64; 2],
    b: [f64; 2],
}

/// Consecutive edge pieces under one bounding box, so that a body far from most of a long
/// (curved, finely sampled) edge skips them at once.
#[derive(Clone, Debug)]
struct EdgeChunk {
    lo: [f64; 2],
    hi: [f64; 2],
    segments: std::ops::Range<usize>,
}

/// Pieces per [`EdgeChunk`].
const EDGE_CHUNK: usize = 16;

/// The edge pieces of `lanes`' outer edges, each tagged with its side: a piece with the road on
/// its right is a left-hand (upper) edge, one with the road on its left a right-hand (lower)
/// edge or a closed lane end. Pieces whose side cannot be told (degenerate) are left out.
fn edge_segments(lanes: &LaneRoad) -> (Vec<EdgeSegment>, Vec<EdgeChunk>) {
    let mut edges = Vec::new();
    let mut chunks = Vec::new();
    for outer in lanes.outer_edges() {
        let start = edges.len();
        for w in outer.polyline_m.windows(2) {
            let edge = match road_side_of(lanes, w[0], w[1]) {
                Some(RoadSide::Right) => RoadEdge::Upper,
                Some(RoadSide::Left) => RoadEdge::Lower,
                None => continue,
            };
            edges.push(EdgeSegment {
                edge,
                a: w[0],
                b: w[1],
            });
        }
        let mut k = start;
        while k < edges.len() {
            let end = (k + EDGE_CHUNK).min(edges.len());
            let mut lo = [f64::INFINITY; 2];
            let mut hi = [f64::NEG_INFINITY; 2];
            for seg in &edges[k..end] {
                for p in [seg.a, seg.b] {
                    for i in 0..2 {
                        lo[i] = lo[i].min(p[i]);
                        hi[i] = hi[i].max(p[i]);
                    }
                }
            }
            chunks.push(EdgeChunk {
                lo,
                hi,
                segments: k..end,
            });
            k = end;
        }
    }
    (edges, chunks)
}

#[derive(Clone, Copy, Debug)]
struct PairState {
    /// Check time at which the pair was last visited.
    last_seen_t_s: f64,
    in_contact: bool,
    ttc_at_last_seen_s: Option<f64>,
    min_gap_m: f64,
    t_min_gap_s: f64,
    min_ttc_s: Option<f64>,
    t_min_ttc_s: Option<f64>,
    tet_s: f64,
    collisions: u32,
}

#[derive(Clone, Copy, Debug)]
struct EdgeState {
    last_seen_t_s: f64,
    in_contact: bool,
}

/// Records collisions, gaps, TTC and edge contacts over a run; fed once per checked instant.
#[derive(Clone, Debug)]
pub struct SafetyMonitor {
    params: SafetyParams,
    lanes: Arc<LaneRoad>,
    edges: Vec<EdgeSegment>,
    edge_chunks: Vec<EdgeChunk>,
    pairs: BTreeMap<(VehicleId, VehicleId), PairState>,
    edge_states: BTreeMap<(VehicleId, RoadEdge), EdgeState>,
    collisions: Vec<CollisionEvent>,
    edge_contacts: Vec<EdgeContactEvent>,
    previous_t_s: Option<f64>,
    tet_s: f64,
    /// Per vehicle: its time exposed to a TTC below the threshold (`SafetySummary::vehicle_tet_s`).
    vehicle_tet_s: BTreeMap<VehicleId, f64>,
    checked_instants: u64,
    checked_duration_s: f64,
    ttc_not_converged: u64,
    report: SafetyStepReport,
    /// Ids from this one on are recorded traffic (`recorded_pairs`).
    recorded_from: Option<VehicleId>,
}

impl SafetyMonitor {
    /// A monitor for the road `lanes` with `params` (validated). The road-edge checks use the
    /// drivable area's outer edges ([`LaneRoad::outer_edges`]).
    pub fn new(params: SafetyParams, lanes: Arc<LaneRoad>) -> Result<Self, SafetyError> {
        params.validate()?;
        let (edges, edge_chunks) = edge_segments(&lanes);
        Ok(Self {
            params,
            lanes,
            edges,
            edge_chunks,
            pairs: BTreeMap::new(),
            edge_states: BTreeMap::new(),
            collisions: Vec::new(),
            edge_contacts: Vec::new(),
            previous_t_s: None,
            tet_s: 0.0,
            vehicle_tet_s: BTreeMap::new(),
            checked_instants: 0,
            checked_duration_s: 0.0,
            ttc_not_converged: 0,
            report: SafetyStepReport::default(),
            recorded_from: None,
        })
    }

    /// The parameters in use.
    pub fn params(&self) -> &SafetyParams {
        &self.params
    }

    /// Every collision episode so far, in time order.
    pub fn collision_events(&self) -> &[CollisionEvent] {
        &self.collisions
    }

    /// Every road-edge contact episode so far, in time order.
    pub fn edge_contact_events(&self) -> &[EdgeContactEvent] {
        &self.edge_contacts
    }

    /// Checks one instant `t_s` standing for the interval `dt_s` that follows it.
    ///
    /// `bodies` must be sorted by strictly increasing id; pairs are visited in id order
    /// (a < b), so the events come out in a deterministic order. `t_s` must be greater than
    /// the previous call's.
    pub fn check(
        &mut self,
        t_s: f64,
        bodies: &[BodyState],
        dt_s: f64,
    ) -> Result<&SafetyStepReport, SafetyError> {
        let time_ok = t_s.is_finite()
            && dt_s.is_finite()
            && dt_s >= 0.0
            && self.previous_t_s.is_none_or(|previous| t_s > previous);
        if !time_ok {
            return Err(SafetyError::InvalidTime {
                t_s,
                dt_s,
                previous_t_s: self.previous_t_s,
            });
        }
        for body in bodies {
            if let Some((field, value)) = body.first_invalid_field() {
                return Err(SafetyError::InvalidBody {
                    id: body.id,
                    field,
                    value,
                });
            }
        }
        for w in bodies.windows(2) {
            if w[0].id >= w[1].id {
                return Err(SafetyError::UnsortedBodies {
                    previous: w[0].id,
                    next: w[1].id,
                });
            }
        }

        let previous_t_s = self.previous_t_s;
        self.report.t_s = t_s;
        self.report.pairs.clear();
        self.report.new_collisions.clear();
        self.report.new_edge_contacts.clear();
        self.report.min_ttc_s = None;

        let radii_m: Vec<f64> = bodies.iter().map(BodyState::bounding_radius_m).collect();
        for (i, j, bounds) in self.followed_pairs(bodies, &radii_m) {
            self.check_pair(t_s, previous_t_s, dt_s, &bodies[i], &bodies[j], bounds)?;
        }
        if self.params.check_road_edges {
            let recorded_from = self.recorded_from;
            for body in bodies
                .iter()
                .filter(|b| recorded_from.is_none_or(|first| b.id < first))
            {
                self.check_edges(t_s, previous_t_s, body)?;
            }
        }

        if self
            .report
            .min_ttc_s
            .is_some_and(|ttc| ttc < self.params.ttc_threshold_s)
        {
            self.tet_s += dt_s;
        }
        self.add_vehicle_exposure(dt_s);
        self.collisions
            .extend(self.report.new_collisions.iter().cloned());
        self.edge_contacts
            .extend(self.report.new_edge_contacts.iter().cloned());
        self.previous_t_s = Some(t_s);
        self.checked_instants += 1;
        self.checked_duration_s += dt_s;
        Ok(&self.report)
    }

    /// Adds `dt_s` to the exposure of every vehicle with at least one pair below the TTC
    /// threshold at this instant (each vehicle once, however many of its pairs are).
    fn add_vehicle_exposure(&mut self, dt_s: f64) {
        let threshold_s = self.params.ttc_threshold_s;
        let mut exposed: Vec<VehicleId> = self
            .report
            .pairs
            .iter()
            .filter(|p| p.ttc_s.is_some_and(|ttc| ttc < threshold_s))
            .flat_map(|p| [p.id_a, p.id_b])
            .collect();
        exposed.sort_unstable();
        exposed.dedup();
        for id in exposed {
            *self.vehicle_tet_s.entry(id).or_insert(0.0) += dt_s;
        }
    }

    /// Whether the monitor follows a pair with these bounds at this instant (module doc).
    fn follows(&self, bounds: PairBounds) -> bool {
        bounds.gap_lower_bound_m
            <= self
                .params
                .pair_range_m
                .max(bounds.relative_speed_mps * self.params.ttc_horizon_s)
    }

    /// The pairs (indices into `bodies`, i < j) followed at this instant, with their bounds, in
    /// id order: from all pairs without the broad phase; with it, from every pair's X test up
    /// to [`SMALL_FLEET`] bodies and from the X sweep beyond. `radii_m` holds each body's
    /// bounding radius.
    fn followed_pairs(
        &self,
        bodies: &[BodyState],
        radii_m: &[f64],
    ) -> Vec<(usize, usize, PairBounds)> {
        let followed = |(i, j): (usize, usize)| {
            if self.skips_pair(bodies[i].id, bodies[j].id) {
                return None;
            }
            let bounds = pair_bounds(&bodies[i], radii_m[i], &bodies[j], radii_m[j]);
            self.follows(bounds).then_some((i, j, bounds))
        };
        let n = bodies.len();
        let all_pairs = (0..n).flat_map(|i| ((i + 1)..n).map(move |j| (i, j)));
        if !self.params.broad_phase {
            return all_pairs.filter_map(followed).collect();
        }
        let window_m = self.sweep_window_m(bodies);
        if n <= SMALL_FLEET {
            // The sweep's own X test on every pair, already in (i, j) order: the same pairs as
            // the sweep (|x_j − x_i| is exactly antisymmetric), without its sorts.
            return all_pairs
                .filter(|&(i, j)| (bodies[j].x_m - bodies[i].x_m).abs() <= window_m)
                .filter_map(followed)
                .collect();
        }
        let xs: Vec<f64> = bodies.iter().map(|b| b.x_m).collect();
        XSweep::new(&xs)
            .pairs_within_window(window_m)
            .into_iter()
            .filter_map(followed)
            .collect()
    }

    /// An X distance beyond which no pair is followed (module doc): a followed pair has
    /// `|Δx| ≤ centre distance ≤ r_a + r_b + max(range, |Δv| · horizon)`.
    fn sweep_window_m(&self, bodies: &[BodyState]) -> f64 {
        let mut radius_m: f64 = 0.0;
        let (mut vx_lo, mut vx_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut vy_lo, mut vy_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for b in bodies {
            radius_m = radius_m.max(b.bounding_radius_m());
            (vx_lo, vx_hi) = (vx_lo.min(b.vx_mps), vx_hi.max(b.vx_mps));
            (vy_lo, vy_hi) = (vy_lo.min(b.vy_mps), vy_hi.max(b.vy_mps));
        }
        let relative_speed_bound_mps = if bodies.is_empty() {
            0.0
        } else {
            (vx_hi - vx_lo).hypot(vy_hi - vy_lo)
        };
        let reach_m = self
            .params
            .pair_range_m
            .max(relative_speed_bound_mps * self.params.ttc_horizon_s);
        (reach_m + 2.0 * radius_m) * (1.0 + 1e-9) + 1e-6
    }

    /// The outcome so far.
    pub fn summary(&self) -> SafetySummary {
        let ttc_threshold_s = self.params.ttc_threshold_s;
        let gap_threshold_m = self.params.near_miss_gap_m;
        let close_call = |min_ttc_s: Option<f64>, min_gap_m: Option<f64>| {
            min_ttc_s.is_some_and(|t| t < ttc_threshold_s)
                || min_gap_m.is_some_and(|g| g < gap_threshold_m)
        };

        let mut pairs = Vec::with_capacity(self.pairs.len());
        let mut min_gap: Option<(f64, f64)> = None;
        let mut min_ttc: Option<(f64, f64)> = None;
        for (&(id_a, id_b), s) in &self.pairs {
            // A pair is created with an exact gap, so `min_gap_m` is always finite here.
            if min_gap
                .is_none_or(|(g, t)| s.min_gap_m < g || (s.min_gap_m == g && s.t_min_gap_s < t))
            {
                min_gap = Some((s.min_gap_m, s.t_min_gap_s));
            }
            if let (Some(ttc), Some(t_ttc)) = (s.min_ttc_s, s.t_min_ttc_s)
                && min_ttc.is_none_or(|(m, t)| ttc < m || (ttc == m && t_ttc < t))
            {
                min_ttc = Some((ttc, t_ttc));
            }
            pairs.push(PairSafety {
                id_a,
                id_b,
                min_gap_m: s.min_gap_m,
                t_min_gap_s: s.t_min_gap_s,
                min_ttc_s: s.min_ttc_s,
                t_min_ttc_s: s.t_min_ttc_s,
                tet_s: s.tet_s,
                collisions: s.collisions,
                near_miss: s.collisions == 0 && close_call(s.min_ttc_s, Some(s.min_gap_m)),
            });
        }
        let min_gap_m = min_gap.map(|(g, _)| g);
        let min_ttc_s = min_ttc.map(|(m, _)| m);
        let (min_gap_to_recorded_m, min_ttc_to_recorded_s) = self.recorded_figures(&pairs);
        SafetySummary {
            collisions_caused_by_replay: self
                .collisions
                .iter()
                .filter(|c| c.caused_by_replay)
                .count() as u32,
            min_gap_to_recorded_m,
            min_ttc_to_recorded_s,
            collisions: self.collisions.clone(),
            min_gap_m,
            t_min_gap_s: min_gap.map(|(_, t)| t),
            min_ttc_s,
            t_min_ttc_s: min_ttc.map(|(_, t)| t),
            near_miss: self.collisions.is_empty() && close_call(min_ttc_s, min_gap_m),
            tet_s: self.tet_s,
            vehicle_tet_s: self.vehicle_tet_s.iter().map(|(&id, &t)| (id, t)).collect(),
            edge_contacts: self.edge_contacts.clone(),
            pairs,
            checked_instants: self.checked_instants,
            checked_duration_s: self.checked_duration_s,
            ttc_not_converged: self.ttc_not_converged,
        }
    }
}
