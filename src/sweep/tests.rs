//! Tests of the sweep engine with a fake runner.

use super::*;

fn plan(runs: u64, shard: Shard) -> SweepPlan {
    SweepPlan {
        scenario: Scenario::load("urgent_merge").unwrap(),
        planner: Some("pf-iso".into()),
        runs,
        seed: 77,
        shard,
    }
}

/// A fake run whose figures are simple functions of the seed.
fn fake(seed: u64) -> Result<RunMetrics, RunFailure> {
    match seed % 11 {
        0 => {
            return Err(RunFailure::Failed(
                "simulation diverged at t = 3 s: test".into(),
            ));
        }
        1 => panic!("test panic {seed}"),
        _ => {}
    }
    let x = (seed % 1000) as f64 / 1000.0;
    Ok(RunMetrics {
        collisions: u64::from(seed.is_multiple_of(7)),
        near_miss: !seed.is_multiple_of(7) && x < 0.2,
        min_ttc_s: if seed.is_multiple_of(5) {
            None
        } else {
            Some(x * 4.0)
        },
        min_gap_m: Some(x * 3.0),
        tet_s: 0.0,
        peak_yaw_rate_radps: x,
        peak_sideslip_rad: x / 10.0,
        peak_yaw_rad: x / 5.0,
        min_speed_mps: 10.0 + x,
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
    })
}

#[test]
fn aggregate_counts_follow_the_rows_and_failures_are_kept() {
    let outcome = run_sweep_with(
        &plan(60, Shard::WHOLE),
        &SweepOptions {
            threads: Some(2),
            ..SweepOptions::default()
        },
        &|_| {},
        fake,
    )
    .unwrap();
    let s = &outcome.summary;
    assert_eq!(s.runs, 60);
    assert_eq!(
        s.samples.iter().map(|r| r.instance).collect::<Vec<_>>(),
        (0..60).collect::<Vec<_>>()
    );
    let seeds: Vec<u64> = (0..60).map(|i| instance_seed(77, i)).collect();
    assert_eq!(s.samples.iter().map(|r| r.seed).collect::<Vec<_>>(), seeds);
    let diverged = seeds.iter().filter(|s| *s % 11 == 0).count() as u64;
    let panicked = seeds.iter().filter(|s| *s % 11 == 1).count() as u64;
    assert!(
        panicked > 0 && diverged > 0,
        "choose another seed for the test"
    );
    assert_eq!(s.panicked, panicked);
    assert_eq!(s.diverged, diverged + panicked);
    assert_eq!(s.completed, 60 - diverged - panicked);
    let ok: Vec<u64> = seeds.iter().copied().filter(|s| s % 11 > 1).collect();
    assert_eq!(
        s.collisions,
        ok.iter().filter(|s| *s % 7 == 0).count() as u64
    );
    assert_eq!(
        s.collision_rate,
        Some(s.collisions as f64 / s.completed as f64)
    );
    assert_eq!(s.fallbacks, ok.iter().map(|s| s % 2).sum::<u64>());
    // p5 by brute force: the smallest value with at least 5 % of the runs at or below it.
    let ttc: Vec<f64> = ok
        .iter()
        .map(|s| {
            if s % 5 == 0 {
                f64::INFINITY
            } else {
                (s % 1000) as f64 / 1000.0 * 4.0
            }
        })
        .collect();
    let brute = ttc
        .iter()
        .copied()
        .filter(|&c| ttc.iter().filter(|&&v| v <= c).count() as f64 >= 0.05 * ttc.len() as f64)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(s.min_ttc_s_p5, Some(brute));
    let failed = s
        .samples
        .iter()
        .find(|r| r.status == RunStatus::Panicked)
        .unwrap();
    assert!(
        failed
            .error
            .as_deref()
            .unwrap()
            .starts_with("panic: test panic")
    );
    assert!(failed.metrics.is_none());
    assert_eq!(
        outcome.verdict(),
        SweepVerdict::RunsFailed {
            failed: diverged + panicked,
            of: 60
        }
    );
    let all_good = run_sweep_with(
        &plan(5, Shard::WHOLE),
        &SweepOptions::default(),
        &|_| {},
        |_| fake(2),
    )
    .unwrap();
    assert_eq!(all_good.verdict(), SweepVerdict::Complete);
}

#[test]
fn merged_shards_equal_the_unsharded_sweep_whatever_the_threads() {
    let options = SweepOptions {
        threads: Some(1),
        ..SweepOptions::default()
    };
    let mut whole = run_sweep_with(&plan(23, Shard::WHOLE), &options, &|_| {}, fake)
        .unwrap()
        .summary;
    let mut parts = Vec::new();
    for index in [2, 0, 3, 1] {
        let shard = Shard::new(index, 4, "t").unwrap();
        let part = run_sweep_with(
            &plan(23, shard),
            &SweepOptions {
                threads: Some(2),
                ..SweepOptions::default()
            },
            &|_| {},
            fake,
        )
        .unwrap();
        parts.push((format!("shard{index}.json"), part.summary));
    }
    // Through JSON, as merge-results reads them.
    let parts: Vec<(String, SweepSummary)> = parts
        .into_iter()
        .map(|(o, p)| {
            (
                o,
                serde_json::from_str(&serde_json::to_string(&p).unwrap()).unwrap(),
            )
        })
        .collect();
    let mut merged = merge_shards(parts.clone()).unwrap();
    whole.wall_time_s = 0.0;
    merged.wall_time_s = 0.0;
    assert_eq!(
        serde_json::to_string(&whole).unwrap(),
        serde_json::to_string(&merged).unwrap()
    );
    // Missing, duplicated and foreign shards are refused, naming the file.
    let err = merge_shards(parts[..3].to_vec()).unwrap_err().to_string();
    assert!(err.contains("missing shards: 1/4"), "{err}");
    let mut twice = parts.clone();
    twice.push(("again.json".into(), parts[0].1.clone()));
    assert!(
        merge_shards(twice)
            .unwrap_err()
            .to_string()
            .contains("again.json")
    );
    let mut foreign = parts.clone();
    foreign[1].1.seed = 78;
    let err = merge_shards(foreign).unwrap_err().to_string();
    assert!(err.contains("shard0.json") && err.contains("seed"), "{err}");
}

#[test]
fn zero_runs_and_zero_threads_are_refused() {
    let err = run_sweep_with(
        &plan(0, Shard::WHOLE),
        &SweepOptions::default(),
        &|_| {},
        fake,
    )
    .unwrap_err();
    assert!(err.to_string().contains("runs = 0"));
    let err = run_sweep_with(
        &plan(3, Shard::WHOLE),
        &SweepOptions {
            threads: Some(0),
            ..SweepOptions::default()
        },
        &|_| {},
        fake,
    )
    .unwrap_err();
    assert!(err.to_string().contains("threads = 0"));
}

#[test]
fn empty_shard_is_a_valid_part() {
    // 2 runs in 4 shards: shard 0/4 holds nothing.
    let part = run_sweep_with(
        &plan(2, Shard::new(0, 4, "t").unwrap()),
        &SweepOptions::default(),
        &|_| {},
        fake,
    )
    .unwrap()
    .summary;
    assert_eq!((part.runs, part.instances), (0, [0, 0]));
    assert_eq!(part.collision_rate, None);
    assert_eq!(part.collision_rate_ci95, None);
}

#[test]
fn interrupted_then_resumed_sweep_equals_the_uninterrupted_one() {
    let whole = run_sweep_with(
        &plan(40, Shard::WHOLE),
        &SweepOptions::default(),
        &|_| {},
        fake,
    )
    .unwrap();
    assert!(!whole.interrupted && whole.summary.missing_runs == 0);
    // Interrupt after 13 runs have finished (one thread: deterministic count).
    let flag = Arc::new(AtomicBool::new(false));
    let finished = std::sync::Mutex::new(Vec::new());
    let options = SweepOptions {
        threads: Some(1),
        interrupt: Some(flag.clone()),
        ..SweepOptions::default()
    };
    let first = run_sweep_with(
        &plan(40, Shard::WHOLE),
        &options,
        &|run| {
            let mut rows = finished.lock().unwrap();
            rows.push(run.clone());
            if rows.len() == 13 {
                flag.store(true, Ordering::Relaxed);
            }
        },
        fake,
    )
    .unwrap();
    assert!(first.interrupted);
    assert_eq!(first.verdict(), SweepVerdict::Interrupted { missing: 27 });
    assert_eq!(first.new_runs, 13);
    assert_eq!(first.summary.runs, 13);
    assert_eq!(first.summary.missing_runs, 27);
    assert!(
        first.summary.table().contains("INCOMPLETE"),
        "{}",
        first.summary.table()
    );
    // Resume with the rows handed out (through JSON, as the JSONL keeps them).
    let resume: Vec<FinishedRun> = finished
        .into_inner()
        .unwrap()
        .into_iter()
        .map(|run| FinishedRun {
            row: serde_json::from_str(&serde_json::to_string(&run.row).unwrap()).unwrap(),
            wall_time_s: run.wall_time_s,
        })
        .collect();
    let ran_again = std::sync::atomic::AtomicU64::new(0);
    let second = run_sweep_with(
        &plan(40, Shard::WHOLE),
        &SweepOptions {
            threads: Some(2),
            resume: resume.clone(),
            ..SweepOptions::default()
        },
        &|_| {
            ran_again.fetch_add(1, Ordering::Relaxed);
        },
        fake,
    )
    .unwrap();
    assert_eq!(
        ran_again.into_inner(),
        27,
        "finished runs must not run again"
    );
    assert_eq!(second.new_runs, 27);
    let (mut a, mut b) = (whole.summary, second.summary);
    a.wall_time_s = 0.0;
    b.wall_time_s = 0.0;
    assert_eq!(
        serde_json::to_string(&a).unwrap(),
        serde_json::to_string(&b).unwrap()
    );
    // Rows of another sweep (other seed) or duplicated rows are refused before any work.
    let mut foreign = plan(40, Shard::WHOLE);
    foreign.seed = 78;
    let options = SweepOptions {
        resume: resume.clone(),
        ..SweepOptions::default()
    };
    let err = run_sweep_with(&foreign, &options, &|_| panic!("ran"), fake).unwrap_err();
    assert!(err.to_string().contains("not a row of this sweep"), "{err}");
    let mut twice = resume.clone();
    twice.push(resume[0].clone());
    let options = SweepOptions {
        resume: twice,
        ..SweepOptions::default()
    };
    let err =
        run_sweep_with(&plan(40, Shard::WHOLE), &options, &|_| panic!("ran"), fake).unwrap_err();
    assert!(err.to_string().contains("twice"), "{err}");
}

#[test]
fn run_and_thread_counts_are_bounded() {
    let err = run_sweep_with(
        &plan(MAX_RUNS + 1, Shard::WHOLE),
        &SweepOptions::default(),
        &|_| {},
        fake,
    )
    .unwrap_err();
    assert!(err.to_string().contains("1 to 1000000"), "{err}");
    let err = run_sweep_with(
        &plan(3, Shard::WHOLE),
        &SweepOptions {
            threads: Some(MAX_THREADS + 1),
            ..SweepOptions::default()
        },
        &|_| {},
        fake,
    )
    .unwrap_err();
    assert!(err.to_string().contains("threads = 1025"), "{err}");
}

/// The fake run on a CommonRoad road: its figures, with the recorded traffic's.
fn fake_on_commonroad(seed: u64) -> Result<RunMetrics, RunFailure> {
    fake(seed).map(|m| RunMetrics {
        commonroad: Some(CommonRoadFigures {
            recorded_traffic: "replay".into(),
            collisions_caused_by_replay: seed % 3,
            min_gap_to_recorded_m: (!seed.is_multiple_of(4)).then_some(0.5),
            min_ttc_to_recorded_s: None,
            goal_reached: Some(seed.is_multiple_of(2)),
            goal_time_s: seed.is_multiple_of(2).then_some(4.25),
        }),
        ..m
    })
}

#[test]
fn commonroad_figures_are_written_read_back_and_aggregated() {
    let plan = plan(12, Shard::WHOLE);
    let outcome = run_sweep_with(&plan, &SweepOptions::default(), &|_| {}, fake_on_commonroad)
        .unwrap_or_else(|e| panic!("{e}"));
    let s = &outcome.summary;
    let done: Vec<&CommonRoadFigures> = s
        .samples
        .iter()
        .filter_map(|r| r.metrics.as_ref()?.commonroad.as_ref())
        .collect();
    assert!(!done.is_empty());
    assert_eq!(s.recorded_traffic.as_deref(), Some("replay"));
    assert_eq!(
        s.collisions_caused_by_replay,
        Some(done.iter().map(|c| c.collisions_caused_by_replay).sum())
    );
    assert_eq!(
        s.runs_with_collisions_caused_by_replay,
        Some(
            done.iter()
                .filter(|c| c.collisions_caused_by_replay > 0)
                .count() as u64
        )
    );
    assert_eq!(s.runs_with_goal, Some(done.len() as u64));
    assert!(
        s.table()
            .contains("recorded traffic replay: collisions caused by replay")
    );
    for row in &s.samples {
        let text = serde_json::to_string(row).unwrap_or_default();
        let back: RunRow = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}: {text}"));
        assert_eq!(&back, row);
        // A malformed figure is an error naming the instance, never dropped silently.
        if row.metrics.is_some() {
            let bad = text.replace(
                "\"collisions_caused_by_replay\":",
                "\"collisions_caused_by_replay\":\"x\",\"_\":",
            );
            let e = serde_json::from_str::<RunRow>(&bad)
                .err()
                .map(|e| e.to_string());
            assert!(
                e.as_deref()
                    .is_some_and(|e| e.contains(&format!("instance {}", row.instance))),
                "{e:?}"
            );
        }
    }
    // Without a CommonRoad road nothing is added.
    let plain = run_sweep_with(&plan, &SweepOptions::default(), &|_| {}, fake)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(plain.summary.recorded_traffic, None);
    let json = serde_json::to_value(&plain.summary).unwrap_or_default();
    for key in [
        "recorded_traffic",
        "collisions_caused_by_replay",
        "goals_reached",
    ] {
        assert!(json.get(key).is_none(), "{key}");
        assert!(json["samples"][0].get(key).is_none(), "{key}");
    }
}
