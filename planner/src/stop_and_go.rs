//! Stop and go: how every planner comes to a stop behind a stopped vehicle and starts again.
//!
//! The planning cycle assumes motion in three places: the waypoint step L_s = v·Δt_plan
//! (Eq. 7), the travel time Δs_i / v_i of Eq. 10, and the times t_i = t_{i−1} + Δs_i / v_i of
//! the path and its broadcast. Each is made well-posed at v → 0:
//!
//! 1. **Path geometry** (Eq. 7). L_s = max(v·Δt_plan, `min_step_m`): at standstill the path
//!    still reaches N·`min_step_m` ahead (20 m with the defaults), so the tracker has a
//!    direction to steer and to start along. Only the speeds on it go to 0.
//! 2. **A stop as a hard cap** ([`stop_and_go_caps_mps`]). In a cycle where the planning
//!    vehicle, or a vehicle ahead of it in its corridor (`following::corridor_leaders`, measured
//!    in its lane's frame), is slower than `stop_and_go_speed_mps`, every speed v_i is capped at
//!    Gipps' safe-following speed behind the vehicles in the corridor,
//!    v_safe = −bτ + √(b²τ² + v_l² + 2b(g − s₀)) (`following` module; b = `max_accel_mps2`,
//!    τ = `following_reaction_s`, s₀ = `following_standstill_gap_m`, the stop point's distance
//!    behind the leader's rear), reached no faster than at b from the current speed,
//!    cap_i = max(v_safe, v_0 − b·(i + 1)Δt_plan, 0), v_safe from the gap now: a receding
//!    cap, renewed every cycle (the slot-by-slot cap v_safe(g_i) at the gap g_i left after
//!    driving the caps so far, which would keep the whole planned path behind the stop point,
//!    was tried: through their warm-started SCP it slowed PF-SP's and PF-ISO's approach so much
//!    that they had not stopped 20 s after starting 60 m behind; not adopted). Behind a standing
//!    leader v_safe falls to 0 as the bumper gap g falls to s₀: near it, v_safe ≈ (g − s₀)/τ, so the gap closes on s₀
//!    exponentially with time constant τ and never below it. When the leader drives off, g and
//!    v_l grow and so does the cap: the vehicle starts again, never faster than Gipps allows.
//!    Once on, the cap stays on while Gipps' speed is below V_target (the vehicle ahead still
//!    holds it back), even after everybody is faster than `stop_and_go_speed_mps`: a queue
//!    that moves off at 10 m/s is followed, not run into at V_target (which PF-CS, with its
//!    constant speed, would otherwise do); it ends when the vehicle ahead no longer constrains
//!    (Gipps' speed ≥ V_target) or leaves the corridor.
//!    The cap applies to all five planners (PF-CS's constant V_target too: constant speed into a
//!    stopped car is not a plan); PF-ISO keeps its interaction term, which may only slow it
//!    further.
//! 3. **Eq. 10 with speeds below v_min**. The optimisation itself keeps its decision variables
//!    in [v_min, max(V_i^max, v_min)] (`min_speed_mps`, so Δs/v stays finite and the solver
//!    unchanged); afterwards a speed above its cap is lowered to the cap, which may be below
//!    v_min, down to 0 ([`apply_caps`]). Slot by slot this is the solution of Eq. 10 with the
//!    travel time floored at v_min, Δs_i / max(v_i, v_min) (the acceleration bound couples the
//!    slots; the caps, falling at no more than b, meet it): on [0, v_min] that time is constant
//!    and the target-speed term ½w2(v_i − V_target)² falls with v_i, so where the cap is below
//!    v_min the best speed is the cap itself (the interaction term is not consulted on such a
//!    slot: the cap is the binding constraint). Where the cap is above v_min it is an ordinary
//!    upper bound inside the optimisation (V_i^max), so the answer is Eq. 10's. Lowering the
//!    variables' bound to v_min/10 in such cycles (Δs/v kept exact) was tried and not adopted:
//!    PF-ISO's interaction term then held the speed in (0.2, 0.5) m/s, above the tracker's
//!    stop speed, and the car crept 0.30 m over 3 s at the stop point instead of standing.
//! 4. **Times** ([`segment_time_s`]). A segment planned at a speed below
//!    [`STANDSTILL_TIMING_SPEED_MPS`] (1 cm/s) is timed as if driven at that speed,
//!    t_i = t_{i−1} + Δs_i / max(v_i, 0.01 m/s): every time is finite (a stopped vehicle's
//!    1 m step then lasts 100 s), and whoever reads the path by time (the broadcast shared
//!    path, `Plan::kinematic_state_at`) sees a stopped vehicle advance by at most 1 cm/s. Not
//!    v_min: floored at 0.5 m/s, a stopped car's broadcast would say it creeps 4 m over the
//!    8 s horizon. The tracker uses the speeds, not the times.
//!
//! The tracker holds a car still with its brakes once both the target and the actual speed are
//! below its `stop_speed_mps` (0.2 m/s), which the cap reaches a few seconds after the gap has
//! come within a few centimetres of s₀.
//!
//! Outside such cycles (everybody around faster than `stop_and_go_speed_mps`) nothing here is
//! computed, so moving traffic is planned bit for bit as before. 0 turns the cap off.

use crate::derived_params::PlanHorizon;
use crate::following::{FollowingParams, cap_behind, corridor_leaders_in_lane_frame};
use crate::lane_road_field::LaneRoadGeometry;
use crate::request::PlanRequest;

/// The numbers of stop and go (module doc, item 2), built once from `PlannerParams`
/// (`derived_params`). Not from the paper.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StopAndGoParams {
    /// A cycle is a stop-and-go cycle when the vehicle or one ahead in its corridor is slower
    /// than this (m/s; `stop_and_go_speed_mps`); 0 turns the cap off.
    pub speed_threshold_mps: f64,
    /// Gipps' safe-following speed and the corridor (`following` module).
    pub following: FollowingParams,
    /// The slots the caps are for (N of Eq. 7) and the speed change a_max·Δt_plan per slot.
    pub horizon: PlanHorizon,
}

/// The per-slot caps of stop and go (module doc, item 2) for a cycle planning along `points`
/// (the fitted path's points from the vehicle on), or `None` when the cycle is not a stop-and-go
/// cycle: nobody in the corridor; or the vehicle and everybody in its corridor faster than
/// `stop_and_go_speed_mps` and, if the last cycle was one (`was_active`), Gipps' speed no
/// longer below V_target; or the cap turned off.
pub fn stop_and_go_caps_mps(
    params: &StopAndGoParams,
    road: &LaneRoadGeometry,
    req: &PlanRequest<'_>,
    points: &[[f64; 2]],
    was_active: bool,
) -> Option<Vec<f64>> {
    let threshold_mps = params.speed_threshold_mps;
    if threshold_mps <= 0.0 {
        return None;
    }
    // Cheap test first (moving traffic costs one comparison per neighbour): nobody slow
    // around and no stop-and-go cycle before, nothing to do.
    let anyone_slow = req.ego.speed_mps < threshold_mps
        || req
            .neighbours
            .iter()
            .any(|n| n.id != req.ego_id && n.state.speed_mps < threshold_mps);
    if !(anyone_slow || was_active) {
        return None;
    }
    let leaders = corridor_leaders_in_lane_frame(
        &params.following,
        road,
        req.ego_id,
        &req.ego,
        &req.ego_shape,
        req.neighbours,
        points,
    );
    let slow = req.ego.speed_mps < threshold_mps
        || leaders
            .iter()
            .any(|&(_, speed_mps)| speed_mps < threshold_mps);
    let cap_now_mps = cap_behind(&params.following, &leaders)?;
    if !(slow || (was_active && cap_now_mps < req.target_speed_mps)) {
        return None;
    }
    let decel_mps = params.horizon.max_speed_change_mps;
    let v0 = req.ego.speed_mps.max(0.0);
    Some(
        (0..params.horizon.waypoint_count)
            .map(|i| cap_now_mps.max(v0 - decel_mps * (i + 1) as f64).max(0.0))
            .collect(),
    )
}

/// Lowers each speed above its cap to the cap (module doc, item 3).
pub(crate) fn apply_caps(speeds_mps: &mut [f64], caps_mps: &[f64]) {
    for (v, cap) in speeds_mps.iter_mut().zip(caps_mps) {
        *v = v.min(*cap);
    }
}

/// Speed floor of a planned path's *times* at standstill (m/s; module doc, item 4).
pub(crate) const STANDSTILL_TIMING_SPEED_MPS: f64 = 0.01;

/// Time to drive a segment of `length_m` at `speed_mps` (s), with the speed floored at
/// [`STANDSTILL_TIMING_SPEED_MPS`] in the time only (module doc, item 4).
pub(crate) fn segment_time_s(length_m: f64, speed_mps: f64) -> f64 {
    length_m / speed_mps.max(STANDSTILL_TIMING_SPEED_MPS)
}

#[cfg(test)]
mod tests;
