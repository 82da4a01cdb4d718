//! What the recording logs: the road, the vehicles' boxes, planned and received paths, the
//! potential fields, time series and events.

use mergesim_types::{MergeRoad, PathPoint, SharedLocalPath};
use rerun::components::{Color, FillMode};
use rerun::{Boxes3D, LineStrips3D, Mesh3D, Points3D, Scalars, SeriesLines, TextLog};

use crate::body_state::BodyState;

use super::colors::{entity_part, normalize_field, vehicle_color, viridis, yaw_quaternion};
use super::{EventLevel, Recorder, RecordingError, check_finite};

impl Recorder {
    /// Logs the road (static): edges, lane divider and the merge section.
    pub fn log_road(&mut self, road: &MergeRoad) -> Result<(), RecordingError> {
        let Some(active) = &self.active else {
            return Ok(());
        };
        road.validate().map_err(|e| RecordingError::InvalidInput {
            call: "log_road",
            reason: e.to_string(),
        })?;
        let z = self.params.line_z_m as f32;
        let to_3d = |p: &[f64; 2]| [p[0] as f32, p[1] as f32, z];
        let upper: Vec<[f32; 3]> = road.upper_edge_polyline().iter().map(to_3d).collect();
        let lower: Vec<[f32; 3]> = road.lower_edge_polyline().iter().map(to_3d).collect();
        active.stream.log_static(
            "world/road/edges",
            &LineStrips3D::new([upper, lower])
                .with_colors([Color::from_rgb(230, 230, 230)])
                .with_radii([self.params.road_line_radius_m as f32])
                .with_labels(["upper edge", "lower edge"]),
        )?;
        let y_lane = road.y_lane_m() as f32;
        active.stream.log_static(
            "world/road/divider",
            &LineStrips3D::new([[
                [road.start_x_m as f32, y_lane, z],
                [road.merge_end_x_m as f32, y_lane, z],
            ]])
            .with_colors([Color::from_rgb(240, 200, 60)])
            .with_radii([0.5 * self.params.road_line_radius_m as f32]),
        )?;
        let half_length = 0.5 * (road.merge_end_x_m - road.merge_start_x_m);
        let half_width = 0.5 * (road.y_upper_m() - road.y_bottom_m);
        active.stream.log_static(
            "world/road/merge_section",
            &Boxes3D::from_centers_and_half_sizes(
                [[
                    (road.merge_start_x_m + half_length) as f32,
                    (road.y_bottom_m + half_width) as f32,
                    // Under the potential-field grids, so it does not tint them.
                    (self.params.field_z_m - 0.1) as f32,
                ]],
                [[half_length as f32, half_width as f32, 0.005]],
            )
            .with_colors([Color::from_unmultiplied_rgba(255, 140, 0, 50)])
            .with_fill_mode(FillMode::Solid)
            .with_labels(["merge section"]),
        )?;
        Ok(())
    }

    /// Logs the vehicles as oriented boxes; `names[i]` labels `bodies[i]`.
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
        let centers = bodies
            .iter()
            .map(|b| [b.x_m as f32, b.y_m as f32, (0.5 * b.height_m) as f32]);
        let half_sizes = bodies.iter().map(|b| {
            [
                (0.5 * b.length_m) as f32,
                (0.5 * b.width_m) as f32,
                (0.5 * b.height_m) as f32,
            ]
        });
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
            &Boxes3D::from_centers_and_half_sizes(centers, half_sizes)
                .with_quaternions(bodies.iter().map(|b| yaw_quaternion(b.yaw_rad)))
                .with_colors(colors)
                .with_labels(names.iter().map(String::as_str))
                .with_fill_mode(FillMode::Solid),
        )?;
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
        let z = self.params.line_z_m as f32;
        let points: Vec<[f32; 3]> = path
            .iter()
            .map(|p| [p.x_m as f32, p.y_m as f32, z])
            .collect();
        let base = format!("world/paths/{}", entity_part(name));
        let radius = self.params.path_line_radius_m as f32;
        let Some(active) = &self.active else {
            return Ok(());
        };
        active.stream.log(
            format!("{base}/planned"),
            &LineStrips3D::new([points.clone()])
                .with_colors([color])
                .with_radii([radius]),
        )?;
        active.stream.log(
            format!("{base}/planned_points"),
            &Points3D::new(points)
                .with_colors([color])
                .with_radii([2.5 * radius]),
        )?;
        Ok(())
    }

    /// Logs the shared local paths a vehicle has received (one strip per sender).
    pub fn log_received_paths(
        &mut self,
        name: &str,
        paths: &[SharedLocalPath],
    ) -> Result<(), RecordingError> {
        let Some(active) = &self.active else {
            return Ok(());
        };
        for slp in paths {
            for w in &slp.waypoints {
                check_finite("log_received_paths", "a waypoint", &[w.x_m, w.y_m])?;
            }
        }
        let z = (self.params.line_z_m + 0.02) as f32;
        let strips = paths.iter().map(|slp| {
            slp.waypoints
                .iter()
                .map(|w| [w.x_m as f32, w.y_m as f32, z])
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
            &LineStrips3D::new(strips)
                .with_colors(colors)
                .with_labels(labels)
                .with_radii([0.5 * self.params.path_line_radius_m as f32]),
        )?;
        Ok(())
    }

    /// Logs a potential field sampled on a grid as a colour-mapped mesh lying on the road.
    ///
    /// Image convention: the grid's corner is (x0_m, y0_m), cells are `cell_m` square, and
    /// `values[j * width + i]` is the value of cell (i, j), whose centre
    /// (x0_m + (i + ½)·cell_m, y0_m + (j + ½)·cell_m) becomes a mesh vertex; the grid needs at
    /// least 2 × 2 cells. Non-finite values are drawn transparent.
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
        let Some(active) = &self.active else {
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
        let (Ok(w), Ok(_)) = (u32::try_from(width), u32::try_from(values.len())) else {
            return Err(RecordingError::InvalidInput {
                call: "log_field",
                reason: "grid too large".into(),
            });
        };
        // One height per vehicle (in name order), so overlapping fields do not z-fight.
        let layer = active
            .name_colors
            .keys()
            .position(|n| n == name)
            .unwrap_or(active.name_colors.len());
        let z = (self.params.field_z_m - 0.01 * layer as f64) as f32;
        let positions = (0..height).flat_map(|j| {
            (0..width).map(move |i| {
                [
                    (x0_m + (i as f64 + 0.5) * cell_m) as f32,
                    (y0_m + (j as f64 + 0.5) * cell_m) as f32,
                    z,
                ]
            })
        });
        let colors: Vec<Color> = normalize_field(values, self.params.field_color_scale)
            .into_iter()
            .map(|t| match t {
                Some(t) => {
                    let [r, g, b] = viridis(t);
                    Color::from_rgb(r, g, b)
                }
                None => Color::TRANSPARENT,
            })
            .collect();
        let mut triangles = Vec::with_capacity(2 * (width - 1) * (height - 1));
        for j in 0..(height as u32 - 1) {
            for i in 0..(w - 1) {
                let v00 = j * w + i;
                let v10 = v00 + 1;
                let v01 = v00 + w;
                let v11 = v01 + 1;
                triangles.push([v00, v10, v11]);
                triangles.push([v00, v11, v01]);
            }
        }
        active.stream.log(
            format!("world/fields/{}", entity_part(name)),
            &Mesh3D::new(positions)
                .with_vertex_colors(colors)
                .with_triangle_indices(triangles),
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

    /// Logs an event line (collision, near miss, planner fallback) at the current time.
    pub fn log_event(&mut self, text: &str, level: EventLevel) -> Result<(), RecordingError> {
        let Some(active) = &self.active else {
            return Ok(());
        };
        active.stream.log(
            "events",
            &TextLog::new(text).with_level(level.as_text_log_level()),
        )?;
        Ok(())
    }
}
