//! The GIF draws a curved road along its curve, and the follow view turns with it.

use mergesim_types::lanes::{LaneRoad, THROUGH_LANE_ID, curved_merge_spec};
use sim::road_drawing::RoadDrawing;

use super::tests::{draw_on, row};
use super::{FrameGeometry, GifParams, GifView};
use crate::plots::ensure_font;

const EDGE_RGB: [u8; 3] = [230, 230, 230];

fn curved() -> LaneRoad {
    let spec = curved_merge_spec(&mergesim_types::MergeRoad::default(), 300.0)
        .unwrap_or_else(|e| panic!("{e}"));
    LaneRoad::new(&spec).unwrap_or_else(|e| panic!("{e}"))
}

/// The share of the outer edges' vertices drawn inside the picture whose pixel (or a
/// neighbour) has the edges' colour, and how many such vertices there are.
fn edge_pixels_on_the_curve(
    lanes: &LaneRoad,
    geometry: &FrameGeometry,
    pixels: &[u8],
) -> (f64, usize) {
    let (w, h) = geometry.size_px;
    let at = |x: i32, y: i32| {
        let i = 3 * (y as usize * w as usize + x as usize);
        [pixels[i], pixels[i + 1], pixels[i + 2]]
    };
    let (mut inside, mut on_edge) = (0usize, 0usize);
    for p in RoadDrawing::new(lanes).outer_edges.iter().flatten() {
        let (x, y) = geometry.to_px(p[0], p[1]);
        if x < 1 || y < geometry.top_px as i32 + 1 || x >= w as i32 - 1 || y >= h as i32 - 1 {
            continue;
        }
        inside += 1;
        let hit = (-1..=1).any(|dx| (-1..=1).any(|dy| at(x + dx, y + dy) == EDGE_RGB));
        on_edge += usize::from(hit);
    }
    (on_edge as f64 / inside.max(1) as f64, inside)
}

/// The whole-road view of the 300 m-radius curved merge road: every vertex of its outer edges
/// falls on a drawn edge pixel.
#[test]
fn the_road_view_draws_the_curve() {
    ensure_font().unwrap_or_else(|e| panic!("{e}"));
    let lanes = curved();
    let instant = [row("ego", 100.0, 20.0)];
    let geometry = FrameGeometry::whole_road(&lanes, &GifParams::default(), &instant);
    let pixels = draw_on(&lanes, &instant, GifView::Road, &geometry, true);
    let (share, inside) = edge_pixels_on_the_curve(&lanes, &geometry, &pixels);
    assert!(inside > 1000, "{inside}");
    assert!(share > 0.99, "{share}");
}

/// The follow view on the curve: at the vehicle's station, centred on the road's middle (the
/// divider, 1.75 m right of the through lane's centre), turned to its lane's heading (the lane
/// runs to the right at the vehicle), and the edges drawn where the curve puts them (they bend
/// away from the picture's horizontal by u²/(2R) over the window).
#[test]
fn the_follow_view_turns_along_the_curve() {
    ensure_font().unwrap_or_else(|e| panic!("{e}"));
    let lanes = curved();
    let lane = lanes
        .lane(THROUGH_LANE_ID)
        .unwrap_or_else(|| panic!("no through lane"));
    let s = 400.0;
    let [x, y] = lane.point(s, 0.0);
    let instant = [row("ego", x, y)];
    let params = GifParams::default();
    let geometry = FrameGeometry::follow(&lanes, &params, [x, y]);
    assert!((geometry.rotation_rad - lane.heading_rad(s)).abs() < 1e-9);
    // The vehicle `behind_m` from the left, 1.75 m (the half lane) above the middle.
    let (px, py) = geometry.to_px(x, y);
    let k = geometry.px_per_m_x;
    assert_eq!(px, (params.behind_m * k).round() as i32);
    let middle = f64::from(geometry.top_px) + 0.5 * f64::from(geometry.size_px.1 - geometry.top_px);
    assert!(
        (f64::from(py) - (middle - 1.75 * k)).abs() <= 1.0,
        "{py} vs {middle}"
    );
    // The divider at the vehicle's station: on the middle line.
    let [dx, dy] = lane.point(s, -1.75);
    let (_, py_divider) = geometry.to_px(dx, dy);
    assert!(
        (f64::from(py_divider) - middle).abs() <= 1.0,
        "{py_divider} vs {middle}"
    );
    // Along the lane, 2 m either side of the vehicle, the lane runs horizontally.
    let (_, y_behind) = geometry.to_px(lane.point(s - 2.0, 0.0)[0], lane.point(s - 2.0, 0.0)[1]);
    let (_, y_ahead) = geometry.to_px(lane.point(s + 2.0, 0.0)[0], lane.point(s + 2.0, 0.0)[1]);
    assert!((y_behind - y_ahead).abs() <= 1, "{y_behind} {y_ahead}");
    let pixels = draw_on(&lanes, &instant, GifView::Follow, &geometry, false);
    let (share, inside) = edge_pixels_on_the_curve(&lanes, &geometry, &pixels);
    // Two edges over an 80 m window with 1 m chords.
    assert!(inside > 100, "{inside}");
    assert!(share > 0.95, "{share}");
}
