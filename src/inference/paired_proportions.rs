//! The confidence interval for the difference of two paired proportions (e.g. the collision
//! rates of two planners run on the same instances): Newcombe (1998), "Improved confidence
//! intervals for the difference between binomial proportions based on paired data",
//! Statistics in Medicine 17:2635–2650, method 10.

use super::mcnemar::Discordance;
use super::{InferenceError, two_sided_tail};
use crate::inference::distributions::normal_upper_quantile;
use crate::sweep::statistics::wilson_interval;

/// The method name written in reports.
pub const NEWCOMBE_METHOD_10: &str =
    "Newcombe (1998) method 10: Wilson score intervals combined, phi continuity-corrected";

/// The difference of two paired proportions with its confidence interval.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PairedProportionDifference {
    /// Number of pairs.
    pub n: u64,
    /// Proportion of pairs with the event in the first planner's run, `(both + only_first)/n`.
    pub first: f64,
    /// Proportion with the event in the second planner's run, `(both + only_second)/n`.
    pub second: f64,
    /// `first − second = (only_first − only_second)/n`.
    pub difference: f64,
    /// The `confidence` interval of the difference, `[low, high]`.
    pub ci: [f64; 2],
    /// The interval's confidence level, in (0, 1).
    pub confidence: f64,
    /// How the interval was computed (`NEWCOMBE_METHOD_10`).
    pub method: &'static str,
}

/// Newcombe's (1998) method 10 interval for `θ = p₁ − p₂` from a paired table
/// (a = both, b = only_first, c = only_second, d = neither, n = a + b + c + d):
///
/// ```text
/// p₁ = (a + b)/n,  p₂ = (a + c)/n,  θ̂ = p₁ − p₂ = (b − c)/n
/// [l₁, u₁], [l₂, u₂]: the Wilson score intervals of p₁ and p₂ (Wilson 1927; Newcombe's
///                      method 3), z = z_(1 − α/2)
/// δ = √((p₁ − l₁)² − 2φ (p₁ − l₁)(u₂ − p₂) + (u₂ − p₂)²)
/// ε = √((u₁ − p₁)² − 2φ (u₁ − p₁)(p₂ − l₂) + (p₂ − l₂)²)
/// CI = [θ̂ − δ, θ̂ + ε]
/// ```
///
/// with the correlation of the two margins estimated by the continuity-corrected phi
/// coefficient of the paper:
///
/// ```text
/// A = ad − bc,   φ = (A − n/2)/√((a + b)(c + d)(a + c)(b + d))   if A > n/2
///                φ = 0                                            if 0 ≤ A ≤ n/2
///                φ = A/√((a + b)(c + d)(a + c)(b + d))            if A < 0
/// ```
///
/// and `φ = 0` when any of the four margins is 0. The interval lies inside [−1, 1] and is
/// never a single point. statsmodels 0.15.0 has no paired version (its `newcomb` method of
/// `confint_proportions_2indep` is the independent-samples interval, which is this one with
/// φ = 0); `tests/inference_reference.rs` checks it against that where φ = 0, an independent
/// Python implementation of the published formulas, and the worked example of Fagerland,
/// Lydersen & Laake (2017, ch. 8).
///
/// Errors: an empty table, a confidence outside (0, 1).
pub fn newcombe_paired_difference(
    table: &Discordance,
    confidence: f64,
) -> Result<PairedProportionDifference, InferenceError> {
    let tail = two_sided_tail(confidence)?;
    let n = table.pairs();
    if n == 0 {
        return Err(InferenceError::EmptyTable);
    }
    let z = normal_upper_quantile(tail);
    let first_count = table.both + table.only_first;
    let second_count = table.both + table.only_second;
    let [l1, u1] = wilson_interval(first_count, n, z).ok_or(InferenceError::EmptyTable)?;
    let [l2, u2] = wilson_interval(second_count, n, z).ok_or(InferenceError::EmptyTable)?;
    let n_f = n as f64;
    let first = first_count as f64 / n_f;
    let second = second_count as f64 / n_f;
    let difference = (table.only_first as f64 - table.only_second as f64) / n_f;
    let phi = corrected_phi(table);
    let combine = |x: f64, y: f64| (x * x - 2.0 * phi * x * y + y * y).max(0.0).sqrt();
    let below = combine(first - l1, u2 - second);
    let above = combine(u1 - first, second - l2);
    Ok(PairedProportionDifference {
        n,
        first,
        second,
        difference,
        ci: [difference - below, difference + above],
        confidence,
        method: NEWCOMBE_METHOD_10,
    })
}

/// Newcombe's (1998) continuity-corrected phi coefficient of a paired table (see
/// [`newcombe_paired_difference`]); 0 when a margin is empty.
fn corrected_phi(table: &Discordance) -> f64 {
    let (a, b, c, d) = (
        table.both as f64,
        table.only_first as f64,
        table.only_second as f64,
        table.neither as f64,
    );
    let margins = [a + b, c + d, a + c, b + d];
    if margins.contains(&0.0) {
        return 0.0;
    }
    // √(efgh) as a product of two square roots (no overflow for large tables).
    let scale = (margins[0] * margins[1]).sqrt() * (margins[2] * margins[3]).sqrt();
    let cross = a * d - b * c;
    let half_n = (a + b + c + d) / 2.0;
    if cross > half_n {
        (cross - half_n) / scale
    } else if cross >= 0.0 {
        0.0
    } else {
        cross / scale
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(both: u64, only_first: u64, only_second: u64, neither: u64) -> Discordance {
        Discordance {
            both,
            only_first,
            only_second,
            neither,
        }
    }

    #[test]
    fn worked_example_of_fagerland_lydersen_laake() {
        // Fagerland, Lydersen & Laake (2017), Statistical Analysis of Contingency Tables,
        // ch. 8: complete response before / after consolidation therapy (Cavo et al. 2012),
        // table [[59, 6], [16, 80]]: estimate −0.0621, Newcombe square-and-add 95 % CI
        // −0.1186 to −0.0046, printed to 4 decimals.
        let r = newcombe_paired_difference(&table(59, 6, 16, 80), 0.95).unwrap();
        assert_eq!(r.n, 161);
        assert!((r.difference - -0.0621).abs() < 5e-5, "{r:?}");
        assert!((r.ci[0] - -0.1186).abs() < 5e-5, "{r:?}");
        assert!((r.ci[1] - -0.0046).abs() < 5e-5, "{r:?}");
    }

    #[test]
    fn phi_correction_cases() {
        // A = ad − bc = 59·80 − 6·16 = 4624 > n/2: corrected.
        let t = table(59, 6, 16, 80);
        let expected = (4624.0 - 80.5) / (65.0f64 * 96.0 * 75.0 * 86.0).sqrt();
        assert!((corrected_phi(&t) - expected).abs() < 1e-15);
        // 0 ≤ A ≤ n/2: φ = 0 (A = 1·1 − 0·0 = 1, n = 2).
        assert_eq!(corrected_phi(&table(1, 0, 0, 1)), 0.0);
        // A < 0: uncorrected (A = 0 − 9).
        let expected = -9.0 / (3.0f64 * 3.0 * 3.0 * 3.0).sqrt();
        assert!((corrected_phi(&table(0, 3, 3, 0)) - expected).abs() < 1e-15);
        // An empty margin: 0.
        assert_eq!(corrected_phi(&table(0, 0, 4, 6)), 0.0);
    }

    #[test]
    fn interval_stays_in_range_and_contains_the_estimate() {
        for t in [
            table(0, 0, 0, 10),
            table(10, 0, 0, 0),
            table(0, 10, 0, 0),
            table(0, 0, 10, 0),
            table(3, 1, 0, 50),
            table(0, 0, 1, 0),
        ] {
            let r = newcombe_paired_difference(&t, 0.95).unwrap();
            assert!(r.ci[0] >= -1.0 && r.ci[1] <= 1.0, "{t:?}: {r:?}");
            assert!(
                r.ci[0] <= r.difference && r.difference <= r.ci[1],
                "{t:?}: {r:?}"
            );
            assert!(r.ci[1] - r.ci[0] > 0.0, "{t:?}: {r:?}");
        }
    }

    #[test]
    fn bad_input_is_an_error() {
        assert_eq!(
            newcombe_paired_difference(&table(0, 0, 0, 0), 0.95),
            Err(InferenceError::EmptyTable)
        );
        for c in [0.0, 1.0, -1.0, f64::NAN] {
            assert!(matches!(
                newcombe_paired_difference(&table(1, 2, 3, 4), c),
                Err(InferenceError::InvalidConfidence(_))
            ));
        }
    }
}
