//! Holm's step-down adjustment of a family of p-values (Holm 1979, "A simple sequentially
//! rejective multiple test procedure", Scandinavian Journal of Statistics 6:65–70).

/// Holm-adjusted p-values, in the input order, as
/// `statsmodels.stats.multitest.multipletests(p, method="holm")[1]` (statsmodels 0.15.0):
/// with the `m` p-values sorted ascending, `p₍₁₎ ≤ … ≤ p₍ₘ₎`,
///
/// ```text
/// p̃₍ᵢ₎ = min(1, max_(j ≤ i) (m − j + 1) · p₍ⱼ₎)
/// ```
///
/// so the adjusted values are monotone in the raw ones, never below them, and capped at 1.
/// Rejecting every hypothesis with `p̃ ≤ α` controls the family-wise error rate at α. Ties get
/// the same adjusted value whatever their order. An empty family gives an empty vector.
///
/// NaN entries (not expected: every p-value of this module is a number) are handled as
/// statsmodels does: they sort last, count in `m`, and stay NaN; the others are unaffected.
pub fn holm(p_values: &[f64]) -> Vec<f64> {
    let m = p_values.len();
    let mut order: Vec<usize> = (0..m).collect();
    // total_cmp puts (positive) NaN after every number; stable, so ties keep input order.
    order.sort_by(|&i, &j| p_values[i].total_cmp(&p_values[j]));
    let mut adjusted = vec![f64::NAN; m];
    let mut running = 0.0_f64;
    for (rank, &i) in order.iter().enumerate() {
        let p = p_values[i];
        if p.is_nan() {
            continue;
        }
        running = running.max((m - rank) as f64 * p);
        adjusted[i] = running.min(1.0);
    }
    adjusted
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_down_by_hand() {
        // Sorted 0.005, 0.01, 0.03, 0.04 → ×4, ×3, ×2, ×1 = 0.02, 0.03, 0.06, 0.04 → monotone:
        // 0.02, 0.03, 0.06, 0.06.
        let adjusted = holm(&[0.01, 0.04, 0.03, 0.005]);
        let expected = [0.03, 0.06, 0.06, 0.02];
        for (a, e) in adjusted.iter().zip(expected) {
            assert!((a - e).abs() < 1e-15, "{adjusted:?}");
        }
    }

    #[test]
    fn ties_cap_and_edge_cases() {
        assert_eq!(holm(&[0.02, 0.02]), vec![0.04, 0.04]);
        assert_eq!(holm(&[0.5, 0.6, 0.9]), vec![1.0, 1.0, 1.0]);
        assert_eq!(holm(&[0.3]), vec![0.3]);
        assert!(holm(&[]).is_empty());
        let with_nan = holm(&[0.01, f64::NAN, 0.04, 0.03]);
        assert!(with_nan[1].is_nan());
        assert!((with_nan[0] - 0.04).abs() < 1e-15);
        assert!((with_nan[2] - 0.09).abs() < 1e-15 && (with_nan[3] - 0.09).abs() < 1e-15);
    }
}
