//! The `[traffic]` scenarios from the command line: the built-ins `on_ramp_flow` and
//! `merge_flow` run (briefly), `scenario expand` writes the instance a seed draws, and bad
//! `[traffic]` input exits 2 naming the file, the line and the field.

mod common;

use common::{merge_sim, run_summary, scratch, stderr};

/// A built-in scenario's file text.
fn builtin_text(name: &str) -> String {
    std::fs::read_to_string(format!(
        "{}/scenarios/builtin/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

fn vehicle_names(summary: &serde_json::Value) -> Vec<String> {
    summary["vehicles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["id"].as_str().unwrap().to_string())
        .collect()
}

/// `merge_sim scenario expand ARGS…`: its stdout, asserting success.
fn expand(args: &[&str]) -> String {
    let mut all = vec!["scenario", "expand"];
    all.extend_from_slice(args);
    let out = merge_sim(&all);
    assert!(out.status.success(), "{}", stderr(&out));
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn the_flow_built_ins_run_nominally_and_per_seed() {
    let dir = scratch("traffic_builtins");
    for (name, nominal_count) in [("merge_flow", 8), ("on_ramp_flow", 15)] {
        let json = dir.join(format!("{name}.json"));
        let summary = run_summary(&json, &["--scenario", name, "--duration", "2"]);
        assert_eq!(summary["scenario"], name);
        assert_eq!(vehicle_names(&summary).len(), nominal_count, "{summary}");
        // A seeded run has the vehicles `scenario expand --seed` lists for that seed.
        let seeded = run_summary(
            &json,
            &["--scenario", name, "--duration", "2", "--seed", "5"],
        );
        let text = expand(&[name, "--seed", "5"]);
        let listed = text.matches("[[vehicles]]").count();
        assert_eq!(vehicle_names(&seeded).len(), listed, "{text}");
        // The expanded text is a scenario of its own: every vehicle written out, no [traffic].
        assert!(!text.contains("[traffic"), "{text}");
        let file = dir.join(format!("{name}_seed5.toml"));
        std::fs::write(&file, &text).unwrap();
        let again = run_summary(
            &json,
            &["--scenario", file.to_str().unwrap(), "--duration", "2"],
        );
        assert_eq!(vehicle_names(&again), vehicle_names(&seeded));
    }
}

#[test]
fn a_human_driver_stream_runs() {
    // The drivers a study swaps in: IDM + MOBIL, not connected, on every generated vehicle.
    let dir = scratch("traffic_idm_mobil");
    let text = builtin_text("merge_flow").replace(
        "driver = { planner = \"pf-iso\" }",
        "driver = \"idm-mobil\"\nconnected = false",
    );
    let file = dir.join("merge_flow_mobil.toml");
    std::fs::write(&file, &text).unwrap();
    let expanded = expand(&[file.to_str().unwrap()]);
    assert_eq!(
        expanded.matches("driver = \"idm-mobil\"").count(),
        8,
        "{expanded}"
    );
    let summary = run_summary(
        &dir.join("out.json"),
        &["--scenario", file.to_str().unwrap(), "--duration", "2"],
    );
    assert_eq!(vehicle_names(&summary).len(), 8);
}

#[test]
fn bad_traffic_input_exits_2_naming_the_file_line_and_field() {
    let dir = scratch("traffic_bad_input");
    let text = builtin_text("on_ramp_flow");
    for (from, to, field, at) in [
        (
            "flow_vph = { uniform = [300.0, 600.0] }",
            "flow_vph = { uniform = [600.0, 300.0] }",
            "traffic.ramp.flow_vph",
            "flow_vph = { uniform = [600.0",
        ),
        // 0.2 s headways over 600 m at 25 m/s: up to 121 cars per main lane, 242 in all.
        (
            "min_headway_s = 1.0",
            "min_headway_s = 0.2",
            "traffic.main.min_headway_s",
            "min_headway_s = 0.2",
        ),
        // Lane 7 does not exist on the on-ramp road.
        (
            "lanes = [4]",
            "lanes = [7]",
            "traffic.ramp",
            "[traffic.ramp]",
        ),
        ("rear_x_m = 5.0", "rear_m = 5.0", "rear_m", "rear_m"),
    ] {
        let bad = text.replacen(from, to, 1);
        assert_ne!(bad, text, "{from}");
        let line = bad.lines().position(|l| l.starts_with(at)).unwrap() + 1;
        let file = dir.join("bad_flow.toml");
        std::fs::write(&file, &bad).unwrap();
        let json = dir.join("out.json");
        let out = merge_sim(&[
            "run",
            "--scenario",
            file.to_str().unwrap(),
            "--no-rrd",
            "--json",
            json.to_str().unwrap(),
        ]);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains("bad_flow.toml"), "{err}");
        assert!(err.contains(field), "{field}: {err}");
        assert!(err.contains(&format!("line {line}")), "line {line}: {err}");
        assert!(!json.exists());
        // `scenario expand` refuses it alike.
        let out = merge_sim(&["scenario", "expand", file.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    }
}

#[test]
fn a_study_swaps_a_streams_driver_with_a_factor() {
    // The dense-merging study's drivers: PF-ISO (the built-in's) against IDM + MOBIL human
    // drivers, as a factor on the stream; every generated vehicle of the cell gets it.
    let text = r#"name = "drivers"
scenario = "merge_flow"
planners = ["pf-sp", "pf-iso"]
reference = "pf-sp"
[instances]
n = 2
seed = 7
[factors]
"traffic.approach.driver" = ["idm-mobil", { planner = "pf-iso" }]
[endpoints]
primary = { figure = "min_gap_m", threshold = "0.5 m" }
"#;
    let plan = mergesim::study::plan::StudyPlan::from_text(text, std::path::Path::new("p.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(plan.cells.len(), 2);
    let drivers: Vec<Vec<sim::config::Driver>> = plan
        .cells
        .iter()
        .map(|(_, s)| {
            s.instantiate(3)
                .vehicles
                .iter()
                .map(|v| v.driver.clone())
                .collect()
        })
        .collect();
    assert!(!drivers[0].is_empty());
    assert!(
        drivers[0]
            .iter()
            .all(|d| *d == sim::config::Driver::IdmMobil)
    );
    assert!(
        drivers[1]
            .iter()
            .all(|d| *d == sim::config::Driver::planner("pf-iso"))
    );
}
