//! `merge_sim sweep --planners`: paired multi-planner sweeps as a user runs them — complete rows,
//! shards merged, an interrupted JSONL resumed, Parquet, and bad input refused.

mod common;

use std::path::{Path, PathBuf};

use common::{merge_sim, scratch, stderr};

use serde_json::Value;

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The report without its wall-clock times (the only figures that differ between runs).
fn without_wall_times(mut v: Value) -> Value {
    v["wall_time_s"] = Value::Null;
    if let Some(parts) = v["per_planner"].as_array_mut() {
        for part in parts {
            part["wall_time_s"] = Value::Null;
        }
    }
    v
}

fn jsonl(path: &Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// The urgent merge shortened to 6 s (the merge itself is not reached; the tests are about the
/// sweep's bookkeeping), written to `dir`; without its `[randomise]` tables if `randomised` is
/// false.
fn short_scenario(dir: &Path, randomised: bool) -> PathBuf {
    let text = mergesim::scenarios::builtin::toml_of("urgent_merge").unwrap();
    assert!(text.contains("duration_s = 25.0"), "the built-in changed");
    let mut text = text.replace("duration_s = 25.0", "duration_s = 6.0");
    if !randomised {
        let start = text.find("[randomise]").expect("the built-in randomises");
        text.truncate(start);
    }
    let path = dir.join(if randomised {
        "short.toml"
    } else {
        "fixed.toml"
    });
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_paired_sweep_has_complete_rows_and_its_shards_and_resumption_give_the_same_report() {
    let dir = scratch("sweep_paired");
    let scenario = short_scenario(&dir, true);
    let common = [
        "sweep",
        "--quiet",
        "--scenario",
        p(&scenario),
        "--planners",
        "pf-cs,pf-iso",
        "--runs",
        "4",
        "--seed",
        "7",
    ];
    let (whole_json, whole_jsonl, whole_parquet) = (
        dir.join("whole.json"),
        dir.join("whole.jsonl"),
        dir.join("whole.parquet"),
    );
    let mut args = common.to_vec();
    args.extend(["--json", p(&whole_json), "--jsonl", p(&whole_jsonl)]);
    args.extend(["--parquet", p(&whole_parquet)]);
    let out = merge_sim(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let whole = read_json(&whole_json);
    assert_eq!(whole["planners"], serde_json::json!(["pf-cs", "pf-iso"]));
    assert_eq!(whole["per_planner"].as_array().unwrap().len(), 2);
    assert!(
        whole["paired_differences"]
            .as_array()
            .unwrap()
            .iter()
            .any(|d| d["metric"] == "min_gap_m" && d["planner"] == "pf-iso")
    );

    // Every (instance, planner) once, both planners of an instance on the same seed and values.
    let mut rows = jsonl(&whole_jsonl);
    assert_eq!(rows.len(), 8);
    rows.sort_by_key(|r| {
        (
            r["instance"].as_u64().unwrap(),
            r["planner"].as_str().unwrap().to_string(),
        )
    });
    for pair in rows.chunks(2) {
        assert_eq!(pair[0]["instance"], pair[1]["instance"]);
        assert_eq!(
            (&pair[0]["planner"], &pair[1]["planner"]),
            (&"pf-cs".into(), &"pf-iso".into())
        );
        assert_eq!(pair[0]["seed"], pair[1]["seed"]);
        assert_eq!(pair[0]["drawn"], pair[1]["drawn"]);
        assert!(pair[0]["drawn"]["sim.mu"].is_f64(), "{}", pair[0]["drawn"]);
        for row in pair {
            assert_eq!(row["planners"], whole["planners"]);
            let vehicles = row["vehicles"].as_array().unwrap();
            let names: Vec<&str> = vehicles
                .iter()
                .map(|v| v["name"].as_str().unwrap())
                .collect();
            assert_eq!(names, ["ego", "obstacle"]);
            assert!(vehicles[0]["min_speed_mps"].is_f64());
            assert!(vehicles[0].get("slowing_onset_s").is_some());
        }
    }
    assert_ne!(rows[0]["drawn"], rows[2]["drawn"]);

    // Two shards, merged (in reverse order), give the same report and the same Parquet bytes.
    let mut shards = Vec::new();
    for index in [1, 0] {
        let json = dir.join(format!("shard{index}.json"));
        let shard = format!("{index}/2");
        let mut args = common.to_vec();
        args.extend(["--threads", "1", "--shard", &shard, "--json", p(&json)]);
        let out = merge_sim(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        shards.push(json);
    }
    let (merged_json, merged_parquet) = (dir.join("merged.json"), dir.join("merged.parquet"));
    let out = merge_sim(&[
        "merge-results",
        p(&shards[0]),
        p(&shards[1]),
        "--json",
        p(&merged_json),
        "--parquet",
        p(&merged_parquet),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("paired differences against the baseline pf-cs")
            && table.contains("sweep urgent_merge pf-iso: seed 7"),
        "{table}"
    );
    assert_eq!(
        without_wall_times(read_json(&merged_json)),
        without_wall_times(whole.clone())
    );
    assert_eq!(
        std::fs::read(&merged_parquet).unwrap(),
        std::fs::read(&whole_parquet).unwrap()
    );

    // An interrupted sweep's JSONL (its first 3 rows) resumed: the same report.
    let resumed_jsonl = dir.join("resumed.jsonl");
    let text = std::fs::read_to_string(&whole_jsonl).unwrap();
    let head: String = text.lines().take(3).map(|l| format!("{l}\n")).collect();
    std::fs::write(&resumed_jsonl, head).unwrap();
    let resumed_json = dir.join("resumed.json");
    let mut args = common.to_vec();
    args.extend([
        "--jsonl",
        p(&resumed_jsonl),
        "--resume",
        "--json",
        p(&resumed_json),
    ]);
    let out = merge_sim(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(jsonl(&resumed_jsonl).len(), 8);
    assert_eq!(
        without_wall_times(read_json(&resumed_json)),
        without_wall_times(whole)
    );

    // Resuming it as a sweep of other planners is refused, naming the line and the field.
    let mut other = common.to_vec();
    other[5] = "pf-cs,pf-sp";
    other.extend(["--jsonl", p(&resumed_jsonl), "--resume"]);
    let out = merge_sim(&other);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("line 1") && stderr(&out).contains("planners"),
        "{}",
        stderr(&out)
    );

    // A row of an older mergesim (no planner list, no drawn values) is refused, naming the file
    // and line.
    let old = dir.join("old.jsonl");
    let mut row = jsonl(&whole_jsonl)[0].clone();
    let object = row.as_object_mut().unwrap();
    object.remove("planners");
    object.remove("drawn");
    object.remove("vehicles");
    std::fs::write(&old, format!("{row}\n")).unwrap();
    let mut args = common.to_vec();
    args.extend(["--jsonl", p(&old), "--resume"]);
    let out = merge_sim(&args);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("old.jsonl, line 1") && stderr(&out).contains("older mergesim"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn one_name_in_planners_is_the_same_sweep_as_planner() {
    let dir = scratch("sweep_paired_one");
    let scenario = short_scenario(&dir, true);
    let mut reports = Vec::new();
    let mut stdouts = Vec::new();
    for (flag, name) in [("--planner", "a.json"), ("--planners", "b.json")] {
        let json = dir.join(name);
        let out = merge_sim(&[
            "sweep",
            "--scenario",
            p(&scenario),
            flag,
            "pf-iso",
            "--runs",
            "2",
            "--json",
            p(&json),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        reports.push(without_wall_times(read_json(&json)));
        // The table but for its wall-time line.
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        stdouts.push(text.lines().skip(1).collect::<Vec<_>>().join("\n"));
    }
    assert_eq!(reports[0], reports[1]);
    assert_eq!(stdouts[0], stdouts[1]);
    assert_eq!(reports[0]["planner"], "pf-iso");
    assert!(reports[0].get("paired_differences").is_none());
}

#[test]
fn an_unknown_planner_in_the_list_exits_2_before_any_work() {
    let dir = scratch("sweep_paired_bad");
    let json = dir.join("out.json");
    for list in ["pf-cs,pf-xyz", "pf-cs,,pf-iso"] {
        let out = merge_sim(&[
            "sweep",
            "--runs",
            "2",
            "--planners",
            list,
            "--json",
            p(&json),
        ]);
        assert_eq!(out.status.code(), Some(2), "{list}: {}", stderr(&out));
        assert!(stderr(&out).contains("--planners"), "{}", stderr(&out));
        assert!(!json.exists());
    }
    let out = merge_sim(&[
        "sweep",
        "--runs",
        "2",
        "--planners",
        "pf-cs,pf-xyz",
        "--json",
        p(&json),
    ]);
    // The message names the bad value and the valid names.
    assert!(
        stderr(&out).contains("pf-xyz") && stderr(&out).contains("pf-iso-pred"),
        "{}",
        stderr(&out)
    );
    // A planner twice, and --planner with --planners, are refused too.
    let out = merge_sim(&[
        "sweep",
        "--runs",
        "2",
        "--planners",
        "pf-iso,pf-iso",
        "--json",
        p(&json),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("listed twice"), "{}", stderr(&out));
    let out = merge_sim(&[
        "sweep",
        "--runs",
        "2",
        "--planner",
        "pf-cs",
        "--planners",
        "pf-iso",
        "--json",
        p(&json),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(!json.exists());
}

#[test]
fn a_sweep_of_a_scenario_without_randomisation_warns_that_every_instance_is_the_same() {
    let dir = scratch("sweep_paired_fixed");
    let scenario = short_scenario(&dir, false);
    let rows = dir.join("rows.jsonl");
    let out = merge_sim(&[
        "sweep",
        "--scenario",
        p(&scenario),
        "--runs",
        "1",
        "--jsonl",
        p(&rows),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains(
            "warning: scenario urgent_merge randomises nothing: every instance is the same run"
        ),
        "{}",
        stderr(&out)
    );
    assert_eq!(jsonl(&rows)[0]["drawn"], serde_json::json!({}));
    // The randomised scenario does not warn.
    let randomised = short_scenario(&dir, true);
    let out = merge_sim(&["sweep", "--scenario", p(&randomised), "--runs", "1"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
}
