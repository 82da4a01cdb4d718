//! What a run produces: the outcome, its planner statistics and the time-series rows.

use serde::{Deserialize, Serialize};
use vehicles::Kinematics;

use crate::metrics::VehicleMetricsSummary;
use crate::safety::SafetySummary;
use crate::v2v::V2vStats;

/// One simulated vehicle at one logged instant (world frame, SI): a row of the time series
/// (`--csv`) and the sample the per-vehicle metrics ([`crate::metrics::VehicleMetrics`]) are
/// fed. The world makes one per vehicle and log instant ([`TimeSeriesRow::at`]) and hands it to
/// the observers in [`crate::observer::VehicleView::sample`].
///
/// Field order is the CSV's column order ([`TimeSeriesRow::CSV_HEADER`]) and the JSON's key
/// order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimeSeriesRow {
    /// Simulated time (s).
    pub t_s: f64,
    /// Vehicle name.
    pub vehicle: String,
    /// Position (m).
    pub x_m: f64,
    /// Position (m).
    pub y_m: f64,
    /// Heading (rad).
    pub yaw_rad: f64,
    /// Yaw rate (rad/s).
    pub yaw_rate_radps: f64,
    /// Sideslip angle β at the centre of gravity (rad).
    pub sideslip_rad: f64,
    /// Speed over ground (m/s).
    pub speed_mps: f64,
    /// Speed the current plan asks for now (m/s).
    pub planned_speed_mps: f64,
    /// Longitudinal acceleration, body frame (m/s²).
    pub accel_long_mps2: f64,
    /// Lateral acceleration, body frame (m/s²).
    pub accel_lat_mps2: f64,
}

impl TimeSeriesRow {
    /// The row of the vehicle named `vehicle` at time `t_s`, in the kinematic state
    /// `kinematics`, whose plan asks for `planned_speed_mps`.
    pub fn at(t_s: f64, vehicle: &str, kinematics: &Kinematics, planned_speed_mps: f64) -> Self {
        Self {
            t_s,
            vehicle: vehicle.to_string(),
            x_m: kinematics.x_m,
            y_m: kinematics.y_m,
            yaw_rad: kinematics.yaw_rad,
            yaw_rate_radps: kinematics.yaw_rate_radps,
            sideslip_rad: kinematics.sideslip_rad,
            speed_mps: kinematics.speed_mps,
            planned_speed_mps,
            accel_long_mps2: kinematics.accel_long_mps2,
            accel_lat_mps2: kinematics.accel_lat_mps2,
        }
    }

    /// CSV header, in the order of [`TimeSeriesRow::csv_line`].
    pub const CSV_HEADER: &'static str = "t_s,vehicle,x_m,y_m,yaw_rad,yaw_rate_radps,sideslip_rad,speed_mps,planned_speed_mps,accel_long_mps2,accel_lat_mps2";

    /// One CSV line (no newline).
    pub fn csv_line(&self) -> String {
        format!(
            "{:.4},{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
            self.t_s,
            self.vehicle,
            self.x_m,
            self.y_m,
            self.yaw_rad,
            self.yaw_rate_radps,
            self.sideslip_rad,
            self.speed_mps,
            self.planned_speed_mps,
            self.accel_long_mps2,
            self.accel_lat_mps2
        )
    }
}

/// Planner timing and fault counters over a run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlannerStats {
    /// Planning cycles run.
    pub plans: u64,
    /// Cycles that returned a fallback plan.
    pub fallbacks: u64,
    /// Cycles decided in a degraded mode (PF-ISO without any shared path around: V2V lost).
    #[serde(default)]
    pub degraded_plans: u64,
    /// Convex solves of the planners' optimisers, summed over the cycles (from
    /// `Behaviour::optimiser_report`; the speed optimisation's for the potential-field
    /// planners).
    #[serde(default)]
    pub optimiser_solves: u64,
    /// Cycles whose optimiser ran out of iterations before meeting its tolerance (the SCP of
    /// Eq. 10 at `max_scp_iterations`): how often the plan may be short of the optimum.
    #[serde(default)]
    pub optimiser_iteration_cap_cycles: u64,
    /// Median wall time of one cycle (µs). Wall-clock: not part of the determinism contract.
    pub p50_plan_us: f64,
    /// 99th percentile wall time of one cycle (µs).
    pub p99_plan_us: f64,
}

/// A recorded vehicle's box at one log instant, as the output keeps it for the GIF: named,
/// without the velocities of the [`crate::body_state::BodyState`] it is made from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordedPose {
    /// Simulated time (s).
    pub t_s: f64,
    /// Its name.
    pub vehicle: String,
    /// Centre (m).
    pub x_m: f64,
    /// Centre (m).
    pub y_m: f64,
    /// Heading (rad).
    pub yaw_rad: f64,
    /// Length (m).
    pub length_m: f64,
    /// Width (m).
    pub width_m: f64,
}

/// The result of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunOutcome {
    /// Simulated time (s).
    pub duration_s: f64,
    /// Exact safety results.
    pub safety: SafetySummary,
    /// Throughput, merging, delay and the safety figures per vehicle class
    /// (`crate::traffic_metrics`).
    #[serde(default)]
    pub traffic: crate::traffic_metrics::TrafficSummary,
    /// Per-vehicle metrics of the simulated vehicles, in vehicle order (recorded traffic has
    /// none, nor time-series rows).
    pub vehicles: Vec<VehicleMetricsSummary>,
    /// Planner counters.
    pub planner_stats: PlannerStats,
    /// V2V counters.
    pub v2v: V2vStats,
    /// Time series at the log period (empty unless requested).
    pub time_series: Vec<TimeSeriesRow>,
    /// Where the recorded traffic was at each log instant, kept with the time series (empty
    /// unless requested, or without recorded traffic): what the GIF draws of it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub recorded_track: Vec<RecordedPose>,
    /// The run's events (collisions, near misses, fallbacks, …), in time order; `Display`
    /// gives each one's event-log line.
    pub events: Vec<crate::event::SimEvent>,
    /// The goals of the vehicles that have one (`crate::goal`), in vehicle order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub goals: Vec<crate::goal::GoalOutcome>,
    /// Wall time per phase of the tick, if `RunOptions::profile` asked for it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<crate::profile::ProfileReport>,
}
