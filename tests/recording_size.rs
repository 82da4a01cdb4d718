//! The recording's size: the default keeps fields and received paths to the first vehicles,
//! and the size estimate that `merge_sim run` warns with is close to what is written.

mod common;

use mergesim::experiment::{InstanceOptions, run_instance};
use mergesim::scenarios::scenario::Scenario;
use mergesim::sim::recording::size_estimate::estimated_bytes;
use mergesim::sim::recording::{Recorder, RecorderParams};
use mergesim::sim::registry::BehaviourRegistry;

/// Records `scenario` with `detail` vehicles in detail; returns (bytes written, estimate).
fn record(scenario: &Scenario, detail: Option<usize>, name: &str) -> (f64, f64) {
    let dir = common::scratch(name);
    let path = dir.join("run.rrd");
    let params = RecorderParams {
        detail_vehicles: detail,
        ..RecorderParams::default()
    };
    let recorder = Recorder::new_file_with_params(&path, "mergesim-test", params).unwrap();
    run_instance(
        scenario,
        &InstanceOptions::default(),
        recorder,
        &BehaviourRegistry::builtin(),
        |_| {},
    )
    .unwrap();
    let written = std::fs::metadata(&path).unwrap().len() as f64;
    let estimate = estimated_bytes(&scenario.sim, &scenario.vehicles, detail);
    (written, estimate)
}

#[test]
fn detail_is_limited_by_default_and_the_estimate_is_close() {
    let mut scenario = Scenario::load("dense_merge").unwrap();
    scenario.sim.duration_s = 10.0;
    let (all, all_estimate) = record(&scenario, None, "size_all");
    let (two, two_estimate) = record(&scenario, Some(2), "size_two");
    // Fields and received paths of 4 of 6 vehicles fewer: much smaller (mostly the received
    // paths: a field is a ~1.7 kB image since the 2D recording, 62 kB as a 3D mesh before).
    assert!(two < 0.7 * all, "{two} vs {all}");
    for (written, estimate) in [(all, all_estimate), (two, two_estimate)] {
        let ratio = estimate / written;
        assert!(
            (0.75..1.33).contains(&ratio),
            "estimate {estimate:.0} B for {written:.0} B written"
        );
    }
    // The 72 s, 50-vehicle platoon by default: below 200 MB by the estimate.
    let platoon = Scenario::load("platoon_merge_50").unwrap();
    let default_detail = RecorderParams::default().detail_vehicles;
    let estimate = estimated_bytes(&platoon.sim, &platoon.vehicles, default_detail);
    assert!(estimate < 200e6, "{estimate}");
    // In full detail its received paths (50 × 49 per instant) make it ~500 MB.
    assert!(estimated_bytes(&platoon.sim, &platoon.vehicles, None) > 400e6);
}
