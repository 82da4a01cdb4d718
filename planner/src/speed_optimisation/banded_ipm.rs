//! A dedicated interior-point solver for the Newton QP of one SCP iteration (`speed_program =
//! "newton-qp-banded"`): the same problem as [`newton_qp`](super::newton_qp), solved without
//! Clarabel by exploiting its structure.
//!
//! ```text
//!   minimise ½ vᵀ diag(h) v + qᵀ v        over v = [v_1 … v_N] (h_i > 0)
//!   subject to  G v ≤ g, the rows of the Newton QP (module doc of `newton_qp`):
//!     box_hi  v_i ≤ hi_i          box_lo  −v_i ≤ −lo_i
//!     accel   ±(v_{i+1} − v_i) ≤ a_max Δt                    (if enabled)
//!     jerk    ±(v_{i+1} − 2 v_i + v_{i−1}) ≤ j_max Δt²        (if enabled)
//! ```
//!
//! Every row touches at most three neighbouring speeds, so the Newton system of a primal–dual
//! interior-point method, reduced to the speeds,
//!
//! ```text
//!   (diag(h) + Gᵀ W G) Δv = r,   W = diag(z_k / s_k)   (z: multipliers, s: slacks)
//! ```
//!
//! is banded (bandwidth 2 with the jerk rows, 1 with the acceleration rows only) and is solved
//! by a banded Cholesky factorisation in O(N) instead of a general sparse LDLᵀ. The iteration
//! is Mehrotra's predictor–corrector (Nocedal & Wright, *Numerical Optimization*, 2nd ed.,
//! Alg. 16.4 for inequality-constrained QPs), from an infeasible start: v the unconstrained
//! minimiser moved into the box, s = max(g − G v, 1), z = 1. It stops when the primal
//! residual, the dual residual and the mean complementarity s·z / m are each below
//! `tolerance` × (1 + the size of their data) — Clarabel's `tol_feas` and `tol_gap_*` in
//! spirit, not bit for bit — and fails (a typed error, as a failed Clarabel solve) after
//! `max_iterations` or on a non-finite iterate.
//!
//! Its solutions agree with Clarabel's to the solvers' tolerance, not to the bit: the
//! acceptance criterion, fixed before it was measured, is in docs/parameters.md
//! (`speed_program`).

use crate::error::PlannerError;

/// The QP's data (module doc).
#[derive(Clone, Debug)]
pub(super) struct BandedQp<'a> {
    /// Diagonal of the Hessian (each > 0).
    pub(super) h: &'a [f64],
    /// Linear term.
    pub(super) q: &'a [f64],
    /// Box of the speeds.
    pub(super) lo: &'a [f64],
    /// Box of the speeds.
    pub(super) hi: &'a [f64],
    /// a_max Δt, or `None` without the acceleration rows.
    pub(super) accel_step: Option<f64>,
    /// j_max Δt², or `None` without the jerk rows.
    pub(super) jerk_step: Option<f64>,
}

/// Lower band of a symmetric banded matrix with bandwidth 2: `band[i] = [M_ii, M_i,i−1,
/// M_i,i−2]`.
type Band = Vec<[f64; 3]>;

/// Factorises the SPD band matrix in place into L (unit-free Cholesky, M = L Lᵀ, same layout);
/// `false` if a pivot is not positive (not positive definite to working precision).
fn cholesky_in_place(band: &mut Band) -> bool {
    let n = band.len();
    for i in 0..n {
        // Off-diagonals of row i: L_i,j for j = i−2, i−1.
        for off in (1..=2).rev() {
            if i < off {
                continue;
            }
            let j = i - off;
            let mut sum = band[i][off];
            // Σ_k<j L_ik L_jk over the band.
            for k_off in 1..=2 {
                // k = j − k_off must be ≥ i − 2 to lie in row i's band.
                if j < k_off || off + k_off > 2 {
                    continue;
                }
                sum -= band[i][off + k_off] * band[j][k_off];
            }
            band[i][off] = sum / band[j][0];
        }
        let row = band[i];
        let mut diag = row[0];
        for (off, l) in row.iter().enumerate().skip(1) {
            if i >= off {
                diag -= l * l;
            }
        }
        if !diag.is_finite() || diag <= 0.0 {
            return false;
        }
        band[i][0] = diag.sqrt();
    }
    true
}

/// Solves L Lᵀ x = rhs in place with the factor of [`cholesky_in_place`].
fn cholesky_solve(factor: &Band, rhs: &mut [f64]) {
    let n = factor.len();
    for i in 0..n {
        let mut x = rhs[i];
        for off in 1..=2 {
            if i >= off {
                x -= factor[i][off] * rhs[i - off];
            }
        }
        rhs[i] = x / factor[i][0];
    }
    for i in (0..n).rev() {
        let mut x = rhs[i];
        for off in 1..=2 {
            if i + off < n {
                x -= factor[i + off][off] * rhs[i + off];
            }
        }
        rhs[i] = x / factor[i][0];
    }
}

/// The largest α in (0, 1] keeping x + α dx ≥ 0.
fn step_to_boundary(x: &[f64], dx: &[f64]) -> f64 {
    x.iter().zip(dx).fold(1.0_f64, |alpha, (xi, dxi)| {
        if *dxi < 0.0 {
            alpha.min(-xi / dxi)
        } else {
            alpha
        }
    })
}

fn inf_norm(x: &[f64]) -> f64 {
    x.iter().fold(0.0_f64, |m, v| m.max(v.abs()))
}

/// Where each block of rows sits in the stacked slack / multiplier vectors (module doc's
/// order): the box's upper and lower rows, then the acceleration rows' + and − halves, then
/// the jerk rows'.
#[derive(Clone, Copy, Debug)]
struct Blocks {
    n: usize,
    /// Acceleration pairs (N − 1, or 0 without the rows).
    accel: usize,
    /// Jerk pairs (N − 2, or 0 without the rows).
    jerk: usize,
}

/// The six blocks of a stacked row vector, in [`Blocks`]' order.
struct Parts<T> {
    hi: T,
    lo: T,
    accel_plus: T,
    accel_minus: T,
    jerk_plus: T,
    jerk_minus: T,
}

impl Blocks {
    fn rows(&self) -> usize {
        2 * self.n + 2 * self.accel + 2 * self.jerk
    }

    /// The blocks of `x` (of length [`rows`](Self::rows)).
    fn split<'a>(&self, x: &'a [f64]) -> Parts<&'a [f64]> {
        let (hi, rest) = x.split_at(self.n);
        let (lo, rest) = rest.split_at(self.n);
        let (accel_plus, rest) = rest.split_at(self.accel);
        let (accel_minus, rest) = rest.split_at(self.accel);
        let (jerk_plus, rest) = rest.split_at(self.jerk);
        let jerk_minus = &rest[..self.jerk];
        Parts {
            hi,
            lo,
            accel_plus,
            accel_minus,
            jerk_plus,
            jerk_minus,
        }
    }

    /// The blocks of `x` (of length [`rows`](Self::rows)), mutable.
    fn split_mut<'a>(&self, x: &'a mut [f64]) -> Parts<&'a mut [f64]> {
        let (hi, rest) = x.split_at_mut(self.n);
        let (lo, rest) = rest.split_at_mut(self.n);
        let (accel_plus, rest) = rest.split_at_mut(self.accel);
        let (accel_minus, rest) = rest.split_at_mut(self.accel);
        let (jerk_plus, rest) = rest.split_at_mut(self.jerk);
        let jerk_minus = &mut rest[..self.jerk];
        Parts {
            hi,
            lo,
            accel_plus,
            accel_minus,
            jerk_plus,
            jerk_minus,
        }
    }

    /// out = G v.
    fn apply(&self, v: &[f64], out: &mut [f64]) {
        let out = self.split_mut(out);
        for ((hi, lo), x) in out.hi.iter_mut().zip(out.lo.iter_mut()).zip(v) {
            *hi = *x;
            *lo = -*x;
        }
        for ((plus, minus), pair) in out
            .accel_plus
            .iter_mut()
            .zip(out.accel_minus.iter_mut())
            .zip(v.windows(2))
        {
            let d = pair[1] - pair[0];
            *plus = d;
            *minus = -d;
        }
        for ((plus, minus), triple) in out
            .jerk_plus
            .iter_mut()
            .zip(out.jerk_minus.iter_mut())
            .zip(v.windows(3))
        {
            let e = triple[2] - 2.0 * triple[1] + triple[0];
            *plus = e;
            *minus = -e;
        }
    }

    /// out += Gᵀ y.
    fn add_transposed(&self, y: &[f64], out: &mut [f64]) {
        let y = self.split(y);
        for ((o, plus), minus) in out.iter_mut().zip(y.hi).zip(y.lo) {
            *o += plus - minus;
        }
        for (i, (plus, minus)) in y.accel_plus.iter().zip(y.accel_minus).enumerate() {
            let c = plus - minus;
            out[i + 1] += c;
            out[i] -= c;
        }
        for (i, (plus, minus)) in y.jerk_plus.iter().zip(y.jerk_minus).enumerate() {
            let c = plus - minus;
            out[i + 2] += c;
            out[i + 1] -= 2.0 * c;
            out[i] += c;
        }
    }

    /// band = diag(h) + Gᵀ diag(w) G (lower band, bandwidth 2).
    fn normal_matrix(&self, h: &[f64], w: &[f64], band: &mut Band) {
        let w = self.split(w);
        for (((row, hi), w_hi), w_lo) in band.iter_mut().zip(h).zip(w.hi).zip(w.lo) {
            *row = [hi + w_hi + w_lo, 0.0, 0.0];
        }
        for (i, (plus, minus)) in w.accel_plus.iter().zip(w.accel_minus).enumerate() {
            let wi = plus + minus;
            band[i][0] += wi;
            band[i + 1][0] += wi;
            band[i + 1][1] -= wi;
        }
        for (i, (plus, minus)) in w.jerk_plus.iter().zip(w.jerk_minus).enumerate() {
            // Row coefficients (1, −2, 1) on (i, i+1, i+2).
            let wi = plus + minus;
            band[i][0] += wi;
            band[i + 1][0] += 4.0 * wi;
            band[i + 2][0] += wi;
            band[i + 1][1] -= 2.0 * wi;
            band[i + 2][1] -= 2.0 * wi;
            band[i + 2][2] += wi;
        }
    }
}

/// The per-iteration data both Newton directions share (module doc): Z r_p, S⁻¹, the
/// residuals and the factor of M.
struct NewtonSystem<'a> {
    blocks: Blocks,
    r_d: &'a [f64],
    r_p: &'a [f64],
    z: &'a [f64],
    z_r_p: &'a [f64],
    inv_s: &'a [f64],
    band: &'a Band,
}

impl NewtonSystem<'_> {
    /// The direction for the complementarity target r_c (s∘z − σμ + corrections):
    ///   Δv = M⁻¹ (−r_d − Gᵀ S⁻¹ (Z r_p − r_c)),
    ///   Δs = −r_p − G Δv,   Δz = −S⁻¹ (r_c + Z Δs).
    /// `y` is scratch of the rows' length.
    fn direction(
        &self,
        r_c: &[f64],
        y: &mut [f64],
        dv: &mut [f64],
        ds: &mut [f64],
        dz: &mut [f64],
    ) {
        for (d, r) in dv.iter_mut().zip(self.r_d) {
            *d = -r;
        }
        for (((y, rc), zr), inv) in y.iter_mut().zip(r_c).zip(self.z_r_p).zip(self.inv_s) {
            *y = (rc - zr) * inv;
        }
        self.blocks.add_transposed(y, dv);
        cholesky_solve(self.band, dv);
        self.blocks.apply(dv, ds);
        for ((((ds, dz), rp), rc), (z, inv)) in ds
            .iter_mut()
            .zip(dz.iter_mut())
            .zip(self.r_p)
            .zip(r_c)
            .zip(self.z.iter().zip(self.inv_s))
        {
            *ds = -rp - *ds;
            *dz = -(rc + z * *ds) * inv;
        }
    }
}

impl BandedQp<'_> {
    /// The right-hand sides g of G v ≤ g, stacked as [`Blocks`].
    fn bounds(&self, blocks: &Blocks) -> Vec<f64> {
        let mut g = Vec::with_capacity(blocks.rows());
        g.extend_from_slice(self.hi);
        g.extend(self.lo.iter().map(|l| -l));
        let accel = self.accel_step.unwrap_or(0.0);
        g.extend(std::iter::repeat_n(accel, 2 * blocks.accel));
        let jerk = self.jerk_step.unwrap_or(0.0);
        g.extend(std::iter::repeat_n(jerk, 2 * blocks.jerk));
        g
    }

    /// The minimiser v (module doc), or why not.
    pub(super) fn solve(
        &self,
        max_iterations: u32,
        tolerance: f64,
    ) -> Result<Vec<f64>, PlannerError> {
        let failed = |status: &str| PlannerError::SolverFailed {
            problem: "speed_optimisation (banded interior point)".into(),
            status: status.into(),
        };
        let n = self.h.len();
        if n == 0 || [self.q.len(), self.lo.len(), self.hi.len()] != [n; 3] {
            return Err(failed("inconsistent dimensions"));
        }
        let blocks = Blocks {
            n,
            accel: if self.accel_step.is_some() && n >= 2 {
                n - 1
            } else {
                0
            },
            jerk: if self.jerk_step.is_some() && n >= 3 {
                n - 2
            } else {
                0
            },
        };
        let m = blocks.rows();
        let g = self.bounds(&blocks);
        // Start: the unconstrained minimiser moved into the box; slacks at least 1.
        let mut v: Vec<f64> = (0..n)
            .map(|i| {
                let free = -self.q[i] / self.h[i];
                free.max(self.lo[i]).min(self.hi[i].max(self.lo[i]))
            })
            .collect();
        let mut gv = vec![0.0; m];
        blocks.apply(&v, &mut gv);
        let mut s: Vec<f64> = gv.iter().zip(&g).map(|(a, b)| (b - a).max(1.0)).collect();
        let mut z = vec![1.0; m];
        let scale_p = 1.0 + inf_norm(&g);
        let scale_d = 1.0 + inf_norm(self.q);

        let mut r_d = vec![0.0; n];
        let mut r_p = vec![0.0; m];
        let mut z_r_p = vec![0.0; m];
        let mut w = vec![0.0; m];
        let mut inv_s = vec![0.0; m];
        let mut y = vec![0.0; m];
        let mut band: Band = vec![[0.0; 3]; n];
        let mut dv = vec![0.0; n];
        let mut ds = vec![0.0; m];
        let mut dz = vec![0.0; m];
        let mut r_c = vec![0.0; m];
        for _ in 0..max_iterations {
            // Residuals: r_d = H v + q + Gᵀ z, r_p = G v + s − g.
            for ((r, (h, q)), x) in r_d.iter_mut().zip(self.h.iter().zip(self.q)).zip(&v) {
                *r = h * x + q;
            }
            blocks.add_transposed(&z, &mut r_d);
            blocks.apply(&v, &mut gv);
            for (((r, gv), s), g) in r_p.iter_mut().zip(&gv).zip(&s).zip(&g) {
                *r = gv + s - g;
            }
            let gap = s.iter().zip(&z).fold(0.0, |gap, (s, z)| gap + s * z);
            for ((((inv, w), zr), s), (z, rp)) in inv_s
                .iter_mut()
                .zip(w.iter_mut())
                .zip(z_r_p.iter_mut())
                .zip(&s)
                .zip(z.iter().zip(&r_p))
            {
                *inv = 1.0 / s;
                *w = z * *inv;
                *zr = z * rp;
            }
            let mu = gap / m as f64;
            if !mu.is_finite() || v.iter().any(|x| !x.is_finite()) {
                return Err(failed("non-finite iterate"));
            }
            if inf_norm(&r_p) <= tolerance * scale_p
                && inf_norm(&r_d) <= tolerance * scale_d
                && mu <= tolerance
            {
                return Ok(v);
            }
            // M = diag(h) + Gᵀ W G, banded; factorised once for both directions.
            blocks.normal_matrix(self.h, &w, &mut band);
            if !cholesky_in_place(&mut band) {
                return Err(failed("Newton system not positive definite"));
            }
            let system = NewtonSystem {
                blocks,
                r_d: &r_d,
                r_p: &r_p,
                z: &z,
                z_r_p: &z_r_p,
                inv_s: &inv_s,
                band: &band,
            };
            // Predictor (affine scaling).
            for ((rc, s), z) in r_c.iter_mut().zip(&s).zip(&z) {
                *rc = s * z;
            }
            system.direction(&r_c, &mut y, &mut dv, &mut ds, &mut dz);
            let alpha_aff = step_to_boundary(&s, &ds).min(step_to_boundary(&z, &dz));
            let mu_aff = s
                .iter()
                .zip(&ds)
                .zip(z.iter().zip(&dz))
                .map(|((s, ds), (z, dz))| (s + alpha_aff * ds) * (z + alpha_aff * dz))
                .sum::<f64>()
                / m as f64;
            let sigma = (mu_aff / mu).powi(3);
            // Corrector (centring and second-order term).
            for ((rc, (s, z)), (ds, dz)) in
                r_c.iter_mut().zip(s.iter().zip(&z)).zip(ds.iter().zip(&dz))
            {
                *rc = s * z + ds * dz - sigma * mu;
            }
            system.direction(&r_c, &mut y, &mut dv, &mut ds, &mut dz);
            let alpha = (0.99 * step_to_boundary(&s, &ds).min(step_to_boundary(&z, &dz))).min(1.0);
            for (x, d) in v.iter_mut().zip(&dv) {
                *x += alpha * d;
            }
            for ((s, z), (ds, dz)) in s.iter_mut().zip(z.iter_mut()).zip(ds.iter().zip(&dz)) {
                *s += alpha * ds;
                *z += alpha * dz;
            }
        }
        Err(failed("max iterations"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small dense reference: M x = b by Gaussian elimination.
    #[allow(clippy::needless_range_loop)]
    fn dense_solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
        let n = b.len();
        for c in 0..n {
            for r in c + 1..n {
                let f = a[r][c] / a[c][c];
                for k in c..n {
                    a[r][k] -= f * a[c][k];
                }
                b[r] -= f * b[c];
            }
        }
        let mut x = vec![0.0; n];
        for r in (0..n).rev() {
            let s: f64 = (r + 1..n).map(|k| a[r][k] * x[k]).sum();
            x[r] = (b[r] - s) / a[r][r];
        }
        x
    }

    #[test]
    fn the_banded_cholesky_solves_a_pentadiagonal_system() {
        let n = 9;
        let mut dense = vec![vec![0.0; n]; n];
        let mut band: Band = vec![[0.0; 3]; n];
        for i in 0..n {
            dense[i][i] = 6.0 + i as f64;
            band[i][0] = dense[i][i];
            if i >= 1 {
                dense[i][i - 1] = -1.5 + 0.1 * i as f64;
                dense[i - 1][i] = dense[i][i - 1];
                band[i][1] = dense[i][i - 1];
            }
            if i >= 2 {
                dense[i][i - 2] = 0.7 - 0.05 * i as f64;
                dense[i - 2][i] = dense[i][i - 2];
                band[i][2] = dense[i][i - 2];
            }
        }
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64).sin() + 2.0).collect();
        let expected = dense_solve(dense, rhs.clone());
        assert!(cholesky_in_place(&mut band));
        let mut x = rhs;
        cholesky_solve(&band, &mut x);
        for (a, b) in x.iter().zip(&expected) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
    }

    #[test]
    fn an_unconstrained_minimum_inside_the_box_is_found() {
        let h = [2.0, 4.0, 1.0];
        let q = [-20.0, -40.0, -12.0];
        let qp = BandedQp {
            h: &h,
            q: &q,
            lo: &[0.5; 3],
            hi: &[30.0; 3],
            accel_step: None,
            jerk_step: None,
        };
        let v = qp.solve(50, 1e-9).unwrap();
        for (vi, expected) in v.iter().zip([10.0, 10.0, 12.0]) {
            assert!((vi - expected).abs() < 1e-6, "{v:?}");
        }
    }

    #[test]
    fn the_acceleration_chain_and_the_box_bind_where_they_must() {
        // Pulled towards 20 m/s from a first speed boxed at 10: the chain of ±1 m/s steps
        // binds from the start, and the box caps the fourth speed at 12.
        let n = 6;
        let h = vec![1.0; n];
        let q = vec![-20.0; n];
        let mut lo = vec![0.5; n];
        let mut hi = vec![30.0; n];
        lo[0] = 10.0;
        hi[0] = 10.0;
        hi[3] = 12.0;
        let qp = BandedQp {
            h: &h,
            q: &q,
            lo: &lo,
            hi: &hi,
            accel_step: Some(1.0),
            jerk_step: None,
        };
        let v = qp.solve(50, 1e-9).unwrap();
        let expected = [10.0, 11.0, 12.0, 12.0, 13.0, 14.0];
        for (vi, e) in v.iter().zip(expected) {
            assert!((vi - e).abs() < 1e-5, "{v:?}");
        }
    }

    #[test]
    fn an_empty_box_is_a_typed_failure_not_a_hang() {
        let qp = BandedQp {
            h: &[1.0, 1.0],
            q: &[0.0, 0.0],
            lo: &[5.0, 5.0],
            hi: &[5.0, 1.0],
            accel_step: Some(0.1),
            jerk_step: None,
        };
        assert!(matches!(
            qp.solve(50, 1e-9),
            Err(PlannerError::SolverFailed { .. })
        ));
    }
}
