//! `merge_sim commonroad dump`: JSON for the test files, exit 2 naming file, line and element
//! for bad ones, nothing on stdout then.

use std::process::Command;

fn dump(path: &str) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_merge_sim"))
        .args(["commonroad", "dump", path])
        .output()
        .expect("merge_sim runs")
}

#[test]
fn dump_prints_the_a9_file_in_its_own_coordinates() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/commonroad/DEU_A9-3_1_T-1.xml"
    );
    let out = dump(path);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(v["scenario"]["format"], "2018b");
    assert_eq!(v["scenario"]["lanelets"].as_array().map(Vec::len), Some(32));
    assert_eq!(v["lane_road"]["lanes"].as_array().map(Vec::len), Some(32));
    // The replayed first state of obstacle 3536: the position rectangle's centre, at 0 s.
    let first = &v["replay"]["3536"][0];
    assert_eq!(first["time_s"], 0.0);
    assert_eq!(first["position_m"][1], -5866.331045464546);
}

#[test]
fn a_bad_reference_exits_2_naming_file_line_and_lanelet() {
    let dir = std::env::temp_dir().join(format!("mergesim_cr_{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let file = dir.join("bad_ref.xml");
    std::fs::write(
        &file,
        "<commonRoad commonRoadVersion=\"2020a\" timeStepSize=\"0.1\">\n  <lanelet id=\"5\">\n    <leftBound><point><x>0</x><y>3</y></point><point><x>9</x><y>3</y></point></leftBound>\n    <rightBound><point><x>0</x><y>0</y></point><point><x>9</x><y>0</y></point></rightBound>\n    <predecessor ref=\"77\"/>\n  </lanelet>\n</commonRoad>\n",
    )
    .expect("write");
    let out = dump(file.to_str().expect("utf-8 path"));
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad_ref.xml:5: lanelet 5: predecessor refers to lanelet 77"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
