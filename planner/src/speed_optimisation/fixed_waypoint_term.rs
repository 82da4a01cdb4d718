//! The interaction term of Eq. 10 as the paper prints it: U_SLP at the fixed Eq. 7 waypoints.
//!
//! "We use (X_pf^{ego,i}, Y_pf^{ego,i}) and (X_pf^{obs,i}, Y_pf^{obs,i}) from Eq. (7) instead of
//! (X, Y) and (X_o, Y_o)": both positions of slot i are waypoints, fixed before the speeds are
//! chosen, so the speed v_i enters U_SLP^i only through D_min(v_i) in σ_x (Eq. 4):
//!
//! ```text
//!   φ_i(v_i) = ln(U₀ + Σ_o U_OB^o(p_i; q_o(t_0 + iΔt), σ_x(D_min(v_i, v_o,i)))) − ln U₀
//!   ∂φ_i/∂v_i = Σ_o ∂U^o/∂σ_x · ∂D_min/∂v_i / √(−2 ln f)  /  (U₀ + Σ_o U^o)
//! ```
//!
//! p_i is the ego's i-th Eq. 7 waypoint, q_o(t) the other's shared path at the same absolute time
//! (for two plans made at the same instant at constant speeds this is its i-th waypoint) and
//! v_o,i its speed there. The term is separable (φ_i depends on v_i alone). With the printed
//! D_min the planning vehicle is the follower, so D_min grows with v_i and the term can only
//! slow it down; once v_i falls to the other's speed D_min sits on its clamp and the term stops
//! pulling. The floor U₀ is the same departure as in the arc-length reading (without it
//! ln U = ln A − q rewards distance without bound, and far vehicles dominate).

use super::SpeedTerm;
use crate::obstacle_field::{MinDistanceLength, ObstacleField, ObstacleFieldParams, Role, Side};
use crate::obstacle_field::{SelfView, min_distances};
use mergesim_types::VehicleShape;

/// One other vehicle at one slot: its field centred on its shared waypoint, and what D_min needs.
#[derive(Clone, Debug)]
pub(crate) struct SlotOther {
    /// Its field (σ's are recomputed from v_i; the centre and heading are used as they are).
    pub field: ObstacleField,
    /// Its speed at the slot (m/s).
    pub speed_mps: f64,
    /// Its shape.
    pub shape: VehicleShape,
    /// Who keeps the gap (applied after σ_x is recomputed from v_i).
    pub role: Role,
}

/// Σ_i φ_i(v_i) at fixed waypoints (module doc).
#[derive(Clone, Debug)]
pub struct FixedWaypointTerm {
    field_params: ObstacleFieldParams,
    /// √(−2 ln f) of `field_params` (σ_x = D_min / this), computed once.
    x_scale: f64,
    ego_shape: VehicleShape,
    floor: f64,
    /// `waypoints[i]`: the ego's Eq. 7 waypoint of slot i + 1.
    waypoints: Vec<[f64; 2]>,
    /// `others[i]`: the other vehicles at slot i + 1.
    others: Vec<Vec<SlotOther>>,
}

impl FixedWaypointTerm {
    /// The term for the ego's `waypoints` and the others at the same slots; `floor` is ε_I.
    pub(crate) fn new(
        field_params: ObstacleFieldParams,
        ego_shape: VehicleShape,
        floor: f64,
        waypoints: Vec<[f64; 2]>,
        others: Vec<Vec<SlotOther>>,
    ) -> Self {
        Self {
            x_scale: field_params.x_scale(),
            field_params,
            ego_shape,
            floor,
            waypoints,
            others,
        }
    }

    /// φ_i(v) and dφ_i/dv for one slot.
    fn slot(&self, i: usize, v_mps: f64) -> (f64, f64) {
        let p = self.waypoints[i];
        let x_scale = self.x_scale;
        let me = SelfView {
            speed_mps: v_mps,
            shape: self.ego_shape,
        };
        let (mut sum_u, mut sum_du) = (0.0, 0.0);
        for other in &self.others[i] {
            let d = min_distances(&self.field_params, me, other.speed_mps, &other.shape);
            let contact_m = 0.5 * (self.ego_shape.length_m + other.shape.length_m);
            let field = ObstacleField {
                sigma_front_m: d.front_m / x_scale,
                sigma_rear_m: d.rear_m / x_scale,
                ..other.field
            }
            .with_role(other.role, contact_m, x_scale);
            let (u, side, du_dsigma) = field.value_and_sigma_derivative(p[0], p[1]);
            // A side held at the contact distance does not move with v.
            let dd_dv = match (side, other.role) {
                (Side::Front, Role::Full) => d.front_dv_s,
                (Side::Rear, Role::Full | Role::RearOnly) => d.rear_dv_s,
                _ => 0.0,
            };
            sum_u += u;
            sum_du += du_dsigma * dd_dv / x_scale;
        }
        let total = self.floor + sum_u;
        ((total / self.floor).ln(), sum_du / total)
    }

    /// The length term of D_min this term uses (for documentation and tests).
    pub fn min_distance_length(&self) -> MinDistanceLength {
        self.field_params.min_distance_length
    }
}

impl SpeedTerm for FixedWaypointTerm {
    fn slots(&self) -> usize {
        self.waypoints.len().min(self.others.len())
    }

    fn value_and_gradient(&self, speeds_mps: &[f64]) -> (f64, Vec<f64>) {
        let n = speeds_mps.len().min(self.slots());
        let mut value = 0.0;
        let mut gradient = vec![0.0; speeds_mps.len()];
        for i in 0..n {
            let (phi, dphi) = self.slot(i, speeds_mps[i]);
            value += phi;
            gradient[i] = dphi;
        }
        (value, gradient)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parameter_set::ParameterSet;

    /// The ego (faster) behind and beside the other in the paper's reading: the term falls as
    /// v_i falls, and its gradient matches central differences.
    #[test]
    fn gradient_matches_central_differences_and_the_term_only_slows() {
        let params = ParameterSet::Paper.planner_params();
        let field_params = params.interaction_field();
        let shape = VehicleShape::default();
        let n = 8;
        let dt = params.step_time_s;
        let me = SelfView {
            speed_mps: 20.0,
            shape,
        };
        let waypoints: Vec<[f64; 2]> = (1..=n)
            .map(|i| [20.0 * dt * i as f64, 1.75 + 0.3 * i as f64])
            .collect();
        let others: Vec<Vec<SlotOther>> = (1..=n)
            .map(|i| {
                let x = 12.0 + 15.0 * dt * i as f64;
                vec![SlotOther {
                    field: ObstacleField::new(&field_params, me, x, 5.25, 0.02, 15.0, &shape),
                    speed_mps: 15.0,
                    shape,
                    role: Role::Full,
                }]
            })
            .collect();
        let term = FixedWaypointTerm::new(
            field_params,
            shape,
            params.interaction_floor,
            waypoints,
            others,
        );
        let v: Vec<f64> = (0..n).map(|i| 19.0 + 0.2 * i as f64).collect();
        let g = super::super::assert_gradient_matches_central_differences(&term, &v);
        assert!(
            g.iter().all(|x| *x >= 0.0),
            "a faster ego widens its D_min: the term grows with v"
        );
        assert!(g.iter().any(|x| *x > 1e-3), "the term must act: {g:?}");
        // At or below the other's speed D_min is on its clamp: nothing left to gain.
        let slow = vec![14.0; n];
        assert!(term.value_and_gradient(&slow).1.iter().all(|x| *x == 0.0));
    }
}
