//! `merge_sim` against hostile input and hostile circumstances, as a user meets them: values
//! out of range, work that could not finish, outputs that are not ours to replace, signals in
//! the middle of a sweep or a run, and seeds that JSON readers would round.

mod common;
#[path = "robustness_cli/helpers.rs"]
mod helpers;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use common::{merge_sim, scratch, stderr};
use helpers::{
    files_in, interrupt_when, lines_of, p, read_json, urgent, with_value, without_wall_time, write,
};
use serde_json::Value;

#[test]
fn every_section_is_validated_with_file_line_and_field_for_run_and_sweep_alike() {
    let dir = scratch("robust_sections");
    // Each was accepted (or panicked, or hung) before: the tracker was never validated,
    // iteration counts and step sizes had no upper bound, the road no magnitude bound.
    let cases = [
        (
            "sim.tracker",
            "lookahead_min_m = nan",
            "tracker.lookahead_min_m",
        ),
        (
            "sim.tracker",
            "max_decel_mps2 = -5.0",
            "tracker.max_decel_mps2",
        ),
        (
            "sim.tracker",
            "speed_kp_per_s = nan",
            "tracker.speed_kp_per_s",
        ),
        (
            "sim.tracker",
            "stop_speed_mps = inf",
            "tracker.stop_speed_mps",
        ),
        (
            "sim.planner",
            "max_scp_iterations = 9223372036854775807",
            "planner.max_scp_iterations",
        ),
        ("sim.planner", "step_time_s = 1e300", "planner.step_time_s"),
        ("sim.planner", "min_step_m = 1e300", "planner.min_step_m"),
        (
            "sim.safety",
            "ttc_threshold_s = nan",
            "safety.ttc_threshold_s",
        ),
        ("sim.road", "y_bottom_m = 1e6", "road.y_bottom_m"),
        ("sim.road", "end_x_m = 1e9", "road.end_x_m"),
        ("sim", "duration_s = 1e-300", "duration_s"),
    ];
    for (section, line, field) in cases {
        let text = with_value(&urgent(), section, line);
        let path = write(&dir, "bad.toml", &text);
        let line_number = text.lines().position(|l| l == line).unwrap() + 1;
        for command in [
            vec!["run", "--no-rrd", "--scenario", p(&path)],
            vec!["sweep", "--runs", "2", "--scenario", p(&path)],
            vec!["compare", "--scenario", p(&path)],
        ] {
            let started = Instant::now();
            let out = merge_sim(&command);
            let err = stderr(&out);
            assert_eq!(out.status.code(), Some(2), "{command:?} {line}: {err}");
            assert!(
                err.contains(field) && err.contains(&format!("line {line_number}")),
                "{command:?} {line}: {err}"
            );
            assert!(
                err.contains("bad.toml"),
                "{command:?} {line}: names no file: {err}"
            );
            assert!(
                started.elapsed() < Duration::from_secs(5),
                "{command:?} {line}: refused only after {:?}",
                started.elapsed()
            );
        }
    }
    assert_eq!(files_in(&dir), ["bad.toml"], "nothing else written");
}

#[test]
fn work_and_parallelism_are_bounded_up_front() {
    for (args, needle) in [
        (vec!["sweep", "--runs", "1000000000"], "1 to 1000000"),
        (
            vec!["sweep", "--runs", "18446744073709551615"],
            "1 to 1000000",
        ),
        (
            vec!["sweep", "--runs", "2", "--threads", "100000"],
            "1 to 1024",
        ),
        (vec!["grid", "--runs", "20000"], "at most 10000"),
        (
            vec!["scenario", "platoon", "--vehicles", "0"],
            "at least one vehicle",
        ),
        (
            vec!["scenario", "platoon", "--vehicles", "100000"],
            "at most 200",
        ),
        (
            vec!["scenario", "platoon", "--vehicles", "201"],
            "a platoon needs at least one vehicle and at most 200",
        ),
    ] {
        let out = merge_sim(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
    }
    // A run of impractical length: planning every 0.1 ms for 250 s is 5e6 cycles.
    let dir = scratch("robust_work");
    let text = urgent()
        .replace("duration_s = 25.0", "duration_s = 250.0")
        .replace("dt_s = 0.002", "dt_s = 0.0001")
        .replace("planner_period_s = 0.1", "planner_period_s = 0.0001")
        .replace("end_x_m = 700.0", "end_x_m = 10000.0");
    let path = write(&dir, "long.toml", &text);
    let started = Instant::now();
    let out = merge_sim(&["run", "--no-rrd", "--scenario", p(&path)]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("planning cycles"), "{}", stderr(&out));
    assert!(started.elapsed() < Duration::from_secs(5));
}

#[test]
fn spawning_off_the_road_or_a_road_too_short_for_the_run_is_refused() {
    let dir = scratch("robust_road");
    let off = urgent().replacen("x_m = 0.0", "x_m = 0.0\ny_offset_m = -1.0", 1);
    let short = urgent().replace("end_x_m = 700.0", "end_x_m = 400.0");
    for (name, text, needle) in [
        ("off.toml", off, "must start on the road"),
        ("short.toml", short, "too short"),
    ] {
        let path = write(&dir, name, &text);
        let out = merge_sim(&["run", "--no-rrd", "--scenario", p(&path)]);
        assert_eq!(out.status.code(), Some(2), "{name}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{name}: {}", stderr(&out));
    }
}

#[test]
fn outputs_that_are_not_regular_writable_files_are_refused_before_simulating() {
    let dir = scratch("robust_outputs");
    let keep = write(&dir, "keep.txt", "precious");
    let link = dir.join("link.json");
    std::os::unix::fs::symlink(&keep, &link).unwrap();
    let fifo = dir.join("fifo.json");
    let status = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(status.success());
    let readonly = write(&dir, "readonly.json", "old");
    let mut perms = std::fs::metadata(&readonly).unwrap().permissions();
    perms.set_readonly(true);
    std::fs::set_permissions(&readonly, perms).unwrap();
    let sub = dir.join("sub");
    std::fs::create_dir(&sub).unwrap();
    for target in [
        p(&link),
        p(&fifo),
        p(&readonly),
        p(&sub),
        "/dev/null",
        "/no/such/folder/x.json",
    ] {
        for args in [
            vec!["run", "--no-rrd", "--json", target],
            vec!["run", "--rrd", target],
            vec!["sweep", "--runs", "1", "--json", target],
        ] {
            let started = Instant::now();
            let out = merge_sim(&args);
            assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
            assert!(stderr(&out).contains(target), "{args:?}: {}", stderr(&out));
            assert!(started.elapsed() < Duration::from_secs(5), "{args:?}");
        }
    }
    assert_eq!(std::fs::read_to_string(&keep).unwrap(), "precious");
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_eq!(std::fs::read_to_string(&readonly).unwrap(), "old");
    assert_eq!(
        files_in(&dir),
        ["fifo.json", "keep.txt", "link.json", "readonly.json", "sub"],
        "no temporary file left"
    );
}

#[test]
fn a_scenario_name_cannot_send_the_default_recording_outside_the_folder() {
    let dir = scratch("robust_name");
    let work = dir.join("work");
    std::fs::create_dir(&work).unwrap();
    let text = urgent().replace("name = \"urgent_merge\"", "name = \"../escaped\"");
    let path = write(&dir, "named.toml", &text);
    let out = Command::new(env!("CARGO_BIN_EXE_merge_sim"))
        .args(["run", "--quiet", "--scenario", p(&path)])
        .current_dir(&work)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(files_in(&work), ["_escaped_pf-iso.rrd"]);
    assert_eq!(files_in(&dir), ["named.toml", "work"]);
}

/// Spawns `merge_sim args` and sends it `signal` once `ready()` holds; returns its exit code.
#[test]
fn an_interrupted_sweep_keeps_its_rows_and_resumes_to_the_uninterrupted_result() {
    let dir = scratch("robust_resume");
    let (json, jsonl) = (dir.join("sweep.json"), dir.join("sweep.jsonl"));
    let common = [
        "sweep",
        "--quiet",
        "--scenario",
        "urgent_merge",
        "--planner",
        "pf-cs",
        "--runs",
        "16",
        "--seed",
        "5",
        "--threads",
        "1",
    ];
    let mut args = common.to_vec();
    args.extend(["--json", p(&json), "--jsonl", p(&jsonl)]);
    let code = interrupt_when(&args, "-INT", || lines_of(&jsonl) >= 3);
    assert_eq!(code, Some(130));
    let finished = lines_of(&jsonl);
    assert!((3..16).contains(&finished), "{finished} rows");
    let partial = read_json(&json);
    assert_eq!(partial["runs"], finished);
    assert_eq!(partial["missing_runs"], 16 - finished);
    // Without --resume an existing JSONL is not touched.
    let out = merge_sim(&args);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--resume"), "{}", stderr(&out));
    assert_eq!(lines_of(&jsonl), finished);
    // An incomplete part is not merged.
    let out = merge_sim(&["merge-results", p(&json)]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("incomplete"), "{}", stderr(&out));
    // A torn last line (killed mid-write) is dropped and its run runs again.
    let mut text = std::fs::read_to_string(&jsonl).unwrap();
    text.push_str("{\"scenario\":\"urgent_mer");
    std::fs::write(&jsonl, text).unwrap();
    // Resume with SIGTERM once: still resumable.
    let mut resume = args.clone();
    resume.push("--resume");
    let code = interrupt_when(&resume, "-TERM", || lines_of(&jsonl) > finished + 1);
    assert_eq!(code, Some(143));
    let out = merge_sim(&resume);
    assert!(out.status.success(), "{}", stderr(&out));
    // Every instance exactly once, and the aggregate of an uninterrupted sweep.
    let mut instances: Vec<u64> = std::fs::read_to_string(&jsonl)
        .unwrap()
        .lines()
        .map(|l| {
            serde_json::from_str::<Value>(l).unwrap()["instance"]
                .as_u64()
                .unwrap()
        })
        .collect();
    instances.sort_unstable();
    assert_eq!(instances, (0..16).collect::<Vec<_>>());
    let whole = dir.join("whole.json");
    let mut args = common.to_vec();
    args.extend(["--json", p(&whole)]);
    let out = merge_sim(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        without_wall_time(read_json(&json)),
        without_wall_time(read_json(&whole))
    );
    // Rows of another sweep are refused, naming the line.
    let mut other = common.to_vec();
    other[9] = "6";
    other.extend(["--jsonl", p(&jsonl), "--resume"]);
    let out = merge_sim(&other);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("line 1") && stderr(&out).contains("sweep_seed"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn an_interrupted_run_leaves_no_recording_or_temporary_file() {
    let dir = scratch("robust_run_signal");
    let rrd = dir.join("run.rrd");
    let args = [
        "run",
        "--quiet",
        "--scenario",
        "platoon_merge_50",
        "--rrd",
        p(&rrd),
    ];
    let tmp = dir.join("run.rrd.tmp");
    let code = interrupt_when(&args, "-INT", || tmp.exists());
    assert_eq!(code, Some(130));
    assert!(files_in(&dir).is_empty(), "{:?}", files_in(&dir));
}

#[test]
fn seeds_are_exact_in_every_json_reader() {
    let dir = scratch("robust_seeds");
    let (json, jsonl, run) = (
        dir.join("s.json"),
        dir.join("s.jsonl"),
        dir.join("run.json"),
    );
    let out = merge_sim(&[
        "sweep",
        "--quiet",
        "--runs",
        "2",
        "--seed",
        "18446744073709551615",
        "--json",
        p(&json),
        "--jsonl",
        p(&jsonl),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let summary = read_json(&json);
    // Written as 0x and 16 hex digits (pandas coerces strings of decimal digits to floats).
    assert_eq!(summary["seed"], "0xffffffffffffffff");
    let row: Value = serde_json::from_str(
        std::fs::read_to_string(&jsonl)
            .unwrap()
            .lines()
            .next()
            .unwrap(),
    )
    .unwrap();
    let seed = row["seed"].as_str().expect("a string").to_string();
    mergesim::exact_seed::parse_seed(&seed).expect("0x and hex digits");
    assert!(seed.starts_with("0x") && seed.len() == 18, "{seed}");
    let out = merge_sim(&[
        "run",
        "--quiet",
        "--no-rrd",
        "--seed",
        &seed,
        "--json",
        p(&run),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(read_json(&run)["seed"], Value::String(seed));
}

#[test]
fn a_malformed_figure_in_a_shard_is_an_error_not_a_diverged_run() {
    let dir = scratch("robust_merge");
    let json = dir.join("shard.json");
    let out = merge_sim(&["sweep", "--quiet", "--runs", "2", "--json", p(&json)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let mut value = read_json(&json);
    value["samples"][1]["min_gap_m"] = Value::String("oops".into());
    std::fs::write(&json, serde_json::to_string(&value).unwrap()).unwrap();
    let out = merge_sim(&["merge-results", p(&json)]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("instance 1") && stderr(&out).contains("malformed"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn the_readme_limits_section_is_the_output_of_merge_sim_limits() {
    let out = merge_sim(&["limits"]);
    assert!(out.status.success());
    let printed = String::from_utf8(out.stdout).unwrap();
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let begin = "<!-- limits:begin (generated by `merge_sim limits`) -->\n";
    let end = "<!-- limits:end -->";
    let start = readme.find(begin).expect("README has the limits markers") + begin.len();
    let stop = readme[start..].find(end).unwrap() + start;
    assert_eq!(
        readme[start..stop].trim(),
        printed.trim(),
        "README \"Limits\" is stale: run scripts/update_readme_limits.py"
    );
    assert!(printed.contains("`[sim.tracker]` `lookahead_min_m`"));
}

#[test]
fn every_experiment_scenario_loads() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/experiments");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            mergesim::scenarios::scenario::Scenario::load(path.to_str().unwrap())
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            count += 1;
        }
    }
    assert!(count >= 4, "{count} experiment scenarios");
}

#[test]
fn inputs_that_are_not_regular_files_are_refused_at_once() {
    let dir = scratch("robust_inputs");
    let fifo = dir.join("scenario.toml");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    for scenario in [p(&fifo), "/dev/zero", p(&dir)] {
        let started = Instant::now();
        let out = merge_sim(&["run", "--no-rrd", "--scenario", scenario]);
        assert_eq!(out.status.code(), Some(2), "{scenario}: {}", stderr(&out));
        assert!(
            stderr(&out).contains("not a regular file"),
            "{}",
            stderr(&out)
        );
        assert!(started.elapsed() < Duration::from_secs(5), "{scenario}");
    }
}

#[test]
fn an_output_may_be_neither_another_output_nor_an_input() {
    let dir = scratch("robust_distinct");
    let scenario = write(&dir, "scenario.toml", &urgent());
    let same = dir.join("same.out");
    let shard = dir.join("shard.json");
    let out = merge_sim(&["sweep", "--quiet", "--runs", "1", "--json", p(&shard)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let shard_text = std::fs::read_to_string(&shard).unwrap();
    for (args, needle) in [
        (
            vec!["run", "--no-rrd", "--json", p(&same), "--csv", p(&same)],
            "same file",
        ),
        (
            vec![
                "run",
                "--no-rrd",
                "--scenario",
                p(&scenario),
                "--json",
                p(&scenario),
            ],
            "input file",
        ),
        (
            vec![
                "sweep",
                "--runs",
                "1",
                "--json",
                p(&same),
                "--jsonl",
                p(&same),
            ],
            "same file",
        ),
        (
            vec!["merge-results", p(&shard), "--json", p(&shard)],
            "input file",
        ),
        (
            vec!["run", "--no-rrd", "--json", "x.json/"],
            "names a folder",
        ),
    ] {
        let out = merge_sim(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
    }
    assert_eq!(std::fs::read_to_string(&scenario).unwrap(), urgent());
    assert_eq!(std::fs::read_to_string(&shard).unwrap(), shard_text);
    assert!(!same.exists());
}

#[test]
fn plot_files_that_are_not_ours_are_refused_before_simulating() {
    let dir = scratch("robust_plots");
    let plots = dir.join("plots");
    std::fs::create_dir_all(plots.join("states_ego.png")).unwrap();
    let started = Instant::now();
    let out = merge_sim(&["compare", "--planners", "pf-cs", "--plots", p(&plots)]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("states_ego.png"), "{}", stderr(&out));
    assert!(started.elapsed() < Duration::from_secs(5));
    assert_eq!(files_in(&plots), ["states_ego.png"]);
}

#[test]
fn errors_about_names_presets_profiles_and_counts_carry_their_line() {
    let dir = scratch("robust_lines");
    let prescribed = urgent().replacen(
        "driver = { planner = \"pf-iso\" }",
        "driver = { prescribed = { path_planner = \"pf-cs\", speed_profile = [[0.0, 15.0, 3.0]] } }",
        1,
    );
    let many = {
        let mut text = urgent()
            .replace("end_x_m = 700.0", "end_x_m = 9000.0")
            .replace("duration_s = 25.0", "duration_s = 1.0");
        let cut = text.find("[randomise]").unwrap();
        text.truncate(cut);
        for i in 0..199 {
            text.push_str(&format!(
                "[[vehicles]]\nname = \"v{i}\"\npreset = \"bmw_320i\"\nlane = \"upper\"\n\
                 x_m = {}\nspeed_mps = 10.0\ntarget_speed_mps = 10.0\ndriver = \"idm\"\n\n",
                100.0 + 10.0 * i as f64
            ));
        }
        text
    };
    for (name, text, line_of, needle) in [
        (
            "duplicate.toml",
            urgent().replacen("name = \"obstacle\"", "name = \"ego\"", 1),
            "name = \"ego\"",
            "duplicate vehicle name",
        ),
        (
            "preset.toml",
            urgent().replacen("preset = \"bmw_320i\"", "preset = \"tesla\"", 1),
            "preset = \"tesla\"",
            "tesla",
        ),
        (
            "profile.toml",
            prescribed,
            "speed_profile",
            "exactly two numbers",
        ),
        // The header of the 201st vehicle (the last one).
        ("many.toml", many, "[[vehicles]]", "1 to 200 vehicles"),
        (
            "step.toml",
            urgent().replace("dt_s = 0.002", "dt_s = 0.02"),
            "dt_s = 0.02",
            "dt_s",
        ),
    ] {
        let path = write(&dir, name, &text);
        let out = merge_sim(&["run", "--no-rrd", "--scenario", p(&path)]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(needle), "{name}: {err}");
        // The last line holding `line_of` (the duplicate is the second `name = "ego"`).
        let line = text
            .lines()
            .enumerate()
            .filter(|(_, l)| l.contains(line_of))
            .map(|(i, _)| i + 1)
            .last()
            .unwrap();
        assert!(
            err.contains(&format!("line {line}")),
            "{name}: line {line}? {err}"
        );
    }
}
