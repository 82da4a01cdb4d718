//! Seeded Monte-Carlo sweeps: N randomised instances of a scenario, run in parallel, reduced to
//! collision / near-miss statistics that do not depend on how the sweep was split or scheduled.
//!
//! Reproducibility contract:
//! - instance `i` of a sweep with seed `K` runs with seed [`instance_seed`]`(K, i)` =
//!   `SplitMix64::derive(K, i)`: the scenario instance is `Scenario::instantiate(seed)` and the
//!   World's random streams use the same seed, exactly as `merge_sim run --seed <seed>`, so any
//!   row can be replayed alone;
//! - rows are collected in instance order whatever the thread scheduling, and every figure of
//!   the aggregate is a function of the rows in instance order ([`SweepSummary::from_rows`]);
//!   so the aggregate of a sharded sweep merged by [`merge_shards`] equals the unsharded one
//!   exactly, except `wall_time_s`.
//!
//! A run whose `World` returns an error (or, defensively, panics) is counted as diverged and
//! recorded with its error; the sweep carries on. Rates are over the completed runs.

pub mod shard;
pub mod statistics;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::Instant;

use planner::PlannerKind;
use rayon::prelude::*;
use scenarios::Scenario;
use scenarios::randomisation::fnv1a64;
use serde::{Deserialize, Serialize};
use sim::rng::SplitMix64;

use thiserror::Error;

use crate::summary::RunSummary;
pub use shard::{Shard, ShardError};
use statistics::{Z_95, mean, nearest_rank_percentile, wilson_interval};

/// The seed of instance `instance` of a sweep seeded with `sweep_seed`.
pub fn instance_seed(sweep_seed: u64, instance: u64) -> u64 {
    SplitMix64::derive(sweep_seed, instance)
}

/// What to sweep.
#[derive(Clone, Debug)]
pub struct SweepPlan {
    /// The scenario (nominal values and randomisation ranges).
    pub scenario: Scenario,
    /// Planner of every planner-driven vehicle (`None`: the scenario's own).
    pub planner: Option<PlannerKind>,
    /// Instances in the whole sweep (≥ 1).
    pub runs: u64,
    /// Sweep seed K.
    pub seed: u64,
    /// The part of the sweep to run.
    pub shard: Shard,
}

/// How to run a sweep (does not change its results).
#[derive(Clone, Debug, Default)]
pub struct SweepOptions {
    /// Worker threads (`None`: one per core).
    pub threads: Option<usize>,
}

/// Why a sweep could not run or shards could not be merged.
#[derive(Debug, Error)]
pub enum SweepError {
    /// A value out of range (names it).
    #[error("{0}")]
    Invalid(String),
    /// The worker pool could not start.
    #[error("cannot start the worker threads: {0}")]
    Threads(String),
}

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
    /// The run's seed, [`instance_seed`]`(K, i)`: `merge_sim run --seed <seed>` replays it.
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
struct JsonlLine<'a> {
    scenario: &'a str,
    planner: &'a str,
    #[serde(flatten)]
    row: &'a RunRow,
    wall_time_s: f64,
}

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
    /// Sweep seed K.
    pub seed: u64,
    /// Instances in the whole sweep.
    pub total_runs: u64,
    /// Which part of the sweep this is (`0/1`: all of it).
    pub shard: Shard,
    /// The instances of this part, `[start, end)`.
    pub instances: [u64; 2],
    /// Runs in this part.
    pub runs: u64,
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
    /// 5th percentile (nearest rank) of the runs' minimum TTC (s); a run without a closing pair
    /// counts as +∞, and `null` means the percentile itself is +∞ (or no completed run).
    pub min_ttc_s_p5: Option<f64>,
    /// 5th percentile (nearest rank) of the runs' minimum gap (m).
    pub min_gap_m_p5: Option<f64>,
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
    /// Wall-clock time (s): of the sweep, or the sum over merged shards. Not reproducible.
    pub wall_time_s: f64,
    /// The runs, in instance order.
    pub samples: Vec<RunRow>,
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
    /// Planner name.
    pub planner: String,
    /// Sweep seed.
    pub seed: u64,
    /// Instances in the whole sweep.
    pub total_runs: u64,
}

impl SweepIdentity {
    /// The identity of a plan.
    pub fn of(plan: &SweepPlan) -> Self {
        let canonical = plan.scenario.to_toml().unwrap_or_default();
        SweepIdentity {
            scenario: plan.scenario.name.clone(),
            scenario_fingerprint: format!("{:016x}", fnv1a64(&canonical)),
            params: plan.scenario.params.name().to_string(),
            planner: planner_label(&plan.scenario, plan.planner),
            seed: plan.seed,
            total_runs: plan.runs,
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
            completed,
            diverged: rows.len() as u64 - completed,
            panicked,
            collisions,
            collision_rate: rate(collisions),
            collision_rate_ci95: wilson_interval(collisions, completed, Z_95),
            near_misses,
            near_miss_rate: rate(near_misses),
            near_miss_rate_ci95: wilson_interval(near_misses, completed, Z_95),
            min_ttc_s_p5: p5(&|m| m.min_ttc_s),
            min_gap_m_p5: p5(&|m| m.min_gap_m),
            mean_peak_yaw_rate_radps: mean_of(&|m| m.peak_yaw_rate_radps),
            mean_peak_sideslip_rad: mean_of(&|m| m.peak_sideslip_rad),
            mean_peak_yaw_rad: mean_of(&|m| m.peak_yaw_rad),
            mean_min_speed_mps: mean_of(&|m| m.min_speed_mps),
            fallbacks: done.iter().map(|m| m.fallbacks).sum(),
            runs_with_fallbacks: count(&|m| m.fallbacks > 0),
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
            seed: self.seed,
            total_runs: self.total_runs,
        }
    }

    /// A few lines for the terminal.
    pub fn table(&self) -> String {
        let opt = |v: Option<f64>, digits: usize| {
            v.map(|x| format!("{x:.digits$}"))
                .unwrap_or_else(|| "-".into())
        };
        let ci = |v: Option<[f64; 2]>| {
            v.map(|[l, h]| format!("[{l:.4}, {h:.4}]"))
                .unwrap_or_else(|| "-".into())
        };
        let per_s = if self.wall_time_s > 0.0 {
            self.runs as f64 / self.wall_time_s
        } else {
            0.0
        };
        format!(
            "sweep {} {}: seed {}, shard {} (instances {}..{} of {}), {} runs in {:.1} s wall ({:.2} runs/s)\n\
             completed {}  diverged {} (panicked {})\n\
             collisions {}  rate {}  95% CI {}\n\
             near misses {}  rate {}  95% CI {}\n\
             p5 min TTC {} s  p5 min gap {} m\n\
             mean peak |r| {} rad/s  mean peak |β| {} rad  mean peak |ψ| {} rad  mean min v {} m/s\n\
             fallback cycles {} (in {} runs)\n",
            self.scenario,
            self.planner,
            self.seed,
            self.shard,
            self.instances[0],
            self.instances[1],
            self.total_runs,
            self.runs,
            self.wall_time_s,
            per_s,
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
            opt(self.mean_peak_yaw_rate_radps, 4),
            opt(self.mean_peak_sideslip_rad, 4),
            opt(self.mean_peak_yaw_rad, 4),
            opt(self.mean_min_speed_mps, 2),
            self.fallbacks,
            self.runs_with_fallbacks,
        )
    }

    /// The JSONL text of the runs (one line each, with scenario, planner and wall time).
    pub fn jsonl(&self, wall_times_s: &[f64]) -> Result<String, serde_json::Error> {
        let mut text = String::new();
        for (i, row) in self.samples.iter().enumerate() {
            let line = JsonlLine {
                scenario: &self.scenario,
                planner: &self.planner,
                row,
                wall_time_s: wall_times_s.get(i).copied().unwrap_or(0.0),
            };
            text.push_str(&serde_json::to_string(&line)?);
            text.push('\n');
        }
        Ok(text)
    }
}

/// A finished sweep: the aggregate and each run's wall time (for the JSONL).
#[derive(Clone, Debug)]
pub struct SweepOutcome {
    /// The aggregate.
    pub summary: SweepSummary,
    /// Wall time of each run (s), in instance order.
    pub run_wall_times_s: Vec<f64>,
}

/// The planner name of a sweep: the override, or the scenario's single planner, or `mixed`.
pub fn planner_label(scenario: &Scenario, planner: Option<PlannerKind>) -> String {
    crate::experiment::planner_label(scenario, planner.map(|k| k.name()))
}

/// Runs instance `seed` of the plan's scenario: what `merge_sim run --seed <seed>` runs.
pub fn simulate_instance(plan: &SweepPlan, seed: u64) -> Result<RunSummary, sim::SimError> {
    let options = crate::experiment::InstanceOptions {
        planner: plan.planner.map(|k| k.name().to_string()),
        seed: Some(seed),
        keep_time_series: false,
    };
    crate::experiment::run_quietly(&plan.scenario, &options)
        .map(|finished| finished.summary)
        .map_err(|e| match e {
            crate::experiment::RunError::Setup(e) | crate::experiment::RunError::Run(e) => e,
        })
}

/// Runs the plan's shard with the simulator; `on_run_done` is called after each run (from the
/// worker threads) for a progress display.
pub fn run_sweep(
    plan: &SweepPlan,
    options: &SweepOptions,
    on_run_done: &(dyn Fn() + Sync),
) -> Result<SweepOutcome, SweepError> {
    run_sweep_with(plan, options, on_run_done, |seed| {
        simulate_instance(plan, seed)
            .map(|summary| RunMetrics::of(&summary))
            .map_err(|e| e.to_string())
    })
}

/// [`run_sweep`] with any runner (`seed → figures or error`), e.g. a fake one in tests.
pub fn run_sweep_with<F>(
    plan: &SweepPlan,
    options: &SweepOptions,
    on_run_done: &(dyn Fn() + Sync),
    runner: F,
) -> Result<SweepOutcome, SweepError>
where
    F: Fn(u64) -> Result<RunMetrics, String> + Sync,
{
    if plan.runs == 0 {
        return Err(SweepError::Invalid(
            "runs = 0: a sweep needs at least 1 run".into(),
        ));
    }
    if options.threads == Some(0) {
        return Err(SweepError::Invalid("threads = 0: need at least 1".into()));
    }
    let identity = SweepIdentity::of(plan);
    let range = plan.shard.instances(plan.runs);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads.unwrap_or(0))
        // A World keeps sizeable locals on the stack; give the workers the main thread's 8 MiB
        // and some margin rather than the 2 MiB default of spawned threads.
        .stack_size(16 << 20)
        .build()
        .map_err(|e| SweepError::Threads(e.to_string()))?;
    let started = Instant::now();
    let results: Vec<(RunRow, f64)> = pool.install(|| {
        range
            .into_par_iter()
            .map(|instance| {
                let seed = instance_seed(plan.seed, instance);
                let run_started = Instant::now();
                let result = catch_unwind(AssertUnwindSafe(|| runner(seed)));
                let wall_s = run_started.elapsed().as_secs_f64();
                let row = match result {
                    Ok(Ok(metrics)) => RunRow {
                        instance,
                        seed,
                        status: RunStatus::Completed,
                        error: None,
                        metrics: Some(metrics),
                    },
                    Ok(Err(error)) => RunRow {
                        instance,
                        seed,
                        status: RunStatus::Diverged,
                        error: Some(error),
                        metrics: None,
                    },
                    Err(payload) => RunRow {
                        instance,
                        seed,
                        status: RunStatus::Panicked,
                        error: Some(panic_message(payload.as_ref())),
                        metrics: None,
                    },
                };
                on_run_done();
                (row, wall_s)
            })
            .collect()
    });
    let wall_time_s = started.elapsed().as_secs_f64();
    let (rows, run_wall_times_s): (Vec<RunRow>, Vec<f64>) = results.into_iter().unzip();
    Ok(SweepOutcome {
        summary: SweepSummary::from_rows(&identity, plan.shard, rows, wall_time_s),
        run_wall_times_s,
    })
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    let text = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown payload".into());
    format!("panic: {text}")
}

/// Combines the summaries of shards (`(origin, summary)`, origin naming the file in errors) into
/// the summary of the whole sweep: same identity, every shard `i/n` present exactly once.
pub fn merge_shards(parts: Vec<(String, SweepSummary)>) -> Result<SweepSummary, SweepError> {
    let Some((first_origin, first)) = parts.first() else {
        return Err(SweepError::Invalid("no shard files given".into()));
    };
    let identity = first.identity();
    let count = first.shard.count;
    let mut seen: Vec<Option<&str>> =
        vec![None; usize::try_from(count).unwrap_or(usize::MAX).min(1 << 20)];
    if seen.len() as u64 != count {
        return Err(SweepError::Invalid(format!(
            "{first_origin}: shard count {count} is too large"
        )));
    }
    for (origin, part) in &parts {
        let other = part.identity();
        let fields = [
            (
                "scenario",
                identity.scenario.clone(),
                other.scenario.clone(),
            ),
            (
                "scenario_fingerprint",
                identity.scenario_fingerprint.clone(),
                other.scenario_fingerprint.clone(),
            ),
            ("planner", identity.planner.clone(), other.planner.clone()),
            ("params", identity.params.clone(), other.params.clone()),
            ("seed", identity.seed.to_string(), other.seed.to_string()),
            (
                "total_runs",
                identity.total_runs.to_string(),
                other.total_runs.to_string(),
            ),
            (
                "shard count",
                count.to_string(),
                part.shard.count.to_string(),
            ),
        ];
        for (name, expected, found) in fields {
            if expected != found {
                return Err(SweepError::Invalid(format!(
                    "{origin}: {name} = {found} differs from {first_origin} ({expected}): not a shard of the same sweep"
                )));
            }
        }
        let slot = &mut seen[part.shard.index as usize];
        if let Some(previous) = slot {
            return Err(SweepError::Invalid(format!(
                "{origin}: shard {} given twice (also {previous})",
                part.shard
            )));
        }
        *slot = Some(origin.as_str());
        let range = part.shard.instances(part.total_runs);
        let instances: Vec<u64> = part.samples.iter().map(|r| r.instance).collect();
        if instances != range.clone().collect::<Vec<_>>()
            || part.instances != [range.start, range.end]
        {
            return Err(SweepError::Invalid(format!(
                "{origin}: shard {} must hold instances {}..{} in order",
                part.shard, range.start, range.end
            )));
        }
        if let Some(bad) = part
            .samples
            .iter()
            .find(|r| r.seed != instance_seed(part.seed, r.instance))
        {
            return Err(SweepError::Invalid(format!(
                "{origin}: instance {} has seed {}, not the derived {}",
                bad.instance,
                bad.seed,
                instance_seed(part.seed, bad.instance)
            )));
        }
    }
    let missing: Vec<String> = seen
        .iter()
        .enumerate()
        .filter(|(_, s)| s.is_none())
        .map(|(i, _)| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(SweepError::Invalid(format!(
            "missing shards: {}",
            missing.join(", ")
        )));
    }
    let mut ordered: Vec<&SweepSummary> = parts.iter().map(|(_, p)| p).collect();
    ordered.sort_by_key(|p| p.shard.index);
    let wall_time_s = ordered.iter().map(|p| p.wall_time_s).sum();
    let rows = ordered
        .into_iter()
        .flat_map(|p| p.samples.iter().cloned())
        .collect();
    Ok(SweepSummary::from_rows(
        &identity,
        Shard::WHOLE,
        rows,
        wall_time_s,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(runs: u64, shard: Shard) -> SweepPlan {
        SweepPlan {
            scenario: Scenario::load("urgent_merge").unwrap(),
            planner: Some(PlannerKind::PfIso),
            runs,
            seed: 77,
            shard,
        }
    }

    /// A fake run whose figures are simple functions of the seed.
    fn fake(seed: u64) -> Result<RunMetrics, String> {
        match seed % 11 {
            0 => return Err("simulation diverged at t = 3 s: test".into()),
            1 => panic!("test panic {seed}"),
            _ => {}
        }
        let x = (seed % 1000) as f64 / 1000.0;
        Ok(RunMetrics {
            collisions: u64::from(seed.is_multiple_of(7)),
            near_miss: !seed.is_multiple_of(7) && x < 0.2,
            min_ttc_s: if seed.is_multiple_of(5) {
                None
            } else {
                Some(x * 4.0)
            },
            min_gap_m: Some(x * 3.0),
            tet_s: 0.0,
            peak_yaw_rate_radps: x,
            peak_sideslip_rad: x / 10.0,
            peak_yaw_rad: x / 5.0,
            min_speed_mps: 10.0 + x,
            yaw_rate_sign_changes: seed % 3,
            fallbacks: seed % 2,
            plans: 10,
        })
    }

    #[test]
    fn aggregate_counts_follow_the_rows_and_failures_are_kept() {
        let outcome = run_sweep_with(
            &plan(60, Shard::WHOLE),
            &SweepOptions { threads: Some(2) },
            &|| {},
            fake,
        )
        .unwrap();
        let s = &outcome.summary;
        assert_eq!(s.runs, 60);
        assert_eq!(
            s.samples.iter().map(|r| r.instance).collect::<Vec<_>>(),
            (0..60).collect::<Vec<_>>()
        );
        let seeds: Vec<u64> = (0..60).map(|i| instance_seed(77, i)).collect();
        assert_eq!(s.samples.iter().map(|r| r.seed).collect::<Vec<_>>(), seeds);
        let diverged = seeds.iter().filter(|s| *s % 11 == 0).count() as u64;
        let panicked = seeds.iter().filter(|s| *s % 11 == 1).count() as u64;
        assert!(
            panicked > 0 && diverged > 0,
            "choose another seed for the test"
        );
        assert_eq!(s.panicked, panicked);
        assert_eq!(s.diverged, diverged + panicked);
        assert_eq!(s.completed, 60 - diverged - panicked);
        let ok: Vec<u64> = seeds.iter().copied().filter(|s| s % 11 > 1).collect();
        assert_eq!(
            s.collisions,
            ok.iter().filter(|s| *s % 7 == 0).count() as u64
        );
        assert_eq!(
            s.collision_rate,
            Some(s.collisions as f64 / s.completed as f64)
        );
        assert_eq!(s.fallbacks, ok.iter().map(|s| s % 2).sum::<u64>());
        // p5 by brute force: the smallest value with at least 5 % of the runs at or below it.
        let ttc: Vec<f64> = ok
            .iter()
            .map(|s| {
                if s % 5 == 0 {
                    f64::INFINITY
                } else {
                    (s % 1000) as f64 / 1000.0 * 4.0
                }
            })
            .collect();
        let brute = ttc
            .iter()
            .copied()
            .filter(|&c| ttc.iter().filter(|&&v| v <= c).count() as f64 >= 0.05 * ttc.len() as f64)
            .fold(f64::INFINITY, f64::min);
        assert_eq!(s.min_ttc_s_p5, Some(brute));
        let failed = s
            .samples
            .iter()
            .find(|r| r.status == RunStatus::Panicked)
            .unwrap();
        assert!(
            failed
                .error
                .as_deref()
                .unwrap()
                .starts_with("panic: test panic")
        );
        assert!(failed.metrics.is_none());
    }

    #[test]
    fn merged_shards_equal_the_unsharded_sweep_whatever_the_threads() {
        let options = SweepOptions { threads: Some(1) };
        let mut whole = run_sweep_with(&plan(23, Shard::WHOLE), &options, &|| {}, fake)
            .unwrap()
            .summary;
        let mut parts = Vec::new();
        for index in [2, 0, 3, 1] {
            let shard = Shard::new(index, 4, "t").unwrap();
            let part = run_sweep_with(
                &plan(23, shard),
                &SweepOptions { threads: Some(2) },
                &|| {},
                fake,
            )
            .unwrap();
            parts.push((format!("shard{index}.json"), part.summary));
        }
        // Through JSON, as merge-results reads them.
        let parts: Vec<(String, SweepSummary)> = parts
            .into_iter()
            .map(|(o, p)| {
                (
                    o,
                    serde_json::from_str(&serde_json::to_string(&p).unwrap()).unwrap(),
                )
            })
            .collect();
        let mut merged = merge_shards(parts.clone()).unwrap();
        whole.wall_time_s = 0.0;
        merged.wall_time_s = 0.0;
        assert_eq!(
            serde_json::to_string(&whole).unwrap(),
            serde_json::to_string(&merged).unwrap()
        );
        // Missing, duplicated and foreign shards are refused, naming the file.
        let err = merge_shards(parts[..3].to_vec()).unwrap_err().to_string();
        assert!(err.contains("missing shards: 1/4"), "{err}");
        let mut twice = parts.clone();
        twice.push(("again.json".into(), parts[0].1.clone()));
        assert!(
            merge_shards(twice)
                .unwrap_err()
                .to_string()
                .contains("again.json")
        );
        let mut foreign = parts.clone();
        foreign[1].1.seed = 78;
        let err = merge_shards(foreign).unwrap_err().to_string();
        assert!(err.contains("shard0.json") && err.contains("seed"), "{err}");
    }

    #[test]
    fn zero_runs_and_zero_threads_are_refused() {
        let err = run_sweep_with(
            &plan(0, Shard::WHOLE),
            &SweepOptions::default(),
            &|| {},
            fake,
        )
        .unwrap_err();
        assert!(err.to_string().contains("runs = 0"));
        let err = run_sweep_with(
            &plan(3, Shard::WHOLE),
            &SweepOptions { threads: Some(0) },
            &|| {},
            fake,
        )
        .unwrap_err();
        assert!(err.to_string().contains("threads = 0"));
    }

    #[test]
    fn empty_shard_is_a_valid_part() {
        // 2 runs in 4 shards: shard 0/4 holds nothing.
        let part = run_sweep_with(
            &plan(2, Shard::new(0, 4, "t").unwrap()),
            &SweepOptions::default(),
            &|| {},
            fake,
        )
        .unwrap()
        .summary;
        assert_eq!((part.runs, part.instances), (0, [0, 0]));
        assert_eq!(part.collision_rate, None);
        assert_eq!(part.collision_rate_ci95, None);
    }
}
