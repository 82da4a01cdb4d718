//! Path tracker: pure pursuit for steering, PID on speed for the wheel torques.
//!
//! It follows; it does not plan. Steering (Coulter, *Implementation of the Pure Pursuit Path
//! Tracking Algorithm*, CMU-RI-TR-92-01, 1992): from the rear axle, aim at the point a
//! look-ahead distance L_d further along the (linearly interpolated) path, with
//! L_d = clamp(L_min + T_la·v, L_min, L_max) growing with speed, and steer the bicycle arc through
//! it: δ = atan(2 L sin α / l_d), α the bearing of the point relative to the heading, l_d its
//! distance. Speed: the target is the speed of the path point nearest ahead of the CoG; the
//! profile's own acceleration v·dv/ds on the current path segment is fed forward, and a PID with
//! conditional-integration anti-windup corrects the rest. The acceleration demand
//! becomes drive torque on the driven axle or brake torque on all wheels (distributed in
//! proportion to the estimated dynamic loads), each wheel's torque limited to what its tyre can
//! transmit, μ·Fz·r.

use serde::{Deserialize, Serialize};

use crate::controls::Controls;
use mergesim_types::bounds::{self, Bound};

use crate::error::VehicleError;
use crate::kinematics::Kinematics;
use crate::params::VehicleParams;
use crate::physics_world::GRAVITY_MPS2;

/// Tuning of the tracker.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrackerParams {
    /// Shortest look-ahead distance L_min (m).
    pub lookahead_min_m: f64,
    /// Look-ahead growth with speed T_la (s): L_d = L_min + T_la·v.
    pub lookahead_time_s: f64,
    /// Longest look-ahead distance L_max (m).
    pub lookahead_max_m: f64,
    /// Speed loop proportional gain (m/s² per m/s).
    pub speed_kp_per_s: f64,
    /// Speed loop integral gain (m/s² per m).
    pub speed_ki_per_s2: f64,
    /// Speed loop derivative gain on the measured speed (s·m/s² per m/s² = −).
    pub speed_kd: f64,
    /// The error is integrated only while |error| is below this band (m/s), so large
    /// transients (handled by the proportional and feed-forward terms) do not wind it up.
    pub speed_integral_band_mps: f64,
    /// Use the speed profile's own acceleration v·dv/ds as a feed-forward term.
    pub speed_feedforward: bool,
    /// Largest acceleration demand (m/s²).
    pub max_accel_mps2: f64,
    /// Largest deceleration demand (m/s², positive).
    pub max_decel_mps2: f64,
    /// Friction coefficient the torque limit μ·Fz·r assumes.
    pub friction_coefficient: f64,
    /// Below this target and actual speed the car is held with the brakes (m/s).
    pub stop_speed_mps: f64,
}

impl Default for TrackerParams {
    fn default() -> Self {
        Self {
            lookahead_min_m: 4.0,
            lookahead_time_s: 0.6,
            lookahead_max_m: 30.0,
            speed_kp_per_s: 1.0,
            speed_ki_per_s2: 0.3,
            speed_kd: 0.0,
            speed_integral_band_mps: 1.0,
            speed_feedforward: true,
            max_accel_mps2: 3.0,
            max_decel_mps2: 8.0,
            friction_coefficient: 0.8,
            stop_speed_mps: 0.2,
        }
    }
}

/// Allowed ranges of the tracker's parameters (README "Limits").
pub const TRACKER_BOUNDS: &[Bound] = &[
    Bound::closed("lookahead_min_m", 0.1, 100.0, "m"),
    Bound::closed("lookahead_time_s", 0.0, 5.0, "s"),
    Bound::closed("lookahead_max_m", 0.1, 200.0, "m"),
    Bound::closed("speed_kp_per_s", 0.0, 100.0, "1/s"),
    Bound::closed("speed_ki_per_s2", 0.0, 100.0, "1/s²"),
    Bound::closed("speed_kd", 0.0, 10.0, ""),
    Bound::closed("speed_integral_band_mps", 0.0, 20.0, "m/s"),
    Bound::above("max_accel_mps2", 0.0, 20.0, "m/s²"),
    Bound::above("max_decel_mps2", 0.0, 30.0, "m/s²"),
    Bound::closed("friction_coefficient", 0.05, 2.0, ""),
    Bound::closed("stop_speed_mps", 0.0, 5.0, "m/s"),
];

impl TrackerParams {
    /// Checks every field against [`TRACKER_BOUNDS`] and the look-ahead range; the error names
    /// the field and its value.
    pub fn validate(&self) -> Result<(), VehicleError> {
        bounds::check_all(
            "tracker",
            TRACKER_BOUNDS,
            &[
                ("lookahead_min_m", self.lookahead_min_m),
                ("lookahead_time_s", self.lookahead_time_s),
                ("lookahead_max_m", self.lookahead_max_m),
                ("speed_kp_per_s", self.speed_kp_per_s),
                ("speed_ki_per_s2", self.speed_ki_per_s2),
                ("speed_kd", self.speed_kd),
                ("speed_integral_band_mps", self.speed_integral_band_mps),
                ("max_accel_mps2", self.max_accel_mps2),
                ("max_decel_mps2", self.max_decel_mps2),
                ("friction_coefficient", self.friction_coefficient),
                ("stop_speed_mps", self.stop_speed_mps),
            ],
        )?;
        if self.lookahead_max_m < self.lookahead_min_m {
            return Err(VehicleError::invalid(
                "tracker.lookahead_max_m",
                self.lookahead_max_m,
                format!(
                    "must be >= tracker.lookahead_min_m = {}",
                    self.lookahead_min_m
                ),
            ));
        }
        Ok(())
    }
}

/// PID speed controller with conditional-integration anti-windup and torque allocation.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeedController {
    params: TrackerParams,
    vehicle: VehicleParams,
    integral_m: f64,
    previous_speed_mps: Option<f64>,
}

impl SpeedController {
    /// A controller for a car with these parameters.
    pub(crate) fn new(params: TrackerParams, vehicle: &VehicleParams) -> Self {
        Self {
            params,
            vehicle: vehicle.clone(),
            integral_m: 0.0,
            previous_speed_mps: None,
        }
    }

    /// Forgets the integral and derivative memory.
    pub fn reset(&mut self) {
        self.integral_m = 0.0;
        self.previous_speed_mps = None;
    }

    /// Acceleration demand (m/s², clamped to [−max_decel, max_accel]) for a speed error, on
    /// top of a feed-forward acceleration `feedforward_mps2`.
    ///
    /// u = a_ff + K_p e + K_i ∫e dt − K_d dv/dt. Anti-windup by conditional integration: the
    /// error is integrated only inside the band |e| < `speed_integral_band_mps`, and then only if
    /// the output is not saturated or if integrating moves it back inside.
    pub(crate) fn acceleration_demand_mps2(
        &mut self,
        target_mps: f64,
        feedforward_mps2: f64,
        speed_mps: f64,
        dt_s: f64,
    ) -> f64 {
        let p = &self.params;
        let error = target_mps - speed_mps;
        let derivative = match self.previous_speed_mps {
            Some(prev) if dt_s > 0.0 => (speed_mps - prev) / dt_s,
            _ => 0.0,
        };
        self.previous_speed_mps = Some(speed_mps);
        let law = |integral: f64| {
            feedforward_mps2 + p.speed_kp_per_s * error + p.speed_ki_per_s2 * integral
                - p.speed_kd * derivative
        };
        if error.abs() < p.speed_integral_band_mps && dt_s.is_finite() {
            let candidate_integral = self.integral_m + error * dt_s;
            let unsaturated = law(candidate_integral);
            let saturated_high = unsaturated > p.max_accel_mps2;
            let saturated_low = unsaturated < -p.max_decel_mps2;
            if (!saturated_high && !saturated_low)
                || (saturated_high && error < 0.0)
                || (saturated_low && error > 0.0)
            {
                self.integral_m = candidate_integral;
            }
        }
        let output = law(self.integral_m);
        if output.is_finite() {
            output.clamp(-p.max_decel_mps2, p.max_accel_mps2)
        } else {
            -p.max_decel_mps2
        }
    }

    /// Estimated normal load of each wheel (FL, FR, RL, RR) under longitudinal acceleration
    /// `accel_mps2`: static loads plus the pitch transfer m·a·h / L, floored at 0 (N).
    pub(crate) fn estimated_wheel_loads_n(&self, accel_mps2: f64) -> [f64; 4] {
        let v = &self.vehicle;
        let l = v.wheelbase_m();
        let transfer = v.mass_kg * accel_mps2 * v.cog_height_m / l;
        let front =
            (0.5 * (v.mass_kg * GRAVITY_MPS2 * v.cog_to_rear_axle_m / l - transfer)).max(0.0);
        let rear =
            (0.5 * (v.mass_kg * GRAVITY_MPS2 * v.cog_to_front_axle_m / l + transfer)).max(0.0);
        [front, front, rear, rear]
    }

    /// Wheel torques realising `accel_mps2`: total force m·a; drive split by the vehicle's drive
    /// share, brakes in proportion to the estimated loads; each wheel limited to μ·Fz·r and to
    /// its actuator limit.
    pub(crate) fn torques_for(&self, accel_mps2: f64) -> ([f64; 4], [f64; 4]) {
        let v = &self.vehicle;
        let r = v.wheel_radius_m;
        let mu = self.params.friction_coefficient;
        let loads = self.estimated_wheel_loads_n(accel_mps2);
        let force = v.mass_kg * accel_mps2;
        let mut drive = [0.0; 4];
        let mut brake = [0.0; 4];
        if force >= 0.0 {
            for (i, torque) in drive.iter_mut().enumerate() {
                let share = if i < 2 {
                    v.drive_torque_front_share
                } else {
                    1.0 - v.drive_torque_front_share
                };
                let wanted = 0.5 * share * force * r;
                *torque = wanted
                    .min(mu * loads[i] * r)
                    .min(v.max_drive_torque_wheel_nm(i));
            }
        } else {
            let total_load: f64 = loads.iter().sum();
            if total_load > 0.0 {
                for (i, torque) in brake.iter_mut().enumerate() {
                    let wanted = -force * r * loads[i] / total_load;
                    *torque = wanted
                        .min(mu * loads[i] * r)
                        .min(v.max_brake_torque_wheel_nm(i));
                }
            }
        }
        (drive, brake)
    }

    /// Torques holding a stopped car: half the transmittable brake torque on every wheel.
    pub(crate) fn holding_brake_nm(&self) -> [f64; 4] {
        let loads = self.estimated_wheel_loads_n(0.0);
        let mut brake = [0.0; 4];
        for (i, torque) in brake.iter_mut().enumerate() {
            *torque =
                (0.5 * self.params.friction_coefficient * loads[i] * self.vehicle.wheel_radius_m)
                    .min(self.vehicle.max_brake_torque_wheel_nm(i));
        }
        brake
    }

    /// Drive / brake torques tracking `target_mps` (wheel order FL, FR, RL, RR).
    pub(crate) fn update(
        &mut self,
        target_mps: f64,
        speed_mps: f64,
        dt_s: f64,
    ) -> ([f64; 4], [f64; 4]) {
        self.update_with_feedforward(target_mps, 0.0, speed_mps, dt_s)
    }

    /// [`update`](Self::update) with a feed-forward acceleration (m/s²).
    pub(crate) fn update_with_feedforward(
        &mut self,
        target_mps: f64,
        feedforward_mps2: f64,
        speed_mps: f64,
        dt_s: f64,
    ) -> ([f64; 4], [f64; 4]) {
        let target = if target_mps.is_finite() {
            target_mps.max(0.0)
        } else {
            0.0
        };
        let feedforward = if feedforward_mps2.is_finite() {
            feedforward_mps2
        } else {
            0.0
        };
        if target <= self.params.stop_speed_mps && speed_mps <= self.params.stop_speed_mps {
            self.integral_m = 0.0;
            self.previous_speed_mps = Some(speed_mps);
            return ([0.0; 4], self.holding_brake_nm());
        }
        let accel = self.acceleration_demand_mps2(target, feedforward, speed_mps, dt_s);
        self.torques_for(accel)
    }
}

/// Where the tracker aimed during its last update (for logging).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TrackerDebug {
    /// Look-ahead point (m).
    pub lookahead_point_m: [f64; 2],
    /// Look-ahead distance L_d used (m).
    pub lookahead_m: f64,
    /// Target speed used (m/s).
    pub target_speed_mps: f64,
    /// Distance from the CoG to the path (m, positive when the path is to the left).
    pub cross_track_error_m: f64,
}

/// Pure pursuit + speed PID.
#[derive(Clone, Debug, PartialEq)]
pub struct Tracker {
    params: TrackerParams,
    wheelbase_m: f64,
    rear_axle_offset_m: f64,
    speed: SpeedController,
    debug: TrackerDebug,
}

/// Largest coordinate magnitude (m) up to which [`project`] skips segments by their bounding
/// boxes; beyond it every segment is computed (the skip's rounding margin assumes this scale).
const PRUNE_COORDINATE_LIMIT_M: f64 = 1e7;

/// Absolute margin (m) of the bounding-box skip in [`project`]: far above the rounding of the
/// projected point (a few ulps of coordinates below [`PRUNE_COORDINATE_LIMIT_M`], ~1e-8 m).
const PRUNE_MARGIN_M: f64 = 1e-6;

/// Whether the axis-aligned box around `a` and `b` lies farther than `distance_m` from
/// (`x`, `y`) along X or along Y (both points beyond it on the same side): then every point of
/// the segment is farther than `distance_m`. Plain comparisons, cheapest when the path runs
/// along X.
fn box_beyond(
    a: &mergesim_types::PathPoint,
    b: &mergesim_types::PathPoint,
    x: f64,
    y: f64,
    distance_m: f64,
) -> bool {
    (a.x_m - x > distance_m && b.x_m - x > distance_m)
        || (x - a.x_m > distance_m && x - b.x_m > distance_m)
        || (a.y_m - y > distance_m && b.y_m - y > distance_m)
        || (y - a.y_m > distance_m && y - b.y_m > distance_m)
}

/// Whether every point of `path` is within [`PRUNE_COORDINATE_LIMIT_M`] (so finite), the
/// condition of [`project`]'s bounding-box skip.
fn path_is_prunable(path: &[mergesim_types::PathPoint]) -> bool {
    path.iter()
        .all(|p| p.x_m.abs() <= PRUNE_COORDINATE_LIMIT_M && p.y_m.abs() <= PRUNE_COORDINATE_LIMIT_M)
}

/// Projection of a point on a polyline: segment index, parameter along it (clamped to [0, 1]
/// except before the first and after the last point), squared distance.
///
/// Segments are visited in order and the first one with the smallest squared distance wins.
/// An inner segment whose bounding box is, by a margin, farther than the best distance so far
/// cannot win (its computed squared distance would be larger), so it is skipped without the
/// projection: the result is bit for bit the one of computing every segment.
///
/// `path_is_prunable` must be [`path_is_prunable`] of `path` (computed once per path by the
/// caller).
fn project(
    path: &[mergesim_types::PathPoint],
    path_is_prunable: bool,
    x: f64,
    y: f64,
) -> (usize, f64, f64) {
    let mut best = (0, 0.0, f64::INFINITY);
    // Distances beyond this cannot beat `best` (m); infinite until a first candidate.
    let mut skip_beyond_m = f64::INFINITY;
    let may_skip = path_is_prunable
        && x.abs() <= PRUNE_COORDINATE_LIMIT_M
        && y.abs() <= PRUNE_COORDINATE_LIMIT_M;
    let last = path.len().saturating_sub(2);
    for i in 0..path.len().saturating_sub(1) {
        let (a, b) = (&path[i], &path[i + 1]);
        // The first and last segments extend beyond their points: never skipped.
        if may_skip && i != 0 && i != last && box_beyond(a, b, x, y, skip_beyond_m) {
            continue;
        }
        let (dx, dy) = (b.x_m - a.x_m, b.y_m - a.y_m);
        let len_sq = dx * dx + dy * dy;
        let mut t = if len_sq > 0.0 {
            ((x - a.x_m) * dx + (y - a.y_m) * dy) / len_sq
        } else {
            0.0
        };
        let lo = if i == 0 { f64::NEG_INFINITY } else { 0.0 };
        let hi = if i == last { f64::INFINITY } else { 1.0 };
        t = t.clamp(lo, hi);
        let (px, py) = (a.x_m + t * dx, a.y_m + t * dy);
        let d = (px - x) * (px - x) + (py - y) * (py - y);
        if d < best.2 {
            best = (i, t, d);
            skip_beyond_m = d.sqrt() * (1.0 + 1e-9) + PRUNE_MARGIN_M;
        }
    }
    best
}

/// The point `distance_m` further along the path from (segment, t); beyond the last point the
/// last segment is extended.
fn walk(path: &[mergesim_types::PathPoint], segment: usize, t: f64, distance_m: f64) -> [f64; 2] {
    let mut remaining = distance_m;
    let mut i = segment;
    let mut t = t;
    loop {
        let (a, b) = (&path[i], &path[i + 1]);
        let (dx, dy) = (b.x_m - a.x_m, b.y_m - a.y_m);
        let len = dx.hypot(dy);
        let left_on_segment = (1.0 - t) * len;
        let is_last = i + 2 >= path.len();
        if remaining <= left_on_segment || is_last {
            let s = if len > 0.0 { t + remaining / len } else { 0.0 };
            return [a.x_m + s * dx, a.y_m + s * dy];
        }
        remaining -= left_on_segment.max(0.0);
        i += 1;
        t = 0.0;
    }
}

impl Tracker {
    /// A tracker for a car with these parameters (see [`TrackerParams::validate`]).
    pub fn new(params: TrackerParams, vehicle: &VehicleParams) -> Self {
        Self {
            wheelbase_m: vehicle.wheelbase_m(),
            rear_axle_offset_m: vehicle.cog_to_rear_axle_m,
            speed: SpeedController::new(params.clone(), vehicle),
            params,
            debug: TrackerDebug::default(),
        }
    }

    /// [`Tracker::new`] after validating both parameter sets.
    pub fn try_new(params: TrackerParams, vehicle: &VehicleParams) -> Result<Self, VehicleError> {
        params.validate()?;
        vehicle.validate()?;
        Ok(Self::new(params, vehicle))
    }

    /// The tuning.
    pub fn params(&self) -> &TrackerParams {
        &self.params
    }

    /// What the last update aimed at.
    pub fn debug(&self) -> TrackerDebug {
        self.debug
    }

    /// Forgets the speed loop's memory.
    pub fn reset(&mut self) {
        self.speed.reset();
    }

    /// Controls following `path` from state `kin`. With fewer than two usable path points (or a
    /// non-finite state) the car keeps its steering and brakes to a stop.
    pub fn update(
        &mut self,
        kin: &Kinematics,
        path: &[mergesim_types::PathPoint],
        dt_s: f64,
    ) -> Controls {
        let finite_state = [kin.x_m, kin.y_m, kin.yaw_rad, kin.speed_mps]
            .iter()
            .all(|v| v.is_finite());
        let finite_path = path
            .iter()
            .all(|p| p.x_m.is_finite() && p.y_m.is_finite() && p.speed_mps.is_finite());
        if path.len() < 2 || !finite_state || !finite_path {
            let (drive, brake) = self.speed.update(0.0, kin.speed_mps.max(0.0), dt_s);
            self.debug = TrackerDebug::default();
            return Controls {
                steer_rad: kin.steer_rad,
                drive_torque_nm: drive,
                brake_torque_nm: brake,
            };
        }
        let (s, c) = kin.yaw_rad.sin_cos();
        // Steering: pure pursuit from the rear axle.
        let rear = [
            kin.x_m - self.rear_axle_offset_m * c,
            kin.y_m - self.rear_axle_offset_m * s,
        ];
        let p = &self.params;
        let lookahead = (p.lookahead_min_m + p.lookahead_time_s * kin.speed_mps.max(0.0))
            .clamp(p.lookahead_min_m, p.lookahead_max_m);
        let prunable = path_is_prunable(path);
        let (seg, t, _) = project(path, prunable, rear[0], rear[1]);
        let target = walk(path, seg, t, lookahead);
        let (dx, dy) = (target[0] - rear[0], target[1] - rear[1]);
        let distance = dx.hypot(dy).max(1e-3);
        let alpha = mergesim_types::angle::wrap_angle_rad(dy.atan2(dx) - kin.yaw_rad);
        let steer = (2.0 * self.wheelbase_m * alpha.sin() / distance).atan();

        // Speed: the path point nearest ahead of the CoG.
        let (seg_cog, t_cog, dist_sq) = project(path, prunable, kin.x_m, kin.y_m);
        let ahead = if seg_cog == 0 && t_cog < 0.0 {
            0
        } else {
            (seg_cog + 1).min(path.len() - 1)
        };
        let target_speed = path[ahead].speed_mps;
        // Feed-forward: the profile's acceleration on the current segment,
        // v dv/ds = (v_b² − v_a²) / (2 |ab|).
        let (a, b) = (&path[seg_cog], &path[seg_cog + 1]);
        let segment_m = (b.x_m - a.x_m).hypot(b.y_m - a.y_m);
        let feedforward = if self.params.speed_feedforward && segment_m > 1e-3 {
            (b.speed_mps * b.speed_mps - a.speed_mps * a.speed_mps) / (2.0 * segment_m)
        } else {
            0.0
        };
        let (drive, brake) =
            self.speed
                .update_with_feedforward(target_speed, feedforward, kin.speed_mps, dt_s);

        let side = (b.x_m - a.x_m) * (kin.y_m - a.y_m) - (b.y_m - a.y_m) * (kin.x_m - a.x_m);
        self.debug = TrackerDebug {
            lookahead_point_m: target,
            lookahead_m: lookahead,
            target_speed_mps: target_speed,
            cross_track_error_m: -side.signum() * dist_sq.sqrt(),
        };
        Controls {
            steer_rad: steer,
            drive_torque_nm: drive,
            brake_torque_nm: brake,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(x: f64, y: f64, v: f64) -> mergesim_types::PathPoint {
        mergesim_types::PathPoint {
            x_m: x,
            y_m: y,
            speed_mps: v,
            t_s: 0.0,
        }
    }

    #[test]
    fn pure_pursuit_steers_onto_the_circle_through_the_target() {
        // Rear axle at the origin heading +X; a target at (d cos a, d sin a) lies on the circle
        // of radius R = d / (2 sin a) tangent to the heading: the bicycle needs δ = atan(L/R).
        let vehicle = VehicleParams::default();
        let params = TrackerParams {
            lookahead_min_m: 10.0,
            lookahead_time_s: 0.0,
            ..TrackerParams::default()
        };
        let mut tracker = Tracker::new(params, &vehicle);
        let lr = vehicle.cog_to_rear_axle_m;
        let kin = Kinematics {
            x_m: lr,
            speed_mps: 10.0,
            ..Kinematics::default()
        };
        let a: f64 = 0.2;
        // A straight path from the rear axle through the target.
        let path = [
            point(0.0, 0.0, 10.0),
            point(20.0 * a.cos(), 20.0 * a.sin(), 10.0),
        ];
        let controls = tracker.update(&kin, &path, 0.01);
        let radius = 10.0 / (2.0 * a.sin());
        let expected = (vehicle.wheelbase_m() / radius).atan();
        assert!(
            (controls.steer_rad - expected).abs() < 1e-9,
            "{} vs {expected}",
            controls.steer_rad
        );
    }

    #[test]
    fn the_box_skip_of_project_changes_no_bit() {
        // A small LCG: paths that curve, double back, repeat points; points near and far.
        let mut state: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..400 {
            let n = 2 + case % 25;
            let (mut x, mut y, mut heading) = (1000.0 * next() - 500.0, 20.0 * next(), 0.0);
            let mut path = Vec::with_capacity(n);
            for _ in 0..n {
                path.push(point(x, y, 10.0));
                heading += (next() - 0.5) * if case % 3 == 0 { 3.0 } else { 0.3 };
                let step_m = if next() < 0.1 { 0.0 } else { 2.5 * next() };
                x += step_m * f64::cos(heading);
                y += step_m * f64::sin(heading);
            }
            assert!(path_is_prunable(&path));
            for _ in 0..50 {
                let q = &path[(next() * n as f64) as usize % n];
                let spread_m = [0.01, 1.0, 10.0, 100.0][(next() * 4.0) as usize % 4];
                let (qx, qy) = (
                    q.x_m + spread_m * (next() - 0.5),
                    q.y_m + spread_m * (next() - 0.5),
                );
                let pruned = project(&path, true, qx, qy);
                let exhaustive = project(&path, false, qx, qy);
                assert_eq!(pruned.0, exhaustive.0);
                assert_eq!(pruned.1.to_bits(), exhaustive.1.to_bits());
                assert_eq!(pruned.2.to_bits(), exhaustive.2.to_bits());
            }
        }
    }

    #[test]
    fn anti_windup_stops_integrating_while_saturated() {
        let vehicle = VehicleParams::default();
        // A tight actuator limit so that a small error (inside the integration band) saturates.
        let params = TrackerParams {
            max_accel_mps2: 0.1,
            ..TrackerParams::default()
        };
        let mut pid = SpeedController::new(params.clone(), &vehicle);
        for _ in 0..1000 {
            let a = pid.acceleration_demand_mps2(10.5, 0.0, 10.0, 0.01);
            assert_eq!(a, params.max_accel_mps2);
        }
        assert_eq!(pid.integral_m, 0.0);
        // As soon as the error reverses the output leaves saturation immediately.
        let a = pid.acceleration_demand_mps2(10.0, 0.0, 10.5, 0.01);
        assert!(a < 0.0);
        // Outside the band nothing is integrated either; inside it, it is.
        let mut pid = SpeedController::new(TrackerParams::default(), &vehicle);
        let _ = pid.acceleration_demand_mps2(15.0, 0.0, 10.0, 0.01);
        assert_eq!(pid.integral_m, 0.0);
        let _ = pid.acceleration_demand_mps2(10.5, 0.0, 10.0, 0.01);
        assert!((pid.integral_m - 0.005).abs() < 1e-15);
    }

    #[test]
    fn torques_respect_tyre_limit() {
        let vehicle = VehicleParams::default();
        let pid = SpeedController::new(TrackerParams::default(), &vehicle);
        let (drive, brake) = pid.torques_for(30.0);
        let loads = pid.estimated_wheel_loads_n(30.0);
        for i in 0..4 {
            assert!(drive[i] <= 0.8 * loads[i] * vehicle.wheel_radius_m + 1e-9);
            assert_eq!(brake[i], 0.0);
        }
        // Rear-wheel drive: nothing on the front.
        assert_eq!(drive[0], 0.0);
        let (drive, brake) = pid.torques_for(-2.0);
        assert_eq!(drive, [0.0; 4]);
        let total: f64 = brake.iter().sum();
        assert!((total - vehicle.mass_kg * 2.0 * vehicle.wheel_radius_m).abs() < 1e-6);
    }
}
