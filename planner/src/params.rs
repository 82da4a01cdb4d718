//! Every tunable number of the planner, in one struct with `Default` and a serde form.
//!
//! Units: the potential U is dimensionless; gains carry the units that make it so
//! (λ in 1/m², ξ in m²). The attractive pull λ·look-ahead (1/m) is the unit force against
//! which all lateral forces compare: the heading of a path step is atan2(F_y, F_x), so only
//! the ratio of the forces matters, never their absolute size.

use serde::{Deserialize, Serialize};

use mergesim_types::bounds::{self, Bound};

use crate::error::PlannerError;
use crate::following::V2vLossFallback;
use crate::obstacle_field::{HeadingForm, LateralForm, MinDistanceLength, ObstacleFieldParams};
use crate::prediction::PredictionModel;
use crate::speed_optimisation::SpeedProgram;

/// Smallest number of waypoints: a cubic has four coefficients (paper, after Eq. 9).
pub const MIN_WAYPOINTS: usize = 4;

/// Largest number of waypoints accepted (keeps the speed problem small and bounded).
pub const MAX_WAYPOINTS: usize = 200;

/// Standard gravity g (m/s²) of the friction speed limit √(μ g / |κ|) (Eq. 10a).
pub const GRAVITY_MPS2: f64 = 9.806_65;

/// Where the interaction term of Eq. 10 evaluates U_SLP (see `PlannerParams::interaction_slp_reading`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SlpReading {
    /// At the ego's Eq. 7 waypoint i and the other's SLP at the same time: speed enters only
    /// through D_min(v_i) (the paper's text, and the `paper` set).
    FixedWaypoints,
    /// At the ego's position after i time slots at the planned speeds (the `mergesim` set).
    ArcLength,
}

/// Parameters of the potential-field planner (paper Eqs. 1–10).
///
/// Defaults are chosen for the paper's urgent merge (two 3.5 m lanes, ego at 20 m/s, obstacle
/// at 15 m/s): see the field docs and `planner/README.md` for the reasoning.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlannerParams {
    // ---------------------------------------------------------------- Eq. 1 (attractive)
    /// λ, slope scale of the attractive field U_AT = ½ λ (X − X_tar)² (1/m²).
    pub attractive_gain_per_m2: f64,
    /// Distance of the moving target X_tar ahead of the point being stepped (m). The pull is
    /// then the constant λ·look-ahead = the unit of force (default 0.05 · 20 = 1).
    pub target_lookahead_m: f64,

    // ---------------------------------------------------------------- Eq. 2 (lane divider)
    /// A_lane, height of the lane-divider ridge. With the edge gain below, the default puts the
    /// lateral equilibrium of each lane within a few centimetres of its centre.
    pub lane_amplitude: f64,
    /// σ of the lane-divider Gaussian (m).
    pub lane_sigma_m: f64,

    // ---------------------------------------------------------------- Eq. 3 (road edges)
    /// ξ, scale of the edge field ½ ξ / (d − l_w/2)² (m²).
    pub edge_gain_m2: f64,
    /// Clearance (d − l_w/2) below which the edge field continues linearly with the slope it has
    /// there, so it stays finite (and keeps pushing) on and beyond the edge (m).
    pub edge_clamp_distance_m: f64,

    // ---------------------------------------------------------------- Eq. 4 (obstacles)
    /// A_obs, peak of an obstacle's field.
    pub obstacle_amplitude: f64,
    /// ε, the field level (absolute) at the lateral safety distance. Must be below
    /// `obstacle_amplitude`.
    pub obstacle_epsilon: f64,
    /// Lateral safety distance at which an obstacle's field has fallen to ε (m): fixes σ_y.
    pub obstacle_lateral_safety_m: f64,
    /// Fraction of A_obs left at the longitudinal safety distance D_min: fixes σ_x.
    pub obstacle_fraction_at_min_distance: f64,
    /// Time gap added to D_min for the follower, v_f · τ (s); 0 gives the paper's D_min.
    pub obstacle_time_gap_s: f64,
    /// M of the planning vehicle in D_min, as a dimensionless factor.
    pub ego_mass_factor: f64,
    /// M_o of the other vehicle in D_min, as a dimensionless factor.
    pub other_mass_factor: f64,
    /// How Eq. 4 aligns an obstacle's ellipse with its heading: `paper-correlation` (the C1/C2
    /// terms as printed, a Gaussian with correlation ψ_o) or `rotation` (the Gaussian in the
    /// obstacle's frame). Shared by the path field and the interaction term.
    pub obstacle_heading_form: HeadingForm,
    /// The length term (l + l_o)/2 of D_min: `wheelbase` (as printed; the bodies overlap at
    /// D_min) or `body-length` (D_min is at least the contact distance). Shared.
    pub obstacle_min_distance_length: MinDistanceLength,
    /// D_min with roles by side (ahead of the obstacle it is the follower) instead of the
    /// planning vehicle always being the follower, as printed. Shared.
    pub obstacle_min_distance_by_side: bool,
    /// Eq. 4's lateral term: `fixed-distance` (σ_y = d_lat/√(−2 ln(ε/A)), a Gaussian that is ε
    /// at d_lat; both sets) or `printed-laplace` (σ_y as printed, |Y − Y_o|/√(−2 ln(ε/A)),
    /// unsquared: a Laplace profile). Shared by the path field and the interaction term.
    pub obstacle_lateral_form: LateralForm,

    // ---------------------------------------------------------------- Eq. 7 (waypoints)
    /// N, number of waypoints (≥ 4).
    pub waypoint_count: usize,
    /// Δt_plan, time per waypoint step: L_s = v·Δt_plan, and the time grid of the interaction
    /// term (s). N · Δt_plan is the horizon of the shared local path.
    pub step_time_s: f64,
    /// Smallest step L_s (m), used at low speed.
    pub min_step_m: f64,
    /// Evaluate each obstacle's field at its constant-velocity position at the time the ego
    /// reaches the waypoint being stepped (k·Δt_plan) instead of at its current position.
    /// The paper steps against the current positions (`false`). On by default: a path stepped
    /// against where the others are *now* meets a leader's field head-on ≈ 80 m ahead and
    /// passes it on one side or the other, flipping from cycle to cycle, which makes the
    /// follower's yaw rate spike; it also lets a faster ego plan into the gap a slower car
    /// occupies now but will have left when the ego arrives (docs/reproduction.md,
    /// "Calibration").
    pub predict_obstacles_in_path: bool,
    /// The lane-end rule's walls: a vehicle settled in a lane that goes on sees the divider
    /// towards a lane that ends ahead as an edge (Eq. 3's term, `LaneRoadGeometry::lane_end_walls`),
    /// so the field of a car beside it cannot push it into a lane that is about to close. The
    /// paper has no such rule (`false`: only Eq. 2's soft divider term). On by default.
    pub lane_end_walls: bool,
    /// Longest sub-step of the gradient integration inside one waypoint step (m). The paper's
    /// Eq. 7 is one sub-step per waypoint; shorter sub-steps follow the force's stream line
    /// instead of zig-zagging over the divider ridge when L_s is several metres.
    pub max_substep_m: f64,
    /// Largest turn of ψ_ref across one sub-step (rad): a longer sub-step is halved (down to
    /// 1/64 of the fixed one) so the integration follows the stream line where the field is
    /// stiff across the path (the road edge's wall) instead of bouncing off it, which made the
    /// far waypoints jump from plan to plan (`local_path` module doc). 0 keeps fixed sub-steps.
    pub substep_max_turn_rad: f64,

    // ---------------------------------------------------------------- Eqs. 8–9 (cubic fit)
    /// Weight of the vehicle's own position as a data point of the fit (waypoints weigh 1).
    pub cubic_origin_weight: f64,
    /// Bound on |a0|, the lateral offset of the path at the vehicle (m).
    pub cubic_max_offset_m: f64,
    /// Bound on the path heading at the vehicle, relative to the vehicle (rad): |a1| ≤ S·tan.
    pub cubic_max_heading_rad: f64,
    /// Bound on the curvature at the vehicle (1/m): |a2| ≤ S²·κ_max/2.
    pub cubic_max_curvature_per_m: f64,
    /// Bound on the curvature rate (1/m²): |a3| ≤ S³·κ'_max/6.
    pub cubic_max_curvature_rate_per_m2: f64,

    // ---------------------------------------------------------------- Eq. 10 (speeds)
    /// V_limit, the speed limit (m/s).
    pub speed_limit_mps: f64,
    /// v_min, lower bound of Eq. 10's decision variables (m/s, > 0): keeps the travel-time term
    /// Δs/v finite. The paper's bound 0 ≤ v_i is read as v_min ≤ v_i in moving traffic; a stop
    /// (speeds below v_min, down to 0) is the `stop_and_go` module's cap, with the travel time
    /// floored at v_min (`stop_and_go_speed_mps`).
    pub min_speed_mps: f64,
    /// w1, weight of the travel time Σ Δs_i / v_i (1/s).
    pub travel_time_weight: f64,
    /// w2, weight of the speed deviation Σ ½ (v_i − V_target)² (s²/m²).
    pub speed_deviation_weight: f64,
    /// w3, weight of the interaction term Σ ln U_SLP^i (0 turns PF-ISO into PF-SP-EQ10).
    pub interaction_weight: f64,
    /// Floor of the interaction term, ln(floor + Σ U_OB) (same unit as A_obs). The term acts
    /// where the others' fields exceed it and fades below: with the default (0.02, a fifth of
    /// the field's fraction 0.1 at D_min) a vehicle further than about 1.3 D_min ahead or
    /// behind, or a lane away, leaves the speeds alone. The paper's ε (far smaller) would make
    /// ln U pull hardest near the ε contour, i.e. at 3–4 σ_x, so vehicles at a safe following
    /// distance keep pushing each other's speeds away from their targets.
    pub interaction_floor: f64,
    /// Time gap τ_I of the follower's D_min in the interaction term (s); the path field's is
    /// `obstacle_time_gap_s`. Separate, so tuning the interaction never moves PF-CS or PF-SP.
    pub interaction_time_gap_s: f64,
    /// ε_I of the interaction term's σ_y: its field's level at `interaction_lateral_safety_m`
    /// (the path field's is `obstacle_epsilon`).
    pub interaction_epsilon: f64,
    /// Lateral safety distance of the interaction term's σ_y (m).
    pub interaction_lateral_safety_m: f64,
    /// Fraction of A_obs left at D_min in the interaction term (fixes its σ_x).
    pub interaction_fraction_at_min_distance: f64,
    /// Where U_SLP is evaluated: `fixed-waypoints` (the paper's reading: at the ego's Eq. 7
    /// waypoint i against the other's i-th shared waypoint, so speed enters only through
    /// D_min(v_i)) or `arc-length` (at the ego's position after i slots at the planned speeds,
    /// s_i = Δt Σ_{j ≤ i} v_j, against the other's SLP at the same time).
    pub interaction_slp_reading: SlpReading,
    /// Shared by every planner that predicts (not an interaction parameter). For a vehicle whose
    /// motion is *predicted* (no fresh shared path: PF-ISO-PRED, PF-SP,
    /// PF-ISO's fallback), fix the roles from the order now: a vehicle behind counts only at
    /// the contact distance, one ahead with its full D_min on both sides, whatever the
    /// prediction says about who will lead. A received shared path is the sender's declared
    /// intent and keeps the per-slot roles of `interaction_rear_only`.
    pub roles_from_order_now: bool,
    /// In the interaction term, a vehicle behind the planning vehicle counts only within the
    /// contact distance (l + l_o)/2 ahead of it, while a vehicle ahead keeps its full
    /// speed-dependent D_min behind it: the follower is responsible for the gap (as in RSS),
    /// so a merging vehicle makes the one it cuts in front of slow down, and a leader is not
    /// pushed above its target speed by a vehicle following it — as long as the follower is
    /// not predicted to draw level. Who is ahead is decided per time slot from the predicted
    /// positions, so being ahead is cheap for both: a vehicle predicted (at constant velocity)
    /// to overtake makes the leader speed up to stay ahead of it, the race of PF-ISO-PRED in
    /// docs/reproduction.md ("Where the two equilibria meet").
    pub interaction_rear_only: bool,
    /// In PF-ISO / PF-ISO-PRED, cap the speeds at max(V_target, v0 − a_max·t): the interaction
    /// term may slow a vehicle down ("slowing down in advance", as in the paper) but not push
    /// it above its target. Without the cap the non-convex term can also be lowered by
    /// accelerating past the other vehicle, a race that a receiver predicting at constant
    /// velocity (no V2V) may run into.
    pub interaction_slows_only: bool,
    /// Half-width of the SCP trust region on each speed after the first iteration (m/s).
    pub trust_region_mps: f64,
    /// Maximum number of SCP iterations (each one convex solve; ≥ 1).
    pub max_scp_iterations: usize,
    /// SCP stops when the objective falls by less than this fraction of its magnitude.
    pub scp_relative_tolerance: f64,
    /// SCP stops (stalled, not capped) when an iteration finds no descent step and the trust
    /// region has shrunk below this (m/s); 0: never, it runs to `max_scp_iterations`. With the
    /// defaults (20 iterations, 0.01 m/s) the cap binds in under 1 % of the planning cycles of
    /// every built-in scenario (docs/parameters.md).
    pub scp_stall_trust_region_mps: f64,
    /// SCP stops (converged) when the convex subproblem's step is this small: every speed of
    /// its solution within this of the iterate (m/s); 0: never. Its value equals
    /// `scp_stall_trust_region_mps`, the radius the SCP already treats as no further progress
    /// (criterion in docs/parameters.md).
    pub scp_step_tolerance_mps: f64,
    /// Bound consecutive speeds by |v_{i+1} − v_i| ≤ a_max · Δt_plan (and v_1 against the
    /// current speed when that is feasible).
    pub accel_bound_enabled: bool,
    /// a_max of the acceleration bound (m/s²).
    pub max_accel_mps2: f64,
    /// Bound |v_{i+1} − 2 v_i + v_{i−1}| ≤ j_max · Δt_plan².
    pub jerk_bound_enabled: bool,
    /// j_max of the jerk bound (m/s³).
    pub max_jerk_mps3: f64,
    /// Interior-point iteration limit of each convex solve (Clarabel `max_iter`); 0 makes every
    /// solve fail, which exercises the fallback.
    pub solver_max_iterations: u32,
    /// Clarabel's gap and feasibility tolerances.
    pub solver_tolerance: f64,
    /// How each SCP iteration's convex subproblem is posed: `cone` (the travel time exact, one
    /// second-order cone per segment), `newton-qp` (its second-order model: a QP, cheaper per
    /// solve; default) or `newton-qp-banded` (the same QP by a banded interior-point method
    /// instead of Clarabel; opt-in). See `speed_optimisation::SpeedProgram`.
    pub speed_program: SpeedProgram,
    /// A shared local path older than this is ignored in favour of a prediction (s).
    pub max_shared_path_age_s: f64,
    /// How a vehicle without a fresh shared path is predicted: `constant-velocity` (straight
    /// along its heading) or `lane-following` (along the road at its speed, keeping its lateral
    /// position, lifted by the tapering edge of the ending lane).
    pub prediction: PredictionModel,

    // ---------------------------------------------------------------- PF-SP (risk-aware speeds)
    /// w_R, weight of PF-SP's risk term Σ_i U(e_i(v)): the path field of the others (Eq. 4 with
    /// the path-field parameters), predicted without V2V, along the vehicle's own path.
    pub risk_weight: f64,

    // ---------------------------------------------------------------- V2V loss (PF-ISO)
    /// What PF-ISO does in a cycle without any fresh shared path from the vehicles around it
    /// (`following` module): `risk-aware-following` (PF-SP's speeds with Gipps' safe-following
    /// cap; ours) or `interact-with-predictions` (the interaction term on predictions).
    pub v2v_loss_fallback: V2vLossFallback,
    /// τ of the safe-following cap: reaction time before braking (s). One second: twice the
    /// planning loop's worst delay (a planning period of 0.1 s plus one slot of 0.4 s).
    pub following_reaction_s: f64,
    /// s₀ of the safe-following cap: bumper gap left when both have stopped (m); 2 m, the
    /// standstill gap of the Intelligent Driver Model's usual calibration.
    pub following_standstill_gap_m: f64,
    /// A vehicle ahead is in the planning vehicle's corridor when its lateral distance from the
    /// planned path is below the half-widths plus this margin (m); 0.5 m, the near-miss gap
    /// of the safety monitor.
    pub following_lateral_margin_m: f64,

    // ---------------------------------------------------------------- stop and go
    /// Speed below which stop and go is handled (m/s; `stop_and_go` module): in a cycle where
    /// the planning vehicle or a vehicle ahead in its corridor is slower than this, every
    /// planner caps its speeds at Gipps' safe-following speed behind the vehicles in its
    /// corridor (`following_reaction_s`, `following_standstill_gap_m`), and the speeds may go
    /// below `min_speed_mps` down to 0. 5 m/s: ten times `min_speed_mps` and half the slowest
    /// speed of the built-in scenarios (10 m/s), so moving traffic is planned as before, bit for
    /// bit (docs/parameters.md). 0 turns it off (the planners then creep at `min_speed_mps`).
    pub stop_and_go_speed_mps: f64,

    // ---------------------------------------------------------------- faults
    /// Comfortable deceleration of the fallback plan (m/s², positive).
    pub fallback_decel_mps2: f64,
}

impl Default for PlannerParams {
    fn default() -> Self {
        Self {
            attractive_gain_per_m2: 0.05,
            target_lookahead_m: 20.0,
            lane_amplitude: 0.03,
            lane_sigma_m: 1.0,
            edge_gain_m2: 0.01,
            edge_clamp_distance_m: 0.1,
            obstacle_amplitude: 1.0,
            // Criterion (docs/parameters.md): the largest value of the 1–2–5 series with which a
            // vehicle alongside, centred in the adjacent lane, moves a path's lateral
            // equilibrium by at most the 5 cm lane-centring tolerance (3.7 cm; 1e-3 gives 5.9).
            obstacle_epsilon: 5e-4,
            obstacle_lateral_safety_m: 3.5,
            obstacle_fraction_at_min_distance: 0.1,
            // The two-second rule (UK Highway Code, rule 126): the follower's D_min is
            // (l + l_o)/2 + 2 s · v_f (+ the braking term), 34.5 m at 15 m/s.
            obstacle_time_gap_s: 2.0,
            ego_mass_factor: 1.0,
            other_mass_factor: 1.0,
            obstacle_heading_form: HeadingForm::Rotation,
            obstacle_lateral_form: LateralForm::FixedDistance,
            obstacle_min_distance_length: MinDistanceLength::BodyLength,
            obstacle_min_distance_by_side: true,
            waypoint_count: 20,
            // N · Δt_plan = 8 s, the planning horizon of Baidu Apollo's EM planner (Fan et al.
            // 2018: "at least 8 s or 200 m"); with N = 20, waypoints every 8 m at 20 m/s, half the
            // tracker's look-ahead there.
            step_time_s: 0.4,
            min_step_m: 1.0,
            max_substep_m: 1.0,
            // A smooth stream line turns by κ·h ≤ 0.05 rad per 1 m sub-step at the cubic's
            // curvature bound, so only sub-steps turning twice that are refined.
            substep_max_turn_rad: 0.1,
            // Obstacles where they will be, not where they are (see the field doc).
            predict_obstacles_in_path: true,
            lane_end_walls: true,
            cubic_origin_weight: 10.0,
            cubic_max_offset_m: 0.5,
            cubic_max_heading_rad: 0.35,
            cubic_max_curvature_per_m: 0.05,
            cubic_max_curvature_rate_per_m2: 0.005,
            speed_limit_mps: 30.0,
            min_speed_mps: 0.5,
            travel_time_weight: 1.0,
            speed_deviation_weight: 1.0,
            // Twice the smallest weight with which the term alone keeps a follower behind a
            // slower leader on a single lane (6.0; a stability margin of 2, the same criterion
            // as `risk_weight`; docs/parameters.md, `planner/tests/calibration.rs`).
            interaction_weight: 12.0,
            // A fifth of the field's level at D_min (0.1): ln(U₀ + U) follows the paper's ln U
            // inside the safety ellipse and fades beyond ≈ 1.3 D_min (exp(−q) = 0.02 ⇔ q = 3.9
            // against q = 2.3 at D_min).
            interaction_floor: 0.02,
            // The two-second rule, as the path field's.
            interaction_time_gap_s: 2.0,
            // The largest value of the 1–2–5 series with which a vehicle in the adjacent lane,
            // 1–30 m ahead, changes a planned speed by at most 0.1 m/s (0.09; 1e-3 gives 0.17).
            interaction_epsilon: 5e-4,
            interaction_lateral_safety_m: 3.5,
            interaction_fraction_at_min_distance: 0.1,
            interaction_slp_reading: SlpReading::ArcLength,
            roles_from_order_now: true,
            interaction_rear_only: true,
            interaction_slows_only: false,
            trust_region_mps: 2.0,
            max_scp_iterations: 20,
            scp_relative_tolerance: 1e-4,
            scp_stall_trust_region_mps: 0.01,
            scp_step_tolerance_mps: 0.01,
            accel_bound_enabled: true,
            max_accel_mps2: 3.0,
            jerk_bound_enabled: false,
            max_jerk_mps3: 10.0,
            solver_max_iterations: 50,
            solver_tolerance: 1e-7,
            speed_program: SpeedProgram::NewtonQp,
            max_shared_path_age_s: 0.5,
            prediction: PredictionModel::LaneFollowing,
            // Twice the smallest weight with which the risk term keeps a PF-SP follower behind
            // a slower leader on a single lane (19.5; docs/parameters.md).
            risk_weight: 39.0,
            v2v_loss_fallback: V2vLossFallback::RiskAwareFollowing,
            following_reaction_s: 1.0,
            following_standstill_gap_m: 2.0,
            following_lateral_margin_m: 0.5,
            stop_and_go_speed_mps: 5.0,
            fallback_decel_mps2: 2.0,
        }
    }
}

fn invalid(name: &str, value: f64, reason: &str) -> PlannerError {
    PlannerError::invalid(format!("planner.{name}"), value, reason)
}

/// Allowed range of every numeric field (`PlannerParams::validate`, README "Limits"). They keep
/// each planning cycle's work bounded (at most 200 waypoints, 50 SCP solves of at most 1000
/// interior-point iterations, a horizon of at most 400 s) and the numbers physical.
pub const PLANNER_BOUNDS: &[Bound] = &[
    Bound::above("attractive_gain_per_m2", 0.0, 10.0, "1/m²"),
    Bound::closed("target_lookahead_m", 1.0, 200.0, "m"),
    Bound::closed("lane_amplitude", 0.0, 10.0, ""),
    Bound::closed("lane_sigma_m", 0.1, 5.0, "m"),
    Bound::closed("edge_gain_m2", 0.0, 10.0, "m²"),
    Bound::closed("edge_clamp_distance_m", 0.01, 2.0, "m"),
    Bound::above("obstacle_amplitude", 0.0, 100.0, ""),
    Bound::open("obstacle_epsilon", 0.0, 1.0, ""),
    Bound::closed("obstacle_lateral_safety_m", 0.5, 20.0, "m"),
    Bound::open("obstacle_fraction_at_min_distance", 0.0, 1.0, ""),
    Bound::closed("obstacle_time_gap_s", 0.0, 10.0, "s"),
    Bound::closed("ego_mass_factor", 0.1, 10.0, ""),
    Bound::closed("other_mass_factor", 0.1, 10.0, ""),
    Bound::closed(
        "waypoint_count",
        MIN_WAYPOINTS as f64,
        MAX_WAYPOINTS as f64,
        "",
    ),
    Bound::closed("step_time_s", 0.01, 2.0, "s"),
    Bound::closed("min_step_m", 0.01, 20.0, "m"),
    Bound::closed("max_substep_m", 0.01, 1000.0, "m"),
    Bound::closed("substep_max_turn_rad", 0.0, std::f64::consts::PI, "rad"),
    Bound::closed("cubic_origin_weight", 0.0, 1e6, ""),
    Bound::above("cubic_max_offset_m", 0.0, 10.0, "m"),
    Bound::open(
        "cubic_max_heading_rad",
        0.0,
        std::f64::consts::FRAC_PI_2,
        "rad",
    ),
    Bound::above("cubic_max_curvature_per_m", 0.0, 1.0, "1/m"),
    Bound::above("cubic_max_curvature_rate_per_m2", 0.0, 1.0, "1/m²"),
    Bound::above("speed_limit_mps", 0.0, 100.0, "m/s"),
    Bound::closed("min_speed_mps", 0.01, 10.0, "m/s"),
    Bound::closed("travel_time_weight", 0.0, 1e4, "1/s"),
    Bound::above("speed_deviation_weight", 0.0, 1e4, "s²/m²"),
    Bound::closed("interaction_weight", 0.0, 1e4, ""),
    Bound::above("interaction_floor", 0.0, 10.0, ""),
    Bound::closed("interaction_time_gap_s", 0.0, 10.0, "s"),
    Bound::open("interaction_epsilon", 0.0, 1.0, ""),
    Bound::closed("interaction_lateral_safety_m", 0.5, 20.0, "m"),
    Bound::open("interaction_fraction_at_min_distance", 0.0, 1.0, ""),
    Bound::above("trust_region_mps", 0.0, 50.0, "m/s"),
    Bound::closed("max_scp_iterations", 1.0, 50.0, ""),
    Bound::closed("scp_relative_tolerance", 0.0, 1.0, ""),
    Bound::closed("scp_stall_trust_region_mps", 0.0, 50.0, "m/s"),
    Bound::closed("scp_step_tolerance_mps", 0.0, 50.0, "m/s"),
    Bound::above("max_accel_mps2", 0.0, 20.0, "m/s²"),
    Bound::above("max_jerk_mps3", 0.0, 100.0, "m/s³"),
    Bound::closed("solver_max_iterations", 0.0, 1000.0, ""),
    Bound::closed("solver_tolerance", 1e-12, 1e-2, ""),
    Bound::closed("max_shared_path_age_s", 0.0, 60.0, "s"),
    Bound::closed("risk_weight", 0.0, 1e4, ""),
    Bound::closed("following_reaction_s", 0.0, 5.0, "s"),
    Bound::closed("following_standstill_gap_m", 0.0, 20.0, "m"),
    Bound::closed("following_lateral_margin_m", 0.0, 5.0, "m"),
    Bound::closed("stop_and_go_speed_mps", 0.0, 30.0, "m/s"),
    Bound::above("fallback_decel_mps2", 0.0, 20.0, "m/s²"),
];

impl PlannerParams {
    /// The numeric fields with their values, in declaration order (see [`PLANNER_BOUNDS`]).
    fn bounded_values(&self) -> Vec<(&'static str, f64)> {
        vec![
            ("attractive_gain_per_m2", self.attractive_gain_per_m2),
            ("target_lookahead_m", self.target_lookahead_m),
            ("lane_amplitude", self.lane_amplitude),
            ("lane_sigma_m", self.lane_sigma_m),
            ("edge_gain_m2", self.edge_gain_m2),
            ("edge_clamp_distance_m", self.edge_clamp_distance_m),
            ("obstacle_amplitude", self.obstacle_amplitude),
            ("obstacle_epsilon", self.obstacle_epsilon),
            ("obstacle_lateral_safety_m", self.obstacle_lateral_safety_m),
            (
                "obstacle_fraction_at_min_distance",
                self.obstacle_fraction_at_min_distance,
            ),
            ("obstacle_time_gap_s", self.obstacle_time_gap_s),
            ("ego_mass_factor", self.ego_mass_factor),
            ("other_mass_factor", self.other_mass_factor),
            ("waypoint_count", self.waypoint_count as f64),
            ("step_time_s", self.step_time_s),
            ("min_step_m", self.min_step_m),
            ("max_substep_m", self.max_substep_m),
            ("substep_max_turn_rad", self.substep_max_turn_rad),
            ("cubic_origin_weight", self.cubic_origin_weight),
            ("cubic_max_offset_m", self.cubic_max_offset_m),
            ("cubic_max_heading_rad", self.cubic_max_heading_rad),
            ("cubic_max_curvature_per_m", self.cubic_max_curvature_per_m),
            (
                "cubic_max_curvature_rate_per_m2",
                self.cubic_max_curvature_rate_per_m2,
            ),
            ("speed_limit_mps", self.speed_limit_mps),
            ("min_speed_mps", self.min_speed_mps),
            ("travel_time_weight", self.travel_time_weight),
            ("speed_deviation_weight", self.speed_deviation_weight),
            ("interaction_weight", self.interaction_weight),
            ("interaction_floor", self.interaction_floor),
            ("interaction_time_gap_s", self.interaction_time_gap_s),
            ("interaction_epsilon", self.interaction_epsilon),
            (
                "interaction_lateral_safety_m",
                self.interaction_lateral_safety_m,
            ),
            (
                "interaction_fraction_at_min_distance",
                self.interaction_fraction_at_min_distance,
            ),
            ("trust_region_mps", self.trust_region_mps),
            ("max_scp_iterations", self.max_scp_iterations as f64),
            ("scp_relative_tolerance", self.scp_relative_tolerance),
            (
                "scp_stall_trust_region_mps",
                self.scp_stall_trust_region_mps,
            ),
            ("scp_step_tolerance_mps", self.scp_step_tolerance_mps),
            ("max_accel_mps2", self.max_accel_mps2),
            ("max_jerk_mps3", self.max_jerk_mps3),
            (
                "solver_max_iterations",
                f64::from(self.solver_max_iterations),
            ),
            ("solver_tolerance", self.solver_tolerance),
            ("max_shared_path_age_s", self.max_shared_path_age_s),
            ("risk_weight", self.risk_weight),
            ("following_reaction_s", self.following_reaction_s),
            (
                "following_standstill_gap_m",
                self.following_standstill_gap_m,
            ),
            (
                "following_lateral_margin_m",
                self.following_lateral_margin_m,
            ),
            ("stop_and_go_speed_mps", self.stop_and_go_speed_mps),
            ("fallback_decel_mps2", self.fallback_decel_mps2),
        ]
    }

    /// Checks every field against [`PLANNER_BOUNDS`] and the fields against each other; the
    /// error names the first offending field and its value.
    pub fn validate(&self) -> Result<(), PlannerError> {
        bounds::check_all("planner", PLANNER_BOUNDS, &self.bounded_values())?;
        for (name, epsilon) in [
            ("obstacle_epsilon", self.obstacle_epsilon),
            ("interaction_epsilon", self.interaction_epsilon),
        ] {
            if epsilon >= self.obstacle_amplitude {
                return Err(invalid(
                    name,
                    epsilon,
                    "must be below planner.obstacle_amplitude (σ_y = d/√(−2 ln(ε/A)))",
                ));
            }
        }
        if self.min_speed_mps >= self.speed_limit_mps {
            return Err(invalid(
                "min_speed_mps",
                self.min_speed_mps,
                "must be below planner.speed_limit_mps",
            ));
        }
        Ok(())
    }

    /// The obstacle fields of the path (Eq. 7) and of PF-SP's risk term.
    pub(crate) fn path_field(&self) -> ObstacleFieldParams {
        ObstacleFieldParams {
            amplitude: self.obstacle_amplitude,
            epsilon: self.obstacle_epsilon,
            lateral_safety_m: self.obstacle_lateral_safety_m,
            fraction_at_min_distance: self.obstacle_fraction_at_min_distance,
            time_gap_s: self.obstacle_time_gap_s,
            ..self.shared_field_readings()
        }
    }

    /// The obstacle fields of the interaction term U_SLP (Eq. 10).
    pub(crate) fn interaction_field(&self) -> ObstacleFieldParams {
        ObstacleFieldParams {
            amplitude: self.obstacle_amplitude,
            epsilon: self.interaction_epsilon,
            lateral_safety_m: self.interaction_lateral_safety_m,
            fraction_at_min_distance: self.interaction_fraction_at_min_distance,
            time_gap_s: self.interaction_time_gap_s,
            ..self.shared_field_readings()
        }
    }

    fn shared_field_readings(&self) -> ObstacleFieldParams {
        ObstacleFieldParams {
            amplitude: self.obstacle_amplitude,
            epsilon: self.obstacle_epsilon,
            lateral_safety_m: self.obstacle_lateral_safety_m,
            fraction_at_min_distance: self.obstacle_fraction_at_min_distance,
            time_gap_s: self.obstacle_time_gap_s,
            ego_mass_factor: self.ego_mass_factor,
            other_mass_factor: self.other_mass_factor,
            heading_form: self.obstacle_heading_form,
            min_distance_length: self.obstacle_min_distance_length,
            min_distance_by_side: self.obstacle_min_distance_by_side,
            lateral_form: self.obstacle_lateral_form,
        }
    }

    /// The attractive pull λ·look-ahead of the moving target (1/m), the unit of force.
    pub fn attractive_pull_per_m(&self) -> f64 {
        self.attractive_gain_per_m2 * self.target_lookahead_m
    }

    /// Waypoint step L_s = max(v·Δt_plan, L_min) for a speed (m).
    pub(crate) fn step_length_m(&self, speed_mps: f64) -> f64 {
        (speed_mps.max(0.0) * self.step_time_s).max(self.min_step_m)
    }
}

#[cfg(test)]
mod tests;
