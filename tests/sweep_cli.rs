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

/// A seed as the JSON files write it: `0x` and 16 hex digits, exact in every reader.
fn seed_of(row: &Value) -> u64 {
    mergesim::exact_seed::parse_seed(row["seed"].as_str().unwrap()).unwrap()
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
    assert_eq!(run["shield_interventions"], row["shield_interventions"]);
    for key in [
        "throughput_vph",
        "merging",
        "merged_before_lane_end",
        "mean_delay_s",
    ] {
        let row_key = if key == "merging" {
            "merging_vehicles"
        } else {
            key
        };
        assert_eq!(run["traffic"][key], row[row_key], "{key}");
    }
    assert!(row["throughput_vph"].as_f64().is_some_and(|q| q > 0.0));
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
        let a = mergesim::scenarios::scenario::Scenario::load(name).unwrap();
        let b = mergesim::scenarios::scenario::Scenario::load(p(&path)).unwrap();
        assert_eq!(a, b, "{name}");
        assert!(
            !b.randomise.is_empty(),
            "{name} has no default randomisation"
        );
    }
}

/// The shard files as a shell glob lists them: `shard_0, shard_1, shard_10, shard_11, shard_2,
/// ...` (lexical order, not shard order).
fn glob_order(dir: &Path, count: usize) -> Vec<String> {
    let mut names: Vec<String> = (0..count)
        .map(|i| p(&dir.join(format!("shard_{i}.json"))).to_string())
        .collect();
    names.sort();
    names
}

/// `v` without any `wall_time_s` (a paired aggregate has one per planner too).
fn without_wall_times(mut v: Value) -> Value {
    match &mut v {
        Value::Object(obj) => {
            obj.remove("wall_time_s");
            for value in obj.values_mut() {
                *value = without_wall_times(value.take());
            }
        }
        Value::Array(items) => {
            for value in items.iter_mut() {
                *value = without_wall_times(value.take());
            }
        }
        _ => {}
    }
    v
}

/// The lines of a JSONL file in file order.
fn jsonl_lines(path: &Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// A 12-shard sweep (one planner, then two paired): `merge-results --jsonl` writes the
/// unsharded sweep's rows sorted by (instance, planner in the sweep's order), whatever the
/// order of the shard files (here a shell glob's: 0, 1, 10, 11, 2, ...); the merged JSONL is a
/// valid JSONL of the unsharded sweep (`--resume` on it has nothing to run and gives the same
/// aggregate); `wall_time_s` of the merge is the sum of the shards'.
#[test]
fn twelve_shards_merge_into_the_unsharded_rows_in_order_single_and_paired() {
    const SHARDS: usize = 12;
    for (name, planners, runs) in [("single", "pf-iso", "24"), ("paired", "pf-cs,pf-iso", "12")] {
        let dir = scratch(&format!("sweep_twelve_{name}"));
        let common = [
            "sweep",
            "--quiet",
            "--scenario",
            "urgent_merge",
            "--planners",
            planners,
            "--runs",
            runs,
            "--seed",
            "5",
        ];
        let whole_json = dir.join("whole.json");
        let whole_jsonl = dir.join("whole.jsonl");
        let mut args = common.to_vec();
        args.extend(["--json", p(&whole_json), "--jsonl", p(&whole_jsonl)]);
        let out = merge_sim(&args, &[]);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        let mut shard_wall_time = 0.0;
        for index in 0..SHARDS {
            let json = dir.join(format!("shard_{index}.json"));
            let shard = format!("{index}/{SHARDS}");
            let mut args = common.to_vec();
            args.extend(["--threads", "1", "--shard", &shard, "--json", p(&json)]);
            let out = merge_sim(&args, &[]);
            assert!(out.status.success(), "{name} {shard}: {}", stderr(&out));
            // The one-line banner, even with --quiet: a job log says which shard ran.
            assert!(
                stderr(&out).contains(&format!("shard {shard} = instances")),
                "{}",
                stderr(&out)
            );
            shard_wall_time += read_json(&json)["wall_time_s"].as_f64().unwrap();
        }
        let merged_json = dir.join("merged.json");
        let merged_jsonl = dir.join("merged.jsonl");
        // An existing regular file is replaced (as --json and --parquet are).
        std::fs::write(&merged_jsonl, "old\n").unwrap();
        let mut args = vec!["merge-results", "--quiet"];
        let files = glob_order(&dir, SHARDS);
        assert_eq!(files[2], p(&dir.join("shard_10.json")), "not glob order");
        args.extend(files.iter().map(String::as_str));
        args.extend(["--json", p(&merged_json), "--jsonl", p(&merged_jsonl)]);
        let out = merge_sim(&args, &[]);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        let merged = read_json(&merged_json);
        assert_eq!(
            without_wall_times(merged.clone()),
            without_wall_times(read_json(&whole_json)),
            "{name}"
        );
        let merged_wall = merged["wall_time_s"].as_f64().unwrap();
        assert!(
            (merged_wall - shard_wall_time).abs() <= 1e-9 * shard_wall_time.max(1.0),
            "{name}: wall_time_s {merged_wall} is not the shards' sum {shard_wall_time}"
        );

        // The rows, in file order, are the unsharded sweep's sorted by (instance, planner).
        let order: Vec<&str> = planners.split(',').collect();
        let mut expected = jsonl_lines(&whole_jsonl);
        expected.sort_by_key(|r| {
            let planner = r["planner"].as_str().unwrap();
            (
                r["instance"].as_u64().unwrap(),
                order.iter().position(|p| *p == planner).unwrap(),
            )
        });
        let rows = jsonl_lines(&merged_jsonl);
        let total: usize = runs.parse::<usize>().unwrap() * order.len();
        assert_eq!(rows.len(), total, "{name}");
        assert_eq!(expected.len(), total, "{name}");
        for (row, want) in rows.iter().zip(&expected) {
            assert!(row["wall_time_s"].is_null(), "{name}: {row}");
            assert_eq!(
                without_wall_time(row.clone()),
                without_wall_time(want.clone()),
                "{name}"
            );
        }
        // The merged file is the JSONL of the unsharded sweep: nothing left to run.
        let resumed_json = dir.join("resumed.json");
        let mut args = common.to_vec();
        args.extend([
            "--json",
            p(&resumed_json),
            "--jsonl",
            p(&merged_jsonl),
            "--resume",
        ]);
        let out = merge_sim(&args, &[]);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        assert!(stderr(&out).contains("0 to run"), "{}", stderr(&out));
        assert_eq!(
            without_wall_times(read_json(&resumed_json)),
            without_wall_times(read_json(&whole_json)),
            "{name}"
        );
    }
}

/// A task resubmitted alone (`sbatch --array=2`) is an array of one task: without `--shard`
/// it runs the whole sweep as shard 0/1 into `shard_2.json`. The sweep warns (even with
/// --quiet), and merge-results refuses the set naming that file and the likely cause, writing
/// no output and leaving an existing one untouched.
#[test]
fn a_task_resubmitted_alone_is_named_by_the_merge_error() {
    let dir = scratch("sweep_resubmitted");
    let common = [
        "sweep",
        "--quiet",
        "--scenario",
        "urgent_merge",
        "--planner",
        "pf-iso",
        "--runs",
        "3",
        "--seed",
        "9",
    ];
    for index in 0..3 {
        let json = dir.join(format!("shard_{index}.json"));
        let id = index.to_string();
        let mut args = common.to_vec();
        args.extend(["--json", p(&json)]);
        // Task 2 as `sbatch --array=2` runs it: ID = MIN = MAX = 2, COUNT = 1.
        let env: Vec<(&str, &str)> = if index == 2 {
            vec![
                ("SLURM_ARRAY_TASK_ID", "2"),
                ("SLURM_ARRAY_TASK_COUNT", "1"),
                ("SLURM_ARRAY_TASK_MIN", "2"),
                ("SLURM_ARRAY_TASK_MAX", "2"),
            ]
        } else {
            vec![
                ("SLURM_ARRAY_TASK_ID", id.as_str()),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ]
        };
        let out = merge_sim(&args, &env);
        assert!(out.status.success(), "{}", stderr(&out));
        if index == 2 {
            assert!(
                stderr(&out).contains("SLURM_ARRAY_TASK_COUNT = 1")
                    && stderr(&out).contains("--shard i/n"),
                "{}",
                stderr(&out)
            );
            assert_eq!(read_json(&json)["shard"], "0/1");
        }
    }
    let merged_jsonl = dir.join("merged.jsonl");
    let merged_json = dir.join("merged.json");
    std::fs::write(&merged_jsonl, "kept\n").unwrap();
    // Whichever file comes first, the error names shard_2.json and the cure.
    for files in [
        ["shard_0.json", "shard_1.json", "shard_2.json"],
        ["shard_2.json", "shard_0.json", "shard_1.json"],
    ] {
        let paths: Vec<String> = files.iter().map(|f| p(&dir.join(f)).to_string()).collect();
        let mut args = vec!["merge-results"];
        args.extend(paths.iter().map(String::as_str));
        args.extend(["--json", p(&merged_json), "--jsonl", p(&merged_jsonl)]);
        let out = merge_sim(&args, &[]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        let err = stderr(&out);
        for needle in [
            "shard_2.json says it is shard 0/1",
            "sbatch --array",
            "--shard i/3",
            "scontrol requeue",
        ] {
            assert!(err.contains(needle), "{needle:?} not in {err}");
        }
        assert_eq!(std::fs::read_to_string(&merged_jsonl).unwrap(), "kept\n");
        assert!(!merged_json.exists());
    }
    // Run again with the shard count explicit, the set merges.
    let json = dir.join("shard_2.json");
    let mut args = common.to_vec();
    args.extend(["--shard", "2/3", "--json", p(&json)]);
    let out = merge_sim(&args, &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let shard_files: Vec<String> = (0..3)
        .map(|i| p(&dir.join(format!("shard_{i}.json"))).to_string())
        .collect();
    let mut args = vec!["merge-results", "--quiet"];
    args.extend(shard_files.iter().map(String::as_str));
    args.extend(["--jsonl", p(&merged_jsonl)]);
    let out = merge_sim(&args, &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let instances: Vec<u64> = jsonl_lines(&merged_jsonl)
        .iter()
        .map(|r| r["instance"].as_u64().unwrap())
        .collect();
    assert_eq!(instances, [0, 1, 2]);
}
