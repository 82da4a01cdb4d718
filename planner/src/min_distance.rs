//! D_min of Eq. 4: the safety distance of a follower behind a leader, and the two D_min of a
//! pair of vehicles (behind and ahead of the obstacle) with their derivatives in the planning
//! vehicle's speed.

use crate::field_params::ObstacleFieldParams;
use mergesim_types::VehicleShape;

/// D_min of Eq. 4 for a follower closing on a leader (m), clamped to at least the length term:
/// length + max(0, v_f τ + M_f v_f²/(2 a_f) − M_l v_l²/(2 a_l)).
#[allow(clippy::too_many_arguments)]
pub fn min_distance_m(
    follower_speed_mps: f64,
    follower_decel_mps2: f64,
    follower_mass_factor: f64,
    leader_speed_mps: f64,
    leader_decel_mps2: f64,
    leader_mass_factor: f64,
    length_term_m: f64,
    time_gap_s: f64,
) -> f64 {
    length_term_m
        + min_distance_excess_m(
            follower_speed_mps,
            follower_decel_mps2,
            follower_mass_factor,
            leader_speed_mps,
            leader_decel_mps2,
            leader_mass_factor,
            time_gap_s,
        )
        .max(0.0)
}

/// v_f τ + M_f v_f²/(2 a_f) − M_l v_l²/(2 a_l), before the clamp (m).
fn min_distance_excess_m(
    follower_speed_mps: f64,
    follower_decel_mps2: f64,
    follower_mass_factor: f64,
    leader_speed_mps: f64,
    leader_decel_mps2: f64,
    leader_mass_factor: f64,
    time_gap_s: f64,
) -> f64 {
    let vf = follower_speed_mps.max(0.0);
    let vl = leader_speed_mps.max(0.0);
    vf * time_gap_s + follower_mass_factor * vf * vf / (2.0 * follower_decel_mps2.max(1e-3))
        - leader_mass_factor * vl * vl / (2.0 * leader_decel_mps2.max(1e-3))
}

/// What the planning vehicle knows about itself for D_min.
#[derive(Clone, Copy, Debug)]
pub struct SelfView {
    /// Its speed (m/s).
    pub speed_mps: f64,
    /// Its shape.
    pub shape: VehicleShape,
}

/// The two D_min of a pair, and their derivatives with respect to the planning vehicle's speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MinDistances {
    /// D_min behind the obstacle (the planning vehicle follows it) (m).
    pub rear_m: f64,
    /// D_min ahead of the obstacle (it follows the planning vehicle; = `rear_m` without roles).
    pub front_m: f64,
    /// ∂rear/∂v of the planning vehicle (s).
    pub rear_dv_s: f64,
    /// ∂front/∂v of the planning vehicle (s).
    pub front_dv_s: f64,
}

/// D_min on both sides of an obstacle moving at `other_speed_mps`, seen by `me` (module doc).
pub fn min_distances(
    params: &ObstacleFieldParams,
    me: SelfView,
    other_speed_mps: f64,
    other_shape: &VehicleShape,
) -> MinDistances {
    let length_m = params
        .min_distance_length
        .half_sum_m(&me.shape, other_shape);
    let (a_me, a_other) = (
        me.shape.max_brake_decel_mps2,
        other_shape.max_brake_decel_mps2,
    );
    let v = me.speed_mps.max(0.0);
    // Behind the obstacle: I follow it.
    let rear_excess = min_distance_excess_m(
        v,
        a_me,
        params.ego_mass_factor,
        other_speed_mps,
        a_other,
        params.other_mass_factor,
        params.time_gap_s,
    );
    let rear_m = length_m + rear_excess.max(0.0);
    let rear_dv_s = if rear_excess > 0.0 && me.speed_mps > 0.0 {
        params.time_gap_s + params.ego_mass_factor * v / a_me.max(1e-3)
    } else {
        0.0
    };
    if !params.min_distance_by_side {
        return MinDistances {
            rear_m,
            front_m: rear_m,
            rear_dv_s,
            front_dv_s: rear_dv_s,
        };
    }
    // Ahead of the obstacle: it follows me.
    let front_excess = min_distance_excess_m(
        other_speed_mps,
        a_other,
        params.other_mass_factor,
        v,
        a_me,
        params.ego_mass_factor,
        params.time_gap_s,
    );
    let front_m = length_m + front_excess.max(0.0);
    let front_dv_s = if front_excess > 0.0 && me.speed_mps > 0.0 {
        -params.ego_mass_factor * v / a_me.max(1e-3)
    } else {
        0.0
    };
    MinDistances {
        rear_m,
        front_m,
        rear_dv_s,
        front_dv_s,
    }
}
