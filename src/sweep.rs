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

mod merge;
mod rows;
pub mod shard;
pub mod statistics;
mod summary;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::Instant;

use planner::PlannerKind;
use rayon::prelude::*;
use scenarios::Scenario;
use sim::rng::SplitMix64;

use thiserror::Error;

use crate::summary::RunSummary;
pub use merge::merge_shards;
pub use rows::{RunMetrics, RunRow, RunStatus};
pub use shard::{Shard, ShardError};
pub use summary::{SweepIdentity, SweepSummary};

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
