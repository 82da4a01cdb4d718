//! Obstacle potential field, paper Eq. 4: an ellipse-shaped Gaussian around another vehicle,
//! aligned with its heading ψ_o.
//!
//! Eq. 4 as printed:
//!
//! ```text
//!   U_OB = A_obs exp[ −C1/2 ( (X − X_o)²/σ_x + (Y − Y_o)²/σ_y − C2 ) ]
//!   C1 = 1 − ψ_o²,   C2 = 2 ψ_o (X − X_o)(Y − Y_o) / (σ_x σ_y)
//!   σ_x = D_min √(−1/ln U),   σ_y = √( −(Y − Y_o)² / (2 ln(ε/A_obs)) )
//!   D_min = M v²/(2 a_b) − M_o v_o²/(2 a_b,o) + (l_fr + l_fr,o)/2
//! ```
//!
//! Two readings of the heading terms, both runnable ([`HeadingForm`]):
//! - [`HeadingForm::PaperCorrelation`] (the `paper` parameter set): C1/C2 taken as printed, with
//!   σ read as a standard deviation (σ² under the squares, as the σ_xσ_y of C2 implies). That is
//!   a bivariate Gaussian in world coordinates whose correlation is ψ_o, scaled by C1 = 1 − ψ_o²:
//!   q = C1/2 · (dx²/σ_x² + dy²/σ_y² − 2 ψ_o dx dy/(σ_x σ_y)). The correlation tilts the ellipse
//!   only by about ψ_o σ_y/σ_x, not by ψ_o; |ψ_o| is capped at [`MAX_CORRELATION_HEADING_RAD`]
//!   so the form stays positive definite (never reached on a highway).
//! - [`HeadingForm::Rotation`] (the `mergesim` set): the exact Gaussian in the obstacle's frame,
//!   u = R(ψ_o)ᵀ (p − p_o), q = u_x²/(2σ_x²) + u_y²/(2σ_y²): a true rotation by ψ_o.
//!
//! Readings common to both sets (listed in `planner/README.md`):
//! - σ_y = d_lat / √(−2 ln(ε/A_obs)): the field is ε at a fixed lateral safety distance d_lat.
//!   The printed σ_y contains Y − Y_o itself: with σ_y² under the square the lateral term is the
//!   constant 2 ln(A/ε) (no lateral decay at all); with σ_y as printed (not squared) it is
//!   |Y − Y_o|·√(2 ln(A/ε)), an exponential profile whose length scale is a unit slip (1 m).
//!   Neither gives a field that decays over a chosen distance, so both sets fix d_lat
//!   ([`LateralForm::FixedDistance`]). The unsquared printed form is an option
//!   (`obstacle_lateral_form = "printed-laplace"`, [`LateralForm::PrintedLaplace`]) for
//!   measuring what that reading does: q's lateral half is k·|u_y|/2 with k = √(−2 ln(ε/A)),
//!   and in the correlation form C2 = 2ψ_o k dx sgn(dy)/σ_x.
//! - σ_x = D_min / √(−2 ln f): the field is the fraction f of A_obs at D_min (the printed
//!   σ_x = D_min √(−1/ln U) has U undefined and lacks the factor 2).
//! - D_min is clamped to at least its length term (a negative D_min would flip the field).
//!   Optional extensions, all off in the `paper` set: a time gap v_f·τ; the length term from the
//!   body lengths instead of the wheelbases ([`MinDistanceLength`]); roles by side: behind the
//!   obstacle the planning vehicle follows (the paper's case), ahead of it the obstacle follows
//!   (with `by_side = false` the planning vehicle is the follower on both sides, as printed).
//!   With the rotation form the two half-Gaussians join with zero slope at u_x = 0 (C¹ field).
//!   With the correlation form the side is the sign of X − X_o, where q is continuous.

use mergesim_types::VehicleShape;

pub use crate::field_params::{
    HeadingForm, LateralForm, MAX_CORRELATION_HEADING_RAD, MinDistanceLength, ObstacleFieldParams,
    Role,
};
pub use crate::min_distance::{MinDistances, SelfView, min_distance_m, min_distances};

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
    /// ψ_o (rad) relative to the lane at the obstacle (the world yaw on a road along +x),
    /// capped for the correlation form.
    pub heading_rad: f64,
    /// (cos, sin) of the lane's heading at the obstacle: the axes the correlation form is
    /// written in ((1, 0) on a road along +x). The rotation form needs none: its ellipse is
    /// the obstacle's own frame, which rotates with the map.
    pub lane_axes: [f64; 2],
    /// σ_x ahead of the obstacle (m).
    pub sigma_front_m: f64,
    /// σ_x behind the obstacle (m).
    pub sigma_rear_m: f64,
    /// σ_y (m) of [`LateralForm::FixedDistance`].
    pub sigma_lateral_m: f64,
    /// The lateral term's form.
    pub lateral_form: LateralForm,
    /// k = √(−2 ln(ε/A)) (1/m) of [`LateralForm::PrintedLaplace`].
    pub lateral_laplace_rate_per_m: f64,
    /// A_obs.
    pub amplitude: f64,
    /// Heading terms.
    pub heading_form: HeadingForm,
}

/// Which half of the field a point lies in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Side {
    /// Ahead of the obstacle (σ_front).
    Front,
    /// Behind it (σ_rear).
    Rear,
}

impl Side {
    /// The side of a point `along` metres ahead of the obstacle along its axis (NaN: rear).
    #[inline]
    fn of_along(along: f64) -> Self {
        if along >= 0.0 {
            Side::Front
        } else {
            Side::Rear
        }
    }
}

impl ObstacleField {
    /// The field of a vehicle at (x, y, ψ) with `other_speed_mps` and `other_shape`, seen by
    /// the planning vehicle `me` (σ's as in the module doc).
    pub(crate) fn new(
        params: &ObstacleFieldParams,
        me: SelfView,
        x_m: f64,
        y_m: f64,
        heading_rad: f64,
        other_speed_mps: f64,
        other_shape: &VehicleShape,
    ) -> Self {
        let d = min_distances(params, me, other_speed_mps, other_shape);
        let x_scale = params.x_scale();
        let (sin_heading, cos_heading) = heading_rad.sin_cos();
        Self {
            x_m,
            y_m,
            cos_heading,
            sin_heading,
            heading_rad: cap_heading(heading_rad),
            lane_axes: [1.0, 0.0],
            sigma_front_m: d.front_m / x_scale,
            sigma_rear_m: d.rear_m / x_scale,
            sigma_lateral_m: params.sigma_lateral_m(),
            lateral_form: params.lateral_form,
            lateral_laplace_rate_per_m: params.lateral_laplace_rate_per_m(),
            amplitude: params.amplitude,
            heading_form: params.heading_form,
        }
    }

    /// The same field with its heading taken relative to a lane heading `lane_heading_rad` at
    /// the obstacle (Eq. 4 on a road of lanes): the correlation form is then written in the
    /// lane's axes, so a rotated copy of the road gives the same field. A lane along +x
    /// (heading 0) leaves the field as it is.
    pub(crate) fn in_lane_frame(self, lane_heading_rad: f64) -> Self {
        if lane_heading_rad == 0.0 {
            return self;
        }
        let (s, c) = lane_heading_rad.sin_cos();
        let world = self.sin_heading.atan2(self.cos_heading);
        Self {
            heading_rad: cap_heading(world - lane_heading_rad),
            lane_axes: [c, s],
            ..self
        }
    }

    /// The same field with its front half shrunk to the contact distance (l + l_o)/2: only the
    /// vehicle behind keeps the speed-dependent gap (the follower is responsible for it, as in
    /// RSS). Used by the interaction term of Eq. 10 when `interaction_rear_only` is set.
    pub(crate) fn rear_only(&self, contact_m: f64, x_scale: f64) -> Self {
        Self {
            sigma_front_m: contact_m / x_scale,
            ..*self
        }
    }

    /// The same field shrunk to the contact distance on both sides: what a leader sees of the
    /// vehicle behind it when the roles are fixed from the order now (the follower keeps the
    /// gap, however their predicted positions develop).
    pub(crate) fn contact_only(&self, contact_m: f64, x_scale: f64) -> Self {
        Self {
            sigma_front_m: contact_m / x_scale,
            sigma_rear_m: contact_m / x_scale,
            ..*self
        }
    }

    /// The field with `role` applied ([`Role::Full`] leaves it as it is).
    pub(crate) fn with_role(&self, role: Role, contact_m: f64, x_scale: f64) -> Self {
        match role {
            Role::Full => *self,
            Role::RearOnly => self.rear_only(contact_m, x_scale),
            Role::ContactOnly => self.contact_only(contact_m, x_scale),
        }
    }

    /// The same field moved to another centre and heading (same σ's).
    pub(crate) fn moved_to(&self, x_m: f64, y_m: f64, cos_heading: f64, sin_heading: f64) -> Self {
        Self {
            x_m,
            y_m,
            cos_heading,
            sin_heading,
            heading_rad: cap_heading(
                sin_heading.atan2(cos_heading) - self.lane_axes[1].atan2(self.lane_axes[0]),
            ),
            ..*self
        }
    }

    /// The side of the field a point is on.
    pub(crate) fn side(&self, x_m: f64, y_m: f64) -> Side {
        let dx = x_m - self.x_m;
        let along = match self.heading_form {
            HeadingForm::Rotation => self.cos_heading * dx + self.sin_heading * (y_m - self.y_m),
            HeadingForm::PaperCorrelation => {
                self.lane_axes[0] * dx + self.lane_axes[1] * (y_m - self.y_m)
            }
        };
        Side::of_along(along)
    }

    /// σ_x of `side` (m).
    #[inline]
    fn sigma_x_m(&self, side: Side) -> f64 {
        match side {
            Side::Front => self.sigma_front_m,
            Side::Rear => self.sigma_rear_m,
        }
    }

    /// The exponent q (U = A·exp(−q)) and ∂q/∂x, ∂q/∂y and ∂q/∂σ_x of the point's side.
    ///
    /// Inlined so that a caller that needs only q (or only q and ∇q) does not pay for the
    /// divisions of the rest. The side is read off the along-coordinate computed here, the
    /// same number [`side`](Self::side) computes.
    #[inline(always)]
    fn exponent_and_derivatives(&self, x_m: f64, y_m: f64) -> (f64, [f64; 2], f64) {
        let dx = x_m - self.x_m;
        let dy = y_m - self.y_m;
        let sy = self.sigma_lateral_m;
        match self.heading_form {
            HeadingForm::Rotation => {
                let ux = self.cos_heading * dx + self.sin_heading * dy;
                let sx = self.sigma_x_m(Side::of_along(ux));
                let uy = -self.sin_heading * dx + self.cos_heading * dy;
                // The lateral half: u_y²/σ_y², or k·|u_y| as printed (LateralForm).
                let (lateral, qy) = match self.lateral_form {
                    LateralForm::FixedDistance => (uy * uy / (sy * sy), uy / (sy * sy)),
                    LateralForm::PrintedLaplace => {
                        let k = self.lateral_laplace_rate_per_m;
                        (k * uy.abs(), 0.5 * k * sign(uy))
                    }
                };
                let q = 0.5 * (ux * ux / (sx * sx) + lateral);
                // dq/du = (u_x/σ_x², ∂/∂u_y); du/dp = R(ψ)ᵀ.
                let qx = ux / (sx * sx);
                let grad = [
                    qx * self.cos_heading - qy * self.sin_heading,
                    qx * self.sin_heading + qy * self.cos_heading,
                ];
                let d_sigma = -ux * ux / (sx * sx * sx);
                (q, grad, d_sigma)
            }
            HeadingForm::PaperCorrelation => {
                // In the lane's axes (identity on a road along +x).
                let [lc, ls] = self.lane_axes;
                let (dx, dy) = (lc * dx + ls * dy, -ls * dx + lc * dy);
                let sx = self.sigma_x_m(Side::of_along(dx));
                let psi = self.heading_rad;
                let c1 = 1.0 - psi * psi;
                match self.lateral_form {
                    LateralForm::FixedDistance => {
                        let (a, b, c) = (1.0 / (sx * sx), 1.0 / (sy * sy), psi / (sx * sy));
                        let q = 0.5 * c1 * (a * dx * dx + b * dy * dy - 2.0 * c * dx * dy);
                        let g = [c1 * (a * dx - c * dy), c1 * (b * dy - c * dx)];
                        let grad = [lc * g[0] - ls * g[1], ls * g[0] + lc * g[1]];
                        // ∂a/∂σ_x = −2/σ_x³, ∂c/∂σ_x = −c/σ_x.
                        let d_sigma =
                            0.5 * c1 * (-2.0 * dx * dx / (sx * sx * sx) + 2.0 * c * dx * dy / sx);
                        (q, grad, d_sigma)
                    }
                    LateralForm::PrintedLaplace => {
                        // σ_y = |dy|/k unsquared: dy²/σ_y = k|dy|, and
                        // 2ψ dx dy/(σ_x σ_y) = 2ψ k dx sgn(dy)/σ_x.
                        let k = self.lateral_laplace_rate_per_m;
                        let a = 1.0 / (sx * sx);
                        let cross = psi * k * sign(dy) / sx;
                        let q = 0.5 * c1 * (a * dx * dx + k * dy.abs() - 2.0 * cross * dx);
                        let g = [c1 * (a * dx - cross), 0.5 * c1 * k * sign(dy)];
                        let grad = [lc * g[0] - ls * g[1], ls * g[0] + lc * g[1]];
                        let d_sigma =
                            0.5 * c1 * (-2.0 * dx * dx / (sx * sx * sx) + 2.0 * cross * dx / sx);
                        (q, grad, d_sigma)
                    }
                }
            }
        }
    }

    /// The exponent q with U = A·exp(−q) (q ≥ 0, except in the printed Laplace form with the
    /// correlation form, where C2 can make it negative near the centre: U > A there).
    #[inline]
    pub(crate) fn exponent(&self, x_m: f64, y_m: f64) -> f64 {
        self.exponent_and_derivatives(x_m, y_m).0
    }

    /// U_OB at (x, y), Eq. 4.
    #[inline]
    pub(crate) fn value(&self, x_m: f64, y_m: f64) -> f64 {
        self.amplitude * (-self.exponent(x_m, y_m)).exp()
    }

    /// U_OB and its gradient with respect to the evaluated point (x, y).
    #[inline]
    pub(crate) fn value_and_gradient(&self, x_m: f64, y_m: f64) -> (f64, [f64; 2]) {
        let (q, dq, _) = self.exponent_and_derivatives(x_m, y_m);
        let u = self.amplitude * (-q).exp();
        (u, [-u * dq[0], -u * dq[1]])
    }

    /// U_OB, the side, and ∂U/∂σ_x of that side at a fixed point (the paper's reading of
    /// U_SLP, where speed enters only through D_min).
    pub(crate) fn value_and_sigma_derivative(&self, x_m: f64, y_m: f64) -> (f64, Side, f64) {
        let (q, _, dq_dsigma) = self.exponent_and_derivatives(x_m, y_m);
        let u = self.amplitude * (-q).exp();
        (u, self.side(x_m, y_m), -u * dq_dsigma)
    }

    /// ∇U_OB at (x, y).
    pub(crate) fn gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        self.value_and_gradient(x_m, y_m).1
    }
}

/// The sign of `v`, 0 at 0 (the derivative of |v| where it has one, and the middle of its
/// subgradient at 0).
fn sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

fn cap_heading(heading_rad: f64) -> f64 {
    mergesim_types::angle::wrap_angle_rad(heading_rad)
        .clamp(-MAX_CORRELATION_HEADING_RAD, MAX_CORRELATION_HEADING_RAD)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::PlannerParams;

    fn me(speed_mps: f64) -> SelfView {
        SelfView {
            speed_mps,
            shape: VehicleShape::default(),
        }
    }

    /// Both heading forms, each with both lateral forms.
    fn forms() -> [ObstacleFieldParams; 4] {
        let rotation = PlannerParams::default().path_field();
        let paper = ObstacleFieldParams {
            heading_form: HeadingForm::PaperCorrelation,
            min_distance_by_side: false,
            min_distance_length: MinDistanceLength::Wheelbase,
            time_gap_s: 0.0,
            ..rotation
        };
        let laplace = |p: ObstacleFieldParams| ObstacleFieldParams {
            lateral_form: LateralForm::PrintedLaplace,
            ..p
        };
        [rotation, paper, laplace(rotation), laplace(paper)]
    }

    #[test]
    fn gradient_matches_central_differences_in_both_forms() {
        for params in forms() {
            let field = ObstacleField::new(
                &params,
                me(20.0),
                30.0,
                5.0,
                0.4,
                15.0,
                &VehicleShape::default(),
            );
            let h = 1e-6;
            for (x, y) in [
                (25.0, 4.0),
                (36.0, 6.5),
                (30.5, 3.0),
                (10.0, 5.0),
                (45.0, 9.0),
            ] {
                // The printed C2 flips sign with Y − Y_o: no derivative across Y = Y_o.
                if params.lateral_form == LateralForm::PrintedLaplace && y == 5.0 {
                    continue;
                }
                let g = field.gradient(x, y);
                let fx = (field.value(x + h, y) - field.value(x - h, y)) / (2.0 * h);
                let fy = (field.value(x, y + h) - field.value(x, y - h)) / (2.0 * h);
                assert!((g[0] - fx).abs() < 1e-7, "({x},{y}): {} vs {fx}", g[0]);
                assert!((g[1] - fy).abs() < 1e-7, "({x},{y}): {} vs {fy}", g[1]);
            }
        }
    }

    #[test]
    fn sigma_derivative_matches_central_differences_in_both_forms() {
        for params in forms() {
            let field = ObstacleField::new(
                &params,
                me(20.0),
                0.0,
                0.0,
                0.2,
                15.0,
                &VehicleShape::default(),
            );
            let h = 1e-6;
            for (x, y) in [(-8.0, 0.5), (6.0, -0.4), (-20.0, 1.0)] {
                let (_, side, du) = field.value_and_sigma_derivative(x, y);
                let shifted = |d: f64| {
                    let mut f = field;
                    match side {
                        Side::Front => f.sigma_front_m += d,
                        Side::Rear => f.sigma_rear_m += d,
                    }
                    f.value(x, y)
                };
                let fd = (shifted(h) - shifted(-h)) / (2.0 * h);
                assert!((du - fd).abs() < 1e-7, "({x},{y}): {du} vs {fd}");
            }
        }
    }

    #[test]
    fn printed_laplace_lateral_term_is_k_times_the_offset() {
        let params = ObstacleFieldParams {
            lateral_form: LateralForm::PrintedLaplace,
            ..PlannerParams::default().path_field()
        };
        let k = (-2.0 * (params.epsilon / params.amplitude).ln()).sqrt();
        for heading_form in [HeadingForm::Rotation, HeadingForm::PaperCorrelation] {
            let params = ObstacleFieldParams {
                heading_form,
                ..params
            };
            let shape = VehicleShape::default();
            let field = ObstacleField::new(&params, me(20.0), 0.0, 0.0, 0.0, 15.0, &shape);
            for y in [-3.5, 0.5, 1.0, 3.5] {
                let expected = params.amplitude * (-0.5 * k * f64::abs(y)).exp();
                assert!(
                    (field.value(0.0, y) - expected).abs() < 1e-15,
                    "{heading_form:?} {y}"
                );
            }
            // Not the fixed-distance Gaussian: at d_lat it is not ε.
            let at_d = field.value(0.0, params.lateral_safety_m);
            assert!((at_d - params.epsilon).abs() > 1e-4, "{at_d}");
        }
        // Neither parameter set uses it.
        for set in [crate::ParameterSet::Paper, crate::ParameterSet::Mergesim] {
            assert_eq!(
                set.planner_params().obstacle_lateral_form,
                LateralForm::FixedDistance
            );
        }
    }

    #[test]
    fn field_levels_match_the_safety_distances() {
        let params = PlannerParams {
            obstacle_time_gap_s: 2.0,
            ..PlannerParams::default()
        }
        .path_field();
        let shape = VehicleShape::default();
        let field = ObstacleField::new(&params, me(20.0), 0.0, 0.0, 0.0, 15.0, &shape);
        // Lateral: ε at d_lat.
        let at_lateral = field.value(0.0, params.lateral_safety_m);
        assert!((at_lateral - params.epsilon).abs() < 1e-12);
        // Behind: the planning vehicle (20 m/s) follows the obstacle (15 m/s).
        let a = shape.max_brake_decel_mps2;
        let d_rear = shape.length_m + 20.0 * 2.0 + (20.0 * 20.0 - 15.0 * 15.0) / (2.0 * a);
        let behind = field.value(-d_rear, 0.0);
        let expected = params.amplitude * params.fraction_at_min_distance;
        assert!((behind - expected).abs() < 1e-12, "{behind} vs {expected}");
    }

    #[test]
    fn min_distance_is_clamped_to_the_length_term() {
        // A much faster leader: the braking terms would make D_min negative.
        let d = min_distance_m(5.0, 7.0, 1.0, 30.0, 7.0, 1.0, 4.5, 0.0);
        assert_eq!(d, 4.5);
        // The paper's formula when positive: v²/2a − v_o²/2a_o + l.
        let d = min_distance_m(20.0, 7.0, 1.0, 15.0, 7.0, 1.0, 4.5, 0.0);
        assert!((d - (4.5 + (400.0 - 225.0) / 14.0)).abs() < 1e-12);
    }

    #[test]
    fn paper_min_distance_has_no_roles_and_uses_wheelbases() {
        let paper = forms()[1];
        let shape = VehicleShape::default();
        // The slower vehicle's view of a faster one: as printed, it is the follower on both
        // sides, so D_min is clamped to the wheelbase term on both.
        let d = min_distances(&paper, me(15.0), 20.0, &shape);
        assert_eq!(d.front_m, d.rear_m);
        assert_eq!(d.rear_m, shape.wheelbase_m);
        assert_eq!(d.rear_dv_s, 0.0);
        // The faster vehicle's view: v²/2a − v_o²/2a + l_fr, growing with its speed.
        let d = min_distances(&paper, me(20.0), 15.0, &shape);
        let a = shape.max_brake_decel_mps2;
        assert!((d.rear_m - (shape.wheelbase_m + 175.0 / (2.0 * a))).abs() < 1e-12);
        assert!((d.rear_dv_s - 20.0 / a).abs() < 1e-12);
        // Roles by side (mergesim): ahead of the slower obstacle, it follows me.
        let ours = forms()[0];
        let d = min_distances(&ours, me(20.0), 15.0, &shape);
        assert!(d.front_m < d.rear_m);
    }

    #[test]
    fn rotation_aligns_the_ellipse_with_the_heading() {
        let params = forms()[0];
        let shape = VehicleShape::default();
        let psi: f64 = 0.3;
        let field = ObstacleField::new(&params, me(15.0), 0.0, 0.0, psi, 15.0, &shape);
        let straight = ObstacleField::new(&params, me(15.0), 0.0, 0.0, 0.0, 15.0, &shape);
        // A point at distance r along the heading sees the same field as the unrotated one at (r, 0).
        let r = 4.0;
        let rotated = field.value(r * psi.cos(), r * psi.sin());
        assert!((rotated - straight.value(r, 0.0)).abs() < 1e-12);
    }

    #[test]
    fn correlation_form_tilts_far_less_than_the_heading() {
        // The paper's C1/C2 form: along the heading the field does not stay at its on-axis
        // value; the ellipse's major axis tilts by ≈ ψ σ_y/σ_x, a small fraction of ψ.
        let params = forms()[1];
        let shape = VehicleShape::default();
        let psi: f64 = 0.1;
        let field = ObstacleField::new(&params, me(20.0), 0.0, 0.0, psi, 15.0, &shape);
        let r = 2.0 * field.sigma_rear_m;
        // Lateral position of the ridge (largest U) at x = −r: for a Gaussian with correlation
        // ρ = ψ, y* = ρ σ_y/σ_x · x.
        let ridge_y = (-2000..=2000)
            .map(|k| k as f64 * 1e-4)
            .max_by(|a, b| field.value(-r, *a).total_cmp(&field.value(-r, *b)))
            .unwrap();
        let expected = psi * field.sigma_lateral_m / field.sigma_rear_m * (-r);
        assert!((ridge_y - expected).abs() < 2e-4, "{ridge_y} vs {expected}");
        assert!(
            ridge_y.abs() < 0.2 * (psi * r).abs(),
            "a rotation would put it at −ψ r"
        );
        // At ψ = 0 both forms agree.
        let rotation = ObstacleField::new(&forms()[0], me(15.0), 0.0, 0.0, 0.0, 15.0, &shape);
        let paper = ObstacleField {
            heading_form: HeadingForm::PaperCorrelation,
            ..rotation
        };
        for (x, y) in [(3.0, 0.4), (-7.0, -0.2)] {
            assert!((rotation.value(x, y) - paper.value(x, y)).abs() < 1e-15);
        }
    }
}
