//! Tests of the scenario format: loading, validation with file, line and field, parameter
//! sets, randomisation.

use super::*;

/// A fixed scenario text for these tests (the built-ins may be retuned).
fn urgent() -> &'static str {
    r#"name = "two_cars"

[sim]
mu = 0.8
duration_s = 25.0

[[vehicles]]
name = "ego"
preset = "bmw_320i"
lane = "lower"
x_m = 0.0
speed_mps = 20.0
target_speed_mps = 20.0
driver = { planner = "pf-iso" }

[[vehicles]]
name = "obstacle"
preset = "bmw_320i"
lane = "upper"
x_m = 25.0
speed_mps = 15.0
target_speed_mps = 15.0
driver = { planner = "pf-iso" }

[randomise]
mu = { uniform = [-0.1, 0.1] }

[randomise.every_vehicle]
cruise_speed_mps = { uniform = [-1.0, 1.0] }

[randomise.vehicles.obstacle]
x_m = { uniform = [-3.0, 3.0] }
"#
}

fn line_of_text(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn every_builtin_loads_and_round_trips() {
    for name in builtin::names() {
        let s = Scenario::load(name).unwrap();
        let text = s.to_toml().unwrap();
        let back = Scenario::from_toml(&text, "round trip").unwrap();
        assert_eq!(s, back, "{name}");
        assert!(!s.randomise.is_empty(), "{name} carries no randomisation");
    }
}

#[test]
fn unknown_key_is_named_with_its_line() {
    let text = urgent().replace("mu = 0.8", "mu = 0.8\nfriction = 3");
    let err = Scenario::from_toml(&text, "x.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("friction") && err.contains("line"), "{err}");
}

#[test]
fn out_of_range_value_is_named_with_file_and_line() {
    let text = urgent().replace("mu = 0.8", "mu = -0.5");
    let err = Scenario::from_toml(&text, "x.toml")
        .unwrap_err()
        .to_string();
    let line = line_of_text(&text, "mu = -0.5");
    assert!(err.contains("mu") && err.contains("-0.5"), "{err}");
    assert!(err.starts_with(&format!("x.toml, line {line}:")), "{err}");
}

#[test]
fn vehicle_value_out_of_range_names_vehicle_and_line() {
    let text = urgent().replacen("\nspeed_mps = 15.0\n", "\nspeed_mps = -4.0\n", 1);
    let err = Scenario::from_toml(&text, "x.toml")
        .unwrap_err()
        .to_string();
    let line = line_of_text(&text, "speed_mps = -4.0");
    assert!(
        err.contains("vehicles[obstacle].speed_mps") && err.contains("-4"),
        "{err}"
    );
    assert!(err.contains(&format!("line {line}")), "{err}");
}

/// Every `[sim.*]` section's errors name the file, the line and the field (they used to
/// lose the line where the road's or the planner's error was flattened to text).
#[test]
fn errors_of_every_sim_section_carry_file_line_and_field() {
    for (section, key, value) in [
        ("road", "lane_width_m", "9.0"),
        ("planner", "step_time_s", "-1.0"),
        ("safety", "ttc_threshold_s", "nan"),
        ("tracker", "lookahead_min_m", "nan"),
        ("v2v", "drop_probability", "2.0"),
    ] {
        let text = format!("{}\n[sim.{section}]\n{key} = {value}\n", urgent());
        let err = Scenario::from_toml(&text, "x.toml").unwrap_err();
        let line = line_of_text(&text, &format!("{key} = {value}"));
        let message = err.to_string();
        assert!(
            message.starts_with(&format!("x.toml, line {line}:")),
            "[sim.{section}] {key}: {message}"
        );
        assert!(message.contains(key), "{message}");
        match err {
            ScenarioError::Invalid { field, .. } => {
                assert_eq!(field.as_deref(), Some(format!("{section}.{key}").as_str()))
            }
            other => panic!("{other:?}"),
        }
    }
}

#[test]
fn randomisation_that_can_leave_the_valid_range_is_refused() {
    // μ = 0.8 − 0.9 can reach −0.1.
    let text = urgent().replace(
        "mu = { uniform = [-0.1, 0.1] }",
        "mu = { uniform = [-0.9, 0.1] }",
    );
    assert_ne!(text, urgent(), "the built-in changed: update this test");
    let err = Scenario::from_toml(&text, "x.toml")
        .unwrap_err()
        .to_string();
    let line = line_of_text(&text, "mu = { uniform = [-0.9");
    assert!(
        err.contains("randomise.mu: at the lower end") && err.contains("mu = -0.09"),
        "{err}"
    );
    assert!(err.contains(&format!("line {line}")), "{err}");
}

#[test]
fn malformed_randomisation_entries_are_named() {
    let cases = [
        (
            "mu = { uniform = [-0.1, 0.1] }",
            "mu = { uniform = [0.1, -0.1] }",
            "randomise.mu",
        ),
        (
            "mu = { uniform = [-0.1, 0.1] }",
            "mu = { normal = { std = 0.1, clip = [0.05, 0.1] } }",
            "randomise.mu",
        ),
        (
            "mu = { uniform = [-0.1, 0.1] }",
            "mu = { gaussian = 1.0 }",
            "gaussian",
        ),
        (
            "[randomise.vehicles.obstacle]",
            "[randomise.vehicles.obstacel]",
            "obstacel",
        ),
        (
            "x_m = { uniform = [-3.0, 3.0] }",
            "z_m = { uniform = [-3.0, 3.0] }",
            "z_m",
        ),
        (
            "mu = { uniform = [-0.1, 0.1] }",
            "mu = { uniform = [-0.1, 0.1, 0.5] }",
            "exactly two numbers",
        ),
        (
            "mu = { uniform = [-0.1, 0.1] }",
            "mu = { normal = { std = 0.1, clip = [-0.1] } }",
            "exactly two numbers",
        ),
    ];
    for (from, to, needle) in cases {
        let text = urgent().replace(from, to);
        assert_ne!(text, urgent(), "{from}: the built-in changed");
        let err = Scenario::from_toml(&text, "x.toml")
            .unwrap_err()
            .to_string();
        let line = line_of_text(&text, to);
        assert!(err.contains(needle), "{to}: {err}");
        assert!(err.contains(&format!("line {line}")), "{to}: {err}");
    }
}

#[test]
fn spawn_overlap_over_the_randomisation_box_is_refused() {
    // Both vehicles in the upper lane 6 m apart: BMW 320i bodies are 4.508 m long, so the
    // nominal gap is 1.492 m, but ±3 m of x randomisation can close it.
    let text = urgent()
        .replacen("lane = \"lower\"", "lane = \"upper\"", 1)
        .replace("x_m = 25.0", "x_m = 6.0");
    let err = Scenario::from_toml(&text, "x.toml")
        .unwrap_err()
        .to_string();
    assert!(err.contains("overlap") && err.contains("obstacle"), "{err}");
    let tight = text.replace(
        "x_m = { uniform = [-3.0, 3.0] }",
        "x_m = { uniform = [-1.0, 1.0] }",
    );
    assert!(Scenario::from_toml(&tight, "x.toml").is_ok());
}

#[test]
fn lower_lane_vehicle_must_start_where_its_lane_exists() {
    let text = urgent().replace("x_m = 0.0", "x_m = 258.0");
    let err = Scenario::from_toml(&text, "x.toml")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("vehicles[ego].x_m") && err.contains("merge_end_x_m"),
        "{err}"
    );
}

#[test]
fn unknown_scenario_lists_builtins() {
    let err = Scenario::load("no_such_scenario").unwrap_err().to_string();
    assert!(err.contains("urgent_merge"), "{err}");
}

#[test]
fn instances_are_deterministic_distinct_and_inside_the_ranges() {
    let s = Scenario::from_toml(urgent(), "fixture").unwrap();
    assert_eq!(s.instance(None), s);
    let a = s.instantiate(42);
    assert_eq!(a, s.instantiate(42));
    assert_ne!(a, s.instantiate(43));
    assert!(a.randomise.is_empty());
    assert_eq!(
        a.instantiate(7),
        a,
        "an instance is its own nominal scenario"
    );
    let mut gaps = Vec::new();
    let mut mus = Vec::new();
    for seed in 0..2000 {
        let i = s.instantiate(seed);
        i.validate("instance").unwrap();
        let (ego, obs) = (&i.vehicles[0], &i.vehicles[1]);
        assert_eq!(
            ego.x_m, s.vehicles[0].x_m,
            "the ego's position is not randomised"
        );
        let gap_offset = obs.x_m - s.vehicles[1].x_m;
        assert!(gap_offset.abs() <= 3.0, "{gap_offset}");
        for (v, n) in [(ego, &s.vehicles[0]), (obs, &s.vehicles[1])] {
            let cruise = v.speed_mps - n.speed_mps;
            assert!(cruise.abs() <= 1.0);
            assert_eq!(v.target_speed_mps - n.target_speed_mps, cruise);
        }
        assert!((0.7..=0.9).contains(&i.sim.mu), "{}", i.sim.mu);
        gaps.push(gap_offset);
        mus.push(i.sim.mu);
    }
    // Uniform draws spread over the range: mean near the centre, extremes near the ends.
    let mean = |xs: &[f64]| xs.iter().sum::<f64>() / xs.len() as f64;
    assert!(mean(&gaps).abs() < 0.2, "{}", mean(&gaps));
    assert!((mean(&mus) - 0.8).abs() < 0.01);
    let max = gaps.iter().cloned().fold(f64::MIN, f64::max);
    assert!(max > 2.9, "{max}");
    // The fields use independent streams: the gap and μ offsets are uncorrelated.
    let (mg, mm) = (mean(&gaps), mean(&mus));
    let cov: f64 = gaps
        .iter()
        .zip(&mus)
        .map(|(g, m)| (g - mg) * (m - mm))
        .sum::<f64>()
        / gaps.len() as f64;
    let corr = cov / (3.0 / 3f64.sqrt() * (0.1 / 3f64.sqrt()));
    assert!(corr.abs() < 0.1, "{corr}");
}

#[test]
fn a_draw_does_not_depend_on_which_other_values_are_randomised() {
    let s = Scenario::from_toml(urgent(), "fixture").unwrap();
    let mut fewer = s.clone();
    fewer.randomise.mu = None;
    let (a, b) = (s.instantiate(9), fewer.instantiate(9));
    assert_eq!(a.vehicles, b.vehicles);
    assert_eq!(b.sim.mu, s.sim.mu);
}

#[test]
fn a_body_partly_off_the_road_at_spawn_is_refused() {
    // The ego (BMW 320i, 1.61 m wide) 1 m below the lower lane's centre (1.75 m): its body
    // reaches y = 0.75 − 0.805 = −0.055 m, below the road edge at 0 m.
    let text = urgent().replacen("x_m = 0.0", "x_m = 0.0\ny_offset_m = -1.0", 1);
    assert_ne!(text, urgent(), "the built-in changed: update this test");
    let err = Scenario::from_toml(&text, "x.toml")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("vehicles[ego].y_offset_m") && err.contains("must start on the road"),
        "{err}"
    );
    let line = line_of_text(&text, "y_offset_m = -1.0");
    assert!(err.contains(&format!("line {line}")), "{err}");
    // Half a body behind the road's start.
    let text = urgent().replacen("x_m = 0.0", "x_m = -48.0", 1);
    let err = Scenario::from_toml(&text, "x.toml")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("vehicles[ego].x_m") && err.contains("beyond the road"),
        "{err}"
    );
}
