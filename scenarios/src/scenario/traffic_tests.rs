//! Tests of the `[traffic]` tables in a scenario: the nominal vehicles, instances, the text
//! written back, and the errors of bad input (file, line, field).

use super::*;

/// A merge road with one fixed ego and one stream over both lanes (a fixed text: the
/// built-ins may be retuned).
fn flow_text() -> String {
    r#"name = "flow"

[sim]
mu = 0.8
duration_s = 40.0

[sim.road]
lane_width_m = 3.5
y_bottom_m = 0.0
merge_start_x_m = 520.0
merge_end_x_m = 620.0
start_x_m = -50.0
end_x_m = 1700.0

[[vehicles]]
name = "ego"
preset = "bmw_320i"
lane = "lower"
x_m = -20.0
speed_mps = 20.0
target_speed_mps = 20.0
driver = { planner = "pf-iso" }

[traffic.approach]
flow_vph = { uniform = [1000.0, 1600.0] }
lanes = ["upper", "lower"]
rear_x_m = 10.0
front_x_m = 480.0
speed_mps = 20.0
min_headway_s = 1.0
driver = "idm-mobil"
connected = false

[randomise.every_vehicle]
cruise_speed_mps = { uniform = [-1.0, 1.0] }
"#
    .to_string()
}

/// The error of `text`, which must be refused as invalid: (line, field, message).
fn invalid(text: &str) -> (Option<usize>, Option<String>, String) {
    match Scenario::from_toml(text, "flow.toml") {
        Err(ScenarioError::Invalid {
            line,
            field,
            message,
            origin,
        }) => {
            assert_eq!(origin, "flow.toml");
            (line.0, field, message)
        }
        other => panic!("expected an invalid scenario, got {other:?}"),
    }
}

/// The 1-based line of the first line of `text` starting with `start`.
fn line_starting(text: &str, start: &str) -> usize {
    text.lines().position(|l| l.starts_with(start)).unwrap() + 1
}

#[test]
fn the_nominal_vehicles_follow_the_listed_ones_and_the_text_reads_back() {
    let text = flow_text();
    let s = Scenario::from_toml(&text, "flow.toml").unwrap();
    // 1,300 veh/h over two lanes: μ = 5.54 s, T = 470 m / 20 m/s = 23.5 s, ⌊T/μ + ½⌋ = 4.
    assert_eq!(s.fixed_vehicles().len(), 1);
    assert_eq!(s.generated_vehicles, 8);
    assert_eq!(s.vehicles.len(), 9);
    assert_eq!(s.vehicles[0].name, "ego");
    assert_eq!(s.vehicles[1].name, "approach_upper_00");
    assert!(
        s.vehicles[1..]
            .iter()
            .all(|v| v.driver == sim::config::Driver::IdmMobil && !v.connected)
    );
    // Written out: the listed vehicle and the [traffic] table, not the generated vehicles.
    let written = s.to_toml().unwrap();
    assert!(!written.contains("approach_upper_00"), "{written}");
    assert!(written.contains("[traffic.approach]"), "{written}");
    assert_eq!(Scenario::from_toml(&written, "written").unwrap(), s);
}

#[test]
fn instances_are_deterministic_vary_in_count_and_have_every_vehicle_listed() {
    let s = Scenario::from_toml(&flow_text(), "flow.toml").unwrap();
    let a = s.instantiate(3);
    assert_eq!(a, s.instantiate(3));
    assert!(a.traffic.is_empty() && a.generated_vehicles == 0);
    assert_eq!(a.vehicles[0].name, "ego");
    let counts: std::collections::BTreeSet<usize> = (0..40)
        .map(|seed| s.instantiate(seed).vehicles.len())
        .collect();
    assert!(counts.len() > 2, "{counts:?}");
    // The instance is a scenario of its own: its text lists every vehicle and reads back.
    let written = a.to_toml().unwrap();
    let back = Scenario::from_toml(&written, "instance").unwrap();
    assert_eq!(back.vehicles, a.vehicles);
    assert_eq!(back.vehicles.len(), a.vehicles.len());
    // The [randomise] offsets reach the generated vehicles: speeds differ from 20 m/s.
    assert!(a.vehicles[1..].iter().any(|v| v.speed_mps != 20.0));
    // The nominal expansion is the nominal scenario with every vehicle listed.
    let nominal = s.expanded(None);
    assert_eq!(nominal.vehicles, s.vehicles);
    assert!(nominal.traffic.is_empty() && nominal.randomise.is_empty());
}

#[test]
fn bad_traffic_values_name_the_file_line_and_field() {
    let text = flow_text();
    // (text replaced, by, the field named, the start of the line named)
    for (from, to, field, at) in [
        (
            "flow_vph = { uniform = [1000.0, 1600.0] }",
            "flow_vph = { uniform = [1600.0, 1000.0] }",
            "traffic.approach.flow_vph",
            "flow_vph",
        ),
        // 1,600 veh/h over two lanes is a mean headway of 4.5 s, below 6 s.
        (
            "min_headway_s = 1.0",
            "min_headway_s = 6.0",
            "traffic.approach.flow_vph",
            "flow_vph",
        ),
        (
            "speed_mps = 20.0\nmin",
            "speed_mps = -2.0\nmin",
            "traffic.approach.speed_mps",
            "speed_mps = -2.0",
        ),
        (
            "front_x_m = 480.0",
            "front_x_m = 5.0",
            "traffic.approach.front_x_m",
            "front_x_m",
        ),
        (
            "lanes = [\"upper\", \"lower\"]",
            "lanes = []",
            "traffic.approach.lanes",
            "lanes",
        ),
        (
            "min_headway_s = 1.0",
            "min_headway_s = 0.1",
            "traffic.approach.min_headway_s",
            "min_headway_s",
        ),
        // The ego inside the window of its lane.
        (
            "x_m = -20.0",
            "x_m = 100.0",
            "vehicles.0.x_m",
            "x_m = 100.0",
        ),
    ] {
        let bad = text.replacen(from, to, 1);
        assert_ne!(bad, text, "{from}");
        let (line, got, message) = invalid(&bad);
        assert_eq!(got.as_deref(), Some(field), "{message}");
        assert!(message.contains(field), "{message}");
        assert_eq!(line, Some(line_starting(&bad, at)), "{field}: {message}");
    }
    // 0.1 s headways in a 470 m window at 20 m/s: up to 236 per lane, more than allowed.
    let (_, _, message) = invalid(&text.replacen("min_headway_s = 1.0", "min_headway_s = 0.1", 1));
    assert!(
        message.contains(&sim::config::MAX_VEHICLES.to_string()),
        "{message}"
    );
}

#[test]
fn the_nominal_and_the_densest_instance_are_checked_against_the_road() {
    // A window reaching into the merge section, where the lower lane narrows: the nominal
    // vehicles fit (the front one at 560 − 20·5.54/2 ≈ 505 m), the densest instance puts one
    // at front_x_m = 560 m.
    let bad = flow_text().replacen("front_x_m = 480.0", "front_x_m = 560.0", 1);
    let (line, field, message) = invalid(&bad);
    assert_eq!(field.as_deref(), Some("traffic.approach"), "{message}");
    assert_eq!(line, Some(line_starting(&bad, "[traffic.approach]")));
    assert!(message.contains("the densest instance"), "{message}");
    assert!(message.contains("approach_lower_00"), "{message}");
    // Further on, the nominal instance already has a car there.
    let bad = flow_text().replacen("front_x_m = 480.0", "front_x_m = 640.0", 1);
    let (line, field, message) = invalid(&bad);
    assert_eq!(field.as_deref(), Some("traffic.approach"), "{message}");
    assert_eq!(line, Some(line_starting(&bad, "[traffic.approach]")));
    assert!(message.contains("the nominal instance"), "{message}");
}

#[test]
fn an_unknown_key_is_refused_by_name() {
    let bad = flow_text().replacen("min_headway_s", "min_headway", 1);
    match Scenario::from_toml(&bad, "flow.toml") {
        Err(ScenarioError::Parse { message, .. }) => {
            assert!(message.contains("min_headway"), "{message}");
            assert!(message.contains("line"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_listed_vehicle_may_not_take_a_generated_name() {
    let bad = flow_text().replacen("name = \"ego\"", "name = \"approach_x\"", 1);
    let (line, field, message) = invalid(&bad);
    assert_eq!(field.as_deref(), Some("vehicles.0.name"), "{message}");
    assert_eq!(line, Some(line_starting(&bad, "name = \"approach_x\"")));
}

#[test]
fn the_built_in_flow_scenarios_load_with_their_documented_counts() {
    // The counts their files state: 6 per main lane and 3 on the ramp; 4 per approach.
    let on_ramp = Scenario::load("on_ramp_flow").unwrap();
    assert_eq!(on_ramp.vehicles.len(), 15);
    assert_eq!(
        on_ramp
            .vehicles
            .iter()
            .filter(|v| v.name.starts_with("ramp_"))
            .count(),
        3
    );
    let merge = Scenario::load("merge_flow").unwrap();
    assert_eq!(merge.vehicles.len(), 8);
    for s in [&on_ramp, &merge] {
        assert!(s.fixed_vehicles().is_empty());
        assert_eq!(
            Scenario::from_toml(&s.to_toml().unwrap(), "again").unwrap(),
            *s
        );
    }
}
