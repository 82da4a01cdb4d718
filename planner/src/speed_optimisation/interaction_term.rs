//! The interaction term of Eq. 10 at the planned arc length (the `mergesim` reading of U_SLP),
//! and PF-SP's risk term, which has the same structure.
//!
//! ```text
//!   φ_i(v) = g(Σ_o U_OB^o(e_i(v); q_o(t_0 + iΔt)))
//!   e_i(v) = path(s_i),   s_i = Δt Σ_{j ≤ i} v_j
//!   g(U)   = ln(U₀ + U) − ln U₀     (Aggregate::LogFloored: U_SLP, PF-ISO)
//!   g(U)   = U                        (Aggregate::Linear: PF-SP's risk)
//! ```
//!
//! e_i is where the ego is after i time steps of Δt = Δt_plan along its fitted path; q_o(t) the
//! other vehicle's shared path (or prediction) at the same absolute time (time-matched, so a
//! stale or differently sampled SLP pairs correctly); U_OB is Eq. 4 centred on q_o with its
//! heading. ∂φ_i/∂s_i = g'(U) ∇U·τ_i (τ_i the path tangent) and ∂s_i/∂v_j = Δt for j ≤ i, so
//! the gradient is a suffix sum.
//!
//! Why a floor: the paper's `ln U_SLP` of a single Gaussian is ln A − q, a concave quadratic
//! whose pull grows without bound with the separation, so far vehicles would dominate the speed
//! choice; ln(U₀ + U) is ln A − q near a vehicle and fades (to 0 after subtracting the
//! constant ln U₀) once the others' fields fall below U₀ (`interaction_floor`).

use super::SpeedTerm;
use crate::obstacle_field::ObstacleField;
use crate::polyline::Polyline;

/// How the fields of one slot combine into φ_i (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Aggregate {
    /// ln(floor + Σ U) − ln floor, floor > 0 (the interaction term U_SLP).
    LogFloored {
        /// ε_I.
        floor: f64,
    },
    /// Σ U (PF-SP's risk).
    Linear,
}

/// Σ_i φ_i(v) along the ego's path (module doc).
#[derive(Clone, Debug)]
pub struct InteractionTerm {
    path: Polyline,
    fallback_tangent: [f64; 2],
    step_time_s: f64,
    aggregate: Aggregate,
    /// `fields[i]`: the other vehicles' fields at time slot i + 1, centred at their predicted
    /// poses.
    fields: Vec<Vec<ObstacleField>>,
}

impl InteractionTerm {
    /// The ego moves along `path` (starting at its current position, tangent
    /// `fallback_tangent` if the path is degenerate); `fields[i]` are the others' fields at
    /// t_0 + (i + 1)·Δt.
    pub(crate) fn new(
        path: Polyline,
        fallback_tangent: [f64; 2],
        step_time_s: f64,
        aggregate: Aggregate,
        fields: Vec<Vec<ObstacleField>>,
    ) -> Self {
        Self {
            path,
            fallback_tangent,
            step_time_s,
            aggregate,
            fields,
        }
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
}

impl SpeedTerm for InteractionTerm {
    fn slots(&self) -> usize {
        self.fields.len()
    }

    fn value_and_gradient(&self, speeds_mps: &[f64]) -> (f64, Vec<f64>) {
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
            let along = grad[0] * tangent[0] + grad[1] * tangent[1];
            match self.aggregate {
                Aggregate::LogFloored { floor } => {
                    let total = floor + sum_u;
                    value += (total / floor).ln();
                    d_ds[i] = along / total;
                }
                Aggregate::Linear => {
                    value += sum_u;
                    d_ds[i] = along;
                }
            }
        }
        let mut gradient = vec![0.0; speeds_mps.len()];
        let mut suffix = 0.0;
        for i in (0..n).rev() {
            suffix += d_ds[i];
            gradient[i] = self.step_time_s * suffix;
        }
        (value, gradient)
    }

    /// Σ_i φ_i(v) without the gradient: the SCP's line search evaluates the objective far more
    /// often than its gradient. The same operations in the same order as
    /// [`value_and_gradient`](Self::value_and_gradient), so the same bits.
    fn value(&self, speeds_mps: &[f64]) -> f64 {
        let mut value = 0.0;
        let mut s = 0.0;
        for (speed_mps, fields) in speeds_mps.iter().zip(&self.fields) {
            s += speed_mps * self.step_time_s;
            let p = self.path.point_and_tangent(s, self.fallback_tangent).0;
            let mut sum_u = 0.0;
            for field in fields {
                sum_u += field.value(p[0], p[1]);
            }
            match self.aggregate {
                Aggregate::LogFloored { floor } => value += ((floor + sum_u) / floor).ln(),
                Aggregate::Linear => value += sum_u,
            }
        }
        value
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::obstacle_field::SelfView;
    use crate::params::PlannerParams;
    use mergesim_types::VehicleShape;

    #[test]
    fn interaction_gradient_matches_central_differences() {
        let params = PlannerParams::default();
        let me = SelfView {
            speed_mps: 15.0,
            shape: VehicleShape::default(),
        };
        let base = ObstacleField::new(
            &params.interaction_field(),
            me,
            0.0,
            0.0,
            0.0,
            20.0,
            &VehicleShape::default(),
        );
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
        let term = InteractionTerm::new(
            path,
            [1.0, 0.0],
            dt,
            Aggregate::LogFloored {
                floor: params.interaction_floor,
            },
            fields,
        );
        let v: Vec<f64> = (0..n).map(|i| 14.0 + 0.1 * i as f64).collect();
        let g = super::super::assert_gradient_matches_central_differences(&term, &v);
        // The value-only evaluation is the same computation: the same bits.
        assert_eq!(
            term.value(&v).to_bits(),
            term.value_and_gradient(&v).0.to_bits()
        );
        assert!(
            g.iter().any(|gi| gi.abs() > 1e-3),
            "the term must act: {g:?}"
        );
    }
}
