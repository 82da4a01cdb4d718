//! Merge sequencing (`pf-iso-seq`, `planner::sequencing`) end to end: the dense merge with every
//! car sequenced, its parameter table in a scenario file, and its errors.

mod common;

use common::{merge_sim, scratch, stderr};

/// `merge_sim run` with `args` and `--json`, parsed.
fn run_json(dir: &std::path::Path, name: &str, args: &[&str]) -> serde_json::Value {
    common::run_summary(&dir.join(format!("{name}.json")), args)
}

/// The built-in dense merge's file with `extra` appended.
fn dense_merge_with(extra: &str) -> String {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/builtin/dense_merge.toml"
    ))
    .unwrap();
    format!("{text}\n{extra}")
}

/// x (m) at which `vehicle` changed from the ending lane 2 to lane 1, from the summary's events.
fn merge_x_m(summary: &serde_json::Value, vehicle: &str) -> Option<f64> {
    summary["events"]
        .as_array()?
        .iter()
        .filter_map(|e| e.as_str())
        .find(|e| {
            e.contains(&format!(
                ": {vehicle} changed lanes left, from lane 2 to lane 1"
            ))
        })
        .and_then(|e| e.split("at x = ").nth(1))
        .and_then(|rest| rest.split(' ').next())
        .and_then(|x| x.parse().ok())
}

/// The merge section's end on the dense merge's road (`merge_end_x_m`).
const LANE_END_X_M: f64 = 260.0;

fn assert_sequenced_merge_is_clean(summary: &serde_json::Value) {
    assert_eq!(summary["collisions"], 0, "{summary}");
    for v in summary["vehicles"].as_array().unwrap() {
        assert_eq!(v["collided"], false, "{v}");
    }
    for lower in ["lower1", "lower2", "lower3"] {
        let x = merge_x_m(summary, lower)
            .unwrap_or_else(|| panic!("{lower} never merged: {}", summary["events"]));
        assert!(x < LANE_END_X_M, "{lower} merged at x = {x} m");
    }
}

#[test]
fn a_dense_merge_with_sequencing_has_no_collision() {
    let dir = scratch("merge_sequencing_dense");
    let seq = run_json(
        &dir,
        "seq",
        &["--scenario", "dense_merge", "--planner", "pf-iso-seq"],
    );
    assert_eq!(seq["planner"], "pf-iso-seq", "{seq}");
    assert_sequenced_merge_is_clean(&seq);
    // Sequencing changes the speeds: the run is not PF-ISO's.
    let iso = run_json(
        &dir,
        "iso",
        &["--scenario", "dense_merge", "--planner", "pf-iso"],
    );
    assert_ne!(seq["vehicles"], iso["vehicles"]);
}

#[test]
fn with_lost_late_and_duplicated_messages_the_dense_merge_stays_clean() {
    // 30 % of the messages lost, 0.1 s latency, 20 % duplicated; a randomised instance (seed 1).
    let dir = scratch("merge_sequencing_faults");
    let file = dir.join("faults.toml");
    std::fs::write(
        &file,
        dense_merge_with(
            "",
        )
        .replace(
            "[randomise]\n",
            "[sim.v2v]\ndrop_probability = 0.3\nlatency_s = 0.1\nduplicate_probability = 0.2\n\n[randomise]\n",
        ),
    )
    .unwrap();
    let summary = run_json(
        &dir,
        "faults",
        &[
            "--scenario",
            file.to_str().unwrap(),
            "--planner",
            "pf-iso-seq",
            "--seed",
            "1",
        ],
    );
    assert_sequenced_merge_is_clean(&summary);
}

#[test]
fn the_parameter_table_is_read_and_a_bad_value_is_refused_naming_file_line_and_field() {
    let dir = scratch("merge_sequencing_params");
    let good = dir.join("good.toml");
    std::fs::write(
        &good,
        dense_merge_with("[sim.planners.pf-iso-seq]\nside_headway_s = 3.5\n"),
    )
    .unwrap();
    let base = run_json(
        &dir,
        "base",
        &["--scenario", "dense_merge", "--planner", "pf-iso-seq"],
    );
    let wider = run_json(
        &dir,
        "wider",
        &[
            "--scenario",
            good.to_str().unwrap(),
            "--planner",
            "pf-iso-seq",
        ],
    );
    assert_ne!(
        base["vehicles"], wider["vehicles"],
        "the table had no effect"
    );

    let bad = dir.join("bad.toml");
    let text = dense_merge_with("[sim.planners.pf-iso-seq]\nside_headway_s = -1.0\n");
    let line = text
        .lines()
        .position(|l| l.starts_with("side_headway_s"))
        .map(|i| i + 1)
        .unwrap();
    std::fs::write(&bad, &text).unwrap();
    let out = merge_sim(&["run", "--no-rrd", "--scenario", bad.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("bad.toml"), "{err}");
    assert!(err.contains(&format!("line {line}")), "{err}");
    assert!(err.contains("side_headway_s"), "{err}");

    let unknown = dir.join("unknown.toml");
    std::fs::write(
        &unknown,
        dense_merge_with("[sim.planners.pf-iso-seq]\nside_headway = 3.0\n"),
    )
    .unwrap();
    let out = merge_sim(&["run", "--no-rrd", "--scenario", unknown.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("side_headway"), "{err}");
}
