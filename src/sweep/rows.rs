//! One run of a sweep: its status, its figures, its row (in the aggregate and in the JSONL).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::VehicleRow;
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
    /// Planner cycles decided in a degraded mode (PF-ISO without any shared path around).
    #[serde(default)]
    pub degraded_plans: u64,
    /// Planner cycles.
    pub plans: u64,
    /// Safety-shield interventions over the vehicles (`[sim] shield`; 0 without one).
    #[serde(default)]
    pub shield_interventions: u64,
    /// Throughput through the merge (vehicles per hour, `sim::traffic_metrics`); `None` with
    /// fewer than two vehicles crossing its section, or on a road without an ending lane.
    #[serde(default)]
    pub throughput_vph: Option<f64>,
    /// Vehicles that started in an ending lane.
    #[serde(default)]
    pub merging_vehicles: u64,
    /// Of them, those that merged before their lane ended.
    #[serde(default)]
    pub merged_before_lane_end: u64,
    /// Mean delay against free flow over the vehicles (s).
    #[serde(default)]
    pub mean_delay_s: Option<f64>,
    /// The figures of a run on a CommonRoad road (`None` on any other road, and then not
    /// written): written flat beside the others, read back by [`RunRow`]'s reader.
    #[serde(skip)]
    pub commonroad: Option<CommonRoadFigures>,
}

/// The figures of a run on a CommonRoad road (as `merge_sim run --json` reports them): written
/// in the rows of a sweep of such a scenario only, so the rows of every other sweep are as
/// before.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CommonRoadFigures {
    /// How the file's recorded traffic moved: `none`, `replay` or `reactive`.
    pub recorded_traffic: String,
    /// Collisions in which a recorded vehicle ran into a simulated one from behind (counted
    /// apart from `collisions`).
    pub collisions_caused_by_replay: u64,
    /// Minimum distance between a simulated and a recorded vehicle's boxes (m); null when no
    /// recorded vehicle came within `pair_range_m` (or none is spawned: mode `none`).
    pub min_gap_to_recorded_m: Option<f64>,
    /// Minimum time to collision between a simulated and a recorded vehicle (s); null if no
    /// such pair was ever closing within the horizon.
    pub min_ttc_to_recorded_s: Option<f64>,
    /// Whether the ego reached its goal (the file's planning problem); null without a goal
    /// (a scenario TOML on a CommonRoad road).
    pub goal_reached: Option<bool>,
    /// When it first met its goal (s); null if it did not or has none.
    pub goal_time_s: Option<f64>,
}

impl CommonRoadFigures {
    /// The figures of a run summary, if its scenario is on a CommonRoad road.
    pub fn of(summary: &RunSummary) -> Option<Self> {
        Some(CommonRoadFigures {
            recorded_traffic: summary.recorded_traffic.clone()?,
            collisions_caused_by_replay: summary.collisions_caused_by_replay as u64,
            min_gap_to_recorded_m: summary.min_gap_to_recorded_m,
            min_ttc_to_recorded_s: summary.min_ttc_to_recorded_s,
            goal_reached: summary.goal_reached,
            goal_time_s: summary.goal_time_s,
        })
    }
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
            degraded_plans: summary.planner_stats.degraded_plans,
            plans: summary.planner_stats.plans,
            shield_interventions: summary.shield_interventions as u64,
            throughput_vph: summary.traffic.throughput_vph,
            merging_vehicles: u64::from(summary.traffic.merging),
            merged_before_lane_end: u64::from(summary.traffic.merged_before_lane_end),
            mean_delay_s: summary.traffic.mean_delay_s,
            commonroad: CommonRoadFigures::of(summary),
        }
    }
}

impl RunMetrics {
    /// Whether no pair was ever closing within the TTC horizon (`min_ttc_s` is `None`): the
    /// best value, +∞, not a missing one. Written beside `min_ttc_s` as `min_ttc_never`.
    pub fn min_ttc_never(&self) -> bool {
        self.min_ttc_s.is_none()
    }

    /// Whether no two bodies ever came within `[sim.safety] pair_range_m` (or the scenario has
    /// one vehicle): `min_gap_m` is `None`, meaning +∞. Written as `min_gap_never`.
    pub fn min_gap_never(&self) -> bool {
        self.min_gap_m.is_none()
    }
}

/// The run-level figures as written: each "never" flag beside the figures.
#[derive(Serialize)]
struct MetricsOut<'a> {
    #[serde(flatten)]
    metrics: &'a RunMetrics,
    min_ttc_never: bool,
    min_gap_never: bool,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    commonroad: Option<&'a CommonRoadFigures>,
}

/// A vehicle's figures as written: its figures and their "never" flags.
#[derive(Serialize)]
struct VehicleOut<'a> {
    #[serde(flatten)]
    row: &'a VehicleRow,
    slowing_onset_never: Option<bool>,
    divider_crossing_never: Option<bool>,
}

/// A vehicle's figures as read: the flags are recomputed from the figures, not trusted.
#[derive(Deserialize)]
struct VehicleIn {
    #[serde(flatten)]
    row: VehicleRow,
    #[serde(default, rename = "slowing_onset_never")]
    _slowing_onset_never: Option<bool>,
    #[serde(default, rename = "divider_crossing_never")]
    _divider_crossing_never: Option<bool>,
}

/// One run of a sweep: one planner on one instance (one JSONL line, without the wall time; one
/// element of `samples`). Its key is (`instance`, `planner`).
///
/// Written with a "never" flag beside each figure whose `null` means it never happened (so
/// +∞, the best or latest value, not a missing one): `min_ttc_never`, `min_gap_never` and per
/// vehicle `slowing_onset_never`, `divider_crossing_never` (null when the run kept no paper
/// figures). The flags are derived from the figures; reading ignores them.
///
/// Read strictly: a `completed` row must carry every figure, well formed (a malformed figure is
/// an error naming the instance, never a silently "diverged" run); a row without `planner` or
/// `drawn` was written by an older mergesim and is refused with a message saying so.
#[derive(Clone, Debug, PartialEq)]
pub struct RunRow {
    /// Instance index i in `0..runs`.
    pub instance: u64,
    /// The planner of the run (its name, or the scenario's own label: `pf-iso`, `mixed`).
    pub planner: String,
    /// The run's seed, [`instance_seed`](super::instance_seed)`(K, i)`: `merge_sim run --seed
    /// <seed>` replays it. A `0x` hex string in JSON (exact in every reader, pandas included);
    /// decimal strings and integers are read too.
    pub seed: u64,
    /// How it ended.
    pub status: RunStatus,
    /// The error of a diverged or panicked run.
    pub error: Option<String>,
    /// The values the scenario drew for this instance (see
    /// [`drawn_values`](super::drawn_values)); the same for every planner of an instance.
    pub drawn: BTreeMap<String, f64>,
    /// The figures of a completed run (absent otherwise).
    pub metrics: Option<RunMetrics>,
    /// Each vehicle's figures, in the scenario's order (empty unless completed).
    pub vehicles: Vec<VehicleRow>,
}

impl Serialize for RunRow {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        #[derive(Serialize)]
        struct Wire<'a> {
            instance: u64,
            planner: &'a str,
            #[serde(with = "crate::exact_seed")]
            seed: u64,
            status: RunStatus,
            #[serde(skip_serializing_if = "Option::is_none")]
            error: &'a Option<String>,
            drawn: &'a BTreeMap<String, f64>,
            #[serde(flatten)]
            metrics: Option<MetricsOut<'a>>,
            vehicles: Vec<VehicleOut<'a>>,
        }
        Wire {
            instance: self.instance,
            planner: &self.planner,
            seed: self.seed,
            status: self.status,
            error: &self.error,
            drawn: &self.drawn,
            metrics: self.metrics.as_ref().map(|m| MetricsOut {
                metrics: m,
                min_ttc_never: m.min_ttc_never(),
                min_gap_never: m.min_gap_never(),
                commonroad: m.commonroad.as_ref(),
            }),
            vehicles: self
                .vehicles
                .iter()
                .map(|v| VehicleOut {
                    row: v,
                    slowing_onset_never: v.slowing_onset_never(),
                    divider_crossing_never: v.divider_crossing_never(),
                })
                .collect(),
        }
        .serialize(serializer)
    }
}

/// Why a row written by an older mergesim cannot be read.
const OLD_FORMAT: &str = "written by an older mergesim (rows now carry `planner`, `drawn` and \
                          `vehicles`): start a new sweep (a new --jsonl file)";

impl<'de> Deserialize<'de> for RunRow {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        #[derive(Deserialize)]
        struct Raw {
            instance: u64,
            #[serde(default)]
            planner: Option<String>,
            #[serde(with = "crate::exact_seed")]
            seed: u64,
            status: RunStatus,
            #[serde(default)]
            error: Option<String>,
            #[serde(default)]
            drawn: Option<BTreeMap<String, f64>>,
            #[serde(default)]
            vehicles: Option<Vec<VehicleIn>>,
            #[serde(flatten)]
            rest: serde_json::Map<String, serde_json::Value>,
        }
        let raw = Raw::deserialize(deserializer)?;
        let instance = raw.instance;
        let raw_vehicles = raw
            .vehicles
            .map(|v| v.into_iter().map(|v| v.row).collect::<Vec<_>>());
        let (Some(planner), Some(drawn)) = (raw.planner, raw.drawn) else {
            return Err(D::Error::custom(format!(
                "instance {instance}: a row without `planner` or `drawn`, {OLD_FORMAT}"
            )));
        };
        let (metrics, vehicles) = match raw.status {
            RunStatus::Completed => {
                let malformed = |e: serde_json::Error| {
                    D::Error::custom(format!(
                        "instance {instance} ({planner}): a completed run with missing or \
                         malformed figures: {e}"
                    ))
                };
                let on_commonroad = raw.rest.contains_key("recorded_traffic");
                let rest = serde_json::Value::Object(raw.rest);
                let mut metrics = RunMetrics::deserialize(&rest).map_err(malformed)?;
                if on_commonroad {
                    metrics.commonroad =
                        Some(CommonRoadFigures::deserialize(&rest).map_err(malformed)?);
                }
                let vehicles = raw_vehicles.ok_or_else(|| {
                    D::Error::custom(format!(
                        "instance {instance} ({planner}): a completed run without `vehicles`, \
                         {OLD_FORMAT}"
                    ))
                })?;
                (Some(metrics), vehicles)
            }
            RunStatus::Diverged | RunStatus::Panicked => (None, raw_vehicles.unwrap_or_default()),
        };
        Ok(RunRow {
            instance,
            planner,
            seed: raw.seed,
            status: raw.status,
            error: raw.error,
            drawn,
            metrics,
            vehicles,
        })
    }
}

/// A JSONL line: a row with its sweep's identity and wall time.
#[derive(Serialize)]
pub(super) struct JsonlLine<'a> {
    pub(super) scenario: &'a str,
    pub(super) scenario_fingerprint: &'a str,
    pub(super) params: &'a str,
    pub(super) planners: &'a [String],
    #[serde(with = "crate::exact_seed")]
    pub(super) sweep_seed: u64,
    pub(super) total_runs: u64,
    #[serde(flatten)]
    pub(super) row: &'a RunRow,
    /// `None` (null) in the rows `merge-results --jsonl` writes: a shard's `--json` keeps no
    /// per-run wall times.
    pub(super) wall_time_s: Option<f64>,
}

/// A JSONL line read back (`--resume`): the identity of its sweep, the row and its wall time.
#[derive(Clone, Debug, Deserialize)]
pub struct JsonlRecord {
    /// Scenario name.
    pub scenario: String,
    /// Fingerprint of the nominal scenario.
    pub scenario_fingerprint: String,
    /// Planner parameter set.
    pub params: String,
    /// The planners of the sweep, the first the baseline (`None`: a line of an older mergesim,
    /// refused by the reader).
    #[serde(default)]
    pub planners: Option<Vec<String>>,
    /// Sweep seed K.
    #[serde(with = "crate::exact_seed")]
    pub sweep_seed: u64,
    /// Instances in the whole sweep.
    pub total_runs: u64,
    /// The run.
    #[serde(flatten)]
    pub row: RunRow,
    /// Wall time of the run (s); null (`None`) in the rows `merge_sim merge-results --jsonl`
    /// writes, as a shard's `--json` file keeps no per-run wall times.
    #[serde(default)]
    pub wall_time_s: Option<f64>,
}
