//! The convex subproblem of one SCP iteration as a quadratic program (`speed_program =
//! "newton-qp"`): the travel time is replaced by its second-order Taylor model at the iterate,
//! so the SOC rows and the t variables of [`cone_program`](super::cone_program) disappear.
//!
//! Decision vector (N entries): x = [v_1 … v_N], offset [`V_OFFSET`](super::cone_program::V_OFFSET) (as in the cone program).
//!
//! ```text
//!   travel time   w1 Δs_i / v_i ≈ w1 Δs_i (1/v̄_i − (v_i − v̄_i)/v̄_i² + (v_i − v̄_i)²/v̄_i³)
//!   minimise ½ vᵀ P v + qᵀ v:
//!     P = diag(h_i),   h_i = w2 + 2 w1 Δs_i / v̄_i³
//!     q_i = g_i − w2 V_target − 3 w1 Δs_i / v̄_i²          (g = w ∇φ(v̄), the linearised term)
//!   rows of s = b − A v, all in one nonnegative cone, in this order:
//!     box_hi  [0, N)          v_i ≤ hi_i
//!     box_lo  [N, 2N)         −v_i ≤ −lo_i
//!     accel   (2(N−1))        ±(v_{i+1} − v_i) ≤ a_max Δt
//!     jerk    (2(N−2))        ±(v_{i+1} − 2v_i + v_{i−1}) ≤ j_max Δt²
//! ```
//!
//! The rows are those of the cone program without its 3N SOC rows; the KKT system shrinks from
//! 3N + 4N − 2 (+ jerk) + 2N to N + 4N − 2 (+ jerk) rows and has no second-order cones. The
//! model is exact to second order at v̄ (its error is O(|v − v̄|³ / v̄⁴) inside the trust
//! region), so the SCP's line search on the true J (`scp`) keeps every accepted step a descent
//! step of the real problem; unlike the cone program it is not exact in one solve when the
//! problem is convex, so the SCP iterates in that case too. Only P's diagonal, q and b change
//! between solves: one Clarabel solver serves every iteration and cycle through `update_P`,
//! `update_q` and `update_b`.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSolver, NonnegativeConeT, SupportedConeT};

use super::banded_ipm::BandedQp;
use super::cone_program::{Layout, PROBLEM};
use super::scp::SpeedOptimiser;
use super::{SpeedOptimiserParams, SpeedProblem, SpeedProgram};
use crate::clarabel_setup::{new_solver, solve_checked, solver_failed};
use crate::error::PlannerError;

/// A Clarabel solver of the Newton QP and what fixes its structure.
pub(super) struct CachedQp {
    layout: Layout,
    max_iterations: u32,
    tolerance_bits: u64,
    solver: DefaultSolver<f64>,
}

impl Layout {
    /// Rows of the QP: the linear rows of the cone program.
    fn qp_rows(&self) -> usize {
        self.linear_rows()
    }

    /// P = diag(h), upper triangle.
    fn qp_p_matrix(&self, h: &[f64]) -> CscMatrix<f64> {
        let n = self.n;
        CscMatrix::new(n, n, (0..=n).collect(), (0..n).collect(), h.to_vec())
    }

    /// A, row blocks as in the module doc (the cone program's linear rows, without its SOC
    /// rows).
    fn qp_a_matrix(&self) -> CscMatrix<f64> {
        let (rows, cols, vals) = self.linear_triplets();
        CscMatrix::new_from_triplets(self.qp_rows(), self.n, rows, cols, vals)
    }

    fn qp_cones(&self) -> Vec<SupportedConeT<f64>> {
        vec![NonnegativeConeT(self.qp_rows())]
    }
}

impl SpeedOptimiser {
    /// One solve of the Newton QP (module doc) expanded at `at` (v̄, every entry > 0), with
    /// the non-convex term linearised to `gradient` (already × its weight) and the box
    /// [lo, hi], by Clarabel or, with `speed_program = "newton-qp-banded"`, by the banded
    /// interior-point method of [`banded_ipm`](super::banded_ipm). Returns v_1..v_N.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn solve_newton_qp(
        &mut self,
        params: &SpeedOptimiserParams,
        layout: Layout,
        problem: &SpeedProblem<'_>,
        at: &[f64],
        gradient: &[f64],
        lo: &[f64],
        hi: &[f64],
        accel_step: f64,
        jerk_step: f64,
    ) -> Result<Vec<f64>, PlannerError> {
        let n = layout.n;
        let (h, q) = newton_model(params, problem, at, gradient, n);
        let mut b = Vec::with_capacity(layout.qp_rows());
        b.extend_from_slice(hi);
        b.extend(lo.iter().map(|l| -l));
        b.extend(std::iter::repeat_n(accel_step, layout.accel_rows()));
        b.extend(std::iter::repeat_n(jerk_step, layout.jerk_rows()));
        if at.iter().any(|v| *v <= 0.0) || h.iter().chain(&q).chain(&b).any(|v| !v.is_finite()) {
            return Err(PlannerError::NonFinite {
                what: "speed_optimisation QP data".into(),
            });
        }
        if params.program == SpeedProgram::NewtonQpBanded {
            // The same QP by the banded interior-point method (`banded_ipm`), with the same
            // iteration cap and tolerance.
            let qp = BandedQp {
                h: &h,
                q: &q,
                lo,
                hi,
                accel_step: layout.accel.then_some(accel_step),
                jerk_step: layout.jerk.then_some(jerk_step),
            };
            let x = qp.solve(params.solver.max_iterations, params.solver.tolerance)?;
            return Ok(snap_onto_box(&x, lo, hi));
        }

        let tolerance_bits = params.solver.tolerance.to_bits();
        let reusable = self.cached_qp.as_ref().is_some_and(|c| {
            c.layout == layout
                && c.max_iterations == params.solver.max_iterations
                && c.tolerance_bits == tolerance_bits
        });
        let updated = reusable
            && self.cached_qp.as_mut().is_some_and(|c| {
                c.solver.update_P(&h).is_ok()
                    && c.solver.update_q(&q).is_ok()
                    && c.solver.update_b(&b).is_ok()
            });
        if !updated {
            let solver = new_solver(
                PROBLEM,
                &layout.qp_p_matrix(&h),
                &q,
                &layout.qp_a_matrix(),
                &b,
                &layout.qp_cones(),
                &params.solver,
            )?;
            self.cached_qp = Some(CachedQp {
                layout,
                max_iterations: params.solver.max_iterations,
                tolerance_bits,
                solver,
            });
        }
        let Some(cached) = self.cached_qp.as_mut() else {
            return Err(solver_failed(PROBLEM, "no solver"));
        };
        let x = solve_checked(&mut cached.solver, PROBLEM, n)?;
        Ok(snap_onto_box(x, lo, hi))
    }
}

/// The Newton model's P diagonal h and linear term q at v̄ = `at` (module doc).
fn newton_model(
    params: &SpeedOptimiserParams,
    problem: &SpeedProblem<'_>,
    at: &[f64],
    gradient: &[f64],
    n: usize,
) -> (Vec<f64>, Vec<f64>) {
    let w1 = params.objective.travel_time_weight;
    let w2 = params.objective.speed_deviation_weight;
    let mut h = Vec::with_capacity(n);
    let mut q = Vec::with_capacity(n);
    for i in 0..n {
        let (ds, vbar) = (problem.segment_lengths_m[i].max(0.0), at[i]);
        h.push(w2 + 2.0 * w1 * ds / (vbar * vbar * vbar));
        q.push(gradient[i] - w2 * problem.target_speed_mps - 3.0 * w1 * ds / (vbar * vbar));
    }
    (h, q)
}

/// Snaps interior-point round-off onto the box [lo, hi] (an empty box, lo > hi, onto lo).
fn snap_onto_box(x: &[f64], lo: &[f64], hi: &[f64]) -> Vec<f64> {
    x.iter()
        .zip(lo.iter().zip(hi))
        .map(|(xi, (l, h))| xi.clamp(*l, h.max(*l)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::{SpeedProblem, SpeedProgram};
    use super::*;
    use crate::params::PlannerParams;

    fn params(program: SpeedProgram, scp_iterations: usize) -> PlannerParams {
        PlannerParams {
            speed_program: program,
            max_scp_iterations: scp_iterations,
            scp_relative_tolerance: 0.0,
            // Tight, so that the comparison measures the programs, not the solver's stopping.
            solver_tolerance: 1e-10,
            ..PlannerParams::default()
        }
    }

    /// A convex speed problem with bends (clipped speeds) and a target above the current speed.
    fn bends() -> (Vec<f64>, Vec<f64>) {
        let segment_lengths_m: Vec<f64> = (0..20).map(|i| 6.0 + 0.3 * i as f64).collect();
        let mut max_speeds_mps = vec![30.0; 20];
        max_speeds_mps[6] = 14.0;
        max_speeds_mps[13] = 12.5;
        (segment_lengths_m, max_speeds_mps)
    }

    /// The convex problem (no interaction term) over `bends()` from `current` towards `target`.
    fn convex<'a>(
        segment_lengths_m: &'a [f64],
        max_speeds_mps: &'a [f64],
        current_speed_mps: f64,
        target_speed_mps: f64,
    ) -> SpeedProblem<'a> {
        SpeedProblem {
            current_speed_mps,
            target_speed_mps,
            segment_lengths_m,
            max_speeds_mps,
            initial_guess_mps: None,
            interaction: None,
            interaction_weight: 0.0,
        }
    }

    #[test]
    fn converges_onto_the_exact_cone_solution_of_a_convex_problem() {
        let (segment_lengths_m, max_speeds_mps) = bends();
        let problem = convex(&segment_lengths_m, &max_speeds_mps, 15.0, 18.0);
        let exact = SpeedOptimiser::new()
            .solve(&(&params(SpeedProgram::Cone, 2)).into(), &problem)
            .unwrap();
        assert_eq!(exact.solves, 1);
        let newton = SpeedOptimiser::new()
            .solve(&(&params(SpeedProgram::NewtonQp, 30)).into(), &problem)
            .unwrap();
        assert!(newton.solves > 1, "the QP iterates on a convex problem");
        for (a, b) in newton.speeds_mps.iter().zip(&exact.speeds_mps) {
            assert!((a - b).abs() < 1e-4, "{a} vs {b}");
        }
        assert!((newton.objective - exact.objective).abs() < 1e-6 * exact.objective.abs());
    }

    /// The acceptance criterion's per-problem part (docs/parameters.md, "A banded solver for
    /// the Newton QP"): with the acceleration and jerk rows on, the banded program's SCP
    /// solution is Clarabel's to 1e-4 m/s per speed and 1e-6 relative in J, at the default
    /// solver tolerance, on convex problems and on problems whose warm start is far off.
    #[test]
    fn the_banded_program_finds_the_clarabel_newton_qp_solution() {
        let (segment_lengths_m, max_speeds_mps) = bends();
        let guess = [12.0; 20];
        for (current, target, warm) in [
            (15.0, 18.0, false),
            (10.0, 25.0, false),
            (22.0, 14.0, false),
            (15.0, 18.0, true),
        ] {
            let mut problem = convex(&segment_lengths_m, &max_speeds_mps, current, target);
            if warm {
                problem.initial_guess_mps = Some(&guess);
            }
            let solve = |program: SpeedProgram| {
                let p = PlannerParams {
                    speed_program: program,
                    ..PlannerParams::default()
                };
                SpeedOptimiser::new().solve(&(&p).into(), &problem).unwrap()
            };
            let clarabel = solve(SpeedProgram::NewtonQp);
            let banded = solve(SpeedProgram::NewtonQpBanded);
            for (a, b) in banded.speeds_mps.iter().zip(&clarabel.speeds_mps) {
                assert!((a - b).abs() < 1e-4, "{current} → {target}: {a} vs {b}");
            }
            assert!(
                (banded.objective - clarabel.objective).abs() <= 1e-6 * clarabel.objective.abs(),
                "{} vs {}",
                banded.objective,
                clarabel.objective
            );
        }
    }

    #[test]
    fn every_iterate_respects_the_acceleration_chain() {
        let (segment_lengths_m, max_speeds_mps) = bends();
        let problem = convex(&segment_lengths_m, &max_speeds_mps, 10.0, 25.0);
        let p = params(SpeedProgram::NewtonQp, 2);
        let solution = SpeedOptimiser::new().solve(&(&p).into(), &problem).unwrap();
        let step = p.max_accel_mps2 * p.step_time_s;
        assert!(solution.anchored);
        assert!((solution.speeds_mps[0] - 10.0).abs() <= step + 1e-6);
        for w in solution.speeds_mps.windows(2) {
            assert!(
                (w[1] - w[0]).abs() <= step + 1e-6,
                "{:?}",
                solution.speeds_mps
            );
        }
        for (v, hi) in solution.speeds_mps.iter().zip(&max_speeds_mps) {
            assert!(*v <= hi + 1e-6);
        }
    }

    #[test]
    fn a_non_positive_expansion_point_is_a_typed_error_not_a_division_by_zero() {
        let (segment_lengths_m, max_speeds_mps) = bends();
        let problem = convex(&segment_lengths_m, &max_speeds_mps, 15.0, 18.0);
        let p = SpeedOptimiserParams::from(&params(SpeedProgram::NewtonQp, 2));
        let layout = Layout::new(&p.bounds, 20);
        let mut at = vec![15.0; 20];
        at[3] = 0.0;
        let err = SpeedOptimiser::new()
            .solve_newton_qp(
                &p,
                layout,
                &problem,
                &at,
                &[0.0; 20],
                &[0.5; 20],
                &max_speeds_mps,
                1.2,
                1.0,
            )
            .unwrap_err();
        assert!(matches!(err, PlannerError::NonFinite { .. }), "{err}");
    }
}
