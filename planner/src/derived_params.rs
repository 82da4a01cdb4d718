//! Each part of the planning cycle's own settings, derived from [`PlannerParams`] in this one
//! place.
//!
//! `PlannerParams` is the flat, serialisable set of every tunable number (scenarios, TOML,
//! Python). The parts of the cycle each read only a few of them, so each has its own small
//! struct, defined where it is used (as Clarabel keeps its settings per solver
//! implementation), and built here by a `From<&PlannerParams>`:
//!
//! | struct                                   | used by                                                  | paper        |
//! |------------------------------------------|----------------------------------------------------------|--------------|
//! | [`AttractionParams`]                     | Eq. 1 (`lane_road_field::LaneAttraction`)                | Eq. 1        |
//! | [`RoadFieldParams`]                      | Eqs. 2–3 (`lane_road_field::LaneRoadField`)              | Eqs. 2–3     |
//! | [`UniversalFieldParams`]                 | the universal field (`potential_field::PotentialField`)  | Eqs. 1–5     |
//! | [`PlanHorizon`]                          | the time slots of the plan and of the speed terms        | Eqs. 7, 10   |
//! | [`CubicLimits`], [`CubicFitParams`]      | the cubic fit (`cubic_fit`)                              | Eqs. 8–9     |
//! | [`SpeedOptimiserParams`]                 | the speed optimisation (`speed_optimisation`)            | Eq. 10       |
//! | [`FollowingParams`]                      | the safe-following cap (`following`)                     | —            |
//! | `StopAndGoParams`                      | stop and go (`stop_and_go`)                              | —            |
//!
//! The obstacle fields (Eq. 4) keep [`ObstacleFieldParams`] (`PlannerParams::path_field`,
//! `PlannerParams::interaction_field`). A planner builds all of them once, at construction
//! (`DerivedParams`), and passes each part its own; values derived from several fields
//! (a_max·Δt_plan, j_max·Δt_plan², the obstacle fields, the solver settings) are computed
//! here only.

use crate::attractive_field::AttractionParams;
use crate::clarabel_setup::ProgramSettings;
use crate::cubic_fit::{CubicFitParams, CubicLimits};
use crate::following::FollowingParams;
use crate::obstacle_field::ObstacleFieldParams;
use crate::params::PlannerParams;
use crate::potential_field::UniversalFieldParams;
use crate::road_field::RoadFieldParams;
use crate::speed_optimisation::{
    ScpSettings, SpeedBounds, SpeedObjectiveParams, SpeedOptimiserParams,
};
use crate::stop_and_go::StopAndGoParams;

/// The time slots of a plan: N waypoints Δt_plan apart (Eq. 7; slot i of Eq. 10's speed terms
/// is at t_0 + i·Δt_plan), and the speed change a_max·Δt_plan a slot allows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanHorizon {
    /// N, the number of waypoints and of speeds (`waypoint_count`).
    pub waypoint_count: usize,
    /// Δt_plan, the time per slot (s; `step_time_s`).
    pub step_time_s: f64,
    /// a_max·Δt_plan, the most the speed changes over one slot at the acceleration bound of
    /// Eq. 10 (m/s; `max_accel_mps2` · `step_time_s`).
    pub max_speed_change_mps: f64,
}

/// Every part's settings of one planner, built once from its [`PlannerParams`] (module doc).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct DerivedParams {
    /// The time slots.
    pub(crate) horizon: PlanHorizon,
    /// The universal field of the path (Eqs. 1–5), with the path's obstacle fields.
    pub(crate) field: UniversalFieldParams,
    /// The interaction term's obstacle fields (Eq. 10's U_SLP).
    pub(crate) interaction_field: ObstacleFieldParams,
    /// The cubic fit (Eqs. 8–9).
    pub(crate) cubic: CubicFitParams,
    /// The speed optimisation (Eq. 10).
    pub(crate) speed: SpeedOptimiserParams,
    /// The safe-following cap of PF-ISO without V2V.
    pub(crate) following: FollowingParams,
    /// Stop and go.
    pub(crate) stop_and_go: StopAndGoParams,
}

impl DerivedParams {
    /// Each part's settings from `params`.
    pub(crate) fn new(params: &PlannerParams) -> Self {
        Self {
            horizon: params.into(),
            field: params.into(),
            interaction_field: params.interaction_field(),
            cubic: params.into(),
            speed: params.into(),
            following: params.into(),
            stop_and_go: params.into(),
        }
    }
}

impl From<&PlannerParams> for PlanHorizon {
    fn from(p: &PlannerParams) -> Self {
        Self {
            waypoint_count: p.waypoint_count,
            step_time_s: p.step_time_s,
            max_speed_change_mps: p.max_accel_mps2 * p.step_time_s,
        }
    }
}

impl From<&PlannerParams> for AttractionParams {
    fn from(p: &PlannerParams) -> Self {
        Self {
            gain_per_m2: p.attractive_gain_per_m2,
            lookahead_m: p.target_lookahead_m,
        }
    }
}

impl From<&PlannerParams> for RoadFieldParams {
    fn from(p: &PlannerParams) -> Self {
        Self {
            lane_amplitude: p.lane_amplitude,
            lane_sigma_m: p.lane_sigma_m,
            edge_gain_m2: p.edge_gain_m2,
            edge_clamp_distance_m: p.edge_clamp_distance_m,
        }
    }
}

impl From<&PlannerParams> for UniversalFieldParams {
    fn from(p: &PlannerParams) -> Self {
        Self {
            attraction: p.into(),
            road: p.into(),
            lane_end_walls: p.lane_end_walls,
            obstacles: p.path_field(),
        }
    }
}

impl From<&PlannerParams> for CubicLimits {
    fn from(p: &PlannerParams) -> Self {
        Self {
            max_offset_m: p.cubic_max_offset_m,
            max_heading_rad: p.cubic_max_heading_rad,
            max_curvature_per_m: p.cubic_max_curvature_per_m,
            max_curvature_rate_per_m2: p.cubic_max_curvature_rate_per_m2,
        }
    }
}

impl From<&PlannerParams> for CubicFitParams {
    fn from(p: &PlannerParams) -> Self {
        Self {
            origin_weight: p.cubic_origin_weight,
            limits: p.into(),
            solver_max_iterations: p.solver_max_iterations,
            solver_tolerance: p.solver_tolerance,
        }
    }
}

impl From<&PlannerParams> for SpeedObjectiveParams {
    fn from(p: &PlannerParams) -> Self {
        Self {
            travel_time_weight: p.travel_time_weight,
            speed_deviation_weight: p.speed_deviation_weight,
        }
    }
}

impl From<&PlannerParams> for SpeedBounds {
    fn from(p: &PlannerParams) -> Self {
        Self {
            min_speed_mps: p.min_speed_mps,
            accel_bound_enabled: p.accel_bound_enabled,
            accel_step_mps: PlanHorizon::from(p).max_speed_change_mps,
            jerk_bound_enabled: p.jerk_bound_enabled,
            jerk_step_mps: p.max_jerk_mps3 * p.step_time_s * p.step_time_s,
        }
    }
}

impl From<&PlannerParams> for ScpSettings {
    fn from(p: &PlannerParams) -> Self {
        Self {
            trust_region_mps: p.trust_region_mps,
            max_iterations: p.max_scp_iterations,
            relative_tolerance: p.scp_relative_tolerance,
            stall_trust_region_mps: p.scp_stall_trust_region_mps,
            step_tolerance_mps: p.scp_step_tolerance_mps,
        }
    }
}

impl From<&PlannerParams> for SpeedOptimiserParams {
    fn from(p: &PlannerParams) -> Self {
        Self {
            objective: p.into(),
            bounds: p.into(),
            scp: p.into(),
            program: p.speed_program,
            solver: ProgramSettings {
                max_iterations: p.solver_max_iterations,
                tolerance: p.solver_tolerance,
                scaling_and_refinement: false,
            },
        }
    }
}

impl From<&PlannerParams> for FollowingParams {
    fn from(p: &PlannerParams) -> Self {
        Self {
            decel_mps2: p.max_accel_mps2,
            reaction_s: p.following_reaction_s,
            standstill_gap_m: p.following_standstill_gap_m,
            lateral_margin_m: p.following_lateral_margin_m,
        }
    }
}

impl From<&PlannerParams> for StopAndGoParams {
    fn from(p: &PlannerParams) -> Self {
        Self {
            speed_threshold_mps: p.stop_and_go_speed_mps,
            following: p.into(),
            horizon: p.into(),
        }
    }
}
