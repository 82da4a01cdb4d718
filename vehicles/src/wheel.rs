//! One wheel: ray-cast suspension, spin degree of freedom and tyre slip.
//!
//! Per physics step and wheel (all in f64, world frame):
//! 1. **Suspension** (spring + damper along the chassis' down axis): a ray from the hardpoint
//!    finds the road at distance d; spring deflection x = x_static + (d_static − d), normal load
//!    Fz = max(0, k·x + c·ẋ) (no negative loads; x ≤ 0 means the wheel hangs in the air).
//! 2. **Slips** at the contact point, in the wheel's ground frame: v_x, v_y of the contact point
//!    of the chassis; κ = (ω r − v_x) / max(|v_x|, v_floor); the lateral slip follows the
//!    relaxation-length model σ·d(tan α')/dt + |v_x|·tan α' = v_y (PAC2002 transient), integrated
//!    implicitly: tan α'⁺ = (tan α' + dt·v_y/σ) / (1 + dt·|v_x|/σ). At v_x → 0 this becomes a
//!    lateral spring of rate K_y/σ instead of an infinitely stiff damper; a low-speed damper fades
//!    in below `low_speed_fade_mps` (PAC2002's VXLOW idea) so a parked car does not ring.
//! 3. **Tyre forces** F_x, F_y from the combined-slip Magic Formula ([`crate::tire`]).
//! 4. **Wheel spin**, semi-implicit (explicit Euler chatters because the spin time
//!    constant J·v/(r²·K_x) is ~3 ms): with F_x linearised in ω,
//!    F_x(ω⁺) ≈ F_x + (∂F_x/∂κ)(r/v_den)(ω⁺ − ω), J(ω⁺ − ω)/dt = T_drive − r·F_x(ω⁺) − T_brake
//!    gives ω⁺ = ω + dt (T_drive − r F_x) / (J + dt r² ∂F_x/∂κ / v_den); the brake is a Coulomb
//!    torque that can stop the wheel but never reverse it. ABS and traction control (optional)
//!    keep a braked / driven wheel's slip at the tyre's pure-slip peak. The force handed to the chassis is the linearised F_x(ω⁺), so
//!    the wheel and the chassis see the same force (action = reaction).

use crate::params::VehicleParams;
use crate::tire::{TireCurves, TireForces};

/// Height of the ray origin above the wheel centre at static equilibrium (m).
const RAY_ORIGIN_ABOVE_WHEEL_M: f64 = 0.3;

/// Fixed geometry of one wheel, in the chassis frame (origin at the CoG).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct WheelGeometry {
    /// Ray origin (x forward, y left, z up) relative to the CoG (m).
    pub hardpoint_m: [f64; 3],
    /// Ray length to the ground at static equilibrium (m).
    pub static_ray_length_m: f64,
    /// Spring deflection at static equilibrium (m).
    pub static_deflection_m: f64,
    /// Spring rate (N/m).
    pub spring_rate_npm: f64,
    /// Damping rate (N·s/m).
    pub damping_rate_nspm: f64,
    /// Steered wheel.
    pub steered: bool,
}

impl WheelGeometry {
    /// The four wheels (FL, FR, RL, RR) of a car with these parameters, springs preloaded so
    /// that the car rests at its CoG height under gravity `g`.
    pub fn for_vehicle(p: &VehicleParams, gravity_mps2: f64) -> [WheelGeometry; 4] {
        let z = p.wheel_radius_m - p.cog_height_m + RAY_ORIGIN_ABOVE_WHEEL_M;
        let front = (
            p.cog_to_front_axle_m,
            0.5 * p.track_front_m,
            p.spring_rate_front_npm,
            p.damping_rate_front_nspm,
            p.static_load_front_n(gravity_mps2),
        );
        let rear = (
            -p.cog_to_rear_axle_m,
            0.5 * p.track_rear_m,
            p.spring_rate_rear_npm,
            p.damping_rate_rear_nspm,
            p.static_load_rear_n(gravity_mps2),
        );
        let make = |(x, half_track, k, c, load): (f64, f64, f64, f64, f64), side: f64, steered| {
            WheelGeometry {
                hardpoint_m: [x, side * half_track, z],
                static_ray_length_m: RAY_ORIGIN_ABOVE_WHEEL_M + p.wheel_radius_m,
                static_deflection_m: load / k,
                spring_rate_npm: k,
                damping_rate_nspm: c,
                steered,
            }
        };
        [
            make(front, 1.0, true),
            make(front, -1.0, true),
            make(rear, 1.0, false),
            make(rear, -1.0, false),
        ]
    }

    /// Longest ray that can still find the ground with the spring unloaded (m).
    pub fn max_ray_length_m(&self) -> f64 {
        self.static_ray_length_m + self.static_deflection_m
    }
}

/// Dynamic state of one wheel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct WheelState {
    /// Spin rate ω (rad/s, positive rolling forward).
    pub spin_radps: f64,
    /// Relaxed lateral slip, tan α' (−).
    pub lateral_slip_tan: f64,
}

/// What one wheel did during the last step (for logging and tests).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WheelTelemetry {
    /// The ray found the road within the suspension travel.
    pub in_contact: bool,
    /// Normal load Fz (N).
    pub normal_load_n: f64,
    /// Spring deflection from its free length (m).
    pub spring_deflection_m: f64,
    /// Slip ratio κ (−).
    pub slip_ratio: f64,
    /// Relaxed slip angle α' (rad).
    pub slip_angle_rad: f64,
    /// Spin rate after the step (rad/s).
    pub spin_radps: f64,
    /// Longitudinal tyre force applied (N, wheel frame).
    pub fx_n: f64,
    /// Lateral tyre force applied (N, wheel frame).
    pub fy_n: f64,
    /// Contact point (m, world: the road's coordinates, not Rapier's local ones).
    pub contact_point_m: [f64; 3],
    /// Brake torque actually applied after ABS (N·m).
    pub applied_brake_torque_nm: f64,
}

/// Everything the per-wheel update needs besides the wheel itself.
pub(crate) struct WheelInputs<'a> {
    pub params: &'a VehicleParams,
    pub curves: &'a TireCurves,
    pub dt_s: f64,
    pub gravity_mps2: f64,
    pub slip_speed_floor_mps: f64,
    pub drive_torque_nm: f64,
    pub brake_torque_nm: f64,
}

/// Contact kinematics of one wheel for this step (world frame, f64).
pub(crate) struct Contact {
    /// Spring deflection x (m), > 0.
    pub deflection_m: f64,
    /// Deflection rate ẋ (m/s), positive compressing.
    pub deflection_rate_mps: f64,
    /// Contact-point velocity along the wheel heading (m/s).
    pub v_long_mps: f64,
    /// Contact-point velocity to the wheel's left (m/s).
    pub v_lat_mps: f64,
    /// cos of the angle between the surface normal and the suspension axis.
    pub normal_cos: f64,
}

/// Result of one wheel update: normal load and tyre forces in the wheel's ground frame.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WheelForces {
    /// Normal load Fz (N), along the road normal.
    pub normal_load_n: f64,
    pub fx_n: f64,
    pub fy_n: f64,
}

/// Suspension + tyre + spin update of a wheel on the ground.
pub(crate) fn update_in_contact(
    geometry: &WheelGeometry,
    state: &mut WheelState,
    contact: &Contact,
    inputs: &WheelInputs<'_>,
    telemetry: &mut WheelTelemetry,
) -> WheelForces {
    let p = inputs.params;
    let tp = &p.tire;
    let dt = inputs.dt_s;
    let r = p.wheel_radius_m;

    // 1. Suspension.
    let suspension_n = (geometry.spring_rate_npm * contact.deflection_m
        + geometry.damping_rate_nspm * contact.deflection_rate_mps)
        .max(0.0);
    let fz = suspension_n * contact.normal_cos.max(0.0);

    // 2. Slips.
    let vx = contact.v_long_mps;
    let vy = contact.v_lat_mps;
    let v_den = vx.abs().max(inputs.slip_speed_floor_mps);
    let omega = state.spin_radps;
    let kappa = (omega * r - vx) / v_den;
    let sigma = tp.relaxation_length_lat_m;
    let mut t = (state.lateral_slip_tan + dt * vy / sigma) / (1.0 + dt * vx.abs() / sigma);
    let t_max = inputs
        .curves
        .peak_slip_angle_tan
        .max(vy.abs() / vx.abs().max(inputs.slip_speed_floor_mps));
    t = t.clamp(-t_max, t_max);
    state.lateral_slip_tan = t;
    let alpha = t.atan();

    // 3. Tyre forces.
    let TireForces {
        fx_n,
        fy_n,
        dfx_dkappa_n,
    } = inputs.curves.combined(tp, fz, kappa, alpha);

    // 4. Semi-implicit spin.
    let dfx_domega = dfx_dkappa_n * r / v_den;
    let j_eff = p.wheel_inertia_kgm2 + dt * r * dfx_domega;
    let omega_free = omega + dt * (inputs.drive_torque_nm - r * fx_n) / j_eff;
    let brake_domega = dt * inputs.brake_torque_nm / j_eff;
    let mut omega_new = if omega_free.abs() <= brake_domega {
        0.0
    } else {
        omega_free - brake_domega * omega_free.signum()
    };
    if p.abs_enabled && inputs.brake_torque_nm > 0.0 && vx > inputs.slip_speed_floor_mps {
        // Peak of F_x0 in braking: κ + S_Hx = −κ_peak.
        let kappa_abs = -inputs.curves.peak_slip_ratio - tp.p_hx1;
        let omega_abs = (vx + kappa_abs * v_den) / r;
        if omega_new < omega_abs {
            omega_new = omega_abs.min(omega_free);
        }
    }
    if p.traction_control_enabled
        && inputs.drive_torque_nm > 0.0
        && vx > -inputs.slip_speed_floor_mps
    {
        // Traction control: the drive torque is cut so that the slip stays at the peak.
        let kappa_tcs = inputs.curves.peak_slip_ratio - tp.p_hx1;
        let omega_tcs = (vx + kappa_tcs * v_den) / r;
        if omega_new > omega_tcs {
            let without_drive = omega_new - dt * inputs.drive_torque_nm / j_eff;
            omega_new = omega_tcs.max(without_drive);
        }
    }
    let applied_brake = if brake_domega > 0.0 {
        inputs.brake_torque_nm * ((omega_free - omega_new).abs() / brake_domega).min(1.0)
    } else {
        0.0
    };
    state.spin_radps = omega_new;

    // Force consistent with ω⁺, clipped to the friction circle.
    let mut fx = fx_n + dfx_domega * (omega_new - omega);
    let mut fy = fy_n;
    // Low-speed lateral damper, fading out linearly by `low_speed_fade_mps`.
    let fade = (1.0 - vx.abs() / tp.low_speed_fade_mps).max(0.0);
    if fade > 0.0 {
        let c = 2.0
            * tp.low_speed_damping_ratio
            * fz
            * (tp.p_ky1.abs() / (sigma * inputs.gravity_mps2)).sqrt();
        fy -= fade * c * vy;
    }
    let limit = inputs.curves.mu * fz;
    if !well_inside_circle(fx, fy, limit) {
        let norm = fx.hypot(fy);
        if norm > limit {
            let s = if norm > 0.0 { limit / norm } else { 0.0 };
            fx *= s;
            fy *= s;
        }
    }

    *telemetry = WheelTelemetry {
        in_contact: true,
        normal_load_n: fz,
        spring_deflection_m: contact.deflection_m,
        slip_ratio: (omega_new * r - vx) / v_den,
        slip_angle_rad: alpha,
        spin_radps: omega_new,
        fx_n: fx,
        fy_n: fy,
        contact_point_m: telemetry.contact_point_m,
        applied_brake_torque_nm: applied_brake,
    };
    WheelForces {
        normal_load_n: fz,
        fx_n: fx,
        fy_n: fy,
    }
}

/// Whether (fx, fy) lies so far inside the circle of radius `limit` that `fx.hypot(fy) <=
/// limit` is certain: |F|² below limit² by a margin (10⁻⁹ relative) far above the rounding of
/// either side, so the exact `hypot` (a slow libm call, once per wheel and step) is needed only
/// near and beyond the circle. Skipping it there changes no result. False for non-finite input.
#[inline]
fn well_inside_circle(fx: f64, fy: f64, limit: f64) -> bool {
    fx * fx + fy * fy < limit * limit * (1.0 - 1e-9)
}

/// Spin update of a wheel in the air: only the drive and brake torques act.
pub(crate) fn update_in_air(
    state: &mut WheelState,
    inputs: &WheelInputs<'_>,
    telemetry: &mut WheelTelemetry,
) {
    let j = inputs.params.wheel_inertia_kgm2;
    let omega_free = state.spin_radps + inputs.dt_s * inputs.drive_torque_nm / j;
    let brake_domega = inputs.dt_s * inputs.brake_torque_nm / j;
    state.spin_radps = if omega_free.abs() <= brake_domega {
        0.0
    } else {
        omega_free - brake_domega * omega_free.signum()
    };
    state.lateral_slip_tan = 0.0;
    *telemetry = WheelTelemetry {
        spin_radps: state.spin_radps,
        applied_brake_torque_nm: inputs.brake_torque_nm,
        ..WheelTelemetry::default()
    };
}

#[cfg(test)]
mod tests {
    use super::well_inside_circle;

    /// The shortcut never skips a force `hypot` would have clipped, at radii straddling the
    /// circle by a few ulps to a few parts in 10⁹, in every direction, and refuses NaN.
    #[test]
    fn the_friction_circle_shortcut_never_skips_a_clip() {
        let mut skipped = 0;
        for limit in [1e-3, 0.7, 2957.0, 3.1e4] {
            for k in 0..360 {
                let angle = f64::from(k) * std::f64::consts::PI / 180.0 + 1e-3;
                for rel in [-1e-8, -1.1e-9, -1e-9, -9e-10, -1e-12, 0.0, 1e-15, 1e-9] {
                    let r = limit * (1.0 + rel);
                    let (fx, fy) = (r * angle.cos(), r * angle.sin());
                    if well_inside_circle(fx, fy, limit) {
                        skipped += 1;
                        assert!(fx.hypot(fy) <= limit, "{fx} {fy} {limit}");
                    }
                }
            }
        }
        // Well inside, the shortcut does act (else it would be no shortcut).
        assert!(skipped > 4 * 360, "{skipped}");
        assert!(!well_inside_circle(f64::NAN, 0.0, 1.0));
        assert!(well_inside_circle(0.5, 0.5, 1.0));
    }
}
