//! The test road `tests/data/line_arc_merge.xodr` (written here: a 100 m line, then a 100 m arc
//! of radius 200 m turning left; lanes -1 and -2 right of the reference line, -2 ending at
//! s = 150 m; lane 1 the opposite carriageway) against its analytic geometry.

use std::path::Path;

use mergesim_opendrive::read_file;
use mergesim_types::lanes::{LaneId, LaneKind};

const RADIUS_M: f64 = 200.0;
const WIDTH_M: f64 = 3.5;

fn road() -> mergesim_opendrive::OpenDriveRoad {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/line_arc_merge.xodr");
    match read_file(&path) {
        Ok(r) => r,
        Err(e) => panic!("{e}"),
    }
}

/// The analytic lateral offset t (left positive) of a point from the reference line, and its s.
fn reference_frame(p: [f64; 2]) -> (f64, f64) {
    if p[0] <= 100.0 {
        (p[0], p[1])
    } else {
        // Arc centre (100, R); the reference line is the circle of radius R, turning left.
        let (cx, cy) = (100.0, RADIUS_M);
        let r = (p[0] - cx).hypot(p[1] - cy);
        let theta = (p[0] - cx).atan2(cy - p[1]);
        (100.0 + RADIUS_M * theta, RADIUS_M - r)
    }
}

fn origin(road: &mergesim_opendrive::OpenDriveRoad, od: i32, section: usize) -> LaneId {
    let o = road
        .lanes
        .iter()
        .find(|o| o.od_lane_id == od && o.section == section);
    match o {
        Some(o) => LaneId(o.id),
        None => panic!("no lane {od} in section {section}: {:?}", road.lanes),
    }
}

#[test]
fn centrelines_lie_at_their_analytic_offsets() {
    let road = road();
    let mut worst_m: f64 = 0.0;
    for (od, t_m) in [(-1, -1.75), (-2, -5.25), (1, 1.75)] {
        for section in [0, 1] {
            if od == -2 && section == 1 {
                continue;
            }
            let id = origin(&road, od, section);
            let spec = road.spec.lanes.iter().find(|l| l.id == id).unwrap();
            for p in &spec.centreline_m {
                let (_, t) = reference_frame(*p);
                worst_m = worst_m.max((t - t_m).abs());
            }
            for w in spec.left_width_m.iter().chain(&spec.right_width_m) {
                assert!((w - 0.5 * WIDTH_M).abs() < 1e-5, "half width {w}");
            }
        }
    }
    println!("worst lateral deviation from the analytic centrelines: {worst_m:.2e} m");
    assert!(worst_m < 0.01, "worst deviation {worst_m} m");
}

#[test]
fn lanes_run_in_travel_direction_with_their_links_and_sides() {
    let road = road();
    let lane = |od, section| {
        let id = origin(&road, od, section);
        road.spec.lanes.iter().find(|l| l.id == id).unwrap().clone()
    };
    let (r1a, r2a, r1b, l1a, l1b) = (
        lane(-1, 0),
        lane(-2, 0),
        lane(-1, 1),
        lane(1, 0),
        lane(1, 1),
    );
    // Right lanes run with the reference line (+x at the start), the left lane against it.
    let dir = |c: &[[f64; 2]]| c[c.len() - 1][0] - c[0][0];
    assert!(dir(&r1a.centreline_m) > 0.0 && dir(&l1a.centreline_m) < 0.0);
    // Section 0's lane -1 goes on into section 1's; lane -2 ends; the opposite lane runs from
    // section 1 into section 0.
    assert_eq!(r1a.successors, vec![r1b.id]);
    assert!(r2a.successors.is_empty());
    assert_eq!(l1b.successors, vec![l1a.id]);
    // Lane -2 is right of lane -1 in travel direction, and an entry lane.
    assert_eq!(r1a.right, Some(r2a.id));
    assert_eq!(r2a.left, Some(r1a.id));
    assert_eq!(r2a.kind, LaneKind::Entry);
    // The opposite carriageway is no neighbour.
    assert_eq!(r1a.left, None);
    // The whole network makes a consistent road of lanes.
    let built = road.lane_road().unwrap();
    assert_eq!(built.lanes().len(), 5);
}

#[test]
fn a_file_that_is_not_opendrive_is_refused_naming_it() {
    let path = Path::new("broken.xodr");
    let e = mergesim_opendrive::read_str("<OpenDRIVE><road", path).unwrap_err();
    assert!(e.to_string().starts_with("broken.xodr: "), "{e}");
    let e = mergesim_opendrive::read_str(
        "<OpenDRIVE><header revMajor=\"1\" revMinor=\"6\"/></OpenDRIVE>",
        path,
    )
    .unwrap_err();
    assert!(e.to_string().starts_with("broken.xodr: "), "{e}");
}

#[test]
fn a_map_far_from_the_origin_is_refused_for_the_importers_precision() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/line_arc_merge.xodr");
    let text = std::fs::read_to_string(&path).unwrap();
    // The same road 5,300 km north (a UTM northing): f32 spacing 0.5 m there.
    let far = text.replace(
        r#"x="0.0" y="0.0" hdg="0.0" length="100.0""#,
        r#"x="0.0" y="5300000.0" hdg="0.0" length="100.0""#,
    );
    let far = far.replace(
        r#"x="100.0" y="0.0" hdg="0.0" length="100.0""#,
        r#"x="100.0" y="5300000.0" hdg="0.0" length="100.0""#,
    );
    assert_ne!(far, text);
    let e = mergesim_opendrive::read_str(&far, Path::new("far.xodr")).unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with("far.xodr: road 1 lane"), "{msg}");
    assert!(msg.contains("32-bit floats"), "{msg}");
    // 100 km is still accepted.
    let near = text.replace(r#"y="0.0" hdg"#, r#"y="90000.0" hdg"#);
    assert!(mergesim_opendrive::read_str(&near, Path::new("near.xodr")).is_ok());
}

#[test]
fn a_geometry_the_importer_drops_is_refused_not_skipped() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/line_arc_merge.xodr");
    let text = std::fs::read_to_string(&path).unwrap();
    for bad in ["NaN", "abc"] {
        let broken = text.replacen(
            r#"length="100.0"><line/>"#,
            &format!(r#"length="{bad}"><line/>"#),
            1,
        );
        assert_ne!(broken, text);
        let e = mergesim_opendrive::read_str(&broken, Path::new("bad.xodr")).unwrap_err();
        let msg = e.to_string();
        assert!(msg.starts_with("bad.xodr: road \"1\""), "{bad}: {msg}");
        assert!(msg.contains("dropped"), "{bad}: {msg}");
    }
}
