//! A user's binary with its own planner (examples/own_planner_cli.rs: `mergesim::cli::main_with`
//! a registry holding `time-gap-cruise`) through the whole command line: `run`, `compare`,
//! `sweep`, `grid`, `study` and a scenario file's `driver` take the name, the rows carry it and
//! the figures are there; the stock `merge_sim` refuses the name (exit 2, listing the valid
//! ones).
//!
//! `cargo test --release` builds the example first (cargo builds a package's examples for its
//! tests); with a single test target, build it yourself first:
//! `cargo build --release --example own_planner_cli && cargo test --release --test own_planner_cli`.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{merge_sim, scratch, stderr};

const NAME: &str = "time-gap-cruise";

/// target/<profile>/examples/own_planner_cli, beside this test's deps/ folder.
fn own_binary() -> PathBuf {
    let exe = std::env::current_exe().expect("the test's own path");
    let deps = exe.parent().expect("the test binary's folder");
    let path = deps
        .join("../examples/own_planner_cli")
        .with_extension(std::env::consts::EXE_EXTENSION);
    assert!(
        path.is_file(),
        "{} is missing: build it with `cargo build --release --example own_planner_cli` \
         (a whole `cargo test` builds it, `cargo test --test own_planner_cli` does not)",
        path.display()
    );
    path
}

fn own(args: &[&str]) -> Output {
    let out = Command::new(own_binary())
        .args(args)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("SLURM_ARRAY_TASK_COUNT")
        .env_remove("JOB_COMPLETION_INDEX")
        .env_remove("MERGESIM_SHARD_COUNT")
        .output()
        .expect("own_planner_cli runs");
    assert!(
        out.status.success(),
        "own_planner_cli {args:?}: {:?}\n{}",
        out.status,
        stderr(&out)
    );
    out
}

fn s(path: &Path) -> &str {
    path.to_str().expect("a UTF-8 path")
}

fn json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn is_png(path: &Path) -> bool {
    std::fs::read(path).is_ok_and(|bytes| bytes.get(1..4) == Some(b"PNG"))
}

#[test]
fn run_and_compare_take_the_users_planner() {
    let dir = scratch("own_planner_run");
    let summary = dir.join("run.json");
    own(&[
        "run",
        "--planner",
        NAME,
        "--duration",
        "6",
        "--no-rrd",
        "--quiet",
        "--json",
        s(&summary),
    ]);
    let v = json(&summary);
    assert_eq!(v["planner"], NAME, "{v}");
    assert!(
        v["vehicles"].as_array().is_some_and(|a| a.len() == 2),
        "{v}"
    );

    let compared = dir.join("compare.json");
    let plots = dir.join("plots");
    std::fs::create_dir_all(&plots).unwrap();
    own(&[
        "compare",
        "--planners",
        &format!("pf-cs,{NAME}"),
        "--duration",
        "6",
        "--json",
        s(&compared),
        "--plots",
        s(&plots),
    ]);
    let v = json(&compared);
    let planners: Vec<&str> = v["runs"]
        .as_array()
        .expect("runs")
        .iter()
        .filter_map(|r| r["planner"].as_str())
        .collect();
    assert_eq!(planners, ["pf-cs", NAME]);
    assert!(is_png(&plots.join("paths.png")));
    let series = std::fs::read_to_string(plots.join("time_series.csv")).unwrap();
    assert!(series.contains(NAME), "time_series.csv lacks {NAME}");
}

#[test]
fn a_scenario_files_driver_names_the_users_planner() {
    let dir = scratch("own_planner_driver");
    let toml = String::from_utf8(merge_sim(&["scenario", "show", "urgent_merge"]).stdout).unwrap();
    // The obstacle (the second vehicle) driven by the user's planner, the ego by PF-ISO.
    let at = toml
        .rfind("driver = { planner = \"pf-iso\" }")
        .expect("the obstacle's driver");
    let toml = format!(
        "{}driver = {{ planner = \"{NAME}\" }}{}",
        &toml[..at],
        &toml[at + "driver = { planner = \"pf-iso\" }".len()..]
    );
    let scenario = dir.join("mixed.toml");
    std::fs::write(&scenario, toml).unwrap();
    let summary = dir.join("run.json");
    own(&[
        "run",
        "--scenario",
        s(&scenario),
        "--duration",
        "6",
        "--no-rrd",
        "--quiet",
        "--json",
        s(&summary),
    ]);
    // Two planners in the scenario: the run's label is `mixed`.
    assert_eq!(json(&summary)["planner"], "mixed");
    // The stock binary has no such planner: the scenario is refused as bad input.
    let out = merge_sim(&["run", "--scenario", s(&scenario), "--no-rrd", "--quiet"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains(NAME), "{}", stderr(&out));
    // The example registers its planner without a parameter type: a table for it is refused
    // by the user's binary before any work, naming the file, the key's line and the planner,
    // and nothing is written.
    let text = std::fs::read_to_string(&scenario).unwrap();
    // The text, an empty line, the table's header, its key.
    let key_line = text.lines().count() + 3;
    let with_table = dir.join("with_table.toml");
    std::fs::write(
        &with_table,
        format!("{text}\n[sim.planners.{NAME}]\ntime_gap_s = 2.0\n"),
    )
    .unwrap();
    let refused = dir.join("refused.json");
    let out = Command::new(own_binary())
        .args([
            "run",
            "--scenario",
            s(&with_table),
            "--no-rrd",
            "--quiet",
            "--json",
            s(&refused),
        ])
        .output()
        .expect("own_planner_cli runs");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("with_table.toml")
            && err.contains(&format!("line {key_line}: planners.{NAME}.time_gap_s"))
            && err.contains("takes no parameters (it was registered without a parameter type"),
        "{err}"
    );
    assert!(!refused.exists());
}

#[test]
fn sweep_and_grid_pair_the_users_planner_with_a_builtin() {
    let dir = scratch("own_planner_sweep");
    let (rows, aggregate) = (dir.join("rows.jsonl"), dir.join("sweep.json"));
    own(&[
        "sweep",
        "--planners",
        &format!("pf-cs,{NAME}"),
        "--runs",
        "3",
        "--duration",
        "6",
        "--quiet",
        "--jsonl",
        s(&rows),
        "--json",
        s(&aggregate),
    ]);
    let text = std::fs::read_to_string(&rows).unwrap();
    let planners: Vec<String> = text
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|row| row["status"] == "completed")
        .map(|row| row["planner"].as_str().unwrap_or_default().to_string())
        .collect();
    assert_eq!(
        planners.len(),
        6,
        "3 instances × 2 planners, all completed:\n{text}"
    );
    assert_eq!(planners.iter().filter(|p| *p == NAME).count(), 3);
    let v = json(&aggregate);
    assert!(v.to_string().contains(NAME), "the aggregate names {NAME}");

    let (csv, grid_json, png) = (dir.join("g.csv"), dir.join("g.json"), dir.join("g.png"));
    own(&[
        "grid",
        "--planners",
        &format!("{NAME},pf-cs"),
        "--path-gaps",
        "1",
        "--interaction-gaps",
        "2",
        "--duration",
        "6",
        "--quiet",
        "--csv",
        s(&csv),
        "--json",
        s(&grid_json),
        "--plot",
        s(&png),
    ]);
    let v = json(&grid_json);
    let grid_rows = v["grid"]["rows"].as_array().expect("grid rows");
    // 4 (prediction × sub-steps) × 1 τ × 1 τ_I cells, two planners, one instance.
    assert_eq!(grid_rows.len(), 8);
    assert_eq!(
        grid_rows.iter().filter(|r| r["planner"] == NAME).count(),
        4,
        "{v}"
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.lines().skip(1).any(|l| l.contains(NAME)), "{text}");
    assert!(is_png(&png));
}

#[test]
fn a_study_plan_names_the_users_planner() {
    let dir = scratch("own_planner_study");
    let plan = dir.join("own.toml");
    std::fs::write(
        &plan,
        format!(
            r#"name = "own"
description = "the user's cruise control against PF-ISO"
scenario = "urgent_merge"
planners = ["pf-iso", "{NAME}"]
reference = "pf-iso"

[instances]
n = 3
seed = 5

[factors]
"sim.duration_s" = [6.0]

[endpoints]
primary = {{ figure = "obstacle.max_abs_yaw_rate_radps", threshold = "0.01 rad/s" }}
"#
        ),
    )
    .unwrap();
    let report = dir.join("own.report");
    own(&["study", s(&plan), "--out", s(&report), "--quiet"]);
    let rows = std::fs::read_to_string(report.join("rows.jsonl")).unwrap();
    assert_eq!(rows.lines().count(), 6, "3 instances × 2 planners");
    assert_eq!(rows.lines().filter(|l| l.contains(NAME)).count(), 3);
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(md.contains(NAME), "report.md names {NAME}");
    assert!(is_png(&report.join("effects.png")));
    // The stock binary refuses the plan (exit 2) naming the planner.
    let out = merge_sim(&["study", s(&plan), "--out", s(&dir.join("stock")), "--quiet"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains(NAME), "{}", stderr(&out));
    // A scenario giving the planner a table it cannot take (registered without a parameter
    // type) is refused when the plan loads, naming the scenario's file and the key's line,
    // before any run and with nothing written.
    let toml = String::from_utf8(merge_sim(&["scenario", "show", "urgent_merge"]).stdout).unwrap();
    let key_line = toml.lines().count() + 3;
    std::fs::write(
        dir.join("tabled.toml"),
        format!("{toml}\n[sim.planners.{NAME}]\ntime_gap_s = 2.0\n"),
    )
    .unwrap();
    let tabled_plan = dir.join("tabled_plan.toml");
    let text = std::fs::read_to_string(&plan).unwrap();
    std::fs::write(
        &tabled_plan,
        text.replace("scenario = \"urgent_merge\"", "scenario = \"tabled.toml\""),
    )
    .unwrap();
    let out_dir = dir.join("tabled.report");
    let out = Command::new(own_binary())
        .args(["study", s(&tabled_plan), "--out", s(&out_dir), "--quiet"])
        .output()
        .expect("own_planner_cli runs");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("tabled.toml")
            && err.contains(&format!("line {key_line}: planners.{NAME}.time_gap_s")),
        "{err}"
    );
    assert!(!out_dir.exists());
}

#[test]
fn the_stock_binary_refuses_the_name_and_the_help_lists_it() {
    let builtins = mergesim::sim::registry::BehaviourRegistry::builtin()
        .names()
        .join(", ");
    for args in [
        vec!["run", "--planner", NAME],
        vec!["compare", "--planners", &format!("pf-cs,{NAME}")],
        vec![
            "sweep",
            "--planners",
            &format!("pf-cs,{NAME}"),
            "--runs",
            "3",
        ],
        vec!["grid", "--planners", &format!("{NAME},pf-cs")],
    ] {
        let out = merge_sim(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        let err = stderr(&out);
        assert!(
            err.contains(&format!("invalid value '{NAME}'"))
                && err.contains(&format!("unknown planner '{NAME}'; valid: {builtins}\n")),
            "{args:?}: {err}"
        );
    }
    // The user's binary lists its planner in --help and refuses a name it lacks the same way.
    let help = String::from_utf8(own(&["run", "--help"]).stdout).unwrap();
    assert!(
        help.contains(&format!("[registered: {builtins}, {NAME}]")),
        "{help}"
    );
    let out = Command::new(own_binary())
        .args(["run", "--planner", "pf-nope"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).starts_with(&format!(
            "error: invalid value 'pf-nope' for '--planner <PLANNER>': unknown planner 'pf-nope'; \
             valid: {builtins}, {NAME}"
        )),
        "{}",
        stderr(&out)
    );
}
