//! Handling maneuvers as vehicle engineers run them, on a wide flat pad.
//!
//! - `steady-state`: constant steer, speed held by the speed PID; the settled state is averaged
//!   over the last `average_window_s` (ISO 4138 constant-steer-angle method).
//! - `step-steer`: straight at speed, then a steering step (as fast as the actuator allows);
//!   reports the settled state plus the yaw-rate response time (50 % steer → 90 % of the
//!   settled yaw rate), peak response time and overshoot (ISO 7401 definitions).
//! - `braking`: straight at speed, then full brake torque on all wheels (ABS as configured in
//!   the vehicle) until stop; reports the stopping distance from brake onset.
//!
//! Every report carries the linear single-track reference ([`LinearSingleTrack`]) and, for
//! braking, the friction-limited distance v²/(2μg).

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::controls::Controls;
use crate::error::VehicleError;
use crate::kinematics::Kinematics;
use crate::params::VehicleParams;
use crate::physics_world::{DT_RANGE_S, GRAVITY_MPS2, PhysicsWorld};
use crate::single_track::LinearSingleTrack;
use crate::tracker::{SpeedController, TrackerParams};
use crate::vehicle::{MU_RANGE, Vehicle};

/// Below this speed a braking car counts as stopped (m/s).
const STOPPED_SPEED_MPS: f64 = 0.05;

/// Extra pad beyond the farthest reachable point (m).
const PAD_MARGIN_M: f64 = 200.0;

/// The maneuver to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ManeuverKind {
    /// Constant steer at constant speed.
    SteadyState,
    /// Steering step at constant speed.
    StepSteer,
    /// Full braking from speed to stop.
    Braking,
}

impl ManeuverKind {
    /// The names accepted by [`FromStr`].
    pub const NAMES: [&'static str; 3] = ["steady-state", "step-steer", "braking"];

    /// The kebab-case name.
    pub fn name(self) -> &'static str {
        match self {
            Self::SteadyState => "steady-state",
            Self::StepSteer => "step-steer",
            Self::Braking => "braking",
        }
    }
}

impl fmt::Display for ManeuverKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ManeuverKind {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "steady-state" => Ok(Self::SteadyState),
            "step-steer" => Ok(Self::StepSteer),
            "braking" => Ok(Self::Braking),
            _ => Err(format!(
                "unknown maneuver {s:?}; valid maneuvers: {}",
                Self::NAMES.join(", ")
            )),
        }
    }
}

/// What to run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ManeuverConfig {
    /// Which maneuver.
    pub kind: ManeuverKind,
    /// Vehicle preset name (one of [`crate::PRESET_NAMES`]); used for the report's name even
    /// when `vehicle_params` overrides the parameters.
    pub vehicle: String,
    /// Parameters to use instead of the preset's.
    pub vehicle_params: Option<VehicleParams>,
    /// Speed held during the maneuver / speed at brake onset (m/s).
    pub speed_mps: f64,
    /// Road-wheel steering angle (rad, positive left); ignored by `braking`.
    pub steer_rad: f64,
    /// Road friction coefficient μ.
    pub mu: f64,
    /// Physics step (s).
    pub dt_s: f64,
    /// Simulated time (s); for `braking`, the time allowed after brake onset.
    pub duration_s: f64,
    /// Time of the steering step / brake onset (s).
    pub step_time_s: f64,
    /// Settled values are averaged over the last this many seconds (s).
    pub average_window_s: f64,
    /// Period of the recorded trace (s); 0 records none.
    pub trace_period_s: f64,
    /// Speed-loop tuning (only the speed PID and torque allocation are used).
    pub tracker: TrackerParams,
}

impl Default for ManeuverConfig {
    fn default() -> Self {
        Self {
            kind: ManeuverKind::SteadyState,
            vehicle: "bmw_320i".into(),
            vehicle_params: None,
            speed_mps: 20.0,
            steer_rad: 0.01,
            mu: 0.8,
            dt_s: 0.002,
            duration_s: 12.0,
            step_time_s: 1.0,
            average_window_s: 2.0,
            trace_period_s: 0.05,
            tracker: TrackerParams::default(),
        }
    }
}

impl ManeuverConfig {
    /// The vehicle parameters this configuration runs with, validated.
    pub fn resolved_vehicle(&self) -> Result<VehicleParams, VehicleError> {
        let params = match &self.vehicle_params {
            Some(p) => p.clone(),
            None => VehicleParams::preset(&self.vehicle)?,
        };
        params.validate()?;
        Ok(params)
    }

    /// Checks every field; the error names the field and its value.
    pub fn validate(&self) -> Result<VehicleParams, VehicleError> {
        let params = self.resolved_vehicle()?;
        if !(self.mu.is_finite() && self.mu > 0.0) {
            return Err(VehicleError::invalid(
                "mu",
                self.mu,
                "must be finite and > 0",
            ));
        }
        if self.mu < MU_RANGE.0 || self.mu > MU_RANGE.1 {
            return Err(VehicleError::invalid(
                "mu",
                self.mu,
                format!("must lie in [{}, {}]", MU_RANGE.0, MU_RANGE.1),
            ));
        }
        if !(self.speed_mps.is_finite() && self.speed_mps > 0.0 && self.speed_mps <= 100.0) {
            return Err(VehicleError::invalid(
                "speed_mps",
                self.speed_mps,
                "must lie in (0, 100] m/s",
            ));
        }
        if !(self.steer_rad.is_finite() && self.steer_rad.abs() <= params.max_steer_rad) {
            return Err(VehicleError::invalid(
                "steer_rad",
                self.steer_rad,
                format!(
                    "must be finite with |steer| <= {} rad",
                    params.max_steer_rad
                ),
            ));
        }
        if !(self.dt_s.is_finite() && self.dt_s >= DT_RANGE_S.0 && self.dt_s <= DT_RANGE_S.1) {
            return Err(VehicleError::invalid(
                "dt_s",
                self.dt_s,
                format!("must lie in [{}, {}] s", DT_RANGE_S.0, DT_RANGE_S.1),
            ));
        }
        if !(self.duration_s.is_finite() && self.duration_s > 0.0 && self.duration_s <= 600.0) {
            return Err(VehicleError::invalid(
                "duration_s",
                self.duration_s,
                "must lie in (0, 600] s",
            ));
        }
        if !(self.step_time_s.is_finite() && self.step_time_s >= 0.0) {
            return Err(VehicleError::invalid(
                "step_time_s",
                self.step_time_s,
                "must be finite and >= 0",
            ));
        }
        if self.kind == ManeuverKind::StepSteer && self.step_time_s >= self.duration_s {
            return Err(VehicleError::invalid(
                "step_time_s",
                self.step_time_s,
                format!("must be below duration_s = {}", self.duration_s),
            ));
        }
        if !(self.average_window_s.is_finite()
            && self.average_window_s > 0.0
            && self.average_window_s <= self.duration_s)
        {
            return Err(VehicleError::invalid(
                "average_window_s",
                self.average_window_s,
                format!("must lie in (0, duration_s = {}]", self.duration_s),
            ));
        }
        if !(self.trace_period_s.is_finite() && self.trace_period_s >= 0.0) {
            return Err(VehicleError::invalid(
                "trace_period_s",
                self.trace_period_s,
                "must be finite and >= 0",
            ));
        }
        self.tracker.validate()?;
        Ok(params)
    }
}

/// Yaw-rate step response (ISO 7401 definitions).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepResponse {
    /// Settled yaw rate (rad/s).
    pub steady_yaw_rate_radps: f64,
    /// Time from 50 % of the steering step to 90 % of the settled yaw rate (s).
    pub response_time_s: f64,
    /// Time from 50 % of the steering step to the yaw-rate peak (s).
    pub peak_response_time_s: f64,
    /// (peak − settled) / settled (−); 0 for a response without overshoot.
    pub overshoot_ratio: f64,
}

/// The linear single-track model's predictions for the same speed and steer.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinearReference {
    /// r = v δ / (L + K_us v²) (rad/s).
    pub yaw_rate_radps: f64,
    /// β at the CoG (rad).
    pub sideslip_rad: f64,
    /// v·r (m/s²).
    pub lat_accel_mps2: f64,
    /// K_us (rad per m/s²).
    pub understeer_gradient_rad_per_mps2: f64,
    /// Speed where β changes sign (m/s).
    pub sideslip_sign_change_speed_mps: f64,
}

/// One sample of the recorded trace.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ManeuverSample {
    /// Time (s).
    pub t_s: f64,
    /// The vehicle's state.
    pub state: Kinematics,
}

/// Result of a maneuver (serialises to JSON for the CLI).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ManeuverReport {
    /// Which maneuver.
    pub maneuver: ManeuverKind,
    /// Vehicle name.
    pub vehicle: String,
    /// Settled speed (steady-state, step-steer) or speed at brake onset (m/s).
    pub speed_mps: f64,
    /// Settled actual road-wheel steering angle (rad).
    pub steer_rad: f64,
    /// Road friction coefficient.
    pub mu: f64,
    /// Settled yaw rate (rad/s).
    pub yaw_rate_radps: f64,
    /// Settled sideslip angle at the CoG (rad).
    pub sideslip_rad: f64,
    /// Settled lateral acceleration (m/s²).
    pub lat_accel_mps2: f64,
    /// Settled roll angle (rad, positive right side down).
    pub roll_rad: f64,
    /// Peak |roll| over the run (rad).
    pub max_abs_roll_rad: f64,
    /// Linear single-track reference at the settled speed and steer.
    pub reference: LinearReference,
    /// Step-steer response (step-steer only).
    pub step_response: Option<StepResponse>,
    /// Distance from brake onset to stop (braking only; None if it did not stop in time) (m).
    pub stopping_distance_m: Option<f64>,
    /// Time from brake onset to stop (s).
    pub stopping_time_s: Option<f64>,
    /// v²/(2μg) at the brake-onset speed (braking only) (m).
    pub reference_stopping_distance_m: Option<f64>,
    /// The vehicle's single-track parameters (axle cornering stiffnesses linearised from the
    /// tyre model at static load).
    pub params: LinearSingleTrack,
    /// Simulated time (s).
    pub simulated_s: f64,
    /// Trace sampled every `trace_period_s`.
    pub trace: Vec<ManeuverSample>,
}

/// Means over the settled window.
struct Settled {
    speed: f64,
    steer: f64,
    yaw_rate: f64,
    sideslip: f64,
    lat_accel: f64,
    roll: f64,
}

/// Running mean of the settled window.
#[derive(Default)]
struct Average {
    n: u32,
    speed: f64,
    steer: f64,
    yaw_rate: f64,
    sideslip: f64,
    lat_accel: f64,
    roll: f64,
}

impl Average {
    fn add(&mut self, k: &Kinematics) {
        self.n += 1;
        self.speed += k.speed_mps;
        self.steer += k.steer_rad;
        self.yaw_rate += k.yaw_rate_radps;
        self.sideslip += k.sideslip_rad;
        self.lat_accel += k.accel_lat_mps2;
        self.roll += k.roll_rad;
    }

    fn mean(&self) -> Settled {
        let n = f64::from(self.n.max(1));
        Settled {
            speed: self.speed / n,
            steer: self.steer / n,
            yaw_rate: self.yaw_rate / n,
            sideslip: self.sideslip / n,
            lat_accel: self.lat_accel / n,
            roll: self.roll / n,
        }
    }
}

/// Runs a maneuver; errors name the offending configuration value.
pub fn run_maneuver(cfg: &ManeuverConfig) -> Result<ManeuverReport, VehicleError> {
    let params = cfg.validate()?;
    let mut world = PhysicsWorld::new(cfg.dt_s)?;
    let total_s = match cfg.kind {
        ManeuverKind::Braking => cfg.step_time_s + cfg.duration_s,
        _ => cfg.duration_s,
    };
    world.try_add_flat_ground(cfg.speed_mps * total_s + PAD_MARGIN_M)?;
    let mut vehicle = Vehicle::spawn(&mut world, &params, 0.0, 0.0, 0.0, cfg.speed_mps)?;
    let mut speed_loop = SpeedController::new(cfg.tracker.clone(), &params);
    let dt = cfg.dt_s;
    let steps = (total_s / dt).round() as u64;
    let step_index = (cfg.step_time_s / dt).round() as u64;
    let window_start = steps.saturating_sub((cfg.average_window_s / dt).round() as u64);
    let trace_every = if cfg.trace_period_s > 0.0 {
        ((cfg.trace_period_s / dt).round() as u64).max(1)
    } else {
        0
    };

    let mut trace = Vec::new();
    let mut average = Average::default();
    let mut max_abs_roll: f64 = 0.0;
    // Step-steer bookkeeping: (t, actual steer, yaw rate) after the step.
    let mut response: Vec<(f64, f64, f64)> = Vec::new();
    // Braking bookkeeping.
    let mut brake_onset: Option<(f64, f64, f64)> = None; // (t, x, y)
    let mut onset_speed = cfg.speed_mps;
    let mut stop: Option<(f64, f64)> = None; // (distance, time)

    let mut kin = vehicle.kinematics(&world);
    let mut simulated_s = 0.0;
    for n in 0..steps {
        let t = n as f64 * dt;
        let (drive, brake) = speed_loop.update(cfg.speed_mps, kin.speed_mps, dt);
        let controls = match cfg.kind {
            ManeuverKind::SteadyState => Controls {
                steer_rad: cfg.steer_rad,
                drive_torque_nm: drive,
                brake_torque_nm: brake,
            },
            ManeuverKind::StepSteer => Controls {
                steer_rad: if n >= step_index { cfg.steer_rad } else { 0.0 },
                drive_torque_nm: drive,
                brake_torque_nm: brake,
            },
            ManeuverKind::Braking => {
                if n >= step_index {
                    if brake_onset.is_none() {
                        brake_onset = Some((t, kin.x_m, kin.y_m));
                        onset_speed = kin.speed_mps;
                    }
                    Controls {
                        steer_rad: 0.0,
                        drive_torque_nm: [0.0; 4],
                        brake_torque_nm: [params.max_brake_torque_nm; 4],
                    }
                } else {
                    Controls {
                        steer_rad: 0.0,
                        drive_torque_nm: drive,
                        brake_torque_nm: brake,
                    }
                }
            }
        };
        vehicle.set_controls(controls);
        vehicle.apply_forces(&mut world, cfg.mu);
        world.step();
        kin = vehicle.kinematics(&world);
        simulated_s = (n + 1) as f64 * dt;
        max_abs_roll = max_abs_roll.max(kin.roll_rad.abs());
        if trace_every > 0 && (n + 1) % trace_every == 0 {
            trace.push(ManeuverSample {
                t_s: simulated_s,
                state: kin,
            });
        }
        if n >= window_start {
            average.add(&kin);
        }
        if cfg.kind == ManeuverKind::StepSteer && n + 1 >= step_index {
            response.push((simulated_s, kin.steer_rad, kin.yaw_rate_radps));
        }
        if let Some((t0, x0, y0)) = brake_onset
            && kin.speed_mps < STOPPED_SPEED_MPS
        {
            stop = Some(((kin.x_m - x0).hypot(kin.y_m - y0), simulated_s - t0));
            break;
        }
    }

    let Settled {
        speed,
        steer,
        yaw_rate,
        sideslip,
        lat_accel,
        roll,
    } = average.mean();
    let single_track = LinearSingleTrack::from_params(&params);
    let (ref_speed, ref_steer) = match cfg.kind {
        ManeuverKind::Braking => (onset_speed, 0.0),
        _ => (speed, steer),
    };
    let reference = LinearReference {
        yaw_rate_radps: single_track.steady_state_yaw_rate_radps(ref_speed, ref_steer),
        sideslip_rad: single_track.steady_state_sideslip_rad(ref_speed, ref_steer),
        lat_accel_mps2: single_track.steady_state_lat_accel_mps2(ref_speed, ref_steer),
        understeer_gradient_rad_per_mps2: single_track.understeer_gradient_rad_per_mps2(),
        sideslip_sign_change_speed_mps: single_track.sideslip_sign_change_speed_mps(),
    };
    let step_response = (cfg.kind == ManeuverKind::StepSteer)
        .then(|| step_response(&response, cfg.steer_rad, yaw_rate))
        .flatten();
    let braking = cfg.kind == ManeuverKind::Braking;
    Ok(ManeuverReport {
        maneuver: cfg.kind,
        vehicle: cfg.vehicle.clone(),
        speed_mps: if braking { onset_speed } else { speed },
        steer_rad: if braking { 0.0 } else { steer },
        mu: cfg.mu,
        yaw_rate_radps: if braking { 0.0 } else { yaw_rate },
        sideslip_rad: if braking { 0.0 } else { sideslip },
        lat_accel_mps2: if braking { 0.0 } else { lat_accel },
        roll_rad: if braking { 0.0 } else { roll },
        max_abs_roll_rad: max_abs_roll,
        reference,
        step_response,
        stopping_distance_m: stop.map(|s| s.0),
        stopping_time_s: stop.map(|s| s.1),
        reference_stopping_distance_m: braking
            .then(|| onset_speed * onset_speed / (2.0 * cfg.mu * GRAVITY_MPS2)),
        params: single_track,
        simulated_s,
        trace,
    })
}

/// ISO 7401 response figures from the samples after the step.
fn step_response(
    samples: &[(f64, f64, f64)],
    steer_cmd: f64,
    settled: f64,
) -> Option<StepResponse> {
    if settled == 0.0 || steer_cmd == 0.0 {
        return None;
    }
    let sign = settled.signum();
    let t50 = samples
        .iter()
        .find(|s| s.1 * steer_cmd.signum() >= 0.5 * steer_cmd.abs())?
        .0;
    let t90 = samples
        .iter()
        .find(|s| s.2 * sign >= 0.9 * settled.abs())?
        .0;
    let (t_peak, peak) =
        samples
            .iter()
            .map(|s| (s.0, s.2 * sign))
            .fold(
                (t50, f64::MIN),
                |best, s| if s.1 > best.1 { s } else { best },
            );
    Some(StepResponse {
        steady_yaw_rate_radps: settled,
        response_time_s: t90 - t50,
        peak_response_time_s: t_peak - t50,
        overshoot_ratio: ((peak - settled.abs()) / settled.abs()).max(0.0),
    })
}
