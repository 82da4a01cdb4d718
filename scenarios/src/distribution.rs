//! Random perturbations of a scenario value: offsets added to its nominal value.
//!
//! Every distribution has bounded support, so a scenario can be checked once, at load time, for
//! all the instances it can ever produce (see [`crate::randomisation`]).
//!
//! In TOML:
//!
//! ```toml
//! x_m = { uniform = [-3.0, 3.0] }                                    # nominal + U[-3, 3]
//! mu = { normal = { mean_offset = 0.0, std = 0.05, clip = [-0.1, 0.1] } }  # truncated normal
//! ```
//!
//! `clip` truncates the normal (the density is renormalised on the window), it does not clamp:
//! clamping would put a point mass on each bound, a value the physical quantity has no reason to
//! prefer. The truncated normal is drawn by inversion, `Φ⁻¹(Φ(α) + u·(Φ(β) − Φ(α)))`, which takes
//! exactly one uniform draw per sample (no rejection loop whose length depends on the window).

use serde::{Deserialize, Serialize};
use sim::rng::SplitMix64;

/// An offset distribution.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Distribution {
    /// `nominal + U[lo, hi]`.
    Uniform(#[serde(deserialize_with = "exactly_two")] [f64; 2]),
    /// `nominal + N(mean_offset, std²)` truncated to `clip`.
    Normal(NormalOffset),
}

/// A normal offset truncated to a window.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NormalOffset {
    /// Mean of the offset (default 0).
    #[serde(default)]
    pub mean_offset: f64,
    /// Standard deviation of the untruncated normal (≥ 0; 0 gives `mean_offset`).
    pub std: f64,
    /// Truncation window `[lo, hi]` of the offset; must contain `mean_offset`.
    #[serde(deserialize_with = "exactly_two")]
    pub clip: [f64; 2],
}

/// Reads `[lo, hi]`: exactly two numbers (serde's arrays would silently ignore a third).
pub(crate) fn exactly_two<'de, D: serde::Deserializer<'de>>(
    deserializer: D,
) -> Result<[f64; 2], D::Error> {
    let values = Vec::<f64>::deserialize(deserializer)?;
    match values.as_slice() {
        [lo, hi] => Ok([*lo, *hi]),
        _ => Err(serde::de::Error::custom(format!(
            "expected exactly two numbers [lo, hi], got {} ({values:?})",
            values.len()
        ))),
    }
}

impl Distribution {
    /// Checks the parameters; the error says what is wrong (the caller adds the field name).
    pub(crate) fn validate(&self) -> Result<(), String> {
        match self {
            Distribution::Uniform([lo, hi]) => {
                if !(lo.is_finite() && hi.is_finite()) {
                    return Err(format!("uniform = [{lo}, {hi}]: bounds must be finite"));
                }
                if lo > hi {
                    return Err(format!(
                        "uniform = [{lo}, {hi}]: lower bound above upper bound"
                    ));
                }
            }
            Distribution::Normal(n) => {
                let [lo, hi] = n.clip;
                if !(n.mean_offset.is_finite() && n.std.is_finite() && n.std >= 0.0) {
                    return Err(format!(
                        "normal: mean_offset = {} must be finite and std = {} finite and >= 0",
                        n.mean_offset, n.std
                    ));
                }
                if !(lo.is_finite() && hi.is_finite() && lo <= n.mean_offset && n.mean_offset <= hi)
                {
                    return Err(format!(
                        "normal: clip = [{lo}, {hi}] must be finite and contain mean_offset = {}",
                        n.mean_offset
                    ));
                }
            }
        }
        Ok(())
    }

    /// The smallest and largest offset this distribution can produce.
    pub(crate) fn offset_bounds(&self) -> [f64; 2] {
        match self {
            Distribution::Uniform(bounds) => *bounds,
            Distribution::Normal(n) => n.clip,
        }
    }

    /// One offset, from exactly one draw of `rng`. Always inside `Self::offset_bounds` for a
    /// valid distribution.
    pub fn sample_offset(&self, rng: &mut SplitMix64) -> f64 {
        let u = rng.next_f64();
        match self {
            Distribution::Uniform([lo, hi]) => (lo + (hi - lo) * u).clamp(*lo, *hi),
            Distribution::Normal(n) => {
                let [lo, hi] = n.clip;
                if n.std == 0.0 {
                    return n.mean_offset.clamp(lo, hi);
                }
                let alpha = (lo - n.mean_offset) / n.std;
                let beta = (hi - n.mean_offset) / n.std;
                let (p_alpha, p_beta) = (normal_cdf(alpha), normal_cdf(beta));
                let z = normal_quantile(p_alpha + u * (p_beta - p_alpha)).clamp(alpha, beta);
                (n.mean_offset + n.std * z).clamp(lo, hi)
            }
        }
    }
}

/// Standard normal cumulative distribution Φ(x) = erfc(−x/√2)/2.
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * erfc(-x / std::f64::consts::SQRT_2)
}

/// Complementary error function, fractional error below 1.2·10⁻⁷ everywhere (the Chebyshev
/// fit of Press et al., *Numerical Recipes*, 2nd ed., §6.2, `erfcc`).
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -z * z - 1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98
                                + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let value = t * poly.exp();
    if x >= 0.0 { value } else { 2.0 - value }
}

/// Standard normal quantile Φ⁻¹(p), relative error below 1.15·10⁻⁹ (P. J. Acklam's rational
/// approximation). −∞ for p ≤ 0, +∞ for p ≥ 1, NaN for NaN.
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    const P_LOW: f64 = 0.024_25;
    if p.is_nan() {
        return f64::NAN;
    }
    if p <= 0.0 {
        return f64::NEG_INFINITY;
    }
    if p >= 1.0 {
        return f64::INFINITY;
    }
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < P_LOW {
        tail((-2.0 * p.ln()).sqrt())
    } else if p <= 1.0 - P_LOW {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pdf(x: f64) -> f64 {
        (-0.5 * x * x).exp() / (std::f64::consts::TAU).sqrt()
    }

    #[test]
    fn cdf_matches_the_standard_normal_table() {
        // Abramowitz & Stegun, Table 26.1 (values of P(x)).
        for (x, p) in [
            (0.0, 0.5),
            (1.0, 0.841_344_746_1),
            (-2.0, 0.022_750_131_95),
            (1.959_963_985, 0.975),
            (3.0, 0.998_650_101_97),
        ] {
            assert!(
                (normal_cdf(x) - p).abs() < 2e-7 * p.max(1e-3),
                "Φ({x}) = {}",
                normal_cdf(x)
            );
        }
    }

    #[test]
    fn quantile_matches_the_table_and_inverts_the_cdf() {
        for (p, x) in [
            (0.5, 0.0),
            (0.975, 1.959_963_984_540),
            (0.01, -2.326_347_874_041),
            (0.999, 3.090_232_306_168),
            (1e-6, -4.753_424_308_823),
        ] {
            assert!(
                (normal_quantile(p) - x).abs() < 1e-8 * x.abs().max(1.0),
                "Φ⁻¹({p})"
            );
        }
        for i in 1..100 {
            let p = i as f64 / 100.0;
            assert!((normal_cdf(normal_quantile(p)) - p).abs() < 2e-7, "{p}");
        }
        assert_eq!(normal_quantile(0.0), f64::NEG_INFINITY);
        assert_eq!(normal_quantile(1.0), f64::INFINITY);
    }

    #[test]
    fn uniform_offsets_have_the_closed_form_moments() {
        let d = Distribution::Uniform([-3.0, 1.0]);
        let mut rng = SplitMix64::new(3);
        let n = 200_000;
        let xs: Vec<f64> = (0..n).map(|_| d.sample_offset(&mut rng)).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        // U[a, b]: mean (a + b)/2 = -1, variance (b − a)²/12 = 4/3.
        assert!((mean + 1.0).abs() < 0.01, "{mean}");
        assert!((var - 4.0 / 3.0).abs() < 0.01, "{var}");
        assert!(xs.iter().all(|x| (-3.0..=1.0).contains(x)));
    }

    #[test]
    fn truncated_normal_has_the_closed_form_mean_and_variance() {
        let n = NormalOffset {
            mean_offset: 0.5,
            std: 2.0,
            clip: [-1.0, 4.0],
        };
        let d = Distribution::Normal(n.clone());
        // Truncated normal on [a, b] (Johnson, Kotz & Balakrishnan): with α, β standardised,
        // Z = Φ(β) − Φ(α): mean μ + σ(φ(α) − φ(β))/Z,
        // variance σ²[1 + (αφ(α) − βφ(β))/Z − ((φ(α) − φ(β))/Z)²].
        let (a, b) = ((-1.0 - 0.5) / 2.0, (4.0 - 0.5) / 2.0);
        // Φ from erf via the series of A&S 7.1.5, independent of the code under test.
        let phi_cdf = |x: f64| {
            let z = x / std::f64::consts::SQRT_2;
            let mut term = z;
            let mut sum = z;
            for k in 1..200 {
                term *= -z * z / k as f64;
                sum += term / (2 * k + 1) as f64;
            }
            0.5 + sum / std::f64::consts::PI.sqrt()
        };
        let zm = phi_cdf(b) - phi_cdf(a);
        let mean_ref = 0.5 + 2.0 * (pdf(a) - pdf(b)) / zm;
        let var_ref =
            4.0 * (1.0 + (a * pdf(a) - b * pdf(b)) / zm - ((pdf(a) - pdf(b)) / zm).powi(2));
        let mut rng = SplitMix64::new(5);
        let count = 200_000;
        let xs: Vec<f64> = (0..count).map(|_| d.sample_offset(&mut rng)).collect();
        let mean = xs.iter().sum::<f64>() / count as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / count as f64;
        // Standard error of the mean ≈ 1.2/√200000 ≈ 0.003.
        assert!((mean - mean_ref).abs() < 0.012, "{mean} vs {mean_ref}");
        assert!((var - var_ref).abs() < 0.02 * var_ref, "{var} vs {var_ref}");
        assert!(xs.iter().all(|x| (-1.0..=4.0).contains(x)));
    }

    #[test]
    fn degenerate_and_invalid_distributions() {
        let mut rng = SplitMix64::new(1);
        let fixed = Distribution::Normal(NormalOffset {
            mean_offset: 0.25,
            std: 0.0,
            clip: [0.0, 1.0],
        });
        assert_eq!(fixed.sample_offset(&mut rng), 0.25);
        assert_eq!(
            Distribution::Uniform([2.0, 2.0]).sample_offset(&mut rng),
            2.0
        );
        assert!(Distribution::Uniform([1.0, -1.0]).validate().is_err());
        assert!(Distribution::Uniform([f64::NAN, 1.0]).validate().is_err());
        let outside = Distribution::Normal(NormalOffset {
            mean_offset: 2.0,
            std: 1.0,
            clip: [-1.0, 1.0],
        });
        assert!(outside.validate().unwrap_err().contains("mean_offset"));
        let negative = Distribution::Normal(NormalOffset {
            mean_offset: 0.0,
            std: -1.0,
            clip: [-1.0, 1.0],
        });
        assert!(negative.validate().is_err());
    }

    #[test]
    fn far_tail_window_stays_inside_the_window() {
        // A window 9σ wide on one side: Φ(β) rounds to 1; samples must still be finite and in it.
        let d = Distribution::Normal(NormalOffset {
            mean_offset: 0.0,
            std: 1.0,
            clip: [-0.1, 40.0],
        });
        let mut rng = SplitMix64::new(9);
        for _ in 0..10_000 {
            let x = d.sample_offset(&mut rng);
            assert!(x.is_finite() && (-0.1..=40.0).contains(&x), "{x}");
        }
    }
}
