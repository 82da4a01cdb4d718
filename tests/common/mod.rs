//! Helpers shared by the integration tests (each test file is its own crate and uses a subset,
//! hence `dead_code` is allowed here).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use mergesim::planner::PlannerKind;
use mergesim::scenarios::Scenario;
use mergesim::sim::recording::Recorder;
use mergesim::sim::{RunOptions, RunOutcome, World};

/// Runs `scenario` in the closed loop without recording (`planner` overrides every
/// planner-driven vehicle's planner); a failure panics with the scenario's name.
pub fn simulate(
    scenario: &Scenario,
    planner: Option<PlannerKind>,
    seed: u64,
    keep_time_series: bool,
) -> RunOutcome {
    let options = RunOptions {
        planner_override: planner,
        seed,
        keep_time_series,
    };
    World::new(
        scenario.sim.clone(),
        &scenario.vehicles,
        &options,
        Recorder::disabled(),
    )
    .unwrap_or_else(|e| panic!("{}: {e}", scenario.name))
    .run(|_| {})
    .unwrap_or_else(|e| panic!("{}: {e}", scenario.name))
}

/// Runs the `merge_sim` binary with `args` and extra environment `env`. The shard variables of
/// Slurm and Kubernetes are removed first: a test run inside such a job must not pick up the
/// job's own shard.
pub fn merge_sim_env(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut command = Command::new(env!("CARGO_BIN_EXE_merge_sim"));
    command.args(args);
    for name in [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_COUNT",
        "SLURM_ARRAY_TASK_MIN",
        "SLURM_ARRAY_TASK_STEP",
        "JOB_COMPLETION_INDEX",
        "MERGESIM_SHARD_COUNT",
    ] {
        command.env_remove(name);
    }
    command.envs(env.iter().copied());
    command.output().expect("merge_sim runs")
}

/// Runs the `merge_sim` binary with `args`.
pub fn merge_sim(args: &[&str]) -> Output {
    merge_sim_env(args, &[])
}

/// An empty scratch directory under cargo's target tmpdir.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The process's stderr as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}
