//! Obstacle potential field, paper Eq. 4: an ellipse-shaped Gaussian around another vehicle,
//! aligned with its heading ψ_o.
//!
//! Readings of the paper (listed in `planner/README.md`):
//! - The C1/C2 terms of Eq. 4 are a small-angle form of a rotated Gaussian (and divide by σ
//!   instead of σ²). We evaluate the Gaussian exactly in the obstacle's frame:
//!   u = R(ψ_o)ᵀ (p − p_o), U = A_obs · exp(−u_x²/(2σ_x²) − u_y²/(2σ_y²)).
//! - σ_y = d_lat / √(−2 ln(ε/A_obs)): the field is ε at a fixed lateral safety distance d_lat
//!   (the paper's σ_y contains Y − Y_o itself, which makes the "Gaussian" a constant).
//! - σ_x = D_min / √(−2 ln f): the field is the fraction f of A_obs at D_min (the paper's
//!   σ_x = D_min √(−1/ln U) without the factor 2 and with U undefined).
//! - D_min = (l + l_o)/2 + max(0, v_f·τ + M_f v_f²/(2 a_f) − M_l v_l²/(2 a_l)), with the body
//!   lengths (the paper's wheelbases would let the boxes overlap at D_min), masses as
//!   dimensionless factors, and the follower/leader roles taken from the side of the obstacle
//!   the point is on: behind it the planning vehicle follows, ahead of it the obstacle follows.
//!   The paper's formula is the "behind" case with τ = 0. The two half-Gaussians join with
//!   zero slope at u_x = 0, so the field stays C¹ (and ln U stays concave in u).

use crate::params::PlannerParams;
use crate::types::VehicleShape;

/// D_min of Eq. 4 for a follower closing on a leader (m), clamped to at least the half
/// lengths: (l_f + l_l)/2 + max(0, v_f τ + M_f v_f²/(2 a_f) − M_l v_l²/(2 a_l)).
#[allow(clippy::too_many_arguments)]
pub fn min_distance_m(
    follower_speed_mps: f64,
    follower_decel_mps2: f64,
    follower_mass_factor: f64,
    leader_speed_mps: f64,
    leader_decel_mps2: f64,
    leader_mass_factor: f64,
    half_lengths_m: f64,
    time_gap_s: f64,
) -> f64 {
    let vf = follower_speed_mps.max(0.0);
    let vl = leader_speed_mps.max(0.0);
    let braking = follower_mass_factor * vf * vf / (2.0 * follower_decel_mps2.max(1e-3))
        - leader_mass_factor * vl * vl / (2.0 * leader_decel_mps2.max(1e-3));
    half_lengths_m + (vf * time_gap_s + braking).max(0.0)
}

/// One obstacle's field (Eq. 4) as seen by one planning vehicle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObstacleField {
    /// Centre X_o (m).
    pub x_m: f64,
    /// Centre Y_o (m).
    pub y_m: f64,
    /// cos ψ_o.
    pub cos_heading: f64,
    /// sin ψ_o.
    pub sin_heading: f64,
    /// σ_x ahead of the obstacle (m).
    pub sigma_front_m: f64,
    /// σ_x behind the obstacle (m).
    pub sigma_rear_m: f64,
    /// σ_y (m).
    pub sigma_lateral_m: f64,
    /// A_obs.
    pub amplitude: f64,
}

/// What the planning vehicle knows about itself for D_min.
#[derive(Clone, Copy, Debug)]
pub struct SelfView {
    /// Its speed (m/s).
    pub speed_mps: f64,
    /// Its shape.
    pub shape: VehicleShape,
}

impl ObstacleField {
    /// The field of a vehicle at (x, y, ψ) with `other_speed_mps` and `other_shape`, seen by
    /// the planning vehicle `me` (σ's as in the module doc).
    pub fn new(
        params: &PlannerParams,
        me: SelfView,
        x_m: f64,
        y_m: f64,
        heading_rad: f64,
        other_speed_mps: f64,
        other_shape: &VehicleShape,
    ) -> Self {
        let half_lengths_m = 0.5 * (me.shape.length_m + other_shape.length_m);
        // Behind the obstacle: I follow it.
        let d_rear = min_distance_m(
            me.speed_mps,
            me.shape.max_brake_decel_mps2,
            params.ego_mass_factor,
            other_speed_mps,
            other_shape.max_brake_decel_mps2,
            params.other_mass_factor,
            half_lengths_m,
            params.obstacle_time_gap_s,
        );
        // Ahead of the obstacle: it follows me.
        let d_front = min_distance_m(
            other_speed_mps,
            other_shape.max_brake_decel_mps2,
            params.other_mass_factor,
            me.speed_mps,
            me.shape.max_brake_decel_mps2,
            params.ego_mass_factor,
            half_lengths_m,
            params.obstacle_time_gap_s,
        );
        let x_scale = (-2.0 * params.obstacle_fraction_at_min_distance.ln()).sqrt();
        let y_scale = (-2.0 * (params.obstacle_epsilon / params.obstacle_amplitude).ln()).sqrt();
        let (sin_heading, cos_heading) = heading_rad.sin_cos();
        Self {
            x_m,
            y_m,
            cos_heading,
            sin_heading,
            sigma_front_m: d_front / x_scale,
            sigma_rear_m: d_rear / x_scale,
            sigma_lateral_m: params.obstacle_lateral_safety_m / y_scale,
            amplitude: params.obstacle_amplitude,
        }
    }

    /// The same field with its front half shrunk to the contact distance (l + l_o)/2: only the
    /// vehicle behind keeps the speed-dependent gap (the follower is responsible for it, as in
    /// RSS). Used by the interaction term of Eq. 10 when `interaction_rear_only` is set.
    pub fn rear_only(&self, half_lengths_m: f64, params: &PlannerParams) -> Self {
        let x_scale = (-2.0 * params.obstacle_fraction_at_min_distance.ln()).sqrt();
        Self {
            sigma_front_m: half_lengths_m / x_scale,
            ..*self
        }
    }

    /// The same field moved to another centre and heading (same σ's).
    pub fn moved_to(&self, x_m: f64, y_m: f64, cos_heading: f64, sin_heading: f64) -> Self {
        Self {
            x_m,
            y_m,
            cos_heading,
            sin_heading,
            ..*self
        }
    }

    /// (u_x, u_y, σ_x): the point in the obstacle's frame and the σ_x of its side.
    fn local(&self, x_m: f64, y_m: f64) -> (f64, f64, f64) {
        let dx = x_m - self.x_m;
        let dy = y_m - self.y_m;
        let ux = self.cos_heading * dx + self.sin_heading * dy;
        let uy = -self.sin_heading * dx + self.cos_heading * dy;
        let sigma_x = if ux >= 0.0 {
            self.sigma_front_m
        } else {
            self.sigma_rear_m
        };
        (ux, uy, sigma_x)
    }

    /// The exponent q with U = A·exp(−q) (q ≥ 0).
    pub fn exponent(&self, x_m: f64, y_m: f64) -> f64 {
        let (ux, uy, sx) = self.local(x_m, y_m);
        let sy = self.sigma_lateral_m;
        0.5 * (ux * ux / (sx * sx) + uy * uy / (sy * sy))
    }

    /// U_OB at (x, y), Eq. 4.
    pub fn value(&self, x_m: f64, y_m: f64) -> f64 {
        self.amplitude * (-self.exponent(x_m, y_m)).exp()
    }

    /// U_OB and its gradient with respect to the evaluated point (x, y).
    pub fn value_and_gradient(&self, x_m: f64, y_m: f64) -> (f64, [f64; 2]) {
        let (ux, uy, sx) = self.local(x_m, y_m);
        let sy = self.sigma_lateral_m;
        let u = self.amplitude * (-0.5 * (ux * ux / (sx * sx) + uy * uy / (sy * sy))).exp();
        // dq/du = (u_x/σ_x², u_y/σ_y²); du/dp = R(ψ)ᵀ.
        let qx = ux / (sx * sx);
        let qy = uy / (sy * sy);
        let gx = -u * (qx * self.cos_heading - qy * self.sin_heading);
        let gy = -u * (qx * self.sin_heading + qy * self.cos_heading);
        (u, [gx, gy])
    }

    /// ∇U_OB at (x, y).
    pub fn gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        self.value_and_gradient(x_m, y_m).1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn me(speed_mps: f64) -> SelfView {
        SelfView {
            speed_mps,
            shape: VehicleShape::default(),
        }
    }

    #[test]
    fn gradient_matches_central_differences_in_a_rotated_frame() {
        let params = PlannerParams::default();
        let field = ObstacleField::new(
            &params,
            me(20.0),
            30.0,
            5.0,
            0.4,
            15.0,
            &VehicleShape::default(),
        );
        assert!(field.sigma_front_m != field.sigma_rear_m);
        let h = 1e-6;
        for (x, y) in [
            (25.0, 4.0),
            (36.0, 6.5),
            (30.5, 3.0),
            (10.0, 5.0),
            (45.0, 9.0),
        ] {
            let g = field.gradient(x, y);
            let fx = (field.value(x + h, y) - field.value(x - h, y)) / (2.0 * h);
            let fy = (field.value(x, y + h) - field.value(x, y - h)) / (2.0 * h);
            assert!((g[0] - fx).abs() < 1e-7, "({x},{y}): {} vs {fx}", g[0]);
            assert!((g[1] - fy).abs() < 1e-7, "({x},{y}): {} vs {fy}", g[1]);
        }
    }

    #[test]
    fn field_levels_match_the_safety_distances() {
        let params = PlannerParams::default();
        let shape = VehicleShape::default();
        let field = ObstacleField::new(&params, me(20.0), 0.0, 0.0, 0.0, 15.0, &shape);
        // Lateral: ε at d_lat.
        let at_lateral = field.value(0.0, params.obstacle_lateral_safety_m);
        assert!((at_lateral - params.obstacle_epsilon).abs() < 1e-12);
        // Behind: the planning vehicle (20 m/s) follows the obstacle (15 m/s).
        let a = shape.max_brake_decel_mps2;
        let d_rear = shape.length_m
            + 20.0 * params.obstacle_time_gap_s
            + (20.0 * 20.0 - 15.0 * 15.0) / (2.0 * a);
        let behind = field.value(-d_rear, 0.0);
        let expected = params.obstacle_amplitude * params.obstacle_fraction_at_min_distance;
        assert!((behind - expected).abs() < 1e-12, "{behind} vs {expected}");
    }

    #[test]
    fn min_distance_is_clamped_to_the_half_lengths() {
        // A much faster leader: the braking terms would make D_min negative.
        let d = min_distance_m(5.0, 7.0, 1.0, 30.0, 7.0, 1.0, 4.5, 0.0);
        assert_eq!(d, 4.5);
        // The paper's formula when positive: v²/2a − v_o²/2a_o + l.
        let d = min_distance_m(20.0, 7.0, 1.0, 15.0, 7.0, 1.0, 4.5, 0.0);
        assert!((d - (4.5 + (400.0 - 225.0) / 14.0)).abs() < 1e-12);
    }

    #[test]
    fn rotation_aligns_the_ellipse_with_the_heading() {
        let params = PlannerParams::default();
        let shape = VehicleShape::default();
        let psi: f64 = 0.3;
        let field = ObstacleField::new(&params, me(15.0), 0.0, 0.0, psi, 15.0, &shape);
        let straight = ObstacleField::new(&params, me(15.0), 0.0, 0.0, 0.0, 15.0, &shape);
        // A point at distance r along the heading sees the same field as the unrotated one at (r, 0).
        let r = 4.0;
        let rotated = field.value(r * psi.cos(), r * psi.sin());
        assert!((rotated - straight.value(r, 0.0)).abs() < 1e-12);
    }
}
