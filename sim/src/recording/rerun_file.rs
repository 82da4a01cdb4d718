//! The Rerun side of [`Recorder`] (cargo feature `rerun`, on by default): the file stream, its
//! blueprint, the clock, and closing or discarding the file. What is logged is in `entities`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use rerun::blueprint::{
    Blueprint, ContainerLike, Horizontal, Spatial3DView, TextLogView, TimeSeriesView, Vertical,
};
use rerun::components::{Color, TextLogLevel};
use rerun::{RecordingStream, RecordingStreamBuilder, ViewCoordinates};

use super::colors::entity_part;
use super::{EventLevel, Recorder, RecorderParams, RecordingError, SIM_TIMELINE, check_finite};

/// An open recording: the stream writing `<path>.tmp`, renamed to `<path>` by
/// [`Recorder::finish`].
pub(super) struct ActiveRecording {
    pub(super) stream: RecordingStream,
    pub(super) tmp_path: PathBuf,
    pub(super) final_path: PathBuf,
    /// Series entities whose static `SeriesLines` style has been logged.
    pub(super) styled_series: BTreeSet<String>,
    /// Colour of each vehicle name seen in `log_vehicles`.
    pub(super) name_colors: BTreeMap<String, Color>,
}

impl Recorder {
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

    /// The temporary file being written, if enabled.
    pub fn tmp_path(&self) -> Option<&Path> {
        self.active.as_ref().map(|a| a.tmp_path.as_path())
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

impl EventLevel {
    pub(super) fn as_text_log_level(self) -> TextLogLevel {
        TextLogLevel::from(match self {
            Self::Debug => TextLogLevel::DEBUG,
            Self::Info => TextLogLevel::INFO,
            Self::Warn => TextLogLevel::WARN,
            Self::Error => TextLogLevel::ERROR,
        })
    }
}
