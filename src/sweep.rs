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

mod engine;
mod figures;
mod merge;
mod paired;
pub(crate) mod parquet;
pub(crate) mod resume;
mod rows;
pub(crate) mod shard;
pub(crate) mod statistics;
mod summary;

use std::sync::Arc;
use std::sync::atomic::AtomicBool;
#[cfg(test)]
use std::sync::atomic::Ordering;

use scenarios::scenario::Scenario;
use sim::registry::BehaviourRegistry;
use sim::rng::SplitMix64;

use thiserror::Error;

use crate::summary::RunSummary;
pub use engine::{RunRequest, run_paired_sweep_with, validate_paired};
pub use figures::{RunFigures, VehicleRow, describe_instance, drawn_unit, drawn_values};
pub use merge::{merge_reports, merge_shards, merged_jsonl};
pub use paired::{BetterWhen, PairedDifference, PairedSweepSummary, SweepReport};
pub use rows::{CommonRoadFigures, JsonlRecord, RunMetrics, RunRow, RunStatus};
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
    /// Registered name of the planner of every planner-driven vehicle (`None`: the scenario's
    /// own); looked up in [`SweepOptions::registry`].
    pub planner: Option<String>,
    /// Instances in the whole sweep (≥ 1).
    pub runs: u64,
    /// Sweep seed K.
    pub seed: u64,
    /// The part of the sweep to run.
    pub shard: Shard,
}

/// What to sweep with several planners: every instance runs with each planner, on the same seed
/// and the same drawn values, so the planners' differences are paired (`merge_sim sweep
/// --planners`).
#[derive(Clone, Debug)]
pub struct PairedSweepPlan {
    /// The scenario (nominal values and randomisation ranges).
    pub scenario: Scenario,
    /// Planners of every planner-driven vehicle, the first the baseline of the paired
    /// differences; empty: the scenario's own planners (one pass, like `planner: None`).
    /// Registered names, looked up in [`SweepOptions::registry`].
    pub planners: Vec<String>,
    /// Instances in the whole sweep (≥ 1); each runs once per planner.
    pub runs: u64,
    /// Sweep seed K.
    pub seed: u64,
    /// The part of the sweep to run (all planners of an instance are in the same shard).
    pub shard: Shard,
}

impl PairedSweepPlan {
    /// The planner overrides in order (`[None]`: the scenario's own).
    pub fn overrides(&self) -> Vec<Option<String>> {
        if self.planners.is_empty() {
            vec![None]
        } else {
            self.planners.iter().cloned().map(Some).collect()
        }
    }

    /// The row label of each planner in order (its name; the scenario's own label without one).
    pub fn labels(&self) -> Vec<String> {
        self.overrides()
            .into_iter()
            .map(|k| crate::experiment::planner_label(&self.scenario, k.as_deref()))
            .collect()
    }
}

impl From<&SweepPlan> for PairedSweepPlan {
    fn from(plan: &SweepPlan) -> Self {
        PairedSweepPlan {
            scenario: plan.scenario.clone(),
            planners: plan.planner.iter().cloned().collect(),
            runs: plan.runs,
            seed: plan.seed,
            shard: plan.shard,
        }
    }
}

/// How to run a sweep (does not change its results).
#[derive(Clone, Debug)]
pub struct SweepOptions {
    /// The planners by name: the plan's planners and the scenario's `driver = { planner = … }`
    /// are looked up here ([`BehaviourRegistry::builtin`] by default; a user's registry adds
    /// their own planners).
    pub registry: Arc<BehaviourRegistry>,
    /// Worker threads (`None`: one per core; at most [`MAX_THREADS`]).
    pub threads: Option<usize>,
    /// Once set (e.g. by a SIGINT/SIGTERM handler), no run starts and running ones stop; the
    /// outcome holds the runs that finished and is marked incomplete.
    pub interrupt: Option<Arc<AtomicBool>>,
    /// Runs finished by an earlier, interrupted attempt of the same sweep (`--resume`): their
    /// instances are not run again and their rows enter the aggregate as they are.
    pub resume: Vec<FinishedRun>,
}

impl Default for SweepOptions {
    /// The built-in planners, one thread per core, no interrupt, nothing resumed.
    fn default() -> Self {
        Self {
            registry: Arc::new(BehaviourRegistry::builtin()),
            threads: None,
            interrupt: None,
            resume: Vec::new(),
        }
    }
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

/// A finished multi-planner sweep (or the part of it that finished before an interruption).
#[derive(Clone, Debug)]
pub struct PairedSweepOutcome {
    /// Each planner's aggregate, in the plan's order (the first the baseline).
    pub summaries: Vec<SweepSummary>,
    /// Wall time of each row of each planner's `samples` (s), in instance order.
    pub run_wall_times_s: Vec<Vec<f64>>,
    /// Runs finished by this attempt (not resumed), over every planner.
    pub new_runs: u64,
    /// Whether the interrupt flag stopped the sweep before every run finished.
    pub interrupted: bool,
    /// Wall time of the whole sweep (s); not reproducible.
    pub wall_time_s: f64,
}

impl PairedSweepOutcome {
    /// How the sweep ended, over every planner's runs.
    pub fn verdict(&self) -> SweepVerdict {
        let sum = |f: fn(&SweepSummary) -> u64| self.summaries.iter().map(f).sum::<u64>();
        let (missing, failed) = (sum(|s| s.missing_runs), sum(|s| s.diverged));
        if missing > 0 {
            SweepVerdict::Interrupted { missing }
        } else if failed > 0 {
            SweepVerdict::RunsFailed {
                failed,
                of: sum(|s| s.runs),
            }
        } else {
            SweepVerdict::Complete
        }
    }

    /// The report (`--json`): one planner's [`SweepSummary`] as a single-planner sweep writes
    /// it, or with several planners the [`PairedSweepSummary`] (per-planner aggregates and the
    /// paired differences against the first).
    pub fn report(&self) -> SweepReport {
        match self.summaries.as_slice() {
            [single] => SweepReport::Single(Box::new(single.clone())),
            _ => SweepReport::Paired(PairedSweepSummary::from_summaries(
                self.summaries.clone(),
                self.wall_time_s,
            )),
        }
    }
}

/// The warning for a sweep of a scenario without `[randomise]`: every instance is the same run.
pub fn unrandomised_warning(scenario: &Scenario) -> Option<String> {
    scenario.randomise.is_empty().then(|| {
        format!(
            "scenario {} randomises nothing: every instance is the same run",
            scenario.name
        )
    })
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
    simulate_run(&plan.scenario, plan.planner.as_deref(), seed, interrupt)
}

/// Runs instance `seed` of `scenario` with `planner` (`None`: the scenario's own) among the
/// built-in planners: what `merge_sim run --scenario S [--planner P] --seed <seed>` runs.
pub fn simulate_run(
    scenario: &Scenario,
    planner: Option<&str>,
    seed: u64,
    interrupt: Option<Arc<AtomicBool>>,
) -> Result<RunSummary, sim::SimError> {
    simulate_run_with(
        scenario,
        planner,
        seed,
        interrupt,
        &BehaviourRegistry::builtin(),
    )
}

/// [`simulate_run`] with the planners of `registry` (a user's among them).
pub fn simulate_run_with(
    scenario: &Scenario,
    planner: Option<&str>,
    seed: u64,
    interrupt: Option<Arc<AtomicBool>>,
    registry: &BehaviourRegistry,
) -> Result<RunSummary, sim::SimError> {
    let options = crate::experiment::InstanceOptions {
        planner: planner.map(str::to_string),
        seed: Some(seed),
        keep_time_series: false,
        interrupt,
        profile: false,
    };
    crate::experiment::run_instance(
        scenario,
        &options,
        sim::recording::Recorder::disabled(),
        registry,
        |_| {},
    )
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
    run_paired_sweep(&PairedSweepPlan::from(plan), options, on_run).map(single_outcome)
}

/// Runs the plan's shard with the simulator, every instance once per planner (the library
/// entry of `merge_sim sweep --planners`); `on_run` is called with each run as it finishes
/// (from the worker threads, in completion order). The rows, aggregates and paired differences
/// do not depend on the thread count or the scheduling.
pub fn run_paired_sweep(
    plan: &PairedSweepPlan,
    options: &SweepOptions,
    on_run: &(dyn Fn(&FinishedRun) + Sync),
) -> Result<PairedSweepOutcome, SweepError> {
    let interrupt = options.interrupt.clone();
    run_paired_sweep_with(
        plan,
        options,
        on_run,
        |request: &RunRequest| match simulate_run_with(
            &plan.scenario,
            request.planner.as_deref(),
            request.seed,
            interrupt.clone(),
            &options.registry,
        ) {
            Ok(summary) => Ok(RunFigures::of(&summary)),
            Err(sim::SimError::Interrupted { .. }) => Err(RunFailure::Interrupted),
            Err(e) => Err(RunFailure::Failed(e.to_string())),
        },
    )
}

/// Checks a plan and its options before any work.
pub fn validate(plan: &SweepPlan, options: &SweepOptions) -> Result<(), SweepError> {
    validate_paired(&PairedSweepPlan::from(plan), options)
}

/// [`run_sweep`] with any runner (`seed → figures or failure`), e.g. a fake one in tests (its
/// rows have no per-vehicle figures).
pub fn run_sweep_with<F>(
    plan: &SweepPlan,
    options: &SweepOptions,
    on_run: &(dyn Fn(&FinishedRun) + Sync),
    runner: F,
) -> Result<SweepOutcome, SweepError>
where
    F: Fn(u64) -> Result<RunMetrics, RunFailure> + Sync,
{
    run_paired_sweep_with(
        &PairedSweepPlan::from(plan),
        options,
        on_run,
        |request: &RunRequest| {
            runner(request.seed).map(|metrics| RunFigures {
                metrics,
                vehicles: Vec::new(),
            })
        },
    )
    .map(single_outcome)
}

/// The outcome of a one-planner [`PairedSweepOutcome`].
fn single_outcome(outcome: PairedSweepOutcome) -> SweepOutcome {
    let PairedSweepOutcome {
        summaries,
        run_wall_times_s,
        new_runs,
        interrupted,
        ..
    } = outcome;
    // A plan of one planner gives exactly one summary (engine invariant).
    let summary = summaries.into_iter().next().unwrap_or_else(|| {
        SweepSummary::from_rows(
            &SweepIdentity {
                scenario: String::new(),
                scenario_fingerprint: String::new(),
                params: String::new(),
                planner: String::new(),
                planners: Vec::new(),
                seed: 0,
                total_runs: 0,
            },
            Shard::WHOLE,
            Vec::new(),
            0.0,
        )
    });
    SweepOutcome {
        summary,
        run_wall_times_s: run_wall_times_s.into_iter().next().unwrap_or_default(),
        new_runs,
        interrupted,
    }
}

#[cfg(test)]
mod paired_tests;
#[cfg(test)]
mod tests;
