//! Per-vehicle motion, comfort and oscillation metrics (the paper's Table / Figs.
//! 7–9 report peak sideslip, yaw and yaw rate, and the speed profile).
//!
//! [`VehicleMetrics`] is fed one [`TimeSeriesRow`] per logged instant and keeps running figures,
//! so memory does not grow with the run length.
//!
//! Integrals treat the samples as a piecewise-linear signal and integrate that exactly:
//! - ∫ a² dt over an interval with end values a₀, a₁ is Δt·(a₀² + a₀a₁ + a₁²)/3;
//! - ∫ |r| dt is Δt·(|r₀| + |r₁|)/2 when r keeps its sign, and Δt·(r₀² + r₁²)/(2(|r₀| + |r₁|))
//!   when it crosses zero inside the interval (plain trapezoids would over-count the crossing).
//!
//! Jerk is the finite difference of consecutive acceleration samples, constant on each interval.
//! RMS values are √(∫ x² dt / duration); with a single sample (no duration) the RMS of the
//! acceleration is its magnitude and the jerk figures are 0.

use mergesim_types::InvalidParameter;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::outcome::TimeSeriesRow;
use crate::paper_metrics::{PaperMetrics, PaperMetricsSummary};

/// Thresholds and windows of the metrics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MetricsParams {
    /// A yaw-rate sign change is counted only when |r| exceeds this with the sign opposite to
    /// the last counted one (hysteresis), so noise around zero does not count (rad/s).
    /// 0.02 rad/s is about a tenth of the yaw-rate peak of a 4 s single lane change at 20 m/s.
    pub yaw_rate_sign_threshold_radps: f64,
    /// Optional `[x_start_m, x_end_m]` window (e.g. the merge section) in which the oscillation
    /// figures are also computed separately. Samples count when x lies in the window;
    /// intervals count when the mean x of their end samples does.
    pub oscillation_window_x_m: Option<[f64; 2]>,
}

impl Default for MetricsParams {
    fn default() -> Self {
        Self {
            yaw_rate_sign_threshold_radps: 0.02,
            oscillation_window_x_m: None,
        }
    }
}

impl MetricsParams {
    /// Checks every field; the error names the field.
    pub fn validate(&self) -> Result<(), MetricsError> {
        let thr = self.yaw_rate_sign_threshold_radps;
        if !(thr.is_finite() && thr >= 0.0) {
            return Err(MetricsError::InvalidParameter(InvalidParameter::new(
                "metrics.yaw_rate_sign_threshold_radps",
                thr,
                "must be finite and >= 0",
            )));
        }
        if let Some([x0, x1]) = self.oscillation_window_x_m
            && !(x0.is_finite() && x1.is_finite() && x1 > x0)
        {
            return Err(MetricsError::InvalidParameter(InvalidParameter::new(
                "metrics.oscillation_window_x_m",
                x1,
                format!("must be finite with end > start = {x0}"),
            )));
        }
        Ok(())
    }
}

/// Everything that can go wrong with the metrics. Never a panic.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MetricsError {
    /// A parameter is out of range.
    #[error(transparent)]
    InvalidParameter(#[from] InvalidParameter),
    /// A sample field is NaN or infinite.
    #[error("non-finite sample field {field} = {value} at t = {t_s} s")]
    NonFinite {
        /// The field.
        field: &'static str,
        /// Its value.
        value: f64,
        /// The sample time.
        t_s: f64,
    },
    /// Sample times must strictly increase.
    #[error("sample time {t_s} s does not follow the previous one {previous_t_s} s")]
    TimeNotIncreasing {
        /// The new time.
        t_s: f64,
        /// The previous time.
        previous_t_s: f64,
    },
}

/// The first motion field of `s` that is NaN or infinite, as `(field name, value)`.
/// `planned_speed_mps` is not a motion figure and is not checked.
fn first_non_finite(s: &TimeSeriesRow) -> Option<(&'static str, f64)> {
    [
        ("t_s", s.t_s),
        ("x_m", s.x_m),
        ("y_m", s.y_m),
        ("yaw_rad", s.yaw_rad),
        ("yaw_rate_radps", s.yaw_rate_radps),
        ("sideslip_rad", s.sideslip_rad),
        ("speed_mps", s.speed_mps),
        ("accel_long_mps2", s.accel_long_mps2),
        ("accel_lat_mps2", s.accel_lat_mps2),
    ]
    .into_iter()
    .find(|(_, v)| !v.is_finite())
}

/// The metrics of one vehicle over a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VehicleMetricsSummary {
    /// Vehicle name.
    pub id: String,
    /// Number of samples.
    pub samples: u64,
    /// Time from the first to the last sample (s).
    pub duration_s: f64,
    /// Peak |sideslip| (rad).
    pub max_abs_sideslip_rad: f64,
    /// When it was first reached (s).
    pub t_max_abs_sideslip_s: f64,
    /// Peak |yaw|, yaw wrapped to (−π, π] (rad).
    pub max_abs_yaw_rad: f64,
    /// Peak |yaw rate| (rad/s).
    pub max_abs_yaw_rate_radps: f64,
    /// When it was first reached (s).
    pub t_max_abs_yaw_rate_s: f64,
    /// Minimum speed (m/s).
    pub min_speed_mps: f64,
    /// When it was first reached (s).
    pub t_min_speed_s: f64,
    /// Maximum speed (m/s).
    pub max_speed_mps: f64,
    /// Speed at the last sample (m/s).
    pub final_speed_mps: f64,
    /// Sum of the XY displacements between consecutive samples (m).
    pub path_length_m: f64,
    /// Yaw-rate sign changes beyond the threshold, with hysteresis.
    pub yaw_rate_sign_changes: u32,
    /// ∫ |yaw rate| dt (rad).
    pub integral_abs_yaw_rate_rad: f64,
    /// Sign changes inside the oscillation window, if one is configured.
    pub window_yaw_rate_sign_changes: Option<u32>,
    /// ∫ |yaw rate| dt inside the oscillation window, if one is configured (rad).
    pub window_integral_abs_yaw_rate_rad: Option<f64>,
    /// Peak |longitudinal acceleration| (m/s²).
    pub peak_abs_accel_long_mps2: f64,
    /// RMS longitudinal acceleration (m/s²).
    pub rms_accel_long_mps2: f64,
    /// Peak |lateral acceleration| (m/s²).
    pub peak_abs_accel_lat_mps2: f64,
    /// RMS lateral acceleration (m/s²).
    pub rms_accel_lat_mps2: f64,
    /// Peak |longitudinal jerk| (m/s³).
    pub peak_abs_jerk_long_mps3: f64,
    /// RMS longitudinal jerk (m/s³).
    pub rms_jerk_long_mps3: f64,
    /// Peak |lateral jerk| (m/s³).
    pub peak_abs_jerk_lat_mps3: f64,
    /// RMS lateral jerk (m/s³).
    pub rms_jerk_lat_mps3: f64,
    /// Whether the vehicle was involved in a collision (set by the caller).
    pub collided: bool,
    /// The paper's figures (slowing onset, winding in the merge zone, lane offset, divider
    /// crossing); null when the metrics were made without a road.
    #[serde(default)]
    pub paper_metrics: Option<PaperMetricsSummary>,
    /// Planning cycles of the vehicle's behaviour that count as planner cycles
    /// (`Behaviour::is_planner`; 0 for a human-driver model or a recorded vehicle).
    #[serde(default)]
    pub plan_cycles: u64,
    /// Of those, cycles whose path fit was limited by a bound
    /// (`OptimiserReport::path_fit_bound_active`: the potential-field planners' cubic of
    /// Eqs. 8–9 met its heading, curvature or curvature-rate bound).
    #[serde(default)]
    pub path_fit_bound_cycles: u64,
    /// `path_fit_bound_cycles / plan_cycles`; null without a planning cycle.
    #[serde(default)]
    pub path_fit_bound_share: Option<f64>,
    /// The same figures as they stood at the run's first contact (vehicle–vehicle or road
    /// edge, any vehicle): over the samples logged before it, so a peak reached while or after
    /// the bodies touch does not enter. Absent (`None`) when the run had no contact: the
    /// whole-run figures are then the pre-contact ones. Set by the run's log
    /// (`crate::run_log::RunLog`) with [`VehicleMetrics::summary`] at the first contact.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pre_contact: Option<Box<VehicleMetricsSummary>>,
}

impl VehicleMetricsSummary {
    /// The figures over the window before the run's first contact: [`Self::pre_contact`] if
    /// the run had a contact, else the whole-run figures themselves.
    pub fn before_first_contact(&self) -> &VehicleMetricsSummary {
        self.pre_contact.as_deref().unwrap_or(self)
    }
}

/// Hysteresis counter of sign changes of a signal beyond a threshold.
#[derive(Clone, Copy, Debug, Default)]
struct SignChangeCounter {
    last_sign_positive: Option<bool>,
    changes: u32,
}

impl SignChangeCounter {
    fn push(&mut self, value: f64, threshold: f64) {
        if value.abs() <= threshold {
            return;
        }
        let positive = value > 0.0;
        if self.last_sign_positive.is_some_and(|last| last != positive) {
            self.changes += 1;
        }
        self.last_sign_positive = Some(positive);
    }
}

/// Peak |x|, ∫x² dt of a piecewise-linear signal, and peak / ∫ of its finite-difference rate.
#[derive(Clone, Copy, Debug, Default)]
struct SignalStats {
    peak_abs: f64,
    integral_sq: f64,
    rate_peak_abs: f64,
    rate_integral_sq: f64,
}

impl SignalStats {
    fn first(&mut self, value: f64) {
        self.peak_abs = value.abs();
    }

    fn push(&mut self, previous: f64, value: f64, dt_s: f64) {
        self.peak_abs = self.peak_abs.max(value.abs());
        self.integral_sq += dt_s * (previous * previous + previous * value + value * value) / 3.0;
        let rate = (value - previous) / dt_s;
        self.rate_peak_abs = self.rate_peak_abs.max(rate.abs());
        self.rate_integral_sq += dt_s * rate * rate;
    }

    /// (RMS of the signal, RMS of its rate) over `duration_s`; `last` is used when there is no
    /// duration.
    fn rms(&self, duration_s: f64, last: f64) -> (f64, f64) {
        if duration_s > 0.0 {
            (
                (self.integral_sq / duration_s).sqrt(),
                (self.rate_integral_sq / duration_s).sqrt(),
            )
        } else {
            (last.abs(), 0.0)
        }
    }
}

/// ∫ |r| dt over one interval of a linearly interpolated signal (exact).
fn integral_abs_linear(r0: f64, r1: f64, dt_s: f64) -> f64 {
    if r0 * r1 >= 0.0 {
        0.5 * dt_s * (r0.abs() + r1.abs())
    } else {
        0.5 * dt_s * (r0 * r0 + r1 * r1) / (r0.abs() + r1.abs())
    }
}

/// Running metrics of one vehicle.
#[derive(Clone, Debug)]
pub struct VehicleMetrics {
    id: String,
    params: MetricsParams,
    first_t_s: Option<f64>,
    last: Option<TimeSeriesRow>,
    samples: u64,
    max_abs_sideslip_rad: f64,
    t_max_abs_sideslip_s: f64,
    max_abs_yaw_rad: f64,
    max_abs_yaw_rate_radps: f64,
    t_max_abs_yaw_rate_s: f64,
    min_speed_mps: f64,
    t_min_speed_s: f64,
    max_speed_mps: f64,
    path_length_m: f64,
    sign_changes: SignChangeCounter,
    integral_abs_yaw_rate_rad: f64,
    window_sign_changes: SignChangeCounter,
    window_integral_abs_yaw_rate_rad: f64,
    accel_long: SignalStats,
    accel_lat: SignalStats,
    collided: bool,
    paper: Option<PaperMetrics>,
    plan_cycles: u64,
    path_fit_bound_cycles: u64,
}

impl VehicleMetrics {
    /// Empty metrics for the vehicle named `id`, with the default parameters.
    pub fn new(id: impl Into<String>) -> Self {
        Self::empty(id.into(), MetricsParams::default())
    }

    /// Empty metrics for the vehicle named `id`, with `params` (validated).
    pub fn with_params(id: impl Into<String>, params: MetricsParams) -> Result<Self, MetricsError> {
        params.validate()?;
        Ok(Self::empty(id.into(), params))
    }

    fn empty(id: String, params: MetricsParams) -> Self {
        Self {
            id,
            params,
            first_t_s: None,
            last: None,
            samples: 0,
            max_abs_sideslip_rad: 0.0,
            t_max_abs_sideslip_s: 0.0,
            max_abs_yaw_rad: 0.0,
            max_abs_yaw_rate_radps: 0.0,
            t_max_abs_yaw_rate_s: 0.0,
            min_speed_mps: f64::INFINITY,
            t_min_speed_s: 0.0,
            max_speed_mps: 0.0,
            path_length_m: 0.0,
            sign_changes: SignChangeCounter::default(),
            integral_abs_yaw_rate_rad: 0.0,
            window_sign_changes: SignChangeCounter::default(),
            window_integral_abs_yaw_rate_rad: 0.0,
            accel_long: SignalStats::default(),
            accel_lat: SignalStats::default(),
            collided: false,
            paper: None,
            plan_cycles: 0,
            path_fit_bound_cycles: 0,
        }
    }

    /// The same metrics also computing the paper's figures on the road `lanes` against
    /// `target_speed_mps` ([`crate::paper_metrics`]).
    pub fn with_paper_metrics(
        mut self,
        lanes: std::sync::Arc<mergesim_types::lanes::LaneRoad>,
        target_speed_mps: f64,
    ) -> Self {
        self.paper = Some(PaperMetrics::new(lanes, target_speed_mps));
        self
    }

    /// The vehicle name.
    pub fn id(&self) -> &str {
        &self.id
    }

    /// Marks the vehicle as involved in a collision.
    pub fn set_collided(&mut self) {
        self.collided = true;
    }

    fn in_window(&self, x_m: f64) -> bool {
        self.params
            .oscillation_window_x_m
            .is_some_and(|[x0, x1]| x_m >= x0 && x_m <= x1)
    }

    /// Adds the sample of the next logged instant (times must strictly increase).
    pub fn push(&mut self, sample: &TimeSeriesRow) -> Result<(), MetricsError> {
        if let Some((field, value)) = first_non_finite(sample) {
            return Err(MetricsError::NonFinite {
                field,
                value,
                t_s: sample.t_s,
            });
        }
        if let Some(last) = &self.last
            && sample.t_s <= last.t_s
        {
            return Err(MetricsError::TimeNotIncreasing {
                t_s: sample.t_s,
                previous_t_s: last.t_s,
            });
        }

        let s = sample;
        let thr = self.params.yaw_rate_sign_threshold_radps;
        if s.sideslip_rad.abs() > self.max_abs_sideslip_rad || self.samples == 0 {
            self.max_abs_sideslip_rad = s.sideslip_rad.abs();
            self.t_max_abs_sideslip_s = s.t_s;
        }
        self.max_abs_yaw_rad = self
            .max_abs_yaw_rad
            .max(mergesim_types::angle::wrap_angle_rad(s.yaw_rad).abs());
        if s.yaw_rate_radps.abs() > self.max_abs_yaw_rate_radps || self.samples == 0 {
            self.max_abs_yaw_rate_radps = s.yaw_rate_radps.abs();
            self.t_max_abs_yaw_rate_s = s.t_s;
        }
        if s.speed_mps < self.min_speed_mps {
            self.min_speed_mps = s.speed_mps;
            self.t_min_speed_s = s.t_s;
        }
        self.max_speed_mps = self.max_speed_mps.max(s.speed_mps);
        self.sign_changes.push(s.yaw_rate_radps, thr);
        if self.in_window(s.x_m) {
            self.window_sign_changes.push(s.yaw_rate_radps, thr);
        }

        match &self.last {
            None => {
                self.first_t_s = Some(s.t_s);
                self.accel_long.first(s.accel_long_mps2);
                self.accel_lat.first(s.accel_lat_mps2);
            }
            Some(p) => {
                let dt_s = s.t_s - p.t_s;
                self.path_length_m += (s.x_m - p.x_m).hypot(s.y_m - p.y_m);
                let abs_r = integral_abs_linear(p.yaw_rate_radps, s.yaw_rate_radps, dt_s);
                self.integral_abs_yaw_rate_rad += abs_r;
                if self.in_window(0.5 * (p.x_m + s.x_m)) {
                    self.window_integral_abs_yaw_rate_rad += abs_r;
                }
                self.accel_long
                    .push(p.accel_long_mps2, s.accel_long_mps2, dt_s);
                self.accel_lat
                    .push(p.accel_lat_mps2, s.accel_lat_mps2, dt_s);
            }
        }
        if let Some(paper) = &mut self.paper {
            paper.push(s);
        }
        self.last = Some(s.clone());
        self.samples += 1;
        Ok(())
    }

    /// Counts one planning cycle of the vehicle's planner, and whether its path fit met a
    /// bound (`OptimiserReport::path_fit_bound_active`).
    pub fn push_plan_cycle(&mut self, path_fit_bound_active: bool) {
        self.plan_cycles += 1;
        self.path_fit_bound_cycles += u64::from(path_fit_bound_active);
    }

    /// Number of samples so far.
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// The figures so far. Before the first sample every figure is 0 and `samples` is 0.
    pub fn summary(&self) -> VehicleMetricsSummary {
        let (duration_s, last_accel_long, last_accel_lat, final_speed_mps) =
            match (self.first_t_s, &self.last) {
                (Some(first_t_s), Some(last)) => (
                    last.t_s - first_t_s,
                    last.accel_long_mps2,
                    last.accel_lat_mps2,
                    last.speed_mps,
                ),
                _ => (0.0, 0.0, 0.0, 0.0),
            };
        let min_speed_mps = if self.samples > 0 {
            self.min_speed_mps
        } else {
            0.0
        };
        let (rms_accel_long_mps2, rms_jerk_long_mps3) =
            self.accel_long.rms(duration_s, last_accel_long);
        let (rms_accel_lat_mps2, rms_jerk_lat_mps3) =
            self.accel_lat.rms(duration_s, last_accel_lat);
        let windowed = self.params.oscillation_window_x_m.is_some();
        VehicleMetricsSummary {
            id: self.id.clone(),
            samples: self.samples,
            duration_s,
            max_abs_sideslip_rad: self.max_abs_sideslip_rad,
            t_max_abs_sideslip_s: self.t_max_abs_sideslip_s,
            max_abs_yaw_rad: self.max_abs_yaw_rad,
            max_abs_yaw_rate_radps: self.max_abs_yaw_rate_radps,
            t_max_abs_yaw_rate_s: self.t_max_abs_yaw_rate_s,
            min_speed_mps,
            t_min_speed_s: self.t_min_speed_s,
            max_speed_mps: self.max_speed_mps,
            final_speed_mps,
            path_length_m: self.path_length_m,
            yaw_rate_sign_changes: self.sign_changes.changes,
            integral_abs_yaw_rate_rad: self.integral_abs_yaw_rate_rad,
            window_yaw_rate_sign_changes: windowed.then_some(self.window_sign_changes.changes),
            window_integral_abs_yaw_rate_rad: windowed
                .then_some(self.window_integral_abs_yaw_rate_rad),
            peak_abs_accel_long_mps2: self.accel_long.peak_abs,
            rms_accel_long_mps2,
            peak_abs_accel_lat_mps2: self.accel_lat.peak_abs,
            rms_accel_lat_mps2,
            peak_abs_jerk_long_mps3: self.accel_long.rate_peak_abs,
            rms_jerk_long_mps3,
            peak_abs_jerk_lat_mps3: self.accel_lat.rate_peak_abs,
            rms_jerk_lat_mps3,
            collided: self.collided,
            paper_metrics: self.paper.as_ref().map(PaperMetrics::summary),
            plan_cycles: self.plan_cycles,
            path_fit_bound_cycles: self.path_fit_bound_cycles,
            path_fit_bound_share: (self.plan_cycles > 0)
                .then(|| self.path_fit_bound_cycles as f64 / self.plan_cycles as f64),
            pre_contact: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integral_abs_linear_matches_geometry() {
        // Same sign: trapezoid.
        assert!((integral_abs_linear(1.0, 3.0, 2.0) - 4.0).abs() < 1e-12);
        // Crossing zero at the middle: two triangles of area ½·1·1.
        assert!((integral_abs_linear(-1.0, 1.0, 2.0) - 1.0).abs() < 1e-12);
        // Crossing at a quarter: triangles ½·0.5·1 + ½·1.5·3.
        assert!((integral_abs_linear(1.0, -3.0, 2.0) - (0.25 + 2.25)).abs() < 1e-12);
    }
}
