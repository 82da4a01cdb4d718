//! The Magic-Formula tyre of CommonRoad's std model (Pacejka 2002 coefficients, camber γ = 0,
//! no turn slip, every scaling factor λ = 1), one tyre per axle carrying the axle load F_z.
//!
//! With the Magic-Formula shape M(B, C, E; x) = C·atan(B x − E (B x − atan(B x))):
//!
//! **Pure longitudinal slip** κ (CommonRoad's s = 1 − R_w ω / u, so braking is κ > 0 and the
//! formula is evaluated at −κ):
//! ```text
//! κ_x = −κ + p_hx1,   D_x = p_dx1 F_z,   B_x = p_kx1 F_z / (p_cx1 D_x),
//! F_x0 = D_x · sin( M(B_x, p_cx1, p_ex1; κ_x) + p_vx1 F_z )
//! ```
//! The vertical shift p_vx1·F_z sits inside the sine here, as in the reference package, where
//! the Magic Formula proper adds it to the force outside. Inside, it acts as an angle in
//! radians: with p_vx1 = −8.8·10⁻⁶ and a 4 kN axle load it is −0.035, so a free-rolling tyre
//! (s = 0) at that load has a force of −56 N, a drag of 1.4 % of its load
//! (`free_rolling_drag_of_the_shift`), where the Magic Formula proper would give +110 N (from
//! the horizontal shift p_hx1). Kept as the reference has it, because the std model here is
//! checked against the reference trajectory by trajectory.
//!
//! **Pure lateral slip** α (at γ = 0 the camber shifts vanish):
//! ```text
//! μ_y = p_dy1,   D_y = μ_y F_z,   B_y = p_ky1 F_z / (p_cy1 D_y),
//! F_y0 = D_y · sin( M(B_y, p_cy1, p_ey1; α) )
//! ```
//! (p_ky1 < 0, so a positive slip angle gives a negative force.)
//!
//! **Combined slip**: each pure force is weighted by a cosine-shaped function of the other slip,
//! normalised to 1 where the other slip is 0:
//! ```text
//! W(B, C, E; x) = cos( M(B, C, E; x) )
//! F_x = F_x0 · W(B_xα, r_cx1, r_ex1; α + r_hx1) / W(B_xα, r_cx1, r_ex1; r_hx1),
//!       B_xα = r_bx1 cos(atan(r_bx2 κ))
//! F_y = F_y0 · W(B_yκ, r_cy1, r_ey1; κ + r_hy1) / W(B_yκ, r_cy1, r_ey1; r_hy1) + S_vyκ,
//!       B_yκ = r_by1 cos(atan(r_by2 (α − r_by3))),
//!       S_vyκ = μ_y F_z r_vy1 cos(atan(r_vy4 α)) · sin(r_vy5 atan(r_vy6 κ))
//! ```
//! Here κ is CommonRoad's s itself (not negated). S_vyκ is a side force that longitudinal slip
//! creates even at α = 0.

use super::params::CommonRoadTireParams;

/// C·atan(B x − E (B x − atan(B x))): the argument of the Magic Formula's sine or cosine.
fn shape(b: f64, c: f64, e: f64, x: f64) -> f64 {
    let bx = b * x;
    c * (bx - e * (bx - bx.atan())).atan()
}

/// Pure-slip longitudinal force F_x0 (N) at CommonRoad's slip ratio `slip` and load `fz_n`.
pub fn pure_longitudinal_force_n(slip: f64, fz_n: f64, t: &CommonRoadTireParams) -> f64 {
    let kappa_x = -slip + t.p_hx1;
    let d = t.p_dx1 * fz_n;
    let b = fz_n * t.p_kx1 / (t.p_cx1 * d);
    d * (shape(b, t.p_cx1, t.p_ex1, kappa_x) + fz_n * t.p_vx1).sin()
}

/// Pure-slip lateral force F_y0 (N) at slip angle `alpha_rad` and load `fz_n`, with the
/// friction coefficient μ_y it used.
pub fn pure_lateral_force_n(alpha_rad: f64, fz_n: f64, t: &CommonRoadTireParams) -> (f64, f64) {
    let mu_y = t.p_dy1;
    let d = mu_y * fz_n;
    let b = fz_n * t.p_ky1 / (t.p_cy1 * d);
    (d * shape(b, t.p_cy1, t.p_ey1, alpha_rad).sin(), mu_y)
}

/// Combined-slip longitudinal force F_x (N) from the pure force `fx0_n`.
pub fn combined_longitudinal_force_n(
    slip: f64,
    alpha_rad: f64,
    fx0_n: f64,
    t: &CommonRoadTireParams,
) -> f64 {
    let b = t.r_bx1 * (t.r_bx2 * slip).atan().cos();
    let at_shift = shape(b, t.r_cx1, t.r_ex1, t.r_hx1).cos();
    fx0_n / at_shift * shape(b, t.r_cx1, t.r_ex1, alpha_rad + t.r_hx1).cos()
}

/// Combined-slip lateral force F_y (N) from the pure force `fy0_n` and its μ_y at load `fz_n`.
pub fn combined_lateral_force_n(
    slip: f64,
    alpha_rad: f64,
    mu_y: f64,
    fz_n: f64,
    fy0_n: f64,
    t: &CommonRoadTireParams,
) -> f64 {
    let b = t.r_by1 * (t.r_by2 * (alpha_rad - t.r_by3)).atan().cos();
    let at_shift = shape(b, t.r_cy1, t.r_ey1, t.r_hy1).cos();
    let side_n = mu_y * fz_n * t.r_vy1 * (t.r_vy4 * alpha_rad).atan().cos();
    let s_vy_n = side_n * (t.r_vy5 * (t.r_vy6 * slip).atan()).sin();
    fy0_n / at_shift * shape(b, t.r_cy1, t.r_ey1, slip + t.r_hy1).cos() + s_vy_n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slopes_at_zero_slip_are_the_stiffnesses() {
        let t = CommonRoadTireParams::default();
        let fz = 3000.0;
        let h = 1e-7;
        let ky =
            (pure_lateral_force_n(h, fz, &t).0 - pure_lateral_force_n(-h, fz, &t).0) / (2.0 * h);
        assert!((ky - t.p_ky1 * fz).abs() < 1e-4 * fz, "{ky}");
        // The longitudinal curve is evaluated at −s, so its slope in s is −K_x (shifts are tiny:
        // p_hx1 moves the point of evaluation, which costs a little slope).
        let kx = (pure_longitudinal_force_n(h, fz, &t) - pure_longitudinal_force_n(-h, fz, &t))
            / (2.0 * h);
        assert!((kx + t.p_kx1 * fz).abs() < 5e-3 * t.p_kx1 * fz, "{kx}");
    }

    #[test]
    fn free_rolling_drag_of_the_shift() {
        let t = CommonRoadTireParams::default();
        let fz = 4000.0;
        let f = pure_longitudinal_force_n(0.0, fz, &t);
        let b = t.p_kx1 / (t.p_cx1 * t.p_dx1);
        let expected = t.p_dx1 * fz * (shape(b, t.p_cx1, t.p_ex1, t.p_hx1) + fz * t.p_vx1).sin();
        assert_eq!(f, expected);
        assert!((f + 55.77).abs() < 0.01, "{f}");
    }

    #[test]
    fn peaks_are_mu_times_load() {
        let t = CommonRoadTireParams::default();
        let fz = 3000.0;
        let peak_y = (0..2000)
            .map(|i| pure_lateral_force_n(i as f64 * 1e-3, fz, &t).0.abs())
            .fold(0.0, f64::max);
        assert!((peak_y - t.p_dy1 * fz).abs() < 1e-3 * fz, "{peak_y}");
        let peak_x = (0..2000)
            .map(|i| pure_longitudinal_force_n(i as f64 * 1e-3, fz, &t).abs())
            .fold(0.0, f64::max);
        assert!((peak_x - t.p_dx1 * fz).abs() < 1e-3 * fz, "{peak_x}");
    }

    #[test]
    fn combined_slip_weights_are_one_without_the_other_slip() {
        let t = CommonRoadTireParams::default();
        // At α = 0 the longitudinal weight is 1.
        let fx = combined_longitudinal_force_n(0.05, 0.0, 1234.0, &t);
        assert!((fx - 1234.0).abs() < 1e-9);
        // At s = 0 the lateral weight is 1 and the slip-induced side force is 0.
        let (alpha, fz) = (0.03, 3000.0);
        let fy = combined_lateral_force_n(0.0, alpha, t.p_dy1, fz, -900.0, &t);
        assert!((fy + 900.0).abs() < 1e-9);
        // A spinning tyre (s < 0) at α = 0 has a side force of μ F_z r_vy1 sin(r_vy5 atan(r_vy6 s)).
        let fy = combined_lateral_force_n(-0.1, 0.0, t.p_dy1, fz, 0.0, &t);
        let side = t.p_dy1 * fz * t.r_vy1 * (t.r_vy5 * (t.r_vy6 * -0.1f64).atan()).sin();
        assert!((fy - side).abs() < 1e-9 && side.abs() > 50.0, "{fy} {side}");
        // Combined slip reduces both forces.
        let fx0 = pure_longitudinal_force_n(-0.05, fz, &t);
        assert!(combined_longitudinal_force_n(-0.05, 0.1, fx0, &t).abs() < fx0.abs());
        let (fy0, mu) = pure_lateral_force_n(0.05, fz, &t);
        assert!(combined_lateral_force_n(0.1, 0.05, mu, fz, fy0, &t).abs() < fy0.abs());
    }
}
