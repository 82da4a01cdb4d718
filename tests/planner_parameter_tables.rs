//! Each planner's own parameters from the command line and the library: `[sim.planners.NAME]`
//! tables and a vehicle's `driver = { planner = "NAME", params = { … } }`. Bad tables exit 2
//! before any work, naming the file, the line and the field, with nothing written; a user's
//! planner registered with its parameter type receives its values; the PF planners' tables
//! are views on one parameter struct, so the old `[sim.planner]` form runs bit for bit the same.

mod common;

use std::sync::{Arc, Mutex};

use common::{merge_sim, scratch, stderr};
use mergesim::experiment::{InstanceOptions, RunError, run_instance};
use mergesim::mergesim_types::{Behaviour, BehaviourError, Decision, Observation, PathPoint};
use mergesim::scenarios::scenario::Scenario;
use mergesim::sim::recording::Recorder;
use mergesim::sim::registry::{BehaviourRegistry, FactoryInput};
use mergesim::sim::{ParamsError, PlannerParameters, SimError};

const URGENT: &str = include_str!("../scenarios/builtin/urgent_merge.toml");
const EGO_DRIVER: &str = "driver = { planner = \"pf-iso\" }";

fn text_with(tables: &str, ego_driver: Option<&str>) -> String {
    let mut text = URGENT.to_string();
    if let Some(driver) = ego_driver {
        text = text.replacen(EGO_DRIVER, driver, 1);
    }
    text + "\n" + tables
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .map(|i| i + 1)
        .unwrap_or_else(|| panic!("{needle:?} not in the text"))
}

#[test]
fn bad_planner_tables_exit_2_naming_file_line_and_field_with_nothing_written() {
    let dir = scratch("planner_tables_refused");
    let cases = [
        (
            "unknown key",
            text_with("[sim.planners.pf-iso]\nw3 = 1.0\n", None),
            "w3 = 1.0",
            "planners.pf-iso.w3",
        ),
        (
            "out of range",
            text_with("[sim.planners.pf]\nwaypoint_count = 2\n", None),
            "waypoint_count = 2",
            "waypoint_count",
        ),
        (
            "another planner's key",
            text_with("[sim.planners.pf]\nrisk_weight = 10.0\n", None),
            "risk_weight = 10.0",
            "belongs to pf-sp's table",
        ),
        (
            "a vehicle's key of another planner's table",
            text_with(
                "",
                Some("driver = { planner = \"pf-iso\", params = { risk_weight = 10.0 } }"),
            ),
            "risk_weight = 10.0",
            "vehicles[ego].driver.params.risk_weight",
        ),
        (
            "a vehicle's value out of range",
            text_with(
                "",
                Some("driver = { planner = \"pf-iso\", params = { interaction_weight = -1.0 } }"),
            ),
            "interaction_weight = -1.0",
            "interaction_weight",
        ),
    ];
    for (what, text, needle, field) in cases {
        let file = dir.join("s.toml");
        std::fs::write(&file, &text).unwrap();
        let line = line_of(&text, needle);
        let json = dir.join("run.json");
        let out = merge_sim(&[
            "run",
            "--no-rrd",
            "--quiet",
            "--scenario",
            file.to_str().unwrap(),
            "--json",
            json.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(2), "{what}: {}", stderr(&out));
        let err = stderr(&out);
        assert!(
            err.contains(&format!("s.toml, line {line}")) && err.contains(field),
            "{what}: {err}"
        );
        assert!(!json.exists(), "{what}: a run summary was written");
        let sweep = dir.join("sweep.json");
        let out = merge_sim(&[
            "sweep",
            "--scenario",
            file.to_str().unwrap(),
            "--runs",
            "2",
            "--quiet",
            "--json",
            sweep.to_str().unwrap(),
        ]);
        assert_eq!(out.status.code(), Some(2), "{what}: {}", stderr(&out));
        assert!(
            stderr(&out).contains(&format!("s.toml, line {line}")),
            "{what}"
        );
        assert!(!sweep.exists(), "{what}: a sweep summary was written");
    }
}

/// The run summary `merge_sim run` writes for scenario `text`.
fn summary_json(dir: &std::path::Path, name: &str, text: &str) -> serde_json::Value {
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, text).unwrap();
    let json = dir.join(format!("{name}.json"));
    let out = merge_sim(&[
        "run",
        "--no-rrd",
        "--quiet",
        "--scenario",
        file.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{name}: {}", stderr(&out));
    serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap()
}

#[test]
fn the_old_planner_table_and_the_new_tables_give_bit_identical_runs() {
    let dir = scratch("planner_tables_identical");
    // Values away from the defaults, one in each table (an interaction weight of 8 instead of
    // 12, a risk weight of 30 instead of 39, 18 waypoints instead of 20).
    let old = text_with(
        "[sim.planner]\nwaypoint_count = 18\ninteraction_weight = 8.0\nrisk_weight = 30.0\n",
        None,
    );
    let new = text_with(
        "[sim.planners.pf]\nwaypoint_count = 18\n\n[sim.planners.pf-iso]\ninteraction_weight = 8.0\n\n[sim.planners.pf-sp]\nrisk_weight = 30.0\n",
        None,
    );
    // The same values given to each vehicle in its own table.
    let vehicle = "params = { waypoint_count = 18, interaction_weight = 8.0 }";
    let own = text_with(
        "[sim.planners.pf-sp]\nrisk_weight = 30.0\n",
        Some(&format!("driver = {{ planner = \"pf-iso\", {vehicle} }}")),
    )
    .replace(
        "driver = { planner = \"pf-iso\" }",
        &format!("driver = {{ planner = \"pf-iso\", {vehicle} }}"),
    );
    let a = summary_json(&dir, "old", &old);
    let b = summary_json(&dir, "new", &new);
    let c = summary_json(&dir, "own", &own);
    let default = summary_json(&dir, "default", URGENT);
    // Everything but the wall-clock times (of the run and of the planning cycles).
    let strip = |mut v: serde_json::Value| {
        if let Some(o) = v.as_object_mut() {
            o.remove("wall_time_s");
            if let Some(stats) = o.get_mut("planner_stats").and_then(|s| s.as_object_mut()) {
                stats.remove("p50_plan_us");
                stats.remove("p99_plan_us");
            }
        }
        v
    };
    let (a, b, c, default) = (strip(a), strip(b), strip(c), strip(default));
    assert_eq!(a, b);
    assert_eq!(a["vehicles"], c["vehicles"]);
    assert_eq!(a["events"], c["events"]);
    assert_eq!(a["planner_stats"], c["planner_stats"]);
    // And the values have an effect: the run differs from the defaults'.
    assert_ne!(a["vehicles"], default["vehicles"]);
}

/// A user's planner parameters.
#[derive(Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
struct HoldParams {
    /// The speed it holds (m/s).
    speed_mps: f64,
}

impl PlannerParameters for HoldParams {
    fn validate(&self) -> Result<(), ParamsError> {
        if self.speed_mps > 0.0 && self.speed_mps <= 40.0 {
            Ok(())
        } else {
            Err(ParamsError::at(
                "speed_mps",
                format!("{} m/s is outside (0, 40] m/s", self.speed_mps),
            ))
        }
    }
}

/// Holds its lane's centre at `speed_mps`.
struct Hold {
    speed_mps: f64,
}

impl Behaviour for Hold {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        let v = self.speed_mps;
        Ok(Decision::follow(
            (0..=20)
                .map(|i| PathPoint {
                    x_m: obs.ego.x_m + 3.0 * i as f64,
                    y_m: obs.ego.y_m,
                    speed_mps: v,
                    t_s: obs.time_s + 3.0 * i as f64 / v,
                })
                .collect(),
        ))
    }
}

#[test]
fn a_user_planner_receives_its_table_and_each_vehicle_s_own_values() {
    let seen: Arc<Mutex<Vec<(String, f64)>>> = Arc::default();
    let mut registry = BehaviourRegistry::builtin();
    let log = Arc::clone(&seen);
    registry
        .register_with_params("hold", move |input: &FactoryInput<'_>, p: &HoldParams| {
            log.lock()
                .unwrap()
                .push((input.spec.name.clone(), p.speed_mps));
            Ok(Box::new(Hold {
                speed_mps: p.speed_mps,
            }) as Box<dyn Behaviour>)
        })
        .unwrap();
    let text = text_with(
        "[sim.planners.hold]\nspeed_mps = 14.0\n",
        Some("driver = { planner = \"hold\", params = { speed_mps = 17.0 } }"),
    )
    .replace(
        "driver = { planner = \"pf-iso\" }",
        "driver = { planner = \"hold\" }",
    )
    .replace("duration_s = 25.0", "duration_s = 6.0");
    let scenario = Scenario::from_toml(&text, "s.toml").unwrap();
    scenario.check_planners(&registry).unwrap();
    let finished = run_instance(
        &scenario,
        &InstanceOptions::default(),
        Recorder::disabled(),
        &registry,
        |_| {},
    )
    .unwrap();
    let seen = seen.lock().unwrap().clone();
    assert_eq!(
        seen,
        vec![("ego".to_string(), 17.0), ("obstacle".to_string(), 14.0)]
    );
    let speeds: Vec<f64> = finished
        .summary
        .vehicles
        .iter()
        .map(|v| v.final_speed_mps)
        .collect();
    assert!((speeds[0] - 17.0).abs() < 0.3, "{speeds:?}");
    assert!((speeds[1] - 14.0).abs() < 0.3, "{speeds:?}");

    // A value out of range is refused by `check_planners` at its line, and by the world
    // (naming the field) if a program skips the check.
    let bad = text.replace("speed_mps = 17.0", "speed_mps = 70.0");
    let scenario = Scenario::from_toml(&bad, "s.toml").unwrap();
    let e = scenario.check_planners(&registry).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!(
            "s.toml, line {}: ",
            line_of(&bad, "speed_mps = 70.0")
        )) && e.contains("vehicles[ego].driver.params.speed_mps"),
        "{e}"
    );
    let e = run_instance(
        &scenario,
        &InstanceOptions::default(),
        Recorder::disabled(),
        &registry,
        |_| {},
    )
    .unwrap_err();
    match e {
        RunError::Setup(SimError::InvalidField { field, message }) => {
            assert_eq!(field, "vehicles[ego].driver.params.speed_mps");
            assert!(message.contains("outside (0, 40]"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}
