//! Parameters of merge sequencing (`pf-iso-seq`, [`super::SequencedPlanner`]): the control
//! zone, the crossing headways, the rear-end safety distance, the acceleration bound and the
//! message timeout. Every default follows a stated criterion (docs/parameters.md, "Merge
//! sequencing"); none was tuned on a scenario.

use mergesim_types::bounds::{Bound, check_all};
use serde::{Deserialize, Serialize};

use crate::error::PlannerError;

/// Merge sequencing's parameters (`[sim.planners.pf-iso-seq]` in a scenario file).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SequencingParams {
    /// L: length of the control zone upstream of the merging zone's entry, measured along the
    /// through lane (m). 150 m: with the built-in road's 100 m merge section the zone spans
    /// 250 m, the simulator's default perception range, so every car in it perceives every
    /// other (and hears it: the default V2V range is 300 m).
    pub control_zone_length_m: f64,
    /// δ: minimum time headway between consecutive crossing times when both cars come from the
    /// same lane (s). 2 s: the time gap the PF planners already keep
    /// (`obstacle_time_gap_s`, `interaction_time_gap_s`).
    pub headway_s: f64,
    /// δ_side: the headway when the predecessor in the queue comes from the other lane (s).
    /// δ + ρ = 3 s: the follower only sees the merging car as its leader once it cuts in, so it
    /// is given one reaction time on top of the same-lane gap.
    pub side_headway_s: f64,
    /// δ_safe of the rear-end constraint gap ≥ δ_safe + ρ·v: bumper gap kept at standstill (m);
    /// 2 m, the PF planners' `following_standstill_gap_m`.
    pub standstill_gap_m: f64,
    /// ρ of the rear-end constraint (s); 1 s, the PF planners' `following_reaction_s`.
    pub reaction_time_s: f64,
    /// u_max: bound on the profile's acceleration |u| (m/s²); 3 m/s², the PF planners'
    /// `max_accel_mps2` (well inside the friction limit μ g ≈ 7.8 m/s² at μ = 0.8). Braking
    /// for the rear-end constraint may go beyond it, up to the vehicle's braking limit.
    pub max_accel_mps2: f64,
    /// A car ahead is "in the same lane" for the rear-end constraint when its lateral distance
    /// is below the half-widths plus this margin (m); 0.5 m, the PF planners'
    /// `following_lateral_margin_m`.
    pub lateral_margin_m: f64,
    /// A car of the queue not heard for longer than this keeps its slot until then, and is
    /// dropped after (s). 1 s: twice the V2V default `stale_after_s` (0.5 s), so one lost
    /// message never drops a car.
    pub message_timeout_s: f64,
    /// Time step of the constrained profile's forward integration (s); 0.05 s, half the
    /// default planning period.
    pub profile_step_s: f64,
}

impl Default for SequencingParams {
    fn default() -> Self {
        Self {
            control_zone_length_m: 150.0,
            headway_s: 2.0,
            side_headway_s: 3.0,
            standstill_gap_m: 2.0,
            reaction_time_s: 1.0,
            max_accel_mps2: 3.0,
            lateral_margin_m: 0.5,
            message_timeout_s: 1.0,
            profile_step_s: 0.05,
        }
    }
}

/// Allowed ranges of [`SequencingParams`] (README "Limits", `merge_sim limits`).
pub const SEQUENCING_BOUNDS: &[Bound] = &[
    Bound::closed("control_zone_length_m", 10.0, 2000.0, "m"),
    Bound::above("headway_s", 0.0, 20.0, "s"),
    Bound::above("side_headway_s", 0.0, 20.0, "s"),
    Bound::closed("standstill_gap_m", 0.0, 50.0, "m"),
    Bound::closed("reaction_time_s", 0.0, 5.0, "s"),
    Bound::above("max_accel_mps2", 0.0, 20.0, "m/s²"),
    Bound::closed("lateral_margin_m", 0.0, 5.0, "m"),
    Bound::above("message_timeout_s", 0.0, 60.0, "s"),
    Bound::closed("profile_step_s", 0.001, 1.0, "s"),
];

impl SequencingParams {
    /// Checks every value against [`SEQUENCING_BOUNDS`]; the error names the field.
    pub fn validate(&self) -> Result<(), PlannerError> {
        check_all(
            "",
            SEQUENCING_BOUNDS,
            &[
                ("control_zone_length_m", self.control_zone_length_m),
                ("headway_s", self.headway_s),
                ("side_headway_s", self.side_headway_s),
                ("standstill_gap_m", self.standstill_gap_m),
                ("reaction_time_s", self.reaction_time_s),
                ("max_accel_mps2", self.max_accel_mps2),
                ("lateral_margin_m", self.lateral_margin_m),
                ("message_timeout_s", self.message_timeout_s),
                ("profile_step_s", self.profile_step_s),
            ],
        )?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_a_bad_value_is_named() {
        SequencingParams::default().validate().unwrap();
        let bad = SequencingParams {
            side_headway_s: -1.0,
            ..SequencingParams::default()
        };
        let e = bad.validate().unwrap_err();
        assert_eq!(
            e.invalid_parameter().map(|p| p.name.as_str()),
            Some("side_headway_s")
        );
    }
}
