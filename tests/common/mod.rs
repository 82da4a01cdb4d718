//! Helpers shared by the integration tests (each test file is its own crate and uses a subset,
//! hence `dead_code` is allowed here).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use mergesim::experiment::{InstanceOptions, run_quietly};
use mergesim::planner::PlannerKind;
use mergesim::scenarios::scenario::Scenario;
use mergesim::sim::RunOutcome;

/// Runs `scenario` in the closed loop without recording (`planner` overrides every
/// planner-driven vehicle's planner; `seed` seeds the V2V drops of the nominal scenario) through
/// the library's one entry, `mergesim::experiment`; a failure panics with the scenario's name.
pub fn simulate(
    scenario: &Scenario,
    planner: Option<PlannerKind>,
    seed: u64,
    keep_time_series: bool,
) -> RunOutcome {
    // The nominal scenario with the run's seed for the V2V stream (not a drawn instance).
    let mut nominal = scenario.clone();
    nominal.randomise = Default::default();
    let options = InstanceOptions {
        planner: planner.map(|k| k.name().to_string()),
        seed: Some(seed),
        keep_time_series,
        interrupt: None,
        profile: false,
    };
    run_quietly(&nominal, &options)
        .unwrap_or_else(|e| panic!("{}: {e}", scenario.name))
        .outcome
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

/// `merge_sim run --no-rrd --quiet --json JSON ARGS…`: asserts that it succeeded and returns
/// the summary it wrote to `json`.
pub fn run_summary(json: &Path, args: &[&str]) -> serde_json::Value {
    let json_arg = json.to_str().unwrap();
    let mut all = vec!["run", "--no-rrd", "--quiet", "--json", json_arg];
    all.extend_from_slice(args);
    let out = merge_sim(&all);
    assert!(out.status.success(), "{}", stderr(&out));
    serde_json::from_slice(&std::fs::read(json).unwrap()).unwrap()
}
