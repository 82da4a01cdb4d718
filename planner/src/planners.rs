//! The planners behind one interface: PF-CS, PF-SP, PF-ISO, and the controls PF-SP-EQ10 and
//! PF-ISO-PRED.
//!
//! Every planner generates the path the same way (Eqs. 1–9); they differ in the speeds:
//!
//! | kind          | speeds                                                                 |
//! |---------------|------------------------------------------------------------------------|
//! | `pf-cs`       | constant V_target (Wang et al. 2022 baseline)                          |
//! | `pf-sp`       | risk-aware speed planning without V2V (the paper's baseline, after Wu et al. 2022): travel time, target speed and w_R Σ U along its own path, U the others' path field (Eq. 4 with the path-field parameters) at their predicted positions; the risk only lowers the speed (capped at max(V_target, v_0 − a_max t)) |
//! | `pf-sp-eq10`  | Eq. 10 with w3 = 0: travel time, target speed, friction limit (a control: on a straight road it equals PF-CS) |
//! | `pf-iso`      | Eq. 10 with the received shared local paths (a prediction for a neighbour whose SLP is missing or stale) |
//! | `pf-iso-pred` | Eq. 10 with every neighbour predicted (no V2V): what V2V buys         |
//!
//! One planning cycle: universal field from the perceived neighbours (Eqs. 1–5) → N gradient
//! steps of L_s = v·Δt_plan (Eqs. 6–7) → constrained cubic fit in the vehicle frame (Eqs. 8–9)
//! → speeds → the path to track (cubic sampled at the waypoints, with speeds and absolute times
//! t_i = t_0 + Σ_{j ≤ i} Δs_j / v_j) and the SLP to broadcast.

use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::cubic_fit::{FitMethod, fit_path_cubic};
use crate::derived_params::DerivedParams;
use crate::error::PlannerError;
use crate::fallback::{FallbackInput, fallback_plan};
use crate::following::{V2vLossFallback, following_cap_in_lane_frame_mps};
use crate::lane_road_field::LaneRoadGeometry;
use crate::local_path::local_path_adaptive;
use crate::others::{
    RoleRules, arc_length_term, fixed_waypoint_term, gather_others, has_fresh_shared_path,
};
use crate::params::{PlannerParams, SlpReading};
use crate::polyline::Polyline;
use crate::potential_field::{GridSpec, PotentialField};
pub use crate::request::{PlanRequest, validate_request};
use crate::speed_optimisation::{
    Aggregate, SpeedOptimiser, SpeedProblem, SpeedTerm, friction_speed_limits,
};
use crate::stop_and_go::{apply_caps, segment_time_s, stop_and_go_caps_mps};
use crate::types::{FallbackReason, PathPoint, Plan, SharedLocalPath, VehicleState};
use mergesim_types::lanes::{LaneId, LaneRoad};
use std::sync::Arc;

/// Which planner a vehicle runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PlannerKind {
    /// PF path, constant speed V_target.
    PfCs,
    /// PF path, risk-aware speed planning without V2V (the paper's baseline).
    PfSp,
    /// PF path, Eq. 10 with w3 = 0 (a control planner).
    PfSpEq10,
    /// PF path, interactive speed optimisation with the shared local paths (Eq. 10).
    PfIso,
    /// Like PF-ISO with the others' paths predicted (no V2V).
    PfIsoPred,
}

impl PlannerKind {
    /// Every kind, in a fixed order.
    pub const ALL: [PlannerKind; 5] = [
        PlannerKind::PfCs,
        PlannerKind::PfSp,
        PlannerKind::PfSpEq10,
        PlannerKind::PfIso,
        PlannerKind::PfIsoPred,
    ];

    /// The kebab-case name (`pf-cs`, `pf-sp`, `pf-sp-eq10`, `pf-iso`, `pf-iso-pred`).
    pub fn name(&self) -> &'static str {
        match self {
            PlannerKind::PfCs => "pf-cs",
            PlannerKind::PfSp => "pf-sp",
            PlannerKind::PfSpEq10 => "pf-sp-eq10",
            PlannerKind::PfIso => "pf-iso",
            PlannerKind::PfIsoPred => "pf-iso-pred",
        }
    }

    /// Whether it uses the interaction term of Eq. 10 (and so the `interaction_*` parameters).
    pub fn is_interactive(&self) -> bool {
        matches!(self, PlannerKind::PfIso | PlannerKind::PfIsoPred)
    }
}

impl std::fmt::Display for PlannerKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for PlannerKind {
    type Err = PlannerError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        PlannerKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| PlannerError::UnknownName {
                what: "planner".into(),
                given: s.into(),
                valid: PlannerKind::ALL.map(|k| k.name()).join(", "),
            })
    }
}

/// What the last planning cycle did (for statistics and the benchmark).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PlanStats {
    /// Convex speed solves of the cycle.
    pub speed_solves: usize,
    /// Whether the speed optimisation's SCP stopped at `max_scp_iterations` before meeting its
    /// tolerance (`SpeedSolution::stopped_at_iteration_cap`).
    pub speed_stopped_at_iteration_cap: bool,
    /// Whether the cubic fit needed the QP (a bound was active).
    pub cubic_qp: bool,
    /// Number of other vehicles in the interaction term.
    pub interacting_vehicles: usize,
    /// Whether the plan is a fallback.
    pub fallback: bool,
    /// Whether PF-ISO planned without any fresh shared path around it (V2V lost), with
    /// `v2v_loss_fallback = risk-aware-following` (`following` module).
    pub v2v_degraded: bool,
    /// Whether the speeds were capped for stop and go (`stop_and_go` module): only then may
    /// they be below `min_speed_mps`.
    pub stop_and_go: bool,
}

/// A potential-field planner of one vehicle. Holds the last good plan (for the fallback and
/// to warm-start the speed optimisation) and the speed optimiser's solver.
#[derive(Clone, Debug)]
pub struct PfPlanner {
    kind: PlannerKind,
    params: PlannerParams,
    /// Each part's settings, derived from `params` once, at construction (`derived_params`).
    derived: DerivedParams,
    /// The road as lanes, prepared once (`lane_road_field.rs`), shareable between planners.
    road: Arc<LaneRoadGeometry>,
    last_good: Option<Plan>,
    optimiser: SpeedOptimiser,
    stats: PlanStats,
    /// The lane (index) the vehicle was settled in at its last cycle, for the lane-end rule's
    /// walls (`LaneRoadGeometry::lane_end_walls`).
    settled_lane: Option<usize>,
    /// Time of the first planning cycle (s): V2V counts as lost only once a shared path could
    /// have arrived (`max_shared_path_age_s` after it).
    first_plan_s: Option<f64>,
    /// Whether the last cycle was a stop-and-go cycle (`stop_and_go` module).
    stopping: bool,
    /// The lanes (indices) the vehicle drives along, e.g. to its goal
    /// ([`PfPlanner::with_route`]); empty: the lane-end rule.
    route: Vec<usize>,
}

fn non_finite(what: &str) -> PlannerError {
    PlannerError::NonFinite { what: what.into() }
}

/// Speed of `path` at absolute time `t_s`: that of the next point (a point carries the speed
/// reached there, i.e. of the step ending at it).
fn speed_at_time(path: &[PathPoint], t_s: f64) -> Option<f64> {
    let k = path.partition_point(|p| p.t_s <= t_s);
    path.get(k.min(path.len().saturating_sub(1)))
        .map(|p| p.speed_mps)
}

/// A cycle's failure, with whatever was computed before it (for the fallback).
struct CycleFailure {
    error: PlannerError,
    waypoints: Option<Vec<[f64; 2]>>,
}

impl PfPlanner {
    /// A planner of `kind` on the road `lanes` (a [`LaneRoad`], or one shared through an
    /// `Arc`: the simulator passes the road its observations carry, `Observation::lanes`);
    /// its geometry is prepared here, once. Fails if the parameters are invalid (a
    /// [`LaneRoad`] is valid once built).
    pub fn new(
        kind: PlannerKind,
        params: PlannerParams,
        lanes: impl Into<Arc<LaneRoad>>,
    ) -> Result<Self, PlannerError> {
        Self::on_geometry(
            kind,
            params,
            Arc::new(LaneRoadGeometry::shared(lanes.into())),
        )
    }

    /// A planner of `kind` on a road already prepared (several planners can share one).
    pub fn on_geometry(
        kind: PlannerKind,
        params: PlannerParams,
        road: Arc<LaneRoadGeometry>,
    ) -> Result<Self, PlannerError> {
        params.validate()?;
        Ok(Self {
            kind,
            derived: DerivedParams::new(&params),
            params,
            road,
            settled_lane: None,
            last_good: None,
            optimiser: SpeedOptimiser::new(),
            stats: PlanStats::default(),
            first_plan_s: None,
            stopping: false,
            route: Vec::new(),
        })
    }

    /// The planner following `route` (lane ids in driving order, e.g. the shortest route to a
    /// goal): Eq. 1's target lane is the route's
    /// ([`LaneRoadGeometry::route_target_lane`]) instead of the lane-end rule's.
    pub fn with_route(mut self, route: &[LaneId]) -> Self {
        self.route = self.road.route_indices(route);
        self
    }

    /// Eq. 1's target on the route, if the planner has one.
    fn follow_route(&self, field: &mut PotentialField<'_>, ego: &VehicleState) {
        if self.route.is_empty() {
            return;
        }
        let p = [ego.x_m, ego.y_m];
        let target = self
            .road
            .route_target_lane(p, &self.route, self.params.target_lookahead_m);
        field.target_lane = target;
        field.target_s_m = self.road.s_m(target, p) + self.params.target_lookahead_m;
    }

    /// The planner kind.
    pub fn kind(&self) -> PlannerKind {
        self.kind
    }

    /// The parameters.
    pub fn params(&self) -> &PlannerParams {
        &self.params
    }

    /// The road, as lanes.
    pub fn road(&self) -> &LaneRoad {
        self.road.road()
    }

    /// The road, shared (to build another planner on it).
    pub fn shared_road(&self) -> Arc<LaneRoad> {
        self.road.shared_road().clone()
    }

    /// The road's prepared geometry, shared (to build another planner on it).
    pub fn road_geometry(&self) -> &Arc<LaneRoadGeometry> {
        &self.road
    }

    /// What the last cycle did.
    pub fn last_stats(&self) -> PlanStats {
        self.stats
    }

    /// The last plan that was not a fallback.
    pub fn last_good_plan(&self) -> Option<&Plan> {
        self.last_good.as_ref()
    }

    /// The universal field of the request's ego (Eq. 5).
    /// The lane-end rule's walls are those of the last cycle's settled lane.
    pub fn field<'s>(&'s self, req: &PlanRequest<'_>) -> PotentialField<'s> {
        let mut field = PotentialField::new(
            &self.derived.field,
            &self.road,
            req.ego_id,
            &req.ego,
            &req.ego_shape,
            req.neighbours,
        );
        self.follow_route(&mut field, &req.ego);
        if self.params.lane_end_walls {
            field.road.walls = self
                .road
                .lane_end_walls(&req.ego, 0.5 * req.ego_shape.width_m, self.settled_lane)
                .0;
        }
        field
    }

    /// Universal potential U at (x, y) seen by the ego of `req` (for drawing the field). It
    /// includes the attractive bowl ½ λ (X − X_tar)², which dominates far from the ego: see
    /// [`PfPlanner::repulsive_field_value`] for a drawing of the road and obstacles only.
    pub fn field_value(&self, req: &PlanRequest<'_>, x_m: f64, y_m: f64) -> f64 {
        self.field(req).value(x_m, y_m)
    }

    /// U_LD + U_RE + Σ U_OB at (x, y) seen by the ego of `req` (no attraction).
    pub fn repulsive_field_value(&self, req: &PlanRequest<'_>, x_m: f64, y_m: f64) -> f64 {
        self.field(req).repulsive_value(x_m, y_m)
    }

    /// U on a grid (row after row, cell centres; see [`GridSpec`]).
    pub(crate) fn field_grid(
        &self,
        req: &PlanRequest<'_>,
        spec: &GridSpec,
        include_attractive: bool,
    ) -> Result<Vec<f64>, PlannerError> {
        self.field(req).grid(spec, include_attractive)
    }

    /// One planning cycle. Never panics. `Err` only for invalid input (non-finite state,
    /// non-positive shape, …); a solver failure or a non-finite intermediate returns `Ok` with
    /// `plan.fallback = Some(..)`: a comfortable deceleration along the last good path.
    pub fn plan(&mut self, req: &PlanRequest<'_>) -> Result<Plan, PlannerError> {
        validate_request(req)?;
        self.stats = PlanStats::default();
        self.first_plan_s.get_or_insert(req.time_s);
        match self.plan_cycle(req) {
            Ok(plan) => {
                self.last_good = Some(plan.clone());
                Ok(plan)
            }
            Err(failure) => {
                let reason = match &failure.error {
                    PlannerError::NonFinite { what } => FallbackReason::NonFinite(what.clone()),
                    other => FallbackReason::SolverFailed(other.to_string()),
                };
                self.stats.fallback = true;
                let input = FallbackInput {
                    time_s: req.time_s,
                    ego_id: req.ego_id,
                    ego: &req.ego,
                    ego_shape: &req.ego_shape,
                    last_good: self.last_good.as_ref(),
                    waypoints: failure.waypoints.as_deref(),
                };
                Ok(fallback_plan(&self.params, &input, reason))
            }
        }
    }

    /// The non-convex speed term of `kind` and its weight (None for PF-SP-EQ10, or with nobody
    /// around).
    /// Also returns the number of other vehicles it considers.
    fn speed_term(
        &self,
        kind: PlannerKind,
        req: &PlanRequest<'_>,
        line: &Polyline,
        waypoints: &[[f64; 2]],
    ) -> (Option<Box<dyn SpeedTerm>>, f64, usize) {
        let params = &self.params;
        let derived = &self.derived;
        let (use_shared_paths, weight) = match kind {
            PlannerKind::PfCs | PlannerKind::PfSpEq10 => return (None, 0.0, 0),
            PlannerKind::PfSp => (false, params.risk_weight),
            PlannerKind::PfIso => (true, params.interaction_weight),
            PlannerKind::PfIsoPred => (false, params.interaction_weight),
        };
        let others = gather_others(
            params.max_shared_path_age_s,
            &self.road,
            req,
            use_shared_paths,
            params.prediction,
        );
        let count = others.len();
        if others.is_empty() || weight <= 0.0 {
            return (None, weight, count);
        }
        let term: Box<dyn SpeedTerm> = if kind == PlannerKind::PfSp {
            // Risk along its own path: the path field, roles from the order now.
            let rules = RoleRules {
                rear_only: false,
                from_order_now: params.roles_from_order_now,
            };
            Box::new(arc_length_term(
                &derived.horizon,
                &derived.field.obstacles,
                rules,
                Aggregate::Linear,
                req,
                &others,
                line,
                &self.road,
            ))
        } else {
            let rules = RoleRules {
                rear_only: params.interaction_rear_only,
                from_order_now: params.roles_from_order_now,
            };
            match params.interaction_slp_reading {
                SlpReading::ArcLength => Box::new(arc_length_term(
                    &derived.horizon,
                    &derived.interaction_field,
                    rules,
                    Aggregate::LogFloored {
                        floor: params.interaction_floor,
                    },
                    req,
                    &others,
                    line,
                    &self.road,
                )),
                SlpReading::FixedWaypoints => Box::new(fixed_waypoint_term(
                    &derived.horizon,
                    &derived.interaction_field,
                    params.interaction_floor,
                    rules,
                    req,
                    &others,
                    waypoints,
                    &self.road,
                )),
            }
        };
        (Some(term), weight, count)
    }

    fn plan_cycle(&mut self, req: &PlanRequest<'_>) -> Result<Plan, CycleFailure> {
        // The lane-end rule's walls: settled in a lane that goes on, now or at the last cycle.
        let (walls, settled_lane) = if self.params.lane_end_walls {
            self.road
                .lane_end_walls(&req.ego, 0.5 * req.ego_shape.width_m, self.settled_lane)
        } else {
            (Vec::new(), None)
        };
        self.settled_lane = settled_lane;
        let params = &self.params;
        let derived = &self.derived;
        let n = derived.horizon.waypoint_count;
        let fail = |error: PlannerError, waypoints: Option<Vec<[f64; 2]>>| CycleFailure {
            error,
            waypoints,
        };

        // Eqs. 1–7: waypoints by gradient steps.
        let mut field = PotentialField::new(
            &derived.field,
            &self.road,
            req.ego_id,
            &req.ego,
            &req.ego_shape,
            req.neighbours,
        );
        self.follow_route(&mut field, &req.ego);
        field.road.walls = walls;
        let step_m = params.step_length_m(req.ego.speed_mps);
        let time_per_step_s = if params.predict_obstacles_in_path {
            params.step_time_s
        } else {
            0.0
        };
        let waypoints = local_path_adaptive(
            &field,
            [req.ego.x_m, req.ego.y_m],
            step_m,
            n,
            params.max_substep_m,
            params.substep_max_turn_rad,
            time_per_step_s,
        );
        if waypoints.iter().flatten().any(|v| !v.is_finite()) {
            return Err(fail(non_finite("potential-field waypoints"), None));
        }

        // Eqs. 8–9: cubic in the vehicle frame.
        let (cubic, xis) = fit_path_cubic(
            &derived.cubic,
            [req.ego.x_m, req.ego.y_m],
            req.ego.yaw_rad,
            &waypoints,
        )
        .map_err(|e| fail(e, Some(waypoints.clone())))?;
        self.stats.cubic_qp = cubic.method == FitMethod::Qp;
        let points: Vec<[f64; 2]> = xis.iter().map(|xi| cubic.world_point(*xi)).collect();
        if points.iter().flatten().any(|v| !v.is_finite()) {
            return Err(fail(non_finite("fitted path"), Some(waypoints)));
        }
        let line = Polyline::with_start([req.ego.x_m, req.ego.y_m], points.iter().copied());
        let segment_lengths_m = line.segment_lengths_m();
        // Stop and go (`stop_and_go` module): caps down to 0 behind a slow or stopped vehicle;
        // None in moving traffic, which is then planned exactly as without it.
        let stop_caps_mps = stop_and_go_caps_mps(
            &derived.stop_and_go,
            &self.road,
            req,
            &points,
            self.stopping,
        );
        self.stopping = stop_caps_mps.is_some();
        self.stats.stop_and_go = self.stopping;

        // V2V lost (`following` module): a PF-ISO cycle without any fresh shared path around
        // plans its speeds as PF-SP, capped at the safe following speed.
        let heard_for_s = req.time_s - self.first_plan_s.unwrap_or(req.time_s);
        let degraded = self.kind == PlannerKind::PfIso
            && params.v2v_loss_fallback == V2vLossFallback::RiskAwareFollowing
            && heard_for_s > params.max_shared_path_age_s
            && req.neighbours.iter().any(|n| n.id != req.ego_id)
            && !has_fresh_shared_path(params.max_shared_path_age_s, req);
        self.stats.v2v_degraded = degraded;
        let speed_kind = if degraded {
            PlannerKind::PfSp
        } else {
            self.kind
        };

        // Speeds (Eq. 10, or PF-SP's risk-aware problem).
        let speeds_mps = match speed_kind {
            PlannerKind::PfCs => {
                let mut speeds_mps = vec![
                    req.target_speed_mps
                        .clamp(params.min_speed_mps, params.speed_limit_mps);
                    n
                ];
                if let Some(caps_mps) = &stop_caps_mps {
                    apply_caps(&mut speeds_mps, caps_mps);
                }
                speeds_mps
            }
            kind => {
                let mut max_speeds_mps = friction_speed_limits(
                    |xi| cubic.curvature_per_m(xi),
                    &xis,
                    req.mu,
                    params.speed_limit_mps,
                );
                let slows_only = match kind {
                    // Risk-aware speed planning lowers the speed for risk; it never races.
                    PlannerKind::PfSp => true,
                    _ => kind.is_interactive() && params.interaction_slows_only,
                };
                if slows_only {
                    // The non-convex term may only slow the vehicle: cap at V_target, or at a
                    // comfortable deceleration from the current speed if that is higher.
                    let decel_mps = derived.horizon.max_speed_change_mps;
                    for (i, v) in max_speeds_mps.iter_mut().enumerate() {
                        let from_now = req.ego.speed_mps - decel_mps * (i + 1) as f64;
                        *v = v.min(req.target_speed_mps.max(from_now));
                    }
                }
                if degraded
                    && let Some(cap_mps) = following_cap_in_lane_frame_mps(
                        &derived.following,
                        &self.road,
                        req.ego_id,
                        &req.ego,
                        &req.ego_shape,
                        req.neighbours,
                        &points,
                    )
                {
                    // Reached no faster than at a_max from the current speed (feasible).
                    let decel_mps = derived.horizon.max_speed_change_mps;
                    for (i, v) in max_speeds_mps.iter_mut().enumerate() {
                        let from_now = req.ego.speed_mps - decel_mps * (i + 1) as f64;
                        *v = v.min(cap_mps.max(from_now).max(params.min_speed_mps));
                    }
                }
                if let Some(caps_mps) = &stop_caps_mps {
                    apply_caps(&mut max_speeds_mps, caps_mps);
                }
                let (term, weight, count) = self.speed_term(kind, req, &line, &waypoints);
                self.stats.interacting_vehicles = count;
                // Warm start: the last good plan's speeds at the same absolute times.
                let guess: Option<Vec<f64>> = self.last_good.as_ref().and_then(|last| {
                    (1..=n)
                        .map(|i| {
                            speed_at_time(
                                &last.path,
                                req.time_s + (i as f64 - 0.5) * derived.horizon.step_time_s,
                            )
                        })
                        .collect()
                });
                let problem = SpeedProblem {
                    current_speed_mps: req.ego.speed_mps,
                    target_speed_mps: req.target_speed_mps,
                    segment_lengths_m: &segment_lengths_m,
                    max_speeds_mps: &max_speeds_mps,
                    initial_guess_mps: guess.as_deref(),
                    interaction: term.as_deref(),
                    interaction_weight: weight,
                };
                let solution = self
                    .optimiser
                    .solve(&derived.speed, &problem)
                    .map_err(|e| fail(e, Some(waypoints.clone())))?;
                self.stats.speed_solves = solution.solves;
                self.stats.speed_stopped_at_iteration_cap = solution.stopped_at_iteration_cap;
                let mut speeds_mps = solution.speeds_mps;
                if let Some(caps_mps) = &stop_caps_mps {
                    // Below v_min, the cap itself (`stop_and_go` module doc, item 3).
                    apply_caps(&mut speeds_mps, caps_mps);
                }
                speeds_mps
            }
        };

        // The path to track and the SLP: t_i = t_0 + Σ Δs_j / v_j. The profile starts at the
        // current speed v_0 at t_0 and reaches v_i at point i (the speed of step i is its value
        // at the step's end, as the bound |v_i − v_{i−1}| ≤ a_max Δt assumes): the first point
        // carries v_0, not v_1, so the plan is no step a car cannot follow.
        let mut path = Vec::with_capacity(n + 1);
        let mut t_s = req.time_s;
        path.push(PathPoint {
            x_m: req.ego.x_m,
            y_m: req.ego.y_m,
            speed_mps: req.ego.speed_mps.max(0.0),
            t_s,
        });
        for (k, p) in points.iter().enumerate() {
            t_s += if stop_caps_mps.is_some() {
                segment_time_s(segment_lengths_m[k], speeds_mps[k])
            } else {
                segment_lengths_m[k] / speeds_mps[k]
            };
            path.push(PathPoint {
                x_m: p[0],
                y_m: p[1],
                speed_mps: speeds_mps[k],
                t_s,
            });
        }
        if path.iter().any(|p| {
            !(p.x_m.is_finite()
                && p.y_m.is_finite()
                && p.speed_mps.is_finite()
                && p.t_s.is_finite())
        }) {
            return Err(fail(non_finite("planned path"), Some(waypoints)));
        }
        let shared = SharedLocalPath::from_path(
            req.ego_id,
            req.time_s,
            req.ego_shape,
            req.ego.speed_mps,
            &path,
        );
        Ok(Plan {
            waypoints,
            path,
            cubic: cubic.coefficients,
            cubic_x_scale_m: cubic.x_scale_m,
            shared,
            fallback: None,
        })
    }
}
