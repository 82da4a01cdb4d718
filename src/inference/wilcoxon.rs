//! The Wilcoxon signed-rank test (Wilcoxon 1945, "Individual comparisons by ranking methods",
//! Biometrics Bulletin 1:80–83) of paired differences, with exactly the defaults of
//! `scipy.stats.wilcoxon(d)` in scipy 1.17.1: zeros dropped (`zero_method="wilcox"`),
//! two-sided, no continuity correction, `method="auto"`.

use super::distributions::normal_sf;
use super::{InferenceError, check_finite};

/// Which null distribution gave the p-value (scipy's `method="auto"` choice, see
/// [`wilcoxon_signed_rank`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum WilcoxonMethod {
    /// The exact null distribution of W⁺ (ranks 1…n, each sign equally likely): no ties and
    /// no zero differences, at most 50 differences.
    Exact,
    /// The exact distribution of W⁺ over all 2ⁿ sign assignments of the observed (average,
    /// tied) ranks, as scipy's permutation test: ties or zeros, at most 13 differences
    /// (zeros included). Exact given the ties.
    Permutation,
    /// The normal approximation with the tie-corrected variance, no continuity correction.
    Normal,
}

/// The signed-rank test of `differences`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Wilcoxon {
    /// Number of non-zero differences (the ones ranked).
    pub n_nonzero: usize,
    /// `min(W⁺, W⁻)`, the smaller of the rank sums of the positive and negative differences
    /// (scipy's two-sided statistic).
    pub statistic: f64,
    /// Two-sided p-value.
    pub p_two_sided: f64,
    /// The null distribution used.
    pub method: WilcoxonMethod,
}

/// The largest sample (zeros included) for which scipy 1.17.1's `method="auto"` may use an
/// exact distribution; above it, always the normal approximation.
pub const EXACT_MAX_N: usize = 50;

/// The largest sample (zeros included) for which, with ties or zeros, scipy 1.17.1 enumerates
/// every sign assignment (2¹³ = 8192 ≤ its 9999 resamples, so its permutation test is exact).
pub const PERMUTATION_MAX_N: usize = 13;

/// The Wilcoxon signed-rank test of `differences`, as `scipy.stats.wilcoxon(differences)`
/// (scipy 1.17.1, `_wilcoxon.py`).
///
/// Zero differences are dropped; the `n` non-zero ones are ranked by `|dᵢ|` (ties get their
/// average rank `rᵢ`), and
///
/// ```text
/// W⁺ = Σ_(dᵢ > 0) rᵢ,   W⁻ = Σ_(dᵢ < 0) rᵢ,   statistic = min(W⁺, W⁻)
/// ```
///
/// The p-value's distribution follows scipy's `method="auto"`, decided on the length `N` of
/// the input (zeros included):
///
/// - `N > 50`: **normal approximation** (Wilcoxon 1945; tie correction as scipy):
///   ```text
///   z = (W⁺ − n(n + 1)/4) / σ,   σ² = (n(n + 1)(2n + 1) − Σ_g (t_g³ − t_g)/2) / 24
///   p = 2 · P(Z > |z|)
///   ```
///   over the groups `g` of `t_g` tied `|dᵢ|`;
/// - `N ≤ 50`, no ties and no zeros: **exact**, `p = min(1, 2 · min(P(W ≤ W⁺), P(W ≥ W⁺)))`
///   under the null (each of the 2ⁿ sign assignments of ranks 1…n equally likely);
/// - `N ≤ 13` with ties or zeros: the same formula over the 2ⁿ sign assignments of the
///   observed average ranks (scipy's **permutation** test, which is exhaustive at this size);
/// - otherwise (14 ≤ N ≤ 50 with ties or zeros): the normal approximation.
///
/// Both exact cases count sign assignments by dynamic programming over the doubled ranks
/// (integers), so the comparisons with W⁺ are exact.
///
/// **No non-zero difference** (all differences 0): statistic 0 and p = 1 (scipy gives 1 for
/// `N ≤ 13` and NaN above; with no difference at all there is no evidence of one).
///
/// Errors: no differences at all, a NaN or infinite difference.
pub fn wilcoxon_signed_rank(differences: &[f64]) -> Result<Wilcoxon, InferenceError> {
    let total = differences.len();
    if total == 0 {
        return Err(InferenceError::TooFewValues { needed: 1, got: 0 });
    }
    check_finite(differences)?;
    let nonzero: Vec<f64> = differences.iter().copied().filter(|&d| d != 0.0).collect();
    let n = nonzero.len();
    let has_zeros = n < total;

    // Average ranks of |d|, doubled so that they are integers (a tie group spanning ranks
    // i+1 … j has average rank (i + 1 + j)/2, doubled i + 1 + j).
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| nonzero[i].abs().total_cmp(&nonzero[j].abs()));
    let mut doubled_rank = vec![0u64; n];
    let mut tie_term = 0.0; // Σ (t³ − t)
    let mut has_ties = false;
    let mut start = 0;
    while start < n {
        let value = nonzero[order[start]].abs();
        let mut end = start + 1;
        while end < n && nonzero[order[end]].abs() == value {
            end += 1;
        }
        let group = (end - start) as u64;
        if group > 1 {
            has_ties = true;
            let t = group as f64;
            tie_term += t * t * t - t;
        }
        for &i in &order[start..end] {
            doubled_rank[i] = start as u64 + 1 + end as u64;
        }
        start = end;
    }
    let doubled_plus: u64 = (0..n)
        .filter(|&i| nonzero[i] > 0.0)
        .map(|i| doubled_rank[i])
        .sum();
    let doubled_total = (n * (n + 1)) as u64;
    let doubled_minus = doubled_total - doubled_plus;
    let statistic = doubled_plus.min(doubled_minus) as f64 / 2.0;

    let method = if total > EXACT_MAX_N {
        WilcoxonMethod::Normal
    } else if !has_ties && !has_zeros {
        WilcoxonMethod::Exact
    } else if total <= PERMUTATION_MAX_N {
        WilcoxonMethod::Permutation
    } else {
        WilcoxonMethod::Normal
    };
    let p_two_sided = if n == 0 {
        1.0
    } else {
        match method {
            WilcoxonMethod::Exact | WilcoxonMethod::Permutation => {
                exact_p(&doubled_rank, doubled_plus)
            }
            WilcoxonMethod::Normal => {
                let n_f = n as f64;
                let mean = n_f * (n_f + 1.0) / 4.0;
                let sd = ((n_f * (n_f + 1.0) * (2.0 * n_f + 1.0) - tie_term / 2.0) / 24.0).sqrt();
                let z = (doubled_plus as f64 / 2.0 - mean) / sd;
                (2.0 * normal_sf(z.abs())).min(1.0)
            }
        }
    };
    Ok(Wilcoxon {
        n_nonzero: n,
        statistic,
        p_two_sided,
        method,
    })
}

/// `min(1, 2 · min(P(S ≤ s), P(S ≥ s)))` for `S` the sum of a random subset of `weights`
/// (each in or out with probability 1/2): the number of subsets with each sum, by dynamic
/// programming, over 2ⁿ. Exact in integers up to n = 63 (counts ≤ 2ⁿ); used for n ≤ 50.
fn exact_p(weights: &[u64], s: u64) -> f64 {
    let total: u64 = weights.iter().sum();
    let mut counts = vec![0u64; total as usize + 1];
    counts[0] = 1;
    let mut reach = 0usize;
    for &w in weights {
        let w = w as usize;
        for sum in (0..=reach).rev() {
            counts[sum + w] += counts[sum];
        }
        reach += w;
    }
    let s = s as usize;
    let at_most: u64 = counts[..=s].iter().sum();
    let at_least: u64 = counts[s..].iter().sum();
    let all = (weights.len() as f64).exp2();
    (2.0 * at_most.min(at_least) as f64 / all).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_distribution_of_ranks_one_to_four() {
        // n = 4: the 16 subsets of {1, 2, 3, 4} have sums 0 1 2 3 3 4 4 5 5 6 6 7 7 8 9 10.
        // W⁺ = 1 (only the smallest positive): P(W ≤ 1) = 2/16, p = 4/16.
        let r = wilcoxon_signed_rank(&[0.5, -1.5, -2.5, -3.5]).unwrap();
        assert_eq!(r.method, WilcoxonMethod::Exact);
        assert_eq!((r.n_nonzero, r.statistic, r.p_two_sided), (4, 1.0, 0.25));
        // All positive: W⁺ = 10, W⁻ = 0, p = 2/16.
        let r = wilcoxon_signed_rank(&[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert_eq!((r.statistic, r.p_two_sided), (0.0, 0.125));
    }

    #[test]
    fn method_follows_scipy_auto() {
        let distinct: Vec<f64> = (1..=50)
            .map(|i| i as f64 * if i % 3 == 0 { -1.0 } else { 1.0 })
            .collect();
        assert_eq!(
            wilcoxon_signed_rank(&distinct).unwrap().method,
            WilcoxonMethod::Exact
        );
        let mut more = distinct.clone();
        more.push(51.0);
        assert_eq!(
            wilcoxon_signed_rank(&more).unwrap().method,
            WilcoxonMethod::Normal
        );
        // A zero makes the 13-value sample a permutation test, the 14-value one normal.
        let mut with_zero: Vec<f64> = (1..=12).map(f64::from).collect();
        with_zero.push(0.0);
        assert_eq!(
            wilcoxon_signed_rank(&with_zero).unwrap().method,
            WilcoxonMethod::Permutation
        );
        with_zero.push(-13.0);
        assert_eq!(
            wilcoxon_signed_rank(&with_zero).unwrap().method,
            WilcoxonMethod::Normal
        );
        // A tie alone does the same.
        let tied = [1.0, -1.0, 2.0, 3.0];
        assert_eq!(
            wilcoxon_signed_rank(&tied).unwrap().method,
            WilcoxonMethod::Permutation
        );
    }

    #[test]
    fn all_zero_differences_give_p_one() {
        for n in [1, 13, 14, 60] {
            let r = wilcoxon_signed_rank(&vec![0.0; n]).unwrap();
            assert_eq!(
                (r.n_nonzero, r.statistic, r.p_two_sided),
                (0, 0.0, 1.0),
                "{n}"
            );
        }
    }

    #[test]
    fn bad_input_is_an_error() {
        assert_eq!(
            wilcoxon_signed_rank(&[]),
            Err(InferenceError::TooFewValues { needed: 1, got: 0 })
        );
        assert_eq!(
            wilcoxon_signed_rank(&[1.0, 2.0, f64::NAN]),
            Err(InferenceError::NonFinite { index: 2 })
        );
    }
}
