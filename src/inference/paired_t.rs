//! The paired t-interval and t-test (Student 1908, "The probable error of a mean",
//! Biometrika 6:1–25) on per-instance differences `dᵢ = xᵢ − yᵢ` of two planners run on the
//! same instances.

use super::distributions::{student_t_two_sided_p, student_t_upper_quantile};
use super::{InferenceError, check_finite, two_sided_tail};
use crate::sweep::statistics::mean;

/// The paired t summary of `n` differences: their mean with its two-sided t-interval, and the
/// t-test of "mean difference = 0".
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PairedT {
    /// Number of differences.
    pub n: usize,
    /// Mean difference `d̄` (in the unit of the differences).
    pub mean: f64,
    /// Sample standard deviation `s` of the differences (n − 1 denominator).
    pub sd: f64,
    /// The `confidence` t-interval of the mean difference, `[low, high]`.
    pub ci: [f64; 2],
    /// The interval's confidence level, in (0, 1) (0.95 for a 95 % interval).
    pub confidence: f64,
    /// The t statistic `d̄ / (s/√n)`.
    pub t: f64,
    /// Degrees of freedom, `n − 1`.
    pub df: f64,
    /// Two-sided p-value of the t-test of mean 0.
    pub p_two_sided: f64,
}

/// The paired t-interval and t-test of `differences` (Student 1908):
///
/// ```text
/// d̄ = Σ dᵢ / n,   s² = Σ (dᵢ − d̄)² / (n − 1),   SE = s/√n,   df = n − 1
/// CI = d̄ ∓ t_(df, 1 − α/2) · SE           (α = 1 − confidence)
/// t  = d̄ / SE,    p = P(|T_df| ≥ |t|) = I_(df/(df + t²))(df/2, 1/2)
/// ```
///
/// the same figures as `scipy.stats.ttest_1samp(d, 0)` and its `confidence_interval`.
///
/// **All differences equal** (`s = 0`, e.g. two planners that behave identically, or a
/// constant offset): the interval is the point `[d̄, d̄]`, and the t statistic and p-value are
/// their limits as `s → 0`: `t = ±∞`, `p = 0` when `d̄ ≠ 0` (as scipy), and `t = 0`, `p = 1`
/// when every difference is 0 (scipy gives NaN for 0/0; "no difference at all" is no
/// evidence against the null). In that case `d̄` is the common value exactly, not a rounded
/// sum. An infinite `t` serialises to JSON `null` with serde_json.
///
/// Errors: fewer than two differences, a NaN or infinite difference, a confidence outside
/// (0, 1).
pub fn paired_t(differences: &[f64], confidence: f64) -> Result<PairedT, InferenceError> {
    let n = differences.len();
    if n < 2 {
        return Err(InferenceError::TooFewValues { needed: 2, got: n });
    }
    check_finite(differences)?;
    let tail = two_sided_tail(confidence)?;
    let df = (n - 1) as f64;
    let first = differences[0];
    if differences.iter().all(|&d| d == first) {
        let (t, p_two_sided) = if first == 0.0 {
            (0.0, 1.0)
        } else {
            (f64::INFINITY.copysign(first), 0.0)
        };
        return Ok(PairedT {
            n,
            mean: first,
            sd: 0.0,
            ci: [first, first],
            confidence,
            t,
            df,
            p_two_sided,
        });
    }
    let mean = mean(differences).ok_or(InferenceError::TooFewValues { needed: 2, got: n })?;
    let sum_of_squares: f64 = differences.iter().map(|d| (d - mean) * (d - mean)).sum();
    let sd = (sum_of_squares / df).sqrt();
    let standard_error = sd / (n as f64).sqrt();
    let t = mean / standard_error;
    let half_width = student_t_upper_quantile(tail, df) * standard_error;
    Ok(PairedT {
        n,
        mean,
        sd,
        ci: [mean - half_width, mean + half_width],
        confidence,
        t,
        df,
        p_two_sided: student_t_two_sided_p(t, df),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn textbook_example() {
        // d = 0, 1, 2, 1: mean 1, s² = (1 + 0 + 1 + 0)/3 = 2/3, SE = s/2, t = 1/SE.
        let d = [0.0, 1.0, 2.0, 1.0];
        let r = paired_t(&d, 0.95).unwrap();
        assert_eq!((r.n, r.mean, r.df), (4, 1.0, 3.0));
        let sd = (2.0f64 / 3.0).sqrt();
        assert!((r.sd - sd).abs() < 1e-15);
        assert!((r.t - 1.0 / (sd / 2.0)).abs() < 1e-14);
        // t_(3, 0.975) = 3.1824463052837078 (scipy.stats.t.ppf(0.975, 3), scipy 1.17.1).
        let half = 3.182_446_305_283_707_8 * sd / 2.0;
        assert!((r.ci[0] - (1.0 - half)).abs() < 1e-13 && (r.ci[1] - (1.0 + half)).abs() < 1e-13);
        assert!(r.p_two_sided > 0.05 && r.p_two_sided < 0.2);
    }

    #[test]
    fn all_equal_differences_have_a_point_interval() {
        let r = paired_t(&[0.3; 8], 0.95).unwrap();
        assert_eq!((r.mean, r.sd, r.ci), (0.3, 0.0, [0.3, 0.3]));
        assert_eq!((r.t, r.p_two_sided), (f64::INFINITY, 0.0));
        let r = paired_t(&[-2.0; 3], 0.9).unwrap();
        assert_eq!((r.t, r.p_two_sided), (f64::NEG_INFINITY, 0.0));
        let r = paired_t(&[0.0; 5], 0.95).unwrap();
        assert_eq!(
            (r.mean, r.sd, r.ci, r.t, r.p_two_sided),
            (0.0, 0.0, [0.0, 0.0], 0.0, 1.0)
        );
    }

    #[test]
    fn bad_input_is_an_error() {
        assert_eq!(
            paired_t(&[], 0.95),
            Err(InferenceError::TooFewValues { needed: 2, got: 0 })
        );
        assert_eq!(
            paired_t(&[1.0], 0.95),
            Err(InferenceError::TooFewValues { needed: 2, got: 1 })
        );
        assert_eq!(
            paired_t(&[1.0, f64::NAN, 2.0], 0.95),
            Err(InferenceError::NonFinite { index: 1 })
        );
        assert_eq!(
            paired_t(&[1.0, 2.0, f64::NEG_INFINITY], 0.95),
            Err(InferenceError::NonFinite { index: 2 })
        );
        for c in [0.0, 1.0, 95.0, f64::NAN] {
            assert!(matches!(
                paired_t(&[1.0, 2.0], c),
                Err(InferenceError::InvalidConfidence(_))
            ));
        }
    }
}
