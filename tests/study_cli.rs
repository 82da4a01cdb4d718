//! `merge_sim study PLAN.toml` as a user runs it: the report and its sections, bad plans
//! (exit 2 naming the line, nothing written), shards merged = the whole study, and the same
//! report whatever the thread count or an interruption.

mod common;

use std::path::{Path, PathBuf};

use common::{merge_sim, scratch, stderr};

/// A small plan: the urgent merge shortened to 6 s, two planners, two levels of μ, `n`
/// instances (2 × 2 × n runs).
fn small_plan(n: u64) -> String {
    format!(
        r#"name = "small"
description = "test plan"
scenario = "urgent_merge"
planners = ["pf-sp", "pf-iso"]
reference = "pf-sp"

[instances]
n = {n}
seed = 11

[factors]
"sim.duration_s" = [6.0]
"sim.mu" = [0.8, 0.6]

[endpoints]
primary = {{ figure = "obstacle.max_abs_yaw_rate_radps", threshold = "0.01 rad/s" }}
secondary = [
  {{ figure = "obstacle.max_abs_sideslip_rad", threshold = "0.002 rad" }},
  {{ figure = "ego.min_speed_mps", threshold = "0.5 m/s" }},
  {{ figure = "min_gap_m", threshold = "0.5 m" }},
]
"#
    )
}

fn write_plan(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn the_small_plan_writes_a_report_with_every_section() {
    let dir = scratch("study_report");
    let plan = write_plan(&dir, "small.toml", &small_plan(3));
    let out = merge_sim(&["study", s(&plan), "--quiet"]);
    assert!(out.status.success(), "{}", stderr(&out));
    // Default folder: <plan stem>.report beside the plan.
    let report = dir.join("small.report");
    let md = read(&report.join("report.md"));
    for section in [
        "# Study: small",
        "**exploratory**",
        "## Provenance",
        "git blob hash",
        "commit that first added the plan",
        "simulator commit",
        "## Design",
        "## Method",
        "## Primary endpoint",
        "## Secondary endpoints",
        "Holm",
        "the family",
        "## Beside them: the other window",
        "## Collisions",
        "McNemar",
        "Newcombe",
        "## Figure",
        "effects.png",
        "obstacle.max_abs_yaw_rate_radps",
        "sim.mu=0.6",
        "negligible",
    ] {
        assert!(md.contains(section), "report.md lacks {section:?}:\n{md}");
    }
    // The plan was never committed here (cargo's tmpdir lies outside git, or inside an ignored
    // target/ of a checkout): exploratory, and it says why.
    let in_work_tree = std::process::Command::new("git")
        .args(["rev-parse", "--is-inside-work-tree"])
        .current_dir(&dir)
        .output()
        .is_ok_and(|out| out.status.success() && out.stdout.starts_with(b"true"));
    let reason = if in_work_tree {
        "the plan was never committed"
    } else {
        "not in a git repository"
    };
    assert!(
        md.contains(reason),
        "{reason:?}:
{md}"
    );
    let json: serde_json::Value = serde_json::from_str(&read(&report.join("report.json"))).unwrap();
    assert_eq!(json["provenance"]["exploratory"], true);
    assert_eq!(
        json["provenance"]["simulator_commit"],
        mergesim::build_info::COMMIT
    );
    // Endpoint table: 2 cells × 1 pair × (3 motion-state endpoints × 2 windows + 1 run figure).
    let endpoints = read(&report.join("endpoints.csv"));
    assert_eq!(endpoints.lines().count(), 1 + 2 * 7, "{endpoints}");
    let header: Vec<&str> = endpoints.lines().next().unwrap().split(',').collect();
    for column in [
        "n",
        "mean_difference",
        "ci95_low",
        "p_t",
        "p_wilcoxon",
        "p_t_holm",
        "median_difference",
        "p90_difference",
        "threshold",
        "verdict",
    ] {
        assert!(header.contains(&column), "{column}");
    }
    let collisions = read(&report.join("collisions.csv"));
    assert_eq!(collisions.lines().count(), 1 + 2, "{collisions}");
    assert!(collisions.starts_with("cell,cell_label,planner,reference,n,both,only_planner"));
    let png = std::fs::read(report.join("effects.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    // One row per run, with the instance seeds shared by every cell and planner.
    let rows = read(&report.join("rows.jsonl"));
    assert_eq!(rows.lines().count(), 2 * 2 * 3);
    let seeds: std::collections::BTreeSet<String> = rows
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap()["seed"].to_string())
        .collect();
    assert_eq!(seeds.len(), 3);
    // The primary endpoint stands alone: no Holm value; tested secondaries have one.
    for line in endpoints.lines().skip(1) {
        let fields: Vec<&str> = line.split(',').collect();
        let at = |name: &str| fields[header.iter().position(|h| *h == name).unwrap()];
        if at("role") == "primary" || at("tested") == "false" {
            assert_eq!(at("p_t_holm"), "", "{line}");
        }
        if at("role") == "secondary" && at("tested") == "true" && !at("p_t").is_empty() {
            assert!(at("p_t_holm").parse::<f64>().unwrap() >= at("p_t").parse::<f64>().unwrap());
        }
    }
    // Running again into the report folder replaces the report.
    let again = merge_sim(&["study", s(&plan), "--quiet"]);
    assert!(again.status.success(), "{}", stderr(&again));
    assert_eq!(read(&report.join("endpoints.csv")), endpoints);
}

/// Each bad plan exits 2 before any run, names the plan's line, and writes nothing.
#[test]
fn bad_plans_exit_2_naming_the_line_and_write_nothing() {
    let dir = scratch("study_bad_plans");
    let good = small_plan(3);
    let cases: Vec<(&str, String, &str, usize)> = vec![
        (
            "unknown factor",
            good.replace("\"sim.mu\" = [0.8, 0.6]", "\"sim.muu\" = [0.8, 0.6]"),
            "unknown factor",
            13,
        ),
        (
            "unknown endpoint (figure)",
            good.replace("obstacle.max_abs_yaw_rate_radps", "obstacle.peak_yaw"),
            "unknown endpoint",
            16,
        ),
        (
            "unknown endpoint (vehicle)",
            good.replace("ego.min_speed_mps", "truck.min_speed_mps"),
            "unknown endpoint",
            19,
        ),
        (
            "empty level list",
            good.replace("[0.8, 0.6]", "[]"),
            "empty level list",
            13,
        ),
        (
            "threshold without a unit (number)",
            good.replace("\"0.002 rad\"", "0.002"),
            "without a unit",
            18,
        ),
        (
            "threshold without a unit (string)",
            good.replace("\"0.5 m/s\"", "\"0.5\""),
            "without a unit",
            19,
        ),
        (
            "threshold in another unit",
            good.replace("\"0.01 rad/s\"", "\"0.5 deg/s\""),
            "does not match",
            16,
        ),
        (
            "too many runs",
            good.replace("n = 3", "n = 30000"),
            "more than the limit of 100000 runs",
            8,
        ),
        (
            "a level out of range",
            good.replace("[0.8, 0.6]", "[0.8, -1.0]"),
            "sim.mu = -1",
            13,
        ),
    ];
    for (what, text, message, line) in cases {
        let plan = write_plan(&dir, "bad.toml", &text);
        let out_dir = dir.join("bad.report");
        let out = merge_sim(&["study", s(&plan)]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{what}: {err}");
        assert!(err.contains(message), "{what}: {err}");
        assert!(
            err.contains(&format!("bad.toml, line {line}:")),
            "{what}: expected line {line}: {err}"
        );
        assert!(!out_dir.exists(), "{what}: wrote {}", out_dir.display());
    }
}

#[test]
fn a_folder_that_is_not_a_report_is_not_written_to() {
    let dir = scratch("study_out_refused");
    let plan = write_plan(&dir, "p.toml", &small_plan(2));
    let mine = dir.join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "keep").unwrap();
    let out = merge_sim(&["study", s(&plan), "--out", s(&mine)]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("not a study report"));
    assert_eq!(std::fs::read_dir(&mine).unwrap().count(), 1);
}

fn tables(dir: &Path) -> Vec<String> {
    ["report.md", "endpoints.csv", "collisions.csv", "rows.jsonl"]
        .iter()
        .map(|f| {
            let text = read(&dir.join(f));
            if *f == "rows.jsonl" {
                // Wall times differ between attempts; rows are compared without them.
                let mut rows: Vec<String> = text
                    .lines()
                    .map(|l| {
                        let mut v: serde_json::Value = serde_json::from_str(l).unwrap();
                        v.as_object_mut().unwrap().remove("wall_time_s");
                        v.to_string()
                    })
                    .collect();
                rows.sort();
                rows.join("\n")
            } else {
                text
            }
        })
        .collect()
}

#[test]
fn shards_merged_threads_and_resumption_give_the_whole_studys_report() {
    let dir = scratch("study_shards");
    let plan = write_plan(&dir, "p.toml", &small_plan(3));
    let whole1 = dir.join("whole1");
    let out = merge_sim(&[
        "study",
        s(&plan),
        "--out",
        s(&whole1),
        "--threads",
        "1",
        "-q",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let reference = tables(&whole1);

    let whole2 = dir.join("whole2");
    let out = merge_sim(&[
        "study",
        s(&plan),
        "--out",
        s(&whole2),
        "--threads",
        "2",
        "-q",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        tables(&whole2),
        reference,
        "thread count changed the report"
    );

    let sharded = dir.join("sharded");
    for shard in ["0/2", "1/2"] {
        let out = merge_sim(&[
            "study",
            s(&plan),
            "--out",
            s(&sharded),
            "--shard",
            shard,
            "-q",
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(
            !sharded.join("report.md").exists(),
            "a shard writes no report"
        );
    }
    // Merging before every shard is there is refused.
    let lonely = dir.join("lonely");
    let out = merge_sim(&[
        "study",
        s(&plan),
        "--out",
        s(&lonely),
        "--shard",
        "0/2",
        "-q",
    ]);
    assert!(out.status.success());
    let out = merge_sim(&["study", s(&plan), "--out", s(&lonely), "--merge"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("1/2 missing"), "{}", stderr(&out));
    let out = merge_sim(&["study", s(&plan), "--out", s(&sharded), "--merge", "-q"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(tables(&sharded), reference, "sharded + merged differs");

    // An interrupted attempt (its rows file cut in the middle of a line) resumed.
    let resumed = dir.join("resumed");
    std::fs::create_dir(&resumed).unwrap();
    std::fs::write(resumed.join(".mergesim-study"), "").unwrap();
    let rows = read(&whole1.join("rows.jsonl"));
    let cut: String = rows
        .lines()
        .take(5)
        .map(|l| format!("{l}\n"))
        .collect::<String>()
        + &rows.lines().nth(5).unwrap()[..20];
    std::fs::write(resumed.join("rows.jsonl"), cut).unwrap();
    let out = merge_sim(&["study", s(&plan), "--out", s(&resumed), "--resume"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("resuming: 5 finished, 7 to run"),
        "{}",
        stderr(&out)
    );
    assert_eq!(tables(&resumed), reference, "resumed study differs");
}

#[test]
fn study_help_explains_the_plan_format() {
    let out = merge_sim(&["study", "--help"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for needle in [
        "[instances]",
        "[factors]",
        "[[cells]]",
        "[endpoints]",
        "threshold",
        "rad/s",
        "[collisions]",
        "pre-contact",
        "100000 runs",
        "exploratory",
        "--shard",
        "--merge",
        "docs/studies/examples/urgent_merge_small.toml",
    ] {
        assert!(text.contains(needle), "help lacks {needle:?}");
    }
}

/// The example plan of the docs, as a user runs it (a copy, so the repository stays clean).
#[test]
fn the_example_plan_runs_and_reports() {
    let dir = scratch("study_example");
    let example =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/studies/examples/urgent_merge_small.toml");
    let plan = dir.join("urgent_merge_small.toml");
    std::fs::copy(&example, &plan).unwrap();
    let started = std::time::Instant::now();
    let out = merge_sim(&["study", s(&plan)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let report = dir.join("urgent_merge_small.report");
    let md = read(&report.join("report.md"));
    for section in [
        "## Provenance",
        "## Primary endpoint",
        "## Secondary endpoints",
        "## Collisions",
        "## Figure",
        "sim.planner.interaction_time_gap_s=3.0",
    ] {
        assert!(md.contains(section), "{section}");
    }
    assert_eq!(read(&report.join("rows.jsonl")).lines().count(), 40);
    // Progress and the primary results on the terminal.
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("obstacle.max_abs_yaw_rate_radps"),
        "{stdout}"
    );
    eprintln!("example study: {:.1} s", started.elapsed().as_secs_f64());
}
