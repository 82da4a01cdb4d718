//! Roads of lanes in scenario files: `[[sim.lane_road.lanes]]` written out, the generated
//! `curved_merge` and `on_ramp` roads, and the refusal of inconsistent lane data with the file,
//! the line and the field.

use mergesim_types::MergeRoad;
use mergesim_types::lanes::LaneId;
use scenarios::scenario::{Scenario, ScenarioError};

/// The urgent merge with its road written out as lanes: exactly the lanes
/// `MergeRoad::lane_road` builds for the default `[sim.road]`, vehicles at the same places (the
/// lanes start at x = −50 m, so s = x + 50).
pub const URGENT_AS_LANES: &str = include_str!("../../tests/data/urgent_merge_lanes.toml");

fn line_of_text(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .unwrap_or_else(|| panic!("{needle:?} not in the text"))
        + 1
}

/// The refusal of `text`: (line, field, message).
fn refusal(text: &str) -> (Option<usize>, Option<String>, String) {
    match Scenario::from_toml(text, "lanes.toml") {
        Err(e @ ScenarioError::Invalid { .. }) => {
            let message = e.to_string();
            let ScenarioError::Invalid { line, field, .. } = e else {
                unreachable!()
            };
            (line.0, field, message)
        }
        Err(other) => panic!("not a validation error: {other}"),
        Ok(_) => panic!("accepted:\n{text}"),
    }
}

fn assert_refused(text: &str, needle: &str, field: &str, words: &str) {
    let (line, got_field, message) = refusal(text);
    assert_eq!(got_field.as_deref(), Some(field), "{message}");
    assert_eq!(line, Some(line_of_text(text, needle)), "{message}");
    assert!(
        message.starts_with(&format!("lanes.toml, line {}:", line_of_text(text, needle))),
        "{message}"
    );
    assert!(message.contains(words), "{message}");
}

#[test]
fn lanes_written_out_give_the_merge_roads_lanes() {
    let s = Scenario::from_toml(URGENT_AS_LANES, "lanes.toml").unwrap();
    let spec = s.sim.lane_road.as_ref().unwrap().spec(&s.sim.road).unwrap();
    assert_eq!(spec, MergeRoad::default().lane_road_spec());
    let lanes = s.sim.lanes().unwrap();
    assert_eq!(lanes.lanes().len(), 2);
    assert!(lanes.lane_end(LaneId(2)).unwrap().closed);
    // It reads back from its own TOML.
    let back = Scenario::from_toml(&s.to_toml().unwrap(), "round trip").unwrap();
    assert_eq!(s, back);
}

#[test]
fn a_duplicate_lane_id_is_refused_at_the_second_lane() {
    let text = URGENT_AS_LANES.replacen("id = 2\n", "id = 1\n", 1);
    let (line, field, message) = refusal(&text);
    // The second `id = 1` line.
    let second = text
        .lines()
        .enumerate()
        .filter(|(_, l)| *l == "id = 1")
        .nth(1)
        .unwrap()
        .0
        + 1;
    assert_eq!(line, Some(second), "{message}");
    assert_eq!(field.as_deref(), Some("lane_road.lanes[1].id"), "{message}");
    assert!(message.contains("used by two lanes"), "{message}");
}

#[test]
fn a_link_to_an_unknown_lane_is_refused() {
    let text = URGENT_AS_LANES.replacen("right = 2", "right = 7", 1);
    assert_refused(
        &text,
        "right = 7",
        "lane_road.lanes[0].right",
        "names lane 7, which does not exist",
    );
}

#[test]
fn a_negative_width_is_refused() {
    let text = URGENT_AS_LANES.replacen("width_m = [3.5]", "width_m = [-3.5]", 1);
    assert_refused(
        &text,
        "width_m = [-3.5]",
        "lane_road.lanes[0].width_m[0]",
        "must be positive",
    );
}

#[test]
fn a_negative_width_at_one_vertex_names_the_vertex() {
    let text = URGENT_AS_LANES.replacen(
        "right_width_m = [1.75, 1.75, -1.75]",
        "right_width_m = [1.75, -2.0, -1.75]",
        1,
    );
    // The width is the sum of the two lists; the error is named after the left one (one value
    // here, so no vertex in the field) and gives the vertex in its message.
    assert_refused(
        &text,
        "left_width_m = [1.75]",
        "lane_road.lanes[1].left_width_m",
        "left_width_m[1]: width -0.25 m must be positive",
    );
}

#[test]
fn a_polyline_with_fewer_than_two_distinct_vertices_is_refused() {
    let text = URGENT_AS_LANES.replacen(
        "centreline_m = [[-50.0, 5.25], [700.0, 5.25]]",
        "centreline_m = [[-50.0, 5.25], [-49.99, 5.25]]",
        1,
    );
    assert_refused(
        &text,
        "[-49.99, 5.25]",
        "lane_road.lanes[0].centreline_m",
        "1 distinct vertices",
    );
}

#[test]
fn a_successor_that_does_not_start_where_the_lane_ends_is_refused() {
    let text = URGENT_AS_LANES.replacen("right = 2\n", "right = 2\nsuccessors = [2]\n", 1);
    assert_refused(
        &text,
        "successors = [2]",
        "lane_road.lanes[0].successors",
        "ends",
    );
}

#[test]
fn a_neighbour_that_is_not_beside_the_lane_is_refused() {
    // Lane 2 moved 10 m to the right: lane 1's right neighbour is not beside it.
    let text = URGENT_AS_LANES.replacen(
        "centreline_m = [[-50.0, 1.75], [160.0, 1.75], [260.0, 1.75]]",
        "centreline_m = [[-50.0, -8.25], [160.0, -8.25], [260.0, -8.25]]",
        1,
    );
    assert_refused(
        &text,
        "right = 2",
        "lane_road.lanes[0].right",
        "is not beside this lane",
    );
}

#[test]
fn an_unknown_lane_key_is_refused_with_its_line() {
    let text = URGENT_AS_LANES.replacen("right = 2\n", "right = 2\ncolour = \"red\"\n", 1);
    let err = Scenario::from_toml(&text, "lanes.toml").unwrap_err();
    let message = err.to_string();
    assert!(matches!(err, ScenarioError::Parse { .. }), "{message}");
    assert!(
        message.contains("colour")
            && message.contains(&format!("line {}", line_of_text(&text, "colour"))),
        "{message}"
    );
}

#[test]
fn a_road_given_twice_is_refused() {
    let text = URGENT_AS_LANES.replacen(
        "planner_period_s = 0.1\n",
        "planner_period_s = 0.1\n\n[sim.road]\nlane_width_m = 3.5\n",
        1,
    );
    let (line, field, message) = refusal(&text);
    assert_eq!(field.as_deref(), Some("lane_road"), "{message}");
    assert!(line.is_some(), "{message}");
    assert!(message.contains("both give the road"), "{message}");
}

#[test]
fn a_lane_road_table_must_give_exactly_one_road() {
    let text = URGENT_AS_LANES.replacen(
        "planner_period_s = 0.1\n",
        "planner_period_s = 0.1\n\n[sim.lane_road]\ncurved_merge = { radius_m = 300.0 }\n",
        1,
    );
    assert_refused(&text, "[sim.lane_road]", "lane_road", "exactly one of");
}

#[test]
fn a_vehicle_on_a_lane_the_road_lacks_is_refused() {
    let text = URGENT_AS_LANES.replacen("lane = \"upper\"", "lane = 9", 1);
    assert_refused(
        &text,
        "lane = 9",
        "vehicles[obstacle].lane",
        "lane 9 does not exist",
    );
}

#[test]
fn a_vehicle_beyond_its_lane_is_refused() {
    let text = URGENT_AS_LANES.replacen("x_m = 85.0", "x_m = 800.0", 1);
    assert_refused(
        &text,
        "x_m = 800.0",
        "vehicles[obstacle].x_m",
        "arc length along lane upper",
    );
}

#[test]
fn a_vehicle_off_the_road_is_refused() {
    // The ego 1 m to the right of its lane's centre: its body crosses the road's lower edge.
    let text = URGENT_AS_LANES.replacen("x_m = 50.0\n", "x_m = 50.0\ny_offset_m = -1.0\n", 1);
    assert_refused(
        &text,
        "y_offset_m = -1.0",
        "vehicles[ego].y_offset_m",
        "off the road",
    );
}

#[test]
fn a_bad_generated_road_parameter_is_named() {
    let text = scenarios::builtin::toml_of("on_ramp").unwrap().replacen(
        "ramp_radius_m = 150.0",
        "ramp_radius_m = 5.0",
        1,
    );
    let (line, field, message) = refusal(&text);
    assert_eq!(
        field.as_deref(),
        Some("lane_road.on_ramp.ramp_radius_m"),
        "{message}"
    );
    assert_eq!(line, Some(line_of_text(&text, "ramp_radius_m = 5.0")));
    let text = scenarios::builtin::toml_of("curved_merge")
        .unwrap()
        .replacen("radius_m = 300.0", "radius_m = 10.0", 1);
    let (line, field, message) = refusal(&text);
    assert_eq!(
        field.as_deref(),
        Some("lane_road.curved_merge.radius_m"),
        "{message}"
    );
    assert_eq!(line, Some(line_of_text(&text, "radius_m = 10.0")));
}

#[test]
fn the_new_builtins_load_on_their_roads_of_lanes() {
    let curved = Scenario::load("curved_merge").unwrap();
    let lanes = curved.sim.lanes().unwrap();
    let ending = lanes.lane(LaneId(2)).unwrap();
    // The ending lane is an arc of radius 300 + 1.75 m turning left.
    assert!((1.0 / ending.curvature_1pm(100.0) - 301.75).abs() < 0.01);
    assert!(lanes.lane_end(LaneId(2)).unwrap().closed);
    let on_ramp = Scenario::load("on_ramp").unwrap();
    let lanes = on_ramp.sim.lanes().unwrap();
    assert_eq!(lanes.lanes().len(), 4);
    let ramp = lanes.lane(LaneId(4)).unwrap();
    assert!((1.0 / ramp.curvature_1pm(20.0) + 150.0).abs() < 0.01);
    assert_eq!(ramp.successors(), [LaneId(3)]);
    assert!(lanes.lane_end(LaneId(3)).unwrap().closed);
    assert_eq!(on_ramp.vehicles[0].lane.id(), LaneId(4));
}

#[test]
fn lanes_too_short_for_the_run_are_refused_at_duration_s() {
    // The ego can drive 20 m/s × 1.1 × 45 s + half its length = 992.3 m; ahead of it: 260 m of
    // its ending lane, then 440 m of the through lane beside its end.
    let text = URGENT_AS_LANES.replacen("duration_s = 25.0", "duration_s = 45.0", 1);
    assert_refused(
        &text,
        "duration_s = 45.0",
        "duration_s",
        "vehicles[ego], which can drive 992.3 m",
    );
    let (_, _, message) = refusal(&text);
    assert!(message.contains("end after 700.0 m"), "{message}");
    // on_ramp: from 5 m along the 52.5 m ramp, its successor (the 300 m acceleration lane, which
    // ends closed) and the right main lane from beside its end (x = 450 m) to x = 650 m.
    let text = scenarios::builtin::toml_of("on_ramp").unwrap().replacen(
        "duration_s = 20.0",
        "duration_s = 30.0",
        1,
    );
    let (_, field, message) = refusal(&text);
    assert_eq!(field.as_deref(), Some("duration_s"), "{message}");
    assert!(
        message.contains("vehicles[ego]") && message.contains("end after 547.5 m"),
        "{message}"
    );
}

#[test]
fn on_the_road_table_lanes_are_named_or_numbered_1_and_2() {
    let urgent = scenarios::builtin::toml_of("urgent_merge").unwrap();
    // "upper" is lane 1: the same scenario.
    let numbered = urgent.replacen("lane = \"upper\"", "lane = 1", 1);
    let a = Scenario::from_toml(urgent, "a.toml").unwrap();
    let b = Scenario::from_toml(&numbered, "b.toml").unwrap();
    assert_eq!(a.vehicles[1].lane.id(), b.vehicles[1].lane.id());
    assert_eq!(
        b.vehicles[1].lane.merge_lane(),
        Some(mergesim_types::Lane::Upper)
    );
    // The merge road has no lane 3.
    let text = urgent.replacen("lane = \"upper\"", "lane = 3", 1);
    assert_refused(
        &text,
        "lane = 3",
        "vehicles[obstacle].lane",
        "has lanes \"lower\" (2) and \"upper\" (1)",
    );
    // A lane name that is neither.
    let text = urgent.replacen("lane = \"upper\"", "lane = \"middle\"", 1);
    let message = Scenario::from_toml(&text, "lanes.toml")
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("\"lower\", \"upper\" or a lane id")
            && message.contains(&format!(
                "line {}",
                line_of_text(&text, "lane = \"middle\"")
            )),
        "{message}"
    );
}
