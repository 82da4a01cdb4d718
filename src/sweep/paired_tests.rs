//! Tests of multi-planner sweeps with a fake runner: rows, pairing, resumption, shards, Parquet.

use std::collections::BTreeMap;

use super::*;

const PLANNERS: [&str; 2] = ["pf-cs", "pf-iso"];

fn plan(runs: u64, shard: Shard) -> PairedSweepPlan {
    PairedSweepPlan {
        scenario: Scenario::load("urgent_merge").unwrap(),
        planners: PLANNERS.iter().map(|p| p.to_string()).collect(),
        runs,
        seed: 91,
        shard,
    }
}

fn unit(seed: u64, salt: u64) -> f64 {
    (SplitMix64::derive(seed, salt) % 10_000) as f64 / 10_000.0
}

fn vehicle(name: &str, seed: u64, salt: u64) -> VehicleRow {
    let x = unit(seed, salt);
    VehicleRow {
        name: name.into(),
        collided: false,
        max_abs_sideslip_rad: x / 100.0,
        max_abs_yaw_rad: x / 10.0,
        max_abs_yaw_rate_radps: x / 20.0,
        min_speed_mps: 10.0 + 5.0 * x,
        t_min_speed_s: 3.0,
        max_speed_mps: 20.0,
        final_speed_mps: 19.0,
        path_length_m: 400.0 + x,
        yaw_rate_sign_changes: seed % 3,
        integral_abs_yaw_rate_rad: x,
        peak_abs_accel_long_mps2: x,
        rms_accel_long_mps2: x / 2.0,
        peak_abs_accel_lat_mps2: x,
        rms_accel_lat_mps2: x / 3.0,
        peak_abs_jerk_long_mps3: x,
        peak_abs_jerk_lat_mps3: x,
        rms_jerk_long_mps3: x,
        rms_jerk_lat_mps3: x,
        slowing_onset_s: (x > 0.3).then_some(2.0 + x),
        merge_zone_rms_yaw_rate_radps: (x > 0.1).then_some(x / 50.0),
        outside_merge_zone_rms_yaw_rate_radps: Some(x / 70.0),
        max_abs_lane_offset_m: Some(x),
        divider_crossing_t_s: (x > 0.5).then_some(10.0 + x),
        divider_crossing_x_m: (x > 0.5).then_some(200.0 + x),
        divider_crossings: Some(u64::from(x > 0.5)),
    }
}

/// A fake run: figures are functions of (seed, planner) that differ between the planners of an
/// instance and between instances, so a wrong pairing changes the paired statistics.
fn fake(request: &RunRequest) -> Result<RunFigures, RunFailure> {
    let seed = request.seed;
    let salt = match request.planner.as_deref() {
        Some("pf-iso") => 7,
        _ => 3,
    };
    if seed.is_multiple_of(13) && salt == 7 {
        return Err(RunFailure::Failed("diverged: test".into()));
    }
    let x = unit(seed, salt);
    let shared = unit(seed, 1);
    Ok(RunFigures {
        metrics: RunMetrics {
            collisions: u64::from(x < 0.15),
            near_miss: (0.15..0.3).contains(&x),
            min_ttc_s: (x > 0.4).then_some(shared * 3.0 + x),
            min_gap_m: Some(shared + x),
            tet_s: 0.0,
            peak_yaw_rate_radps: x / 20.0,
            peak_sideslip_rad: x / 100.0,
            peak_yaw_rad: x / 10.0,
            min_speed_mps: 10.0 + 5.0 * shared + x,
            yaw_rate_sign_changes: seed % 3,
            fallbacks: seed % 2,
            degraded_plans: 0,
            plans: 10,
            shield_interventions: 0,
            throughput_vph: None,
            merging_vehicles: 0,
            merged_before_lane_end: 0,
            mean_delay_s: None,
            commonroad: None,
        },
        vehicles: vec![
            vehicle("ego", seed, salt),
            vehicle("obstacle", seed, salt + 100),
        ],
    })
}

fn options(threads: usize) -> SweepOptions {
    SweepOptions {
        threads: Some(threads),
        ..SweepOptions::default()
    }
}

fn through_json<T: serde::Serialize + serde::de::DeserializeOwned>(value: &T) -> T {
    serde_json::from_str(&serde_json::to_string(value).unwrap()).unwrap()
}

fn without_wall_time(report: &SweepReport) -> serde_json::Value {
    let mut value: serde_json::Value =
        serde_json::from_str(&report.to_json_pretty().unwrap()).unwrap();
    value["wall_time_s"] = serde_json::Value::Null;
    if let Some(parts) = value["per_planner"].as_array_mut() {
        for part in parts {
            part["wall_time_s"] = serde_json::Value::Null;
        }
    }
    value
}

#[test]
fn every_instance_runs_with_every_planner_on_the_same_seed_and_drawn_values() {
    let outcome =
        run_paired_sweep_with(&plan(9, Shard::WHOLE), &options(2), &|_| {}, fake).unwrap();
    let report = outcome.report();
    let rows = report.rows();
    assert_eq!(rows.len(), 18);
    let keys: Vec<(u64, &str)> = rows
        .iter()
        .map(|r| (r.instance, r.planner.as_str()))
        .collect();
    let expected: Vec<(u64, &str)> = (0..9).flat_map(|i| [(i, "pf-cs"), (i, "pf-iso")]).collect();
    assert_eq!(keys, expected);
    let scenario = Scenario::load("urgent_merge").unwrap();
    for pair in rows.chunks(2) {
        let (a, b) = (pair[0], pair[1]);
        assert_eq!(a.seed, instance_seed(91, a.instance));
        assert_eq!((a.seed, &a.drawn), (b.seed, &b.drawn));
        // The drawn values are what the scenario draws for that seed, by name.
        assert_eq!(a.drawn, drawn_values(&scenario, a.seed));
        let instance = scenario.instantiate(a.seed);
        assert_eq!(a.drawn["sim.mu"], instance.sim.mu);
        assert_eq!(
            a.drawn["vehicles.obstacle.x_m"], instance.vehicles[1].x_m,
            "{:?}",
            a.drawn
        );
        assert_eq!(
            a.drawn["vehicles.ego.speed_mps"],
            instance.vehicles[0].speed_mps
        );
        // urgent_merge randomises mu, both cruise speeds and the obstacle's x only.
        assert!(!a.drawn.contains_key("vehicles.ego.x_m"));
        assert_eq!(a.drawn.len(), 6, "{:?}", a.drawn);
    }
    assert_ne!(rows[0].drawn, rows[2].drawn, "instances must differ");
    // A failed run keeps its drawn values and has no vehicles.
    let failed = rows.iter().find(|r| r.status == RunStatus::Diverged);
    if let Some(failed) = failed {
        assert!(failed.vehicles.is_empty() && !failed.drawn.is_empty());
    }
    // Per-planner aggregates hold only their planner's rows.
    let SweepReport::Paired(paired) = &report else {
        panic!("two planners give a paired report")
    };
    assert_eq!(paired.planners, ["pf-cs", "pf-iso"]);
    for summary in &paired.per_planner {
        assert!(summary.samples.iter().all(|r| r.planner == summary.planner));
        assert_eq!(summary.runs, 9);
    }
    // The same rows whatever the thread count.
    let one = run_paired_sweep_with(&plan(9, Shard::WHOLE), &options(1), &|_| {}, fake).unwrap();
    assert_eq!(without_wall_time(&one.report()), without_wall_time(&report));
}

/// The paired difference computed independently: instance by instance, looked up by instance.
fn by_hand(
    summaries: &[SweepSummary],
    value: impl Fn(&RunRow) -> Option<f64>,
) -> (f64, f64, u64, u64, u64) {
    let baseline: BTreeMap<u64, &RunRow> = summaries[0]
        .samples
        .iter()
        .filter(|r| r.metrics.is_some())
        .map(|r| (r.instance, r))
        .collect();
    let mut differences = Vec::new();
    let (mut lower, mut higher, mut tied) = (0, 0, 0);
    for row in summaries[1].samples.iter().filter(|r| r.metrics.is_some()) {
        let Some(base) = baseline.get(&row.instance) else {
            continue;
        };
        let (a, b) = (value(row).unwrap(), value(base).unwrap());
        differences.push(a - b);
        if a < b {
            lower += 1;
        } else if a > b {
            higher += 1;
        } else {
            tied += 1;
        }
    }
    let n = differences.len() as f64;
    let mean = differences.iter().sum::<f64>() / n;
    let variance = differences.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (variance / n).sqrt(), lower, higher, tied)
}

#[test]
fn paired_differences_are_the_differences_of_the_rows_of_each_instance() {
    let outcome =
        run_paired_sweep_with(&plan(40, Shard::WHOLE), &options(2), &|_| {}, fake).unwrap();
    let summaries = outcome.summaries.clone();
    let failed = summaries[1].diverged;
    assert!(
        failed > 0,
        "choose another seed: the test wants a failed run"
    );
    let differences = paired::paired_differences(&summaries);
    let find = |metric: &str, vehicle: Option<&str>| {
        differences
            .iter()
            .find(|d| d.metric == metric && d.vehicle.as_deref() == vehicle)
            .unwrap()
            .clone()
    };
    let gap = find("min_gap_m", None);
    let (mean, se, lower, higher, tied) =
        by_hand(&summaries, |r| r.metrics.as_ref().and_then(|m| m.min_gap_m));
    assert_eq!(gap.compared, 40 - failed);
    assert_eq!(gap.pairs, 40 - failed);
    assert!((gap.mean_difference.unwrap() - mean).abs() < 1e-12);
    assert!((gap.standard_error.unwrap() - se).abs() < 1e-12);
    // Higher gap is better.
    assert_eq!((gap.better, gap.worse), (Some(higher), Some(lower)));
    assert_eq!((gap.lower, gap.higher, gap.tied), (lower, higher, tied));
    assert!(lower > 0 && higher > 0);
    let speed = find("min_speed_mps", Some("obstacle"));
    let (mean, se, lower, higher, _) = by_hand(&summaries, |r| {
        r.vehicles
            .iter()
            .find(|v| v.name == "obstacle")
            .map(|v| v.min_speed_mps)
    });
    assert!((speed.mean_difference.unwrap() - mean).abs() < 1e-12);
    assert!((speed.standard_error.unwrap() - se).abs() < 1e-12);
    assert_eq!((speed.better, speed.worse), (Some(higher), Some(lower)));
    let collisions = find("collisions", None);
    let (_, _, lower, higher, tied) = by_hand(&summaries, |r| {
        r.metrics.as_ref().map(|m| m.collisions as f64)
    });
    assert_eq!(
        (collisions.better, collisions.worse, collisions.tied),
        (Some(lower), Some(higher), tied)
    );
    // The pairing is by instance, not by position: the planner's rows in another order give
    // the same differences (a positional pairing would not).
    let mut shuffled = summaries.clone();
    shuffled[1].samples.reverse();
    assert_eq!(paired::paired_differences(&shuffled), differences);
    // And a wrong pairing (instances shifted by one) does give different figures, so the
    // check above can fail.
    let mut shifted = summaries.clone();
    let count = shifted[1].samples.len() as u64;
    for row in &mut shifted[1].samples {
        row.instance = (row.instance + 1) % count;
    }
    assert_ne!(paired::paired_differences(&shifted), differences);
    // Undirected figures report lower / higher only.
    let onset = find("slowing_onset_s", Some("ego"));
    assert_eq!((onset.better, onset.worse), (None, None));
    assert_eq!(onset.lower + onset.higher + onset.tied, onset.compared);
}

#[test]
fn an_interrupted_then_resumed_paired_sweep_and_merged_shards_equal_the_whole() {
    let whole = run_paired_sweep_with(&plan(11, Shard::WHOLE), &options(2), &|_| {}, fake)
        .unwrap()
        .report();
    // Interrupted after 9 of the 22 runs (one thread: a deterministic count).
    let flag = Arc::new(AtomicBool::new(false));
    let finished = std::sync::Mutex::new(Vec::new());
    let first = run_paired_sweep_with(
        &plan(11, Shard::WHOLE),
        &SweepOptions {
            threads: Some(1),
            interrupt: Some(flag.clone()),
            ..SweepOptions::default()
        },
        &|run| {
            let mut rows = finished.lock().unwrap();
            rows.push(run.clone());
            if rows.len() == 9 {
                flag.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        },
        fake,
    )
    .unwrap();
    assert_eq!(first.verdict(), SweepVerdict::Interrupted { missing: 13 });
    let SweepReport::Paired(partial) = first.report() else {
        panic!("paired")
    };
    assert_eq!(partial.missing_runs, 13);
    // Resume from the rows as the JSONL keeps them (through JSON).
    let resume: Vec<FinishedRun> = finished
        .into_inner()
        .unwrap()
        .into_iter()
        .map(|run| FinishedRun {
            row: through_json(&run.row),
            wall_time_s: run.wall_time_s,
        })
        .collect();
    let ran_again = std::sync::atomic::AtomicU64::new(0);
    let second = run_paired_sweep_with(
        &plan(11, Shard::WHOLE),
        &SweepOptions {
            threads: Some(2),
            resume: resume.clone(),
            ..SweepOptions::default()
        },
        &|_| {
            ran_again.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        },
        fake,
    )
    .unwrap();
    assert_eq!(ran_again.into_inner(), 13);
    assert_eq!(
        without_wall_time(&second.report()),
        without_wall_time(&whole)
    );
    // Shards (through their JSON files), merged in any order, equal the whole sweep.
    let mut parts = Vec::new();
    for index in [2, 0, 1] {
        let part = run_paired_sweep_with(
            &plan(11, Shard::new(index, 3, "t").unwrap()),
            &options(1),
            &|_| {},
            fake,
        )
        .unwrap()
        .report();
        let text = part.to_json_pretty().unwrap();
        parts.push((
            format!("shard{index}.json"),
            SweepReport::from_json(&text).unwrap(),
        ));
    }
    let merged = merge_reports(parts.clone()).unwrap();
    assert_eq!(without_wall_time(&merged), without_wall_time(&whole));
    // A shard of a sweep with other planners is refused, naming its file.
    let mut other = plan(11, Shard::new(1, 3, "t").unwrap());
    other.planners = vec!["pf-cs".into(), "pf-sp".into()];
    let foreign = run_paired_sweep_with(&other, &options(1), &|_| {}, fake)
        .unwrap()
        .report();
    let mut mixed = parts.clone();
    mixed[2] = ("foreign.json".into(), foreign);
    let err = merge_reports(mixed).unwrap_err().to_string();
    assert!(
        err.contains("foreign.json") && err.contains("planners"),
        "{err}"
    );
    // Resumed rows of a planner the sweep does not run, or twice, are refused before any work.
    let mut wrong = resume.clone();
    wrong[0].row.planner = "pf-sp".into();
    let err = run_paired_sweep_with(
        &plan(11, Shard::WHOLE),
        &SweepOptions {
            resume: wrong,
            ..SweepOptions::default()
        },
        &|_| panic!("ran"),
        fake,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("pf-sp") && err.contains("not a row"), "{err}");
    let mut twice = resume.clone();
    twice.push(resume[0].clone());
    let err = run_paired_sweep_with(
        &plan(11, Shard::WHOLE),
        &SweepOptions {
            resume: twice,
            ..SweepOptions::default()
        },
        &|_| panic!("ran"),
        fake,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("twice"), "{err}");
}

#[test]
fn a_planner_listed_twice_is_refused() {
    let mut twice = plan(3, Shard::WHOLE);
    twice.planners = vec!["pf-iso".into(), "pf-iso".into()];
    let err = run_paired_sweep_with(&twice, &SweepOptions::default(), &|_| panic!("ran"), fake)
        .unwrap_err()
        .to_string();
    assert!(err.contains("pf-iso is listed twice"), "{err}");
}

#[test]
fn an_unregistered_planner_is_refused_before_any_run_and_a_registered_one_runs() {
    let mut unknown = plan(3, Shard::WHOLE);
    unknown.planners = vec!["pf-cs".into(), "mine".into()];
    let err = run_paired_sweep_with(&unknown, &SweepOptions::default(), &|_| panic!("ran"), fake)
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("unknown planner 'mine'; valid: ") && err.contains("pf-iso"),
        "{err}"
    );
    // The same name, registered, runs (the registry travels in the options).
    let mut registry = sim::registry::BehaviourRegistry::builtin();
    let pf_cs_again: sim::registry::BehaviourFactory =
        std::sync::Arc::new(|input: &sim::registry::FactoryInput<'_>| {
            sim::registry::BehaviourRegistry::builtin().create("pf-cs", input)
        });
    registry.register("mine", pf_cs_again).unwrap();
    let options = SweepOptions {
        registry: std::sync::Arc::new(registry),
        threads: Some(1),
        ..SweepOptions::default()
    };
    let outcome = run_paired_sweep_with(&unknown, &options, &|_| {}, fake).unwrap();
    assert_eq!(outcome.summaries.len(), 2);
    assert_eq!(outcome.summaries[1].samples[0].planner, "mine");
}

#[test]
fn rows_of_an_older_mergesim_or_with_malformed_figures_are_refused_naming_the_instance() {
    let outcome =
        run_paired_sweep_with(&plan(2, Shard::WHOLE), &options(1), &|_| {}, fake).unwrap();
    let row = outcome.summaries[0].samples[1].clone();
    let mut value = serde_json::to_value(&row).unwrap();
    assert_eq!(
        serde_json::from_value::<RunRow>(value.clone()).unwrap(),
        row
    );
    value.as_object_mut().unwrap().remove("drawn");
    let err = serde_json::from_value::<RunRow>(value.clone())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("instance 1") && err.contains("older mergesim"),
        "{err}"
    );
    let mut value = serde_json::to_value(&row).unwrap();
    value["vehicles"][0]["min_speed_mps"] = serde_json::Value::String("fast".into());
    assert!(serde_json::from_value::<RunRow>(value).is_err());
    let mut value = serde_json::to_value(&row).unwrap();
    value["min_gap_m"] = serde_json::Value::String("oops".into());
    let err = serde_json::from_value::<RunRow>(value)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("instance 1") && err.contains("malformed"),
        "{err}"
    );
}

#[test]
fn the_parquet_file_holds_exactly_the_rows_of_the_jsonl() {
    use ::parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
    use arrow_array::{Array, BooleanArray, Float64Array, StringArray, UInt64Array};
    let outcome =
        run_paired_sweep_with(&plan(14, Shard::WHOLE), &options(2), &|_| {}, fake).unwrap();
    let report = outcome.report();
    let dir = std::env::temp_dir().join(format!("mergesim_parquet_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("rows.parquet");
    parquet::write_parquet(&path, &report).unwrap();
    // Nothing else left in the folder (no temporary file).
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    let file = std::fs::File::open(&path).unwrap();
    let builder = ParquetRecordBatchReaderBuilder::try_new(file).unwrap();
    let metadata = builder.schema().metadata().clone();
    let batches: Vec<_> = builder.build().unwrap().map(Result::unwrap).collect();
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(batches.len(), 1);
    let batch = &batches[0];
    let rows = report.rows();
    assert_eq!(batch.num_rows(), rows.len());
    assert!(rows.iter().any(|r| r.status != RunStatus::Completed));
    let identity: serde_json::Value =
        serde_json::from_str(&metadata[parquet::METADATA_KEY]).unwrap();
    assert_eq!(identity["planners"], serde_json::json!(["pf-cs", "pf-iso"]));
    assert_eq!(identity["sweep_seed"], "0x000000000000005b");
    // Every column against the JSON of the rows, looked up by the column's name.
    let json: Vec<serde_json::Value> = rows
        .iter()
        .map(|r| serde_json::to_value(r).unwrap())
        .collect();
    let schema = batch.schema();
    let mut vehicle_columns = 0;
    for (index, field) in schema.fields().iter().enumerate() {
        let name = field.name();
        let column = batch.column(index);
        for (i, row) in json.iter().enumerate() {
            let expected = if let Some(key) = name.strip_prefix("drawn.") {
                row["drawn"][key].clone()
            } else if let Some((vehicle, figure)) = name
                .split_once('.')
                .filter(|(v, _)| *v == "ego" || *v == "obstacle")
            {
                vehicle_columns += 1;
                row["vehicles"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .find(|v| v["name"] == vehicle)
                    .map(|v| v[figure].clone())
                    .unwrap_or(serde_json::Value::Null)
            } else if name == "sweep_seed" {
                serde_json::json!(91)
            } else if name == "seed" {
                serde_json::json!(
                    crate::exact_seed::parse_seed(row["seed"].as_str().unwrap()).unwrap()
                )
            } else {
                row.get(name.as_str())
                    .cloned()
                    .unwrap_or(serde_json::Value::Null)
            };
            let found = if column.is_null(i) {
                serde_json::Value::Null
            } else if let Some(a) = column.as_any().downcast_ref::<UInt64Array>() {
                serde_json::json!(a.value(i))
            } else if let Some(a) = column.as_any().downcast_ref::<Float64Array>() {
                serde_json::json!(a.value(i))
            } else if let Some(a) = column.as_any().downcast_ref::<BooleanArray>() {
                serde_json::json!(a.value(i))
            } else if let Some(a) = column.as_any().downcast_ref::<StringArray>() {
                serde_json::json!(a.value(i))
            } else {
                panic!("{name}: unexpected type {:?}", field.data_type())
            };
            assert_eq!(found, expected, "column {name}, row {i}");
        }
    }
    assert_eq!(vehicle_columns, 2 * 28 * rows.len());
    // Every run-level figure and every vehicle figure of the JSON is a column.
    for key in json[0].as_object().unwrap().keys() {
        if !["drawn", "vehicles"].contains(&key.as_str()) {
            assert!(schema.field_with_name(key).is_ok(), "no column {key}");
        }
    }
    for key in json[0]["vehicles"][0].as_object().unwrap().keys() {
        if key != "name" {
            assert!(
                schema.field_with_name(&format!("ego.{key}")).is_ok(),
                "no column ego.{key}"
            );
        }
    }
    // The same bytes whatever the thread count.
    let again = run_paired_sweep_with(&plan(14, Shard::WHOLE), &options(1), &|_| {}, fake)
        .unwrap()
        .report();
    let meta = BTreeMap::new();
    assert_eq!(
        parquet::parquet_bytes(&again.rows(), 91, &meta).unwrap(),
        parquet::parquet_bytes(&report.rows(), 91, &meta).unwrap()
    );
}

#[test]
fn an_unrandomised_scenario_is_warned_about() {
    let mut scenario = Scenario::load("urgent_merge").unwrap();
    assert_eq!(unrandomised_warning(&scenario), None);
    scenario.randomise = Default::default();
    let warning = unrandomised_warning(&scenario).unwrap();
    assert!(warning.contains("every instance is the same"), "{warning}");
    assert!(drawn_values(&scenario, 5).is_empty());
}
