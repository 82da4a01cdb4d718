//! The std car's ideal ABS and traction control ([`crate::CommonRoadVehicle`]).

use crate::commonroad_models::{CommonRoadVehicleParams, StdState};
use crate::params::VehicleParams;

/// Below this wheel ground speed the std wheels' slip is not controlled (m/s).
const SLIP_CONTROL_MIN_SPEED_MPS: f64 = 1.0;

/// The std car's ABS and traction control, ideal as the `rapier` car's (`crate::wheel`): after
/// each RK4 sub-step a braked wheel turning slower than the tyre's peak braking slip, or a
/// driven wheel turning faster than its peak driving slip, is set to that slip. CommonRoad's
/// std model has neither; without them a full brake locks the wheels, and CommonRoad's tyre
/// (its slip-ratio side force `r_vy*`) then spins the car.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct WheelSlipControl {
    /// Longest braking slip ratio s = 1 − R_w ω / u_w (at the force's peak), or `None`: no ABS.
    brake_slip: Option<f64>,
    /// Most negative driving slip ratio, or `None`: no traction control.
    drive_slip: Option<f64>,
}

impl WheelSlipControl {
    /// The control of a car of `params` on a road of friction `mu`: the peak of its
    /// Magic-Formula longitudinal curve, S_Hx off centre (CommonRoad's κ_x = −s + p_hx1).
    pub(super) fn of(params: &VehicleParams, mu: f64) -> Option<Self> {
        if !params.abs_enabled && !params.traction_control_enabled {
            return None;
        }
        let peak = crate::tire::TireCurves::new(&params.tire, mu).peak_slip_ratio;
        let shift = params.tire.p_hx1;
        Some(Self {
            brake_slip: params.abs_enabled.then_some(shift + peak),
            drive_slip: params.traction_control_enabled.then_some(shift - peak),
        })
    }

    /// `s` with each wheel's spin held within the slip limits for acceleration input `a`.
    pub(super) fn hold(
        &self,
        mut s: StdState,
        acceleration_mps2: f64,
        p: &CommonRoadVehicleParams,
    ) -> StdState {
        let (lf, rw) = (p.cog_to_front_axle_m, p.wheel_radius_m);
        let (sin_b, cos_b) = s.slip_angle_rad.sin_cos();
        let (sin_d, cos_d) = s.steering_angle_rad.sin_cos();
        let v = s.speed_mps;
        let u_front = v * cos_b * cos_d + (v * sin_b + lf * s.yaw_rate_radps) * sin_d;
        let u_rear = v * cos_b;
        let limit = |omega: f64, u_mps: f64| -> f64 {
            if u_mps < SLIP_CONTROL_MIN_SPEED_MPS {
                return omega;
            }
            match (acceleration_mps2 < 0.0, self.brake_slip, self.drive_slip) {
                (true, Some(slip), _) => omega.max((1.0 - slip) * u_mps / rw),
                (false, _, Some(slip)) if acceleration_mps2 > 0.0 => {
                    omega.min((1.0 - slip) * u_mps / rw)
                }
                _ => omega,
            }
        };
        s.front_wheel_speed_radps = limit(s.front_wheel_speed_radps, u_front);
        s.rear_wheel_speed_radps = limit(s.rear_wheel_speed_radps, u_rear);
        s
    }
}
