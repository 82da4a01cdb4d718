//! The vehicle-model seam from the user's side: `--vehicle-model ks|st|std|rapier` runs the
//! urgent merge with every car moved by that model (named in the summary), an unknown name is
//! refused with exit 2 before any output (from the CLI and from a scenario file, with its line
//! and field), a scenario can mix models per vehicle, a user's own model plugs into the
//! registry, and a run is bitwise repeatable.

mod common;

use std::sync::Arc;

use common::{merge_sim, scratch, stderr};
use mergesim::experiment::{InstanceOptions, run_instance};
use mergesim::scenarios::scenario::Scenario;
use mergesim::sim::recording::Recorder;
use mergesim::sim::registry::BehaviourRegistry;
use mergesim::sim::vehicle_models::VehicleModelInput;
use mergesim::vehicles::{CommonRoadIntegration, CommonRoadModel, CommonRoadVehicle, VehicleModel};

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
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap()
}

#[test]
fn every_builtin_model_runs_the_urgent_merge_and_is_named_in_the_summary() {
    let mut final_speeds = Vec::new();
    for model in ["rapier", "ks", "st", "std"] {
        let summary = run_json(
            &format!("model_{model}"),
            &["--scenario", "urgent_merge", "--vehicle-model", model],
        );
        let named = summary.get("vehicle_model").and_then(|v| v.as_str());
        if model == "rapier" {
            assert_eq!(named, None, "rapier is the default and left out");
        } else {
            assert_eq!(named, Some(model));
        }
        assert_eq!(summary["collisions"], 0, "{model}: {summary}");
        let ego = &summary["vehicles"][0];
        // The ego merged and went on: it drove most of the 25 s at about its 20 m/s.
        let path_m = ego["path_length_m"].as_f64().unwrap();
        assert!(path_m > 400.0, "{model}: path {path_m} m");
        final_speeds.push(ego["final_speed_mps"].as_f64().unwrap());
    }
    // The models differ: the summaries are not copies of one another.
    for pair in final_speeds.windows(2) {
        assert_ne!(pair[0], pair[1], "{final_speeds:?}");
    }
}

#[test]
fn an_unknown_model_is_refused_with_exit_2_before_any_output() {
    let dir = scratch("model_unknown_cli");
    let json = dir.join("out.json");
    let out = merge_sim(&[
        "run",
        "--vehicle-model",
        "bicycle",
        "--no-rrd",
        "--json",
        json.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("unknown vehicle model 'bicycle'; valid: rapier, ks, st, std"),
        "{err}"
    );
    assert!(!json.exists());
    // The help lists the registered models.
    let help = merge_sim(&["run", "--help"]);
    let text = String::from_utf8_lossy(&help.stdout);
    assert!(text.contains("[registered: rapier, ks, st, std]"), "{text}");

    // In a scenario file: the file, the line and the field.
    let text = mergesim::scenarios::builtin::toml_of("urgent_merge")
        .unwrap()
        .replacen("mu = 0.8", "mu = 0.8\nvehicle_model = \"bicycle\"", 1);
    let path = dir.join("bad.toml");
    std::fs::write(&path, &text).unwrap();
    let line = text.lines().position(|l| l.contains("bicycle")).unwrap() + 1;
    let out = merge_sim(&[
        "run",
        "--scenario",
        path.to_str().unwrap(),
        "--no-rrd",
        "--json",
        json.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("{}, line {line}:", path.display())),
        "{err}"
    );
    assert!(err.contains("sim.vehicle_model"), "{err}");
    assert!(!json.exists());
}

#[test]
fn a_scenario_mixes_models_per_vehicle_and_the_cli_overrides_them() {
    let text = mergesim::scenarios::builtin::toml_of("urgent_merge")
        .unwrap()
        .replacen(
            "preset = \"bmw_320i\"",
            "preset = \"bmw_320i\"\nvehicle_model = \"ks\"",
            1,
        );
    let dir = scratch("model_mixed");
    let path = dir.join("mixed.toml");
    std::fs::write(&path, &text).unwrap();
    let mixed = run_json("model_mixed_run", &["--scenario", path.to_str().unwrap()]);
    assert_eq!(mixed["vehicle_model"], "mixed");
    let all_st = run_json(
        "model_mixed_override",
        &[
            "--scenario",
            path.to_str().unwrap(),
            "--vehicle-model",
            "st",
        ],
    );
    assert_eq!(all_st["vehicle_model"], "st");
    let st = run_json("model_mixed_st_only", &["--vehicle-model", "st"]);
    // Everything but the scenario's name and the wall-clock figures.
    let strip = |mut v: serde_json::Value| {
        let o = v.as_object_mut().unwrap();
        o.remove("wall_time_s");
        o.remove("scenario");
        let stats = o["planner_stats"].as_object_mut().unwrap();
        stats.remove("p50_plan_us");
        stats.remove("p99_plan_us");
        v
    };
    assert_eq!(
        strip(all_st),
        strip(st),
        "--vehicle-model st replaces every car's model"
    );
}

#[test]
fn a_users_model_plugs_into_the_registry_and_runs_are_repeatable() {
    let mut registry = BehaviourRegistry::builtin();
    registry
        .register_vehicle_model(
            "ks-again",
            "the built-in ks under another name",
            Arc::new(|input: &mut VehicleModelInput<'_>| {
                let car = CommonRoadVehicle::spawn(
                    input.physics,
                    CommonRoadModel::Ks,
                    input.params,
                    CommonRoadIntegration::default(),
                    input.pose_m,
                    input.speed_mps,
                )?;
                Ok(Box::new(car) as Box<dyn VehicleModel>)
            }),
        )
        .unwrap();
    assert!(
        registry
            .register_vehicle_model(
                "ks",
                "again",
                Arc::new(|_: &mut VehicleModelInput<'_>| unreachable!())
            )
            .is_err()
    );
    let scenario = Scenario::load("urgent_merge")
        .unwrap()
        .with_vehicle_model("ks-again");
    scenario.check_planners(&registry).unwrap();
    assert!(
        scenario
            .check_planners(&BehaviourRegistry::builtin())
            .is_err(),
        "the built-in registry does not know it"
    );
    let run = || {
        run_instance(
            &scenario,
            &InstanceOptions::default(),
            Recorder::disabled(),
            &registry,
            |_| {},
        )
        .unwrap()
        .summary
    };
    let (a, b) = (run(), run());
    assert_eq!(a.vehicle_model.as_deref(), Some("ks-again"));
    // Bitwise: every vehicle's figures, the events and the closest gap.
    assert_eq!(a.vehicles, b.vehicles);
    assert_eq!(a.events, b.events);
    assert_eq!(a.min_gap_m.map(f64::to_bits), b.min_gap_m.map(f64::to_bits));
    // The same model as the built-in ks: the same run.
    let builtin = run_instance(
        &Scenario::load("urgent_merge")
            .unwrap()
            .with_vehicle_model("ks"),
        &InstanceOptions::default(),
        Recorder::disabled(),
        &BehaviourRegistry::builtin(),
        |_| {},
    )
    .unwrap()
    .summary;
    assert_eq!(builtin.vehicles, a.vehicles);
}
