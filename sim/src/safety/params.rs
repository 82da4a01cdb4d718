//! Thresholds of the safety metrics, and the errors of the safety checks.

use mergesim_types::bounds::Bound;
use mergesim_types::{InvalidParameter, VehicleId, bounds};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use planner::PlannerError;

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
    /// A pair is followed at an instant when its bounding-circle gap bound is within this
    /// distance (m), or within the distance it could close at its current relative speed over
    /// `ttc_horizon_s` (where a TTC can be finite). So a pair's minimum gap is exact whenever
    /// it falls below this range; a pair never followed is not listed. 250 m, the perception
    /// range's criterion (docs/parameters.md).
    pub pair_range_m: f64,
    /// Find the followed pairs with the X sweep (`crate::spatial`), O(N log N + k); `false`
    /// visits every pair, O(N²), the reference the sweep is tested against (same results).
    pub broad_phase: bool,
}

/// Default of [`SafetyParams::pair_range_m`] (m).
pub const DEFAULT_PAIR_RANGE_M: f64 = 250.0;

impl Default for SafetyParams {
    fn default() -> Self {
        Self {
            ttc_threshold_s: 1.5,
            near_miss_gap_m: 0.5,
            ttc_horizon_s: 10.0,
            check_road_edges: true,
            contact_tolerance_m: 0.01,
            pair_range_m: DEFAULT_PAIR_RANGE_M,
            broad_phase: true,
        }
    }
}

/// Allowed ranges of the safety thresholds (README "Limits").
pub const SAFETY_BOUNDS: &[Bound] = &[
    Bound::above("ttc_threshold_s", 0.0, 60.0, "s"),
    Bound::above("ttc_horizon_s", 0.0, 60.0, "s"),
    Bound::closed("contact_tolerance_m", 0.0, 0.1, "m"),
    Bound::closed("near_miss_gap_m", 0.0, 10.0, "m"),
    Bound::closed("pair_range_m", 10.0, 1e5, "m"),
];

impl SafetyParams {
    /// Checks every field against [`SAFETY_BOUNDS`] and the horizon against the threshold; the
    /// error names the field.
    pub(crate) fn validate(&self) -> Result<(), SafetyError> {
        bounds::check_all(
            "safety",
            SAFETY_BOUNDS,
            &[
                ("ttc_threshold_s", self.ttc_threshold_s),
                ("ttc_horizon_s", self.ttc_horizon_s),
                ("contact_tolerance_m", self.contact_tolerance_m),
                ("near_miss_gap_m", self.near_miss_gap_m),
                ("pair_range_m", self.pair_range_m),
            ],
        )?;
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

#[cfg(test)]
mod tests {
    use super::*;

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
