//! Recordings are byte-identical for the same scenario and seed: whatever the machine's speed,
//! whatever the number of worker threads the world plans on (`rayon`), and whichever directory
//! the file is written to. The decoded file still holds the road, the vehicles, the plots, the
//! events and the default layout.

mod common;

use std::collections::BTreeSet;
use std::io::BufReader;
use std::path::Path;

use mergesim::experiment::{InstanceOptions, run_instance};
use mergesim::scenarios::scenario::Scenario;
use mergesim::sim::recording::{Recorder, RecorderParams};
use mergesim::sim::registry::BehaviourRegistry;
use re_log_encoding::DecoderApp;
use rerun::StoreKind;
use rerun::log::{Chunk, LogMsg};

/// Records 2 s of `urgent_merge` (seed 7) to `path`, planning on `threads` worker threads.
fn record(path: &Path, threads: usize) -> Vec<u8> {
    let mut scenario = Scenario::load("urgent_merge").unwrap();
    scenario.sim.duration_s = 2.0;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let recorder =
            Recorder::new_file_with_params(path, "mergesim", RecorderParams::default()).unwrap();
        let options = InstanceOptions {
            seed: Some(7),
            ..InstanceOptions::default()
        };
        run_instance(
            &scenario,
            &options,
            recorder,
            &BehaviourRegistry::builtin(),
            |_| {},
        )
        .unwrap();
    });
    std::fs::read(path).unwrap()
}

#[test]
fn two_recordings_of_one_run_are_byte_identical_on_any_thread_count() {
    let dir = common::scratch("recording_bytes");
    let one = dir.join("one");
    let two = dir.join("two");
    std::fs::create_dir_all(&one).unwrap();
    std::fs::create_dir_all(&two).unwrap();
    let first = record(&one.join("run.rrd"), 1);
    let second = record(&two.join("run.rrd"), 2);
    assert!(first.len() > 10_000, "{} bytes", first.len());
    assert_eq!(first.len(), second.len(), "the sizes differ");
    let first_difference = first.iter().zip(&second).position(|(a, b)| a != b);
    assert_eq!(first_difference, None, "the files differ from this byte on");
}

#[test]
fn a_deterministic_recording_holds_the_entities_and_the_layout() {
    let dir = common::scratch("recording_bytes_decode");
    let path = dir.join("run.rrd");
    record(&path, 2);
    let file = std::fs::File::open(&path).unwrap();
    let mut entities = BTreeSet::new();
    let mut timelines = BTreeSet::new();
    let mut blueprint_entities = BTreeSet::new();
    let mut activations = 0;
    let mut row_ids = Vec::new();
    for msg in DecoderApp::decode_lazy(BufReader::new(file)) {
        match msg.unwrap() {
            LogMsg::BlueprintActivationCommand(cmd) => {
                assert!(cmd.make_default && !cmd.make_active);
                activations += 1;
            }
            LogMsg::ArrowMsg(store_id, arrow_msg) => {
                let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
                let path = chunk.entity_path().to_string();
                if store_id.kind() == StoreKind::Blueprint {
                    blueprint_entities.insert(path);
                    continue;
                }
                row_ids.extend_from_slice(chunk.row_ids_slice());
                timelines.extend(chunk.timelines().keys().map(|t| t.to_string()));
                entities.insert(path);
            }
            LogMsg::SetStoreInfo(_) => {}
        }
    }
    for expected in [
        "/world/road/edges",
        "/world/vehicles",
        "/world/follow",
        "/world/overview",
        "/world/paths/ego/planned",
        "/legend/field_scale/bar",
        "/plots/speed_mps/ego",
    ] {
        assert!(
            entities.contains(expected),
            "{expected} missing: {entities:?}"
        );
    }
    assert!(entities.iter().any(|e| e.starts_with("/world/fields/")));
    // Only simulated time: no wall-clock `log_time`, no `log_tick`.
    assert_eq!(timelines, BTreeSet::from(["sim_time".to_string()]));
    // Row ids are unique.
    let unique: BTreeSet<_> = row_ids.iter().collect();
    assert_eq!(unique.len(), row_ids.len());
    // The layout: the viewport, the panels, 4 + 5 views and 3 containers.
    assert_eq!(activations, 1);
    for expected in [
        "/viewport",
        "/time_panel",
        "/blueprint_panel",
        "/selection_panel",
    ] {
        assert!(blueprint_entities.contains(expected), "{expected} missing");
    }
    let views = blueprint_entities
        .iter()
        .filter(|e| e.starts_with("/view/") && e.matches('/').count() == 2)
        .count();
    let containers = blueprint_entities
        .iter()
        .filter(|e| e.starts_with("/container/"))
        .count();
    assert_eq!((views, containers), (9, 3), "{blueprint_entities:?}");
}
