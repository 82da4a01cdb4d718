//! `merge_sim opendrive dump`: JSON for the test road, exit 2 naming the file for bad ones,
//! nothing on stdout then.

use std::process::Command;

fn dump(path: &str) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_merge_sim"))
        .args(["opendrive", "dump", path])
        .output()
        .expect("merge_sim runs")
}

#[test]
fn dump_prints_the_lanes_with_their_opendrive_origin() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/opendrive/tests/data/line_arc_merge.xodr"
    );
    let out = dump(path);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let lanes = v["lanes"].as_array().expect("lanes");
    assert_eq!(lanes.len(), 5);
    assert!(
        lanes
            .iter()
            .any(|l| l["od_lane_id"] == -2 && l["lane_type"] == "entry")
    );
    assert_eq!(v["lane_road"]["lanes"].as_array().map(Vec::len), Some(5));
}

#[test]
fn a_bad_file_exits_2_naming_it_and_prints_nothing() {
    let dir = std::env::temp_dir().join(format!("mergesim_od_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    for (name, text) in [
        ("malformed.xodr", "<OpenDRIVE><road"),
        (
            "no_lanes.xodr",
            "<OpenDRIVE><header revMajor=\"1\" revMinor=\"6\"/></OpenDRIVE>",
        ),
    ] {
        let file = dir.join(name);
        std::fs::write(&file, text).expect("write");
        let out = dump(file.to_str().expect("utf-8 path"));
        assert_eq!(out.status.code(), Some(2), "{name}");
        assert!(out.stdout.is_empty(), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(name), "{name}: {err}");
    }
    let out = dump("/nonexistent/road.xodr");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/road.xodr"));
}
