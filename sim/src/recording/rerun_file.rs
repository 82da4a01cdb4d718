//! The Rerun side of [`Recorder`] (cargo feature `rerun`, on by default): the file stream, its
//! blueprint, the clock, and closing or discarding the file. What is logged is in `entities`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use rerun::components::{Color, TextLogLevel};
use rerun::external::re_log_types::{BlueprintActivationCommand, StoreId, StoreInfo};
use rerun::log::LogMsg;
use rerun::{StoreKind, TimePoint};

use super::rrd_writer::{BLUEPRINT_STORE, RrdWriter};
use super::{EventLevel, Recorder, RecorderParams, RecordingError, SIM_TIMELINE, check_finite};

/// The recording id of a file named `file_name`: the name itself, so that the same run recorded
/// twice under the same name gives the same bytes (wherever the file is), and files of
/// different names open side by side in the viewer (which merges the data of one recording id).
fn recording_id(file_name: &str) -> String {
    file_name.to_owned()
}

/// An open recording: the stream writing `<path>.tmp`, renamed to `<path>` by
/// [`Recorder::finish`].
pub(super) struct ActiveRecording {
    pub(super) stream: RrdWriter,
    pub(super) tmp_path: PathBuf,
    pub(super) final_path: PathBuf,
    /// Series entities whose static `SeriesLines` style has been logged.
    pub(super) styled_series: BTreeSet<String>,
    /// Colour of each vehicle name seen in `log_vehicles`.
    pub(super) name_colors: BTreeMap<String, Color>,
    /// The road logged by `log_road`: the follow frame turns to the followed vehicle's lane.
    pub(super) lanes: Option<mergesim_types::lanes::LaneRoad>,
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

        let app_id =
            rerun::ApplicationId::try_new(app_id).map_err(|e| RecordingError::InvalidInput {
                call: "new_file",
                reason: e.to_string(),
            })?;
        let name = final_path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let rec_id = recording_id(&name);
        // The SDK's own description of the writer (its version, rustc and LLVM), without its
        // random store id.
        let source = rerun::new_store_info(app_id.clone()).store_source;
        let blueprint_id = StoreId::new(StoreKind::Blueprint, app_id.clone(), rec_id.clone());
        let recording_store = StoreId::new(StoreKind::Recording, app_id, rec_id);
        // A stale temporary file (or link) of a killed process is removed, never written
        // through.
        if std::fs::symlink_metadata(&tmp_path).is_ok() {
            std::fs::remove_file(&tmp_path).ok();
        }
        let mut stream = RrdWriter::create(
            &tmp_path,
            params
                .blueprint
                .then(|| StoreInfo::new(blueprint_id.clone(), source.clone())),
            StoreInfo::new(recording_store, source),
        )?;
        if params.blueprint {
            // The default layout, complete before its activation (as the SDK sends it).
            let mut at_zero = TimePoint::default();
            at_zero.insert_cell("blueprint", rerun::TimeCell::from_sequence(0));
            stream.set_timepoint(at_zero);
            for (path, batches) in super::blueprint::blueprint_rows(&params) {
                stream.log_to(BLUEPRINT_STORE, path, false, batches)?;
            }
            stream.flush_store(BLUEPRINT_STORE)?;
            stream.write_command(&LogMsg::BlueprintActivationCommand(
                BlueprintActivationCommand {
                    blueprint_id,
                    make_active: false,
                    make_default: true,
                },
            ))?;
        }
        // Data logged before the first `set_time` is at `sim_time` = 0.
        stream.set_duration_secs(SIM_TIMELINE, 0.0);
        let mut recorder = Self {
            params,
            active: Some(ActiveRecording {
                stream,
                tmp_path,
                final_path,
                styled_series: BTreeSet::new(),
                name_colors: BTreeMap::new(),
                lanes: None,
            }),
        };
        recorder.log_field_legend()?;
        Ok(recorder)
    }

    /// Sets the current time of the `sim_time` timeline (s).
    pub fn set_time(&mut self, t_s: f64) -> Result<(), RecordingError> {
        let Some(active) = &mut self.active else {
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
        // Writes the last chunks and the footer, and closes the file.
        if let Err(err) = stream.finish() {
            std::fs::remove_file(&tmp_path).ok();
            return Err(err);
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
            drop(active.stream);
            std::fs::remove_file(&active.tmp_path).ok();
        }
    }
}

impl EventLevel {
    /// Lower-case name (an entity-path part).
    pub(super) fn name(self) -> &'static str {
        match self {
            Self::Debug => "debug",
            Self::Info => "info",
            Self::Warn => "warn",
            Self::Error => "error",
        }
    }

    pub(super) fn as_text_log_level(self) -> TextLogLevel {
        TextLogLevel::from(match self {
            Self::Debug => TextLogLevel::DEBUG,
            Self::Info => TextLogLevel::INFO,
            Self::Warn => TextLogLevel::WARN,
            Self::Error => TextLogLevel::ERROR,
        })
    }
}
