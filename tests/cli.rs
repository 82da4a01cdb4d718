//! The `merge_sim` binary as a user runs it: outputs, contracts and bad input.

mod common;

use std::path::Path;
use std::process::Command;

use common::{merge_sim, scratch, stderr};

#[test]
fn run_writes_json_and_csv_that_follow_the_contract() {
    let dir = scratch("contract");
    let json = dir.join("run.json");
    let csv = dir.join("run.csv");
    let out = merge_sim(&[
        "run",
        "--no-rrd",
        "--quiet",
        "--json",
        json.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for key in [
        "scenario",
        "planner",
        "seed",
        "duration_s",
        "wall_time_s",
        "collisions",
        "min_gap_m",
        "min_ttc_s",
        "near_miss",
        "vehicles",
        "planner_stats",
    ] {
        assert!(v.get(key).is_some(), "missing {key} in {v}");
    }
    assert_eq!(v["scenario"], "urgent_merge");
    assert_eq!(v["planner"], "pf-iso");
    assert!((v["duration_s"].as_f64().unwrap() - 25.0).abs() < 1e-6);
    let vehicles = v["vehicles"].as_array().unwrap();
    let ids: Vec<&str> = vehicles.iter().map(|x| x["id"].as_str().unwrap()).collect();
    assert_eq!(ids, ["ego", "obstacle"]);
    for vehicle in vehicles {
        for key in [
            "max_abs_sideslip_rad",
            "max_abs_yaw_rad",
            "max_abs_yaw_rate_radps",
            "min_speed_mps",
            "t_min_speed_s",
            "path_length_m",
            "yaw_rate_sign_changes",
            "collided",
        ] {
            assert!(vehicle.get(key).is_some(), "missing vehicles[].{key}");
        }
        // 25 s at 10–20 m/s: the path length must be physically plausible.
        let length = vehicle["path_length_m"].as_f64().unwrap();
        assert!(length > 150.0 && length < 600.0, "{length}");
    }
    for key in ["plans", "fallbacks", "p50_plan_us", "p99_plan_us"] {
        assert!(
            v["planner_stats"].get(key).is_some(),
            "missing planner_stats.{key}"
        );
    }
    // Two vehicles planning at 10 Hz for 25 s.
    assert_eq!(v["planner_stats"]["plans"].as_u64().unwrap(), 2 * 250);

    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "t_s,vehicle,x_m,y_m,yaw_rad,yaw_rate_radps,sideslip_rad,speed_mps,planned_speed_mps,accel_long_mps2,accel_lat_mps2"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert!(rows.iter().all(|r| r.len() == 11));
    // Both vehicles at every logged instant (20 Hz × 25 s).
    assert_eq!(rows.len(), 2 * 500);
    assert!(rows.iter().all(|r| r[1] == "ego" || r[1] == "obstacle"));
    assert!(rows.iter().all(|r| {
        r.iter()
            .skip(2)
            .all(|x| x.parse::<f64>().unwrap().is_finite())
    }));
}

#[test]
fn recording_is_written_and_decodes_with_rerun_s_own_decoder() {
    let dir = scratch("rrd");
    let rrd = dir.join("run.rrd");
    let out = merge_sim(&["run", "--quiet", "--rrd", rrd.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let size = std::fs::metadata(&rrd).unwrap().len();
    assert!(size > 10_000, "recording only {size} bytes");
    // No temporary file left beside it.
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name() != "run.rrd")
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    // Every message decodes with the decoder of the same Rerun version (no external tool).
    let file = std::fs::File::open(&rrd).unwrap();
    let mut entities = std::collections::BTreeSet::new();
    let mut messages = 0;
    for msg in re_log_encoding::DecoderApp::decode_lazy(std::io::BufReader::new(file)) {
        let msg = msg.expect("a message that decodes");
        messages += 1;
        if let rerun::log::LogMsg::ArrowMsg(store_id, arrow_msg) = &msg
            && store_id.kind() == rerun::StoreKind::Recording
        {
            let chunk = rerun::log::Chunk::from_arrow_msg(arrow_msg).unwrap();
            entities.insert(chunk.entity_path().to_string());
        }
    }
    assert!(messages > 10, "{messages} messages");
    for entity in ["/world/vehicles", "/world/paths/ego/planned", "/events"] {
        assert!(
            entities.contains(entity),
            "{entity} missing from {entities:?}"
        );
    }
    // With a Rerun CLI of the same version (`.ci/run` installs it and sets this), let it
    // verify the file too.
    if let Some(cli) = std::env::var_os("MERGESIM_RERUN_CLI") {
        let verify = Command::new(cli)
            .args(["rrd", "verify"])
            .arg(&rrd)
            .output()
            .expect("MERGESIM_RERUN_CLI runs");
        assert!(
            verify.status.success(),
            "rerun rrd verify: {}",
            stderr(&verify)
        );
    }
}

#[test]
fn bad_input_exits_2_naming_the_value_and_writes_nothing() {
    let dir = scratch("bad");
    let json = dir.join("out.json");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["run".into(), "--scenario".into(), "nowhere".into()],
            "nowhere",
        ),
        (
            vec!["run".into(), "--planner".into(), "pf-xyz".into()],
            "pf-xyz",
        ),
        (
            vec![
                "maneuver".into(),
                "braking".into(),
                "--vehicle".into(),
                "tesla".into(),
            ],
            "tesla",
        ),
        (
            vec![
                "maneuver".into(),
                "braking".into(),
                "--mu".into(),
                "0".into(),
            ],
            "mu",
        ),
        (
            vec![
                "maneuver".into(),
                "braking".into(),
                "--mu".into(),
                "-0.3".into(),
            ],
            "-0.3",
        ),
        (
            vec![
                "maneuver".into(),
                "braking".into(),
                "--speed-mps".into(),
                "NaN".into(),
            ],
            "NaN",
        ),
        (
            vec![
                "maneuver".into(),
                "braking".into(),
                "--trace-period-s".into(),
                "-0.02".into(),
            ],
            "trace_period_s",
        ),
        (
            vec!["run".into(), "--json".into(), "/no/such/dir/x.json".into()],
            "/no/such/dir",
        ),
    ];
    for (mut args, needle) in cases {
        if !args.iter().any(|a| a == "--json") {
            args.extend(["--json".to_string(), json.to_str().unwrap().to_string()]);
        }
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = merge_sim(&refs);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
        assert!(!stderr(&out).contains("panicked"), "{}", stderr(&out));
        assert!(!json.exists(), "{args:?} left {}", json.display());
    }
    let empty: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert!(empty.is_empty());
}

#[test]
fn bad_scenario_file_names_the_field() {
    let dir = scratch("bad_file");
    let path = dir.join("bad.toml");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/builtin/urgent_merge.toml"),
    )
    .unwrap()
    .replace("mu = 0.8", "mu = 7.5");
    std::fs::write(&path, text).unwrap();
    let out = merge_sim(&["run", "--no-rrd", "--scenario", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        stderr(&out).contains("mu") && stderr(&out).contains("7.5"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn scenario_show_reads_back_unchanged() {
    let dir = scratch("show");
    let out = merge_sim(&["scenario", "show", "urgent_merge"]);
    assert!(out.status.success());
    let path = dir.join("urgent.toml");
    std::fs::write(&path, &out.stdout).unwrap();
    let a = scenarios::scenario::Scenario::load("urgent_merge").unwrap();
    let b = scenarios::scenario::Scenario::load(path.to_str().unwrap()).unwrap();
    assert_eq!(a, b);
    let list = merge_sim(&["scenario", "list"]);
    assert!(String::from_utf8_lossy(&list.stdout).contains("urgent_merge"));
}

/// `--trace-period-s` spaces the trace (rounded to whole steps of `--dt-s`), 0 drops it.
#[test]
fn maneuver_trace_period_sets_the_trace_spacing() {
    let dir = scratch("maneuver_trace");
    let json = dir.join("m.json");
    // The trace's times with `--trace-period-s period`, or with the default period.
    let trace_times = |period: Option<&str>| -> Vec<f64> {
        let mut args = vec!["maneuver", "step-steer", "--dt-s", "0.0025"];
        if let Some(period) = period {
            args.extend(["--trace-period-s", period]);
        }
        args.extend(["--json", json.to_str().unwrap()]);
        let out = merge_sim(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        v["trace"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| s["t_s"].as_f64().unwrap())
            .collect()
    };
    let times = trace_times(Some("0.02"));
    assert!(times.len() > 100, "{}", times.len());
    for pair in times.windows(2) {
        assert!((pair[1] - pair[0] - 0.02).abs() < 1e-9, "{pair:?}");
    }
    // The default (0.05 s) gives fewer samples; 0 gives none.
    let default_len = trace_times(None).len();
    assert!(
        default_len * 2 < times.len(),
        "{default_len} vs {}",
        times.len()
    );
    assert!(trace_times(Some("0")).is_empty());
}

#[test]
fn maneuver_json_has_the_documented_keys() {
    let dir = scratch("maneuver");
    let json = dir.join("m.json");
    let out = merge_sim(&[
        "maneuver",
        "steady-state",
        "--speed-mps",
        "15",
        "--steer-rad",
        "0.01",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for key in [
        "maneuver",
        "vehicle",
        "speed_mps",
        "steer_rad",
        "mu",
        "yaw_rate_radps",
        "sideslip_rad",
        "lat_accel_mps2",
        "params",
    ] {
        assert!(v.get(key).is_some(), "missing {key}: {v}");
    }
    for key in [
        "mass_kg",
        "yaw_inertia_kgm2",
        "lf_m",
        "lr_m",
        "cornering_stiffness_front_npr",
        "cornering_stiffness_rear_npr",
    ] {
        assert!(v["params"].get(key).is_some(), "missing params.{key}");
    }
    assert_eq!(v["vehicle"], "bmw_320i");
    // Left steer at 15 m/s: positive yaw rate of the order of the kinematic v·δ/L.
    let r = v["yaw_rate_radps"].as_f64().unwrap();
    assert!(r > 0.03 && r < 0.07, "{r}");
    let braking = merge_sim(&["maneuver", "braking", "--speed-mps", "20"]);
    assert!(braking.status.success(), "{}", stderr(&braking));
    let b: serde_json::Value = serde_json::from_slice(&braking.stdout).unwrap();
    let d = b["stopping_distance_m"].as_f64().unwrap();
    let reference = 20.0f64.powi(2) / (2.0 * 0.8 * 9.81);
    assert!(
        d > 0.95 * reference && d < 1.3 * reference,
        "{d} vs {reference}"
    );
}

#[test]
fn two_runs_write_identical_json_but_for_wall_clock_fields() {
    let dir = scratch("determinism");
    let read = |name: &str| {
        let path = dir.join(name);
        let out = merge_sim(&[
            "run",
            "--no-rrd",
            "--quiet",
            "--json",
            path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        // Wall-clock measurements are the only fields allowed to differ.
        let obj = v.as_object_mut().unwrap();
        obj.remove("wall_time_s");
        let stats = obj["planner_stats"].as_object_mut().unwrap();
        stats.remove("p50_plan_us");
        stats.remove("p99_plan_us");
        v
    };
    let a = read("a.json");
    let b = read("b.json");
    assert_eq!(a, b);
}

#[test]
fn run_profile_says_where_the_wall_time_went() {
    let dir = scratch("profile");
    let json = dir.join("run.json");
    let out = merge_sim(&[
        "run",
        "--no-rrd",
        "--profile",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("where the wall time went"), "{text}");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let phases = v["profile"]["phases"].as_array().unwrap();
    let names: Vec<&str> = phases
        .iter()
        .map(|p| p["phase"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "v2v",
            "planning",
            "tracking",
            "tire_forces",
            "physics",
            "safety",
            "metrics",
            "recording"
        ]
    );
    let wall = |name: &str| {
        phases.iter().find(|p| p["phase"] == name).unwrap()["wall_s"]
            .as_f64()
            .unwrap()
    };
    // Two vehicles plan 250 times each and rapier steps 12,500 times: both take time; nothing
    // is recorded.
    assert!(wall("planning") > 0.0 && wall("physics") > 0.0);
    let total: f64 = phases.iter().map(|p| p["wall_s"].as_f64().unwrap()).sum();
    assert!(wall("recording") < 0.01 * total, "{phases:?}");
    assert!(total <= v["wall_time_s"].as_f64().unwrap() * 1.01 + 1e-3);
    // Without --profile there is no profile.
    let out = merge_sim(&[
        "run",
        "--no-rrd",
        "--quiet",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert!(v.get("profile").is_none());
}

#[test]
fn a_large_recording_is_announced_before_it_is_written() {
    let dir = scratch("large_recording");
    let rrd = dir.join("platoon.rrd");
    // Fields and received paths of all 50 vehicles: about 500 MB. Stopped by SIGTERM after
    // three seconds, long before it is written.
    let out = Command::new("timeout")
        .args(["-s", "TERM", "3"])
        .arg(env!("CARGO_BIN_EXE_merge_sim"))
        .args([
            "run",
            "--quiet",
            "--scenario",
            "platoon_merge_50",
            "--record-detail",
            "all",
            "--rrd",
            rrd.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = stderr(&out);
    let warning = err.lines().next().unwrap_or_default();
    assert!(
        warning.starts_with("warning: the recording") && warning.contains("MB"),
        "{err}"
    );
    let megabytes: f64 = warning
        .split("about ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap();
    assert!(megabytes > 500.0, "{warning}");
    assert_eq!(
        out.status.code(),
        Some(124),
        "timeout's code for a stopped child: {err}"
    );
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}; {err}");
    // The default detail keeps the same run well below the threshold: no warning.
    let out = Command::new("timeout")
        .args(["-s", "TERM", "1"])
        .arg(env!("CARGO_BIN_EXE_merge_sim"))
        .args([
            "run",
            "--quiet",
            "--scenario",
            "platoon_merge_50",
            "--rrd",
            rrd.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
}

#[test]
fn compare_refuses_a_planner_listed_twice_and_is_silent_with_quiet() {
    let dir = scratch("compare_quiet");
    let json = dir.join("cmp.json");
    let out = merge_sim(&[
        "compare",
        "--planners",
        "pf-cs,pf-cs",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("--planners: pf-cs is listed twice"),
        "{}",
        stderr(&out)
    );
    assert!(!json.exists(), "nothing written before the refusal");

    let out = merge_sim(&[
        "compare",
        "-q",
        "--planners",
        "pf-cs",
        "--duration",
        "1",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(json.exists(), "--quiet still writes the outputs asked for");
}

#[test]
fn compare_outputs_name_the_scenario_parameter_set_and_commit() {
    let dir = scratch("compare_caption");
    let (json, markdown) = (dir.join("cmp.json"), dir.join("cmp.md"));
    let out = merge_sim(&[
        "compare",
        "--params",
        "paper",
        "--planners",
        "pf-cs,pf-iso",
        "--json",
        json.to_str().unwrap(),
        "--markdown",
        markdown.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let commit = mergesim::build_info::short_commit();
    let caption = format!("scenario urgent_merge · parameters paper · nominal · mergesim {commit}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(stdout.lines().next(), Some(caption.as_str()), "{stdout}");
    let md = std::fs::read_to_string(&markdown).unwrap();
    assert_eq!(md.lines().next(), Some(caption.as_str()), "{md}");
    assert!(md.contains("| metric | pf-cs | pf-iso |"), "{md}");
    let value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(value["scenario"], "urgent_merge");
    assert_eq!(value["params"], "paper");
    assert_eq!(value["commit"], commit.as_str());
    assert_eq!(value["caption"], caption.as_str());
    let runs = value["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 2);
    assert_eq!(runs[1]["planner"], "pf-iso");
}
