//! The parameter sets, the paper's metrics, the prescribed-speed driver and the sensitivity
//! grid as a user reaches them from the command line.

mod common;

use common::{merge_sim, scratch, stderr};

fn json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn params_selects_the_set_and_the_json_says_which_with_the_paper_s_metrics() {
    let dir = scratch("params_set");
    for set in ["paper", "mergesim"] {
        let path = dir.join(format!("{set}.json"));
        let out = merge_sim(&[
            "run",
            "--no-rrd",
            "--quiet",
            "--params",
            set,
            "--planner",
            "pf-cs",
            "--json",
            path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        let v = json(&path);
        assert_eq!(v["params"], set);
        let obstacle = &v["vehicles"][1];
        let paper = &obstacle["paper_metrics"];
        for key in [
            "slowing_onset_s",
            "merge_zone_rms_yaw_rate_radps",
            "outside_merge_zone_rms_yaw_rate_radps",
            "max_abs_lane_offset_m",
            "divider_crossing",
        ] {
            assert!(paper.get(key).is_some(), "{set}: missing {key} in {paper}");
        }
        assert_eq!(paper["merge_zone_x_m"], serde_json::json!([160.0, 280.0]));
        let crossing = &v["vehicles"][0]["paper_metrics"]["divider_crossing"];
        assert!(crossing["x_m"].as_f64().unwrap() > 160.0, "{crossing}");
    }
    // The two sets give different runs.
    let a = json(&dir.join("paper.json"));
    let b = json(&dir.join("mergesim.json"));
    assert_ne!(
        a["vehicles"][1]["max_abs_yaw_rate_radps"],
        b["vehicles"][1]["max_abs_yaw_rate_radps"]
    );
}

#[test]
fn an_unknown_parameter_set_is_refused_with_the_valid_ones() {
    let out = merge_sim(&["run", "--no-rrd", "--params", "literal"]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(err.contains("paper") && err.contains("mergesim"), "{err}");

    let dir = scratch("params_unknown");
    let file = dir.join("s.toml");
    let text = String::from_utf8(merge_sim(&["scenario", "show", "urgent_merge"]).stdout)
        .unwrap()
        .replacen("[sim]", "params = \"literal\"\n\n[sim]", 1);
    std::fs::write(&file, &text).unwrap();
    let out = merge_sim(&["run", "--no-rrd", "--scenario", file.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(
        err.contains("s.toml") && err.contains("params") && err.contains("paper"),
        "{err}"
    );
}

#[test]
fn a_scenario_s_planner_values_apply_on_top_of_its_set() {
    let dir = scratch("params_overlay");
    let file = dir.join("s.toml");
    let text = String::from_utf8(merge_sim(&["scenario", "show", "urgent_merge"]).stdout)
        .unwrap()
        .replacen("[sim]", "params = \"paper\"\n\n[sim]", 1)
        + "\n[sim.planner]\nobstacle_time_gap_s = 1.5\n";
    std::fs::write(&file, &text).unwrap();
    let scenario = mergesim::scenarios::scenario::Scenario::load(file.to_str().unwrap()).unwrap();
    assert_eq!(scenario.params, mergesim::planner::ParameterSet::Paper);
    assert_eq!(scenario.sim.planner.obstacle_time_gap_s, 1.5);
    // Everything else is the paper set's.
    assert!(!scenario.sim.planner.predict_obstacles_in_path);
    // --params mergesim keeps the file's value and takes the rest from mergesim.
    let ours = scenario
        .with_parameter_set(mergesim::planner::ParameterSet::Mergesim)
        .unwrap();
    assert_eq!(ours.sim.planner.obstacle_time_gap_s, 1.5);
    assert!(ours.sim.planner.predict_obstacles_in_path);
    // And the text written back reads back the same.
    let again =
        mergesim::scenarios::scenario::Scenario::from_toml(&scenario.to_toml().unwrap(), "x")
            .unwrap();
    assert_eq!(again.sim.planner, scenario.sim.planner);
}

#[test]
fn the_prescribed_speed_driver_follows_its_profile_and_bad_profiles_exit_2() {
    let dir = scratch("prescribed");
    let path = dir.join("run.json");
    let scenario = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/experiments/prebraking_paper_profile.toml"
    );
    let out = merge_sim(&[
        "run",
        "--no-rrd",
        "--quiet",
        "--scenario",
        scenario,
        "--json",
        path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v = json(&path);
    let obstacle = &v["vehicles"][1];
    let min = obstacle["min_speed_mps"].as_f64().unwrap();
    let t_min = obstacle["t_min_speed_s"].as_f64().unwrap();
    assert!((min - 9.4).abs() < 0.3, "{min}");
    assert!((t_min - 14.9).abs() < 1.0, "{t_min}");
    let onset = obstacle["paper_metrics"]["slowing_onset_s"]
        .as_f64()
        .unwrap();
    assert!((3.1..4.0).contains(&onset), "{onset}");

    let bad = std::fs::read_to_string(scenario)
        .unwrap()
        .replace("[14.9, 9.4]", "[14.9, -9.4]");
    let file = dir.join("bad.toml");
    std::fs::write(&file, bad).unwrap();
    let out = merge_sim(&["run", "--no-rrd", "--scenario", file.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert!(
        err.contains("vehicles[obstacle].driver.prescribed.speed_profile[2] speed"),
        "{err}"
    );
}

#[test]
fn a_small_grid_writes_paired_rows_csv_and_figure() {
    let dir = scratch("grid");
    let (csv, json_path, png) = (dir.join("g.csv"), dir.join("g.json"), dir.join("g.png"));
    let out = merge_sim(&[
        "grid",
        "--planners",
        "pf-cs,pf-iso",
        "--path-gaps",
        "0",
        "--interaction-gaps",
        "1,2",
        "--quiet",
        "--csv",
        csv.to_str().unwrap(),
        "--json",
        json_path.to_str().unwrap(),
        "--plot",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v = json(&json_path);
    // 4 (prediction × sub-steps) × 1 τ × 2 τ_I cells, two planners, one instance.
    assert_eq!(v["grid"]["rows"].as_array().unwrap().len(), 16);
    assert_eq!(v["paired_peak_yaw_rate"].as_array().unwrap().len(), 8);
    let text = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(
        text.lines().count(),
        1 + 16 * 2,
        "one line per run and vehicle"
    );
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    // Bad input: an unknown vehicle, before any run.
    let out = merge_sim(&["grid", "--vehicle", "bus"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("bus"), "{}", stderr(&out));
}
