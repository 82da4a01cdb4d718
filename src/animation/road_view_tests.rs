//! The road view of a road whose lanes do not run along +X (a recorded map) is turned so that
//! they run to the right, and recorded traffic is drawn in grey.

use mergesim_types::lanes::{LaneId, LaneRoad, LaneRoadSpec, LaneSpec};
use sim::RecordedPose;

use super::frame::{RECORDED_GREY, road_view_rotation_rad};
use super::tests::{draw_with_recorded, row};
use super::{FrameGeometry, GifParams, GifView};
use crate::plots::ensure_font;

/// Two 200 m lanes side by side, driven along `heading_rad`, 5.9 km from the origin.
fn diagonal(heading_rad: f64) -> LaneRoad {
    let (s, c) = heading_rad.sin_cos();
    let origin = [3000.0, -5866.0];
    let lane = |id: u32, offset_m: f64| {
        let start = [origin[0] - s * offset_m, origin[1] + c * offset_m];
        let mut spec = LaneSpec::new(
            LaneId(id),
            vec![start, [start[0] + 200.0 * c, start[1] + 200.0 * s]],
            3.5,
        );
        spec.left = (id == 2).then_some(LaneId(1));
        spec.right = (id == 1).then_some(LaneId(2));
        spec
    };
    let spec = LaneRoadSpec {
        lanes: vec![lane(1, 0.0), lane(2, -3.5)],
        ..LaneRoadSpec::default()
    };
    LaneRoad::new(&spec).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_diagonal_road_is_turned_to_run_to_the_right() {
    for heading in [0.6, -2.4, 3.0] {
        let lanes = diagonal(heading);
        let rotation = road_view_rotation_rad(&lanes);
        assert!(
            (rotation - heading).abs() < 1e-9,
            "{rotation} for {heading}"
        );
        let geometry = FrameGeometry::whole_road(&lanes, &GifParams::default(), &[]);
        // The lanes' start is at the left edge, their end at the right, at one height.
        let (s, c) = heading.sin_cos();
        let start = [3000.0, -5866.0];
        let end = [start[0] + 200.0 * c, start[1] + 200.0 * s];
        let (x0, y0) = geometry.to_px(start[0], start[1]);
        let (x1, y1) = geometry.to_px(end[0], end[1]);
        let w = geometry.size_px.0 as i32;
        assert!(x0 < w / 20 && x1 > w - w / 20, "{x0} {x1} of {w}");
        assert!((y0 - y1).abs() <= 1, "{y0} {y1}");
    }
    // The straight merge road keeps its unturned picture.
    let merge = mergesim_types::MergeRoad::default()
        .lane_road()
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(road_view_rotation_rad(&merge), 0.0);
}

#[test]
fn recorded_traffic_is_drawn_in_grey_at_its_instant() {
    ensure_font().unwrap_or_else(|e| panic!("{e}"));
    let lanes = diagonal(0.6);
    let (s, c) = 0.6_f64.sin_cos();
    let at = [3000.0 + 100.0 * c, -5866.0 + 100.0 * s];
    let instant = [row("ego", 3000.0 + 20.0 * c, -5866.0 + 20.0 * s)];
    let geometry = FrameGeometry::whole_road(&lanes, &GifParams::default(), &instant);
    let pose = |t_s: f64| RecordedPose {
        t_s,
        vehicle: "cr-1".into(),
        x_m: at[0],
        y_m: at[1],
        yaw_rad: 0.6,
        length_m: 4.5,
        width_m: 1.8,
    };
    let grey_at_pose = |recorded: &[RecordedPose]| {
        let pixels =
            draw_with_recorded(&lanes, &instant, recorded, GifView::Road, &geometry, false);
        let (x, y) = geometry.to_px(at[0], at[1]);
        let i = 3 * (y as usize * geometry.size_px.0 as usize + x as usize);
        pixels[i..i + 3] == RECORDED_GREY
    };
    let t = instant[0].t_s;
    assert!(grey_at_pose(&[pose(t)]));
    // A pose of another instant is not drawn.
    assert!(!grey_at_pose(&[pose(t + 0.05)]));
    assert!(!grey_at_pose(&[]));
}
