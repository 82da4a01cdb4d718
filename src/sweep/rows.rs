//! One run of a sweep: its status, its figures, its row (in the aggregate and in the JSONL).

use serde::{Deserialize, Serialize};

use crate::summary::RunSummary;

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RunStatus {
    /// Simulated to the end.
    Completed,
    /// The World returned an error.
    Diverged,
    /// The run panicked (a bug; counted as diverged too).
    Panicked,
}

/// The safety and motion figures of a completed run (the fields of [`RunSummary`] a sweep
/// aggregates; equal to what `merge_sim run --seed <seed> --json` reports).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunMetrics {
    /// Collision events (vehicle–vehicle and vehicle–road edge).
    pub collisions: u64,
    /// Near miss without collision (min TTC or min gap below its threshold).
    pub near_miss: bool,
    /// Minimum TTC (s); `None`: no pair ever closing within the horizon.
    pub min_ttc_s: Option<f64>,
    /// Minimum gap between any two bodies (m).
    pub min_gap_m: Option<f64>,
    /// Time with TTC below the threshold (s).
    pub tet_s: f64,
    /// Largest |yaw rate| of any vehicle (rad/s).
    pub peak_yaw_rate_radps: f64,
    /// Largest |sideslip| of any vehicle (rad).
    pub peak_sideslip_rad: f64,
    /// Largest |yaw| of any vehicle (rad).
    pub peak_yaw_rad: f64,
    /// Lowest speed of any vehicle (m/s): how hard somebody had to brake.
    pub min_speed_mps: f64,
    /// Yaw-rate sign changes, summed over the vehicles.
    pub yaw_rate_sign_changes: u64,
    /// Planner cycles that fell back.
    pub fallbacks: u64,
    /// Planner cycles.
    pub plans: u64,
}

impl RunMetrics {
    /// The figures of a run summary.
    pub fn of(summary: &RunSummary) -> Self {
        let peak = |f: fn(&sim::metrics::VehicleMetricsSummary) -> f64| {
            summary.vehicles.iter().map(f).fold(0.0, f64::max)
        };
        RunMetrics {
            collisions: summary.collisions as u64,
            near_miss: summary.near_miss,
            min_ttc_s: summary.min_ttc_s,
            min_gap_m: summary.min_gap_m,
            tet_s: summary.tet_s,
            peak_yaw_rate_radps: peak(|v| v.max_abs_yaw_rate_radps),
            peak_sideslip_rad: peak(|v| v.max_abs_sideslip_rad),
            peak_yaw_rad: peak(|v| v.max_abs_yaw_rad),
            min_speed_mps: summary
                .vehicles
                .iter()
                .map(|v| v.min_speed_mps)
                .fold(f64::INFINITY, f64::min),
            yaw_rate_sign_changes: summary
                .vehicles
                .iter()
                .map(|v| u64::from(v.yaw_rate_sign_changes))
                .sum(),
            fallbacks: summary.planner_stats.fallbacks,
            plans: summary.planner_stats.plans,
        }
    }
}

/// One run of a sweep (one JSONL line, without the wall time; one element of `samples`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunRow {
    /// Instance index i in `0..runs`.
    pub instance: u64,
    /// The run's seed, [`instance_seed`](super::instance_seed)`(K, i)`: `merge_sim run --seed <seed>` replays it.
    pub seed: u64,
    /// How it ended.
    pub status: RunStatus,
    /// The error of a diverged or panicked run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The figures of a completed run (absent otherwise).
    #[serde(flatten)]
    pub metrics: Option<RunMetrics>,
}

/// A JSONL line: a row with its context and wall time.
#[derive(Serialize)]
pub(super) struct JsonlLine<'a> {
    pub(super) scenario: &'a str,
    pub(super) planner: &'a str,
    #[serde(flatten)]
    pub(super) row: &'a RunRow,
    pub(super) wall_time_s: f64,
}
