//! The aggregate of a sweep (or of one shard): counts, rates with Wilson intervals, nearest-rank
//! percentiles, means, and the rows it was made from; its identity, table and JSONL.

use scenarios::randomisation::fnv1a64;
use serde::{Deserialize, Serialize};

use super::rows::JsonlLine;
use super::statistics::{Z_95, mean, nearest_rank_percentile, wilson_interval};
use super::{PairedSweepPlan, RunMetrics, RunRow, RunStatus, Shard, SweepPlan};

/// The aggregate of a sweep or of one shard (the `--json` file). The per-run `samples` are
/// kept so that shards can be merged into exactly the unsharded aggregate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSummary {
    /// Scenario name.
    pub scenario: String,
    /// FNV-1a 64 of the nominal scenario's canonical TOML (hex): shards of different scenario
    /// files that share a name are not merged.
    pub scenario_fingerprint: String,
    /// Planner name (`pf-iso`, ..., or `mixed`).
    pub planner: String,
    /// Planner parameter set (`paper` or `mergesim`).
    pub params: String,
    /// Sweep seed K (a string in JSON: exact in every reader; integers are read too).
    #[serde(with = "crate::exact_seed")]
    pub seed: u64,
    /// Instances in the whole sweep.
    pub total_runs: u64,
    /// Which part of the sweep this is (`0/1`: all of it).
    pub shard: Shard,
    /// The instances of this part, `[start, end)`.
    pub instances: [u64; 2],
    /// Runs in this part that finished (completed or diverged).
    pub runs: u64,
    /// Instances of this part without a row: the sweep was interrupted before they finished
    /// (0 for a complete part; resume it with `merge_sim sweep … --resume`).
    #[serde(default)]
    pub missing_runs: u64,
    /// Runs that simulated to the end.
    pub completed: u64,
    /// Runs whose World returned an error or that panicked.
    pub diverged: u64,
    /// Of the diverged runs, those that panicked.
    pub panicked: u64,
    /// Completed runs with at least one collision.
    pub collisions: u64,
    /// `collisions / completed`.
    pub collision_rate: Option<f64>,
    /// 95 % Wilson score interval of the collision rate.
    pub collision_rate_ci95: Option<[f64; 2]>,
    /// Completed runs with a near miss (and no collision).
    pub near_misses: u64,
    /// `near_misses / completed`.
    pub near_miss_rate: Option<f64>,
    /// 95 % Wilson score interval of the near-miss rate.
    pub near_miss_rate_ci95: Option<[f64; 2]>,
    /// Values the percentiles are over: the completed runs, a "never" value counted as +∞.
    #[serde(default)]
    pub percentiles_n: u64,
    /// 5th percentile (nearest rank) of the runs' minimum TTC (s); a run without a closing pair
    /// counts as +∞, and `null` means the percentile itself is +∞ (or no completed run).
    pub min_ttc_s_p5: Option<f64>,
    /// Completed runs in which no pair was ever closing (`min_ttc_never`; +∞ in the percentile).
    #[serde(default)]
    pub runs_min_ttc_never: u64,
    /// 5th percentile (nearest rank) of the runs' minimum gap (m); a run in which no two bodies
    /// came within range counts as +∞.
    pub min_gap_m_p5: Option<f64>,
    /// Completed runs in which no two bodies came within range (`min_gap_never`; +∞ in the
    /// percentile).
    #[serde(default)]
    pub runs_min_gap_never: u64,
    /// Values each mean below is over: the completed runs (these figures are never null).
    #[serde(default)]
    pub means_n: u64,
    /// Mean over completed runs of the largest |yaw rate| of any vehicle (rad/s).
    pub mean_peak_yaw_rate_radps: Option<f64>,
    /// Mean over completed runs of the largest |sideslip| of any vehicle (rad).
    pub mean_peak_sideslip_rad: Option<f64>,
    /// Mean over completed runs of the largest |yaw| of any vehicle (rad).
    pub mean_peak_yaw_rad: Option<f64>,
    /// Mean over completed runs of the lowest speed of any vehicle (m/s).
    pub mean_min_speed_mps: Option<f64>,
    /// Planner fallback cycles, summed over the completed runs.
    pub fallbacks: u64,
    /// Completed runs with at least one fallback.
    pub runs_with_fallbacks: u64,
    /// How the recorded traffic of the scenario's CommonRoad road moved (`none`, `replay`,
    /// `reactive`), read off the completed runs; absent (with the four figures below) for a
    /// scenario on no CommonRoad road.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub recorded_traffic: Option<String>,
    /// Collisions caused by the replay of recorded traffic, summed over the completed runs
    /// (not in `collisions`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub collisions_caused_by_replay: Option<u64>,
    /// Completed runs with at least one collision caused by the replay.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runs_with_collisions_caused_by_replay: Option<u64>,
    /// Completed runs whose ego has a goal (the file's planning problem).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runs_with_goal: Option<u64>,
    /// Of those, the runs whose ego reached its goal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goals_reached: Option<u64>,
    /// Wall-clock time (s): of the sweep, or the sum over merged shards. Not reproducible.
    pub wall_time_s: f64,
    /// The runs, in instance order.
    pub samples: Vec<RunRow>,
}

/// One JSONL line (without the newline) of a run of the sweep `identity`.
pub fn jsonl_line(
    identity: &SweepIdentity,
    row: &RunRow,
    wall_time_s: f64,
) -> Result<String, serde_json::Error> {
    jsonl_line_with(identity, row, Some(wall_time_s))
}

/// [`jsonl_line`] with the run's wall time optional (null: unknown, as in merged shards).
pub(super) fn jsonl_line_with(
    identity: &SweepIdentity,
    row: &RunRow,
    wall_time_s: Option<f64>,
) -> Result<String, serde_json::Error> {
    serde_json::to_string(&JsonlLine {
        scenario: &identity.scenario,
        scenario_fingerprint: &identity.scenario_fingerprint,
        params: &identity.params,
        planners: &identity.planners,
        sweep_seed: identity.seed,
        total_runs: identity.total_runs,
        row,
        wall_time_s,
    })
}

/// What identifies a sweep (shared by its shards).
#[derive(Clone, Debug, PartialEq)]
pub struct SweepIdentity {
    /// Scenario name.
    pub scenario: String,
    /// See [`SweepSummary::scenario_fingerprint`].
    pub scenario_fingerprint: String,
    /// Planner parameter set.
    pub params: String,
    /// Planner name (of a multi-planner sweep: the names joined with commas).
    pub planner: String,
    /// Every planner of the sweep, the first the baseline (in each JSONL line: part of what
    /// identifies the sweep).
    pub planners: Vec<String>,
    /// Sweep seed.
    pub seed: u64,
    /// Instances in the whole sweep.
    pub total_runs: u64,
}

impl SweepIdentity {
    /// The identity of a plan.
    pub fn of(plan: &SweepPlan) -> Self {
        Self::of_paired(&PairedSweepPlan::from(plan))
    }

    /// The identity of a (multi-planner) plan.
    pub fn of_paired(plan: &PairedSweepPlan) -> Self {
        let canonical = plan.scenario.to_toml().unwrap_or_default();
        let planners = plan.labels();
        SweepIdentity {
            scenario: plan.scenario.name.clone(),
            scenario_fingerprint: format!("{:016x}", fnv1a64(&canonical)),
            params: plan.scenario.params.name().to_string(),
            planner: planners.join(","),
            planners,
            seed: plan.seed,
            total_runs: plan.runs,
        }
    }

    /// The identity of one planner's aggregate within this sweep.
    pub fn for_planner(&self, planner: &str) -> Self {
        SweepIdentity {
            planner: planner.to_string(),
            ..self.clone()
        }
    }
}

impl SweepSummary {
    /// The aggregate of `rows` (the instances `shard.instances(total_runs)`, in instance order).
    pub fn from_rows(
        identity: &SweepIdentity,
        shard: Shard,
        rows: Vec<RunRow>,
        wall_time_s: f64,
    ) -> Self {
        let range = shard.instances(identity.total_runs);
        let done: Vec<&RunMetrics> = rows.iter().filter_map(|r| r.metrics.as_ref()).collect();
        let completed = done.len() as u64;
        let count = |f: &dyn Fn(&RunMetrics) -> bool| done.iter().filter(|m| f(m)).count() as u64;
        let collisions = count(&|m| m.collisions > 0);
        let near_misses = count(&|m| m.near_miss);
        let rate = |k: u64| (completed > 0).then(|| k as f64 / completed as f64);
        let p5 = |f: &dyn Fn(&RunMetrics) -> Option<f64>| {
            let mut values: Vec<f64> = done.iter().map(|m| f(m).unwrap_or(f64::INFINITY)).collect();
            values.sort_by(f64::total_cmp);
            nearest_rank_percentile(&values, 5.0).filter(|v| v.is_finite())
        };
        let mean_of =
            |f: &dyn Fn(&RunMetrics) -> f64| mean(&done.iter().map(|m| f(m)).collect::<Vec<_>>());
        let on_road: Vec<&super::CommonRoadFigures> =
            done.iter().filter_map(|m| m.commonroad.as_ref()).collect();
        let on_commonroad = !on_road.is_empty();
        let count_on_road = |f: &dyn Fn(&super::CommonRoadFigures) -> bool| {
            on_commonroad.then(|| on_road.iter().filter(|c| f(c)).count() as u64)
        };
        let panicked = rows
            .iter()
            .filter(|r| r.status == RunStatus::Panicked)
            .count() as u64;
        SweepSummary {
            scenario: identity.scenario.clone(),
            scenario_fingerprint: identity.scenario_fingerprint.clone(),
            params: identity.params.clone(),
            planner: identity.planner.clone(),
            seed: identity.seed,
            total_runs: identity.total_runs,
            shard,
            instances: [range.start, range.end],
            runs: rows.len() as u64,
            missing_runs: (range.end - range.start).saturating_sub(rows.len() as u64),
            completed,
            diverged: rows.len() as u64 - completed,
            panicked,
            collisions,
            collision_rate: rate(collisions),
            collision_rate_ci95: wilson_interval(collisions, completed, Z_95),
            near_misses,
            near_miss_rate: rate(near_misses),
            near_miss_rate_ci95: wilson_interval(near_misses, completed, Z_95),
            percentiles_n: completed,
            min_ttc_s_p5: p5(&|m| m.min_ttc_s),
            runs_min_ttc_never: count(&|m| m.min_ttc_never()),
            min_gap_m_p5: p5(&|m| m.min_gap_m),
            runs_min_gap_never: count(&|m| m.min_gap_never()),
            means_n: completed,
            mean_peak_yaw_rate_radps: mean_of(&|m| m.peak_yaw_rate_radps),
            mean_peak_sideslip_rad: mean_of(&|m| m.peak_sideslip_rad),
            mean_peak_yaw_rad: mean_of(&|m| m.peak_yaw_rad),
            mean_min_speed_mps: mean_of(&|m| m.min_speed_mps),
            fallbacks: done.iter().map(|m| m.fallbacks).sum(),
            runs_with_fallbacks: count(&|m| m.fallbacks > 0),
            recorded_traffic: on_road.first().map(|c| c.recorded_traffic.clone()),
            collisions_caused_by_replay: on_commonroad
                .then(|| on_road.iter().map(|c| c.collisions_caused_by_replay).sum()),
            runs_with_collisions_caused_by_replay: count_on_road(&|c| {
                c.collisions_caused_by_replay > 0
            }),
            runs_with_goal: count_on_road(&|c| c.goal_reached.is_some()),
            goals_reached: count_on_road(&|c| c.goal_reached == Some(true)),
            wall_time_s,
            samples: rows,
        }
    }

    /// The identity of the sweep this summary belongs to.
    pub fn identity(&self) -> SweepIdentity {
        SweepIdentity {
            scenario: self.scenario.clone(),
            scenario_fingerprint: self.scenario_fingerprint.clone(),
            params: self.params.clone(),
            planner: self.planner.clone(),
            planners: vec![self.planner.clone()],
            seed: self.seed,
            total_runs: self.total_runs,
        }
    }

    /// A few lines for the terminal.
    pub fn table(&self) -> String {
        self.table_resumed(0)
    }

    /// [`table`](Self::table) of a sweep of which `resumed` runs were read back (`--resume`)
    /// rather than run: the rate is over the runs of this attempt's wall time only.
    pub fn table_resumed(&self, resumed: u64) -> String {
        self.table_with_timing(&timing_line(self.runs, resumed, self.wall_time_s))
    }

    /// [`table`](Self::table) of one planner of a paired sweep of `all_runs` runs, whose wall
    /// time (in `wall_time_s`) is the whole paired sweep's; `resumed` of the `all_runs` were
    /// read back (`--resume`).
    pub(crate) fn table_in_paired_sweep(&self, all_runs: u64, resumed: u64) -> String {
        let timing = if resumed == 0 {
            let per_s = runs_per_s(all_runs, self.wall_time_s);
            format!(
                "{all_runs} runs in {:.1} s wall, {per_s:.2} runs/s",
                self.wall_time_s
            )
        } else {
            timing_line(all_runs, resumed, self.wall_time_s)
        };
        self.table_with_timing(&format!("{} runs (the paired sweep: {timing})", self.runs))
    }

    fn table_with_timing(&self, timing: &str) -> String {
        let opt = |v: Option<f64>, digits: usize| {
            v.map(|x| format!("{x:.digits$}"))
                .unwrap_or_else(|| "-".into())
        };
        let ci = |v: Option<[f64; 2]>| {
            v.map(|[l, h]| format!("[{l:.4}, {h:.4}]"))
                .unwrap_or_else(|| "-".into())
        };
        format!(
            "sweep {} {}: seed {}, shard {} (instances {}..{} of {}), {}\n\
             completed {}  diverged {} (panicked {})\n\
             collisions {}  rate {}  95% CI {}\n\
             near misses {}  rate {}  95% CI {}\n\
             p5 min TTC {} s  p5 min gap {} m  (n {}: completed runs; a run that never closed \
             ({}) / never came within range ({}) counts as +inf)\n\
             means over n {} completed runs: peak |r| {} rad/s  peak |β| {} rad  peak |ψ| {} rad  \
             min v {} m/s\n\
             fallback cycles {} (in {} runs)\n",
            self.scenario,
            self.planner,
            self.seed,
            self.shard,
            self.instances[0],
            self.instances[1],
            self.total_runs,
            timing,
            self.completed,
            self.diverged,
            self.panicked,
            self.collisions,
            opt(self.collision_rate, 4),
            ci(self.collision_rate_ci95),
            self.near_misses,
            opt(self.near_miss_rate, 4),
            ci(self.near_miss_rate_ci95),
            opt(self.min_ttc_s_p5, 3),
            opt(self.min_gap_m_p5, 3),
            self.percentiles_n,
            self.runs_min_ttc_never,
            self.runs_min_gap_never,
            self.means_n,
            opt(self.mean_peak_yaw_rate_radps, 4),
            opt(self.mean_peak_sideslip_rad, 4),
            opt(self.mean_peak_yaw_rad, 4),
            opt(self.mean_min_speed_mps, 2),
            self.fallbacks,
            self.runs_with_fallbacks,
        ) + &self.commonroad_lines()
            + &if self.missing_runs > 0 {
                format!(
                    "INCOMPLETE: {} of {} runs missing (interrupted); the figures above are over the \
                 finished runs only\n",
                    self.missing_runs,
                    self.instances[1] - self.instances[0]
                )
            } else {
                String::new()
            }
    }

    /// The line of the CommonRoad figures (nothing on any other road).
    fn commonroad_lines(&self) -> String {
        let Some(mode) = &self.recorded_traffic else {
            return String::new();
        };
        let goals = match (self.runs_with_goal, self.goals_reached) {
            (Some(n), Some(k)) if n > 0 => format!("  goal reached in {k} of {n} runs"),
            _ => String::new(),
        };
        format!(
            "recorded traffic {mode}: collisions caused by replay {} (in {} runs){goals}\n",
            self.collisions_caused_by_replay.unwrap_or(0),
            self.runs_with_collisions_caused_by_replay.unwrap_or(0),
        )
    }

    /// One JSONL line (without the newline): `row` with the sweep's identity and `wall_time_s`.
    pub fn jsonl_line(&self, row: &RunRow, wall_time_s: f64) -> Result<String, serde_json::Error> {
        jsonl_line(&self.identity(), row, wall_time_s)
    }

    /// The JSONL text of the runs (one line each, with scenario, planner and wall time).
    pub fn jsonl(&self, wall_times_s: &[f64]) -> Result<String, serde_json::Error> {
        let mut text = String::new();
        for (i, row) in self.samples.iter().enumerate() {
            text.push_str(&self.jsonl_line(row, wall_times_s.get(i).copied().unwrap_or(0.0))?);
            text.push('\n');
        }
        Ok(text)
    }
}

/// `runs` over `wall_time_s` (0 for no time at all).
fn runs_per_s(runs: u64, wall_time_s: f64) -> f64 {
    if wall_time_s > 0.0 {
        runs as f64 / wall_time_s
    } else {
        0.0
    }
}

/// "N runs in T s wall (R runs/s)"; with `resumed` of the N read back (`--resume`), the rate
/// is over the runs of this attempt only (a resumed sweep's wall time is this attempt's).
fn timing_line(runs: u64, resumed: u64, wall_time_s: f64) -> String {
    let ran = runs.saturating_sub(resumed);
    let per_s = runs_per_s(ran, wall_time_s);
    if resumed == 0 {
        format!("{runs} runs in {wall_time_s:.1} s wall ({per_s:.2} runs/s)")
    } else {
        format!(
            "{runs} runs, {resumed} of them read back with --resume; {ran} run in this attempt, \
             {wall_time_s:.1} s wall ({per_s:.2} runs/s)"
        )
    }
}

#[cfg(test)]
mod timing_tests {
    use super::timing_line;

    #[test]
    fn a_resumed_sweep_s_rate_counts_only_the_runs_of_this_attempt() {
        assert_eq!(timing_line(8, 0, 2.0), "8 runs in 2.0 s wall (4.00 runs/s)");
        assert_eq!(
            timing_line(8, 6, 2.0),
            "8 runs, 6 of them read back with --resume; 2 run in this attempt, 2.0 s wall \
             (1.00 runs/s)"
        );
        // Nothing left to run: no rate made of the runs read back.
        assert!(
            timing_line(4, 4, 0.001).ends_with("0 run in this attempt, 0.0 s wall (0.00 runs/s)")
        );
    }
}
