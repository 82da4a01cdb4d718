//! The linear single-track ("bicycle") model: the textbook reference the 3-D vehicle is checked
//! against (e.g. Rajamani, *Vehicle Dynamics and Control*, 2nd ed., ch. 2–3; Mitschke &
//! Wallentowitz, *Dynamik der Kraftfahrzeuge*).
//!
//! Small angles, constant speed v, axle cornering stiffnesses C_f, C_r (N/rad, both tyres of the
//! axle), slip angles α_f = β + l_f r / v − δ, α_r = β − l_r r / v, lateral forces F = −C α:
//! ```text
//! m v (β̇ + r) = C_f (δ − β − l_f r/v) + C_r (−β + l_r r/v)
//! I_z ṙ      = l_f C_f (δ − β − l_f r/v) − l_r C_r (−β + l_r r/v)
//! ```
//! Steady state (β̇ = ṙ = 0): the yaw moment balance gives F_f l_f = F_r l_r, so
//! F_f = m v r l_r / L and F_r = m v r l_f / L. Substituting into the axle laws:
//! ```text
//! r = v δ / (L + K_us v²),            K_us = (m / L) (l_r / C_f − l_f / C_r)   [rad/(m/s²)]
//! β = r (l_r / v − m v l_f / (C_r L)) = δ (l_r − m v² l_f / (C_r L)) / (L + K_us v²)
//! ```
//! β changes sign at v_β0 = √(l_r C_r L / (m l_f)): positive (kinematic, β → l_r δ / L) below,
//! negative above.

use serde::{Deserialize, Serialize};

use crate::params::VehicleParams;
use crate::physics_world::GRAVITY_MPS2;
use crate::tire::TireCurves;

/// Parameters of the linear single-track model of a car.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinearSingleTrack {
    /// Mass m (kg).
    pub mass_kg: f64,
    /// Yaw inertia I_z (kg·m²).
    pub yaw_inertia_kgm2: f64,
    /// CoG to front axle l_f (m).
    pub lf_m: f64,
    /// CoG to rear axle l_r (m).
    pub lr_m: f64,
    /// Front axle cornering stiffness C_f (N/rad).
    pub cornering_stiffness_front_npr: f64,
    /// Rear axle cornering stiffness C_r (N/rad).
    pub cornering_stiffness_rear_npr: f64,
}

impl LinearSingleTrack {
    /// The model of a car, with axle cornering stiffnesses linearised from its tyre model at the
    /// static axle loads (2·|p_ky1|·Fz_static per axle; independent of μ).
    pub fn from_params(p: &VehicleParams) -> Self {
        let fz_front = p.static_load_front_n(GRAVITY_MPS2);
        let fz_rear = p.static_load_rear_n(GRAVITY_MPS2);
        Self {
            mass_kg: p.mass_kg,
            yaw_inertia_kgm2: p.yaw_inertia_kgm2,
            lf_m: p.cog_to_front_axle_m,
            lr_m: p.cog_to_rear_axle_m,
            cornering_stiffness_front_npr: 2.0
                * TireCurves::cornering_stiffness_npr(&p.tire, fz_front),
            cornering_stiffness_rear_npr: 2.0
                * TireCurves::cornering_stiffness_npr(&p.tire, fz_rear),
        }
    }

    /// Wheelbase L (m).
    pub fn wheelbase_m(&self) -> f64 {
        self.lf_m + self.lr_m
    }

    /// Understeer gradient K_us = (m/L)(l_r/C_f − l_f/C_r) (rad per m/s²); > 0 understeer.
    pub fn understeer_gradient_rad_per_mps2(&self) -> f64 {
        self.mass_kg / self.wheelbase_m()
            * (self.lr_m / self.cornering_stiffness_front_npr
                - self.lf_m / self.cornering_stiffness_rear_npr)
    }

    /// Steady-state yaw rate r = v δ / (L + K_us v²) (rad/s).
    pub fn steady_state_yaw_rate_radps(&self, speed_mps: f64, steer_rad: f64) -> f64 {
        let l = self.wheelbase_m();
        speed_mps * steer_rad
            / (l + self.understeer_gradient_rad_per_mps2() * speed_mps * speed_mps)
    }

    /// Steady-state sideslip at the CoG,
    /// β = δ (l_r − m v² l_f / (C_r L)) / (L + K_us v²) (rad).
    pub fn steady_state_sideslip_rad(&self, speed_mps: f64, steer_rad: f64) -> f64 {
        let l = self.wheelbase_m();
        let v2 = speed_mps * speed_mps;
        steer_rad
            * (self.lr_m - self.mass_kg * v2 * self.lf_m / (self.cornering_stiffness_rear_npr * l))
            / (l + self.understeer_gradient_rad_per_mps2() * v2)
    }

    /// Steady-state lateral acceleration v·r (m/s²).
    pub fn steady_state_lat_accel_mps2(&self, speed_mps: f64, steer_rad: f64) -> f64 {
        speed_mps * self.steady_state_yaw_rate_radps(speed_mps, steer_rad)
    }

    /// Speed at which the steady-state sideslip changes sign, √(l_r C_r L / (m l_f)) (m/s).
    pub fn sideslip_sign_change_speed_mps(&self) -> f64 {
        (self.lr_m * self.cornering_stiffness_rear_npr * self.wheelbase_m()
            / (self.mass_kg * self.lf_m))
            .sqrt()
    }
}

/// Steady-state yaw rate of the linear single-track model of a car, r = v δ / (L + K_us v²)
/// (rad/s); shorthand for [`LinearSingleTrack::from_params`] +
/// [`LinearSingleTrack::steady_state_yaw_rate_radps`].
pub fn linear_yaw_rate_radps(params: &VehicleParams, speed_mps: f64, steer_rad: f64) -> f64 {
    LinearSingleTrack::from_params(params).steady_state_yaw_rate_radps(speed_mps, steer_rad)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Integrates the linear ODE (written out independently in the module doc) to steady state
    /// with RK4 and compares with the closed forms.
    #[test]
    fn closed_forms_match_integrated_ode() {
        let mut m = LinearSingleTrack::from_params(&VehicleParams::default());
        // Make it understeer so that K_us matters.
        m.cornering_stiffness_rear_npr *= 1.4;
        let (v, delta) = (22.0, 0.01);
        let f = |beta: f64, r: f64| {
            let af = beta + m.lf_m * r / v - delta;
            let ar = beta - m.lr_m * r / v;
            let ff = -m.cornering_stiffness_front_npr * af;
            let fr = -m.cornering_stiffness_rear_npr * ar;
            (
                (ff + fr) / (m.mass_kg * v) - r,
                (m.lf_m * ff - m.lr_m * fr) / m.yaw_inertia_kgm2,
            )
        };
        let (mut beta, mut r) = (0.0, 0.0);
        let h = 1e-3;
        for _ in 0..20_000 {
            let k1 = f(beta, r);
            let k2 = f(beta + 0.5 * h * k1.0, r + 0.5 * h * k1.1);
            let k3 = f(beta + 0.5 * h * k2.0, r + 0.5 * h * k2.1);
            let k4 = f(beta + h * k3.0, r + h * k3.1);
            beta += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
            r += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        }
        assert!((r - m.steady_state_yaw_rate_radps(v, delta)).abs() < 1e-9);
        assert!((beta - m.steady_state_sideslip_rad(v, delta)).abs() < 1e-9);
        let v0 = m.sideslip_sign_change_speed_mps();
        assert!(m.steady_state_sideslip_rad(v0, delta).abs() < 1e-12);
    }

    #[test]
    fn commonroad_tyres_make_the_bmw_nearly_neutral() {
        // K_y ∝ Fz and static loads ∝ l_r, l_f make l_r/C_f = l_f/C_r exactly.
        let m = LinearSingleTrack::from_params(&VehicleParams::default());
        assert!(m.understeer_gradient_rad_per_mps2().abs() < 1e-12);
    }
}
