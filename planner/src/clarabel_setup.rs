//! The one place the planner sets up and runs Clarabel: each program's settings (kept per
//! program, as Clarabel keeps its settings per solver implementation), building a solver, and
//! checking a solve's status and solution.
//!
//! The programs built on it are written out where they are assembled: the bounded cubic fit of
//! the local path (Eq. 9, [`crate::cubic_fit`]) and the convex subproblems of the speed
//! optimisation (Eq. 10, `speed_optimisation::cone_program` and `speed_optimisation::newton_qp`).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};

use crate::error::PlannerError;

/// The settings one program solves with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ProgramSettings {
    /// Clarabel's `max_iter`.
    pub(crate) max_iterations: u32,
    /// Clarabel's `tol_gap_abs`, `tol_gap_rel` and `tol_feas`.
    pub(crate) tolerance: f64,
    /// Data equilibration and iterative refinement of the KKT solves (Clarabel's defaults, on).
    /// The speed programs turn both off: they are small and well scaled (A entries ±1, ±2, P
    /// diagonal, speeds of order 10), and the two cost about half their solve time there
    /// without changing the answer (closed-form test at 1e-5).
    pub(crate) scaling_and_refinement: bool,
}

impl ProgramSettings {
    /// Clarabel's settings: quiet, no presolve (the programs have no redundant rows to remove),
    /// the rest at Clarabel's defaults.
    pub(crate) fn clarabel(&self) -> DefaultSettings<f64> {
        DefaultSettings {
            verbose: false,
            max_iter: self.max_iterations,
            tol_gap_abs: self.tolerance,
            tol_gap_rel: self.tolerance,
            tol_feas: self.tolerance,
            presolve_enable: false,
            equilibrate_enable: self.scaling_and_refinement,
            iterative_refinement_enable: self.scaling_and_refinement,
            ..DefaultSettings::default()
        }
    }
}

/// The error of program `problem` whose solver failed with `status`.
pub(crate) fn solver_failed(problem: &str, status: impl Into<String>) -> PlannerError {
    PlannerError::SolverFailed {
        problem: problem.into(),
        status: status.into(),
    }
}

/// A solver of `minimise ½ xᵀPx + qᵀx  s.t.  b − Ax ∈ cones` for program `problem`.
pub(crate) fn new_solver(
    problem: &str,
    p: &CscMatrix<f64>,
    q: &[f64],
    a: &CscMatrix<f64>,
    b: &[f64],
    cones: &[SupportedConeT<f64>],
    settings: &ProgramSettings,
) -> Result<DefaultSolver<f64>, PlannerError> {
    DefaultSolver::new(p, q, a, b, cones, settings.clarabel())
        .map_err(|e| solver_failed(problem, e.to_string()))
}

/// Solves, and returns the solution x of program `problem` if the solver reports it solved (or
/// almost) and x has `len` finite entries.
pub(crate) fn solve_checked<'s>(
    solver: &'s mut DefaultSolver<f64>,
    problem: &str,
    len: usize,
) -> Result<&'s [f64], PlannerError> {
    solver.solve();
    let status = solver.solution.status;
    if !matches!(status, SolverStatus::Solved | SolverStatus::AlmostSolved) {
        return Err(solver_failed(problem, format!("{status:?}")));
    }
    let x = &solver.solution.x;
    if x.len() != len || x.iter().any(|v| !v.is_finite()) {
        return Err(PlannerError::NonFinite {
            what: format!("{problem} solution"),
        });
    }
    Ok(x)
}
