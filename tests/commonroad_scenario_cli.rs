//! CommonRoad files as scenarios from the user's side: `run|compare|sweep --scenario FILE.xml`
//! report the goal; `--recorded-traffic` and `--duration`; bad input exits 2 naming the file,
//! the line and the element, and writes nothing.

mod common;

use common::{merge_sim, scratch, stderr};

const US101: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/commonroad/USA_US101-4_1_T-1.xml"
);
const Y_MERGE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/data/commonroad/own/y_merge.xml"
);

fn run_json(name: &str, args: &[&str]) -> serde_json::Value {
    let dir = scratch(name);
    let json = dir.join("out.json");
    let mut all = vec![
        "run",
        "--no-rrd",
        "--quiet",
        "--json",
        json.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    let out = merge_sim(&all);
    assert!(out.status.success(), "{}", stderr(&out));
    serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap()
}

#[test]
fn us101_runs_with_pf_iso_and_reports_its_goal() {
    for mode in ["none", "replay"] {
        let v = run_json(
            &format!("us101_{mode}"),
            &[
                "--scenario",
                US101,
                "--planner",
                "pf-iso",
                "--recorded-traffic",
                mode,
            ],
        );
        assert_eq!(v["scenario"], "USA_US101-4_1_T-1");
        // Until the goal's time interval ends (time step 100 × 0.1 s).
        assert_eq!(v["duration_s"], 10.0);
        assert!(v["goal_reached"].is_boolean(), "{v}");
        assert_eq!(
            v["goal_reached"].as_bool() == Some(true),
            v["goal_time_s"].is_number()
        );
    }
    let v = run_json(
        "us101_duration",
        &["--scenario", US101, "--duration", "2.5"],
    );
    assert_eq!(v["duration_s"], 2.5);
}

#[test]
fn the_y_merge_ego_reaches_its_goal_lanelet() {
    let v = run_json(
        "y_merge",
        &["--scenario", Y_MERGE, "--recorded-traffic", "none"],
    );
    assert_eq!(v["goal_reached"], true, "{v}");
    let t = v["goal_time_s"].as_f64().unwrap();
    // The ramp is ≈ 102 m long; the ego starts 5 m along it at 15 m/s.
    assert!(t > 5.0 && t < 8.0, "{t}");
    let out = merge_sim(&[
        "compare",
        "--scenario",
        Y_MERGE,
        "--recorded-traffic",
        "none",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("goal reached at s"));
    let out = merge_sim(&[
        "sweep",
        "--scenario",
        Y_MERGE,
        "--recorded-traffic",
        "none",
        "--runs",
        "2",
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn a_built_in_has_no_recorded_traffic_to_set() {
    let out = merge_sim(&[
        "run",
        "--scenario",
        "urgent_merge",
        "--recorded-traffic",
        "none",
        "--no-rrd",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("CommonRoad road"), "{}", stderr(&out));
    let out = merge_sim(&[
        "run",
        "--scenario",
        US101,
        "--recorded-traffic",
        "sometimes",
        "--no-rrd",
    ]);
    assert_eq!(out.status.code(), Some(2));
}

/// `merge_sim run` on `text` written to `file`: exit 2, the message holds `expected`, no output.
fn assert_refused(name: &str, file: &str, text: &str, expected: &[String]) {
    let dir = scratch(name);
    let path = dir.join(file);
    std::fs::write(&path, text).unwrap();
    let json = dir.join("out.json");
    let rrd = dir.join("out.rrd");
    let out = merge_sim(&[
        "run",
        "--scenario",
        path.to_str().unwrap(),
        "--quiet",
        "--json",
        json.to_str().unwrap(),
        "--rrd",
        rrd.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{name}: {err}");
    assert!(err.contains(&path.display().to_string()), "{name}: {err}");
    for e in expected {
        assert!(err.contains(e.as_str()), "{name}: {e:?} not in {err}");
    }
    assert!(!json.exists(), "{name}: output written");
    assert!(!rrd.exists(), "{name}: a recording written");
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn bad_commonroad_scenarios_exit_2_naming_file_line_and_element() {
    let y = std::fs::read_to_string(Y_MERGE).unwrap();
    // Malformed XML: the parser's line.
    let bad = y.replacen("<successor ref=\"12\"/>", "<successor ref=\"12\">", 1);
    assert_refused("cr_malformed", "m.xml", &bad, &["malformed XML".into()]);
    // An unknown lanelet reference.
    let bad = y.replacen("<successor ref=\"12\"/>", "<successor ref=\"99\"/>", 1);
    let line = line_of(&bad, "ref=\"99\"");
    assert_refused(
        "cr_unknown_ref",
        "u.xml",
        &bad,
        &[format!("u.xml:{line}: lanelet 10:"), "lanelet 99".into()],
    );
    // Bounds with different point counts.
    let bad = y.replacen(
        "<point><x>100.0000</x><y>1.7500</y></point></leftBound>",
        "<point><x>100.0000</x><y>1.7500</y></point><point><x>110.0000</x><y>1.7500</y></point></leftBound>",
        1,
    );
    assert_ne!(bad, y);
    assert_refused(
        "cr_bounds",
        "b.xml",
        &bad,
        &[
            format!("b.xml:{}: lanelet 10:", line_of(&bad, "<lanelet id=\"10\"")),
            "points".into(),
        ],
    );
    // An unsupported format version.
    let bad = y.replacen(
        "commonRoadVersion=\"2020a\"",
        "commonRoadVersion=\"2017a\"",
        1,
    );
    assert_refused("cr_version", "v.xml", &bad, &["2017a".into()]);
    // A goal no route reaches (lanelet 10, beside the ramp's start).
    let bad = y.replacen("<lanelet ref=\"12\"/>", "<lanelet ref=\"10\"/>", 1);
    assert_refused(
        "cr_unreachable",
        "g.xml",
        &bad,
        &[
            format!(
                "g.xml, line {}: planningProblem 201:",
                line_of(&bad, "<goalState>")
            ),
            "no route".into(),
        ],
    );
    // A planning problem whose initial state is on no lanelet.
    let pp = y.find("<planningProblem").unwrap();
    let (head, tail) = y.split_at(pp);
    let bad = format!(
        "{head}{}",
        tail.replacen("<x>5.0000</x>", "<x>-50.0000</x>", 1)
    );
    assert_refused(
        "cr_off_lanelet",
        "o.xml",
        &bad,
        &[
            format!(
                "o.xml, line {}: planningProblem 201:",
                line_of(&bad, "<planningProblem") + 1
            ),
            "on no lanelet".into(),
        ],
    );
}

#[test]
fn a_toml_vehicle_off_its_lanelet_exits_2_at_its_line() {
    let text = format!(
        "name = \"t\"\n[sim]\nduration_s = 5.0\n[sim.road]\ncommonroad = \"{}\"\n\n[[vehicles]]\nname = \"ego\"\npreset = \"bmw_320i\"\nlanelet = 12\ns_m = 10.0\nd_m = -2.0\nspeed_mps = 15.0\ntarget_speed_mps = 15.0\ndriver = {{ planner = \"pf-iso\" }}\n",
        Y_MERGE
    );
    assert_refused(
        "toml_off_lanelet",
        "t.toml",
        &text,
        &[
            format!("t.toml, line {}:", line_of(&text, "d_m")),
            "vehicles[ego].d_m".into(),
        ],
    );
}

#[test]
fn leaving_the_map_ends_the_run_with_an_event() {
    // Lanelet 12 ends (open) at x = 300 m: at ≈ 15 m/s the ego leaves the map after ≈ 20 s.
    let v = run_json(
        "left_map",
        &[
            "--scenario",
            Y_MERGE,
            "--recorded-traffic",
            "none",
            "--duration",
            "40",
        ],
    );
    let d = v["duration_s"].as_f64().unwrap();
    assert!(d > 15.0 && d < 25.0, "{d}");
    let events: Vec<&str> = v["events"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|e| e.as_str())
        .collect();
    assert!(
        events
            .iter()
            .any(|e| e.contains("ego left the map") && e.contains("lane 12")),
        "{events:?}"
    );
    // The goal was reached before.
    assert_eq!(v["goal_reached"], true);
}

#[test]
fn too_many_lanelets_exit_2() {
    let mut body = String::new();
    for i in 0..=mergesim_commonroad::MAX_LANELETS {
        let y = 4.0 * i as f64;
        body.push_str(&format!(
            "<lanelet id=\"{}\"><leftBound><point><x>0</x><y>{}</y></point><point><x>9</x><y>{}</y></point></leftBound><rightBound><point><x>0</x><y>{y}</y></point><point><x>9</x><y>{y}</y></point></rightBound></lanelet>\n",
            i + 1,
            y + 3.0,
            y + 3.0
        ));
    }
    let text = format!(
        "<commonRoad commonRoadVersion=\"2020a\" timeStepSize=\"0.1\">\n{body}</commonRoad>\n"
    );
    assert_refused(
        "cr_too_many",
        "many.xml",
        &text,
        &[format!(
            "{} lanelets",
            mergesim_commonroad::MAX_LANELETS + 1
        )],
    );
}

#[test]
fn at_a_fork_the_route_chooses_the_branch() {
    let fork = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/commonroad/own/fork.xml"
    );
    let dir = scratch("fork_route");
    let lane_changes = |route: &str| -> Vec<String> {
        let text = format!(
            "name = \"fork\"\n[sim]\nduration_s = 14.0\n[sim.road]\ncommonroad = \"{fork}\"\n\n[[vehicles]]\nname = \"ego\"\npreset = \"bmw_320i\"\nlanelet = 20\ns_m = 10.0\nspeed_mps = 15.0\ntarget_speed_mps = 15.0\ndriver = {{ planner = \"pf-iso\" }}\n{route}\n"
        );
        let path = dir.join(format!("fork{}.toml", route.len()));
        std::fs::write(&path, text).unwrap();
        let v = run_json("fork_route_run", &["--scenario", path.to_str().unwrap()]);
        v["events"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|e| e.as_str())
            .filter(|e| e.contains("changed lanes"))
            .map(str::to_string)
            .collect()
    };
    // Without a route (and routed to the exit) the car ends in the exit 22; routed straight on
    // it stays on lanelet 21.
    for route in ["", "route = [20, 22]"] {
        let changes = lane_changes(route);
        assert!(
            changes.iter().any(|e| e.contains("to lane 22")),
            "{route}: {changes:?}"
        );
    }
    assert_eq!(lane_changes("route = [20, 21]"), Vec::<String>::new());
}
