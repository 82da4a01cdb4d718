//! A scenario TOML on an OpenDRIVE road (`[sim.lane_road] opendrive = { file = … }`, relative to
//! the TOML): it runs from any working directory, and a missing or broken file is refused with
//! exit 2 naming the TOML, the line and the field, before anything is written.

use std::path::PathBuf;
use std::process::Command;

fn merge_sim(args: &[&str], cwd: &std::path::Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_merge_sim"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("merge_sim runs")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mergesim_od_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn scenario() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenarios/opendrive/merge_on_line_arc.toml")
}

#[test]
fn the_opendrive_scenario_runs_from_another_directory() {
    let dir = scratch("run");
    let json = dir.join("summary.json");
    let out = merge_sim(
        &[
            "run",
            "--scenario",
            scenario().to_str().expect("utf-8"),
            "--no-rrd",
            "--quiet",
            "--json",
            json.to_str().expect("utf-8"),
        ],
        &dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&json).expect("summary")).expect("JSON");
    let run = if v.is_array() { &v[0] } else { &v };
    assert_eq!(run["vehicles"].as_array().map(Vec::len), Some(2), "{run}");
    assert_eq!(run["collisions"], 0, "{run}");
}

#[test]
fn a_missing_or_broken_road_file_exits_2_naming_toml_line_and_field() {
    let dir = scratch("opendrive_bad");
    let text = std::fs::read_to_string(scenario()).expect("scenario");
    let broken = dir.join("broken.xodr");
    std::fs::write(&broken, "<OpenDRIVE><road").expect("write");
    for (name, file) in [
        ("missing.toml", "nowhere.xodr"),
        ("broken.toml", "broken.xodr"),
    ] {
        let toml = dir.join(name);
        let rewritten = text.replace("../../opendrive/tests/data/line_arc_taper.xodr", file);
        assert_ne!(rewritten, text);
        std::fs::write(&toml, rewritten).expect("write");
        let json = dir.join(format!("{name}.json"));
        let out = merge_sim(
            &[
                "run",
                "--scenario",
                toml.to_str().expect("utf-8"),
                "--no-rrd",
                "--json",
                json.to_str().expect("utf-8"),
            ],
            &dir,
        );
        assert_eq!(out.status.code(), Some(2), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(name), "{name}: {err}");
        assert!(err.contains("line 25"), "{name}: {err}");
        assert!(
            err.contains("sim.lane_road.opendrive.file"),
            "{name}: {err}"
        );
        assert!(err.contains(file), "{name}: {err}");
        assert!(!json.exists(), "{name}: output written");
    }
}
