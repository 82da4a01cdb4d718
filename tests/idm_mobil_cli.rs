//! `driver = "idm-mobil"` from a scenario file, as a user would write it: a human driver who
//! changes lanes (IDM with MOBIL), its `[sim.mobil]` table, and the errors of bad input.

mod common;

use common::{merge_sim, scratch, stderr};

/// The built-in urgent merge's file with the ego's driver replaced by `driver` and `extra`
/// appended at its end (a new table).
fn urgent_merge_with(driver: &str, extra: &str) -> String {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/builtin/urgent_merge.toml"
    ))
    .unwrap();
    let ego_driver = "driver = { planner = \"pf-iso\" }";
    let at = text.find(ego_driver).expect("the ego's driver line");
    let mut out = String::new();
    out.push_str(&text[..at]);
    out.push_str(&format!("driver = {driver}"));
    out.push_str(&text[at + ego_driver.len()..]);
    out.push('\n');
    out.push_str(extra);
    out
}

/// `merge_sim run --scenario FILE --json FILE.json`, parsed.
fn run_json(path: &std::path::Path) -> serde_json::Value {
    common::run_summary(
        &path.with_extension("json"),
        &["--scenario", path.to_str().unwrap()],
    )
}

/// The ego's lane-change events.
fn lane_changes_of_ego(summary: &serde_json::Value) -> Vec<String> {
    summary["events"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|e| e.as_str())
        .filter(|e| e.contains("ego") && e.contains("lane"))
        .map(str::to_string)
        .collect()
}

#[test]
fn an_idm_mobil_ego_merges_in_the_urgent_merge_where_a_plain_idm_ego_hits_the_lane_end() {
    let dir = scratch("idm_mobil_urgent_merge");
    // The plain IDM driver never changes lanes: the narrowing lane carries it into the edge.
    let plain = dir.join("plain.toml");
    std::fs::write(&plain, urgent_merge_with("\"idm\"", "")).unwrap();
    let plain = run_json(&plain);
    assert!(
        plain["collisions"].as_u64().unwrap() > 0,
        "the plain IDM ego was expected to touch the edge: {plain}"
    );
    // The traffic figures say the same: one merging vehicle, not merged before its lane ended.
    let ego_traffic = |summary: &serde_json::Value| {
        summary["traffic"]["vehicles"]
            .as_array()
            .unwrap()
            .iter()
            .find(|v| v["vehicle"] == "ego")
            .cloned()
            .unwrap()
    };
    assert_eq!(plain["traffic"]["merging"], 1, "{}", plain["traffic"]);
    assert_eq!(plain["traffic"]["merged_before_lane_end"], 0);
    assert_eq!(ego_traffic(&plain)["merged_before_lane_end"], false);
    assert_eq!(ego_traffic(&plain)["class"], "idm");
    // With MOBIL it changes into the through lane, behind or ahead of the obstacle, untouched.
    let mobil = dir.join("mobil.toml");
    std::fs::write(&mobil, urgent_merge_with("\"idm-mobil\"", "")).unwrap();
    let summary = run_json(&mobil);
    assert_eq!(summary["collisions"], 0, "{summary}");
    let changes = lane_changes_of_ego(&summary);
    assert!(!changes.is_empty(), "no lane change of the ego: {summary}");
    let ego = ego_traffic(&summary);
    assert_eq!(ego["class"], "idm-mobil");
    assert_eq!(ego["merged_before_lane_end"], true, "{ego}");
    assert_eq!(summary["traffic"]["merged_before_lane_end"], 1);
    // It merged at the instant of its lane-change event (`t = 12.35 s: ego changed lanes …`).
    let merged_at_s = ego["merged_at_s"].as_f64().unwrap();
    let event_t_s: f64 = changes[0]
        .trim_start_matches("t = ")
        .split(' ')
        .next()
        .and_then(|t| t.parse().ok())
        .unwrap();
    assert!(
        (merged_at_s - event_t_s).abs() < 0.006,
        "{merged_at_s} vs {}",
        changes[0]
    );
    // It travelled the whole run (never stuck at the lane's end): more than 25 s × 10 m/s.
    let ego = summary["vehicles"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["id"] == "ego")
        .unwrap();
    assert!(ego["path_length_m"].as_f64().unwrap() > 250.0, "{ego}");
}

#[test]
fn the_mobil_table_is_read_and_checked() {
    let dir = scratch("idm_mobil_table");
    // A politeness of 0 and no bias still merges (the lane's end is a standing obstacle, so
    // staying has the lower acceleration), and the table is echoed back in the canonical form.
    let path = dir.join("selfish.toml");
    std::fs::write(
        &path,
        urgent_merge_with(
            "\"idm-mobil\"",
            "[sim.mobil]\npoliteness = 0.0\nending_lane_bias_mps2 = 0.0\n",
        ),
    )
    .unwrap();
    let summary = run_json(&path);
    assert_eq!(summary["collisions"], 0, "{summary}");
    assert!(!lane_changes_of_ego(&summary).is_empty(), "{summary}");

    // Out of range: exit 2, the file, the line and the field, and no output written.
    let bad = dir.join("bad.toml");
    let text = urgent_merge_with("\"idm-mobil\"", "[sim.mobil]\npoliteness = -1.0\n");
    let line = text
        .lines()
        .position(|l| l.starts_with("politeness"))
        .unwrap()
        + 1;
    std::fs::write(&bad, &text).unwrap();
    let json = dir.join("out.json");
    let out = merge_sim(&[
        "run",
        "--scenario",
        bad.to_str().unwrap(),
        "--no-rrd",
        "--json",
        json.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("bad.toml"), "{err}");
    assert!(err.contains("mobil.politeness"), "{err}");
    assert!(err.contains(&format!("line {line}")), "line {line}: {err}");
    assert!(!json.exists());

    // An unknown key and a misspelt driver name are refused alike, naming what is valid.
    let typo = dir.join("typo.toml");
    std::fs::write(
        &typo,
        urgent_merge_with("\"idm-mobil\"", "[sim.mobil]\npoliteness_factor = 0.1\n"),
    )
    .unwrap();
    let out = merge_sim(&["run", "--scenario", typo.to_str().unwrap(), "--no-rrd"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("politeness_factor"), "{err}");
    let misspelt = dir.join("misspelt.toml");
    std::fs::write(&misspelt, urgent_merge_with("\"idm-mobl\"", "")).unwrap();
    let out = merge_sim(&["run", "--scenario", misspelt.to_str().unwrap(), "--no-rrd"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("idm-mobil"), "{err}");

    // As a planner name it takes no planner parameters, and says where the driver's are.
    let params = dir.join("planner_params.toml");
    std::fs::write(
        &params,
        urgent_merge_with(
            "{ planner = \"pf-iso\" }",
            "[sim.planners.idm-mobil]\npoliteness = 0.5\n",
        ),
    )
    .unwrap();
    let json = dir.join("params.json");
    let out = merge_sim(&[
        "run",
        "--scenario",
        params.to_str().unwrap(),
        "--planner",
        "idm-mobil",
        "--no-rrd",
        "--json",
        json.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("planners.idm-mobil.politeness"), "{err}");
    assert!(err.contains("[sim.mobil]"), "{err}");
    assert!(!json.exists());
}

/// The built-in scenario `name` as `merge_sim scenario show` prints it, with every
/// `driver = { planner = "pf-iso" }` line (a vehicle's or a traffic stream's) replaced by
/// `driver = "idm-mobil"` and `connected = false`, written to `path`.
fn all_idm_mobil(name: &str, path: &std::path::Path) {
    let out = merge_sim(&["scenario", "show", name]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    let pf_iso = "driver = { planner = \"pf-iso\" }";
    assert!(text.contains(pf_iso), "{text}");
    std::fs::write(
        path,
        text.replace(pf_iso, "driver = \"idm-mobil\"\nconnected = false"),
    )
    .unwrap();
}

#[test]
fn on_the_on_ramp_an_idm_mobil_driver_leaves_the_acceleration_lane_and_no_main_road_car_enters_it()
{
    let dir = scratch("idm_mobil_on_ramp");
    // From the ramp the driver follows its lane into the acceleration lane and then sees the
    // main road beside it: it merges before the lane ends, untouched (it used to hold the
    // ramp, which has no neighbour, and ran into the acceleration lane's end).
    let path = dir.join("on_ramp.toml");
    all_idm_mobil("on_ramp", &path);
    let summary = run_json(&path);
    assert_eq!(summary["collisions"], 0, "{}", summary["events"]);
    assert_eq!(summary["traffic"]["merging"], 1);
    assert_eq!(summary["traffic"]["merged_before_lane_end"], 1);
    // Dense on-ramp traffic: the main road's drivers never change into the acceleration lane
    // (lane 3: it ends ahead, theirs does not), nor into a lane that is not beside them yet,
    // and none of them touches an edge.
    let path = dir.join("on_ramp_flow.toml");
    all_idm_mobil("on_ramp_flow", &path);
    let summary = run_json(&path);
    let events: Vec<&str> = summary["events"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|e| e.as_str())
        .collect();
    assert!(
        !events
            .iter()
            .any(|e| e.contains(": main_") && (e.contains("to lane 3") || e.contains("to lane 4"))),
        "{events:?}"
    );
    assert!(
        !events
            .iter()
            .any(|e| e.contains("vehicle main_") && e.contains("road edge")),
        "{events:?}"
    );
    let traffic = &summary["traffic"];
    assert_eq!(
        traffic["merged_before_lane_end"], traffic["merging"],
        "{traffic}"
    );
    // `idm-mobil` as a planner name (a study's baseline): the same drivers on the same
    // instance, so the same run: the same events and traffic figures, classes included.
    let by_name = common::run_summary(
        &dir.join("by_name.json"),
        &["--scenario", "on_ramp_flow", "--planner", "idm-mobil"],
    );
    assert_eq!(by_name["events"], summary["events"]);
    assert_eq!(by_name["traffic"], summary["traffic"]);
    assert_eq!(by_name["min_gap_m"], summary["min_gap_m"]);
    assert_eq!(by_name["traffic"]["classes"][0]["class"], "idm-mobil");
}
