//! `merge_sim sweep` and `merge_sim merge-results` as a user (or a cluster job) runs them:
//! sharding, merging, replaying a run from its seed, and refusing bad input.

mod common;

use std::path::Path;

use common::{merge_sim_env as merge_sim, scratch, stderr};

use serde_json::Value;

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn without_wall_time(mut v: Value) -> Value {
    if let Some(obj) = v.as_object_mut() {
        obj.remove("wall_time_s");
    }
    v
}

/// The JSONL's rows in instance order (the file holds them in completion order).
fn jsonl_rows(path: &Path) -> Vec<Value> {
    let mut rows: Vec<Value> = std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    rows.sort_by_key(|r| r["instance"].as_u64().unwrap());
    rows
}

/// A seed as the JSON files write it: a string of digits, exact in every reader.
fn seed_of(row: &Value) -> u64 {
    row["seed"].as_str().unwrap().parse().unwrap()
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

const RUNS: &str = "7";

#[test]
fn sharded_sweep_merges_into_exactly_the_unsharded_one_and_rows_replay() {
    let dir = scratch("sweep_shards");
    let common = [
        "sweep",
        "--quiet",
        "--scenario",
        "urgent_merge",
        "--planner",
        "pf-iso",
        "--runs",
        RUNS,
        "--seed",
        "11",
    ];
    let whole_json = dir.join("whole.json");
    let whole_jsonl = dir.join("whole.jsonl");
    let mut args = common.to_vec();
    args.extend(["--json", p(&whole_json), "--jsonl", p(&whole_jsonl)]);
    let out = merge_sim(&args, &[]);
    assert!(out.status.success(), "{}", stderr(&out));

    // Three shards of sizes 2, 2, 3; shard 1 from Slurm's variables (1-based array), the others
    // from --shard, and one thread each so the scheduling differs from the unsharded sweep.
    let mut shard_files = Vec::new();
    let mut shard_rows = Vec::new();
    for index in 0..3 {
        let json = dir.join(format!("shard{index}.json"));
        let jsonl = dir.join(format!("shard{index}.jsonl"));
        let shard = format!("{index}/3");
        let mut args = common.to_vec();
        args.extend(["--threads", "1", "--json", p(&json), "--jsonl", p(&jsonl)]);
        let slurm_id = (index + 1).to_string();
        let out = if index == 1 {
            merge_sim(
                &args,
                &[
                    ("SLURM_ARRAY_TASK_ID", slurm_id.as_str()),
                    ("SLURM_ARRAY_TASK_COUNT", "3"),
                    ("SLURM_ARRAY_TASK_MIN", "1"),
                ],
            )
        } else {
            args.extend(["--shard", shard.as_str()]);
            merge_sim(&args, &[])
        };
        assert!(out.status.success(), "{}", stderr(&out));
        assert_eq!(read_json(&json)["shard"], shard.as_str());
        shard_rows.extend(jsonl_rows(&jsonl));
        shard_files.push(json);
    }
    // merge-results, given the shards in a scrambled order.
    let merged_json = dir.join("merged.json");
    let out = merge_sim(
        &[
            "merge-results",
            "--quiet",
            p(&shard_files[2]),
            p(&shard_files[0]),
            p(&shard_files[1]),
            "--json",
            p(&merged_json),
        ],
        &[],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let whole = read_json(&whole_json);
    assert_eq!(
        without_wall_time(read_json(&merged_json)),
        without_wall_time(whole.clone())
    );

    // The documented aggregate keys.
    for key in [
        "runs",
        "collisions",
        "collision_rate",
        "collision_rate_ci95",
        "near_misses",
        "near_miss_rate",
        "min_ttc_s_p5",
        "min_gap_m_p5",
        "mean_peak_yaw_rate_radps",
        "fallbacks",
        "diverged",
        "wall_time_s",
    ] {
        assert!(whole.get(key).is_some(), "missing {key}");
    }
    assert_eq!(whole["runs"], 7);
    let ci = whole["collision_rate_ci95"].as_array().unwrap();
    let rate = whole["collision_rate"].as_f64().unwrap();
    assert!(ci[0].as_f64().unwrap() <= rate && rate <= ci[1].as_f64().unwrap());

    // The shards' JSONL lines, concatenated in shard order, are the unsharded file's lines.
    let whole_rows = jsonl_rows(&whole_jsonl);
    assert_eq!(whole_rows.len(), 7);
    let strip = |rows: &[Value]| {
        rows.iter()
            .cloned()
            .map(without_wall_time)
            .collect::<Vec<_>>()
    };
    assert_eq!(strip(&shard_rows), strip(&whole_rows));

    // Seeds are distinct, and any row replays alone with `run --seed`.
    let seeds: Vec<u64> = whole_rows.iter().map(seed_of).collect();
    let mut distinct = seeds.clone();
    distinct.sort_unstable();
    distinct.dedup();
    assert_eq!(distinct.len(), seeds.len());
    let row = &whole_rows[5];
    let replay = dir.join("replay.json");
    let seed = seed_of(row).to_string();
    let out = merge_sim(
        &[
            "run",
            "--no-rrd",
            "--quiet",
            "--scenario",
            "urgent_merge",
            "--planner",
            "pf-iso",
            "--seed",
            &seed,
            "--json",
            p(&replay),
        ],
        &[],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let run = read_json(&replay);
    assert_eq!(run["seed"], row["seed"]);
    for key in ["collisions", "near_miss", "min_ttc_s", "min_gap_m", "tet_s"] {
        assert_eq!(run[key], row[key], "{key}");
    }
    assert_eq!(run["planner_stats"]["fallbacks"], row["fallbacks"]);
    assert_eq!(run["planner_stats"]["plans"], row["plans"]);
    let vehicles = run["vehicles"].as_array().unwrap();
    let peak = |key: &str| {
        vehicles
            .iter()
            .map(|v| v[key].as_f64().unwrap())
            .fold(0.0, f64::max)
    };
    assert_eq!(
        peak("max_abs_yaw_rate_radps"),
        row["peak_yaw_rate_radps"].as_f64().unwrap()
    );
    assert_eq!(
        peak("max_abs_sideslip_rad"),
        row["peak_sideslip_rad"].as_f64().unwrap()
    );
    // A different instance is a different run (the seed does pick the randomised instance).
    assert_ne!(run["min_gap_m"], whole_rows[4]["min_gap_m"]);

    // Merging refuses an incomplete or mixed set of shards, with exit code 2.
    let out = merge_sim(
        &["merge-results", p(&shard_files[0]), p(&shard_files[2])],
        &[],
    );
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("missing shards: 1/3"),
        "{}",
        stderr(&out)
    );
    let out = merge_sim(&["merge-results", p(&shard_files[0]), p(&whole_json)], &[]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("whole.json"), "{}", stderr(&out));
    let out = merge_sim(&["merge-results", p(&whole_jsonl)], &[]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("whole.jsonl"), "{}", stderr(&out));
}

#[test]
fn bad_sweep_input_exits_2_naming_the_value_and_writes_nothing() {
    let dir = scratch("sweep_bad");
    let json = dir.join("out.json");
    let bad_toml = dir.join("bad.toml");
    let text = mergesim::scenarios::builtin::toml_of("urgent_merge")
        .unwrap()
        .replace(
            "[randomise]\nmu = { uniform = [-0.1, 0.1] }",
            "[randomise]\nmu = { uniform = [-0.1, 1.5] }",
        );
    assert!(
        text.contains("[-0.1, 1.5]"),
        "the built-in changed: update this test"
    );
    std::fs::write(&bad_toml, &text).unwrap();
    let line = text
        .lines()
        .position(|l| l.contains("[-0.1, 1.5]"))
        .unwrap()
        + 1;
    let line_text = format!("line {line}");
    /// (arguments, environment, what stderr must name).
    type Case<'a> = (Vec<&'a str>, Vec<(&'a str, &'a str)>, Vec<&'a str>);
    let cases: Vec<Case> = vec![
        (vec!["sweep", "--runs", "0"], vec![], vec!["--runs", "'0'"]),
        (vec!["sweep", "--runs", "-3"], vec![], vec!["-3"]),
        (vec!["sweep", "--runs", "many"], vec![], vec!["many"]),
        (
            vec!["sweep", "--runs", "2", "--shard", "4/4"],
            vec![],
            vec!["4/4"],
        ),
        (
            vec!["sweep", "--runs", "2", "--shard", "1-4"],
            vec![],
            vec!["1-4"],
        ),
        (
            vec!["sweep", "--runs", "2", "--threads", "0"],
            vec![],
            vec!["--threads"],
        ),
        (
            vec!["sweep", "--runs", "2", "--planner", "pf-xyz"],
            vec![],
            vec!["pf-xyz"],
        ),
        (
            vec!["sweep", "--runs", "2"],
            vec![
                ("SLURM_ARRAY_TASK_ID", "5"),
                ("SLURM_ARRAY_TASK_COUNT", "4"),
            ],
            vec!["SLURM_ARRAY_TASK_ID", "5/4"],
        ),
        (
            vec!["sweep", "--runs", "2"],
            vec![("JOB_COMPLETION_INDEX", "1")],
            vec!["MERGESIM_SHARD_COUNT"],
        ),
        (
            vec!["sweep", "--runs", "2", "--scenario", p(&bad_toml)],
            vec![],
            vec!["bad.toml", &line_text, "randomise.mu", "mu = 2.3"],
        ),
        (
            vec!["merge-results", "/no/such/shard.json"],
            vec![],
            vec!["/no/such/shard.json"],
        ),
    ];
    for (mut args, env, needles) in cases {
        if args[0] == "sweep" {
            args.extend(["--json", p(&json)]);
        }
        let out = merge_sim(&args, &env);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        for needle in needles {
            assert!(
                stderr(&out).contains(needle),
                "{args:?}: {needle:?} not in {}",
                stderr(&out)
            );
        }
        assert!(!stderr(&out).contains("panicked"), "{}", stderr(&out));
        assert!(!json.exists(), "{args:?} left {}", json.display());
    }
}

#[test]
fn every_builtin_is_listed_and_shows_as_toml_that_reads_back_unchanged() {
    let dir = scratch("sweep_show");
    let list = merge_sim(&["scenario", "list"], &[]);
    let listed = String::from_utf8_lossy(&list.stdout).into_owned();
    for name in [
        "urgent_merge",
        "relaxed_merge",
        "dense_merge",
        "mixed_traffic",
        "degraded_v2v",
        "wet_road",
        "platoon_merge_50",
    ] {
        assert!(listed.contains(name), "{name} not listed: {listed}");
        let out = merge_sim(&["scenario", "show", name], &[]);
        assert!(out.status.success(), "{}", stderr(&out));
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(&path, &out.stdout).unwrap();
        let a = mergesim::scenarios::Scenario::load(name).unwrap();
        let b = mergesim::scenarios::Scenario::load(p(&path)).unwrap();
        assert_eq!(a, b, "{name}");
        assert!(
            !b.randomise.is_empty(),
            "{name} has no default randomisation"
        );
    }
}
