//! Interactive speed optimisation, paper Eq. 10, solved by sequential convex programming
//! (SCP) with Clarabel.
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
//!   φ_i(v) = ln(ε_I + Σ_o U_OB^o(e_i(v); q_o(t_0 + iΔt))) − ln ε_I
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
//! ε_I + Σ_o U_OB^o with a floor ε_I (`interaction_floor`): ln U ≈ ln A − q near a vehicle,
//! and the term fades (to 0 after subtracting the constant ln ε_I) once the others' fields
//! fall below ε_I. v_min > 0 keeps Δs/v finite (the paper writes 0 ≤ v_i).
//!
//! # Solution
//!
//! The travel time is convex: t_i ≥ Δs_i / v_i ⇔ t_i v_i ≥ Δs_i, t_i, v_i ≥ 0
//! ⇔ ‖(t_i − v_i, 2√Δs_i)‖ ≤ t_i + v_i, a second-order cone. The interaction term is
//! linearised at the current iterate v̄ (φ ≈ φ(v̄) + ∇φ(v̄)ᵀ(v − v̄)), the resulting convex
//! cone program is solved inside the trust region |v_i − v̄_i| ≤ ρ, and the step d = v* − v̄
//! to its solution v* is shortened by a backtracking line search on the true J (t = 1, ½, ¼, …
//! until J(v̄ + t d) ≤ J(v̄) + ¼ t ∇J(v̄)ᵀd, see `ARMIJO_FRACTION`; ρ is halved when t < 1
//! or no t passes); iterations stop when J stops falling or after `max_scp_iterations` solves. The linearised
//! interaction has no curvature, so v* usually sits on the trust-region boundary; kept whole
//! (or rejected, the only alternative), the step could only move by ρ, ρ/2, …, and when the
//! minimum lies between v̄ and v̄ ± ρ/2 successive planning cycles (each one warm-started at
//! the last) jumped across it and back: a cycle-to-cycle sawtooth of ±ρ/4 in the planned
//! speed. d is a descent direction whenever the convex model falls (the model's convex
//! part is exact and its linear part is the gradient), so the search always finds a decrease
//! unless v̄ is stationary, and v̄ + t d stays feasible (convex feasible set). It costs
//! evaluations of J only, no extra solves. The start v̄⁰ is `initial_guess` (the previous plan
//! shifted in time: across planning cycles this continues the same SCP, as in real-time
//! iteration schemes) projected onto the box and acceleration chain, so every accepted
//! iterate is feasible and J never exceeds J(v̄⁰). With jerk rows the projection may be
//! infeasible and the first iteration runs without a trust region. With w3 = 0 (PF-SP) the
//! problem is convex and one solve is exact. All iterations, and consecutive planning
//! cycles, reuse one Clarabel solver through `update_q` / `update_b` (P and A are fixed).
//!
//! Decision vector of the cone program (n = 2N): x = [v_1 … v_N, t_1 … t_N].
//!
//! ```text
//!   ½ xᵀPx + qᵀx:   P = diag(w2 … w2, 0 … 0),   q = [w3 ∇φ(v̄) − w2 V_target ; w1 … w1]
//!   rows of s = b − A x:
//!     [0, N)            v_i ≤ hi_i                       A = +e_vi             b = hi_i
//!     [N, 2N)           −v_i ≤ −lo_i                     A = −e_vi             b = −lo_i
//!     accel (2(N−1))    ±(v_{i+1} − v_i) ≤ a_max Δt      A = ±(e_v(i+1) − e_vi) b = a_max Δt
//!     jerk  (2(N−2))    ±(v_{i+1} − 2v_i + v_{i−1}) ≤ j_max Δt²
//!     ── all of the above in one nonnegative cone ──
//!     SOC_i (3 rows)    (t_i + v_i, t_i − v_i, 2√Δs_i) ∈ SOC(3)
//!                       A = (−e_ti − e_vi, −e_ti + e_vi, 0)   b = (0, 0, 2√Δs_i)
//! ```
//!
//! hi_i / lo_i hold V_i^max / v_min, the anchor to the current speed on v_1 (dropped when it
//! cannot be met together with the other bounds, e.g. in a sharp bend at high speed: the
//! friction limit wins over comfort) and the trust region.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSolver, IPSolver, NonnegativeConeT, SecondOrderConeT, SolverStatus,
    SupportedConeT,
};

use crate::error::PlannerError;
use crate::obstacle_field::ObstacleField;
use crate::params::PlannerParams;
use crate::polyline::Polyline;

/// The interaction term Σ_i φ_i(v) of Eq. 10 (module doc).
#[derive(Clone, Debug)]
pub struct InteractionTerm {
    path: Polyline,
    fallback_tangent: [f64; 2],
    step_time_s: f64,
    floor: f64,
    /// `fields[i]`: the other vehicles' fields at time slot i + 1, centred at their predicted
    /// poses.
    fields: Vec<Vec<ObstacleField>>,
}

impl InteractionTerm {
    /// The ego moves along `path` (starting at its current position, tangent
    /// `fallback_tangent` if the path is degenerate); `fields[i]` are the others' fields at
    /// t_0 + (i + 1)·Δt; `floor` is ε_I (> 0).
    pub fn new(
        path: Polyline,
        fallback_tangent: [f64; 2],
        step_time_s: f64,
        floor: f64,
        fields: Vec<Vec<ObstacleField>>,
    ) -> Self {
        Self {
            path,
            fallback_tangent,
            step_time_s,
            floor,
            fields,
        }
    }

    /// Number of time slots.
    pub fn slots(&self) -> usize {
        self.fields.len()
    }

    /// The ego's position e_i(v) after each time slot.
    pub fn ego_positions(&self, speeds_mps: &[f64]) -> Vec<[f64; 2]> {
        let mut s = 0.0;
        speeds_mps
            .iter()
            .map(|v| {
                s += v * self.step_time_s;
                self.path.point_and_tangent(s, self.fallback_tangent).0
            })
            .collect()
    }

    /// Σ_i φ_i(v) and its gradient with respect to v.
    pub fn value_and_gradient(&self, speeds_mps: &[f64]) -> (f64, Vec<f64>) {
        let n = speeds_mps.len().min(self.fields.len());
        let mut value = 0.0;
        // dφ_i/ds_i for each slot, then a suffix sum gives ∂/∂v_j = Δt Σ_{i ≥ j} dφ_i/ds_i.
        let mut d_ds = vec![0.0; n];
        let mut s = 0.0;
        for i in 0..n {
            s += speeds_mps[i] * self.step_time_s;
            let (p, tangent) = self.path.point_and_tangent(s, self.fallback_tangent);
            let mut sum_u = 0.0;
            let mut grad = [0.0, 0.0];
            for field in &self.fields[i] {
                let (u, g) = field.value_and_gradient(p[0], p[1]);
                sum_u += u;
                grad[0] += g[0];
                grad[1] += g[1];
            }
            let total = self.floor + sum_u;
            value += (total / self.floor).ln();
            d_ds[i] = (grad[0] * tangent[0] + grad[1] * tangent[1]) / total;
        }
        let mut gradient = vec![0.0; speeds_mps.len()];
        let mut suffix = 0.0;
        for i in (0..n).rev() {
            suffix += d_ds[i];
            gradient[i] = self.step_time_s * suffix;
        }
        (value, gradient)
    }

    /// Σ_i φ_i(v).
    pub fn value(&self, speeds_mps: &[f64]) -> f64 {
        self.value_and_gradient(speeds_mps).0
    }
}

/// One speed problem (module doc).
#[derive(Clone, Copy, Debug)]
pub struct SpeedProblem<'a> {
    /// v_0, the current speed (m/s): anchors v_1 when the acceleration bound is on.
    pub current_speed_mps: f64,
    /// V_target (m/s).
    pub target_speed_mps: f64,
    /// Δs_i, i = 1..N (m).
    pub segment_lengths_m: &'a [f64],
    /// V_i^max (m/s), already min(V_limit, friction limit).
    pub max_speeds_mps: &'a [f64],
    /// Where iteration 0 linearises the interaction term (default: V_target clipped).
    pub initial_guess_mps: Option<&'a [f64]>,
    /// The interaction term (None, or w3 = 0: PF-SP).
    pub interaction: Option<&'a InteractionTerm>,
}

/// The optimiser's answer.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeedSolution {
    /// v_1..v_N (m/s).
    pub speeds_mps: Vec<f64>,
    /// J(v) (true objective, not the linearised one).
    pub objective: f64,
    /// Convex solves performed.
    pub solves: usize,
    /// Whether v_1 was anchored to the current speed.
    pub anchored: bool,
}

/// Solver structure: what fixes P and A.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Layout {
    n: usize,
    accel: bool,
    jerk: bool,
}

impl Layout {
    fn new(params: &PlannerParams, n: usize) -> Self {
        Self {
            n,
            accel: params.accel_bound_enabled && n >= 2,
            jerk: params.jerk_bound_enabled && n >= 3,
        }
    }

    fn accel_rows(&self) -> usize {
        if self.accel { 2 * (self.n - 1) } else { 0 }
    }

    fn jerk_rows(&self) -> usize {
        if self.jerk { 2 * (self.n - 2) } else { 0 }
    }

    fn linear_rows(&self) -> usize {
        2 * self.n + self.accel_rows() + self.jerk_rows()
    }

    fn rows(&self) -> usize {
        self.linear_rows() + 3 * self.n
    }

    fn cones(&self) -> Vec<SupportedConeT<f64>> {
        let mut cones = vec![NonnegativeConeT(self.linear_rows())];
        cones.extend((0..self.n).map(|_| SecondOrderConeT(3)));
        cones
    }

    /// P = diag(w2 on v, 0 on t), upper triangle.
    fn p_matrix(&self, w2: f64) -> CscMatrix<f64> {
        let n = self.n;
        let mut colptr: Vec<usize> = (0..=n).collect();
        colptr.extend(std::iter::repeat_n(n, n));
        CscMatrix::new(2 * n, 2 * n, colptr, (0..n).collect(), vec![w2; n])
    }

    /// A, row blocks as in the module doc.
    fn a_matrix(&self) -> CscMatrix<f64> {
        let n = self.n;
        let (mut rows, mut cols, mut vals) = (Vec::new(), Vec::new(), Vec::new());
        let mut push = |r: usize, c: usize, v: f64| {
            rows.push(r);
            cols.push(c);
            vals.push(v);
        };
        // Box rows.
        for i in 0..n {
            push(i, i, 1.0);
            push(n + i, i, -1.0);
        }
        let mut r = 2 * n;
        if self.accel {
            for i in 0..n - 1 {
                push(r, i + 1, 1.0);
                push(r, i, -1.0);
                push(r + 1, i + 1, -1.0);
                push(r + 1, i, 1.0);
                r += 2;
            }
        }
        if self.jerk {
            for i in 1..n - 1 {
                push(r, i + 1, 1.0);
                push(r, i, -2.0);
                push(r, i - 1, 1.0);
                push(r + 1, i + 1, -1.0);
                push(r + 1, i, 2.0);
                push(r + 1, i - 1, -1.0);
                r += 2;
            }
        }
        // Second-order cones: (t_i + v_i, t_i − v_i, 2√Δs_i).
        for i in 0..n {
            let base = r + 3 * i;
            push(base, n + i, -1.0);
            push(base, i, -1.0);
            push(base + 1, n + i, -1.0);
            push(base + 1, i, 1.0);
        }
        CscMatrix::new_from_triplets(self.rows(), 2 * n, rows, cols, vals)
    }
}

struct CachedSolver {
    layout: Layout,
    w2_bits: u64,
    max_iterations: u32,
    tolerance_bits: u64,
    solver: DefaultSolver<f64>,
}

/// The speed optimiser. Holds a Clarabel solver between solves (and planning cycles) so only
/// q and b are rewritten; it is rebuilt when the problem's structure changes.
#[derive(Default)]
pub struct SpeedOptimiser {
    cached: Option<CachedSolver>,
}

impl std::fmt::Debug for SpeedOptimiser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpeedOptimiser")
            .field("cached", &self.cached.as_ref().map(|c| c.layout))
            .finish()
    }
}

impl Clone for SpeedOptimiser {
    /// A clone starts without a cached solver (Clarabel's solver is not `Clone`).
    fn clone(&self) -> Self {
        Self::default()
    }
}

fn solver_failed(status: impl Into<String>) -> PlannerError {
    PlannerError::SolverFailed {
        problem: "speed_optimisation".into(),
        status: status.into(),
    }
}

/// J(v) of Eq. 10 (module doc), with the interaction term if given.
pub fn objective(params: &PlannerParams, problem: &SpeedProblem<'_>, speeds_mps: &[f64]) -> f64 {
    let mut j = 0.0;
    for (v, ds) in speeds_mps.iter().zip(problem.segment_lengths_m) {
        let dv = v - problem.target_speed_mps;
        j += params.travel_time_weight * ds / v + 0.5 * params.speed_deviation_weight * dv * dv;
    }
    if let Some(term) = problem.interaction {
        j += params.interaction_weight * term.value(speeds_mps);
    }
    j
}

/// ∂/∂v_i of the convex part of J (travel time and target speed): −w1 Δs_i / v_i² + w2 (v_i − V).
fn smooth_gradient(params: &PlannerParams, problem: &SpeedProblem<'_>, i: usize, v: f64) -> f64 {
    -params.travel_time_weight * problem.segment_lengths_m[i] / (v * v)
        + params.speed_deviation_weight * (v - problem.target_speed_mps)
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
    pub fn solve(
        &mut self,
        params: &PlannerParams,
        problem: &SpeedProblem<'_>,
    ) -> Result<SpeedSolution, PlannerError> {
        let n = problem.segment_lengths_m.len();
        if n == 0 || problem.max_speeds_mps.len() != n {
            return Err(PlannerError::InvalidParameter {
                name: "speed_optimisation.max_speeds_mps".into(),
                value: problem.max_speeds_mps.len() as f64,
                reason: format!("need one bound per segment ({n} segments, at least one)"),
            });
        }
        if let Some(term) = problem.interaction
            && term.slots() != n
        {
            return Err(PlannerError::InvalidParameter {
                name: "speed_optimisation.interaction".into(),
                value: term.slots() as f64,
                reason: format!("need one time slot per segment ({n})"),
            });
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
        let layout = Layout::new(params, n);
        let accel_step = params.max_accel_mps2 * params.step_time_s;
        let jerk_step = params.max_jerk_mps3 * params.step_time_s * params.step_time_s;

        // Box bounds: v_min ≤ v_i ≤ max(V_i^max, v_min).
        let lo = vec![params.min_speed_mps; n];
        let hi: Vec<f64> = problem
            .max_speeds_mps
            .iter()
            .map(|v| v.max(params.min_speed_mps))
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
            .filter(|_| params.interaction_weight > 0.0);
        let gradient_at = |v: &[f64]| -> Vec<f64> {
            match interaction {
                Some(term) => {
                    let (_, g) = term.value_and_gradient(v);
                    g.iter().map(|gi| params.interaction_weight * gi).collect()
                }
                None => vec![0.0; n],
            }
        };

        // Without interaction the problem is convex: one exact solve.
        if interaction.is_none() {
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
            let j = objective(params, problem, &v);
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
        let mut j = objective(params, problem, &v);
        let mut trust_first = !layout.jerk && j.is_finite();
        let mut rho = params.trust_region_mps;
        let mut solves = 0;
        let mut solved_once = false;
        for iteration in 0..params.max_scp_iterations {
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
            let candidate = match self.solve_convex(
                params, layout, problem, &g, &lo_k, &hi_k, accel_step, jerk_step,
            ) {
                Ok(candidate) => candidate,
                Err(e) if !solved_once => return Err(e),
                Err(_) => break,
            };
            solved_once = true;
            let jc = objective(params, problem, &candidate);
            if !trust_first && iteration == 0 {
                // No feasible start to compare with: take the first solution as it is.
                v = candidate;
                j = jc;
                trust_first = true;
                continue;
            }
            // Backtracking (Armijo) line search along d = candidate − v̄ on the true J.
            let d: Vec<f64> = candidate.iter().zip(&v).map(|(c, vi)| c - vi).collect();
            let slope: f64 = (0..n)
                .map(|i| (smooth_gradient(params, problem, i, v[i]) + g[i]) * d[i])
                .sum();
            let mut step = 1.0;
            let mut accepted = None;
            if slope.is_finite() && slope < 0.0 {
                for _ in 0..=LINE_SEARCH_HALVINGS {
                    let trial: Vec<f64> = v.iter().zip(&d).map(|(vi, di)| vi + step * di).collect();
                    let jt = objective(params, problem, &trial);
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
            if let Some((trial, jt)) = accepted {
                let decrease = j - jt;
                v = trial;
                j = jt;
                if decrease <= params.scp_relative_tolerance * j.abs().max(1.0) {
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
        })
    }

    /// One convex solve with the interaction linearised to `gradient` (already × w3) and the
    /// box [lo, hi]. Returns v_1..v_N.
    #[allow(clippy::too_many_arguments)]
    fn solve_convex(
        &mut self,
        params: &PlannerParams,
        layout: Layout,
        problem: &SpeedProblem<'_>,
        gradient: &[f64],
        lo: &[f64],
        hi: &[f64],
        accel_step: f64,
        jerk_step: f64,
    ) -> Result<Vec<f64>, PlannerError> {
        let n = layout.n;
        // q = [w3 ∇φ − w2 V_target ; w1].
        let mut q = Vec::with_capacity(2 * n);
        q.extend(
            gradient
                .iter()
                .map(|g| g - params.speed_deviation_weight * problem.target_speed_mps),
        );
        q.extend(std::iter::repeat_n(params.travel_time_weight, n));
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

        let w2_bits = params.speed_deviation_weight.to_bits();
        let tolerance_bits = params.solver_tolerance.to_bits();
        let reusable = self.cached.as_ref().is_some_and(|c| {
            c.layout == layout
                && c.w2_bits == w2_bits
                && c.max_iterations == params.solver_max_iterations
                && c.tolerance_bits == tolerance_bits
        });
        let updated = reusable
            && self
                .cached
                .as_mut()
                .is_some_and(|c| c.solver.update_q(&q).is_ok() && c.solver.update_b(&b).is_ok());
        if !updated {
            let settings = DefaultSettings {
                verbose: false,
                max_iter: params.solver_max_iterations,
                tol_gap_abs: params.solver_tolerance,
                tol_gap_rel: params.solver_tolerance,
                tol_feas: params.solver_tolerance,
                presolve_enable: false,
                // The problem is small and well scaled (A entries ±1, ±2; P = w2 I; speeds of
                // order 10): equilibration and iterative refinement cost about half the solve
                // time here without changing the answer (closed-form test at 1e-5).
                equilibrate_enable: false,
                iterative_refinement_enable: false,
                ..DefaultSettings::default()
            };
            let solver = DefaultSolver::new(
                &layout.p_matrix(params.speed_deviation_weight),
                &q,
                &layout.a_matrix(),
                &b,
                &layout.cones(),
                settings,
            )
            .map_err(|e| solver_failed(e.to_string()))?;
            self.cached = Some(CachedSolver {
                layout,
                w2_bits,
                max_iterations: params.solver_max_iterations,
                tolerance_bits,
                solver,
            });
        }
        let Some(cached) = self.cached.as_mut() else {
            return Err(solver_failed("no solver"));
        };
        cached.solver.solve();
        let status = cached.solver.solution.status;
        if !matches!(status, SolverStatus::Solved | SolverStatus::AlmostSolved) {
            return Err(solver_failed(format!("{status:?}")));
        }
        let x = &cached.solver.solution.x;
        if x.len() != 2 * n || x.iter().any(|v| !v.is_finite()) {
            return Err(PlannerError::NonFinite {
                what: "speed_optimisation solution".into(),
            });
        }
        // Snap interior-point round-off onto the box.
        Ok((0..n)
            .map(|i| x[i].clamp(lo[i], hi[i].max(lo[i])))
            .collect())
    }
}

/// V_i^max = min(V_limit, √(μ g / |κ_i|)) for each segment (Eq. 10a), κ_i the largest |κ| at
/// the segment's ends and middle. κ → 0 is guarded: below μ g / V_limit² the limit is V_limit.
pub fn friction_speed_limits(
    curvature_per_m: impl Fn(f64) -> f64,
    waypoint_xi_m: &[f64],
    mu: f64,
    speed_limit_mps: f64,
) -> Vec<f64> {
    let mu_g = mu.max(0.0) * crate::params::GRAVITY_MPS2;
    let mut previous = 0.0;
    waypoint_xi_m
        .iter()
        .map(|&xi| {
            let kappa = [previous, 0.5 * (previous + xi), xi]
                .iter()
                .map(|&x| curvature_per_m(x).abs())
                .fold(0.0, f64::max);
            previous = xi;
            if kappa * speed_limit_mps * speed_limit_mps <= mu_g {
                speed_limit_mps
            } else {
                (mu_g / kappa).sqrt()
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::obstacle_field::SelfView;
    use crate::types::VehicleShape;

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
        let params = PlannerParams {
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
        };
        let mut optimiser = SpeedOptimiser::new();
        let solution = optimiser.solve(&params, &problem).unwrap();
        assert_eq!(solution.solves, 1);
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
                "i = {i}: {} vs {expected} (owed {owed})",
                solution.speeds_mps[i]
            );
        }
        assert!(
            solution.speeds_mps[0] > 15.3,
            "travel time pushes above V_target"
        );
        // The cached solver gives the same answer on a re-solve.
        let again = optimiser.solve(&params, &problem).unwrap();
        for (a, b) in again.speeds_mps.iter().zip(&solution.speeds_mps) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
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
        };
        let solution = SpeedOptimiser::new().solve(&params, &problem).unwrap();
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
        };
        let solution = SpeedOptimiser::new().solve(&params, &problem).unwrap();
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
            .solve(&PlannerParams::default(), &problem)
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
        };
        let solution = SpeedOptimiser::new().solve(&params, &problem).unwrap();
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
        };
        let err = SpeedOptimiser::new().solve(&params, &problem).unwrap_err();
        assert!(matches!(err, PlannerError::SolverFailed { .. }), "{err}");
    }

    #[test]
    fn interaction_gradient_matches_central_differences() {
        let params = PlannerParams::default();
        let me = SelfView {
            speed_mps: 15.0,
            shape: VehicleShape::default(),
        };
        let base = ObstacleField::new(&params, me, 0.0, 0.0, 0.0, 20.0, &VehicleShape::default());
        let n = 10;
        let dt = params.step_time_s;
        // The other vehicle passes at 20 m/s while moving from the lower to the upper lane.
        let fields: Vec<Vec<ObstacleField>> = (1..=n)
            .map(|i| {
                let t = i as f64 * dt;
                let heading: f64 = 0.05;
                vec![base.moved_to(-4.0 + 20.0 * t, 2.5 + 0.8 * t, heading.cos(), heading.sin())]
            })
            .collect();
        let path = Polyline::new(
            (0..=n)
                .map(|k| [k as f64 * 3.75, 5.25 + 0.01 * k as f64])
                .collect(),
        )
        .unwrap();
        let term = InteractionTerm::new(path, [1.0, 0.0], dt, params.interaction_floor, fields);
        let v: Vec<f64> = (0..n).map(|i| 14.0 + 0.1 * i as f64).collect();
        let (_, g) = term.value_and_gradient(&v);
        let h = 1e-6;
        for j in 0..n {
            let mut up = v.clone();
            up[j] += h;
            let mut down = v.clone();
            down[j] -= h;
            let fd = (term.value(&up) - term.value(&down)) / (2.0 * h);
            assert!(
                (g[j] - fd).abs() < 1e-6 * (1.0 + fd.abs()),
                "j = {j}: {} vs {fd}",
                g[j]
            );
        }
        assert!(
            g.iter().any(|gi| gi.abs() > 1e-3),
            "the term must act: {g:?}"
        );
    }

    #[test]
    fn friction_limit_is_sqrt_mu_g_over_kappa() {
        let kappa = 0.02;
        let limits = friction_speed_limits(|_| kappa, &[5.0, 10.0], 0.8, 30.0);
        let expected = (0.8 * crate::params::GRAVITY_MPS2 / kappa).sqrt();
        assert!((limits[0] - expected).abs() < 1e-12);
        let straight = friction_speed_limits(|_| 0.0, &[5.0], 0.8, 30.0);
        assert_eq!(straight, vec![30.0]);
    }
}
