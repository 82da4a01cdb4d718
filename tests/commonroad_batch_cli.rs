//! A CommonRoad scenario's figures in the batch outputs: `sweep` rows (JSONL, JSON, Parquet)
//! and aggregate, `compare`'s caption and table, `grid`'s default vehicle, and `run`'s default
//! recording name, which carry the recorded-traffic mode; a built-in scenario's outputs
//! stay as they were.

mod common;

use std::path::Path;

use common::{merge_sim, scratch, stderr};

const US101: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/commonroad/USA_US101-4_1_T-1.xml"
);

/// The keys a row or an aggregate carries on a CommonRoad road only.
const ROW_KEYS: [&str; 6] = [
    "recorded_traffic",
    "collisions_caused_by_replay",
    "min_gap_to_recorded_m",
    "min_ttc_to_recorded_s",
    "goal_reached",
    "goal_time_s",
];

/// Runs a two-run sweep of `scenario` into `dir`; returns its JSONL rows, its `--json`
/// aggregate and its stdout.
fn sweep(
    dir: &Path,
    scenario: &str,
    extra: &[&str],
) -> (Vec<serde_json::Value>, serde_json::Value, String) {
    let jsonl = dir.join("rows.jsonl");
    let json = dir.join("sweep.json");
    let parquet = dir.join("rows.parquet");
    let mut args = vec![
        "sweep",
        "--scenario",
        scenario,
        "--runs",
        "2",
        "--threads",
        "2",
        "--jsonl",
        jsonl.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
        "--parquet",
        parquet.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let out = merge_sim(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let rows = std::fs::read_to_string(&jsonl)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let aggregate = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    (
        rows,
        aggregate,
        String::from_utf8_lossy(&out.stdout).into_owned(),
    )
}

/// The column names of a Parquet file.
fn parquet_columns(path: &Path) -> Vec<String> {
    let file = std::fs::File::open(path).unwrap();
    let builder =
        parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder::try_new(file).unwrap();
    builder
        .schema()
        .fields()
        .iter()
        .map(|f| f.name().clone())
        .collect()
}

#[test]
fn a_us101_replay_sweep_counts_the_collisions_caused_by_replay_in_every_output() {
    let dir = scratch("crbatch_sweep_replay");
    let (rows, aggregate, stdout) = sweep(&dir, US101, &["--recorded-traffic", "replay"]);
    assert_eq!(rows.len(), 2);
    let mut caused = 0;
    for row in &rows {
        assert_eq!(row["status"], "completed", "{row}");
        assert_eq!(row["recorded_traffic"], "replay", "{row}");
        // `merge_sim run` on this file measured 2 on 2026-12-02.
        let n = row["collisions_caused_by_replay"].as_u64().unwrap();
        assert!(n > 0, "{row}");
        caused += n;
        assert!(row["min_gap_to_recorded_m"].is_number(), "{row}");
        assert!(row["goal_reached"].is_boolean(), "{row}");
        assert!(row.get("goal_time_s").is_some(), "{row}");
    }
    assert_eq!(aggregate["recorded_traffic"], "replay", "{aggregate}");
    assert_eq!(aggregate["collisions_caused_by_replay"], caused);
    assert_eq!(aggregate["runs_with_collisions_caused_by_replay"], 2);
    assert_eq!(aggregate["runs_with_goal"], 2);
    assert!(
        stdout.contains(&format!(
            "recorded traffic replay: collisions caused by replay {caused} (in 2 runs)"
        )),
        "{stdout}"
    );
    let columns = parquet_columns(&dir.join("rows.parquet"));
    for key in ROW_KEYS {
        assert!(columns.iter().any(|c| c == key), "{key}: {columns:?}");
    }
    // The rows read back: resuming the finished sweep runs nothing and reports the same.
    let jsonl = dir.join("rows.jsonl");
    let json = dir.join("resumed.json");
    let out = merge_sim(&[
        "sweep",
        "--scenario",
        US101,
        "--recorded-traffic",
        "replay",
        "--runs",
        "2",
        "--jsonl",
        jsonl.to_str().unwrap(),
        "--resume",
        "--json",
        json.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let resumed: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(resumed["samples"], aggregate["samples"]);
    assert_eq!(resumed["collisions_caused_by_replay"], caused);
}

#[test]
fn a_sweep_without_recorded_traffic_names_the_mode_and_has_none_to_meet() {
    let dir = scratch("crbatch_sweep_none");
    let (rows, aggregate, _) = sweep(&dir, US101, &["--recorded-traffic", "none"]);
    for row in &rows {
        assert_eq!(row["recorded_traffic"], "none", "{row}");
        assert_eq!(row["collisions_caused_by_replay"], 0, "{row}");
        assert!(row["min_gap_to_recorded_m"].is_null(), "{row}");
    }
    assert_eq!(aggregate["recorded_traffic"], "none");
    assert_eq!(aggregate["collisions_caused_by_replay"], 0);
}

#[test]
fn a_built_in_sweep_has_no_commonroad_columns() {
    let dir = scratch("crbatch_sweep_builtin");
    let (rows, aggregate, stdout) = sweep(&dir, "urgent_merge", &["--duration", "3"]);
    for key in ROW_KEYS {
        for row in &rows {
            assert!(row.get(key).is_none(), "{key}: {row}");
        }
        assert!(aggregate.get(key).is_none(), "{key}: {aggregate}");
    }
    assert!(!stdout.contains("recorded traffic"), "{stdout}");
    let columns = parquet_columns(&dir.join("rows.parquet"));
    for key in ROW_KEYS {
        assert!(!columns.iter().any(|c| c == key), "{key}: {columns:?}");
    }
}

#[test]
fn compare_names_the_recorded_traffic_mode_and_the_collisions_it_caused() {
    let dir = scratch("crbatch_compare");
    let markdown = dir.join("compare.md");
    let json = dir.join("compare.json");
    let out = merge_sim(&[
        "compare",
        "--scenario",
        US101,
        "--recorded-traffic",
        "replay",
        "--planners",
        "pf-iso,pf-cs",
        "--markdown",
        markdown.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let table = String::from_utf8_lossy(&out.stdout);
    let caption = table.lines().next().unwrap_or_default();
    assert!(caption.contains("· recorded traffic replay ·"), "{table}");
    let caused = table
        .lines()
        .find(|l| l.starts_with("caused by replay"))
        .unwrap_or_else(|| panic!("{table}"));
    let value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(value["recorded_traffic"], "replay");
    let counts: Vec<String> = value["runs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["collisions_caused_by_replay"].to_string())
        .collect();
    assert_eq!(
        caused.split_whitespace().skip(3).collect::<Vec<_>>(),
        counts
    );
    assert!(counts.iter().any(|c| c != "0"), "{table}");
    let md = std::fs::read_to_string(&markdown).unwrap();
    assert!(md.lines().next().unwrap_or_default() == caption, "{md}");
    assert!(md.contains("| caused by replay |"), "{md}");

    let builtin_json = dir.join("builtin.json");
    let out = merge_sim(&[
        "compare",
        "--planners",
        "pf-iso",
        "--json",
        builtin_json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let builtin = String::from_utf8_lossy(&out.stdout).into_owned()
        + &std::fs::read_to_string(&builtin_json).unwrap();
    assert!(!builtin.contains("recorded traffic"), "{builtin}");
    assert!(!builtin.contains("caused by replay"), "{builtin}");
}

#[test]
fn grid_on_a_commonroad_file_compares_its_ego_by_default() {
    let dir = scratch("crbatch_grid");
    let json = dir.join("grid.json");
    let out = merge_sim(&[
        "grid",
        "--scenario",
        US101,
        "--base-only",
        "--planners",
        "pf-iso,pf-cs",
        "--quiet",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(value["vehicle"], "ego");
    // A name that is not there is still refused.
    let out = merge_sim(&[
        "grid",
        "--scenario",
        US101,
        "--base-only",
        "--vehicle",
        "obstacle",
        "--quiet",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("vehicles: ego"), "{}", stderr(&out));
}

#[cfg(feature = "rerun")]
#[test]
fn run_recordings_of_one_file_in_two_modes_do_not_overwrite_each_other() {
    use std::process::Command;
    let dir = scratch("crbatch_rrd");
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_merge_sim"))
            .current_dir(&dir)
            .args(["run", "--quiet"])
            .args(args)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr(&out));
    };
    run(&["--scenario", US101, "--duration", "1"]);
    run(&[
        "--scenario",
        US101,
        "--recorded-traffic",
        "none",
        "--duration",
        "1",
    ]);
    run(&["--scenario", US101, "--recorded-traffic", "reactive"]);
    run(&["--scenario", "urgent_merge", "--duration", "1"]);
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "USA_US101-4_1_T-1_pf-iso_1s.rrd",
            "USA_US101-4_1_T-1_pf-iso_none_1s.rrd",
            "USA_US101-4_1_T-1_pf-iso_reactive.rrd",
            "urgent_merge_pf-iso.rrd",
        ]
    );
}
