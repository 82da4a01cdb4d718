//! Replaying a sweep's row as a user does: by its sweep seed and instance
//! (`run --sweep-seed K --instance I`), or by its seed as the file writes it (`0x…`) or as an
//! older file wrote it (decimal); `run --seed` saying what it drew; a seed that went through a
//! double refused; and the "never" flags and counts (`n`) of the rows and tables.

mod common;

use std::path::Path;

use common::{merge_sim, scratch, stderr};
use serde_json::Value;

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn jsonl(path: &Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// The run-level figures of `merge_sim run --json` that a sweep row carries, as the row names
/// them.
fn run_figures(run: &Value) -> Vec<(&'static str, Value)> {
    let vehicles = run["vehicles"].as_array().unwrap();
    let peak = |key: &str| {
        vehicles
            .iter()
            .map(|v| v[key].as_f64().unwrap())
            .fold(0.0, f64::max)
    };
    vec![
        ("collisions", run["collisions"].clone()),
        ("near_miss", run["near_miss"].clone()),
        ("min_ttc_s", run["min_ttc_s"].clone()),
        ("min_gap_m", run["min_gap_m"].clone()),
        ("tet_s", run["tet_s"].clone()),
        ("fallbacks", run["planner_stats"]["fallbacks"].clone()),
        ("plans", run["planner_stats"]["plans"].clone()),
        (
            "peak_yaw_rate_radps",
            serde_json::json!(peak("max_abs_yaw_rate_radps")),
        ),
        (
            "peak_sideslip_rad",
            serde_json::json!(peak("max_abs_sideslip_rad")),
        ),
    ]
}

/// The urgent merge, 4 s, with the obstacle ahead in the ego's lane at a cruise speed drawn
/// from 14 to 25 m/s: slower than the ego the pair closes (a finite min TTC), faster it never
/// does (in the unchanged urgent merge no pair ever closes).
fn closing_scenario(dir: &Path) -> String {
    let out = merge_sim(&["scenario", "show", "urgent_merge"]);
    assert!(out.status.success());
    let mut text = String::from_utf8(out.stdout).unwrap();
    for (old, new) in [
        ("duration_s = 25.0", "duration_s = 4.0"),
        ("lane = \"upper\"", "lane = \"lower\""),
        (
            "x_m = { uniform = [-3.0, 3.0] }",
            "x_m = { uniform = [-3.0, 3.0] }\ncruise_speed_mps = { uniform = [-1.0, 9.0] }",
        ),
    ] {
        assert_eq!(text.matches(old).count(), 1, "{old}");
        text = text.replace(old, new);
    }
    let path = dir.join("closing.toml");
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

fn assert_same_run(run: &Value, row: &Value, what: &str) {
    assert_eq!(run["seed"], row["seed"], "{what}: seed");
    assert_eq!(run["drawn"], row["drawn"], "{what}: drawn");
    for (key, value) in run_figures(run) {
        assert_eq!(value, row[key], "{what}: {key}");
    }
}

#[test]
fn rows_replay_by_sweep_seed_and_instance_and_by_seed_in_either_form() {
    let dir = scratch("replay_rows");
    let scenario = closing_scenario(&dir);
    let rows_path = dir.join("rows.jsonl");
    let summary_path = dir.join("sweep.json");
    // The sweep seed in hex, as the files write it: the same sweep as --seed 42.
    let out = merge_sim(&[
        "sweep",
        "--quiet",
        "--scenario",
        &scenario,
        "--planners",
        "pf-cs,pf-iso",
        "--runs",
        "4",
        "--seed",
        "0x2a",
        "--jsonl",
        p(&rows_path),
        "--json",
        p(&summary_path),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let rows = jsonl(&rows_path);
    assert_eq!(rows.len(), 8);
    for row in &rows {
        assert_eq!(row["sweep_seed"], "0x000000000000002a");
        let seed = row["seed"].as_str().unwrap();
        assert!(seed.starts_with("0x") && seed.len() == 18, "{seed}");
        // The never flags say what the nulls mean.
        assert_eq!(
            row["min_ttc_never"],
            Value::Bool(row["min_ttc_s"].is_null())
        );
        assert_eq!(
            row["min_gap_never"],
            Value::Bool(row["min_gap_m"].is_null())
        );
        for vehicle in row["vehicles"].as_array().unwrap() {
            assert_eq!(
                vehicle["slowing_onset_never"],
                Value::Bool(vehicle["slowing_onset_s"].is_null())
            );
        }
    }
    let find = |instance: u64, planner: &str| {
        rows.iter()
            .find(|r| r["instance"] == instance && r["planner"] == planner)
            .unwrap()
            .clone()
    };
    for (instance, planner, sweep_seed) in [(3, "pf-iso", "42"), (1, "pf-cs", "0x2a")] {
        let row = find(instance, planner);
        let json = dir.join(format!("replay_{instance}_{planner}.json"));
        let instance_text = instance.to_string();
        let out = merge_sim(&[
            "run",
            "--no-rrd",
            "--quiet",
            "--scenario",
            &scenario,
            "--planner",
            planner,
            "--sweep-seed",
            sweep_seed,
            "--instance",
            &instance_text,
            "--json",
            p(&json),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert_same_run(
            &read_json(&json),
            &row,
            &format!("--sweep-seed {sweep_seed} --instance {instance} ({planner})"),
        );
    }
    // Different instances are different runs (the replay does pick the row's instance).
    assert_ne!(
        find(3, "pf-iso")["min_gap_m"],
        find(2, "pf-iso")["min_gap_m"]
    );

    // By seed: the hex string of the row, and the decimal form older files wrote.
    let row = find(2, "pf-iso");
    let hex = row["seed"].as_str().unwrap().to_string();
    let decimal = mergesim::exact_seed::parse_seed(&hex).unwrap().to_string();
    for seed in [&hex, &decimal] {
        let json = dir.join("by_seed.json");
        std::fs::remove_file(&json).ok();
        let out = merge_sim(&[
            "run",
            "--no-rrd",
            "--quiet",
            "--scenario",
            &scenario,
            "--planner",
            "pf-iso",
            "--seed",
            seed,
            "--json",
            p(&json),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert_same_run(&read_json(&json), &row, &format!("--seed {seed}"));
    }

    // n: the counts the statistics are over, and the never counts, in the JSON and the table.
    let summary = read_json(&summary_path);
    for planner in &summary["per_planner"].as_array().unwrap()[..] {
        let name = planner["planner"].as_str().unwrap();
        let mine: Vec<&Value> = rows.iter().filter(|r| r["planner"] == name).collect();
        assert_eq!(planner["means_n"], 4);
        assert_eq!(planner["percentiles_n"], 4);
        let never = mine.iter().filter(|r| r["min_ttc_never"] == true).count();
        assert_eq!(planner["runs_min_ttc_never"], never as u64, "{name}");
    }
    let ttc = summary["paired_differences"]
        .as_array()
        .unwrap()
        .iter()
        .find(|d| d["metric"] == "min_ttc_s" && d["vehicle"].is_null())
        .unwrap();
    let (mut never, mut baseline_never, mut both_finite) = (0, 0, 0);
    for instance in 0..4 {
        let (a, b) = (find(instance, "pf-iso"), find(instance, "pf-cs"));
        never += u64::from(a["min_ttc_never"] == true);
        baseline_never += u64::from(b["min_ttc_never"] == true);
        both_finite += u64::from(a["min_ttc_never"] == false && b["min_ttc_never"] == false);
    }
    // The scenario gives both kinds, so the counts differ and are told apart.
    assert!(
        never > 0 && both_finite > 0,
        "never {never}, finite pairs {both_finite}"
    );
    assert_eq!(ttc["compared"], 4);
    assert_eq!(ttc["never"], never);
    assert_eq!(ttc["baseline_never"], baseline_never);
    assert_eq!(ttc["pairs"], both_finite);
    // Printed beside the means: the table of the same sweep.
    let out = merge_sim(&[
        "sweep",
        "--scenario",
        &scenario,
        "--planners",
        "pf-cs,pf-iso",
        "--runs",
        "4",
        "--seed",
        "42",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("means over n 4 completed runs"), "{table}");
    assert!(
        table.contains("never P/B") && table.contains("n = pairs with both values finite"),
        "{table}"
    );
    let ttc_line = table
        .lines()
        .find(|l| l.contains("min_ttc_s") && l.contains("(run)"))
        .unwrap();
    let cells: Vec<&str> = ttc_line.split_whitespace().collect();
    assert_eq!(
        cells[3..6].to_vec(),
        vec![
            "4".to_string(),
            format!("{never}/{baseline_never}"),
            both_finite.to_string()
        ],
        "{ttc_line}"
    );
}

#[test]
fn run_with_a_seed_prints_the_seed_and_every_value_it_drew() {
    let dir = scratch("replay_drawn");
    let rows_path = dir.join("rows.jsonl");
    let out = merge_sim(&[
        "sweep",
        "--quiet",
        "--planner",
        "pf-iso",
        "--runs",
        "2",
        "--seed",
        "5",
        "--jsonl",
        p(&rows_path),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let row = jsonl(&rows_path)
        .into_iter()
        .find(|r| r["instance"] == 1)
        .unwrap();
    let seed = row["seed"].as_str().unwrap();
    let json = dir.join("run.json");
    let out = merge_sim(&[
        "run",
        "--no-rrd",
        "--planner",
        "pf-iso",
        "--sweep-seed",
        "5",
        "--instance",
        "1",
        "--json",
        p(&json),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    let decimal = mergesim::exact_seed::parse_seed(seed).unwrap();
    assert!(
        err.contains(&format!(
            "seed {seed} (= {decimal}; instance 1 of sweep seed 0x0000000000000005) drew"
        )),
        "{err}"
    );
    let drawn = row["drawn"].as_object().unwrap();
    assert!(drawn.len() >= 5, "{drawn:?}");
    for (name, value) in drawn {
        let unit = if name.ends_with("_mps") {
            " m/s"
        } else if name.ends_with("_m") {
            " m"
        } else if name.ends_with("_s") {
            " s"
        } else {
            ""
        };
        let line = format!("  {name} = {}{unit}\n", value.as_f64().unwrap());
        assert!(err.contains(&line), "missing {line:?} in\n{err}");
    }
    // stdout stays the run's table; the drawn values are in the JSON too.
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(!table.contains(" drew "), "{table}");
    assert_eq!(read_json(&json)["drawn"], row["drawn"]);
    // --quiet prints nothing; the nominal run has no `drawn`.
    let out = merge_sim(&["run", "--no-rrd", "--quiet", "--seed", seed]);
    assert!(
        out.status.success() && out.stderr.is_empty(),
        "{}",
        stderr(&out)
    );
    let nominal = dir.join("nominal.json");
    let out = merge_sim(&["run", "--no-rrd", "--quiet", "--json", p(&nominal)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(read_json(&nominal).get("drawn").is_none());
}

#[test]
fn a_seed_that_went_through_a_double_is_refused_with_exit_2() {
    let dir = scratch("replay_bad_seed");
    let json = dir.join("run.json");
    // What pandas prints of a seed it read as a float.
    for (args, needle) in [
        (vec!["--seed", "9.853264649648847e18"], "not a whole number"),
        (vec!["--seed", "12.0"], "not a whole number"),
        (vec!["--seed", "0xZZ"], "not a seed"),
        (vec!["--seed", "0x10000000000000000"], "64 bits"),
        (
            vec!["--seed", "3", "--sweep-seed", "1", "--instance", "2"],
            "cannot be used with",
        ),
        (vec!["--sweep-seed", "1"], "--instance"),
        (vec!["--instance", "1"], "--sweep-seed"),
    ] {
        let mut all = vec!["run", "--no-rrd", "--json", p(&json)];
        all.extend(args.iter().copied());
        let out = merge_sim(&all);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
        assert!(!json.exists(), "{args:?} wrote {}", json.display());
    }
    let out = merge_sim(&["sweep", "--runs", "1", "--seed", "4.2e1"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
}
