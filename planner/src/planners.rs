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

use std::sync::Arc;

use mergesim_types::lanes::{LaneId, LaneRoad};
use mergesim_types::{FallbackReason, VehicleState};

use crate::Plan;
use crate::derived_params::DerivedParams;
use crate::error::PlannerError;
use crate::fallback::{FallbackInput, fallback_plan};
use crate::lane_road_field::LaneRoadGeometry;
use crate::params::PlannerParams;
use crate::planner_kind::PlannerKind;
use crate::potential_field::{GridSpec, PotentialField};
use crate::request::{PlanRequest, validate_request};
use crate::speed_optimisation::SpeedOptimiser;

mod plan_cycle;

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
    /// The road as lanes, prepared once (`lane_road_field/geometry.rs`), shareable between planners.
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
}
