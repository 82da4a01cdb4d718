//! CommonRoad files as scenarios: the ego, its goal and route, the recorded traffic, the
//! duration, and the refusals (file, line, element).

use std::path::{Path, PathBuf};

use mergesim_types::lanes::LaneId;
use scenarios::scenario::{Scenario, ScenarioError};
use sim::goal::GoalPosition;
use sim::recorded_traffic::TrafficMode;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/commonroad")
        .join(name)
}

fn load(name: &str) -> Scenario {
    Scenario::load(data(name).to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"))
}

/// A temporary file with `text`, under a folder of its own.
fn temp_file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "mergesim_crscen_{}_{}",
        std::process::id(),
        name.replace(['.', '/'], "_")
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn refusal(path: &Path) -> String {
    match Scenario::load(path.to_str().unwrap()) {
        Ok(_) => panic!("{} was accepted", path.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn us101_ego_goal_and_traffic() {
    let s = load("USA_US101-4_1_T-1.xml");
    assert_eq!(s.name, "USA_US101-4_1_T-1");
    assert_eq!(s.vehicles.len(), 1);
    let ego = &s.vehicles[0];
    assert_eq!(ego.name, "ego");
    assert_eq!(ego.speed_mps, 5.331);
    // The goal's velocity interval [0, 3] m/s: its midpoint.
    assert_eq!(ego.target_speed_mps, 1.5);
    let goal = ego.goal.as_ref().unwrap();
    assert_eq!(goal.states.len(), 1);
    // Time steps 90–100 at 0.1 s.
    let t = goal.states[0].time_s.unwrap();
    assert!((t.start - 9.0).abs() < 1e-12 && (t.end - 10.0).abs() < 1e-12);
    assert!(matches!(
        goal.states[0].position,
        Some(GoalPosition::Shapes(_))
    ));
    // The run lasts until the goal's time interval ends.
    assert!((s.sim.duration_s - 10.0).abs() < 1e-12);
    // A route from the start lanelet to one the goal rectangle touches.
    let route = ego.route.as_ref().unwrap();
    assert_eq!(route.first(), Some(&ego.lane.id()));
    assert_eq!(s.sim.recorded_traffic.vehicles.len(), 22);
    assert_eq!(s.sim.recorded_traffic.mode, TrafficMode::Replay);
    assert!(
        s.sim
            .recorded_traffic
            .vehicles
            .iter()
            .all(|v| v.name.starts_with("cr-") && !v.states.is_empty())
    );
    let road = s.sim.commonroad_road().unwrap();
    assert!(road.file.is_absolute());
    let none = s.with_recorded_traffic(TrafficMode::None).unwrap();
    assert_eq!(none.sim.recorded_traffic.mode, TrafficMode::None);
    assert_eq!(
        none.sim.commonroad_road().unwrap().recorded_traffic,
        TrafficMode::None
    );
    assert_eq!(s.with_duration(4.0).unwrap().sim.duration_s, 4.0);
}

#[test]
fn a9_time_only_goal_keeps_the_lane_rule() {
    let s = load("DEU_A9-3_1_T-1.xml");
    let ego = &s.vehicles[0];
    let goal = ego.goal.as_ref().unwrap();
    assert!(!goal.has_position());
    // No position: no route (the lane-end rule).
    assert_eq!(ego.route, None);
    // Time steps 0–30 at 0.2 s.
    assert!((s.sim.duration_s - 6.0).abs() < 1e-9);
    // No goal velocity: the lanelets' speed limit (2018b speedLimit).
    assert!(ego.target_speed_mps > 27.0 && ego.target_speed_mps < 28.0);
}

#[test]
fn own_files_route_across_a_lane_change_and_through_a_y_merge() {
    let s = load("own/acceleration_lane.xml");
    let ego = &s.vehicles[0];
    assert_eq!(ego.lane.id(), LaneId(2));
    assert_eq!(ego.route, Some(vec![LaneId(2), LaneId(1)]));
    // No goal velocity, no speed limit: its initial speed.
    assert_eq!(ego.target_speed_mps, 20.0);
    // The goal's time interval ends at step 250.
    assert!((s.sim.duration_s - 25.0).abs() < 1e-9);
    let y = load("own/y_merge.xml");
    let ego = &y.vehicles[0];
    assert_eq!(ego.route, Some(vec![LaneId(11), LaneId(12)]));
    assert_eq!(ego.target_speed_mps, 15.0);
    // No time interval: the last recorded state (step 100).
    assert!((y.sim.duration_s - 10.0).abs() < 1e-9);
}

#[test]
fn a_goal_no_route_reaches_is_refused_naming_file_line_and_problem() {
    let text = std::fs::read_to_string(data("own/y_merge.xml")).unwrap();
    // The goal on the main lanelet 10, which the ramp does not lead to.
    let bad = text.replace("<lanelet ref=\"12\"/>", "<lanelet ref=\"10\"/>");
    assert_ne!(bad, text);
    let path = temp_file("unreachable.xml", &bad);
    let e = refusal(&path);
    let line = bad.lines().position(|l| l.contains("<goalState>")).unwrap() + 1;
    assert!(
        e.contains(&format!(
            "unreachable.xml, line {line}: planningProblem 201:"
        )) && e.contains("no route")
            && e.contains("lanelet 11"),
        "{e}"
    );
}

#[test]
fn an_initial_state_on_no_lanelet_is_refused() {
    let text = std::fs::read_to_string(data("own/acceleration_lane.xml")).unwrap();
    let pp = text.find("<planningProblem").unwrap();
    let (head, tail) = text.split_at(pp);
    let bad = format!(
        "{head}{}",
        tail.replacen("<y>-3.5000</y>", "<y>-40.0000</y>", 1)
    );
    assert_ne!(bad, text);
    let path = temp_file("off_map.xml", &bad);
    let e = refusal(&path);
    let line = bad
        .lines()
        .position(|l| l.contains("<planningProblem"))
        .unwrap()
        + 2;
    assert!(
        e.contains(&format!("off_map.xml, line {line}: planningProblem 200:"))
            && e.contains("on no lanelet"),
        "{e}"
    );
}

#[test]
fn reader_refusals_keep_file_line_and_element() {
    let text = std::fs::read_to_string(data("own/y_merge.xml")).unwrap();
    let bad = text.replacen("<successor ref=\"12\"/>", "<successor ref=\"99\"/>", 1);
    let path = temp_file("bad_ref.xml", &bad);
    let e = Scenario::load(path.to_str().unwrap()).unwrap_err();
    assert!(matches!(e, ScenarioError::CommonRoad(_)), "{e}");
    assert!(e.to_string().contains("bad_ref.xml:7: lanelet 10:"), "{e}");
}

fn toml_on_own_road(vehicles: &str, road_extra: &str) -> String {
    let xml = data("own/acceleration_lane.xml");
    format!(
        "name = \"t\"\n[sim]\nduration_s = 5.0\n[sim.road]\ncommonroad = \"{}\"\n{road_extra}\n{vehicles}",
        xml.display()
    )
}

const EGO: &str = "[[vehicles]]\nname = \"ego\"\npreset = \"bmw_320i\"\nlanelet = 2\ns_m = 10.0\nd_m = 0.5\nspeed_mps = 20.0\ntarget_speed_mps = 20.0\ndriver = { planner = \"pf-iso\" }\n";

#[test]
fn a_toml_scenario_on_a_commonroad_road_places_vehicles_by_lanelet() {
    let s = Scenario::from_toml(
        &toml_on_own_road(EGO, "recorded_traffic = \"none\""),
        "t.toml",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.vehicles[0].lane.id(), LaneId(2));
    assert_eq!(s.vehicles[0].x_m, 10.0);
    assert_eq!(s.vehicles[0].y_offset_m, 0.5);
    assert_eq!(s.sim.recorded_traffic.mode, TrafficMode::None);
    // The file's recorded car is read (and left out in mode none).
    assert_eq!(s.sim.recorded_traffic.vehicles.len(), 1);
    // The scenario in scenarios/commonroad/ loads, its path relative to it.
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("commonroad/urgent_merge_acceleration_lane.toml");
    let s = Scenario::load(p.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.vehicles.len(), 2);
}

#[test]
fn a_vehicle_placed_off_its_lanelet_is_refused_at_its_d_m_line() {
    // d = 2.5 m: beyond the 3.5 m lanelet's half width (it would lie on the next lanelet).
    let text = toml_on_own_road(&EGO.replace("d_m = 0.5", "d_m = 2.5"), "");
    let e = Scenario::from_toml(&text, "t.toml")
        .unwrap_err()
        .to_string();
    let line = text.lines().position(|l| l.starts_with("d_m")).unwrap() + 1;
    assert!(
        e.starts_with(&format!("t.toml, line {line}: "))
            && e.contains("vehicles[ego].d_m = 2.5")
            && e.contains("lanelet 2"),
        "{e}"
    );
}

#[test]
fn commonroad_road_keys_are_checked() {
    let e = Scenario::from_toml(
        &toml_on_own_road(EGO, "recorded_traffic = \"sometimes\""),
        "t.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("line 6") && e.contains("recorded_traffic"),
        "{e}"
    );
    let e = Scenario::from_toml(&toml_on_own_road(EGO, "lane_width_m = 3.0"), "t.toml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("line 6") && e.contains("road.lane_width_m"),
        "{e}"
    );
    let missing = "name = \"t\"\n[sim.road]\ncommonroad = \"no/such/file.xml\"\n".to_string() + EGO;
    let e = Scenario::from_toml(&missing, "t.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("no/such/file.xml"), "{e}");
}

#[test]
fn a_commonroad_scenario_written_as_toml_reads_back_the_same() {
    let s = load("USA_US101-4_1_T-1.xml");
    let text = s.to_toml().unwrap();
    let back = Scenario::from_toml(&text, "back.toml").unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(back.vehicles, s.vehicles);
    assert_eq!(back.sim.duration_s, s.sim.duration_s);
    assert_eq!(back.sim.recorded_traffic, s.sim.recorded_traffic);
    assert_eq!(back.sim.lane_road, s.sim.lane_road);
}

#[test]
fn a_toml_whose_commonroad_file_cannot_be_read_is_named_with_its_line() {
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("commonroad/urgent_merge_acceleration_lane.toml");
    let text = std::fs::read_to_string(shipped).unwrap();
    // Copied elsewhere, its relative path to the XML no longer leads anywhere.
    let path = temp_file("moved.toml", &text);
    let e = refusal(&path);
    let line = text
        .lines()
        .position(|l| l.starts_with("commonroad ="))
        .unwrap()
        + 1;
    assert!(
        e.starts_with(&format!(
            "{}, line {line}: sim.road.commonroad: ",
            path.display()
        )) && e.contains("acceleration_lane.xml"),
        "{e}"
    );
}
