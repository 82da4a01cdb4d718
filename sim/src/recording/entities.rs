//! What the recording logs: the road, the vehicles' boxes, planned and received paths, the
//! potential fields, the follow frame, the field's colour bar, time series and events.

use mergesim_types::lanes::LaneRoad;
use mergesim_types::{PathPoint, SharedLocalPath};
use rerun::components::{Color, MarkerShape};
use rerun::{
    Boxes2D, Image, LineStrips2D, Points2D, Scalars, SeriesLines, SeriesPoints, TextLog,
    Transform3D,
};

use crate::body_state::BodyState;

use super::colors::{
    entity_part, field_scale_ticks, normalize_field, vehicle_color, viridis, y_up_quaternion,
};
use super::{EventLevel, Recorder, RecordingError, check_finite};

/// Draw orders of the 2D layers (higher is drawn on top).
const DRAW_MERGE_SECTION: f32 = -20.0;
const DRAW_FIELD: f32 = -10.0;
const DRAW_ROAD: f32 = 0.0;
const DRAW_RECEIVED: f32 = 5.0;
const DRAW_PLANNED: f32 = 10.0;
const DRAW_VEHICLES: f32 = 20.0;

/// Width of the colour bar (pixels of its image; one per step of the scale).
pub(super) const COLOR_BAR_STEPS: u32 = 256;

/// Length (m, in the whole-road view's frame) that any road is scaled to fit: the view's fixed
/// bounds show [−10, `OVERVIEW_LENGTH_M` + 10] × [−`OVERVIEW_HALF_HEIGHT_M`, +…].
pub(super) const OVERVIEW_LENGTH_M: f64 = 750.0;
/// Half height (m) of the whole-road view's fixed bounds.
pub(super) const OVERVIEW_HALF_HEIGHT_M: f64 = 16.0;

/// The whole-road view's frame `world/overview` for a road whose bounds are `bounds_m`
/// (`[min, max]`, m): its origin at the bounds' left end (X) and vertical centre (Y), Y flipped
/// (up on screen), and scaled so that a road longer than [`OVERVIEW_LENGTH_M`] or higher than
/// twice [`OVERVIEW_HALF_HEIGHT_M`] fits the view's fixed bounds (a smaller one keeps
/// 1 m = 1 m). Returns (translation, scale): a world point p appears in the view at
/// scale · R⁻¹ (p − translation). On the straight merge road: the road's start and centre line.
pub(super) fn overview_frame(bounds_m: [[f64; 2]; 2]) -> ([f32; 3], f32) {
    let [lo, hi] = bounds_m;
    let length_m = hi[0] - lo[0];
    let height_m = hi[1] - lo[1];
    let by_length = if length_m.is_finite() && length_m > OVERVIEW_LENGTH_M {
        OVERVIEW_LENGTH_M / length_m
    } else {
        1.0
    };
    let by_height = if height_m.is_finite() && height_m > 2.0 * OVERVIEW_HALF_HEIGHT_M {
        2.0 * OVERVIEW_HALF_HEIGHT_M / height_m
    } else {
        1.0
    };
    let scale = by_length.min(by_height);
    // A road scaled by its height is centred along X in the view.
    let x0_m = if by_height < by_length {
        0.5 * (lo[0] + hi[0]) - 0.5 * OVERVIEW_LENGTH_M / scale
    } else {
        lo[0]
    };
    let centre_y_m = 0.5 * (lo[1] + hi[1]);
    ([x0_m as f32, centre_y_m as f32, 0.0], scale as f32)
}

/// Colour of event markers by level.
fn event_color(level: EventLevel) -> Color {
    match level {
        EventLevel::Debug => Color::from_rgb(150, 150, 150),
        EventLevel::Info => Color::from_rgb(60, 140, 230),
        EventLevel::Warn => Color::from_rgb(240, 170, 20),
        EventLevel::Error => Color::from_rgb(220, 30, 30),
    }
}

impl Recorder {
    /// Logs the road made of lanes (static): the drivable area's outer edges (solid), the
    /// dividers between same-direction lanes (dashed), the closed ends of lanes that end, the
    /// merge sections (the tapering stretch of each ending lane, a translucent band) and, with
    /// [`RecorderParams::lane_ids`](super::RecorderParams::lane_ids), each lane's id; and the
    /// static frame of the whole-road view.
    pub fn log_road(&mut self, lanes: &LaneRoad) -> Result<(), RecordingError> {
        let Some(active) = &mut self.active else {
            return Ok(());
        };
        active.lanes = Some(lanes.clone());
        let drawing = crate::road_drawing::RoadDrawing::new(lanes);
        let to_2d = |p: &[f64; 2]| [p[0] as f32, p[1] as f32];
        let strips = |lines: &[Vec<[f64; 2]>]| -> Vec<Vec<[f32; 2]>> {
            lines
                .iter()
                .map(|l| l.iter().map(to_2d).collect())
                .collect()
        };
        active.stream.log_static(
            "world/road/edges",
            &LineStrips2D::new(strips(&drawing.outer_edges))
                .with_colors([Color::from_rgb(230, 230, 230)])
                .with_radii([self.params.road_line_radius_m as f32])
                .with_draw_order(DRAW_ROAD),
        )?;
        active.stream.log_static(
            "world/road/divider",
            &LineStrips2D::new(strips(&drawing.divider_dashes()))
                .with_colors([Color::from_rgb(240, 200, 60)])
                .with_radii([0.5 * self.params.road_line_radius_m as f32])
                .with_draw_order(DRAW_ROAD),
        )?;
        if !drawing.closed_ends.is_empty() {
            let ends: Vec<Vec<[f64; 2]>> = drawing.closed_ends.iter().map(|e| e.to_vec()).collect();
            active.stream.log_static(
                "world/road/lane_ends",
                &LineStrips2D::new(strips(&ends))
                    .with_colors([Color::from_rgb(230, 60, 40)])
                    .with_radii([1.5 * self.params.road_line_radius_m as f32])
                    .with_draw_order(DRAW_ROAD),
            )?;
        }
        if !drawing.merge_section_centrelines.is_empty() {
            let (lines, radii): (Vec<Vec<[f32; 2]>>, Vec<f32>) = drawing
                .merge_section_centrelines
                .iter()
                .map(|(line, width)| (line.iter().map(to_2d).collect(), (0.5 * width) as f32))
                .unzip();
            active.stream.log_static(
                "world/road/merge_section",
                &LineStrips2D::new(lines)
                    .with_colors([Color::from_unmultiplied_rgba(255, 140, 0, 50)])
                    .with_radii(radii)
                    .with_draw_order(DRAW_MERGE_SECTION),
            )?;
        }
        if self.params.lane_ids {
            active.stream.log_static(
                "world/road/lane_ids",
                &Points2D::new(drawing.lane_labels.iter().map(|l| to_2d(&l.at_m)))
                    .with_labels(drawing.lane_labels.iter().map(|l| l.text.clone()))
                    .with_colors([Color::from_rgb(200, 200, 255)])
                    .with_radii([0.3_f32])
                    .with_show_labels(true)
                    .with_draw_order(DRAW_ROAD),
            )?;
        }
        // The frame's scale is the inverse of the view's: world lengths shrink by `scale`.
        let (translation, scale) = overview_frame(drawing.bounds_m);
        active.stream.log_static(
            "world/overview",
            &Transform3D::from_translation_rotation_scale(
                translation,
                y_up_quaternion(),
                1.0 / scale,
            ),
        )?;
        Ok(())
    }

    /// Logs the field's colour bar (static): a gradient image one unit high and
    /// `COLOR_BAR_STEPS` wide, with labelled ticks under it.
    pub(super) fn log_field_legend(&mut self) -> Result<(), RecordingError> {
        let Some(active) = &mut self.active else {
            return Ok(());
        };
        let scale = self.params.field_color_scale;
        let range = self.params.field_range;
        check_finite("log_field_legend", "field_range", &range)?;
        let steps = COLOR_BAR_STEPS;
        let mut rgba = Vec::with_capacity(4 * steps as usize);
        for k in 0..steps {
            let [r, g, b] = viridis(f64::from(k) / f64::from(steps - 1));
            rgba.extend_from_slice(&[r, g, b, 255]);
        }
        let width = f64::from(steps);
        // The bar is 256 × 12 scene units: x = position on the scale × 256.
        active.stream.log_static(
            "legend/field_scale",
            &Transform3D::from_scale([1.0, 12.0, 1.0]),
        )?;
        active.stream.log_static(
            "legend/field_scale/bar",
            &Image::from_rgba32(rgba, [steps, 1]),
        )?;
        let ticks = field_scale_ticks(scale, range);
        let scale_name = match scale {
            super::FieldColorScale::Linear => "linear",
            super::FieldColorScale::Log => "log",
        };
        active.stream.log_static(
            "legend/ticks",
            &Points2D::new(ticks.iter().map(|(t, _)| [(t * width) as f32, 18.0]))
                .with_labels(ticks.iter().map(|(_, v)| format!("{v}")))
                .with_colors([Color::from_rgb(230, 230, 230)])
                .with_radii([2.0]),
        )?;
        active.stream.log_static(
            "legend/title",
            &Points2D::new([[0.5 * width as f32, -6.0]])
                .with_labels([format!(
                    "potential U ({scale_name} scale, {} to {}; clamped outside)",
                    range[0], range[1]
                )])
                .with_radii([0.1]),
        )?;
        Ok(())
    }

    /// Logs the vehicles as boxes; `names[i]` labels `bodies[i]`. Also moves the follow frame
    /// to the vehicle named [`super::RecorderParams::follow`] if it is among them.
    pub fn log_vehicles(
        &mut self,
        bodies: &[BodyState],
        names: &[String],
    ) -> Result<(), RecordingError> {
        let Some(active) = &mut self.active else {
            return Ok(());
        };
        if names.len() != bodies.len() {
            return Err(RecordingError::InvalidInput {
                call: "log_vehicles",
                reason: format!("{} bodies but {} names", bodies.len(), names.len()),
            });
        }
        for body in bodies {
            if let Some((field, value)) = body.first_invalid_field() {
                return Err(RecordingError::InvalidInput {
                    call: "log_vehicles",
                    reason: format!("vehicle {}: {field} = {value}", body.id),
                });
            }
        }
        let centers = bodies.iter().map(|b| [b.x_m as f32, b.y_m as f32]);
        let half_sizes = bodies
            .iter()
            .map(|b| [(0.5 * b.length_m) as f32, (0.5 * b.width_m) as f32]);
        let colors: Vec<Color> = bodies
            .iter()
            .map(|b| {
                let [r, g, bl] = vehicle_color(b.id);
                Color::from_rgb(r, g, bl)
            })
            .collect();
        for (name, color) in names.iter().zip(&colors) {
            active.name_colors.insert(name.clone(), *color);
        }
        active.stream.log(
            "world/vehicles",
            &Boxes2D::from_centers_and_half_sizes(centers, half_sizes)
                .with_colors(colors)
                .with_labels(names.iter().map(String::as_str))
                .with_radii([self.params.vehicle_outline_radius_m as f32])
                .with_draw_order(DRAW_VEHICLES),
        )?;
        if let Some(body) = names
            .iter()
            .position(|n| *n == self.params.follow)
            .and_then(|i| bodies.get(i))
        {
            // Turned to the heading of the vehicle's lane (the nearest lane of the logged road),
            // so that the follow view turns along a curve: R = R_z(θ) · R_x(π) = (x, y, z, w)
            // (cos θ/2, sin θ/2, 0, 0); θ = 0 on a straight road along X (the plain Y flip).
            let heading_rad = active
                .lanes
                .as_ref()
                .filter(|_| body.x_m.is_finite() && body.y_m.is_finite())
                .map_or(0.0, |lanes| {
                    let hit = lanes.nearest_lane([body.x_m, body.y_m]);
                    lanes
                        .lane(hit.lane)
                        .map_or(0.0, |l| l.heading_rad(hit.frame.s_m))
                });
            let rotation = if heading_rad == 0.0 {
                y_up_quaternion()
            } else {
                let (s, c) = (0.5 * heading_rad).sin_cos();
                rerun::datatypes::Quaternion::from_xyzw([c as f32, s as f32, 0.0, 0.0])
            };
            active.stream.log(
                "world/follow",
                &Transform3D::from_translation_rotation(
                    [body.x_m as f32, body.y_m as f32, 0.0],
                    rotation,
                ),
            )?;
        }
        Ok(())
    }
    fn color_of(&self, name: &str) -> Color {
        self.active
            .as_ref()
            .and_then(|a| a.name_colors.get(name).copied())
            .unwrap_or(Color::from_rgb(200, 200, 200))
    }

    /// Logs the path a vehicle is tracking as a line strip with its points.
    pub fn log_planned_path(
        &mut self,
        name: &str,
        path: &[PathPoint],
    ) -> Result<(), RecordingError> {
        if self.active.is_none() {
            return Ok(());
        }
        for p in path {
            check_finite("log_planned_path", "a path point", &[p.x_m, p.y_m])?;
        }
        let color = self.color_of(name);
        let points: Vec<[f32; 2]> = path.iter().map(|p| [p.x_m as f32, p.y_m as f32]).collect();
        let base = format!("world/paths/{}", entity_part(name));
        let radius = self.params.path_line_radius_m as f32;
        let Some(active) = &mut self.active else {
            return Ok(());
        };
        active.stream.log(
            format!("{base}/planned"),
            &LineStrips2D::new([points.clone()])
                .with_colors([color])
                .with_radii([radius])
                .with_draw_order(DRAW_PLANNED),
        )?;
        active.stream.log(
            format!("{base}/planned_points"),
            &Points2D::new(points)
                .with_colors([color])
                .with_radii([2.5 * radius])
                .with_draw_order(DRAW_PLANNED),
        )?;
        Ok(())
    }

    /// Logs the shared local paths a vehicle has received (one strip per sender).
    pub fn log_received_paths(
        &mut self,
        name: &str,
        paths: &[SharedLocalPath],
    ) -> Result<(), RecordingError> {
        let Some(active) = &mut self.active else {
            return Ok(());
        };
        for slp in paths {
            for w in &slp.waypoints {
                check_finite("log_received_paths", "a waypoint", &[w.x_m, w.y_m])?;
            }
        }
        let strips = paths.iter().map(|slp| {
            slp.waypoints
                .iter()
                .map(|w| [w.x_m as f32, w.y_m as f32])
                .collect::<Vec<_>>()
        });
        let colors = paths.iter().map(|slp| {
            let [r, g, b] = vehicle_color(slp.vehicle_id);
            Color::from_unmultiplied_rgba(r, g, b, 140)
        });
        let labels = paths
            .iter()
            .map(|slp| format!("SLP from {}", slp.vehicle_id));
        active.stream.log(
            format!("world/paths/{}/received", entity_part(name)),
            &LineStrips2D::new(strips)
                .with_colors(colors)
                .with_labels(labels)
                .with_radii([0.5 * self.params.path_line_radius_m as f32])
                .with_draw_order(DRAW_RECEIVED),
        )?;
        Ok(())
    }

    /// Logs a potential field sampled on a grid as an image lying on the road, coloured on the
    /// recording's fixed scale.
    ///
    /// Image convention: the grid's corner is (x0_m, y0_m), cells are `cell_m` square, and
    /// `values[j * width + i]` is the value of cell (i, j), which covers
    /// [x0_m + i·cell_m, x0_m + (i + 1)·cell_m] × [y0_m + j·cell_m, y0_m + (j + 1)·cell_m]; the
    /// grid needs at least 2 × 2 cells. Non-finite values are drawn transparent.
    #[allow(clippy::too_many_arguments)]
    pub fn log_field(
        &mut self,
        name: &str,
        x0_m: f64,
        y0_m: f64,
        cell_m: f64,
        width: usize,
        height: usize,
        values: &[f64],
    ) -> Result<(), RecordingError> {
        let Some(active) = &mut self.active else {
            return Ok(());
        };
        check_finite("log_field", "the grid origin", &[x0_m, y0_m])?;
        if !(cell_m.is_finite() && cell_m > 0.0) {
            return Err(RecordingError::InvalidInput {
                call: "log_field",
                reason: format!("cell_m = {cell_m} must be finite and > 0"),
            });
        }
        if width < 2 || height < 2 || width.checked_mul(height) != Some(values.len()) {
            return Err(RecordingError::InvalidInput {
                call: "log_field",
                reason: format!(
                    "{width} x {height} grid (at least 2 x 2) but {} values",
                    values.len()
                ),
            });
        }
        let (Ok(w), Ok(h)) = (u32::try_from(width), u32::try_from(height)) else {
            return Err(RecordingError::InvalidInput {
                call: "log_field",
                reason: "grid too large".into(),
            });
        };
        let alpha = (self.params.field_opacity.clamp(0.0, 1.0) * 255.0).round() as u8;
        let mut rgba = Vec::with_capacity(4 * values.len());
        for t in normalize_field(
            values,
            self.params.field_color_scale,
            self.params.field_range,
        ) {
            match t {
                Some(t) => {
                    let [r, g, b] = viridis(t);
                    rgba.extend_from_slice(&[r, g, b, alpha]);
                }
                None => rgba.extend_from_slice(&[0, 0, 0, 0]),
            }
        }
        let path = format!("world/fields/{}", entity_part(name));
        active.stream.log(
            path.as_str(),
            &Transform3D::from_translation([x0_m as f32, y0_m as f32, 0.0]).with_scale([
                cell_m as f32,
                cell_m as f32,
                1.0,
            ]),
        )?;
        active.stream.log(
            path,
            &Image::from_rgba32(rgba, [w, h]).with_draw_order(DRAW_FIELD),
        )?;
        Ok(())
    }

    /// Logs one value per series for `name` (a vehicle) at the current time, on
    /// `plots/<series>/<name>`: one plot per series, one line per vehicle.
    pub fn log_scalars(
        &mut self,
        name: &str,
        values: &[(&str, f64)],
    ) -> Result<(), RecordingError> {
        if self.active.is_none() {
            return Ok(());
        }
        let color = self.color_of(name);
        let Some(active) = &mut self.active else {
            return Ok(());
        };
        for (series, value) in values {
            // A non-finite value is a gap in the plot, not an error of the run.
            if !value.is_finite() {
                continue;
            }
            let path = format!("plots/{}/{}", entity_part(series), entity_part(name));
            if !active.styled_series.contains(&path) {
                active.stream.log_static(
                    path.as_str(),
                    &SeriesLines::new().with_names([name]).with_colors([color]),
                )?;
                active.styled_series.insert(path.clone());
            }
            active.stream.log(path, &Scalars::single(*value))?;
        }
        Ok(())
    }

    /// Logs an event line (collision, near miss, lane change, planner fallback) at the current
    /// time, and a marker for it at the bottom of every time-series plot of the blueprint.
    pub fn log_event(&mut self, text: &str, level: EventLevel) -> Result<(), RecordingError> {
        let Some(active) = &mut self.active else {
            return Ok(());
        };
        active.stream.log(
            "events",
            &TextLog::new(text).with_level(level.as_text_log_level()),
        )?;
        if level == EventLevel::Debug {
            return Ok(());
        }
        for plot in &self.params.blueprint_series {
            let Some([y_min, _]) = plot.y_range else {
                continue;
            };
            let level_name = level.name();
            let path = format!("plots/{}/events/{level_name}", entity_part(&plot.series));
            if !active.styled_series.contains(&path) {
                active.stream.log_static(
                    path.as_str(),
                    &SeriesPoints::new()
                        .with_names([format!("{level_name} event")])
                        .with_colors([event_color(level)])
                        .with_markers([MarkerShape::Up])
                        .with_marker_sizes([8.0]),
                )?;
                active.styled_series.insert(path.clone());
            }
            active.stream.log(path, &Scalars::single(y_min))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mergesim_types::MergeRoad;

    fn bounds(road: &MergeRoad) -> [[f64; 2]; 2] {
        let lanes = road.lane_road().unwrap_or_else(|e| panic!("{e}"));
        crate::road_drawing::RoadDrawing::new(&lanes).bounds_m
    }

    /// Where a world point appears in the whole-road view: scale · R⁻¹ (p − translation), R the
    /// Y flip.
    fn in_view(road: &MergeRoad, x_m: f64, y_m: f64) -> (f64, f64) {
        let ([tx, ty, _], scale) = overview_frame(bounds(road));
        let s = f64::from(scale);
        (s * (x_m - f64::from(tx)), -s * (y_m - f64::from(ty)))
    }

    #[test]
    fn the_whole_road_view_shows_every_road_whole() {
        let urgent = MergeRoad::default();
        let platoon = MergeRoad {
            merge_start_x_m: 1300.0,
            merge_end_x_m: 1400.0,
            end_x_m: 3000.0,
            ..MergeRoad::default()
        };
        let short = MergeRoad {
            merge_start_x_m: 20.0,
            merge_end_x_m: 60.0,
            start_x_m: 0.0,
            end_x_m: 100.0,
            ..MergeRoad::default()
        };
        // A road up to 750 m long keeps 1 m = 1 m; a longer one is scaled down.
        assert_eq!(overview_frame(bounds(&urgent)).1, 1.0);
        assert_eq!(overview_frame(bounds(&short)).1, 1.0);
        assert!((f64::from(overview_frame(bounds(&platoon)).1) - 750.0 / 3050.0).abs() < 1e-6);
        for road in [urgent, platoon, short] {
            for x_m in [
                road.start_x_m,
                road.merge_start_x_m,
                road.merge_end_x_m,
                road.end_x_m,
            ] {
                for y_m in [road.y_bottom_m, road.y_upper_m()] {
                    let (x, y) = in_view(&road, x_m, y_m);
                    assert!(
                        (-10.0..=OVERVIEW_LENGTH_M + 10.0).contains(&x)
                            && (-OVERVIEW_HALF_HEIGHT_M..=OVERVIEW_HALF_HEIGHT_M).contains(&y),
                        "{road:?}: ({x_m}, {y_m}) appears at ({x}, {y})"
                    );
                }
            }
        }
    }

    /// A road on a 300 m-radius curve (600 m along its divider: 2 rad) is scaled by its
    /// height and every point of its edges appears within the view's fixed bounds.
    #[test]
    fn the_whole_road_view_shows_a_curved_road_whole() {
        let spec = mergesim_types::lanes::curved_merge_spec(&MergeRoad::default(), 300.0)
            .unwrap_or_else(|e| panic!("{e}"));
        let lanes = LaneRoad::new(&spec).unwrap_or_else(|e| panic!("{e}"));
        let drawing = crate::road_drawing::RoadDrawing::new(&lanes);
        let ([tx, ty, _], scale) = overview_frame(drawing.bounds_m);
        assert!(scale < 1.0);
        for p in drawing.outer_edges.iter().flatten() {
            let s = f64::from(scale);
            let (x, y) = (s * (p[0] - f64::from(tx)), -s * (p[1] - f64::from(ty)));
            assert!(
                (-10.0..=OVERVIEW_LENGTH_M + 10.0).contains(&x)
                    && (-OVERVIEW_HALF_HEIGHT_M - 1e-3..=OVERVIEW_HALF_HEIGHT_M + 1e-3)
                        .contains(&y),
                "{p:?} appears at ({x}, {y})"
            );
        }
    }
}
