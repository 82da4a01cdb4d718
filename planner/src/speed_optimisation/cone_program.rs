//! The convex subproblem of one SCP iteration, as a Clarabel cone program.
//!
//! Decision vector (2N entries): x = [v_1 … v_N, t_1 … t_N], offsets [`V_OFFSET`] and
//! [`t_offset`]`(N)`.
//!
//! ```text
//!   minimise ½ xᵀPx + qᵀx:   P = diag(w2 … w2, 0 … 0),   q = [w ∇φ(v̄) − w2 V_target ; w1 … w1]
//!   rows of s = b − A x, in this order:
//!     box_hi  [0, N)          v_i ≤ hi_i                       A = +e_vi             b = hi_i
//!     box_lo  [N, 2N)         −v_i ≤ −lo_i                     A = −e_vi             b = −lo_i
//!     accel   (2(N−1))        ±(v_{i+1} − v_i) ≤ a_max Δt      A = ±(e_v(i+1) − e_vi) b = a_max Δt
//!     jerk    (2(N−2))        ±(v_{i+1} − 2v_i + v_{i−1}) ≤ j_max Δt²
//!     ── all of the above in one nonnegative cone ──
//!     SOC_i   (3 rows each)   (t_i + v_i, t_i − v_i, 2√Δs_i) ∈ SOC(3)   ⇔ t_i v_i ≥ Δs_i
//!                             A = (−e_ti − e_vi, −e_ti + e_vi, 0)   b = (0, 0, 2√Δs_i)
//! ```
//!
//! w ∇φ(v̄) is the linearised non-convex term (w3 for U_SLP, w_R for PF-SP's risk). hi_i / lo_i
//! hold V_i^max / v_min, the anchor to the current speed on v_1 (dropped when it cannot be met
//! together with the other bounds, e.g. in a sharp bend at high speed: the friction limit wins
//! over comfort) and the trust region. P and A depend only on N, w2 and which optional rows
//! are on, so one Clarabel solver serves every iteration and planning cycle through
//! `update_q` / `update_b`.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSolver, NonnegativeConeT, SecondOrderConeT, SupportedConeT};

use super::scp::SpeedOptimiser;
use super::{SpeedBounds, SpeedOptimiserParams, SpeedProblem};
use crate::clarabel_setup::{new_solver, solve_checked, solver_failed};
use crate::error::PlannerError;

/// Offset of v_1 in the decision vector.
pub(crate) const V_OFFSET: usize = 0;

/// Offset of t_1 in the decision vector of an N-speed problem.
pub(crate) const fn t_offset(n: usize) -> usize {
    n
}

/// Solver structure: what fixes P and A.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Layout {
    pub(super) n: usize,
    pub(super) accel: bool,
    pub(super) jerk: bool,
}

impl Layout {
    pub(super) fn new(bounds: &SpeedBounds, n: usize) -> Self {
        Self {
            n,
            accel: bounds.accel_bound_enabled && n >= 2,
            jerk: bounds.jerk_bound_enabled && n >= 3,
        }
    }

    pub(super) fn accel_rows(&self) -> usize {
        if self.accel { 2 * (self.n - 1) } else { 0 }
    }

    pub(super) fn jerk_rows(&self) -> usize {
        if self.jerk { 2 * (self.n - 2) } else { 0 }
    }

    pub(super) fn linear_rows(&self) -> usize {
        2 * self.n + self.accel_rows() + self.jerk_rows()
    }

    pub(super) fn rows(&self) -> usize {
        self.linear_rows() + 3 * self.n
    }

    pub(super) fn cones(&self) -> Vec<SupportedConeT<f64>> {
        let mut cones = vec![NonnegativeConeT(self.linear_rows())];
        cones.extend((0..self.n).map(|_| SecondOrderConeT(3)));
        cones
    }

    /// P = diag(w2 on v, 0 on t), upper triangle.
    pub(super) fn p_matrix(&self, w2: f64) -> CscMatrix<f64> {
        let n = self.n;
        let mut colptr: Vec<usize> = (0..=n).collect();
        colptr.extend(std::iter::repeat_n(n, n));
        CscMatrix::new(2 * n, 2 * n, colptr, (0..n).collect(), vec![w2; n])
    }

    /// Triplets (row, column, value) of the linear rows — box, acceleration, jerk, in the order
    /// of the module doc — over the speeds at columns V_OFFSET + i. The Newton QP has exactly
    /// these rows; the cone program adds its SOC rows after them.
    pub(super) fn linear_triplets(&self) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let n = self.n;
        let v = |i: usize| V_OFFSET + i;
        let box_hi_row = 0;
        let box_lo_row = n;
        let accel_row = 2 * n;
        let jerk_row = accel_row + self.accel_rows();
        let (mut rows, mut cols, mut vals) = (Vec::new(), Vec::new(), Vec::new());
        let mut push = |r: usize, c: usize, value: f64| {
            rows.push(r);
            cols.push(c);
            vals.push(value);
        };
        for i in 0..n {
            push(box_hi_row + i, v(i), 1.0);
            push(box_lo_row + i, v(i), -1.0);
        }
        if self.accel {
            for i in 0..n - 1 {
                let r = accel_row + 2 * i;
                push(r, v(i + 1), 1.0);
                push(r, v(i), -1.0);
                push(r + 1, v(i + 1), -1.0);
                push(r + 1, v(i), 1.0);
            }
        }
        if self.jerk {
            for i in 1..n - 1 {
                let r = jerk_row + 2 * (i - 1);
                push(r, v(i + 1), 1.0);
                push(r, v(i), -2.0);
                push(r, v(i - 1), 1.0);
                push(r + 1, v(i + 1), -1.0);
                push(r + 1, v(i), 2.0);
                push(r + 1, v(i - 1), -1.0);
            }
        }
        (rows, cols, vals)
    }

    /// A, row blocks as in the module doc.
    pub(super) fn a_matrix(&self) -> CscMatrix<f64> {
        let n = self.n;
        // Columns: v_i at V_OFFSET + i, t_i at t_offset(n) + i.
        let v = |i: usize| V_OFFSET + i;
        let t = |i: usize| t_offset(n) + i;
        let soc_row = self.linear_rows();
        let (mut rows, mut cols, mut vals) = self.linear_triplets();
        // Second-order cones: (t_i + v_i, t_i − v_i, 2√Δs_i); the constant is in b.
        for i in 0..n {
            let r = soc_row + 3 * i;
            for (row, col, value) in [
                (r, t(i), -1.0),
                (r, v(i), -1.0),
                (r + 1, t(i), -1.0),
                (r + 1, v(i), 1.0),
            ] {
                rows.push(row);
                cols.push(col);
                vals.push(value);
            }
        }
        CscMatrix::new_from_triplets(self.rows(), 2 * n, rows, cols, vals)
    }
}

pub(super) struct CachedSolver {
    pub(super) layout: Layout,
    w2_bits: u64,
    max_iterations: u32,
    tolerance_bits: u64,
    solver: DefaultSolver<f64>,
}

/// The name of both programs of the speed optimisation in errors.
pub(super) const PROBLEM: &str = "speed_optimisation";

impl SpeedOptimiser {
    /// One convex solve with the non-convex term linearised to `gradient` (already × its weight) and the
    /// box [lo, hi]. Returns v_1..v_N.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn solve_convex(
        &mut self,
        params: &SpeedOptimiserParams,
        layout: Layout,
        problem: &SpeedProblem<'_>,
        gradient: &[f64],
        lo: &[f64],
        hi: &[f64],
        accel_step: f64,
        jerk_step: f64,
    ) -> Result<Vec<f64>, PlannerError> {
        let n = layout.n;
        let w = &params.objective;
        // q = [w3 ∇φ − w2 V_target ; w1].
        let mut q = Vec::with_capacity(2 * n);
        q.extend(
            gradient
                .iter()
                .map(|g| g - w.speed_deviation_weight * problem.target_speed_mps),
        );
        q.extend(std::iter::repeat_n(w.travel_time_weight, n));
        // b, block by block.
        let mut b = Vec::with_capacity(layout.rows());
        b.extend_from_slice(hi);
        b.extend(lo.iter().map(|l| -l));
        b.extend(std::iter::repeat_n(accel_step, layout.accel_rows()));
        b.extend(std::iter::repeat_n(jerk_step, layout.jerk_rows()));
        for ds in problem.segment_lengths_m {
            b.extend_from_slice(&[0.0, 0.0, 2.0 * ds.max(0.0).sqrt()]);
        }
        if q.iter().chain(&b).any(|v| !v.is_finite()) {
            return Err(PlannerError::NonFinite {
                what: "speed_optimisation data".into(),
            });
        }

        let w2_bits = w.speed_deviation_weight.to_bits();
        let tolerance_bits = params.solver.tolerance.to_bits();
        let reusable = self.cached.as_ref().is_some_and(|c| {
            c.layout == layout
                && c.w2_bits == w2_bits
                && c.max_iterations == params.solver.max_iterations
                && c.tolerance_bits == tolerance_bits
        });
        let updated = reusable
            && self
                .cached
                .as_mut()
                .is_some_and(|c| c.solver.update_q(&q).is_ok() && c.solver.update_b(&b).is_ok());
        if !updated {
            let solver = new_solver(
                PROBLEM,
                &layout.p_matrix(w.speed_deviation_weight),
                &q,
                &layout.a_matrix(),
                &b,
                &layout.cones(),
                &params.solver,
            )?;
            self.cached = Some(CachedSolver {
                layout,
                w2_bits,
                max_iterations: params.solver.max_iterations,
                tolerance_bits,
                solver,
            });
        }
        let Some(cached) = self.cached.as_mut() else {
            return Err(solver_failed(PROBLEM, "no solver"));
        };
        let x = solve_checked(&mut cached.solver, PROBLEM, 2 * n)?;
        // Snap interior-point round-off onto the box.
        Ok((0..n)
            .map(|i| x[i].clamp(lo[i], hi[i].max(lo[i])))
            .collect())
    }
}
