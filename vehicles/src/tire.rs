//! Magic-Formula tyre (PAC2002 structure, CommonRoad coefficients) with combined slip.
//!
//! Conventions (per tyre, in the wheel's ground frame, x along the wheel heading, y to its left):
//! - slip ratio κ = (ω·r − v_x) / max(|v_x|, v_floor): positive when driving;
//! - slip angle α = atan(v_y / |v_x|) (CommonRoad's convention): positive when the contact patch
//!   slides to the left, which produces a force to the right because `p_ky1 < 0`.
//!
//! Pure slip (CommonRoad `tire_model.py`, `formula_longitudinal` / `formula_lateral`, γ = 0):
//! ```text
//! F_x0 = D_x sin(C_x atan(B_x κ_x − E_x (B_x κ_x − atan(B_x κ_x)))) + S_Vx,  κ_x = κ + S_Hx
//! F_y0 = D_y sin(C_y atan(B_y α   − E_y (B_y α   − atan(B_y α))))
//! D = μ·Fz,  B_x = p_kx1·Fz / (C_x D_x) = p_kx1 / (C_x μ),  B_y = p_ky1 / (C_y μ)
//! ```
//! Combined slip (`formula_longitudinal_comb` / `formula_lateral_comb`): F_x = G_xα·F_x0 and
//! F_y = G_yκ·F_y0 with the cosine weighting functions
//! ```text
//! G_xα = cos(C_xα atan(B_xα α_s − E_xα(B_xα α_s − atan(B_xα α_s)))) / (same at α_s = S_Hxα),
//!        B_xα = r_bx1 cos(atan(r_bx2 κ)), α_s = α + S_Hxα
//! G_yκ = cos(C_yκ atan(B_yκ κ_s − E_yκ(B_yκ κ_s − atan(B_yκ κ_s)))) / (same at κ_s = S_Hyκ),
//!        B_yκ = r_by1 cos(atan(r_by2 (α − r_by3))), κ_s = −κ + S_Hyκ
//! ```
//! (CommonRoad's κ in the weighting functions is its braking-positive slip `s = −κ`.)
//! Both weights are clipped at 0: beyond the range the coefficients were fitted on (slip angles
//! above ~0.45 rad for G_xα, a freely spinning wheel with κ ≫ 1 for G_yκ) the cosines turn
//! negative, which would reverse the force (a brake pushing forward, a spinning wheel pulling
//! the car into the slide); a sliding contact patch gives a force near zero in those
//! directions instead.
//! Finally the resultant is clipped to the friction circle |F| ≤ μ·Fz, so the force never
//! exceeds what the road can carry whatever the coefficients.
//!
//! One deliberate difference from CommonRoad's code: `S_Vx = p_vx1·Fz` (a force, N) is added
//! outside the sine as in PAC2002. CommonRoad's `formula_longitudinal` adds it to the sine's
//! argument (radians), which at Fz = 3 kN shifts its curve by up to 2.6 % of the peak; PAC2002's
//! form changes the force by 0.03 N.

use std::f64::consts::FRAC_PI_2;

use crate::params::TireParams;

/// Forces of one tyre in its ground frame and the slope used by the implicit wheel-spin step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct TireForces {
    /// Longitudinal force (N), positive forward.
    pub fx_n: f64,
    /// Lateral force (N), positive to the left.
    pub fy_n: f64,
    /// ∂F_x/∂κ at the evaluated point (N), floored at zero (beyond the peak the implicit
    /// linearisation is not used; the physical instability of a locking wheel is kept).
    pub dfx_dkappa_n: f64,
}

/// μ-dependent constants of the tyre curves, computed once per friction coefficient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct TireCurves {
    /// Road friction coefficient μ the curves were built for.
    pub mu: f64,
    b_x: f64,
    b_y: f64,
    /// Slip ratio magnitude (measured from the curve's centre S_Hx) at which F_x0 peaks.
    pub peak_slip_ratio: f64,
    /// tan of the slip angle at which F_y0 peaks.
    pub peak_slip_angle_tan: f64,
}

/// Magic Formula "sine of atan" core: D·sin(C·atan(x − E(x − atan x))) with its x-derivative.
#[inline]
fn magic_formula(x: f64, c: f64, d: f64, e: f64) -> (f64, f64) {
    let atan_x = x.atan();
    let phi = x - e * (x - atan_x);
    let theta = c * phi.atan();
    let (sin_t, cos_t) = theta.sin_cos();
    let dphi_dx = 1.0 - e + e / (1.0 + x * x);
    (d * sin_t, d * cos_t * c / (1.0 + phi * phi) * dphi_dx)
}

/// Cosine weighting core: cos(C·atan(x − E(x − atan x))).
#[inline]
fn weighting(x: f64, c: f64, e: f64) -> f64 {
    let phi = x - e * (x - x.atan());
    (c * phi.atan()).cos()
}

/// Solves x − E(x − atan x) = tan(π / (2C)) for x > 0 (the argument where the Magic Formula
/// peaks). Newton's method on a monotone function (E ≤ 1), started at the E = 0 solution.
fn peak_argument(c: f64, e: f64) -> f64 {
    let target = (FRAC_PI_2 / c).tan();
    let mut x = target;
    for _ in 0..50 {
        let f = x - e * (x - x.atan()) - target;
        let df = 1.0 - e + e / (1.0 + x * x);
        let step = f / df;
        x -= step;
        if step.abs() < 1e-12 * x.abs().max(1.0) {
            break;
        }
    }
    x
}

impl TireCurves {
    /// Builds the curves for friction coefficient `mu` (> 0, checked by the caller).
    pub(crate) fn new(p: &TireParams, mu: f64) -> Self {
        let b_x = p.p_kx1 / (p.p_cx1 * mu);
        let b_y = p.p_ky1 / (p.p_cy1 * mu);
        let peak_x = peak_argument(p.p_cx1, p.p_ex1);
        let peak_y = peak_argument(p.p_cy1, p.p_ey1);
        Self {
            mu,
            b_x,
            b_y,
            peak_slip_ratio: peak_x / b_x.abs(),
            peak_slip_angle_tan: (peak_y / b_y.abs()).tan(),
        }
    }

    /// Pure longitudinal force F_x0(κ) and its slope ∂F_x0/∂κ (N).
    #[inline]
    pub(crate) fn pure_longitudinal(&self, p: &TireParams, fz_n: f64, kappa: f64) -> (f64, f64) {
        let d = self.mu * fz_n;
        let (f, df_dx) = magic_formula(self.b_x * (kappa + p.p_hx1), p.p_cx1, d, p.p_ex1);
        (f + p.p_vx1 * fz_n, df_dx * self.b_x)
    }

    /// Pure lateral force F_y0(α) (N).
    #[inline]
    pub(crate) fn pure_lateral(&self, p: &TireParams, fz_n: f64, alpha_rad: f64) -> f64 {
        let d = self.mu * fz_n;
        magic_formula(self.b_y * alpha_rad, p.p_cy1, d, p.p_ey1).0
    }

    /// Weighting G_xα(κ, α) of the longitudinal force under combined slip.
    #[inline]
    pub(crate) fn g_x_alpha(&self, p: &TireParams, kappa: f64, alpha_rad: f64) -> f64 {
        // cos(atan(z)) = 1 / sqrt(1 + z²)
        let rk = p.r_bx2 * kappa;
        let b = p.r_bx1 / (1.0 + rk * rk).sqrt();
        let num = weighting(b * (alpha_rad + p.r_hx1), p.r_cx1, p.r_ex1);
        let den = weighting(b * p.r_hx1, p.r_cx1, p.r_ex1);
        (num / den).max(0.0)
    }

    /// Weighting G_yκ(κ, α) of the lateral force under combined slip.
    #[inline]
    pub(crate) fn g_y_kappa(&self, p: &TireParams, kappa: f64, alpha_rad: f64) -> f64 {
        let ra = p.r_by2 * (alpha_rad - p.r_by3);
        let b = p.r_by1 / (1.0 + ra * ra).sqrt();
        let num = weighting(b * (-kappa + p.r_hy1), p.r_cy1, p.r_ey1);
        let den = weighting(b * p.r_hy1, p.r_cy1, p.r_ey1);
        (num / den).max(0.0)
    }

    /// Combined-slip forces at normal load `fz_n`, clipped to the friction circle μ·Fz.
    #[inline]
    pub(crate) fn combined(
        &self,
        p: &TireParams,
        fz_n: f64,
        kappa: f64,
        alpha_rad: f64,
    ) -> TireForces {
        if fz_n <= 0.0 {
            return TireForces::default();
        }
        let (fx0, dfx0) = self.pure_longitudinal(p, fz_n, kappa);
        let fy0 = self.pure_lateral(p, fz_n, alpha_rad);
        let gx = self.g_x_alpha(p, kappa, alpha_rad);
        let gy = self.g_y_kappa(p, kappa, alpha_rad);
        let mut fx = gx * fx0;
        let mut fy = gy * fy0;
        let limit = self.mu * fz_n;
        let norm_sq = fx * fx + fy * fy;
        let mut scale = 1.0;
        if norm_sq > limit * limit {
            scale = limit / norm_sq.sqrt();
            fx *= scale;
            fy *= scale;
        }
        TireForces {
            fx_n: fx,
            fy_n: fy,
            dfx_dkappa_n: (gx * dfx0 * scale).max(0.0),
        }
    }

    /// Linear cornering stiffness of one tyre at load `fz_n`, |∂F_y/∂α| at α = κ = 0 (N/rad).
    /// Equals |p_ky1|·Fz: independent of μ.
    pub(crate) fn cornering_stiffness_npr(p: &TireParams, fz_n: f64) -> f64 {
        p.p_ky1.abs() * fz_n
    }
}

/// Speed floor of the slip-ratio denominator for a given step (m/s).
///
/// A braked-locked wheel turns the tyre into a damper of rate K_x / v_floor per wheel, i.e.
/// p_kx1·m·g / v_floor for the car. Rapier integrates the chassis explicitly, so the velocity
/// decays by the factor (1 − p_kx1·g·dt / v_floor) per step; the floor is raised to
/// 1.25·p_kx1·g·dt so that this factor stays ≥ 0.2 (no sign flip, no chatter) at any step.
pub fn slip_speed_floor_mps(p: &TireParams, dt_s: f64, gravity_mps2: f64) -> f64 {
    p.low_speed_floor_mps
        .max(1.25 * p.p_kx1 * gravity_mps2 * dt_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn central_diff(f: impl Fn(f64) -> f64, x: f64) -> f64 {
        let h = 1e-6;
        (f(x + h) - f(x - h)) / (2.0 * h)
    }

    #[test]
    fn slope_matches_finite_difference() {
        let p = TireParams::default();
        let c = TireCurves::new(&p, 0.85);
        for kappa in [-0.3, -0.05, -0.001, 0.0, 0.02, 0.08, 0.5] {
            let (_, analytic) = c.pure_longitudinal(&p, 3000.0, kappa);
            let numeric = central_diff(|k| c.pure_longitudinal(&p, 3000.0, k).0, kappa);
            assert!(
                (analytic - numeric).abs() <= 1e-5 * numeric.abs().max(1.0),
                "kappa {kappa}: {analytic} vs {numeric}"
            );
        }
    }

    #[test]
    fn pure_curves_peak_at_mu_fz_where_predicted() {
        let p = TireParams::default();
        for mu in [0.3, 0.8, 1.0] {
            let c = TireCurves::new(&p, mu);
            let fz = 4000.0;
            // Brute-force maximum over a fine grid.
            let (mut best_k, mut best_f) = (0.0, f64::MIN);
            for i in 0..200_000 {
                let k = i as f64 * 1e-5;
                let f = c.pure_longitudinal(&p, fz, k - p.p_hx1).0 - p.p_vx1 * fz;
                if f > best_f {
                    best_f = f;
                    best_k = k;
                }
            }
            assert!((best_f - mu * fz).abs() < 1e-6 * fz, "peak {best_f}");
            assert!(
                (best_k - c.peak_slip_ratio).abs() < 2e-5,
                "{best_k} vs {}",
                c.peak_slip_ratio
            );
            let (mut best_a, mut best_fy) = (0.0, f64::MIN);
            for i in 0..200_000 {
                let a = i as f64 * 1e-5;
                let f = -c.pure_lateral(&p, fz, a);
                if f > best_fy {
                    best_fy = f;
                    best_a = a;
                }
            }
            assert!((best_fy - mu * fz).abs() < 1e-6 * fz);
            assert!((best_a.tan() - c.peak_slip_angle_tan).abs() < 2e-5);
        }
    }

    #[test]
    fn cornering_stiffness_is_slope_at_zero() {
        let p = TireParams::default();
        let c = TireCurves::new(&p, 0.8);
        let fz = 2957.0;
        let slope = central_diff(|a| c.combined(&p, fz, 0.0, a).fy_n, 0.0);
        let expected = TireCurves::cornering_stiffness_npr(&p, fz);
        assert!(
            (-slope - expected).abs() < 1e-4 * expected,
            "{slope} vs {expected}"
        );
    }

    /// Reference values computed with CommonRoad's own `vehiclemodels/utils/tire_model.py`
    /// (commonroad-vehicle-models 3.0.2, `parameters_tire.yaml`, γ = 0, Fz = 3000 N), whose slip
    /// `s` is braking-positive (κ = −s). Nominal friction (μ = p_dx1 resp. p_dy1, so λ_μ = 1).
    /// The longitudinal references were computed with `p_vx1 = 0` (see the module doc: CommonRoad
    /// puts S_Vx inside the sine), the lateral combined ones without CommonRoad's S_Vyκ term
    /// (see [`TireParams`]).
    #[test]
    fn matches_commonroad_tire_model_reference() {
        let p = TireParams::default();
        let fz = 3000.0;
        let cx = TireCurves::new(&p, p.p_dx1);
        let long_ref = [
            (-0.2, 3470.513602117857),
            (-0.05, 2635.508796331445),
            (-0.01, 739.7147656481881),
            (0.01, -581.2159983148217),
            (0.05, -2560.39756619056),
            (0.3, -3281.365582340755),
        ];
        for (s, reference) in long_ref {
            let ours = cx.pure_longitudinal(&p, fz, -s).0;
            // p_vx1·Fz = −0.026 N is the only difference.
            assert!(
                (ours - reference).abs() < 0.05,
                "s {s}: {ours} vs {reference}"
            );
        }
        let cy = TireCurves::new(&p, p.p_dy1);
        let lat_ref = [
            (-0.2, 3119.9699546370884),
            (-0.03, 1743.4161003284414),
            (0.01, -647.7993029687594),
            (0.05, -2445.3630382681754),
            (0.15, -3146.684130551598),
        ];
        for (alpha, reference) in lat_ref {
            let ours = cy.pure_lateral(&p, fz, alpha);
            assert!(
                (ours - reference).abs() < 1e-6 * fz,
                "alpha {alpha}: {ours} vs {reference}"
            );
        }
        let gx_ref = [
            (0.05, 0.05, 0.8014443271053713),
            (-0.1, -0.1, 0.7362981232949433),
            (0.02, 0.2, 0.2627152253124017),
        ];
        for (s, alpha, reference) in gx_ref {
            let ours = cx.g_x_alpha(&p, -s, alpha);
            assert!((ours - reference).abs() < 1e-9, "{ours} vs {reference}");
        }
        let gy_ref = [
            (0.05, 0.05, 0.9538011787068313),
            (-0.1, -0.1, 0.831939252872901),
            (0.02, 0.2, 0.9978266028283671),
        ];
        for (s, alpha, reference) in gy_ref {
            let ours = cy.g_y_kappa(&p, -s, alpha);
            assert!((ours - reference).abs() < 1e-9, "{ours} vs {reference}");
        }
    }

    /// The clipped weights stay in [0, 1.05] over the whole slip range, so the combined force
    /// never points against the pure-slip force.
    #[test]
    fn combined_weights_never_reverse_the_force() {
        let p = TireParams::default();
        let c = TireCurves::new(&p, 0.8);
        for i in -200..=200 {
            for j in -78..=78 {
                let kappa = f64::from(i) * 0.05;
                let alpha = f64::from(j) * 0.02;
                let gx = c.g_x_alpha(&p, kappa, alpha);
                let gy = c.g_y_kappa(&p, kappa, alpha);
                assert!((0.0..=1.05).contains(&gx), "G_xα({kappa}, {alpha}) = {gx}");
                assert!((0.0..=1.05).contains(&gy), "G_yκ({kappa}, {alpha}) = {gy}");
            }
        }
    }

    #[test]
    fn combined_force_never_exceeds_friction_circle() {
        let p = TireParams::default();
        let c = TireCurves::new(&p, 0.7);
        for i in -40..=40 {
            for j in -40..=40 {
                let kappa = i as f64 * 0.025;
                let alpha = j as f64 * 0.02;
                let f = c.combined(&p, 5000.0, kappa, alpha);
                assert!(f.fx_n.hypot(f.fy_n) <= 0.7 * 5000.0 * (1.0 + 1e-12));
            }
        }
    }
}
