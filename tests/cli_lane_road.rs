//! Roads of lanes from the user's side: inconsistent lane data is refused by the binary with
//! the file, the line and the field and exit code 2 before any output; the merge road written
//! out as lanes runs exactly as the `[sim.road]` table; the new built-ins load and run.

mod common;

use common::{merge_sim, scratch, stderr};
use mergesim::scenarios::scenario::Scenario;

/// urgent_merge with its road written out as lanes (scenarios/tests/lane_road.rs has the same
/// text; the vehicles are urgent_merge's, at s = x + 50 m since the lanes start at x = −50 m).
const URGENT_AS_LANES: &str = include_str!("data/urgent_merge_lanes.toml");

fn line_of_text(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

/// Runs `merge_sim run` on `text` written to a file; checks exit 2, the file, line and field in
/// the message, and that no output was written.
fn assert_cli_refuses(name: &str, text: &str, needle: &str, field: &str) {
    let dir = scratch(name);
    let path = dir.join("bad.toml");
    std::fs::write(&path, text).unwrap();
    let json = dir.join("out.json");
    let out = merge_sim(&[
        "run",
        "--scenario",
        path.to_str().unwrap(),
        "--no-rrd",
        "--quiet",
        "--json",
        json.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    let line = line_of_text(text, needle);
    assert!(
        err.contains(&format!("{}, line {line}:", path.display())),
        "{name}: {err}"
    );
    assert!(err.contains(field), "{name}: {err}");
    assert!(!json.exists(), "{name}: output written");
}

#[test]
fn the_binary_refuses_inconsistent_lanes_with_file_line_field_and_exit_2() {
    assert_cli_refuses(
        "lanes_unknown_link",
        &URGENT_AS_LANES.replacen("right = 2", "right = 7", 1),
        "right = 7",
        "lane_road.lanes[0].right",
    );
    assert_cli_refuses(
        "lanes_negative_width",
        &URGENT_AS_LANES.replacen("width_m = [3.5]", "width_m = [-3.5]", 1),
        "width_m = [-3.5]",
        "lane_road.lanes[0].width_m[0]",
    );
    assert_cli_refuses(
        "lanes_one_vertex",
        &URGENT_AS_LANES.replacen(
            "[[-50.0, 5.25], [700.0, 5.25]]",
            "[[-50.0, 5.25], [-50.0, 5.25]]",
            1,
        ),
        "[[-50.0, 5.25], [-50.0, 5.25]]",
        "lane_road.lanes[0].centreline_m",
    );
    let duplicate = URGENT_AS_LANES.replacen("id = 2\n", "id = 1 # the duplicate\n", 1);
    assert_cli_refuses(
        "lanes_duplicate_id",
        &duplicate,
        "# the duplicate",
        "lane_road.lanes[1].id",
    );
}

#[test]
fn the_merge_road_written_as_lanes_runs_exactly_as_the_road_table() {
    let table = Scenario::load("urgent_merge").unwrap();
    let lanes = Scenario::from_toml(URGENT_AS_LANES, "urgent_merge_lanes.toml").unwrap();
    let a = common::simulate(&table, None, 0, true);
    let b = common::simulate(&lanes, None, 0, true);
    // Measured identical (2026-12-02): every time-series row and every figure.
    let json = |v: &dyn erased::Json| v.value();
    assert_eq!(json(&a.vehicles), json(&b.vehicles));
    assert!(!a.time_series.is_empty());
    assert_eq!(json(&a.time_series), json(&b.time_series));
    assert_eq!(a.events, b.events);
    assert_eq!(a.safety.collisions.len(), b.safety.collisions.len());
    assert_eq!(a.safety.min_gap_m, b.safety.min_gap_m);
    assert!(a.events.iter().any(|e| matches!(
        e,
        mergesim::sim::SimEvent::LaneChange { direction, .. } if direction == "left"
    ) && e.to_string().contains("changed lanes left")));
}

/// Serialising the outcome's parts for comparison.
mod erased {
    pub trait Json {
        fn value(&self) -> serde_json::Value;
    }
    impl<T: serde::Serialize> Json for T {
        fn value(&self) -> serde_json::Value {
            serde_json::to_value(self).unwrap()
        }
    }
}

#[test]
fn the_new_builtins_load_and_a_run_starts() {
    for name in ["curved_merge", "on_ramp"] {
        let out = merge_sim(&["scenario", "show", name]);
        assert!(out.status.success(), "{}", stderr(&out));
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(text.contains("[sim.lane_road"), "{name}: {text}");
        // Four seconds of the scenario through the binary: it loads, validates and runs.
        let dir = scratch(&format!("builtin_{name}"));
        let path = dir.join(format!("{name}.toml"));
        let short = text
            .lines()
            .map(|l| {
                if l.starts_with("duration_s") {
                    "duration_s = 4.0"
                } else {
                    l
                }
            })
            .collect::<Vec<_>>()
            .join("\n");
        std::fs::write(&path, short).unwrap();
        let json = dir.join("run.json");
        let out = merge_sim(&[
            "run",
            "--scenario",
            path.to_str().unwrap(),
            "--no-rrd",
            "--quiet",
            "--json",
            json.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{name}: {}", stderr(&out));
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        assert!(
            (v["duration_s"].as_f64().unwrap() - 4.0).abs() < 1e-9,
            "{v}"
        );
    }
}

/// The largest distance of `vehicle` from the centreline of the lane it is in (the lanes of
/// `scenario`'s road), over the run's time series.
fn max_offset_from_its_lane_m(
    scenario: &Scenario,
    rows: &[mergesim::sim::TimeSeriesRow],
    vehicle: &str,
) -> f64 {
    let lanes = scenario.sim.lanes().unwrap();
    rows.iter()
        .filter(|r| r.vehicle == vehicle)
        .map(|r| {
            let hit = lanes
                .lanes_at([r.x_m, r.y_m])
                .into_iter()
                .next()
                .unwrap_or_else(|| panic!("{vehicle} off the lanes at t = {}", r.t_s));
            hit.frame.d_m.abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn the_simulators_drivers_follow_curved_lanes_and_successors() {
    use mergesim::sim::config::Driver;
    // on_ramp: the ego keeps its lane from the ramp (a 150 m arc) into the acceleration lane,
    // its successor (no lane change); the others follow their main lanes with the IDM.
    let mut on_ramp = Scenario::load("on_ramp").unwrap();
    on_ramp.sim.duration_s = 6.0;
    on_ramp.vehicles[0].driver = Driver::LaneKeeping;
    for v in &mut on_ramp.vehicles[1..] {
        v.driver = Driver::Idm;
    }
    let outcome = common::simulate(&on_ramp, None, 0, true);
    assert!(
        !outcome
            .events
            .iter()
            .any(|e| matches!(e, mergesim::sim::SimEvent::LaneChange { .. })),
        "{:?}",
        outcome.events
    );
    // At 20 m/s the ego leaves the 52.5 m ramp after ≈ 2.4 s: it ends on the acceleration lane.
    let lanes = on_ramp.sim.lanes().unwrap();
    let last = outcome
        .time_series
        .iter()
        .rfind(|r| r.vehicle == "ego")
        .unwrap();
    let hit = lanes.lanes_at([last.x_m, last.y_m]);
    assert_eq!(hit.first().map(|h| h.lane.0), Some(3), "{last:?}");
    for name in ["ego", "obstacle", "overtaker"] {
        let offset_m = max_offset_from_its_lane_m(&on_ramp, &outcome.time_series, name);
        assert!(
            offset_m < 0.3,
            "{name}: {offset_m} m from its lane's centre"
        );
    }
    // curved_merge: both vehicles keep their lanes on the 300 m curve with the IDM.
    let mut curved = Scenario::load("curved_merge").unwrap();
    curved.sim.duration_s = 8.0;
    for v in &mut curved.vehicles {
        v.driver = Driver::Idm;
    }
    let outcome = common::simulate(&curved, None, 0, true);
    assert!(
        !outcome
            .events
            .iter()
            .any(|e| matches!(e, mergesim::sim::SimEvent::LaneChange { .. })),
        "{:?}",
        outcome.events
    );
    for name in ["ego", "obstacle"] {
        let offset_m = max_offset_from_its_lane_m(&curved, &outcome.time_series, name);
        assert!(
            offset_m < 0.3,
            "{name}: {offset_m} m from its lane's centre"
        );
    }
}
