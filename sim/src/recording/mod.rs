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

mod colors;
mod entities;
pub mod size_estimate;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use rerun::blueprint::{
    Blueprint, ContainerLike, Horizontal, Spatial3DView, TextLogView, TimeSeriesView, Vertical,
};
use rerun::components::{Color, TextLogLevel};
use rerun::{RecordingStream, RecordingStreamBuilder, ViewCoordinates};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use entities::check_finite;

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
        // A stale temporary file (or link) of a killed process is removed, never written
        // through.
        if std::fs::symlink_metadata(&tmp_path).is_ok() {
            std::fs::remove_file(&tmp_path).ok();
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

    /// The recording's parameters.
    pub fn params(&self) -> &RecorderParams {
        &self.params
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

pub use colors::{entity_part, normalize_field, vehicle_color, viridis};
