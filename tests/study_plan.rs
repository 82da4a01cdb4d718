//! Study plans read and checked without running anything: the ways of writing factors and
//! cells, what a factor may set, and the refusals that name the line.

use std::path::Path;

use mergesim::study::plan::EndpointWindow;
use mergesim::study::plan::StudyPlan;

const HEAD: &str = r#"name = "p"
scenario = "urgent_merge"
planners = ["pf-sp", "pf-iso"]
reference = "pf-sp"
[instances]
n = 4
seed = "18446744073709551615"
[endpoints]
primary = { figure = "obstacle.max_abs_yaw_rate_radps", threshold = "0.01 rad/s" }
"#;

fn load(extra: &str) -> Result<StudyPlan, String> {
    StudyPlan::from_text(&format!("{HEAD}{extra}"), Path::new("p.toml")).map_err(|e| e.to_string())
}

#[test]
fn factors_are_a_full_factorial_of_any_scenario_value() {
    let plan = load(
        "[factors]\nsim.mu = [0.8, 0.6]\nparams = [\"paper\", \"mergesim\"]\n\
         \"vehicles.ego.target_speed_mps\" = [14.0, 16.0]\n\
         \"sim.planner.interaction_time_gap_s\" = [1.0]\n",
    )
    .unwrap();
    assert_eq!(plan.cells.len(), 8);
    assert_eq!(plan.total_runs(), 8 * 2 * 4);
    assert_eq!(plan.seed, u64::MAX);
    assert_eq!(plan.window, EndpointWindow::PreContact);
    // Each cell's scenario holds its values (nested keys `sim.mu = …` work as quoted ones).
    for (cell, scenario) in &plan.cells {
        let label = cell.label();
        let mu = if label.contains("sim.mu=0.6") {
            0.6
        } else {
            0.8
        };
        assert_eq!(scenario.sim.mu, mu, "{label}");
        let ego = scenario.vehicles.iter().find(|v| v.name == "ego").unwrap();
        let speed = if label.contains("target_speed_mps=16.0") {
            16.0
        } else {
            14.0
        };
        assert_eq!(ego.target_speed_mps, speed, "{label}");
        assert_eq!(scenario.sim.planner.interaction_time_gap_s, 1.0);
        let set = if label.contains("params=\"paper\"") {
            "paper"
        } else {
            "mergesim"
        };
        assert_eq!(scenario.params.name(), set, "{label}");
    }
}

#[test]
fn listed_cells_and_no_factors() {
    let plan = load("[[cells]]\n\"sim.mu\" = 0.7\n[[cells]]\n\"sim.mu\" = 0.5\n").unwrap();
    assert_eq!(plan.cells.len(), 2);
    assert_eq!(plan.cells[1].1.sim.mu, 0.5);
    let plain = load("").unwrap();
    assert_eq!(plain.cells.len(), 1);
    assert_eq!(plain.cells[0].0.label(), "nominal");
    assert_eq!(plain.cells[0].1, plain.scenario);
}

#[test]
fn refusals_name_the_line() {
    // HEAD has 9 lines.
    let cases = [
        (
            "[factors]\n\"sim.mu\" = [0.8]\n[[cells]]\n\"sim.mu\" = 0.7\n",
            "not both",
            12,
        ),
        (
            "[[cells]]\n\"sim.mu\" = 0.7\n[[cells]]\n\"sim.mu\" = 0.7\n",
            "repeats cell 0",
            13,
        ),
        ("[factors]\n\"sim.mu\" = 0.8\n", "levels are a list", 11),
        (
            "[factors]\n\"vehicles.truck.x_m\" = [1.0]\n",
            "unknown factor",
            11,
        ),
        ("[factors]\n\"sim\" = [1.0]\n", "unknown factor", 11),
        ("[collisions]\nendpoints = \"after\"\n", "pre-contact", 11),
    ];
    for (extra, message, line) in cases {
        let err = load(extra).unwrap_err();
        assert!(err.contains(message), "{extra}: {err}");
        assert!(
            err.contains(&format!("p.toml, line {line}:")),
            "{extra}: {err}"
        );
    }
    let text = HEAD.replace("reference = \"pf-sp\"", "reference = \"pf-cs\"");
    let err = StudyPlan::from_text(&text, Path::new("p.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("line 4") && err.contains("not one of the planners"),
        "{err}"
    );
    let text = HEAD.replace("n = 4", "n = 1");
    let err = StudyPlan::from_text(&text, Path::new("p.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("line 6") && err.contains(">= 2"), "{err}");
    let text = format!("{HEAD}unknown_key = 1\n");
    let err = StudyPlan::from_text(&text, Path::new("p.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("unknown_key") && err.contains("line 10"),
        "{err}"
    );
}
