//! Inference for paired comparisons: the statistics a study report gives for two planners run
//! on the same instances (`merge_sim study`). Pure functions of the values they are given, no
//! randomness, no I/O; each concept in its own file:
//!
//! - [`distributions`]: Student's t, the standard normal and the binomial (CDFs and quantiles,
//!   on the regularised incomplete beta function);
//! - `paired_t` ([`paired_t()`], [`PairedT`]): the paired t-interval and t-test on
//!   per-instance differences (Student 1908);
//! - `wilcoxon`: the Wilcoxon signed-rank test (Wilcoxon 1945), as `scipy.stats.wilcoxon`;
//! - `mcnemar`: the exact McNemar test on a paired 2×2 table (McNemar 1947);
//! - `paired_proportions`: Newcombe's (1998) method 10 interval for the difference of paired
//!   proportions;
//! - `holm` ([`holm()`]): Holm's (1979) step-down adjustment of a family of p-values.
//!
//! Percentiles and means of a sample are not here: they are `crate::sweep::statistics`
//! (`mean`, `nearest_rank_percentile`, `wilson_interval`), which this module reuses.
//!
//! Every result is checked against scipy / statsmodels on fixed data
//! (`tests/inference_reference.rs`, fixture written by `scripts/inference_reference.py`).

pub mod distributions;
pub(crate) mod holm;
pub(crate) mod mcnemar;
pub(crate) mod paired_proportions;
pub(crate) mod paired_t;
pub(crate) mod wilcoxon;

pub use holm::holm;
pub use mcnemar::{Discordance, mcnemar_exact};
pub use paired_proportions::{PairedProportionDifference, newcombe_paired_difference};
pub use paired_t::{PairedT, paired_t};
pub use wilcoxon::{Wilcoxon, WilcoxonMethod, wilcoxon_signed_rank};

/// Why a statistic cannot be computed from the values given.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum InferenceError {
    /// Fewer values than the statistic needs (a t-interval needs two differences).
    #[error("{needed} values needed, {got} given")]
    TooFewValues {
        /// The smallest number of values the statistic accepts.
        needed: usize,
        /// The number given.
        got: usize,
    },
    /// A value is NaN or infinite (its position in the input).
    #[error("value {index} is not a finite number")]
    NonFinite {
        /// Index of the first non-finite value.
        index: usize,
    },
    /// A confidence level outside the open interval (0, 1).
    #[error("confidence level {0} is not strictly between 0 and 1")]
    InvalidConfidence(f64),
    /// A 2×2 table with no pairs at all (no proportion is defined).
    #[error("the paired table is empty (no pairs)")]
    EmptyTable,
}

/// The index of the first non-finite value, as an error.
fn check_finite(values: &[f64]) -> Result<(), InferenceError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(InferenceError::NonFinite { index }),
        None => Ok(()),
    }
}

/// The two-sided tail probability `(1 − confidence) / 2` of a confidence level in (0, 1).
fn two_sided_tail(confidence: f64) -> Result<f64, InferenceError> {
    if confidence > 0.0 && confidence < 1.0 {
        Ok((1.0 - confidence) / 2.0)
    } else {
        Err(InferenceError::InvalidConfidence(confidence))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn confidence_must_be_inside_the_open_unit_interval() {
        for bad in [0.0, 1.0, -0.5, 1.5, f64::NAN, f64::INFINITY] {
            assert!(
                matches!(
                    two_sided_tail(bad),
                    Err(InferenceError::InvalidConfidence(_))
                ),
                "{bad}"
            );
        }
        assert_eq!(two_sided_tail(0.5), Ok(0.25));
    }

    #[test]
    fn the_first_non_finite_value_is_named() {
        assert_eq!(check_finite(&[1.0, 2.0]), Ok(()));
        assert_eq!(
            check_finite(&[1.0, f64::NAN, f64::INFINITY]),
            Err(InferenceError::NonFinite { index: 1 })
        );
    }
}
