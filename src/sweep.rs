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
//!
//! Interruption and resumption: each run is handed to the caller as it finishes (the CLI appends
//! it to the JSONL and flushes). An interrupt flag stops the sweep between runs and inside them;
//! the aggregate of what finished is marked incomplete (`missing_runs`). Resuming passes the
//! finished rows back ([`SweepOptions::resume`]): only the missing instances run, and since
//! every figure is a function of the rows in instance order, the aggregate equals that of an
//! uninterrupted sweep (except `wall_time_s`).

mod merge;
pub mod resume;
mod rows;
pub mod shard;
pub mod statistics;
mod summary;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use planner::PlannerKind;
use rayon::prelude::*;
use scenarios::Scenario;
use sim::rng::SplitMix64;

use thiserror::Error;

use crate::summary::RunSummary;
pub use merge::merge_shards;
pub use rows::{JsonlRecord, RunMetrics, RunRow, RunStatus};
pub use shard::{Shard, ShardError};
pub use summary::{SweepIdentity, SweepSummary, jsonl_line};

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
    /// Worker threads (`None`: one per core; at most [`MAX_THREADS`]).
    pub threads: Option<usize>,
    /// Once set (e.g. by a SIGINT/SIGTERM handler), no run starts and running ones stop; the
    /// outcome holds the runs that finished and is marked incomplete.
    pub interrupt: Option<Arc<AtomicBool>>,
    /// Runs finished by an earlier, interrupted attempt of the same sweep (`--resume`): their
    /// instances are not run again and their rows enter the aggregate as they are.
    pub resume: Vec<FinishedRun>,
}

/// Most instances of one sweep (a sweep keeps every row in memory, ≈ 200 bytes each; for more,
/// run several sweeps with different seeds).
pub const MAX_RUNS: u64 = 1_000_000;

/// Most worker threads.
pub const MAX_THREADS: usize = 1024;

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

/// A run that finished: its row and its wall time (s).
#[derive(Clone, Debug, PartialEq)]
pub struct FinishedRun {
    /// The row.
    pub row: RunRow,
    /// Wall time of the run (s); not reproducible.
    pub wall_time_s: f64,
}

/// Why a run gave no figures.
#[derive(Clone, Debug, PartialEq)]
pub enum RunFailure {
    /// The World returned an error (the row records it; the sweep carries on).
    Failed(String),
    /// The run was interrupted: it gives no row and is run again by `--resume`.
    Interrupted,
}

/// A finished sweep (or the part of it that finished before an interruption).
#[derive(Clone, Debug)]
pub struct SweepOutcome {
    /// The aggregate (its `missing_runs` counts the instances without a row).
    pub summary: SweepSummary,
    /// Wall time of each row of `summary.samples` (s), in instance order.
    pub run_wall_times_s: Vec<f64>,
    /// Runs finished by this attempt (not resumed).
    pub new_runs: u64,
    /// Whether the interrupt flag stopped the sweep before every run finished.
    pub interrupted: bool,
}

/// How a sweep ended: what its exit status reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweepVerdict {
    /// Every run finished and completed (collisions are results, not failures).
    Complete,
    /// Every run finished, `failed` of them diverged or panicked (exit code 1).
    RunsFailed {
        /// Diverged or panicked runs.
        failed: u64,
        /// Runs of the part.
        of: u64,
    },
    /// Interrupted with `missing` runs not run (exit code 128 + the signal).
    Interrupted {
        /// Instances without a row.
        missing: u64,
    },
}

impl SweepOutcome {
    /// How the sweep ended.
    pub fn verdict(&self) -> SweepVerdict {
        let s = &self.summary;
        if s.missing_runs > 0 {
            SweepVerdict::Interrupted {
                missing: s.missing_runs,
            }
        } else if s.diverged > 0 {
            SweepVerdict::RunsFailed {
                failed: s.diverged,
                of: s.runs,
            }
        } else {
            SweepVerdict::Complete
        }
    }
}

/// The planner name of a sweep: the override, or the scenario's single planner, or `mixed`.
pub fn planner_label(scenario: &Scenario, planner: Option<PlannerKind>) -> String {
    crate::experiment::planner_label(scenario, planner.map(|k| k.name()))
}

/// Runs instance `seed` of the plan's scenario: what `merge_sim run --seed <seed>` runs.
pub fn simulate_instance(plan: &SweepPlan, seed: u64) -> Result<RunSummary, sim::SimError> {
    simulate_instance_until(plan, seed, None)
}

/// [`simulate_instance`], stopped with [`sim::SimError::Interrupted`] once `interrupt` is set.
pub fn simulate_instance_until(
    plan: &SweepPlan,
    seed: u64,
    interrupt: Option<Arc<AtomicBool>>,
) -> Result<RunSummary, sim::SimError> {
    let options = crate::experiment::InstanceOptions {
        planner: plan.planner.map(|k| k.name().to_string()),
        seed: Some(seed),
        keep_time_series: false,
        interrupt,
        profile: false,
    };
    crate::experiment::run_quietly(&plan.scenario, &options)
        .map(|finished| finished.summary)
        .map_err(|e| match e {
            crate::experiment::RunError::Setup(e) | crate::experiment::RunError::Run(e) => e,
        })
}

/// Runs the plan's shard with the simulator; `on_run` is called with each run as it finishes
/// (from the worker threads, in completion order), e.g. to append it to the JSONL and advance a
/// progress bar.
pub fn run_sweep(
    plan: &SweepPlan,
    options: &SweepOptions,
    on_run: &(dyn Fn(&FinishedRun) + Sync),
) -> Result<SweepOutcome, SweepError> {
    let interrupt = options.interrupt.clone();
    run_sweep_with(plan, options, on_run, |seed| match simulate_instance_until(
        plan,
        seed,
        interrupt.clone(),
    ) {
        Ok(summary) => Ok(RunMetrics::of(&summary)),
        Err(sim::SimError::Interrupted { .. }) => Err(RunFailure::Interrupted),
        Err(e) => Err(RunFailure::Failed(e.to_string())),
    })
}

/// Checks a plan and its options before any work.
pub fn validate(plan: &SweepPlan, options: &SweepOptions) -> Result<(), SweepError> {
    if plan.runs == 0 || plan.runs > MAX_RUNS {
        return Err(SweepError::Invalid(format!(
            "runs = {}: a sweep runs 1 to {MAX_RUNS} instances (for more, run several sweeps \
             with different seeds)",
            plan.runs
        )));
    }
    if let Some(threads) = options.threads
        && !(1..=MAX_THREADS).contains(&threads)
    {
        return Err(SweepError::Invalid(format!(
            "threads = {threads}: need 1 to {MAX_THREADS}"
        )));
    }
    let range = plan.shard.instances(plan.runs);
    let mut seen = std::collections::BTreeSet::new();
    for run in &options.resume {
        let row = &run.row;
        if !range.contains(&row.instance) {
            return Err(SweepError::Invalid(format!(
                "resumed row of instance {} lies outside shard {}'s instances {}..{}",
                row.instance, plan.shard, range.start, range.end
            )));
        }
        let expected = instance_seed(plan.seed, row.instance);
        if row.seed != expected {
            return Err(SweepError::Invalid(format!(
                "resumed row of instance {} has seed {}, not {expected} = the seed of instance \
                 {} of a sweep with seed {}: not a row of this sweep",
                row.instance, row.seed, row.instance, plan.seed
            )));
        }
        if !seen.insert(row.instance) {
            return Err(SweepError::Invalid(format!(
                "instance {} appears twice among the resumed rows",
                row.instance
            )));
        }
    }
    Ok(())
}

/// [`run_sweep`] with any runner (`seed → figures or failure`), e.g. a fake one in tests.
pub fn run_sweep_with<F>(
    plan: &SweepPlan,
    options: &SweepOptions,
    on_run: &(dyn Fn(&FinishedRun) + Sync),
    runner: F,
) -> Result<SweepOutcome, SweepError>
where
    F: Fn(u64) -> Result<RunMetrics, RunFailure> + Sync,
{
    validate(plan, options)?;
    let identity = SweepIdentity::of(plan);
    let range = plan.shard.instances(plan.runs);
    let done: std::collections::BTreeSet<u64> =
        options.resume.iter().map(|r| r.row.instance).collect();
    let todo: Vec<u64> = range.clone().filter(|i| !done.contains(i)).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads.unwrap_or(0))
        // A World keeps sizeable locals on the stack; give the workers the main thread's 8 MiB
        // and some margin rather than the 2 MiB default of spawned threads.
        .stack_size(16 << 20)
        .build()
        .map_err(|e| SweepError::Threads(e.to_string()))?;
    let interrupted = || {
        options
            .interrupt
            .as_ref()
            .is_some_and(|flag| flag.load(Ordering::Relaxed))
    };
    let started = Instant::now();
    let new_runs: Vec<FinishedRun> = pool.install(|| {
        todo.into_par_iter()
            .filter_map(|instance| {
                if interrupted() {
                    return None;
                }
                let seed = instance_seed(plan.seed, instance);
                let run_started = Instant::now();
                let result = catch_unwind(AssertUnwindSafe(|| runner(seed)));
                let wall_time_s = run_started.elapsed().as_secs_f64();
                let (status, error, metrics) = match result {
                    Ok(Ok(metrics)) => (RunStatus::Completed, None, Some(metrics)),
                    Ok(Err(RunFailure::Interrupted)) => return None,
                    Ok(Err(RunFailure::Failed(error))) => (RunStatus::Diverged, Some(error), None),
                    Err(payload) => (
                        RunStatus::Panicked,
                        Some(panic_message(payload.as_ref())),
                        None,
                    ),
                };
                let run = FinishedRun {
                    row: RunRow {
                        instance,
                        seed,
                        status,
                        error,
                        metrics,
                    },
                    wall_time_s,
                };
                on_run(&run);
                Some(run)
            })
            .collect()
    });
    let wall_time_s = started.elapsed().as_secs_f64();
    let new_count = new_runs.len() as u64;
    let mut all: Vec<FinishedRun> = options.resume.iter().cloned().chain(new_runs).collect();
    all.sort_by_key(|r| r.row.instance);
    let (rows, run_wall_times_s): (Vec<RunRow>, Vec<f64>) =
        all.into_iter().map(|r| (r.row, r.wall_time_s)).unzip();
    let summary = SweepSummary::from_rows(&identity, plan.shard, rows, wall_time_s);
    Ok(SweepOutcome {
        interrupted: summary.missing_runs > 0,
        summary,
        run_wall_times_s,
        new_runs: new_count,
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
#[cfg(test)]
mod tests;
