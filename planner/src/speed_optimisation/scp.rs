//! The SCP loop: linearise the non-convex term, solve the convex subproblem inside a trust
//! region, shorten the step by backtracking on the true objective (module doc of
//! `speed_optimisation`).

use super::cone_program::{CachedSolver, Layout};
use super::newton_qp::CachedQp;
use super::{
    SpeedOptimiserParams, SpeedProblem, SpeedProgram, SpeedSolution, objective, smooth_gradient,
};
use crate::error::PlannerError;

/// The speed optimiser. Holds a Clarabel solver between solves (and planning cycles) so only
/// q and b are rewritten; it is rebuilt when the problem's structure changes.
#[derive(Default)]
pub(crate) struct SpeedOptimiser {
    pub(super) cached: Option<CachedSolver>,
    pub(super) cached_qp: Option<CachedQp>,
}

impl std::fmt::Debug for SpeedOptimiser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpeedOptimiser")
            .field("cached", &self.cached.as_ref().map(|c| c.layout))
            .field("cached_qp", &self.cached_qp.is_some())
            .finish()
    }
}

impl Clone for SpeedOptimiser {
    /// A clone starts without a cached solver (Clarabel's solver is not `Clone`).
    fn clone(&self) -> Self {
        Self::default()
    }
}

/// Sufficient-decrease fraction c of the SCP line search: a step t along d is kept only if
/// J(v̄ + t d) ≤ J(v̄) + c t ∇J(v̄)ᵀd. Where J is close to quadratic along d, with its minimum
/// at t*, the test holds iff t ≤ 2(1 − c)·t* = 1.5 t*; so a halved step that passes after a
/// failed one lies in (0.75 t*, 1.5 t*] and the distance to the minimum along d shrinks at
/// least by half: the iterate converges onto a local minimum (within one cycle and across
/// warm-started cycles) instead of jumping across it by a fixed trust-region quantum.
const ARMIJO_FRACTION: f64 = 0.25;

/// Halvings of the SCP line search before the step is given up (t ≥ 2⁻⁶: with the 2 m/s trust
/// region, steps down to ≈ 3 cm/s). Each halving costs one evaluation of J, no convex solve.
const LINE_SEARCH_HALVINGS: usize = 6;

/// Reachable-interval check of the box + acceleration chain from v_1.
fn chain_is_feasible(lo: &[f64], hi: &[f64], step_mps: f64) -> bool {
    let (mut l, mut h) = (lo[0], hi[0]);
    if l > h {
        return false;
    }
    for i in 1..lo.len() {
        l = lo[i].max(l - step_mps);
        h = hi[i].min(h + step_mps);
        if l > h {
            return false;
        }
    }
    true
}

/// The point of the box [lo, hi] with |v_{i+1} − v_i| ≤ step closest to `guess` in the sense
/// of a forward clamp under the largest feasible profile: U_N = hi_N, U_i = min(hi_i,
/// U_{i+1} + step); then v_i = clamp(guess_i, max(lo_i, v_{i−1} − step), min(U_i, v_{i−1} +
/// step)). Feasible whenever the chain is (`chain_is_feasible`) and lo_i ≤ hi_i for i > 1.
fn project_onto_chain(guess: &[f64], lo: &[f64], hi: &[f64], step: f64) -> Vec<f64> {
    let n = guess.len();
    let mut upper = hi.to_vec();
    for i in (0..n.saturating_sub(1)).rev() {
        upper[i] = upper[i].min(upper[i + 1] + step);
    }
    let mut v = Vec::with_capacity(n);
    for i in 0..n {
        let (mut l, mut h) = (lo[i], upper[i]);
        if let Some(prev) = v.last().copied() {
            let prev: f64 = prev;
            l = l.max(prev - step);
            h = h.min(prev + step);
        }
        v.push(guess[i].clamp(l, h.max(l)));
    }
    v
}

impl SpeedOptimiser {
    /// A fresh optimiser.
    pub fn new() -> Self {
        Self::default()
    }

    /// Solves one speed problem (module doc). Errors when the first convex solve fails
    /// (status other than Solved / AlmostSolved, or a non-finite value); later SCP
    /// iterations that fail just end the iteration with the last accepted speeds.
    pub(crate) fn solve(
        &mut self,
        params: &SpeedOptimiserParams,
        problem: &SpeedProblem<'_>,
    ) -> Result<SpeedSolution, PlannerError> {
        let n = problem.segment_lengths_m.len();
        if n == 0 || problem.max_speeds_mps.len() != n {
            return Err(PlannerError::invalid(
                "speed_optimisation.max_speeds_mps",
                problem.max_speeds_mps.len() as f64,
                format!("need one bound per segment ({n} segments, at least one)"),
            ));
        }
        if let Some(term) = problem.interaction
            && term.slots() != n
        {
            return Err(PlannerError::invalid(
                "speed_optimisation.interaction",
                term.slots() as f64,
                format!("need one time slot per segment ({n})"),
            ));
        }
        let scalars = [problem.current_speed_mps, problem.target_speed_mps];
        if scalars
            .iter()
            .chain(problem.segment_lengths_m)
            .chain(problem.max_speeds_mps)
            .any(|v| !v.is_finite())
        {
            return Err(PlannerError::NonFinite {
                what: "speed problem data".into(),
            });
        }
        let layout = Layout::new(&params.bounds, n);
        let accel_step = params.bounds.accel_step_mps;
        let jerk_step = params.bounds.jerk_step_mps;
        let weights = &params.objective;

        // Box bounds: v_min ≤ v_i ≤ max(V_i^max, v_min).
        let lo = vec![params.bounds.min_speed_mps; n];
        let hi: Vec<f64> = problem
            .max_speeds_mps
            .iter()
            .map(|v| v.max(params.bounds.min_speed_mps))
            .collect();
        // Anchor v_1 to the current speed when the chain stays feasible.
        let mut lo_anchor = lo.clone();
        let mut hi_anchor = hi.clone();
        let mut anchored = false;
        if layout.accel {
            let v0 = problem.current_speed_mps.max(0.0);
            lo_anchor[0] = lo[0].max(v0 - accel_step);
            hi_anchor[0] = hi[0].min(v0 + accel_step);
            anchored = chain_is_feasible(&lo_anchor, &hi_anchor, accel_step);
        }
        let (base_lo, base_hi) = if anchored {
            (lo_anchor, hi_anchor)
        } else {
            (lo.clone(), hi.clone())
        };

        let interaction = problem
            .interaction
            .filter(|_| problem.interaction_weight > 0.0);
        let gradient_at = |v: &[f64]| -> Vec<f64> {
            match interaction {
                Some(term) => {
                    let (_, g) = term.value_and_gradient(v);
                    g.iter().map(|gi| problem.interaction_weight * gi).collect()
                }
                None => vec![0.0; n],
            }
        };

        // Without interaction the problem is convex: one exact solve of the cone program.
        if interaction.is_none() && params.program == SpeedProgram::Cone {
            let zero = vec![0.0; n];
            let mut solves = 1;
            let v = match self.solve_convex(
                params, layout, problem, &zero, &base_lo, &base_hi, accel_step, jerk_step,
            ) {
                Ok(v) => v,
                Err(_) if anchored => {
                    // E.g. jerk rows the anchored chain cannot meet: retry unanchored.
                    solves += 1;
                    anchored = false;
                    self.solve_convex(
                        params, layout, problem, &zero, &lo, &hi, accel_step, jerk_step,
                    )?
                }
                Err(e) => return Err(e),
            };
            let j = objective(weights, problem, &v);
            if !j.is_finite() {
                return Err(PlannerError::NonFinite {
                    what: "speed objective".into(),
                });
            }
            return Ok(SpeedSolution {
                speeds_mps: v,
                objective: j,
                solves,
                anchored,
                stopped_at_iteration_cap: false,
            });
        }

        // SCP from a feasible start: the guess (previous plan shifted in time, or V_target)
        // projected onto the box and acceleration chain. With jerk rows the projection is not
        // guaranteed feasible, so the first iteration then runs without a trust region.
        let raw_guess: Vec<f64> = match problem.initial_guess_mps {
            Some(g) if g.len() == n && g.iter().all(|v| v.is_finite()) => g.to_vec(),
            _ => vec![problem.target_speed_mps; n],
        };
        let chain_step = if layout.accel {
            accel_step
        } else {
            f64::INFINITY
        };
        let mut v = project_onto_chain(&raw_guess, &base_lo, &base_hi, chain_step);
        let mut j = objective(weights, problem, &v);
        let mut trust_first = !layout.jerk && j.is_finite();
        let mut rho = params.scp.trust_region_mps;
        let mut solves = 0;
        let mut solved_once = false;
        // Cleared by every way out of the loop but running out of iterations.
        let mut stopped_at_iteration_cap = true;
        for iteration in 0..params.scp.max_iterations {
            let g = gradient_at(&v);
            let (lo_k, hi_k): (Vec<f64>, Vec<f64>) = if iteration > 0 || trust_first {
                (
                    base_lo
                        .iter()
                        .zip(&v)
                        .map(|(l, vi)| l.max(vi - rho))
                        .collect(),
                    base_hi
                        .iter()
                        .zip(&v)
                        .map(|(h, vi)| h.min(vi + rho))
                        .collect(),
                )
            } else {
                (base_lo.clone(), base_hi.clone())
            };
            solves += 1;
            let solved = match params.program {
                SpeedProgram::Cone => self.solve_convex(
                    params, layout, problem, &g, &lo_k, &hi_k, accel_step, jerk_step,
                ),
                SpeedProgram::NewtonQp | SpeedProgram::NewtonQpBanded => self.solve_newton_qp(
                    params, layout, problem, &v, &g, &lo_k, &hi_k, accel_step, jerk_step,
                ),
            };
            let candidate = match solved {
                Ok(candidate) => candidate,
                Err(e) if !solved_once => return Err(e),
                Err(_) => {
                    stopped_at_iteration_cap = false;
                    break;
                }
            };
            solved_once = true;
            let jc = objective(weights, problem, &candidate);
            if !trust_first && iteration == 0 {
                // No feasible start to compare with: take the first solution as it is.
                v = candidate;
                j = jc;
                trust_first = true;
                continue;
            }
            // Backtracking (Armijo) line search along d = candidate − v̄ on the true J.
            let d: Vec<f64> = candidate.iter().zip(&v).map(|(c, vi)| c - vi).collect();
            let step_mps = d.iter().fold(0.0_f64, |m, di| m.max(di.abs()));
            if params.scp.step_tolerance_mps > 0.0 && step_mps <= params.scp.step_tolerance_mps {
                // The subproblem barely moves the iterate: converged. Its solution is kept when
                // it does not raise J (for the Newton QP, the last Newton step).
                if jc.is_finite() && jc <= j {
                    v = candidate;
                    j = jc;
                }
                stopped_at_iteration_cap = false;
                break;
            }
            let slope: f64 = (0..n)
                .map(|i| (smooth_gradient(weights, problem, i, v[i]) + g[i]) * d[i])
                .sum();
            let mut step = 1.0;
            let mut accepted = None;
            if slope.is_finite() && slope < 0.0 {
                for _ in 0..=LINE_SEARCH_HALVINGS {
                    let trial: Vec<f64> = v.iter().zip(&d).map(|(vi, di)| vi + step * di).collect();
                    let jt = objective(weights, problem, &trial);
                    if jt.is_finite() && jt < j && jt <= j + ARMIJO_FRACTION * step * slope {
                        accepted = Some((trial, jt));
                        break;
                    }
                    step *= 0.5;
                }
            }
            if step < 1.0 || accepted.is_none() {
                rho *= 0.5;
            }
            if accepted.is_none() && rho < params.scp.stall_trust_region_mps {
                // No descent step and a trust region this small: stalled, not capped.
                stopped_at_iteration_cap = false;
                break;
            }
            if let Some((trial, jt)) = accepted {
                let decrease = j - jt;
                v = trial;
                j = jt;
                if decrease <= params.scp.relative_tolerance * j.abs().max(1.0) {
                    stopped_at_iteration_cap = false;
                    break;
                }
            }
        }
        if !j.is_finite() || v.iter().any(|x| !x.is_finite()) {
            return Err(PlannerError::NonFinite {
                what: "speed objective".into(),
            });
        }
        Ok(SpeedSolution {
            speeds_mps: v,
            objective: j,
            solves,
            anchored,
            stopped_at_iteration_cap,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::SpeedProblem;
    use super::*;
    use crate::params::PlannerParams;

    fn unbounded_params() -> PlannerParams {
        PlannerParams {
            accel_bound_enabled: false,
            jerk_bound_enabled: false,
            ..PlannerParams::default()
        }
    }

    /// Positive root of w2 v³ − w2 V v² − w1 Δs = 0 (stationary point of
    /// w1 Δs / v + w2/2 (v − V)²) by Cardano's formula for the depressed cubic.
    fn cardano_optimum(w1: f64, w2: f64, target: f64, ds: f64) -> f64 {
        let c = w1 * ds / w2;
        // v = t + V/3: t³ + p t + q = 0.
        let p = -target * target / 3.0;
        let q = -2.0 * target.powi(3) / 27.0 - c;
        let disc = (q / 2.0).powi(2) + (p / 3.0).powi(3);
        assert!(disc > 0.0);
        let t = (-q / 2.0 + disc.sqrt()).cbrt() + (-q / 2.0 - disc.sqrt()).cbrt();
        t + target / 3.0
    }

    #[test]
    fn without_interaction_matches_the_per_waypoint_closed_form() {
        for program in [
            SpeedProgram::Cone,
            SpeedProgram::NewtonQp,
            SpeedProgram::NewtonQpBanded,
        ] {
            closed_form_case(program);
        }
    }

    /// The cone program in one solve; the Newton QP iterated to convergence.
    fn closed_form_case(program: SpeedProgram) {
        let params = PlannerParams {
            speed_program: program,
            max_scp_iterations: 30,
            scp_relative_tolerance: 0.0,
            travel_time_weight: 40.0,
            speed_deviation_weight: 0.8,
            solver_tolerance: 1e-10,
            ..unbounded_params()
        };
        let segment_lengths_m: Vec<f64> = (0..12).map(|i| 2.0 + 0.7 * i as f64).collect();
        let mut max_speeds_mps = vec![30.0; 12];
        max_speeds_mps[3] = 14.0; // clips
        max_speeds_mps[7] = 12.5; // clips
        let problem = SpeedProblem {
            current_speed_mps: 15.0,
            target_speed_mps: 15.0,
            segment_lengths_m: &segment_lengths_m,
            max_speeds_mps: &max_speeds_mps,
            initial_guess_mps: None,
            interaction: None,
            interaction_weight: 0.0,
        };
        let mut optimiser = SpeedOptimiser::new();
        let solution = optimiser.solve(&(&params).into(), &problem).unwrap();
        if program == SpeedProgram::Cone {
            assert_eq!(solution.solves, 1);
        }
        // Accuracy owed by the solver: J is w2-strongly convex in v, so a duality gap g bounds
        // ½ w2 ‖v − v*‖² ≤ g; Clarabel stops at g ≤ tol·(1 + |J|).
        let gap = params.solver_tolerance * (1.0 + solution.objective.abs());
        let owed = (2.0 * gap / params.speed_deviation_weight).sqrt();
        for i in 0..12 {
            let free = cardano_optimum(40.0, 0.8, 15.0, segment_lengths_m[i]);
            // The stationarity condition holds at the reference itself.
            let residual = -40.0 * segment_lengths_m[i] / (free * free) + 0.8 * (free - 15.0);
            assert!(residual.abs() < 1e-9);
            let expected = free.clamp(params.min_speed_mps, max_speeds_mps[i]);
            assert!(
                (solution.speeds_mps[i] - expected).abs() < owed,
                "{program:?}, i = {i}: {} vs {expected} (owed {owed})",
                solution.speeds_mps[i]
            );
        }
        assert!(
            solution.speeds_mps[0] > 15.3,
            "travel time pushes above V_target"
        );
        // The cached solver gives the same answer on a re-solve.
        let again = optimiser.solve(&(&params).into(), &problem).unwrap();
        for (a, b) in again.speeds_mps.iter().zip(&solution.speeds_mps) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
    }

    /// `stopped_at_iteration_cap`: true when the SCP runs out of iterations still improving,
    /// false once it meets its tolerance, and false for the cone program's one exact solve.
    #[test]
    fn reports_whether_the_iteration_cap_stopped_it() {
        let segment_lengths_m: Vec<f64> = vec![4.0; 12];
        let max_speeds_mps = vec![30.0; 12];
        let problem = SpeedProblem {
            current_speed_mps: 15.0,
            target_speed_mps: 15.0,
            segment_lengths_m: &segment_lengths_m,
            max_speeds_mps: &max_speeds_mps,
            initial_guess_mps: Some(&[12.0; 12]),
            interaction: None,
            interaction_weight: 0.0,
        };
        let solve = |program: SpeedProgram, iterations: usize| {
            let params = PlannerParams {
                speed_program: program,
                max_scp_iterations: iterations,
                travel_time_weight: 40.0,
                speed_deviation_weight: 0.8,
                ..unbounded_params()
            };
            SpeedOptimiser::new()
                .solve(&(&params).into(), &problem)
                .unwrap()
        };
        let one = solve(SpeedProgram::NewtonQp, 1);
        assert_eq!(one.solves, 1);
        assert!(one.stopped_at_iteration_cap);
        let many = solve(SpeedProgram::NewtonQp, 30);
        assert!(many.solves > 1 && many.solves < 30, "{}", many.solves);
        assert!(!many.stopped_at_iteration_cap);
        let exact = solve(SpeedProgram::Cone, 1);
        assert_eq!(exact.solves, 1);
        assert!(!exact.stopped_at_iteration_cap);
    }

    /// A warm start already at the optimum: the step-size stop ends the SCP after one solve;
    /// without it (`scp_step_tolerance_mps = 0`, and no relative-decrease stop) the SCP goes on
    /// solving for steps it cannot take. Both give the same speeds.
    #[test]
    fn a_warm_start_at_the_optimum_stops_after_one_solve() {
        let segment_lengths_m: Vec<f64> = (0..12).map(|i| 3.0 + 0.5 * i as f64).collect();
        let max_speeds_mps = vec![30.0; 12];
        let params = |step_tolerance_mps: f64| PlannerParams {
            travel_time_weight: 40.0,
            speed_deviation_weight: 0.8,
            scp_step_tolerance_mps: step_tolerance_mps,
            scp_relative_tolerance: 0.0,
            ..unbounded_params()
        };
        let cold = SpeedProblem {
            current_speed_mps: 15.0,
            target_speed_mps: 15.0,
            segment_lengths_m: &segment_lengths_m,
            max_speeds_mps: &max_speeds_mps,
            initial_guess_mps: None,
            interaction: None,
            interaction_weight: 0.0,
        };
        let optimum = SpeedOptimiser::new()
            .solve(&(&params(0.0)).into(), &cold)
            .unwrap()
            .speeds_mps;
        let warm = SpeedProblem {
            initial_guess_mps: Some(&optimum),
            ..cold
        };
        let with_stop = SpeedOptimiser::new()
            .solve(&(&params(0.01)).into(), &warm)
            .unwrap();
        let without = SpeedOptimiser::new()
            .solve(&(&params(0.0)).into(), &warm)
            .unwrap();
        assert_eq!(with_stop.solves, 1);
        assert!(!with_stop.stopped_at_iteration_cap);
        assert!(without.solves > 5, "{}", without.solves);
        for (a, b) in with_stop.speeds_mps.iter().zip(&without.speeds_mps) {
            assert!((a - b).abs() < 1e-6, "{a} vs {b}");
        }
    }

    #[test]
    fn acceleration_bounds_hold_and_anchor_to_the_current_speed() {
        let params = PlannerParams::default();
        let n = 20;
        let segment_lengths_m = vec![5.0; n];
        let max_speeds_mps = vec![30.0; n];
        let problem = SpeedProblem {
            current_speed_mps: 10.0,
            target_speed_mps: 20.0,
            segment_lengths_m: &segment_lengths_m,
            max_speeds_mps: &max_speeds_mps,
            initial_guess_mps: None,
            interaction: None,
            interaction_weight: 0.0,
        };
        let solution = SpeedOptimiser::new()
            .solve(&(&params).into(), &problem)
            .unwrap();
        assert!(solution.anchored);
        let step = params.max_accel_mps2 * params.step_time_s;
        assert!((solution.speeds_mps[0] - (10.0 + step)).abs() < 1e-5);
        for w in solution.speeds_mps.windows(2) {
            assert!(w[1] - w[0] <= step + 1e-6);
        }
    }

    #[test]
    fn jerk_bounds_hold_on_a_speed_step() {
        let params = PlannerParams {
            jerk_bound_enabled: true,
            max_jerk_mps3: 4.0,
            ..PlannerParams::default()
        };
        let n = 16;
        let segment_lengths_m = vec![4.0; n];
        let mut max_speeds_mps = vec![30.0; n];
        for v in &mut max_speeds_mps[8..] {
            *v = 12.0; // a bend ahead
        }
        let problem = SpeedProblem {
            current_speed_mps: 16.0,
            target_speed_mps: 16.0,
            segment_lengths_m: &segment_lengths_m,
            max_speeds_mps: &max_speeds_mps,
            initial_guess_mps: None,
            interaction: None,
            interaction_weight: 0.0,
        };
        let solution = SpeedOptimiser::new()
            .solve(&(&params).into(), &problem)
            .unwrap();
        let dt = params.step_time_s;
        let jerk_step = params.max_jerk_mps3 * dt * dt;
        let accel_step = params.max_accel_mps2 * dt;
        let v = &solution.speeds_mps;
        for w in v.windows(3) {
            assert!(
                (w[2] - 2.0 * w[1] + w[0]).abs() <= jerk_step + 1e-6,
                "{v:?}"
            );
        }
        for w in v.windows(2) {
            assert!((w[1] - w[0]).abs() <= accel_step + 1e-6, "{v:?}");
        }
        assert!(v[8..].iter().all(|x| *x <= 12.0 + 1e-6), "{v:?}");
        // The bound binds: without it the profile has a sharper corner.
        let free = SpeedOptimiser::new()
            .solve(&(&PlannerParams::default()).into(), &problem)
            .unwrap();
        let max_second_difference = free
            .speeds_mps
            .windows(3)
            .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
            .fold(0.0, f64::max);
        assert!(max_second_difference > jerk_step + 1e-3);
    }

    #[test]
    fn infeasible_anchor_is_dropped_for_the_friction_limit() {
        let params = PlannerParams::default();
        let segment_lengths_m = vec![5.0; 8];
        let mut max_speeds_mps = vec![30.0; 8];
        max_speeds_mps[1] = 8.0; // cannot brake from 25 to 8 in two steps at 3 m/s²
        let problem = SpeedProblem {
            current_speed_mps: 25.0,
            target_speed_mps: 25.0,
            segment_lengths_m: &segment_lengths_m,
            max_speeds_mps: &max_speeds_mps,
            initial_guess_mps: None,
            interaction: None,
            interaction_weight: 0.0,
        };
        let solution = SpeedOptimiser::new()
            .solve(&(&params).into(), &problem)
            .unwrap();
        assert!(!solution.anchored);
        assert!(solution.speeds_mps[1] <= 8.0 + 1e-6);
    }

    #[test]
    fn iteration_limit_zero_is_a_typed_failure() {
        let params = PlannerParams {
            solver_max_iterations: 0,
            ..PlannerParams::default()
        };
        let segment_lengths_m = vec![5.0; 6];
        let max_speeds_mps = vec![30.0; 6];
        let problem = SpeedProblem {
            current_speed_mps: 20.0,
            target_speed_mps: 20.0,
            segment_lengths_m: &segment_lengths_m,
            max_speeds_mps: &max_speeds_mps,
            initial_guess_mps: None,
            interaction: None,
            interaction_weight: 0.0,
        };
        let err = SpeedOptimiser::new()
            .solve(&(&params).into(), &problem)
            .unwrap_err();
        assert!(matches!(err, PlannerError::SolverFailed { .. }), "{err}");
    }
}
