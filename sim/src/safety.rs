//! Exact safety checks between vehicle bodies and against the road edges, with
//! parry3d 0.31.
//!
//! What is measured, at every instant the world loop hands to [`SafetyMonitor::check`]:
//! - **collision**: exact intersection of two vehicles' oriented boxes (parry's SAT for
//!   cuboids); one [`CollisionEvent`] per pair and *contact episode* (a pair that stays in
//!   contact over many instants counts once; separating and touching again counts again);
//! - **road-edge contact**: a box touching an edge of [`MergeRoad`] (the straight upper edge and
//!   the piecewise lower edge of Eq. 3, taper included) or lying entirely beyond it; one
//!   [`EdgeContactEvent`] per vehicle, edge and episode;
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
//! # Cost
//! Pairs are culled with bounding circles, and the culling never changes a result:
//! - the exact intersection test runs only when the circles overlap;
//! - the exact distance runs only when the circle bound could lower the pair's minimum gap
//!   (otherwise the instant's gap is reported as a lower bound);
//! - the shape cast runs only when the circles could meet within the horizon at the pair's
//!   relative speed (`gap_lower_bound ≤ |v_b − v_a| · horizon`).

use std::collections::BTreeMap;

use mergesim_types::InvalidParameter;
use parry3d::math::{Pose, Vector};
use parry3d::query::{self, ShapeCastOptions, ShapeCastStatus};
use parry3d::shape::{Cuboid, Segment};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use planner::{MergeRoad, PlannerError, VehicleId};

pub use crate::body_state::BodyState;

/// Thresholds of the safety metrics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SafetyParams {
    /// A TTC below this is a conflict (s). 1.5 s is the FHWA SSAM default.
    pub ttc_threshold_s: f64,
    /// A gap below this is a near miss even if the TTC is not short (m).
    pub near_miss_gap_m: f64,
    /// Look-ahead of the TTC shape cast (s); beyond it, TTC is `None`.
    pub ttc_horizon_s: f64,
    /// Whether to check vehicles against the road edges.
    pub check_road_edges: bool,
    /// Boxes closer than this count as touching (m). Rapier resolves contacts speculatively:
    /// two rigid bodies that hit each other (or a barrier) come to rest touching, not
    /// overlapping, so a physical collision shows as an exact parry distance of about zero
    /// rather than as an intersection. 0 = intersection only.
    pub contact_tolerance_m: f64,
}

impl Default for SafetyParams {
    fn default() -> Self {
        Self {
            ttc_threshold_s: 1.5,
            near_miss_gap_m: 0.5,
            ttc_horizon_s: 10.0,
            check_road_edges: true,
            contact_tolerance_m: 0.01,
        }
    }
}

impl SafetyParams {
    /// Checks every field; the error names the field.
    pub fn validate(&self) -> Result<(), SafetyError> {
        let positive = [
            ("ttc_threshold_s", self.ttc_threshold_s),
            ("ttc_horizon_s", self.ttc_horizon_s),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(SafetyError::InvalidParameter(InvalidParameter::new(
                    format!("safety.{name}"),
                    value,
                    "must be finite and > 0",
                )));
            }
        }
        if !(self.contact_tolerance_m.is_finite()
            && (0.0..=0.1).contains(&self.contact_tolerance_m))
        {
            return Err(SafetyError::InvalidParameter(InvalidParameter::new(
                "safety.contact_tolerance_m",
                self.contact_tolerance_m,
                "must lie in [0, 0.1] m",
            )));
        }
        if !(self.near_miss_gap_m.is_finite() && self.near_miss_gap_m >= 0.0) {
            return Err(SafetyError::InvalidParameter(InvalidParameter::new(
                "safety.near_miss_gap_m",
                self.near_miss_gap_m,
                "must be finite and >= 0",
            )));
        }
        if self.ttc_horizon_s < self.ttc_threshold_s {
            return Err(SafetyError::InvalidParameter(InvalidParameter::new(
                "safety.ttc_horizon_s",
                self.ttc_horizon_s,
                format!(
                    "must be >= safety.ttc_threshold_s = {}",
                    self.ttc_threshold_s
                ),
            )));
        }
        Ok(())
    }
}

/// Everything that can go wrong in the safety checks. Never a panic.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SafetyError {
    /// A parameter is out of range.
    #[error(transparent)]
    InvalidParameter(#[from] InvalidParameter),
    /// The road geometry is invalid.
    #[error("invalid road: {0}")]
    InvalidRoad(#[from] PlannerError),
    /// A body state is NaN, infinite or has a non-positive dimension.
    #[error("invalid body state of vehicle {id}: {field} = {value}")]
    InvalidBody {
        /// The vehicle.
        id: VehicleId,
        /// The field.
        field: &'static str,
        /// Its value.
        value: f64,
    },
    /// Bodies must be sorted by strictly increasing id.
    #[error("bodies not sorted by strictly increasing id: {previous} then {next}")]
    UnsortedBodies {
        /// The id before.
        previous: VehicleId,
        /// The id after it.
        next: VehicleId,
    },
    /// Check times must increase, and `dt_s` must be finite and non-negative.
    #[error("invalid check time t = {t_s} s, dt = {dt_s} s (previous t = {previous_t_s:?} s)")]
    InvalidTime {
        /// The time given.
        t_s: f64,
        /// The interval given.
        dt_s: f64,
        /// The previous check time.
        previous_t_s: Option<f64>,
    },
    /// parry does not support a shape pair (cannot happen with boxes and segments).
    #[error("geometric query unsupported: {0}")]
    Unsupported(String),
}

/// Which road edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RoadEdge {
    /// The straight upper (left) edge, Y = Y_u.
    Upper,
    /// The piecewise lower (right) edge of Eq. 3, including the merge taper.
    Lower,
}

/// Start of a collision episode between two vehicles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CollisionEvent {
    /// The checked instant at which the boxes were first found intersecting (s).
    pub t_s: f64,
    /// Smaller id of the pair.
    pub id_a: VehicleId,
    /// Larger id of the pair.
    pub id_b: VehicleId,
    /// Time of first contact between the previous checked instant and `t_s`, from the TTC at
    /// the previous instant (exact for constant velocities); `None` if the pair was already
    /// intersecting or not closing then.
    pub t_contact_estimate_s: Option<f64>,
    /// Relative speed |v_b − v_a| at `t_s` (m/s).
    pub relative_speed_mps: f64,
}

impl CollisionEvent {
    /// Whether vehicle `id` is one of the two.
    pub fn involves(&self, id: VehicleId) -> bool {
        self.id_a == id || self.id_b == id
    }

    /// One line for logs; `names[id]` names vehicle `id` (falls back to the id).
    pub fn describe(&self, names: &[String]) -> String {
        let name = |id: VehicleId| {
            names
                .get(id as usize)
                .cloned()
                .unwrap_or_else(|| format!("vehicle {id}"))
        };
        let contact = self
            .t_contact_estimate_s
            .map(|t| format!(", first contact at {t:.3} s"))
            .unwrap_or_default();
        format!(
            "collision {} / {} at t = {:.3} s{contact}, relative speed {:.2} m/s",
            name(self.id_a),
            name(self.id_b),
            self.t_s,
            self.relative_speed_mps
        )
    }
}

/// Start of an episode of a vehicle touching or crossing a road edge.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EdgeContactEvent {
    /// The checked instant (s).
    pub t_s: f64,
    /// The vehicle.
    pub id: VehicleId,
    /// Which edge.
    pub edge: RoadEdge,
}

/// Safety figures of one pair of vehicles over the run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairSafety {
    /// Smaller id.
    pub id_a: VehicleId,
    /// Larger id.
    pub id_b: VehicleId,
    /// Minimum exact gap between the boxes (m); 0 when they touched.
    pub min_gap_m: f64,
    /// When the minimum gap was first reached (s).
    pub t_min_gap_s: f64,
    /// Minimum TTC (s); `None` if never closing within the horizon.
    pub min_ttc_s: Option<f64>,
    /// When the minimum TTC was first reached (s).
    pub t_min_ttc_s: Option<f64>,
    /// Time with TTC below the threshold (s).
    pub tet_s: f64,
    /// Number of collision episodes.
    pub collisions: u32,
    /// Near miss: min TTC or min gap below its threshold, without a collision.
    pub near_miss: bool,
}

/// The safety outcome of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SafetySummary {
    /// Every collision episode, in time order (pairs in id order within an instant).
    pub collisions: Vec<CollisionEvent>,
    /// Minimum exact gap between any two boxes (m); `None` with fewer than two vehicles.
    pub min_gap_m: Option<f64>,
    /// When `min_gap_m` was first reached (s).
    pub t_min_gap_s: Option<f64>,
    /// Minimum TTC over all pairs and instants (s).
    pub min_ttc_s: Option<f64>,
    /// When `min_ttc_s` was first reached (s).
    pub t_min_ttc_s: Option<f64>,
    /// Near miss: (min TTC < threshold or min gap < gap threshold) and no collision.
    pub near_miss: bool,
    /// Time during which at least one pair had TTC below the threshold (s).
    pub tet_s: f64,
    /// Every road-edge contact episode, in time order.
    pub edge_contacts: Vec<EdgeContactEvent>,
    /// Per pair, in id order.
    pub pairs: Vec<PairSafety>,
    /// Number of checked instants.
    pub checked_instants: u64,
    /// Sum of the `dt_s` of the checked instants (s).
    pub checked_duration_s: f64,
    /// Shape casts that stopped without converging (their TTC is parry's conservative value).
    pub ttc_not_converged: u64,
}

/// What one pair looked like at the last checked instant.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairInstant {
    /// Smaller id.
    pub id_a: VehicleId,
    /// Larger id.
    pub id_b: VehicleId,
    /// Whether the boxes intersect.
    pub intersecting: bool,
    /// Gap between the boxes (m): exact, or a lower bound when `gap_is_lower_bound`.
    pub gap_m: f64,
    /// True when the pair was far enough apart that only the bounding-circle bound was computed.
    pub gap_is_lower_bound: bool,
    /// TTC (s), `None` if not touching within the horizon at constant velocity.
    pub ttc_s: Option<f64>,
}

/// The result of one [`SafetyMonitor::check`].
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SafetyStepReport {
    /// The instant (s).
    pub t_s: f64,
    /// Every pair, in id order.
    pub pairs: Vec<PairInstant>,
    /// Collision episodes that started at this instant.
    pub new_collisions: Vec<CollisionEvent>,
    /// Edge contact episodes that started at this instant.
    pub new_edge_contacts: Vec<EdgeContactEvent>,
    /// Smallest TTC at this instant.
    pub min_ttc_s: Option<f64>,
}

/// One straight piece of a road edge, in world coordinates.
#[derive(Clone, Copy, Debug)]
struct EdgeSegment {
    edge: RoadEdge,
    a: [f64; 2],
    b: [f64; 2],
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
    road: MergeRoad,
    edges: Vec<EdgeSegment>,
    pairs: BTreeMap<(VehicleId, VehicleId), PairState>,
    edge_states: BTreeMap<(VehicleId, RoadEdge), EdgeState>,
    collisions: Vec<CollisionEvent>,
    edge_contacts: Vec<EdgeContactEvent>,
    previous_t_s: Option<f64>,
    tet_s: f64,
    checked_instants: u64,
    checked_duration_s: f64,
    ttc_not_converged: u64,
    report: SafetyStepReport,
}

impl SafetyMonitor {
    /// A monitor for `road` with `params` (both validated).
    pub fn new(params: SafetyParams, road: &MergeRoad) -> Result<Self, SafetyError> {
        params.validate()?;
        road.validate()?;
        let mut edges = Vec::new();
        for (edge, polyline) in [
            (RoadEdge::Upper, road.upper_edge_polyline()),
            (RoadEdge::Lower, road.lower_edge_polyline()),
        ] {
            for w in polyline.windows(2) {
                edges.push(EdgeSegment {
                    edge,
                    a: w[0],
                    b: w[1],
                });
            }
        }
        Ok(Self {
            params,
            road: road.clone(),
            edges,
            pairs: BTreeMap::new(),
            edge_states: BTreeMap::new(),
            collisions: Vec::new(),
            edge_contacts: Vec::new(),
            previous_t_s: None,
            tet_s: 0.0,
            checked_instants: 0,
            checked_duration_s: 0.0,
            ttc_not_converged: 0,
            report: SafetyStepReport::default(),
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

        for (i, a) in bodies.iter().enumerate() {
            for b in &bodies[i + 1..] {
                self.check_pair(t_s, previous_t_s, dt_s, a, b)?;
            }
        }
        if self.params.check_road_edges {
            for body in bodies {
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
        self.collisions
            .extend(self.report.new_collisions.iter().cloned());
        self.edge_contacts
            .extend(self.report.new_edge_contacts.iter().cloned());
        self.previous_t_s = Some(t_s);
        self.checked_instants += 1;
        self.checked_duration_s += dt_s;
        Ok(&self.report)
    }

    fn check_pair(
        &mut self,
        t_s: f64,
        previous_t_s: Option<f64>,
        dt_s: f64,
        a: &BodyState,
        b: &BodyState,
    ) -> Result<(), SafetyError> {
        let ttc_horizon_s = self.params.ttc_horizon_s;
        let ttc_threshold_s = self.params.ttc_threshold_s;
        let centre_distance_m = (b.x_m - a.x_m).hypot(b.y_m - a.y_m);
        let gap_lower_bound_m =
            (centre_distance_m - a.bounding_radius_m() - b.bounding_radius_m()).max(0.0);
        let rel_vx_mps = b.vx_mps - a.vx_mps;
        let rel_vy_mps = b.vy_mps - a.vy_mps;
        let relative_speed_mps = rel_vx_mps.hypot(rel_vy_mps);

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

    fn check_edges(
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
        SafetySummary {
            collisions: self.collisions.clone(),
            min_gap_m,
            t_min_gap_s: min_gap.map(|(_, t)| t),
            min_ttc_s,
            t_min_ttc_s: min_ttc.map(|(_, t)| t),
            near_miss: self.collisions.is_empty() && close_call(min_ttc_s, min_gap_m),
            tet_s: self.tet_s,
            edge_contacts: self.edge_contacts.clone(),
            pairs,
            checked_instants: self.checked_instants,
            checked_duration_s: self.checked_duration_s,
            ttc_not_converged: self.ttc_not_converged,
        }
    }
}

/// The body's cuboid and its pose relative to the origin (`origin_x_m`, `origin_y_m`, 0):
/// resting on the road plane, rotated by the yaw about +Z.
fn local_box(body: &BodyState, origin_x_m: f64, origin_y_m: f64) -> (Pose, Cuboid) {
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

    #[test]
    fn params_validation_names_the_field() {
        let bad = SafetyParams {
            ttc_horizon_s: 1.0,
            ..SafetyParams::default()
        };
        let err = bad.validate().unwrap_err().to_string();
        assert!(err.contains("ttc_horizon_s"), "{err}");
        let json = r#"{"ttc_threshold_s": 2.0, "bogus": 1}"#;
        assert!(serde_json::from_str::<SafetyParams>(json).is_err());
        let partial: SafetyParams = serde_json::from_str(r#"{"ttc_threshold_s": 2.0}"#).unwrap();
        assert_eq!(partial.ttc_horizon_s, SafetyParams::default().ttc_horizon_s);
    }
}
