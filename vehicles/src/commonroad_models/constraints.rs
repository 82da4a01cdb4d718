//! The input of CommonRoad's models and the two constraints every model applies to it before
//! using it.
//!
//! **Steering velocity.** The steering angle δ stays in [δ_min, δ_max] because the rate that
//! would push it further out is replaced by 0; any other rate is clipped to
//! [v_δ,min, v_δ,max]:
//! ```text
//! v_δ' = 0                  if (δ ≤ δ_min and v_δ ≤ 0) or (δ ≥ δ_max and v_δ ≥ 0)
//!        v_δ,min            else if v_δ ≤ v_δ,min
//!        v_δ,max            else if v_δ ≥ v_δ,max
//!        v_δ                otherwise
//! ```
//! **Longitudinal acceleration.** Above the switching speed v_S the engine's power bounds the
//! acceleration, so the positive limit falls as 1/v; the speed stays in [v_min, v_max] the same
//! way as the steering angle:
//! ```text
//! a_+ = a_max · v_S / v    if v > v_S,    else a_max
//! a'  = 0                  if (v ≤ v_min and a ≤ 0) or (v ≥ v_max and a ≥ 0)
//!       −a_max             else if a ≤ −a_max
//!       a_+                else if a ≥ a_+
//!       a                  otherwise
//! ```
//! Both are evaluated at every call of a model's derivative, i.e. at each Runge–Kutta stage; a
//! state can overshoot a limit by at most one step's worth of rate.

use serde::{Deserialize, Serialize};

use super::params::{CommonRoadLongitudinalLimits, CommonRoadSteeringLimits};

/// The two inputs of CommonRoad's ks, st and std models (in CommonRoad's order u₁, u₂).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CommonRoadInput {
    /// u₁: rate of the front-wheel steering angle (rad/s).
    pub steering_velocity_radps: f64,
    /// u₂: longitudinal acceleration (m/s²).
    pub acceleration_mps2: f64,
}

impl CommonRoadInput {
    /// The input in CommonRoad's order `[u1, u2]`.
    pub fn to_array(&self) -> [f64; 2] {
        [self.steering_velocity_radps, self.acceleration_mps2]
    }
}

/// The steering velocity the models use at steering angle `steering_angle_rad` when
/// `steering_velocity_radps` is asked for (see the module doc).
pub fn constrain_steering_velocity(
    steering_angle_rad: f64,
    steering_velocity_radps: f64,
    limits: &CommonRoadSteeringLimits,
) -> f64 {
    let at_min = steering_angle_rad <= limits.min_angle_rad && steering_velocity_radps <= 0.0;
    let at_max = steering_angle_rad >= limits.max_angle_rad && steering_velocity_radps >= 0.0;
    if at_min || at_max {
        0.0
    } else if steering_velocity_radps <= limits.min_steering_velocity_radps {
        limits.min_steering_velocity_radps
    } else if steering_velocity_radps >= limits.max_steering_velocity_radps {
        limits.max_steering_velocity_radps
    } else {
        steering_velocity_radps
    }
}

/// The longitudinal acceleration the models use at speed `speed_mps` when `acceleration_mps2`
/// is asked for (see the module doc).
pub fn constrain_acceleration(
    speed_mps: f64,
    acceleration_mps2: f64,
    limits: &CommonRoadLongitudinalLimits,
) -> f64 {
    let positive_limit_mps2 = if speed_mps > limits.switching_speed_mps {
        limits.max_acceleration_mps2 * limits.switching_speed_mps / speed_mps
    } else {
        limits.max_acceleration_mps2
    };
    let at_min = speed_mps <= limits.min_speed_mps && acceleration_mps2 <= 0.0;
    let at_max = speed_mps >= limits.max_speed_mps && acceleration_mps2 >= 0.0;
    if at_min || at_max {
        0.0
    } else if acceleration_mps2 <= -limits.max_acceleration_mps2 {
        -limits.max_acceleration_mps2
    } else if acceleration_mps2 >= positive_limit_mps2 {
        positive_limit_mps2
    } else {
        acceleration_mps2
    }
}

/// Both constraints at steering angle `steering_angle_rad` and speed `speed_mps`.
pub fn constrain_input(
    steering_angle_rad: f64,
    speed_mps: f64,
    input: &CommonRoadInput,
    steering: &CommonRoadSteeringLimits,
    longitudinal: &CommonRoadLongitudinalLimits,
) -> CommonRoadInput {
    CommonRoadInput {
        steering_velocity_radps: constrain_steering_velocity(
            steering_angle_rad,
            input.steering_velocity_radps,
            steering,
        ),
        acceleration_mps2: constrain_acceleration(speed_mps, input.acceleration_mps2, longitudinal),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commonroad_models::CommonRoadVehicleParams;

    #[test]
    fn steering_velocity_is_clipped_and_stopped_at_the_angle_limits() {
        let s = CommonRoadVehicleParams::default().steering; // ±1.066 rad, ±0.4 rad/s
        assert_eq!(constrain_steering_velocity(0.0, 0.3, &s), 0.3);
        assert_eq!(constrain_steering_velocity(0.0, 1.0, &s), 0.4);
        assert_eq!(constrain_steering_velocity(0.0, -1.0, &s), -0.4);
        assert_eq!(constrain_steering_velocity(1.066, 0.1, &s), 0.0);
        assert_eq!(constrain_steering_velocity(1.066, 0.0, &s), 0.0);
        assert_eq!(constrain_steering_velocity(1.1, -1.0, &s), -0.4);
        assert_eq!(constrain_steering_velocity(-1.066, -0.1, &s), 0.0);
        assert_eq!(constrain_steering_velocity(-1.066, 0.2, &s), 0.2);
    }

    #[test]
    fn acceleration_limit_falls_with_speed_above_the_switching_speed() {
        let l = CommonRoadVehicleParams::default().longitudinal; // v_S 7.319, a_max 11.5
        assert_eq!(constrain_acceleration(5.0, 3.0, &l), 3.0);
        assert_eq!(constrain_acceleration(5.0, 20.0, &l), 11.5);
        assert_eq!(constrain_acceleration(5.0, -20.0, &l), -11.5);
        // 11.5 · 7.319 / 14.638 = 5.75
        assert!((constrain_acceleration(14.638, 20.0, &l) - 5.75).abs() < 1e-12);
        // braking is not reduced by the power limit
        assert_eq!(constrain_acceleration(30.0, -11.0, &l), -11.0);
        assert_eq!(constrain_acceleration(50.8, 1.0, &l), 0.0);
        assert_eq!(constrain_acceleration(50.8, -1.0, &l), -1.0);
        assert_eq!(constrain_acceleration(-13.9, -1.0, &l), 0.0);
        assert_eq!(constrain_acceleration(-13.9, 1.0, &l), 1.0);
    }
}
