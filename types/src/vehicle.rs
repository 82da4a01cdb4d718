//! A vehicle as the planners see it: its state, its footprint and braking, and a perceived
//! neighbour.

use serde::{Deserialize, Serialize};

/// Identifier of a vehicle in a scenario (index order is the deterministic visiting order).
pub type VehicleId = u32;

/// What the planner knows about a vehicle at planning time (world frame, SI).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct VehicleState {
    /// Position of the centre of gravity along the road (m).
    pub x_m: f64,
    /// Lateral position of the centre of gravity (m).
    pub y_m: f64,
    /// Heading of the body x axis (rad, counter-clockwise from +X).
    pub yaw_rad: f64,
    /// Speed over ground (m/s).
    pub speed_mps: f64,
}

/// Footprint and braking capability of a vehicle, used by the obstacle field (Eq. 4).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct VehicleShape {
    /// Body length (m).
    pub length_m: f64,
    /// Body width (m).
    pub width_m: f64,
    /// Wheelbase l_fr (m).
    pub wheelbase_m: f64,
    /// Maximum braking deceleration a_b (m/s², positive).
    pub max_brake_decel_mps2: f64,
}

/// The braking deceleration a planner relies on (a_b of Eq. 5, m/s²) for a car whose braking
/// limit on this road is `limit_mps2`: `margin` × the limit, rounded down to 0.1 m/s² (the
/// margin and rounding that gave the presets' 7 m/s² at μ = 0.8: 0.9 · 0.8 · 9.81 = 7.06). A
/// product below 0.1 m/s² is kept unrounded, so the result stays positive for a positive limit
/// and margin.
pub fn planning_brake_decel_mps2(limit_mps2: f64, margin: f64) -> f64 {
    let product_mps2 = margin * limit_mps2;
    // The 1e-9 absorbs the product's rounding error (0.9 · 7.0 must round to 6.3, not 6.2).
    let rounded_mps2 = (product_mps2 * 10.0 + 1e-9).floor() / 10.0;
    if rounded_mps2 > 0.0 {
        rounded_mps2
    } else {
        product_mps2
    }
}

impl Default for VehicleShape {
    fn default() -> Self {
        // BMW 320i (CommonRoad vehicle 2): 4.508 m × 1.610 m, wheelbase 2.578 m; a_b = 7 m/s²,
        // friction-limited braking at μ = 0.8 (`planning_brake_decel_mps2(0.8 g, 0.9)`). The
        // simulator gives each car its own (`sim::agent`).
        Self {
            length_m: 4.508,
            width_m: 1.61,
            wheelbase_m: 2.578,
            max_brake_decel_mps2: 7.0,
        }
    }
}

/// Another vehicle as currently perceived (position, heading, speed, shape).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Neighbour {
    /// Its id.
    pub id: VehicleId,
    /// Its state.
    pub state: VehicleState,
    /// Its footprint.
    pub shape: VehicleShape,
}

#[cfg(test)]
mod planning_brake_tests {
    use super::planning_brake_decel_mps2;

    #[test]
    fn margin_times_limit_rounded_down_to_a_tenth() {
        assert_eq!(planning_brake_decel_mps2(0.8 * 9.81, 0.9), 7.0);
        assert_eq!(planning_brake_decel_mps2(0.5 * 9.81, 0.9), 4.4);
        // Exactly representable products are not pushed a tenth down by rounding error.
        assert_eq!(planning_brake_decel_mps2(7.0, 0.9), 6.3);
        assert_eq!(planning_brake_decel_mps2(10.0, 1.0), 10.0);
        // Below a tenth the product is kept, so a_b stays positive.
        let tiny = planning_brake_decel_mps2(0.05, 0.9);
        assert!((tiny - 0.045).abs() < 1e-15, "{tiny}");
    }
}
