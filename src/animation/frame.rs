//! One frame of the animation: where road coordinates fall in the picture (the follow window or
//! the whole road) and the drawing of the road, the vehicles and the header.

use mergesim_types::lanes::{LaneRoad, Side};
use plotters::coord::Shift;
use plotters::prelude::*;
use sim::recording::vehicle_color;
use sim::road_drawing::{RoadDrawing, road_middle_offset_m, road_width_m};
use sim::safety::CollisionEvent;
use sim::{RecordedPose, TimeSeriesRow};

use super::{GifParams, GifVehicle, GifView};
use crate::plots::font;

/// Colour of recorded traffic (the recording's grey).
pub(super) const RECORDED_GREY: [u8; 3] = [150, 150, 150];

/// Height of the header line (pixels).
pub(super) const HEADER_PX: u32 = 22;

/// Height of the bands above and below the road that hold the vehicles' names in the road view
/// (pixels).
const LABEL_BAND_PX: u32 = 15;

/// Lateral scale of the road view (pixels per metre) when the road's length alone would make
/// the lanes thinner: a 3.5 m lane is 14 px high.
const ROAD_VIEW_PX_PER_M_ACROSS: f64 = 4.0;

/// Smallest drawn footprint (pixels along, across), so a car stays visible on a long road.
const MIN_FOOTPRINT_PX: (f64, f64) = (8.0, 5.0);

/// Largest height of the road view when its lanes are stretched across (pixels, as a multiple
/// of the picture's width): a road that curves far across keeps one scale instead.
const ROAD_VIEW_MAX_STRETCHED_HEIGHT: f64 = 1.0;

/// How road coordinates map to a frame's pixels: a point p is turned into the view's axes,
/// (u, v) = R(−rotation) (p − origin), then u goes to the right and v up. The road view has its
/// origin at (0, 0) and no rotation (u, v = X, Y) unless its lanes run along another direction
/// (`road_view_rotation_rad`); the follow view's origin is the followed
/// vehicle's station on the middle of the road, turned so that its lane runs to the right,
/// along a curve too.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameGeometry {
    /// The view's origin in road coordinates (m).
    pub origin_m: [f64; 2],
    /// The view's rotation: the road direction drawn to the right (rad).
    pub rotation_rad: f64,
    /// u at the picture's left edge (m).
    pub x0_m: f64,
    /// v at the top of the road area (m).
    pub y_top_m: f64,
    /// Pixels per metre along u.
    pub px_per_m_x: f64,
    /// Pixels per metre along v: the same as along u in the follow view; in the road view of a
    /// long road larger, so the lanes stay visible (the header says by how much).
    pub px_per_m_y: f64,
    /// Top of the road area (pixels).
    pub top_px: u32,
    /// Picture size (pixels).
    pub size_px: (u32, u32),
}

impl FrameGeometry {
    /// The follow view of a vehicle at `vehicle_m`: [`GifParams::behind_m`] behind it to
    /// [`GifParams::ahead_m`] ahead along its lane (the nearest lane) and turned to the lane's
    /// heading there; across, the road's whole width ([`sim::road_drawing::road_width_m`]) with
    /// [`GifParams::margin_m`] beside it, centred on the road's middle
    /// ([`sim::road_drawing::road_middle_offset_m`]: on the straight merge road the divider, as
    /// before); one scale.
    pub fn follow(lanes: &LaneRoad, params: &GifParams, vehicle_m: [f64; 2]) -> Self {
        let px_per_m = f64::from(params.width_px) / (params.behind_m + params.ahead_m);
        let half_height_m = 0.5 * road_width_m(lanes) + params.margin_m;
        let road_px = (2.0 * half_height_m * px_per_m).ceil().clamp(16.0, 4000.0);
        let (origin_m, rotation_rad) = if vehicle_m.iter().all(|c| c.is_finite()) {
            let hit = lanes.nearest_lane(vehicle_m);
            lanes.lane(hit.lane).map_or((vehicle_m, 0.0), |l| {
                let s = hit.frame.s_m;
                (
                    l.point(s, road_middle_offset_m(lanes, hit.lane)),
                    l.heading_rad(s),
                )
            })
        } else {
            (vehicle_m, 0.0)
        };
        Self {
            origin_m,
            rotation_rad,
            x0_m: -params.behind_m,
            y_top_m: half_height_m,
            px_per_m_x: px_per_m,
            px_per_m_y: px_per_m,
            top_px: HEADER_PX,
            size_px: (params.width_px, HEADER_PX + road_px as u32),
        }
    }

    /// The road view: the whole road, and every position in `rows`, across the picture's
    /// width; the vehicles' names in a band above and below the road. A road whose lanes run
    /// along another direction than +X (a recorded map) is turned so that they run to the right
    /// (`road_view_rotation_rad`).
    pub fn whole_road(lanes: &LaneRoad, params: &GifParams, rows: &[TimeSeriesRow]) -> Self {
        let rotation_rad = road_view_rotation_rad(lanes);
        let turned = Self {
            origin_m: [0.0, 0.0],
            rotation_rad,
            x0_m: 0.0,
            y_top_m: 0.0,
            px_per_m_x: 1.0,
            px_per_m_y: 1.0,
            top_px: 0,
            size_px: (1, 1),
        };
        let (blo, bhi) = if rotation_rad == 0.0 {
            let [blo, bhi] = RoadDrawing::new(lanes).bounds_m;
            (blo, bhi)
        } else {
            let mut lo = [f64::INFINITY; 2];
            let mut hi = [f64::NEG_INFINITY; 2];
            for lane in lanes.lanes() {
                for side in [Side::Left, Side::Right] {
                    for p in lane.bound_polyline(side) {
                        let (u, v) = turned.to_view_m(p[0], p[1]);
                        lo = [lo[0].min(u), lo[1].min(v)];
                        hi = [hi[0].max(u), hi[1].max(v)];
                    }
                }
            }
            (lo, hi)
        };
        let (mut lo, mut hi) = (blo[0], bhi[0]);
        for r in rows
            .iter()
            .filter(|r| r.x_m.is_finite() && r.y_m.is_finite())
        {
            let (u, _) = turned.to_view_m(r.x_m, r.y_m);
            lo = lo.min(u - 5.0);
            hi = hi.max(u + 5.0);
        }
        let span = (hi - lo).max(1.0);
        let pad = 0.01 * span;
        let px_per_m_x = f64::from(params.width_px) / (span + 2.0 * pad);
        let height_m = bhi[1] - blo[1] + 2.0 * params.margin_m;
        let stretched = px_per_m_x.max(ROAD_VIEW_PX_PER_M_ACROSS);
        let max_height_px = ROAD_VIEW_MAX_STRETCHED_HEIGHT * f64::from(params.width_px);
        let px_per_m_y = if height_m * stretched <= max_height_px {
            stretched
        } else {
            px_per_m_x.max(max_height_px / height_m)
        };
        let road_px = (height_m * px_per_m_y).ceil().clamp(16.0, 4000.0);
        Self {
            origin_m: [0.0, 0.0],
            rotation_rad,
            x0_m: lo - pad,
            y_top_m: bhi[1] + params.margin_m,
            px_per_m_x,
            px_per_m_y,
            top_px: HEADER_PX + LABEL_BAND_PX,
            size_px: (
                params.width_px,
                HEADER_PX + 2 * LABEL_BAND_PX + road_px as u32,
            ),
        }
    }

    /// The view's axes (u, v) of road point (x, y) (m).
    pub fn to_view_m(&self, x_m: f64, y_m: f64) -> (f64, f64) {
        let (dx, dy) = (x_m - self.origin_m[0], y_m - self.origin_m[1]);
        if self.rotation_rad == 0.0 {
            return (dx, dy);
        }
        let (s, c) = self.rotation_rad.sin_cos();
        (c * dx + s * dy, -s * dx + c * dy)
    }

    /// The pixel of road point (x, y).
    pub fn to_px(&self, x_m: f64, y_m: f64) -> (i32, i32) {
        let (u, v) = self.to_view_m(x_m, y_m);
        (
            ((u - self.x0_m) * self.px_per_m_x).round() as i32,
            (f64::from(self.top_px) + (self.y_top_m - v) * self.px_per_m_y).round() as i32,
        )
    }
}

/// Roads within this angle of the X axis (rad, 0.06°) are drawn unturned in the road view.
const ROAD_VIEW_UNTURNED_RAD: f64 = 1e-3;

/// The road view's rotation: the direction from the longest lane's first centreline vertex to
/// its last; 0 for a road within [`ROAD_VIEW_UNTURNED_RAD`] of the X axis (the built-in merge
/// roads keep their picture).
pub fn road_view_rotation_rad(lanes: &LaneRoad) -> f64 {
    let Some(longest) = lanes
        .lanes()
        .iter()
        .max_by(|a, b| a.length_m().total_cmp(&b.length_m()))
    else {
        return 0.0;
    };
    let c = longest.centreline().vertices_m();
    let (Some(first), Some(last)) = (c.first(), c.last()) else {
        return 0.0;
    };
    let chord_rad = (last[1] - first[1]).atan2(last[0] - first[0]);
    if chord_rad.abs() < ROAD_VIEW_UNTURNED_RAD || !chord_rad.is_finite() {
        0.0
    } else {
        chord_rad
    }
}

/// The corners of a footprint centred at (x, y) with heading `yaw`.
pub(super) fn footprint(x: f64, y: f64, yaw: f64, length: f64, width: f64) -> [(f64, f64); 4] {
    let (s, c) = yaw.sin_cos();
    let (hl, hw) = (0.5 * length, 0.5 * width);
    [(hl, hw), (-hl, hw), (-hl, -hw), (hl, -hw)]
        .map(|(dx, dy)| (x + c * dx - s * dy, y + s * dx + c * dy))
}

/// The pixel corners of a footprint at `pose_m` = (x, y, yaw), at least [`MIN_FOOTPRINT_PX`]
/// in size; `None` for a non-finite pose.
fn footprint_px(
    geometry: &FrameGeometry,
    pose_m: [f64; 3],
    length_m: f64,
    width_m: f64,
) -> Option<[(i32, i32); 4]> {
    if !pose_m.iter().all(|c| c.is_finite()) {
        return None;
    }
    let length_m = length_m.max(MIN_FOOTPRINT_PX.0 / geometry.px_per_m_x);
    let width_m = width_m.max(MIN_FOOTPRINT_PX.1 / geometry.px_per_m_y);
    Some(
        footprint(pose_m[0], pose_m[1], pose_m[2], length_m, width_m)
            .map(|(x, y)| geometry.to_px(x, y)),
    )
}

/// What one frame shows besides its instant.
pub(super) struct FrameScene<'a> {
    pub(super) road: &'a RoadDrawing,
    /// Write each lane's id on the road.
    pub(super) lane_ids: bool,
    pub(super) vehicles: &'a [GifVehicle],
    /// The recorded traffic's boxes (`RunOutcome::recorded_track`, in time order).
    pub(super) recorded: &'a [RecordedPose],
    pub(super) collisions: &'a [CollisionEvent],
    pub(super) follow: &'a str,
    pub(super) title: &'a str,
    pub(super) view: GifView,
}

/// Draws the frame of `instant` with `geometry`.
pub(super) fn draw_frame(
    root: &DrawingArea<BitMapBackend<'_>, Shift>,
    scene: &FrameScene<'_>,
    instant: &[TimeSeriesRow],
    geometry: &FrameGeometry,
) -> Result<(), String> {
    let FrameScene {
        road,
        lane_ids,
        vehicles,
        recorded,
        collisions,
        follow,
        title,
        view,
    } = *scene;
    let e = |err: &dyn std::fmt::Display| err.to_string();
    let (w, _) = geometry.size_px;
    root.fill(&RGBColor(40, 40, 44)).map_err(|x| e(&x))?;
    let t_s = instant.first().map_or(0.0, |r| r.t_s);
    let followed = instant.iter().find(|r| r.vehicle == follow);
    let to_px = |x: f64, y: f64| geometry.to_px(x, y);
    // Merge sections (the tapering stretch of each lane that ends).
    let line = |pts: &[[f64; 2]]| pts.iter().map(|p| to_px(p[0], p[1])).collect::<Vec<_>>();
    for section in &road.merge_sections {
        root.draw(&Polygon::new(line(section), RGBColor(75, 58, 38).filled()))
            .map_err(|x| e(&x))?;
    }
    // Outer edges solid, dividers dashed, closed lane ends.
    for edge in &road.outer_edges {
        root.draw(&PathElement::new(
            line(edge),
            ShapeStyle::from(&RGBColor(230, 230, 230)).stroke_width(2),
        ))
        .map_err(|x| e(&x))?;
    }
    for dash in road.divider_dashes() {
        root.draw(&PathElement::new(
            line(&dash),
            ShapeStyle::from(&RGBColor(240, 200, 60)).stroke_width(1),
        ))
        .map_err(|x| e(&x))?;
    }
    for end in &road.closed_ends {
        root.draw(&PathElement::new(
            line(end),
            ShapeStyle::from(&RGBColor(230, 60, 40)).stroke_width(3),
        ))
        .map_err(|x| e(&x))?;
    }
    if lane_ids {
        for label in &road.lane_labels {
            let (x, y) = to_px(label.at_m[0], label.at_m[1]);
            root.draw(&Text::new(
                label.text.clone(),
                (x - 14, y - 6),
                font(11).color(&RGBColor(200, 200, 255)),
            ))
            .map_err(|x| e(&x))?;
        }
    }
    // Recorded traffic at this instant: grey boxes, unlabelled.
    let first = recorded.partition_point(|p| p.t_s < t_s);
    for pose in recorded[first..].iter().take_while(|p| p.t_s == t_s) {
        let pose_m = [pose.x_m, pose.y_m, pose.yaw_rad];
        let Some(corners) = footprint_px(geometry, pose_m, pose.length_m, pose.width_m) else {
            continue;
        };
        root.draw(&Polygon::new(
            corners.to_vec(),
            RGBColor(RECORDED_GREY[0], RECORDED_GREY[1], RECORDED_GREY[2]).filled(),
        ))
        .map_err(|x| e(&x))?;
    }
    // Vehicles: footprints first, names on top.
    let mut labels = Vec::new();
    for row in instant {
        let Some(v) = vehicles.iter().find(|v| v.name == row.vehicle) else {
            continue;
        };
        let pose_m = [row.x_m, row.y_m, row.yaw_rad];
        let Some(corners) = footprint_px(geometry, pose_m, v.length_m, v.width_m) else {
            continue;
        };
        // Outside the window: not drawn (its label would be pinned to the picture's edge).
        if corners.iter().all(|&(x, _)| x < 0) || corners.iter().all(|&(x, _)| x >= w as i32) {
            continue;
        }
        let [r, g, b] = vehicle_color(v.id);
        let fill = Polygon::new(corners.to_vec(), RGBColor(r, g, b).filled());
        let crashed = collisions
            .iter()
            .any(|c| c.t_s <= t_s + 1e-9 && c.involves(v.id));
        let mut outline = corners.to_vec();
        outline.push(corners[0]);
        let outline = PathElement::new(
            outline,
            ShapeStyle::from(&RGBColor(255, 40, 40)).stroke_width(3),
        );
        // In the road view a car is a few pixels: its red outline goes under it, not over it.
        if crashed && view == GifView::Road {
            root.draw(&outline).map_err(|x| e(&x))?;
        }
        root.draw(&fill).map_err(|x| e(&x))?;
        if crashed && view == GifView::Follow {
            root.draw(&outline).map_err(|x| e(&x))?;
        }
        let position = match view {
            GifView::Follow => {
                let (lx, ly) = to_px(row.x_m - 0.5 * v.length_m, row.y_m + 0.5 * v.width_m);
                (lx, ly - 13)
            }
            // Names in the bands: even ids above the road, odd ids below.
            GifView::Road => {
                let (lx, _) = to_px(row.x_m, row.y_m);
                let y = if v.id % 2 == 0 {
                    geometry.top_px as i32 - LABEL_BAND_PX as i32 + 1
                } else {
                    geometry.size_px.1 as i32 - LABEL_BAND_PX as i32 + 1
                };
                (lx - 4, y)
            }
        };
        labels.push((v.name.clone(), position));
    }
    for (name, position) in labels {
        root.draw(&Text::new(
            name,
            position,
            font(12).color(&RGBColor(235, 235, 235)),
        ))
        .map_err(|x| e(&x))?;
    }
    // Header.
    root.draw(&Rectangle::new(
        [(0, 0), (w as i32, HEADER_PX as i32)],
        RGBColor(20, 20, 22).filled(),
    ))
    .map_err(|x| e(&x))?;
    let speed = followed.map_or(String::new(), |r| {
        format!("  {follow} {:.1} m/s  x = {:.0} m", r.speed_mps, r.x_m)
    });
    let scale = match view {
        GifView::Follow => String::new(),
        GifView::Road => {
            let stretch = geometry.px_per_m_y / geometry.px_per_m_x;
            if stretch > 1.05 {
                format!("  whole road (across ×{stretch:.0})")
            } else {
                "  whole road".into()
            }
        }
    };
    let crash = collisions
        .iter()
        .rfind(|c| c.t_s <= t_s + 1e-9)
        .map_or(String::new(), |c| format!("  COLLISION at {:.2} s", c.t_s));
    root.draw(&Text::new(
        format!("{title}  t = {t_s:5.2} s{scale}{speed}{crash}"),
        (6, 4),
        font(14).color(&RGBColor(240, 240, 240)),
    ))
    .map_err(|x| e(&x))?;
    Ok(())
}
