//! The two named parameter sets of every planner: `paper` (the paper's literal reading wherever
//! it can run) and `mergesim` (our improvements, the default).
//!
//! Both sets share every number the paper does not give (N, Δt_plan, the weights, the cubic's
//! bounds, …): those are fixed by the criteria in `docs/parameters.md`, which do not depend on
//! which planner comes out ahead. They differ only in readings of the paper's equations:
//!
//! | field | `paper` | `mergesim` | what the improvement fixes |
//! |---|---|---|---|
//! | `obstacle_heading_form` | `paper-correlation` (C1/C2 as printed) | `rotation` | the printed form tilts the ellipse by ≈ ψσ_y/σ_x, not ψ |
//! | `obstacle_min_distance_length` | `wheelbase` | `body-length` | at a wheelbase's distance the bodies overlap |
//! | `obstacle_min_distance_by_side` | false | true | ahead of a slower car the printed D_min is the clamp: the faster car may cut in at contact distance |
//! | `obstacle_time_gap_s` | 0 | 2 s | two cars at equal speed may follow bumper to bumper |
//! | `predict_obstacles_in_path` | false | true | a path stepped against where the others are *now* meets a leader's field head-on and flips sides from cycle to cycle |
//! | `lane_end_walls` | false | true | a car beside the ending lane can be pushed into it by another's field (the lane-end rule) |
//! | `max_substep_m`, `substep_max_turn_rad` | one step per waypoint | 1 m, adaptive | an 8 m step jumps the 1 m wide divider ridge and bounces off the edge's wall |
//! | `interaction_slp_reading` | `fixed-waypoints` | `arc-length` | speed enters only through D_min(v): the term cannot tell where a slower car will be |
//! | `interaction_time_gap_s` | 0 | 2 s | as the path field's |
//! | `interaction_rear_only`, `roles_from_order_now` | false, false | true, true | who keeps the gap (the follower), decided once from the order now for predicted vehicles |
//! | `prediction` | `constant-velocity` | `lane-following` | a car 0.02 rad off the road axis is predicted a lane off after 160 m |
//! | `v2v_loss_fallback` | `interact-with-predictions` | `risk-aware-following` | without any shared path the interaction term on predictions lets two cars side by side each expect the other to yield (the paper says nothing about losing V2V) |
//!
//! Each row's cost, measured on single runs, is in `docs/reproduction_history.md`.

use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::PlannerError;
use crate::following::V2vLossFallback;
use crate::obstacle_field::{HeadingForm, MinDistanceLength};
use crate::params::{PlannerParams, SlpReading};
use crate::prediction::PredictionModel;

/// A named parameter set (module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ParameterSet {
    /// The paper's literal reading wherever it can run.
    Paper,
    /// Our improvements (the default).
    #[default]
    Mergesim,
}

impl ParameterSet {
    /// Every set, in a fixed order.
    pub(crate) const ALL: [ParameterSet; 2] = [ParameterSet::Paper, ParameterSet::Mergesim];

    /// The name used on the command line and in scenario files.
    pub fn name(self) -> &'static str {
        match self {
            ParameterSet::Paper => "paper",
            ParameterSet::Mergesim => "mergesim",
        }
    }

    /// The planner parameters of this set.
    pub fn planner_params(self) -> PlannerParams {
        match self {
            ParameterSet::Mergesim => PlannerParams::default(),
            ParameterSet::Paper => PlannerParams {
                obstacle_heading_form: HeadingForm::PaperCorrelation,
                obstacle_min_distance_length: MinDistanceLength::Wheelbase,
                obstacle_min_distance_by_side: false,
                obstacle_time_gap_s: 0.0,
                predict_obstacles_in_path: false,
                lane_end_walls: false,
                // One gradient step per waypoint for any L_s below 1 km (Eq. 7 as printed).
                max_substep_m: 1000.0,
                substep_max_turn_rad: 0.0,
                interaction_slp_reading: SlpReading::FixedWaypoints,
                interaction_time_gap_s: 0.0,
                interaction_rear_only: false,
                roles_from_order_now: false,
                prediction: PredictionModel::ConstantVelocity,
                v2v_loss_fallback: V2vLossFallback::InteractWithPredictions,
                // U_SLP is "calculated like Eq. 4": the same ε, d_lat and f as the path field.
                interaction_epsilon: PlannerParams::default().obstacle_epsilon,
                interaction_lateral_safety_m: PlannerParams::default().obstacle_lateral_safety_m,
                interaction_fraction_at_min_distance: PlannerParams::default()
                    .obstacle_fraction_at_min_distance,
                ..PlannerParams::default()
            },
        }
    }
}

impl std::fmt::Display for ParameterSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ParameterSet {
    type Err = PlannerError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        ParameterSet::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| PlannerError::UnknownName {
                what: "parameter set".into(),
                given: s.into(),
                valid: ParameterSet::ALL.map(|p| p.name()).join(", "),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_sets_are_valid_and_differ_only_in_readings() {
        let paper = ParameterSet::Paper.planner_params();
        let ours = ParameterSet::Mergesim.planner_params();
        paper.validate().unwrap();
        ours.validate().unwrap();
        // Every number the paper does not give is shared.
        assert_eq!(paper.waypoint_count, ours.waypoint_count);
        assert_eq!(paper.step_time_s, ours.step_time_s);
        assert_eq!(paper.interaction_weight, ours.interaction_weight);
        assert_eq!(paper.risk_weight, ours.risk_weight);
        assert_eq!(paper.obstacle_epsilon, ours.obstacle_epsilon);
        assert_ne!(paper, ours);
    }

    #[test]
    fn names_round_trip_and_unknown_names_list_the_valid_ones() {
        for set in ParameterSet::ALL {
            assert_eq!(set.name().parse::<ParameterSet>().unwrap(), set);
        }
        let err = "literal".parse::<ParameterSet>().unwrap_err().to_string();
        assert!(err.contains("paper") && err.contains("mergesim"), "{err}");
    }
}
