//! CommonRoad's kinematic single-track model "ks": the car is a bicycle whose wheels roll
//! without slipping, so its motion follows from the geometry alone. Reference point: the
//! centre of the rear axle.
//!
//! State (CommonRoad's order): x = [s_x, s_y, δ, v, ψ] — position of the rear-axle centre
//! (m), front-wheel steering angle (rad), speed of the rear axle (m/s, negative reversing), yaw
//! angle (rad). Input: u = [v_δ, a] — steering velocity (rad/s) and longitudinal acceleration
//! (m/s²), both passed through the constraints of [`super::constraints`] first (giving
//! v_δ', a'). With the wheelbase L = l_f + l_r:
//! ```text
//! ṡ_x = v cos ψ
//! ṡ_y = v sin ψ
//! δ̇   = v_δ'
//! v̇   = a'
//! ψ̇   = v tan δ / L
//! ```
//! Valid where the tyres' slip is negligible: low lateral acceleration (parking, urban speeds,
//! gentle highway manoeuvres); it has no sideslip and no load transfer.
//!
//! The same kinematics written for the centre of mass (used by the st and std models at low
//! speed, [`ks_cog_derivative`]): the velocity there points at the kinematic sideslip angle
//! β_k = atan(tan δ · l_r / L), and
//! ```text
//! ṡ_x = v cos(ψ + β_k),   ṡ_y = v sin(ψ + β_k),   δ̇ = v_δ',   v̇ = a',   ψ̇ = v cos β_k tan δ / L
//! ```

use serde::{Deserialize, Serialize};

use super::constraints::{CommonRoadInput, constrain_input};
use super::integrate::{CommonRoadState, step_rk4};
use super::params::CommonRoadVehicleParams;

/// State of the ks model (reference point: rear-axle centre). As a derivative, each field holds
/// the rate of that component (unit per second).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct KsState {
    /// x₁ = s_x: x position of the rear-axle centre (m).
    pub x_m: f64,
    /// x₂ = s_y: y position of the rear-axle centre (m).
    pub y_m: f64,
    /// x₃ = δ: front-wheel steering angle (rad).
    pub steering_angle_rad: f64,
    /// x₄ = v: speed (m/s; negative when reversing).
    pub speed_mps: f64,
    /// x₅ = ψ: yaw angle (rad), not wrapped.
    pub yaw_rad: f64,
}

impl CommonRoadState<5> for KsState {
    fn to_array(&self) -> [f64; 5] {
        [
            self.x_m,
            self.y_m,
            self.steering_angle_rad,
            self.speed_mps,
            self.yaw_rad,
        ]
    }

    fn from_array(v: [f64; 5]) -> Self {
        Self {
            x_m: v[0],
            y_m: v[1],
            steering_angle_rad: v[2],
            speed_mps: v[3],
            yaw_rad: v[4],
        }
    }
}

/// The ks model's derivative ẋ = f(x, u, p) (see the module doc); `input` is constrained here.
pub fn ks_derivative(x: &KsState, input: &CommonRoadInput, p: &CommonRoadVehicleParams) -> KsState {
    let u = constrain_input(
        x.steering_angle_rad,
        x.speed_mps,
        input,
        &p.steering,
        &p.longitudinal,
    );
    KsState {
        x_m: x.speed_mps * x.yaw_rad.cos(),
        y_m: x.speed_mps * x.yaw_rad.sin(),
        steering_angle_rad: u.steering_velocity_radps,
        speed_mps: u.acceleration_mps2,
        yaw_rad: x.speed_mps / p.wheelbase_m() * x.steering_angle_rad.tan(),
    }
}

/// One fixed RK4 step of `dt_s` (s) of the ks model with the input held.
pub fn ks_step_rk4(
    x: &KsState,
    input: &CommonRoadInput,
    p: &CommonRoadVehicleParams,
    dt_s: f64,
) -> KsState {
    step_rk4(|s: &KsState| ks_derivative(s, input, p), x, dt_s)
}

/// The kinematic model written for the centre of mass (module doc, second system), with the
/// state in ks layout but position and speed meant at the centre of mass. Used by the st and std
/// models at low speed; `input` is constrained here (constraining twice changes nothing).
pub fn ks_cog_derivative(
    x: &KsState,
    input: &CommonRoadInput,
    p: &CommonRoadVehicleParams,
) -> KsState {
    let u = constrain_input(
        x.steering_angle_rad,
        x.speed_mps,
        input,
        &p.steering,
        &p.longitudinal,
    );
    let wheelbase_m = p.wheelbase_m();
    let beta_rad = (x.steering_angle_rad.tan() * p.cog_to_rear_axle_m / wheelbase_m).atan();
    KsState {
        x_m: x.speed_mps * (beta_rad + x.yaw_rad).cos(),
        y_m: x.speed_mps * (beta_rad + x.yaw_rad).sin(),
        steering_angle_rad: u.steering_velocity_radps,
        speed_mps: u.acceleration_mps2,
        yaw_rad: x.speed_mps * beta_rad.cos() * x.steering_angle_rad.tan() / wheelbase_m,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_line_at_constant_speed() {
        let p = CommonRoadVehicleParams::default();
        let mut x = KsState {
            x_m: 1.0,
            y_m: 2.0,
            steering_angle_rad: 0.0,
            speed_mps: 10.0,
            yaw_rad: std::f64::consts::FRAC_PI_6,
        };
        let u = CommonRoadInput::default();
        for _ in 0..100 {
            x = ks_step_rk4(&x, &u, &p, 0.01);
        }
        // 1 s at 10 m/s along 30°: (1 + 10 cos 30°, 2 + 10 sin 30°) = (9.660254…, 7).
        assert!((x.x_m - (1.0 + 10.0 * 3f64.sqrt() / 2.0)).abs() < 1e-12);
        assert!((x.y_m - 7.0).abs() < 1e-12);
        assert_eq!(x.speed_mps, 10.0);
        assert_eq!(x.yaw_rad, std::f64::consts::FRAC_PI_6);
    }

    #[test]
    fn constant_steering_drives_a_circle_of_radius_l_over_tan_delta() {
        let p = CommonRoadVehicleParams::default();
        let delta = 0.1_f64;
        let radius_m = p.wheelbase_m() / delta.tan(); // 25.7031… m
        let v = 5.0;
        let mut x = KsState {
            steering_angle_rad: delta,
            speed_mps: v,
            ..KsState::default()
        };
        // A quarter circle: ψ = π/2 after t = (π/2)·R / v.
        let t = std::f64::consts::FRAC_PI_2 * radius_m / v;
        let n = 2000;
        for _ in 0..n {
            x = ks_step_rk4(&x, &CommonRoadInput::default(), &p, t / n as f64);
        }
        assert!((x.yaw_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        // Rear axle from (0, 0) heading +x to (R, R).
        assert!((x.x_m - radius_m).abs() < 1e-9, "{}", x.x_m - radius_m);
        assert!((x.y_m - radius_m).abs() < 1e-9, "{}", x.y_m - radius_m);
    }

    #[test]
    fn centre_of_mass_form_moves_along_the_kinematic_sideslip() {
        let p = CommonRoadVehicleParams::default();
        let x = KsState {
            steering_angle_rad: 0.2,
            speed_mps: 10.0,
            ..KsState::default()
        };
        let f = ks_cog_derivative(&x, &CommonRoadInput::default(), &p);
        let beta = (0.2f64.tan() * p.cog_to_rear_axle_m / p.wheelbase_m()).atan();
        assert!((f.y_m / f.x_m - beta.tan()).abs() < 1e-12);
        // Same yaw rate as the rear-axle form: the rear axle moves at v_cog · cos β.
        let rear = ks_derivative(
            &KsState {
                speed_mps: 10.0 * beta.cos(),
                ..x
            },
            &CommonRoadInput::default(),
            &p,
        );
        assert!((f.yaw_rad - rear.yaw_rad).abs() < 1e-12);
    }
}
