//! The recording draws any road of lanes: the curved merge road's edges lie on its outer
//! edges, its divider is dashed, the lanes' ids are written on request, and the follow frame
//! turns with the followed vehicle's lane.

use std::collections::BTreeMap;
use std::io::BufReader;

use mergesim_types::MergeRoad;
use mergesim_types::lanes::{LaneRoad, THROUGH_LANE_ID, curved_merge_spec};
use re_log_encoding::DecoderApp;
use rerun::StoreKind;
use rerun::log::{Chunk, LogMsg};
use sim::recording::{Recorder, RecorderParams};
use sim::safety::BodyState;

/// Every line strip logged under each entity, decoded from the file.
fn strips(path: &std::path::Path) -> BTreeMap<String, Vec<Vec<[f32; 2]>>> {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{e}"));
    let mut out: BTreeMap<String, Vec<Vec<[f32; 2]>>> = BTreeMap::new();
    for msg in DecoderApp::decode_lazy(BufReader::new(file)) {
        let msg = msg.unwrap_or_else(|e| panic!("{e}"));
        let LogMsg::ArrowMsg(store_id, arrow_msg) = &msg else {
            continue;
        };
        if store_id.kind() == StoreKind::Blueprint {
            continue;
        }
        let chunk = Chunk::from_arrow_msg(arrow_msg).unwrap_or_else(|e| panic!("{e}"));
        let entity = chunk.entity_path().to_string();
        let entry = out.entry(entity).or_default();
        let id = rerun::LineStrips2D::descriptor_strips().component;
        for row in chunk.iter_component::<rerun::components::LineStrip2D>(id) {
            entry.extend(
                row.iter()
                    .map(|s| s.0.iter().map(|p| [p.x(), p.y()]).collect::<Vec<_>>()),
            );
        }
    }
    out
}

/// The rotations logged for `world/follow`, (x, y, z, w).
fn follow_quaternions(path: &std::path::Path) -> Vec<[f32; 4]> {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{e}"));
    let mut out = Vec::new();
    for msg in DecoderApp::decode_lazy(BufReader::new(file)) {
        let msg = msg.unwrap_or_else(|e| panic!("{e}"));
        let LogMsg::ArrowMsg(store_id, arrow_msg) = &msg else {
            continue;
        };
        if store_id.kind() == StoreKind::Blueprint {
            continue;
        }
        let chunk = Chunk::from_arrow_msg(arrow_msg).unwrap_or_else(|e| panic!("{e}"));
        if chunk.entity_path().to_string() != "/world/follow" {
            continue;
        }
        let id = rerun::Transform3D::descriptor_quaternion().component;
        for row in chunk.iter_component::<rerun::components::RotationQuat>(id) {
            out.extend(row.iter().map(|q| q.0.0));
        }
    }
    out
}

#[test]
fn a_curved_road_is_recorded_along_its_curve() {
    let spec = curved_merge_spec(&MergeRoad::default(), 300.0).unwrap_or_else(|e| panic!("{e}"));
    let lanes = LaneRoad::new(&spec).unwrap_or_else(|e| panic!("{e}"));
    let dir = std::env::temp_dir().join(format!("mergesim_rec_lanes_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{e}"));
    let path = dir.join("curved.rrd");
    let params = RecorderParams {
        lane_ids: true,
        ..RecorderParams::default()
    };
    let mut rec = Recorder::new_file_with_params(&path, "mergesim_test", params)
        .unwrap_or_else(|e| panic!("{e}"));
    rec.log_road(&lanes).unwrap_or_else(|e| panic!("{e}"));
    // The ego on the through lane at s = 400 m: the follow frame turns to the lane's heading.
    let lane = lanes
        .lane(THROUGH_LANE_ID)
        .unwrap_or_else(|| panic!("no through lane"));
    let [x, y] = lane.point(400.0, 0.0);
    let heading = lane.heading_rad(400.0);
    rec.set_time(0.0).unwrap_or_else(|e| panic!("{e}"));
    let ego = BodyState {
        id: 0,
        x_m: x,
        y_m: y,
        yaw_rad: heading,
        vx_mps: 20.0 * heading.cos(),
        vy_mps: 20.0 * heading.sin(),
        yaw_rate_radps: 0.0,
        length_m: 4.5,
        width_m: 1.8,
        height_m: 1.4,
    };
    rec.log_vehicles(&[ego], &["ego".to_string()])
        .unwrap_or_else(|e| panic!("{e}"));
    rec.finish().unwrap_or_else(|e| panic!("{e}"));
    let quaternions = follow_quaternions(&path);
    assert_eq!(quaternions.len(), 1);
    let q = quaternions[0];
    let (s, c) = (0.5 * heading).sin_cos();
    let expected = [c as f32, s as f32, 0.0, 0.0];
    for k in 0..4 {
        assert!((q[k] - expected[k]).abs() < 1e-6, "{q:?} vs {expected:?}");
    }
    let strips = strips(&path);
    for entity in [
        "/world/road/edges",
        "/world/road/divider",
        "/world/road/merge_section",
        "/world/road/lane_ids",
        "/world/overview",
    ] {
        assert!(strips.contains_key(entity), "{entity}: {:?}", strips.keys());
    }
    // The edges: the two outer edges, sampled along the curve (1 m chords), every vertex on
    // the drivable area's boundary (f32 at up to ~600 m: 61 µm).
    let edges = &strips["/world/road/edges"];
    assert_eq!(edges.len(), 2);
    let vertices: Vec<[f32; 2]> = edges.iter().flatten().copied().collect();
    assert!(vertices.len() > 1000, "{}", vertices.len());
    for p in &vertices {
        let d = lanes.signed_distance_to_edge_m([f64::from(p[0]), f64::from(p[1])]);
        assert!(d.abs() < 1e-3, "{p:?} is {d} m from the edge");
    }
    // They turn: the heading changes by the road's 2 rad along the upper edge.
    let upper = edges
        .iter()
        .max_by_key(|e| e.len())
        .unwrap_or_else(|| panic!("no edges"));
    let heading = |a: [f32; 2], b: [f32; 2]| f64::from(b[1] - a[1]).atan2(f64::from(b[0] - a[0]));
    let turn =
        heading(upper[upper.len() - 2], upper[upper.len() - 1]) - heading(upper[0], upper[1]);
    assert!(turn > 1.5, "{turn}");
    // The divider is dashed: many short strips, each at most a dash long.
    let dashes = &strips["/world/road/divider"];
    assert!(dashes.len() > 20, "{}", dashes.len());
    for d in dashes {
        let length: f32 = d
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum();
        assert!(length <= 4.0 + 1e-3, "{length}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
