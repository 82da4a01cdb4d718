//! CommonRoad's single-track model "st": a bicycle with linear tyres and longitudinal load
//! transfer. Reference point: the centre of mass.
//!
//! State (CommonRoad's order): x = [s_x, s_y, δ, v, ψ, ψ̇, β] — position of the centre of mass
//! (m), front-wheel steering angle (rad), speed of the centre of mass (m/s), yaw angle (rad),
//! yaw rate (rad/s), sideslip angle at the centre of mass (rad). Input u = [v_δ, a], passed
//! through [`super::constraints`] (giving v_δ', a').
//!
//! **Dynamic form**, used when |v| ≥ 0.1 m/s. Both axles have the normalised cornering
//! stiffness C_S = −p_ky1 / p_dy1 (1/rad) and the friction coefficient μ = p_dy1 of the tyre
//! table; the axle loads, per unit mass and times L, are
//! N_f = g·l_r − a'·h_s and N_r = g·l_f + a'·h_s (g = 9.81 m/s², h_s the sprung mass's CoG
//! height), so an axle's lateral force is μ·C_S·(m N / L)·(−α) with the linear slip angles
//! α_f = β + l_f ψ̇ / v − δ and α_r = β − l_r ψ̇ / v. Written out:
//! ```text
//! ṡ_x = v cos(ψ + β)
//! ṡ_y = v sin(ψ + β)
//! δ̇   = v_δ'
//! v̇   = a'
//! ψ̈   = μ m / (I_z L) · [ −(l_f² C_S N_f + l_r² C_S N_r) ψ̇ / v
//!                         + (l_r C_S N_r − l_f C_S N_f) β
//!                         + l_f C_S N_f δ ]
//! β̇   = [ μ / (v² L) · (l_r C_S N_r − l_f C_S N_f) − 1 ] ψ̇
//!       − μ / (v L) · (C_S N_r + C_S N_f) β
//!       + μ / (v L) · C_S N_f δ
//! ```
//! **Kinematic form**, used when |v| < 0.1 m/s (the dynamic form divides by v): positions, δ̇,
//! v̇ and ψ̇ are those of the kinematic model about the centre of mass
//! ([`super::ks::ks_cog_derivative`], sideslip β_k = atan(tan δ · l_r / L)), and the last two
//! rates are
//! ```text
//! β̇ = l_r v_δ' / ( L cos²δ · (1 + (tan²δ · l_r / L)²) )
//! ψ̈ = ( a' cos β tan δ − v sin β · β̇ · tan δ + v cos β · v_δ' / cos²δ ) / L
//! ```
//! with β the state's sideslip. These are as the reference package writes them: the exact time
//! derivative of β_k has (tan δ · l_r / L)² in the denominator, not (tan²δ · l_r / L)²; for the
//! BMW 320i the reference's β̇ is larger than the exact one by 0.08 % at δ = 0.05 rad, 0.3 % at
//! 0.1 rad, 1.2 % at 0.2 rad and 6.2 % at 0.5 rad.
//!
//! **Validity.** The tyres are linear and never saturate: the lateral force grows with the slip
//! angle without bound, so the model is a good approximation only while the lateral
//! acceleration stays well below the friction limit μ·g. Textbooks on the single-track model
//! (e.g. Schramm, Hiller & Bardini, *Vehicle Dynamics: Modeling and Simulation*, 2014, ch. 10;
//! Mitschke & Wallentowitz, *Dynamik der Kraftfahrzeuge*) put the end of the tyres' linear range
//! on a dry road at about 0.4 g. With CommonRoad's own tyre table the same limit follows from
//! the Magic-Formula curve: where the linear model asks an axle for 0.4·μ of its load, the
//! Magic-Formula tyre at the same slip angle gives 5.2 % less (3.0 % at 0.3·μ, 7.8 % at 0.5·μ,
//! 17 % at 0.8·μ; `linear_tyre_error_at_fractions_of_mu` below). So: **|a_y| ≲ 0.4·μ·g
//! ≈ 4 m/s²** (μ = 1.0489), at a speed above the switch to the kinematic form. Beyond it the st
//! model overestimates the lateral force and cannot spin out; use std there.

use serde::{Deserialize, Serialize};

use super::constraints::{CommonRoadInput, constrain_input};
use super::integrate::{CommonRoadState, step_rk4};
use super::ks::{KsState, ks_cog_derivative};
use super::params::CommonRoadVehicleParams;

/// Gravitational acceleration of CommonRoad's st and std models (m/s²).
pub const COMMONROAD_GRAVITY_MPS2: f64 = 9.81;

/// Speed below which the st model switches to its kinematic form (m/s), compared with |v|.
pub const ST_KINEMATIC_BELOW_MPS: f64 = 0.1;

/// State of the st model (reference point: centre of mass). As a derivative, each field holds
/// the rate of that component (unit per second).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StState {
    /// x₁ = s_x: x position of the centre of mass (m).
    pub x_m: f64,
    /// x₂ = s_y: y position of the centre of mass (m).
    pub y_m: f64,
    /// x₃ = δ: front-wheel steering angle (rad).
    pub steering_angle_rad: f64,
    /// x₄ = v: speed of the centre of mass (m/s).
    pub speed_mps: f64,
    /// x₅ = ψ: yaw angle (rad), not wrapped.
    pub yaw_rad: f64,
    /// x₆ = ψ̇: yaw rate (rad/s).
    pub yaw_rate_radps: f64,
    /// x₇ = β: sideslip angle at the centre of mass (rad).
    pub slip_angle_rad: f64,
}

impl CommonRoadState<7> for StState {
    fn to_array(&self) -> [f64; 7] {
        [
            self.x_m,
            self.y_m,
            self.steering_angle_rad,
            self.speed_mps,
            self.yaw_rad,
            self.yaw_rate_radps,
            self.slip_angle_rad,
        ]
    }

    fn from_array(v: [f64; 7]) -> Self {
        Self {
            x_m: v[0],
            y_m: v[1],
            steering_angle_rad: v[2],
            speed_mps: v[3],
            yaw_rad: v[4],
            yaw_rate_radps: v[5],
            slip_angle_rad: v[6],
        }
    }
}

/// The rates of the sideslip and of the yaw rate, (β̇, ψ̈), that the st and std models use
/// at low speed (module doc, kinematic form); `u` already constrained.
pub(super) fn kinematic_slip_and_yaw_accel(
    steering_angle_rad: f64,
    speed_mps: f64,
    slip_angle_rad: f64,
    u: &CommonRoadInput,
    p: &CommonRoadVehicleParams,
) -> (f64, f64) {
    let wheelbase_m = p.wheelbase_m();
    let tan_delta = steering_angle_rad.tan();
    let cos2_delta = steering_angle_rad.cos().powi(2);
    let q = tan_delta.powi(2) * p.cog_to_rear_axle_m / wheelbase_m;
    let d_beta = p.cog_to_rear_axle_m * u.steering_velocity_radps
        / (wheelbase_m * cos2_delta * (1.0 + q.powi(2)));
    let dd_psi = 1.0 / wheelbase_m
        * (u.acceleration_mps2 * slip_angle_rad.cos() * tan_delta
            - speed_mps * slip_angle_rad.sin() * d_beta * tan_delta
            + speed_mps * slip_angle_rad.cos() * u.steering_velocity_radps / cos2_delta);
    (d_beta, dd_psi)
}

/// The st model's derivative ẋ = f(x, u, p) (see the module doc); `input` is constrained here.
pub fn st_derivative(x: &StState, input: &CommonRoadInput, p: &CommonRoadVehicleParams) -> StState {
    let u = constrain_input(
        x.steering_angle_rad,
        x.speed_mps,
        input,
        &p.steering,
        &p.longitudinal,
    );
    let v = x.speed_mps;
    if v.abs() < ST_KINEMATIC_BELOW_MPS {
        let ks = ks_cog_derivative(
            &KsState {
                x_m: x.x_m,
                y_m: x.y_m,
                steering_angle_rad: x.steering_angle_rad,
                speed_mps: v,
                yaw_rad: x.yaw_rad,
            },
            &u,
            p,
        );
        let (d_beta, dd_psi) =
            kinematic_slip_and_yaw_accel(x.steering_angle_rad, v, x.slip_angle_rad, &u, p);
        return StState {
            x_m: ks.x_m,
            y_m: ks.y_m,
            steering_angle_rad: ks.steering_angle_rad,
            speed_mps: ks.speed_mps,
            yaw_rad: ks.yaw_rad,
            yaw_rate_radps: dd_psi,
            slip_angle_rad: d_beta,
        };
    }
    let g = COMMONROAD_GRAVITY_MPS2;
    let mu = p.st_friction_coefficient();
    let c_sf = p.st_cornering_stiffness_per_rad();
    let c_sr = c_sf;
    let (lf, lr) = (p.cog_to_front_axle_m, p.cog_to_rear_axle_m);
    let (h, m, iz) = (p.sprung_cog_height_m, p.mass_kg, p.yaw_inertia_kgm2);
    let a = u.acceleration_mps2;
    let (delta, psi_dot, beta) = (x.steering_angle_rad, x.yaw_rate_radps, x.slip_angle_rad);
    // Axle loads per unit mass, times L; the products are grouped as the reference groups them,
    // so that the two round alike.
    let n_f = g * lr - a * h;
    let n_r = g * lf + a * h;
    let wheelbase_m = lr + lf;
    let dd_psi = -mu * m / (v * iz * wheelbase_m)
        * (lf.powi(2) * c_sf * n_f + lr.powi(2) * c_sr * n_r)
        * psi_dot
        + mu * m / (iz * wheelbase_m) * (lr * c_sr * n_r - lf * c_sf * n_f) * beta
        + mu * m / (iz * wheelbase_m) * lf * c_sf * n_f * delta;
    let d_beta = (mu / (v.powi(2) * wheelbase_m) * (c_sr * n_r * lr - c_sf * n_f * lf) - 1.0)
        * psi_dot
        - mu / (v * wheelbase_m) * (c_sr * n_r + c_sf * n_f) * beta
        + mu / (v * wheelbase_m) * (c_sf * n_f) * delta;
    StState {
        x_m: v * (beta + x.yaw_rad).cos(),
        y_m: v * (beta + x.yaw_rad).sin(),
        steering_angle_rad: u.steering_velocity_radps,
        speed_mps: a,
        yaw_rad: psi_dot,
        yaw_rate_radps: dd_psi,
        slip_angle_rad: d_beta,
    }
}

/// One fixed RK4 step of `dt_s` (s) of the st model with the input held.
pub fn st_step_rk4(
    x: &StState,
    input: &CommonRoadInput,
    p: &CommonRoadVehicleParams,
    dt_s: f64,
) -> StState {
    step_rk4(|s: &StState| st_derivative(s, input, p), x, dt_s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commonroad_models::tire::pure_lateral_force_n;
    use crate::single_track::LinearSingleTrack;

    /// Holds δ at `v` until the yaw rate settles.
    fn settle(v: f64, delta: f64, p: &CommonRoadVehicleParams) -> StState {
        let mut x = StState {
            steering_angle_rad: delta,
            speed_mps: v,
            ..StState::default()
        };
        for _ in 0..20_000 {
            x = st_step_rk4(&x, &CommonRoadInput::default(), p, 1e-3);
        }
        x
    }

    /// The linear single-track model of `single_track.rs` with st's axle cornering stiffnesses
    /// μ·C_S·(static axle load): at a' = 0 the two models are the same ODE.
    fn linear(p: &CommonRoadVehicleParams) -> LinearSingleTrack {
        let g = COMMONROAD_GRAVITY_MPS2;
        let l = p.wheelbase_m();
        let k = p.st_friction_coefficient() * p.st_cornering_stiffness_per_rad();
        LinearSingleTrack {
            mass_kg: p.mass_kg,
            yaw_inertia_kgm2: p.yaw_inertia_kgm2,
            lf_m: p.cog_to_front_axle_m,
            lr_m: p.cog_to_rear_axle_m,
            cornering_stiffness_front_npr: k * p.mass_kg * g * p.cog_to_rear_axle_m / l,
            cornering_stiffness_rear_npr: k * p.mass_kg * g * p.cog_to_front_axle_m / l,
        }
    }

    #[test]
    fn steady_state_matches_the_linear_single_track_formulas() {
        for p in [
            CommonRoadVehicleParams::ford_escort(),
            CommonRoadVehicleParams::bmw_320i(),
        ] {
            let lin = linear(&p);
            for (v, delta) in [(10.0, 0.01), (20.0, 0.02), (30.0, 0.005)] {
                let x = settle(v, delta, &p);
                let r = lin.steady_state_yaw_rate_radps(v, delta);
                let beta = lin.steady_state_sideslip_rad(v, delta);
                assert!((x.yaw_rate_radps - r).abs() < 1e-9 * r.abs(), "{v} {delta}");
                assert!((x.slip_angle_rad - beta).abs() < 1e-9 * beta.abs().max(1e-3));
            }
        }
        // Hand value: CommonRoad's tyre makes the BMW neutral (K_us = 0), so r = v δ / L.
        let p = CommonRoadVehicleParams::bmw_320i();
        let x = settle(20.0, 0.02, &p);
        assert!((x.yaw_rate_radps - 20.0 * 0.02 / 2.5789128).abs() < 1e-9);
    }

    #[test]
    fn low_speed_uses_the_kinematic_form() {
        let p = CommonRoadVehicleParams::default();
        let x = StState {
            steering_angle_rad: 0.1,
            speed_mps: 0.05,
            yaw_rate_radps: 3.0, // ignored by the kinematic form's ψ̇
            ..StState::default()
        };
        let u = CommonRoadInput {
            steering_velocity_radps: 0.2,
            acceleration_mps2: 1.0,
        };
        let f = st_derivative(&x, &u, &p);
        let ks = ks_cog_derivative(
            &KsState {
                x_m: 0.0,
                y_m: 0.0,
                steering_angle_rad: 0.1,
                speed_mps: 0.05,
                yaw_rad: 0.0,
            },
            &u,
            &p,
        );
        assert_eq!(f.yaw_rad, ks.yaw_rad);
        assert_eq!(f.x_m, ks.x_m);
        // β̇ at β = 0: l_r v_δ / (L cos²δ (1 + (tan²δ l_r/L)²)).
        let (lr, l) = (p.cog_to_rear_axle_m, p.wheelbase_m());
        let q = 0.1f64.tan().powi(2) * lr / l;
        let expected = lr * 0.2 / (l * 0.1f64.cos().powi(2) * (1.0 + q * q));
        assert!((f.slip_angle_rad - expected).abs() < 1e-15);
    }

    /// The figures of the module doc's validity paragraph.
    #[test]
    fn linear_tyre_error_at_fractions_of_mu() {
        let t = CommonRoadVehicleParams::default().tire;
        let fz_n = 4000.0;
        let k = -t.p_ky1; // linear force per unit load per rad
        let shortfall = |fraction: f64| {
            let alpha = fraction * t.p_dy1 / k;
            let (fy_n, _) = pure_lateral_force_n(alpha, fz_n, &t);
            1.0 - fy_n.abs() / (k * alpha * fz_n)
        };
        assert!((shortfall(0.3) - 0.030).abs() < 5e-4);
        assert!((shortfall(0.4) - 0.052).abs() < 5e-4);
        assert!((shortfall(0.5) - 0.078).abs() < 5e-4);
        assert!((shortfall(0.8) - 0.173).abs() < 5e-4);
    }
}
