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
    fn fake(seed: u64) -> Result<RunMetrics, RunFailure> {
        match seed % 11 {
            0 => {
                return Err(RunFailure::Failed(
                    "simulation diverged at t = 3 s: test".into(),
                ));
            }
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
            degraded_plans: 0,
            plans: 10,
        })
    }

    #[test]
    fn aggregate_counts_follow_the_rows_and_failures_are_kept() {
        let outcome = run_sweep_with(
            &plan(60, Shard::WHOLE),
            &SweepOptions {
                threads: Some(2),
                ..SweepOptions::default()
            },
            &|_| {},
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
        assert_eq!(
            outcome.verdict(),
            SweepVerdict::RunsFailed {
                failed: diverged + panicked,
                of: 60
            }
        );
        let all_good = run_sweep_with(
            &plan(5, Shard::WHOLE),
            &SweepOptions::default(),
            &|_| {},
            |_| fake(2),
        )
        .unwrap();
        assert_eq!(all_good.verdict(), SweepVerdict::Complete);
    }

    #[test]
    fn merged_shards_equal_the_unsharded_sweep_whatever_the_threads() {
        let options = SweepOptions {
            threads: Some(1),
            ..SweepOptions::default()
        };
        let mut whole = run_sweep_with(&plan(23, Shard::WHOLE), &options, &|_| {}, fake)
            .unwrap()
            .summary;
        let mut parts = Vec::new();
        for index in [2, 0, 3, 1] {
            let shard = Shard::new(index, 4, "t").unwrap();
            let part = run_sweep_with(
                &plan(23, shard),
                &SweepOptions {
                    threads: Some(2),
                    ..SweepOptions::default()
                },
                &|_| {},
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
            &|_| {},
            fake,
        )
        .unwrap_err();
        assert!(err.to_string().contains("runs = 0"));
        let err = run_sweep_with(
            &plan(3, Shard::WHOLE),
            &SweepOptions {
                threads: Some(0),
                ..SweepOptions::default()
            },
            &|_| {},
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
            &|_| {},
            fake,
        )
        .unwrap()
        .summary;
        assert_eq!((part.runs, part.instances), (0, [0, 0]));
        assert_eq!(part.collision_rate, None);
        assert_eq!(part.collision_rate_ci95, None);
    }

    #[test]
    fn interrupted_then_resumed_sweep_equals_the_uninterrupted_one() {
        let whole = run_sweep_with(
            &plan(40, Shard::WHOLE),
            &SweepOptions::default(),
            &|_| {},
            fake,
        )
        .unwrap();
        assert!(!whole.interrupted && whole.summary.missing_runs == 0);
        // Interrupt after 13 runs have finished (one thread: deterministic count).
        let flag = Arc::new(AtomicBool::new(false));
        let finished = std::sync::Mutex::new(Vec::new());
        let options = SweepOptions {
            threads: Some(1),
            interrupt: Some(flag.clone()),
            ..SweepOptions::default()
        };
        let first = run_sweep_with(
            &plan(40, Shard::WHOLE),
            &options,
            &|run| {
                let mut rows = finished.lock().unwrap();
                rows.push(run.clone());
                if rows.len() == 13 {
                    flag.store(true, Ordering::Relaxed);
                }
            },
            fake,
        )
        .unwrap();
        assert!(first.interrupted);
        assert_eq!(first.verdict(), SweepVerdict::Interrupted { missing: 27 });
        assert_eq!(first.new_runs, 13);
        assert_eq!(first.summary.runs, 13);
        assert_eq!(first.summary.missing_runs, 27);
        assert!(
            first.summary.table().contains("INCOMPLETE"),
            "{}",
            first.summary.table()
        );
        // Resume with the rows handed out (through JSON, as the JSONL keeps them).
        let resume: Vec<FinishedRun> = finished
            .into_inner()
            .unwrap()
            .into_iter()
            .map(|run| FinishedRun {
                row: serde_json::from_str(&serde_json::to_string(&run.row).unwrap()).unwrap(),
                wall_time_s: run.wall_time_s,
            })
            .collect();
        let ran_again = std::sync::atomic::AtomicU64::new(0);
        let second = run_sweep_with(
            &plan(40, Shard::WHOLE),
            &SweepOptions {
                threads: Some(2),
                resume: resume.clone(),
                ..SweepOptions::default()
            },
            &|_| {
                ran_again.fetch_add(1, Ordering::Relaxed);
            },
            fake,
        )
        .unwrap();
        assert_eq!(
            ran_again.into_inner(),
            27,
            "finished runs must not run again"
        );
        assert_eq!(second.new_runs, 27);
        let (mut a, mut b) = (whole.summary, second.summary);
        a.wall_time_s = 0.0;
        b.wall_time_s = 0.0;
        assert_eq!(
            serde_json::to_string(&a).unwrap(),
            serde_json::to_string(&b).unwrap()
        );
        // Rows of another sweep (other seed) or duplicated rows are refused before any work.
        let mut foreign = plan(40, Shard::WHOLE);
        foreign.seed = 78;
        let options = SweepOptions {
            resume: resume.clone(),
            ..SweepOptions::default()
        };
        let err = run_sweep_with(&foreign, &options, &|_| panic!("ran"), fake).unwrap_err();
        assert!(err.to_string().contains("not a row of this sweep"), "{err}");
        let mut twice = resume.clone();
        twice.push(resume[0].clone());
        let options = SweepOptions {
            resume: twice,
            ..SweepOptions::default()
        };
        let err = run_sweep_with(&plan(40, Shard::WHOLE), &options, &|_| panic!("ran"), fake)
            .unwrap_err();
        assert!(err.to_string().contains("twice"), "{err}");
    }

    #[test]
    fn run_and_thread_counts_are_bounded() {
        let err = run_sweep_with(
            &plan(MAX_RUNS + 1, Shard::WHOLE),
            &SweepOptions::default(),
            &|_| {},
            fake,
        )
        .unwrap_err();
        assert!(err.to_string().contains("1 to 1000000"), "{err}");
        let err = run_sweep_with(
            &plan(3, Shard::WHOLE),
            &SweepOptions {
                threads: Some(MAX_THREADS + 1),
                ..SweepOptions::default()
            },
            &|_| {},
            fake,
        )
        .unwrap_err();
        assert!(err.to_string().contains("threads = 1025"), "{err}");
    }
}
