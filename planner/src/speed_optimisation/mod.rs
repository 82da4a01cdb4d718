//! Interactive speed optimisation, paper Eq. 10, solved by sequential convex programming
//! (SCP) with Clarabel.
//!
//! Files: `scp` (the SCP loop and its line search), `cone_program` (the convex
//! subproblem: decision vector, constraint rows and their assembly), `newton_qp` (the same
//! subproblem with the travel time's second-order model: a QP, `speed_program = "newton-qp"`), `interaction_term`
//! ([`InteractionTerm`]: U_SLP at the planned arc length, and PF-SP's risk term),
//! `fixed_waypoint_term` ([`FixedWaypointTerm`]: U_SLP as the paper prints it), `friction_limits` (Eq. 10a).
//!
//! # The problem (Eq. 10, as read here)
//!
//! Over the speeds v = (v_1 … v_N):
//!
//! ```text
//!   minimise   J(v) = w1 Σ_i Δs_i / v_i                    travel time along the path
//!                   + w2 Σ_i ½ (v_i − V_target)²            deviation from the target speed
//!                   + w3 Σ_i φ_i(v)                         interaction with the others' SLPs
//!   subject to v_min ≤ v_i ≤ V_i^max = min(V_limit, √(μ g / |κ_i|))          (Eq. 10a)
//!              |v_{i+1} − v_i| ≤ a_max Δt,  |v_1 − v_0| ≤ a_max Δt            (optional)
//!              |v_{i+1} − 2 v_i + v_{i−1}| ≤ j_max Δt²                        (optional)
//!
//!   φ_i(v) = ln(U₀ + Σ_o U_OB^o(e_i(v); q_o(t_0 + iΔt))) − ln U₀
//!   e_i(v) = path(s_i),   s_i = Δt Σ_{j ≤ i} v_j
//! ```
//!
//! Δs_i is the length of the i-th segment of the fitted path; e_i is where the ego is after i
//! time steps of Δt = Δt_plan (the brief's s_i = Σ v_j Δt), q_o(t) the other vehicle's SLP
//! interpolated at the same absolute time (time-matched, so a stale or differently sampled
//! SLP pairs correctly); U_OB is Eq. 4 centred on q_o with its heading.
//!
//! Readings (also in `planner/README.md`): the paper's `ln U_SLP` of a single Gaussian is
//! ln A − q, a concave quadratic whose pull grows without bound with the separation, so far
//! vehicles would dominate the speed choice; we read U_SLP as the accumulated field
//! U₀ + Σ_o U_OB^o with a floor U₀ (`interaction_floor`): ln U ≈ ln A − q near a vehicle,
//! and the term fades (to 0 after subtracting the constant ln U₀) once the others' fields
//! fall below U₀. v_min > 0 keeps Δs/v finite (the paper writes 0 ≤ v_i).
//!
//! # Solution
//!
//! Each SCP iteration solves a convex subproblem, posed one of two ways
//! (`PlannerParams::speed_program`): [`SpeedProgram::Cone`] keeps the travel time exact: t_i ≥ Δs_i / v_i ⇔ t_i v_i ≥ Δs_i, t_i, v_i ≥ 0
//! ⇔ ‖(t_i − v_i, 2√Δs_i)‖ ≤ t_i + v_i, a second-order cone (`cone_program`);
//! [`SpeedProgram::NewtonQp`] replaces it by its second-order Taylor model at the iterate, a QP
//! (`newton_qp`), cheaper per solve (the default). What follows is written for the cone program; the QP
//! differs only where said. The interaction term is
//! linearised at the current iterate v̄ (φ ≈ φ(v̄) + ∇φ(v̄)ᵀ(v − v̄)), the resulting convex
//! cone program is solved inside the trust region |v_i − v̄_i| ≤ ρ, and the step d = v* − v̄
//! to its solution v* is shortened by a backtracking line search on the true J (t = 1, ½, ¼, …
//! until J(v̄ + t d) ≤ J(v̄) + ¼ t ∇J(v̄)ᵀd, see `ARMIJO_FRACTION`; ρ is halved when t < 1
//! or no t passes); iterations stop when J stops falling, when the subproblem's step d is
//! within `scp_step_tolerance_mps` of zero in every speed (converged: the warm start was
//! already optimal), when no t passes with ρ below `scp_stall_trust_region_mps` (stalled), or
//! after `max_scp_iterations` solves. The linearised
//! interaction has no curvature, so v* usually sits on the trust-region boundary; kept whole
//! (or rejected, the only alternative), the step could only move by ρ, ρ/2, …, and when the
//! minimum lies between v̄ and v̄ ± ρ/2 successive planning cycles (each one warm-started at
//! the last) jumped across it and back: a cycle-to-cycle sawtooth of ±ρ/4 in the planned
//! speed. d is a descent direction whenever the convex model falls (the model's convex
//! part is exact — for the QP, exact to second order at v̄ — and its linear part is the
//! gradient), so the search always finds a decrease
//! unless v̄ is stationary, and v̄ + t d stays feasible (convex feasible set). It costs
//! evaluations of J only, no extra solves. The start v̄⁰ is `initial_guess` (the previous plan
//! shifted in time: across planning cycles this continues the same SCP, as in real-time
//! iteration schemes) projected onto the box and acceleration chain, so every accepted
//! iterate is feasible and J never exceeds J(v̄⁰). With jerk rows the projection may be
//! infeasible and the first iteration runs without a trust region. With w3 = 0 (PF-SP-EQ10)
//! the problem is convex and one solve of the cone program is exact (the QP iterates). All
//! iterations, and consecutive planning cycles, reuse one Clarabel solver through `update_q` /
//! `update_b` (and, for the QP, `update_P` of its diagonal): A is fixed.
//!
//! The non-convex term is any `SpeedTerm`: w3·Σ φ_i of PF-ISO (either reading of U_SLP), or
//! w_R·Σ U_i of PF-SP's risk-aware speeds, with its own weight in `SpeedProblem`.

pub(crate) mod banded_ipm;
pub(crate) mod cone_program;
pub(crate) mod fixed_waypoint_term;
pub(crate) mod friction_limits;
pub(crate) mod interaction_term;
pub(crate) mod newton_qp;
pub(crate) mod scp;

pub use fixed_waypoint_term::FixedWaypointTerm;
pub(crate) use friction_limits::friction_speed_limits;
pub use interaction_term::{Aggregate, InteractionTerm};
pub(crate) use scp::SpeedOptimiser;

use serde::{Deserialize, Serialize};

use crate::clarabel_setup::ProgramSettings;

/// How each SCP iteration's convex subproblem is posed (`PlannerParams::speed_program`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpeedProgram {
    /// The travel time exactly, t_i v_i ≥ Δs_i as one second-order cone per segment
    /// (`cone_program`): a convex problem (no interaction term) is solved exactly in one
    /// solve.
    Cone,
    /// The travel time by its second-order Taylor model at the iterate: a QP with no cones and
    /// no t variables (`newton_qp`), a third of the cost per solve; the SCP then iterates on
    /// convex problems too. The default: iterated to convergence (the default
    /// `max_scp_iterations` and `scp_stall_trust_region_mps`) it reaches the cone program's
    /// optimum at 2–3× less cost per planning cycle (docs/parameters.md).
    #[default]
    NewtonQp,
    /// The same Newton QP solved without Clarabel, by a primal–dual interior-point method on
    /// its banded Newton system (`banded_ipm`): the same optimum to the solvers' tolerance
    /// (not to the bit), at a fraction of the cost per solve. Opt-in; the acceptance
    /// criterion and the measured agreement are in docs/parameters.md.
    NewtonQpBanded,
}

/// The weights of J's convex part (module doc), built once from `PlannerParams`
/// (`derived_params`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedObjectiveParams {
    /// w1, weight of the travel time Σ Δs_i / v_i (1/s; `travel_time_weight`).
    pub travel_time_weight: f64,
    /// w2, weight of the speed deviation Σ ½ (v_i − V_target)² (s²/m²;
    /// `speed_deviation_weight`).
    pub speed_deviation_weight: f64,
}

/// The constraints of Eq. 10 that do not come with the problem (module doc): the lower bound
/// v_min and the optional acceleration and jerk rows, with their right-hand sides computed
/// once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedBounds {
    /// v_min ≤ v_i (m/s; `min_speed_mps`).
    pub min_speed_mps: f64,
    /// Whether |v_{i+1} − v_i| ≤ a_max Δt (and |v_1 − v_0| ≤ a_max Δt) is on
    /// (`accel_bound_enabled`).
    pub accel_bound_enabled: bool,
    /// a_max Δt, the acceleration rows' bound (m/s; `max_accel_mps2` · `step_time_s`).
    pub accel_step_mps: f64,
    /// Whether |v_{i+1} − 2 v_i + v_{i−1}| ≤ j_max Δt² is on (`jerk_bound_enabled`).
    pub jerk_bound_enabled: bool,
    /// j_max Δt², the jerk rows' bound (m/s; `max_jerk_mps3` · `step_time_s`²).
    pub jerk_step_mps: f64,
}

/// The SCP loop's settings (module doc, "Solution").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScpSettings {
    /// ρ, the trust region's initial half-width on each speed (m/s; `trust_region_mps`).
    pub trust_region_mps: f64,
    /// Most convex solves (≥ 1; `max_scp_iterations`).
    pub max_iterations: usize,
    /// Stop when J falls by less than this fraction of |J| (`scp_relative_tolerance`).
    pub relative_tolerance: f64,
    /// Stop, stalled, when no descent step is found and ρ is below this (m/s;
    /// `scp_stall_trust_region_mps`).
    pub stall_trust_region_mps: f64,
    /// Stop, converged, when the subproblem's solution lies within this of the iterate in every
    /// speed (m/s; `scp_step_tolerance_mps`; 0: never).
    pub step_tolerance_mps: f64,
}

/// Everything `SpeedOptimiser::solve` reads besides the `SpeedProblem`, built once from
/// `PlannerParams` (`derived_params`; `SpeedOptimiserParams::from(&params)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedOptimiserParams {
    /// w1 and w2 of J.
    pub objective: SpeedObjectiveParams,
    /// v_min and the acceleration and jerk rows.
    pub bounds: SpeedBounds,
    /// The SCP loop.
    pub scp: ScpSettings,
    /// How each convex subproblem is posed (`speed_program`).
    pub program: SpeedProgram,
    /// Clarabel's settings of both programs: `solver_max_iterations`, `solver_tolerance`,
    /// without equilibration and iterative refinement
    /// (`ProgramSettings::scaling_and_refinement`).
    pub(crate) solver: ProgramSettings,
}

/// A smooth, possibly non-convex term Σ_i φ_i(v) of the speed objective, linearised by the SCP.
pub(crate) trait SpeedTerm: std::fmt::Debug {
    /// Number of time slots (one per speed).
    fn slots(&self) -> usize;

    /// Σ_i φ_i(v) and its gradient with respect to v.
    fn value_and_gradient(&self, speeds_mps: &[f64]) -> (f64, Vec<f64>);

    /// Σ_i φ_i(v).
    fn value(&self, speeds_mps: &[f64]) -> f64 {
        self.value_and_gradient(speeds_mps).0
    }
}

/// One speed problem (module doc).
#[derive(Clone, Copy, Debug)]
pub(crate) struct SpeedProblem<'a> {
    /// v_0, the current speed (m/s): anchors v_1 when the acceleration bound is on.
    pub current_speed_mps: f64,
    /// V_target (m/s).
    pub target_speed_mps: f64,
    /// Δs_i, i = 1..N (m).
    pub segment_lengths_m: &'a [f64],
    /// V_i^max (m/s), already min(V_limit, friction limit).
    pub max_speeds_mps: &'a [f64],
    /// Where iteration 0 linearises the non-convex term (default: V_target clipped).
    pub initial_guess_mps: Option<&'a [f64]>,
    /// The non-convex term (None: the convex Eq. 10 with w3 = 0).
    pub interaction: Option<&'a dyn SpeedTerm>,
    /// Its weight (w3 for U_SLP, w_R for PF-SP's risk); 0 drops it.
    pub interaction_weight: f64,
}

/// The optimiser's answer.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SpeedSolution {
    /// v_1..v_N (m/s).
    pub speeds_mps: Vec<f64>,
    /// J(v) (true objective, not the linearised one).
    pub objective: f64,
    /// Convex solves performed.
    pub solves: usize,
    /// Whether v_1 was anchored to the current speed.
    pub anchored: bool,
    /// Whether the SCP ran all `max_scp_iterations` iterations without meeting its relative
    /// tolerance (the answer may be short of the local optimum); false for the one exact solve
    /// of a convex problem.
    pub stopped_at_iteration_cap: bool,
}

/// J(v) of Eq. 10 (module doc), with the non-convex term if given.
pub(crate) fn objective(
    params: &SpeedObjectiveParams,
    problem: &SpeedProblem<'_>,
    speeds_mps: &[f64],
) -> f64 {
    let mut j = 0.0;
    for (v, ds) in speeds_mps.iter().zip(problem.segment_lengths_m) {
        let dv = v - problem.target_speed_mps;
        j += params.travel_time_weight * ds / v + 0.5 * params.speed_deviation_weight * dv * dv;
    }
    if let Some(term) = problem.interaction
        && problem.interaction_weight > 0.0
    {
        j += problem.interaction_weight * term.value(speeds_mps);
    }
    j
}

/// ∂/∂v_i of the convex part of J (travel time and target speed): −w1 Δs_i / v_i² + w2 (v_i − V).
fn smooth_gradient(
    params: &SpeedObjectiveParams,
    problem: &SpeedProblem<'_>,
    i: usize,
    v: f64,
) -> f64 {
    -params.travel_time_weight * problem.segment_lengths_m[i] / (v * v)
        + params.speed_deviation_weight * (v - problem.target_speed_mps)
}

/// Asserts that `term`'s gradient at `speeds_mps` matches central differences (relative 1e-6)
/// and returns it.
#[cfg(test)]
pub(crate) fn assert_gradient_matches_central_differences(
    term: &dyn SpeedTerm,
    speeds_mps: &[f64],
) -> Vec<f64> {
    let (_, g) = term.value_and_gradient(speeds_mps);
    let h = 1e-6;
    for j in 0..speeds_mps.len() {
        let mut up = speeds_mps.to_vec();
        up[j] += h;
        let mut down = speeds_mps.to_vec();
        down[j] -= h;
        let fd = (term.value(&up) - term.value(&down)) / (2.0 * h);
        assert!(
            (g[j] - fd).abs() < 1e-6 * (1.0 + fd.abs()),
            "j = {j}: {} vs {fd}",
            g[j]
        );
    }
    g
}
