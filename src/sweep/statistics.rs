//! The statistics of a sweep: binomial confidence intervals, percentiles and means, each a pure
//! function of values given in instance order (so a merged sharded sweep reproduces the
//! unsharded figures bit for bit).

/// The standard normal quantile of 0.975 (two-sided 95 % intervals).
pub const Z_95: f64 = 1.959_963_984_540_054;

/// Wilson score interval of a binomial proportion (Wilson 1927; Newcombe 1998, method 3):
///
/// ```text
/// centre    = (p̂ + z²/(2n)) / (1 + z²/n)
/// halfwidth = z / (1 + z²/n) · √(p̂(1 − p̂)/n + z²/(4n²))
/// ```
///
/// Unlike the Wald interval p̂ ± z√(p̂(1 − p̂)/n) it stays inside [0, 1] and does not collapse
/// to a point at 0 or n successes, which matters here: most sweeps of a good planner see no
/// collision at all, and "0 of 200" must still say "up to 1.9 %". `None` when `n = 0`.
pub fn wilson_interval(successes: u64, n: u64, z: f64) -> Option<[f64; 2]> {
    if n == 0 || successes > n {
        return None;
    }
    let n_f = n as f64;
    let p = successes as f64 / n_f;
    let z2 = z * z;
    let denominator = 1.0 + z2 / n_f;
    let centre = (p + z2 / (2.0 * n_f)) / denominator;
    let half = z / denominator * (p * (1.0 - p) / n_f + z2 / (4.0 * n_f * n_f)).sqrt();
    // The bounds at p̂ = 0 and p̂ = 1 are exactly 0 and 1; say so rather than round near them.
    let lo = if successes == 0 {
        0.0
    } else {
        (centre - half).max(0.0)
    };
    let hi = if successes == n {
        1.0
    } else {
        (centre + half).min(1.0)
    };
    Some([lo, hi])
}

/// The project's one percentile (`mergesim_types::percentile`), here beside the other
/// statistics of a sweep.
pub(crate) use mergesim_types::percentile::nearest_rank_percentile;

/// Arithmetic mean, summed in the given order. `None` for no values.
pub fn mean(values: &[f64]) -> Option<f64> {
    if values.is_empty() {
        None
    } else {
        Some(values.iter().sum::<f64>() / values.len() as f64)
    }
}

/// Standard error of the mean of `values`: the sample standard deviation (n − 1) over √n,
/// summed in the given order. `None` for fewer than two values.
pub fn standard_error(values: &[f64]) -> Option<f64> {
    let m = mean(values)?;
    if values.len() < 2 {
        return None;
    }
    let n = values.len() as f64;
    let variance = values.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0);
    Some((variance / n).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wilson_matches_newcombe_1998() {
        // Newcombe, "Two-sided confidence intervals for the single proportion: comparison of
        // seven methods", Stat. Med. 17 (1998), Table II, method 3 (score, no continuity
        // correction), to the 4 decimals printed there.
        for (x, n, lo, hi) in [
            (81, 263, 0.2553, 0.3662),
            (15, 148, 0.0624, 0.1605),
            (0, 20, 0.0, 0.1611),
            (1, 29, 0.0061, 0.1718),
        ] {
            let [l, h] = wilson_interval(x, n, Z_95).unwrap();
            assert!(
                (l - lo).abs() < 6e-5 && (h - hi).abs() < 6e-5,
                "{x}/{n}: [{l}, {h}]"
            );
        }
    }

    #[test]
    fn wilson_with_no_successes_has_the_closed_form_upper_bound() {
        // p̂ = 0: upper bound z²/(n + z²).
        for n in [1u64, 10, 200, 10_000] {
            let [l, h] = wilson_interval(0, n, Z_95).unwrap();
            let z2 = Z_95 * Z_95;
            assert_eq!(l, 0.0);
            assert!((h - z2 / (n as f64 + z2)).abs() < 1e-15, "{n}: {h}");
            // Symmetry: n successes mirror 0 successes.
            let [l2, h2] = wilson_interval(n, n, Z_95).unwrap();
            assert!((l2 - (1.0 - h)).abs() < 1e-12 && h2 == 1.0);
        }
        assert_eq!(wilson_interval(0, 0, Z_95), None);
        assert_eq!(wilson_interval(3, 2, Z_95), None);
    }

    #[test]
    fn nearest_rank_matches_the_textbook_example() {
        // The worked example of the nearest-rank method (five values 15, 20, 35, 40, 50).
        let v = [15.0, 20.0, 35.0, 40.0, 50.0];
        for (p, expected) in [
            (5.0, 15.0),
            (30.0, 20.0),
            (40.0, 20.0),
            (50.0, 35.0),
            (100.0, 50.0),
            (0.0, 15.0),
        ] {
            assert_eq!(nearest_rank_percentile(&v, p), Some(expected), "p{p}");
        }
        assert_eq!(nearest_rank_percentile(&[], 5.0), None);
        assert_eq!(nearest_rank_percentile(&v, 101.0), None);
        // 200 samples 1..=200: p5 is the 10th.
        let many: Vec<f64> = (1..=200).map(f64::from).collect();
        assert_eq!(nearest_rank_percentile(&many, 5.0), Some(10.0));
    }

    #[test]
    fn mean_of_values() {
        assert_eq!(mean(&[1.0, 2.0, 6.0]), Some(3.0));
        assert_eq!(mean(&[]), None);
    }

    #[test]
    fn standard_error_of_values() {
        // Sample variance of 1, 2, 6 is ((−2)² + (−1)² + 3²) / 2 = 7; SE = √(7/3).
        assert_eq!(
            standard_error(&[1.0, 2.0, 6.0]),
            Some((7.0f64 / 3.0).sqrt())
        );
        assert_eq!(standard_error(&[4.0]), None);
        assert_eq!(standard_error(&[]), None);
    }
}
