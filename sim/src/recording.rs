//! Rerun recording of a run (`.rrd` file) with the `rerun` 0.36 Rust SDK.
//!
//! A [`Recorder`] either writes a file or does nothing ([`Recorder::disabled`]), so the world
//! loop can call it unconditionally. The file is written to `<path>.tmp` and renamed to `<path>`
//! only by [`Recorder::finish`]; a recorder dropped without `finish` (a run that failed)
//! removes its temporary file, so no half-written recording is ever left under the final name.
//!
//! # Entity layout
//! | entity | archetype | content |
//! |---|---|---|
//! | `world` | `ViewCoordinates` (static) | X forward along the road, Y left, Z up |
//! | `world/road/edges` | `LineStrips3D` (static) | upper edge, piecewise lower edge (Eq. 3) |
//! | `world/road/divider` | `LineStrips3D` (static) | lane divider up to the end of the merge |
//! | `world/road/merge_section` | `Boxes3D` (static) | translucent slab over the merge section |
//! | `world/vehicles` | `Boxes3D` | oriented boxes, label and colour per vehicle |
//! | `world/paths/<name>/planned` (+ `_points`) | `LineStrips3D`, `Points3D` | planned path |
//! | `world/paths/<name>/received` | `LineStrips3D` | shared local paths received over V2V |
//! | `world/fields/<name>` | `Mesh3D` | a potential field, colour-mapped, lying on the road |
//! | `plots/<series>/<name>` | `Scalars` (+ static `SeriesLines`) | one plot per series |
//! | `events` | `TextLog` | collisions, near misses, planner fallbacks |
//!
//! All temporal data is on the duration timeline `sim_time` (seconds of simulated time).
//!
//! # Potential fields
//! A field is logged as a `Mesh3D` grid in world coordinates, its vertices at the sample points
//! and coloured with viridis, lying just below the road plane: it renders in the same 3D view as
//! the road, the vehicles and the paths, at the right place and scale, with no camera or
//! image-to-world transform needed (a 2D image would need its own view and lose the overlay).
//!
//! # Blueprint
//! The 0.36 Rust SDK supports blueprints (marked experimental): the file starts with a default
//! layout — the 3D road view over the event log on the left, one time-series view per series on
//! the right. Disable it with [`RecorderParams::blueprint`].

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use rerun::blueprint::{
    Blueprint, ContainerLike, Horizontal, Spatial3DView, TextLogView, TimeSeriesView, Vertical,
};
use rerun::components::{Color, FillMode, TextLogLevel};
use rerun::datatypes::Quaternion;
use rerun::{
    Boxes3D, LineStrips3D, Mesh3D, Points3D, RecordingStream, RecordingStreamBuilder, Scalars,
    SeriesLines, TextLog, ViewCoordinates,
};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use planner::{MergeRoad, PathPoint, SharedLocalPath, VehicleId};

use crate::body_state::BodyState;

/// Name of the timeline all temporal data is logged on.
pub const SIM_TIMELINE: &str = "sim_time";

/// How field values are mapped to colours.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FieldColorScale {
    /// (v − min) / (max − min).
    Linear,
    /// ln(1 + v − min) / ln(1 + max − min): potential fields span orders of magnitude near the
    /// road edges (Eq. 3 diverges there), so a linear map would show one bright line.
    Log,
}

/// Options of the recording.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RecorderParams {
    /// Write a default viewer layout into the file.
    pub blueprint: bool,
    /// The series that get their own time-series view in the blueprint (in this order).
    pub blueprint_series: Vec<String>,
    /// Colour scale of potential fields.
    pub field_color_scale: FieldColorScale,
    /// Height at which fields are drawn (m); slightly below the road so boxes stay visible.
    pub field_z_m: f64,
    /// Height at which road lines and paths are drawn (m).
    pub line_z_m: f64,
    /// Radius of the road lines (m).
    pub road_line_radius_m: f64,
    /// Radius of the path lines (m).
    pub path_line_radius_m: f64,
}

impl Default for RecorderParams {
    fn default() -> Self {
        Self {
            blueprint: true,
            blueprint_series: [
                "sideslip_rad",
                "yaw_rad",
                "yaw_rate_radps",
                "speed_mps",
                "planned_speed_mps",
            ]
            .map(String::from)
            .to_vec(),
            field_color_scale: FieldColorScale::Log,
            field_z_m: -0.02,
            line_z_m: 0.03,
            road_line_radius_m: 0.08,
            path_line_radius_m: 0.06,
        }
    }
}

/// Severity of a logged event.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EventLevel {
    /// Diagnostics.
    Debug,
    /// Normal events (e.g. a vehicle passed the merge point).
    Info,
    /// Near misses, planner fallbacks.
    Warn,
    /// Collisions, road-edge contacts.
    Error,
}

impl EventLevel {
    fn as_text_log_level(self) -> TextLogLevel {
        TextLogLevel::from(match self {
            Self::Debug => TextLogLevel::DEBUG,
            Self::Info => TextLogLevel::INFO,
            Self::Warn => TextLogLevel::WARN,
            Self::Error => TextLogLevel::ERROR,
        })
    }
}

/// Everything that can go wrong while recording. Never a panic.
#[derive(Debug, Error)]
pub enum RecordingError {
    /// The Rerun SDK could not create the stream or log data.
    #[error("rerun: {0}")]
    Rerun(#[from] rerun::RecordingStreamError),
    /// Flushing the stream to the file failed.
    #[error("rerun flush: {0}")]
    Flush(#[from] rerun::sink::SinkFlushError),
    /// Renaming or removing the file failed.
    #[error("file {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// Bad input to a log call (mismatched lengths, non-finite numbers, empty names).
    #[error("invalid input to {call}: {reason}")]
    InvalidInput {
        /// The method.
        call: &'static str,
        /// What is wrong.
        reason: String,
    },
}

struct ActiveRecording {
    stream: RecordingStream,
    tmp_path: PathBuf,
    final_path: PathBuf,
    /// Series entities whose static `SeriesLines` style has been logged.
    styled_series: BTreeSet<String>,
    /// Colour of each vehicle name seen in `log_vehicles`.
    name_colors: BTreeMap<String, Color>,
}

/// Writes a Rerun recording, or does nothing when disabled.
pub struct Recorder {
    params: RecorderParams,
    active: Option<ActiveRecording>,
}

/// Colours of vehicles by id: the paper's green ego and blue obstacle first, then the
/// Tableau-10 palette.
const VEHICLE_PALETTE: [[u8; 3]; 8] = [
    [44, 160, 44],
    [31, 119, 180],
    [255, 127, 14],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [188, 189, 34],
];

/// Viridis sampled at nine evenly spaced points (matplotlib), interpolated linearly.
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// The palette colour of vehicle `id`.
pub fn vehicle_color(id: VehicleId) -> [u8; 3] {
    VEHICLE_PALETTE[(id as usize) % VEHICLE_PALETTE.len()]
}

/// Viridis colour of `t` in [0, 1] (clamped).
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let scaled = t * (VIRIDIS.len() - 1) as f64;
    let i = (scaled.floor() as usize).min(VIRIDIS.len() - 2);
    let f = scaled - i as f64;
    let mut out = [0u8; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let a = f64::from(VIRIDIS[i][c]);
        let b = f64::from(VIRIDIS[i + 1][c]);
        *o = (a + f * (b - a)).round() as u8;
    }
    out
}

/// Maps `values` to [0, 1] with `scale`; non-finite values map to `None`.
pub fn normalize_field(values: &[f64], scale: FieldColorScale) -> Vec<Option<f64>> {
    let finite = values.iter().copied().filter(|v| v.is_finite());
    let min = finite.clone().fold(f64::INFINITY, f64::min);
    let max = finite.fold(f64::NEG_INFINITY, f64::max);
    let range = max - min;
    values
        .iter()
        .map(|&v| {
            if !v.is_finite() {
                return None;
            }
            if !range.is_finite() || range <= 0.0 {
                return Some(0.0);
            }
            Some(match scale {
                FieldColorScale::Linear => (v - min) / range,
                FieldColorScale::Log => (v - min).ln_1p() / range.ln_1p(),
            })
        })
        .collect()
}

/// Turns a free-form name into one entity-path part: ASCII letters, digits, `_` and `-` kept,
/// everything else replaced by `_`.
pub fn entity_part(name: &str) -> String {
    let part: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if part.is_empty() { "_".into() } else { part }
}

fn yaw_quaternion(yaw_rad: f64) -> Quaternion {
    let half = 0.5 * yaw_rad;
    Quaternion::from_xyzw([0.0, 0.0, half.sin() as f32, half.cos() as f32])
}

fn check_finite(call: &'static str, what: &str, values: &[f64]) -> Result<(), RecordingError> {
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        return Err(RecordingError::InvalidInput {
            call,
            reason: format!("{what} is not finite ({v})"),
        });
    }
    Ok(())
}

impl Recorder {
    /// A recorder that records nothing; every call is a cheap no-op.
    pub fn disabled() -> Self {
        Self {
            params: RecorderParams::default(),
            active: None,
        }
    }

    /// Starts a recording to `path` (written as `<path>.tmp` until [`Self::finish`]) with the
    /// default parameters.
    pub fn new_file(path: impl AsRef<Path>, app_id: &str) -> Result<Self, RecordingError> {
        Self::new_file_with_params(path, app_id, RecorderParams::default())
    }

    /// Starts a recording to `path` with `params`.
    pub fn new_file_with_params(
        path: impl AsRef<Path>,
        app_id: &str,
        params: RecorderParams,
    ) -> Result<Self, RecordingError> {
        let final_path = path.as_ref().to_path_buf();
        let mut tmp_name = final_path.as_os_str().to_owned();
        tmp_name.push(".tmp");
        let tmp_path = PathBuf::from(tmp_name);

        // `enabled(true)`: an explicit file recording is not switched off by the `RERUN`
        // environment variable; use `Recorder::disabled` for that.
        let app_id =
            rerun::ApplicationId::try_new(app_id).map_err(|e| RecordingError::InvalidInput {
                call: "new_file",
                reason: e.to_string(),
            })?;
        let mut builder = RecordingStreamBuilder::new(app_id).enabled(true);
        if params.blueprint {
            builder = builder.with_default_blueprint(Self::blueprint(&params));
        }
        let stream = builder.save(&tmp_path)?;
        stream.log_static("world", &ViewCoordinates::RIGHT_HAND_Z_UP())?;
        Ok(Self {
            params,
            active: Some(ActiveRecording {
                stream,
                tmp_path,
                final_path,
                styled_series: BTreeSet::new(),
                name_colors: BTreeMap::new(),
            }),
        })
    }

    /// The default layout: road 3D view over the event log, time series on the right.
    fn blueprint(params: &RecorderParams) -> Blueprint {
        let plots: Vec<ContainerLike> = params
            .blueprint_series
            .iter()
            .map(|series| {
                TimeSeriesView::new(series.clone())
                    .with_origin(format!("/plots/{}", entity_part(series)))
                    .into()
            })
            .collect();
        let left = Vertical::new([
            Spatial3DView::new("Road").with_origin("/world").into(),
            TextLogView::new("Events").with_origin("/events").into(),
        ])
        .with_row_shares([3.0, 1.0]);
        let root = if plots.is_empty() {
            Horizontal::new([left.into()])
        } else {
            Horizontal::new([left.into(), Vertical::new(plots).into()])
                .with_column_shares([3.0, 2.0])
        };
        Blueprint::new(root)
            .with_auto_views(false)
            .with_auto_layout(false)
    }

    /// Whether this recorder writes anything.
    pub fn is_enabled(&self) -> bool {
        self.active.is_some()
    }

    /// The temporary file being written, if enabled.
    pub fn tmp_path(&self) -> Option<&Path> {
        self.active.as_ref().map(|a| a.tmp_path.as_path())
    }

    /// Sets the current time of the `sim_time` timeline (s).
    pub fn set_time(&self, t_s: f64) -> Result<(), RecordingError> {
        let Some(active) = &self.active else {
            return Ok(());
        };
        check_finite("set_time", "t_s", &[t_s])?;
        active.stream.set_duration_secs(SIM_TIMELINE, t_s);
        Ok(())
    }

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

    /// Flushes and closes the file, then renames `<path>.tmp` to `<path>`.
    pub fn finish(mut self) -> Result<(), RecordingError> {
        let Some(active) = self.active.take() else {
            return Ok(());
        };
        let ActiveRecording {
            stream,
            tmp_path,
            final_path,
            ..
        } = active;
        let flushed = stream.flush_blocking();
        // Replaces the file sink; its writer thread writes the footer and closes the file
        // before this returns.
        stream.finalize_deferred_sinks();
        drop(stream);
        if let Err(err) = flushed {
            std::fs::remove_file(&tmp_path).ok();
            return Err(err.into());
        }
        std::fs::rename(&tmp_path, &final_path).map_err(|source| {
            std::fs::remove_file(&tmp_path).ok();
            RecordingError::Io {
                path: final_path.clone(),
                source,
            }
        })
    }
}

impl Drop for Recorder {
    /// A recorder dropped without [`Recorder::finish`] belongs to a failed run: close the
    /// stream and delete the temporary file.
    fn drop(&mut self) {
        if let Some(active) = self.active.take() {
            active.stream.finalize_deferred_sinks();
            drop(active.stream);
            std::fs::remove_file(&active.tmp_path).ok();
        }
    }
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder")
            .field("tmp_path", &self.tmp_path())
            .finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_hits_its_control_points_and_clamps() {
        assert_eq!(viridis(0.0), VIRIDIS[0]);
        assert_eq!(viridis(1.0), VIRIDIS[8]);
        assert_eq!(viridis(0.5), VIRIDIS[4]);
        assert_eq!(viridis(-3.0), VIRIDIS[0]);
        assert_eq!(viridis(f64::NAN), VIRIDIS[0]);
        // Half way between two control points is their mean.
        let mid = viridis(1.0 / 16.0);
        for c in 0..3 {
            let expected = 0.5 * (f64::from(VIRIDIS[0][c]) + f64::from(VIRIDIS[1][c]));
            assert!((f64::from(mid[c]) - expected).abs() <= 0.5);
        }
    }

    #[test]
    fn normalize_field_maps_min_and_max() {
        let v = [2.0, 4.0, f64::NAN, 10.0];
        let lin = normalize_field(&v, FieldColorScale::Linear);
        assert_eq!(lin, vec![Some(0.0), Some(0.25), None, Some(1.0)]);
        let log = normalize_field(&v, FieldColorScale::Log);
        let expected = 3.0_f64.ln() / 9.0_f64.ln();
        assert!((log[1].unwrap() - expected).abs() < 1e-12);
        assert_eq!(log[3], Some(1.0));
        assert_eq!(
            normalize_field(&[5.0, 5.0], FieldColorScale::Log),
            vec![Some(0.0); 2]
        );
    }

    #[test]
    fn entity_parts_are_sanitised() {
        assert_eq!(entity_part("ego car/1"), "ego_car_1");
        assert_eq!(entity_part("yaw_rate_radps"), "yaw_rate_radps");
        assert_eq!(entity_part(""), "_");
    }

    #[test]
    fn yaw_quaternion_rotates_x_onto_heading() {
        let yaw = 0.7_f64;
        let [x, y, z, w] = yaw_quaternion(yaw).xyzw().map(f64::from);
        // Rotate (1, 0, 0) by q: first column of the rotation matrix.
        let rx = 1.0 - 2.0 * (y * y + z * z);
        let ry = 2.0 * (x * y + w * z);
        assert!((rx - yaw.cos()).abs() < 1e-6 && (ry - yaw.sin()).abs() < 1e-6);
    }
}
