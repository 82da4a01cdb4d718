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

mod colors;
#[cfg(feature = "rerun")]
mod entities;
#[cfg(feature = "rerun")]
mod rerun_file;
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
    /// Potential fields and received shared paths are recorded for the first this many
    /// vehicles (by id) only; `None`: for all. Boxes, planned paths, time series and events are
    /// recorded for every vehicle. Both grow with the number of vehicles (received paths with
    /// its square): with 50 vehicles they made a 72 s recording 1 GB.
    pub detail_vehicles: Option<usize>,
}

/// Vehicles whose fields and received paths are recorded by default (every built-in scenario
/// but the dense merge and the platoon has at most this many).
pub const DEFAULT_DETAIL_VEHICLES: usize = 4;

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
            detail_vehicles: Some(DEFAULT_DETAIL_VEHICLES),
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

pub use colors::{entity_part, normalize_field, vehicle_color, viridis};
