//! CommonRoad's single-track drift model "std": the single-track model with Magic-Formula tyres
//! under combined slip and the spin of one wheel per axle, so it saturates, drifts and spins
//! out. Reference point: the centre of mass. (The file is `drift.rs` because a module named
//! `std` would shadow the standard library.)
//!
//! State (CommonRoad's order): x = [s_x, s_y, δ, v, ψ, ψ̇, β, ω_f, ω_r] — the st model's seven
//! states, then the front and rear wheel spin rates (rad/s). Input u = [v_δ, a], passed through
//! [`super::constraints`] (giving v_δ', a').
//!
//! **Dynamic part.** With v̂ = 0.1 m/s, the tyre slips are
//! ```text
//! α_f = atan((v sin β + l_f ψ̇) / (v cos β)) − δ,   α_r = atan((v sin β − l_r ψ̇) / (v cos β))
//!                                                    (both 0 when v ≤ v̂)
//! u_wf = max(0, v cos β cos δ + (v sin β + l_f ψ̇) sin δ),   u_wr = max(0, v cos β)
//! s_f = 1 − R_w ω_f / max(u_wf, v̂),                         s_r = 1 − R_w ω_r / max(u_wr, v̂)
//! ```
//! the axle loads F_zf = m (g l_r − a' h_s) / L, F_zr = m (g l_f + a' h_s) / L (g = 9.81 m/s²),
//! and the tyre forces F_xi, F_yi those of [`super::tire`] under combined slip. The acceleration
//! input becomes a torque: T_E = m R_w a' (engine) if a' > 0, else T_B = m R_w a' (brakes), split
//! to the front axle by the shares T_se, T_sb. Then
//! ```text
//! v̇_d  = ( −F_yf sin(δ − β) + F_yr sin β + F_xr cos β + F_xf cos(δ − β) ) / m
//! ψ̈_d  = ( F_yf cos δ · l_f − F_yr l_r + F_xf sin δ · l_f ) / I_z
//! β̇_d  = −ψ̇ + ( F_yf cos(δ − β) + F_yr cos β − F_xr sin β + F_xf sin(δ − β) ) / (m v)
//!                                                    (0 when v ≤ v̂)
//! ω̇_f,d = ( −R_w F_xf + T_sb T_B + T_se T_E ) / I_w             (0 when ω_f < 0)
//! ω̇_r,d = ( −R_w F_xr + (1 − T_sb) T_B + (1 − T_se) T_E ) / I_w  (0 when ω_r < 0)
//! ```
//! **Kinematic part**: ψ̇_k from [`super::ks::ks_cog_derivative`], β̇_k and ψ̈_k as in the st
//! model's kinematic form ([`super::st`]), and wheels that follow the ground within 0.02 s,
//! ω̇_i,k = (u_wi / R_w − max(0, ω_i)) / 0.02.
//!
//! **Blend.** Both are evaluated at every speed and mixed by w = ½ (tanh((v − 0.2) / 0.05) + 1)
//! (w → 1 above about 0.3 m/s, → 0 below about 0.1 m/s):
//! ```text
//! ṡ_x = v cos(ψ + β),   ṡ_y = v sin(ψ + β),   δ̇ = v_δ',
//! v̇ = w v̇_d + (1 − w) a',   ψ̇ = w ψ̇ + (1 − w) ψ̇_k,   ψ̈ = w ψ̈_d + (1 − w) ψ̈_k,
//! β̇ = w β̇_d + (1 − w) β̇_k,   ω̇_i = w ω̇_i,d + (1 − w) ω̇_i,k
//! ```
//! As in the reference, the slips use the wheel speeds as given, the kinematic wheel part uses
//! them clamped at 0. (The reference also writes the clamped speeds back into the state list it
//! is handed; this function is pure and leaves the state alone, and the reference script hands
//! the package a copy, so the two agree.)
//!
//! **Validity.** Up to and beyond the friction limit (saturation, drift, spin-out) on a flat
//! road, for the tyre table it is given (one friction coefficient, μ_x = 1.17, μ_y = 1.05); it
//! has no roll, no pitch dynamics (the load transfer is quasi-static) and one tyre per axle.
//! It is stiff (see [`super::integrate`] for step sizes).

use serde::{Deserialize, Serialize};

use super::constraints::{CommonRoadInput, constrain_input};
use super::integrate::{CommonRoadState, step_rk4};
use super::ks::{KsState, ks_cog_derivative};
use super::params::CommonRoadVehicleParams;
use super::st::{COMMONROAD_GRAVITY_MPS2, StState, kinematic_slip_and_yaw_accel};
use super::tire::{
    combined_lateral_force_n, combined_longitudinal_force_n, pure_lateral_force_n,
    pure_longitudinal_force_n,
};

/// Centre of the std model's blend between its kinematic and dynamic parts (m/s).
pub const STD_BLEND_CENTRE_MPS: f64 = 0.2;
/// Width of that blend (m/s): the weight is ½ (tanh((v − centre) / width) + 1).
pub const STD_BLEND_WIDTH_MPS: f64 = 0.05;
/// Speed v̂ at and below which the std model's slip angles and dynamic β̇ are 0, and the floor of
/// its slip-ratio denominators (m/s): half the blend centre.
pub const STD_SLIP_SPEED_FLOOR_MPS: f64 = 0.5 * STD_BLEND_CENTRE_MPS;
/// Time constant with which the kinematic part's wheels follow the ground speed (s).
pub const STD_KINEMATIC_WHEEL_TIME_CONSTANT_S: f64 = 0.02;

/// State of the std model (reference point: centre of mass). As a derivative, each field holds
/// the rate of that component (unit per second).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StdState {
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
    /// x₈ = ω_f: spin rate of the front wheel (rad/s).
    pub front_wheel_speed_radps: f64,
    /// x₉ = ω_r: spin rate of the rear wheel (rad/s).
    pub rear_wheel_speed_radps: f64,
}

impl StdState {
    /// CommonRoad's initial std state for a car rolling freely in st state `x`: the wheel spin
    /// rates match the ground speed at each wheel's centre along its heading,
    /// ω_f = v cos β cos δ / R_w and ω_r = v cos β / R_w.
    pub fn rolling(x: &StState, p: &CommonRoadVehicleParams) -> Self {
        let along_mps = x.speed_mps * x.slip_angle_rad.cos();
        Self {
            x_m: x.x_m,
            y_m: x.y_m,
            steering_angle_rad: x.steering_angle_rad,
            speed_mps: x.speed_mps,
            yaw_rad: x.yaw_rad,
            yaw_rate_radps: x.yaw_rate_radps,
            slip_angle_rad: x.slip_angle_rad,
            front_wheel_speed_radps: along_mps * x.steering_angle_rad.cos() / p.wheel_radius_m,
            rear_wheel_speed_radps: along_mps / p.wheel_radius_m,
        }
    }
}

impl CommonRoadState<9> for StdState {
    fn to_array(&self) -> [f64; 9] {
        [
            self.x_m,
            self.y_m,
            self.steering_angle_rad,
            self.speed_mps,
            self.yaw_rad,
            self.yaw_rate_radps,
            self.slip_angle_rad,
            self.front_wheel_speed_radps,
            self.rear_wheel_speed_radps,
        ]
    }

    fn from_array(v: [f64; 9]) -> Self {
        Self {
            x_m: v[0],
            y_m: v[1],
            steering_angle_rad: v[2],
            speed_mps: v[3],
            yaw_rad: v[4],
            yaw_rate_radps: v[5],
            slip_angle_rad: v[6],
            front_wheel_speed_radps: v[7],
            rear_wheel_speed_radps: v[8],
        }
    }
}

/// Weight w of the std model's dynamic part at speed `speed_mps` (module doc, "Blend").
pub fn std_dynamic_weight(speed_mps: f64) -> f64 {
    0.5 * (((speed_mps - STD_BLEND_CENTRE_MPS) / STD_BLEND_WIDTH_MPS).tanh() + 1.0)
}

/// The std model's derivative ẋ = f(x, u, p) (see the module doc); `input` is constrained here.
pub fn std_derivative(
    x: &StdState,
    input: &CommonRoadInput,
    p: &CommonRoadVehicleParams,
) -> StdState {
    let g = COMMONROAD_GRAVITY_MPS2;
    let (lf, lr) = (p.cog_to_front_axle_m, p.cog_to_rear_axle_m);
    let wheelbase_m = lf + lr;
    let (m, iz, rw) = (p.mass_kg, p.yaw_inertia_kgm2, p.wheel_radius_m);
    let v_hat = STD_SLIP_SPEED_FLOOR_MPS;
    let u = constrain_input(
        x.steering_angle_rad,
        x.speed_mps,
        input,
        &p.steering,
        &p.longitudinal,
    );
    let a = u.acceleration_mps2;
    let (delta, v, psi_dot, beta) = (
        x.steering_angle_rad,
        x.speed_mps,
        x.yaw_rate_radps,
        x.slip_angle_rad,
    );
    let (omega_f, omega_r) = (x.front_wheel_speed_radps, x.rear_wheel_speed_radps);

    // Slip angles, loads, wheel ground speeds and slip ratios.
    let moving = v > v_hat;
    let (alpha_f, alpha_r) = if moving {
        let along = v * beta.cos();
        (
            ((v * beta.sin() + psi_dot * lf) / along).atan() - delta,
            ((v * beta.sin() - psi_dot * lr) / along).atan(),
        )
    } else {
        (0.0, 0.0)
    };
    let fz_f = m * (-a * p.sprung_cog_height_m + g * lr) / wheelbase_m;
    let fz_r = m * (a * p.sprung_cog_height_m + g * lf) / wheelbase_m;
    let u_wf =
        (v * beta.cos() * delta.cos() + (v * beta.sin() + lf * psi_dot) * delta.sin()).max(0.0);
    let u_wr = (v * beta.cos()).max(0.0);
    let s_f = 1.0 - rw * omega_f / u_wf.max(v_hat);
    let s_r = 1.0 - rw * omega_r / u_wr.max(v_hat);

    // Tyre forces under combined slip.
    let t = &p.tire;
    let fx0_f = pure_longitudinal_force_n(s_f, fz_f, t);
    let fx0_r = pure_longitudinal_force_n(s_r, fz_r, t);
    let (fy0_f, mu_yf) = pure_lateral_force_n(alpha_f, fz_f, t);
    let (fy0_r, mu_yr) = pure_lateral_force_n(alpha_r, fz_r, t);
    let fx_f = combined_longitudinal_force_n(s_f, alpha_f, fx0_f, t);
    let fx_r = combined_longitudinal_force_n(s_r, alpha_r, fx0_r, t);
    let fy_f = combined_lateral_force_n(s_f, alpha_f, mu_yf, fz_f, fy0_f, t);
    let fy_r = combined_lateral_force_n(s_r, alpha_r, mu_yr, fz_r, fy0_r, t);

    // Engine or brake torque from the acceleration input.
    let (brake_nm, engine_nm) = if a > 0.0 {
        (0.0, m * rw * a)
    } else {
        (m * rw * a, 0.0)
    };

    // Dynamic part.
    // Grouped as the reference groups them (1/m · (…)), so that the two round alike.
    let d_v = 1.0 / m
        * (-fy_f * (delta - beta).sin()
            + fy_r * beta.sin()
            + fx_r * beta.cos()
            + fx_f * (delta - beta).cos());
    let dd_psi = 1.0 / iz * (fy_f * delta.cos() * lf - fy_r * lr + fx_f * delta.sin() * lf);
    let d_beta = if moving {
        -psi_dot
            + 1.0 / (m * v)
                * (fy_f * (delta - beta).cos() + fy_r * beta.cos() - fx_r * beta.sin()
                    + fx_f * (delta - beta).sin())
    } else {
        0.0
    };
    let (sb, se, iw) = (
        p.brake_torque_front_share,
        p.drive_torque_front_share,
        p.wheel_inertia_kgm2,
    );
    let d_omega_f = if omega_f >= 0.0 {
        1.0 / iw * (-rw * fx_f + sb * brake_nm + se * engine_nm)
    } else {
        0.0
    };
    let d_omega_r = if omega_r >= 0.0 {
        1.0 / iw * (-rw * fx_r + (1.0 - sb) * brake_nm + (1.0 - se) * engine_nm)
    } else {
        0.0
    };

    // Kinematic part (wheel speeds clamped at 0).
    let ks = ks_cog_derivative(
        &KsState {
            x_m: x.x_m,
            y_m: x.y_m,
            steering_angle_rad: delta,
            speed_mps: v,
            yaw_rad: x.yaw_rad,
        },
        &u,
        p,
    );
    let (d_beta_ks, dd_psi_ks) = kinematic_slip_and_yaw_accel(delta, v, beta, &u, p);
    let tau = STD_KINEMATIC_WHEEL_TIME_CONSTANT_S;
    let d_omega_f_ks = (1.0 / tau) * (u_wf / rw - omega_f.max(0.0));
    let d_omega_r_ks = (1.0 / tau) * (u_wr / rw - omega_r.max(0.0));

    let w = std_dynamic_weight(v);
    let w_ks = 1.0 - w;
    StdState {
        x_m: v * (beta + x.yaw_rad).cos(),
        y_m: v * (beta + x.yaw_rad).sin(),
        steering_angle_rad: u.steering_velocity_radps,
        speed_mps: w * d_v + w_ks * ks.speed_mps,
        yaw_rad: w * psi_dot + w_ks * ks.yaw_rad,
        yaw_rate_radps: w * dd_psi + w_ks * dd_psi_ks,
        slip_angle_rad: w * d_beta + w_ks * d_beta_ks,
        front_wheel_speed_radps: w * d_omega_f + w_ks * d_omega_f_ks,
        rear_wheel_speed_radps: w * d_omega_r + w_ks * d_omega_r_ks,
    }
}

/// One fixed RK4 step of `dt_s` (s) of the std model with the input held.
pub fn std_step_rk4(
    x: &StdState,
    input: &CommonRoadInput,
    p: &CommonRoadVehicleParams,
    dt_s: f64,
) -> StdState {
    step_rk4(|s: &StdState| std_derivative(s, input, p), x, dt_s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blend_weight() {
        assert_eq!(std_dynamic_weight(0.2), 0.5);
        assert!(std_dynamic_weight(0.4) > 0.9996);
        assert!(std_dynamic_weight(0.05) < 0.0025);
    }

    #[test]
    fn free_rolling_straight_keeps_its_heading_and_wheel_match() {
        let p = CommonRoadVehicleParams::default();
        let x = StdState::rolling(
            &StState {
                speed_mps: 15.0,
                ..StState::default()
            },
            &p,
        );
        assert_eq!(x.rear_wheel_speed_radps, 15.0 / 0.344);
        let f = std_derivative(&x, &CommonRoadInput::default(), &p);
        // No steering, no slip angle: no lateral motion (the lateral forces at α = 0 come only
        // from the slip-induced side force, ∝ sin(r_vy5 atan(r_vy6 s)), and s = 0 here).
        assert_eq!(f.y_m, 0.0);
        assert_eq!(f.slip_angle_rad, 0.0);
        assert_eq!(f.yaw_rate_radps, 0.0);
        // The tyres' shifts make the free-rolling car decelerate slightly (drag of the shift
        // inside the sine, see `tire`), never accelerate it hard.
        assert!(f.speed_mps.abs() < 0.5, "{}", f.speed_mps);
    }

    #[test]
    fn near_standstill_it_is_the_kinematic_model() {
        let p = CommonRoadVehicleParams::default();
        let x = StdState::rolling(
            &StState {
                steering_angle_rad: 0.1,
                speed_mps: 0.01,
                ..StState::default()
            },
            &p,
        );
        let u = CommonRoadInput {
            steering_velocity_radps: 0.1,
            acceleration_mps2: 1.0,
        };
        let f = std_derivative(&x, &u, &p);
        let w = std_dynamic_weight(0.01);
        assert!(w < 1e-3);
        // Acceleration input followed up to the tiny dynamic weight.
        assert!((f.speed_mps - 1.0).abs() < 10.0 * w, "{}", f.speed_mps);
        let ks = ks_cog_derivative(
            &KsState {
                x_m: 0.0,
                y_m: 0.0,
                steering_angle_rad: 0.1,
                speed_mps: 0.01,
                yaw_rad: 0.0,
            },
            &u,
            &p,
        );
        assert!((f.yaw_rad - ks.yaw_rad).abs() < 1e-6);
    }
}
