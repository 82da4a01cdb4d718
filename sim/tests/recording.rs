//! The recorder writes a decodable `.rrd` under its final name only on `finish`, leaves nothing
//! behind when dropped, and does nothing when disabled.

use std::collections::BTreeSet;
use std::io::BufReader;
use std::path::PathBuf;

use mergesim_types::{MergeRoad, PathPoint, SharedLocalPath, TimedWaypoint, VehicleShape};
use re_log_encoding::DecoderApp;
use rerun::StoreKind;
use rerun::log::{Chunk, LogMsg};
use sim::recording::{EventLevel, Recorder, RecordingError, SIM_TIMELINE};
use sim::safety::BodyState;

fn out_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mergesim_rec_{test}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn body(id: u32, x_m: f64, y_m: f64, yaw_rad: f64) -> BodyState {
    BodyState {
        id,
        x_m,
        y_m,
        yaw_rad,
        vx_mps: 20.0,
        vy_mps: 0.0,
        yaw_rate_radps: 0.0,
        length_m: 4.508,
        width_m: 1.61,
        height_m: 1.4,
    }
}

/// Logs a short synthetic run: everything the world loop would log.
fn log_run(rec: &mut Recorder) -> Result<(), RecordingError> {
    let road = MergeRoad::default();
    rec.log_road(&road.lane_road().map_err(|e| RecordingError::InvalidInput {
        call: "lane_road",
        reason: e.to_string(),
    })?)?;
    let names = vec!["ego".to_string(), "obstacle".to_string()];
    for k in 0..20 {
        let t = 0.05 * k as f64;
        rec.set_time(t)?;
        let bodies = [
            body(0, 20.0 * t, 1.75, 0.02),
            body(1, 5.0 + 15.0 * t, 5.25, 0.0),
        ];
        rec.log_vehicles(&bodies, &names)?;
        let path: Vec<PathPoint> = (0..10)
            .map(|i| PathPoint {
                x_m: 20.0 * t + 5.0 * i as f64,
                y_m: 1.75 + 0.1 * i as f64,
                speed_mps: 20.0,
                t_s: t + 0.25 * i as f64,
            })
            .collect();
        rec.log_planned_path("ego", &path)?;
        let slp = SharedLocalPath {
            vehicle_id: 1,
            stamp_s: t,
            shape: VehicleShape::default(),
            speed_mps: 15.0,
            waypoints: (0..10)
                .map(|i| TimedWaypoint {
                    t_s: t + 0.1 * i as f64,
                    x_m: 5.0 + 15.0 * t + 1.5 * i as f64,
                    y_m: 5.25,
                })
                .collect(),
        };
        rec.log_received_paths("ego", &[slp])?;
        rec.log_scalars(
            "ego",
            &[
                ("sideslip_rad", 0.01 * t),
                ("speed_mps", 20.0),
                ("planned_speed_mps", f64::NAN),
            ],
        )?;
    }
    let (w, h) = (40usize, 14usize);
    let values: Vec<f64> = (0..w * h)
        .map(|i| (i % w) as f64 + 0.5 * (i / w) as f64)
        .collect();
    rec.log_field("ego", 0.0, 0.0, 0.5, w, h, &values)?;
    rec.log_event("collision ego / obstacle at t = 0.95 s", EventLevel::Error)?;
    Ok(())
}

#[test]
fn recording_is_written_on_finish_and_decodes() {
    let dir = out_dir("finish");
    let path = dir.join("run.rrd");
    let mut rec = Recorder::new_file(&path, "mergesim_test").unwrap();
    let tmp = rec.tmp_path().unwrap().to_path_buf();
    assert_eq!(tmp, dir.join("run.rrd.tmp"));
    log_run(&mut rec).unwrap();
    assert!(!path.exists(), "final file must not exist before finish");
    rec.finish().unwrap();
    assert!(path.exists() && !tmp.exists());
    assert!(std::fs::metadata(&path).unwrap().len() > 1000);

    // Decode every message back with Rerun's own decoder.
    let file = std::fs::File::open(&path).unwrap();
    let mut entities = BTreeSet::new();
    let mut descriptors = BTreeSet::new();
    let mut sim_times_ns = BTreeSet::new();
    let mut blueprint_msgs = 0;
    let mut blueprint_entities = Vec::new();
    let mut blueprint_descriptors = BTreeSet::new();
    let mut activations = 0;
    let mut follow_rows = 0;
    let mut follow_xy: Vec<[f32; 2]> = Vec::new();
    for msg in DecoderApp::decode_lazy(BufReader::new(file)) {
        let msg = msg.unwrap();
        if let LogMsg::BlueprintActivationCommand(cmd) = &msg {
            assert!(cmd.make_default);
            activations += 1;
        }
        if let LogMsg::ArrowMsg(store_id, arrow_msg) = &msg {
            let chunk = Chunk::from_arrow_msg(arrow_msg).unwrap();
            if store_id.kind() == StoreKind::Blueprint {
                blueprint_msgs += 1;
                blueprint_entities.push(chunk.entity_path().to_string());
                for d in chunk.component_descriptors() {
                    blueprint_descriptors.insert(d.to_string());
                }
                continue;
            }
            entities.insert(chunk.entity_path().to_string());
            if chunk.entity_path().to_string() == "/world/follow" {
                follow_rows += chunk.num_rows();
                let id = rerun::Transform3D::descriptor_translation().component;
                for row in chunk.iter_component::<rerun::components::Translation3D>(id) {
                    follow_xy.extend(row.iter().map(|t| [t.0.0[0], t.0.0[1]]));
                }
            }
            for d in chunk.component_descriptors() {
                descriptors.insert(d.to_string());
            }
            for (name, column) in chunk.timelines() {
                if name.as_str() == SIM_TIMELINE {
                    sim_times_ns.extend(column.times_raw().iter().copied());
                }
            }
        }
    }
    for entity in [
        "/world/overview",
        "/world/follow",
        "/legend/field_scale",
        "/legend/field_scale/bar",
        "/legend/ticks",
        "/plots/speed_mps/events/error",
        "/world/road/edges",
        "/world/road/divider",
        "/world/road/merge_section",
        "/world/vehicles",
        "/world/paths/ego/planned",
        "/world/paths/ego/planned_points",
        "/world/paths/ego/received",
        "/world/fields/ego",
        "/plots/sideslip_rad/ego",
        "/plots/speed_mps/ego",
        "/events",
    ] {
        assert!(
            entities.contains(entity),
            "{entity} missing from {entities:?}"
        );
    }
    // The NaN planned speed is a gap, not a logged value.
    assert!(!entities.contains("/plots/planned_speed_mps/ego"));
    let has = |needle: &str| descriptors.iter().any(|d| d.contains(needle));
    // Top-down 2D: boxes, lines and the field as an image placed by its transform.
    assert!(has("Boxes2D:half_sizes"), "{descriptors:?}");
    assert!(has("LineStrips2D:strips"));
    assert!(has("Image:buffer"));
    assert!(has("Transform3D:translation"));
    assert!(has("Transform3D:scale"));
    assert!(has("SeriesPoints:markers"));
    assert!(has("TextLog:level"));
    assert!(
        !has("Boxes3D") && !has("Mesh3D"),
        "3D archetypes left: {descriptors:?}"
    );
    // The follow frame moves at every logged instant (the ego is in every log_vehicles call).
    assert_eq!(follow_rows, 20);
    // ... at the ego's position (x = 20 t, y = 1.75 in `log_run`), never the obstacle's.
    follow_xy.sort_by(|a, b| a[0].total_cmp(&b[0]));
    assert_eq!(follow_xy.len(), 20);
    for (k, [x, y]) in follow_xy.iter().enumerate() {
        assert!(
            (x - k as f32).abs() < 1e-4 && (y - 1.75).abs() < 1e-6,
            "{follow_xy:?}"
        );
    }
    // 20 instants at 50 ms on the duration timeline (nanoseconds).
    assert_eq!(sim_times_ns.len(), 20);
    assert!(sim_times_ns.contains(&950_000_000));
    assert!(blueprint_msgs > 0, "no blueprint in the file");
    assert_eq!(
        activations, 1,
        "the blueprint is activated once, as the default"
    );
    // Three 2D views with visual bounds (follow, whole road, colour bar), one y axis and one
    // legend corner per time-series view, written into the blueprint store.
    let count = |suffix: &str| {
        blueprint_entities
            .iter()
            .filter(|e| e.ends_with(suffix))
            .count()
    };
    assert_eq!(count("/VisualBounds2D"), 3, "{blueprint_entities:?}");
    assert_eq!(count("/ScalarAxis"), 5);
    assert_eq!(count("/PlotLegend"), 5);
    let bp_has = |needle: &str| blueprint_descriptors.iter().any(|d| d.contains(needle));
    assert!(bp_has("VisualBounds2D:range"), "{blueprint_descriptors:?}");
    assert!(bp_has("ScalarAxis:range"));
    assert!(bp_has("ViewBlueprint:space_origin"));

    // When a `rerun` CLI of the same version is available, let it verify the file too:
    // MERGESIM_RERUN_CLI=/path/to/rerun cargo test --release -p sim --test recording
    if let Some(cli) = std::env::var_os("MERGESIM_RERUN_CLI") {
        let out = std::process::Command::new(cli)
            .args(["rrd", "verify"])
            .arg(&path)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "rerun rrd verify failed:\n{}\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }

    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn dropped_recorder_leaves_no_file() {
    let dir = out_dir("drop");
    let path = dir.join("failed.rrd");
    let tmp;
    {
        let mut rec = Recorder::new_file(&path, "mergesim_test").unwrap();
        tmp = rec.tmp_path().unwrap().to_path_buf();
        log_run(&mut rec).unwrap();
        assert!(tmp.exists());
        // The run fails here: the recorder is dropped without `finish`.
    }
    assert!(!tmp.exists(), "temporary file left behind");
    assert!(!path.exists(), "final file written without finish");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn disabled_recorder_is_a_no_op_and_bad_input_is_an_error() {
    let mut rec = Recorder::disabled();
    assert!(!rec.is_enabled());
    log_run(&mut rec).unwrap();
    rec.finish().unwrap();

    let dir = out_dir("bad");
    let path = dir.join("bad.rrd");
    let mut rec = Recorder::new_file(&path, "mergesim_test").unwrap();
    let names = vec!["ego".to_string()];
    assert!(matches!(
        rec.log_vehicles(&[body(0, 0.0, 0.0, 0.0), body(1, 9.0, 0.0, 0.0)], &names),
        Err(RecordingError::InvalidInput { .. })
    ));
    assert!(rec.log_field("f", 0.0, 0.0, 0.5, 3, 3, &[0.0; 8]).is_err());
    assert!(rec.log_field("f", 0.0, 0.0, -0.5, 2, 2, &[0.0; 4]).is_err());
    assert!(rec.set_time(f64::NAN).is_err());
    drop(rec);
    assert!(!path.exists());

    // A directory that does not exist: a typed error, no panic.
    let missing = dir.join("no/such/dir/x.rrd");
    assert!(Recorder::new_file(&missing, "mergesim_test").is_err());
    std::fs::remove_dir_all(&dir).ok();
}
