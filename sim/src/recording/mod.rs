//! Rerun recording of a run (`.rrd` file) with the `rerun` 0.36 Rust SDK.
//!
//! Built only with the cargo feature `rerun` (on by default); without it, which spares the
//! Rerun SDK's ~500 crates, [`Recorder::disabled`] works as always and
//! [`Recorder::new_file_with_params`] returns [`RecordingError::Unsupported`].
//!
//! A [`Recorder`] either writes a file or does nothing ([`Recorder::disabled`]), so the world
//! loop can call it unconditionally. The file is written to `<path>.tmp` and renamed to `<path>`
//! only by [`Recorder::finish`]; a recorder dropped without `finish` (a run that failed)
//! removes its temporary file, so no half-written recording is ever left under the final name.
//!
//! # Entity layout
//! Everything is drawn top-down in 2D, in road coordinates (X forward along the road, Y to the
//! left, metres); the views turn Y upwards on screen.
//!
//! | entity | archetype | content |
//! |---|---|---|
//! | `world/road/edges` | `LineStrips2D` (static) | the drivable area's outer edges, solid (any road of lanes, curved or not; on the merge road the upper edge and the piecewise lower edge of Eq. 3) |
//! | `world/road/divider` | `LineStrips2D` (static) | the dividers between same-direction lanes, dashed (4 m dashes, 4 m gaps) |
//! | `world/road/lane_ends` | `LineStrips2D` (static) | closed ends of lanes that end (a taper's tip has none); only if there are any |
//! | `world/road/merge_section` | `LineStrips2D` (static) | translucent band along the tapering stretch of each lane that ends |
//! | `world/road/lane_ids` | `Points2D` (static) | each lane's id at half its length (only with `RecorderParams::lane_ids`) |
//! | `world/vehicles` | `Boxes2D` | one box (length × width, axis-aligned), label and colour per vehicle |
//! | `world/recorded_vehicles` | `Boxes2D` | one grey box and label per recorded vehicle present (recorded traffic; empty when none) |
//! | `world/paths/<name>/planned` (+ `_points`) | `LineStrips2D`, `Points2D` | planned path |
//! | `world/paths/<name>/received` | `LineStrips2D` | shared local paths received over V2V |
//! | `world/fields/<name>` | `Image` (RGBA) + `Transform3D` | a potential field on the fixed colour scale, under the rest |
//! | `world/follow` | `Transform3D` | a frame at the followed vehicle, Y flipped: the follow view's origin |
//! | `world/overview` | `Transform3D` (static) | the road frame (origin at the road's start and centre line, Y flipped, roads longer than 750 m scaled down to 750 m): the whole-road view's origin, so its fixed bounds show the whole of any road |
//! | `legend/field_scale` | `Image`, `Points2D` (static) | the field's colour bar and its labelled ticks |
//! | `plots/<series>/<name>` | `Scalars` (+ static `SeriesLines`) | one plot per series |
//! | `plots/<series>/events/<level>` | `Scalars` (+ static `SeriesPoints`) | a marker per event (info, warn, error), at the plot's lower y bound |
//! | `events` | `TextLog` | collisions, near misses, lane changes, planner fallbacks |
//!
//! All temporal data is on the duration timeline `sim_time` (seconds of simulated time).
//! Vehicles are axis-aligned boxes (`Boxes2D` has no rotation): on a highway |yaw| stays below
//! ~0.1 rad, which moves a corner by less than 0.25 m; the yaw is in its own plot.
//!
//! # Following a vehicle
//! Rerun 0.36 has no follow camera and a view's visual bounds are a blueprint value, not a
//! temporal one. The recording therefore logs, at every logged instant, the transform of
//! `world/follow` (translation = the followed vehicle's position, rotation = the heading θ of
//! its lane (the nearest lane of the road given to `log_road`) about Z, then 180° about X, which
//! turns Y up on screen; θ = 0 on the straight merge road), so the follow view turns along a
//! curve. The "Follow" view has `world/follow` as its origin, so Rerun draws
//! everything under `world` in that frame: the followed vehicle stays at (0, 0) and the visual
//! bounds ([`RecorderParams::follow_window_m`]) form a fixed window around it. The "Whole road"
//! view has the static frame `world/overview` as its origin.
//!
//! # Potential fields
//! A field is an RGBA image placed on the road by its transform (translation = the grid's corner,
//! scale = the cell size), under the vehicles and paths. Its colours are on one **fixed** scale
//! for the whole run and every vehicle ([`FieldColorScale`], [`RecorderParams::field_range`]),
//! so a colour is a value: the colour bar `legend/field_scale` (its own view, "Field scale")
//! shows the scale with labelled ticks; values outside the range are clamped.
//!
//! # Blueprint
//! The file starts with a default layout: the follow view over the whole-road view, the field's
//! colour bar and the event log on the left, one time-series view per series (title with units,
//! fixed y range, legend in a corner) on the right. It is written as the archetypes the SDK's
//! blueprint builders write (views, containers, viewport, panels) plus the view properties they
//! cannot set (visual bounds, axes, legends), with fixed ids (`blueprint`).
//! Disable the blueprint with [`RecorderParams::blueprint`].
//!
//! # The same bytes for the same run
//! The file is written by `rrd_writer`, not by the SDK's `RecordingStream`: row and chunk ids
//! count up from 1, the recording id is the file's name, the only timeline is `sim_time` (data
//! logged before the first [`Recorder::set_time`] is at 0), chunks are cut by rows and bytes
//! (never by a timer) and the footer's stores come in a fixed order. So the same run gives the
//! same bytes on any machine and any thread count (`tests/recording_bytes.rs`).

#[cfg(feature = "rerun")]
mod blueprint;
mod colors;
#[cfg(feature = "rerun")]
mod entities;
#[cfg(feature = "rerun")]
mod recorded_entities;
#[cfg(feature = "rerun")]
mod rerun_file;
#[cfg(feature = "rerun")]
mod rrd_writer;
pub mod size_estimate;
#[cfg(not(feature = "rerun"))]
mod without_rerun;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use thiserror::Error;

#[cfg(feature = "rerun")]
use rerun_file::ActiveRecording;
#[cfg(not(feature = "rerun"))]
use without_rerun::ActiveRecording;

/// Name of the timeline all temporal data is logged on.
pub const SIM_TIMELINE: &str = "sim_time";

/// How field values are mapped to colours, between the fixed bounds
/// [`RecorderParams::field_range`] = [lo, hi] (values outside are clamped).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FieldColorScale {
    /// (v − lo) / (hi − lo).
    Linear,
    /// ln(1 + v − lo) / ln(1 + hi − lo): potential fields span orders of magnitude near the
    /// road edges (Eq. 3 diverges there), so a linear map would show one bright line.
    Log,
}

/// One time-series view of the blueprint.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeriesPlot {
    /// The series (`plots/<series>/...`).
    pub series: String,
    /// The view's title, with the unit.
    pub title: String,
    /// The initial y range [min, max] in the series' unit (`None`: fit the data).
    pub y_range: Option<[f64; 2]>,
}

impl SeriesPlot {
    fn new(series: &str, title: &str, y_range: [f64; 2]) -> Self {
        Self {
            series: series.into(),
            title: title.into(),
            y_range: Some(y_range),
        }
    }
}

/// The window of the follow view around the followed vehicle (m, road axes).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FollowWindow {
    /// Road shown behind the vehicle (m).
    pub behind_m: f64,
    /// Road shown ahead of the vehicle (m).
    pub ahead_m: f64,
    /// Road shown to each side of the vehicle (m).
    pub side_m: f64,
}

impl Default for FollowWindow {
    fn default() -> Self {
        Self {
            behind_m: 30.0,
            ahead_m: 50.0,
            side_m: 6.0,
        }
    }
}

/// Options of the recording.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RecorderParams {
    /// Write a default viewer layout into the file.
    pub blueprint: bool,
    /// The time-series views of the blueprint (in this order).
    pub blueprint_series: Vec<SeriesPlot>,
    /// The vehicle the follow view keeps in its window (`merge_sim run --follow`, which refuses
    /// an unknown name). If no logged vehicle has this name, `world/follow` is never logged and
    /// the follow view shows nothing.
    pub follow: String,
    /// The follow view's window around that vehicle.
    pub follow_window_m: FollowWindow,
    /// Colour scale of potential fields.
    pub field_color_scale: FieldColorScale,
    /// The fixed value range [lo, hi] of the field's colour scale (the potential U is
    /// dimensionless). The default covers the recorded fields of the built-in scenarios
    /// (measured 2026-12-02 on `urgent_merge` and `dense_merge`: 0.01 to 201, median ~35; the
    /// attractive bowl dominates far from the vehicle); larger values are clamped.
    pub field_range: [f64; 2],
    /// Opacity of the field images, 0 to 1 (the road lines and vehicles stay visible over it).
    pub field_opacity: f64,
    /// Radius of the vehicles' box outlines (m).
    pub vehicle_outline_radius_m: f64,
    /// Radius of the road lines (m).
    pub road_line_radius_m: f64,
    /// Radius of the path lines (m).
    pub path_line_radius_m: f64,
    /// Potential fields and received shared paths are recorded for the first this many
    /// vehicles (by id) only; `None`: for all. Boxes, planned paths, time series and events are
    /// recorded for every vehicle. Both grow with the number of vehicles (received paths with
    /// its square): with 50 vehicles the size estimate puts a 72 s recording at ~0.5 GB.
    pub detail_vehicles: Option<usize>,
    /// Write each lane's id on the road (`world/road/lane_ids`; `merge_sim run --lane-ids`).
    pub lane_ids: bool,
}

/// Vehicles whose fields and received paths are recorded by default (every built-in scenario
/// but the dense merge and the platoon has at most this many).
pub(crate) const DEFAULT_DETAIL_VEHICLES: usize = 4;

impl Default for RecorderParams {
    fn default() -> Self {
        Self {
            blueprint: true,
            blueprint_series: vec![
                SeriesPlot::new("speed_mps", "Speed (m/s)", [0.0, 30.0]),
                SeriesPlot::new("planned_speed_mps", "Planned speed (m/s)", [0.0, 30.0]),
                SeriesPlot::new("yaw_rad", "Yaw (rad)", [-0.1, 0.1]),
                SeriesPlot::new("yaw_rate_radps", "Yaw rate (rad/s)", [-0.2, 0.2]),
                SeriesPlot::new("sideslip_rad", "Sideslip (rad)", [-0.02, 0.02]),
            ],
            follow: "ego".into(),
            follow_window_m: FollowWindow::default(),
            field_color_scale: FieldColorScale::Log,
            field_range: [0.0, 200.0],
            field_opacity: 0.6,
            vehicle_outline_radius_m: 0.15,
            road_line_radius_m: 0.08,
            path_line_radius_m: 0.06,
            detail_vehicles: Some(DEFAULT_DETAIL_VEHICLES),
            lane_ids: false,
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

/// Everything that can go wrong while recording. Never a panic.
#[derive(Debug, Error)]
pub enum RecordingError {
    /// The Rerun SDK could not create the stream or log data.
    #[cfg(feature = "rerun")]
    #[error("rerun: {0}")]
    Rerun(#[from] rerun::RecordingStreamError),
    /// Flushing the stream to the file failed.
    #[cfg(feature = "rerun")]
    #[error("rerun flush: {0}")]
    Flush(#[from] rerun::sink::SinkFlushError),
    /// This build has no Rerun support (built without the cargo feature `rerun`).
    #[error(
        "this merge_sim was built without recording support (cargo feature `rerun`, on by \
         default): run with --no-rrd, or rebuild with the default features"
    )]
    Unsupported,
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

/// Writes a Rerun recording, or does nothing when disabled.
pub struct Recorder {
    params: RecorderParams,
    active: Option<ActiveRecording>,
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

    /// The recording's parameters.
    pub fn params(&self) -> &RecorderParams {
        &self.params
    }

    /// Whether this recorder writes anything.
    pub fn is_enabled(&self) -> bool {
        self.active.is_some()
    }
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder")
            .field("tmp_path", &self.tmp_path())
            .finish_non_exhaustive()
    }
}

/// An error naming `call` if any of `values` is not finite.
#[cfg(feature = "rerun")]
fn check_finite(call: &'static str, what: &str, values: &[f64]) -> Result<(), RecordingError> {
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        return Err(RecordingError::InvalidInput {
            call,
            reason: format!("{what} is not finite ({v})"),
        });
    }
    Ok(())
}

pub use colors::{
    DISTINCT_VEHICLE_COLORS, entity_part, field_scale_ticks, normalize_field, vehicle_color,
    viridis,
};
