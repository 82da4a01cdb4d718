//! [`Recorder`] in a build without the cargo feature `rerun`: a recorder can only be
//! disabled, so every log call is a no-op and opening a file is [`RecordingError::Unsupported`].
//! The signatures are those of the Rerun build (`entities`, `rerun_file`); CI checks this build
//! (`cargo check -p sim --no-default-features`).

use std::path::Path;

use mergesim_types::{PathPoint, SharedLocalPath};

use super::{EventLevel, Recorder, RecorderParams, RecordingError};
use crate::body_state::BodyState;

/// No open recording can exist without Rerun.
pub(super) enum ActiveRecording {}

impl Recorder {
    /// Always [`RecordingError::Unsupported`] in this build.
    pub fn new_file_with_params(
        _path: impl AsRef<Path>,
        _app_id: &str,
        _params: RecorderParams,
    ) -> Result<Self, RecordingError> {
        Err(RecordingError::Unsupported)
    }

    /// No-op (no recording can be open).
    pub(crate) fn set_time(&mut self, _t_s: f64) -> Result<(), RecordingError> {
        Ok(())
    }

    /// No-op (no recording can be open).
    pub(crate) fn finish(self) -> Result<(), RecordingError> {
        Ok(())
    }

    /// Always `None`.
    pub(crate) fn tmp_path(&self) -> Option<&Path> {
        None
    }

    /// No-op.
    pub(crate) fn log_road(
        &mut self,
        _lanes: &mergesim_types::lanes::LaneRoad,
    ) -> Result<(), RecordingError> {
        Ok(())
    }

    /// No-op.
    pub(crate) fn log_vehicles(
        &mut self,
        _bodies: &[BodyState],
        _names: &[String],
    ) -> Result<(), RecordingError> {
        Ok(())
    }

    /// No-op.
    pub(crate) fn log_recorded_vehicles(
        &mut self,
        _bodies: &[BodyState],
        _names: &[String],
    ) -> Result<(), RecordingError> {
        Ok(())
    }

    /// No-op.
    pub(crate) fn log_planned_path(
        &mut self,
        _name: &str,
        _path: &[PathPoint],
    ) -> Result<(), RecordingError> {
        Ok(())
    }

    /// No-op.
    pub(crate) fn log_received_paths(
        &mut self,
        _name: &str,
        _paths: &[SharedLocalPath],
    ) -> Result<(), RecordingError> {
        Ok(())
    }

    /// No-op.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn log_field(
        &mut self,
        _name: &str,
        _x0_m: f64,
        _y0_m: f64,
        _cell_m: f64,
        _width: usize,
        _height: usize,
        _values: &[f64],
    ) -> Result<(), RecordingError> {
        Ok(())
    }

    /// No-op.
    pub(crate) fn log_scalars(
        &mut self,
        _name: &str,
        _values: &[(&str, f64)],
    ) -> Result<(), RecordingError> {
        Ok(())
    }

    /// No-op.
    pub(crate) fn log_event(
        &mut self,
        _text: &str,
        _level: EventLevel,
    ) -> Result<(), RecordingError> {
        Ok(())
    }
}
