//! The Rerun side of [`Recorder`] (cargo feature `rerun`, on by default): the file stream, its
//! blueprint, the clock, and closing or discarding the file. What is logged is in `entities`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use rerun::blueprint::components::{Corner2D, PanelState};
use rerun::blueprint::{
    Blueprint, BlueprintActivation, BlueprintPanel, ContainerLike, Horizontal, SelectionPanel,
    Spatial2DView, TextLogView, TimePanel, TimeSeriesView, Vertical,
};
use rerun::components::{Color, TextLogLevel};
use rerun::datatypes::{Range1D, Range2D};
use rerun::external::re_log_types::{BlueprintActivationCommand, EntityPath};
use rerun::external::re_sdk_types::blueprint::archetypes::{
    PlotLegend, ScalarAxis, VisualBounds2D,
};
use rerun::log::LogMsg;
use rerun::{AsComponents, RecordingStream, RecordingStreamBuilder, StoreKind};

use super::colors::entity_part;
use super::{EventLevel, Recorder, RecorderParams, RecordingError, SIM_TIMELINE, check_finite};

/// A view property the blueprint builder of the 0.36 Rust SDK cannot set: logged at
/// `view/<id>/<archetype>`, where the viewer reads it.
struct ViewProperty {
    view: EntityPath,
    archetype: &'static str,
    value: Box<dyn AsComponents>,
}

/// The blueprint store's id path of a view and the view as a container entry.
fn view_entry(view: impl Into<ContainerLike>) -> (Option<EntityPath>, ContainerLike) {
    let like: ContainerLike = view.into();
    let path = match &like {
        ContainerLike::View(v) => Some(v.blueprint_path()),
        _ => None,
    };
    (path, like)
}

/// The default layout: the follow view over the whole-road view, the field's colour bar and the
/// event log on the left; one time-series view per series on the right. Returns the blueprint
/// and the view properties to add to it.
fn blueprint(params: &RecorderParams) -> (Blueprint, Vec<ViewProperty>) {
    let mut props = Vec::new();
    let mut bounds = |view: Option<EntityPath>, x: [f64; 2], y: [f64; 2]| {
        if let Some(view) = view {
            props.push(ViewProperty {
                view,
                archetype: "VisualBounds2D",
                value: Box::new(VisualBounds2D::new(Range2D {
                    x_range: Range1D(x),
                    y_range: Range1D(y),
                })),
            });
        }
    };
    let w = params.follow_window_m;
    let (follow_id, follow) = view_entry(
        Spatial2DView::new(format!("Follow {} (m)", params.follow))
            .with_origin("/world/follow")
            .with_contents(["/world/**"]),
    );
    // The follow frame has Y flipped (up on screen), so the window's y range is flipped too.
    bounds(follow_id, [-w.behind_m, w.ahead_m], [-w.side_m, w.side_m]);
    let (road_id, road) = view_entry(
        Spatial2DView::new("Whole road (m)")
            .with_origin("/world/overview")
            .with_contents(["/world/**", "- /world/paths/**"]),
    );
    // The road's own frame is scaled to fit these bounds (`entities::overview_frame`).
    let half_height_m = super::entities::OVERVIEW_HALF_HEIGHT_M;
    bounds(
        road_id,
        [-10.0, super::entities::OVERVIEW_LENGTH_M + 10.0],
        [-half_height_m, half_height_m],
    );
    let (legend_id, legend) =
        view_entry(Spatial2DView::new("Field scale (potential U)").with_origin("/legend"));
    bounds(
        legend_id,
        [-10.0, f64::from(super::entities::COLOR_BAR_STEPS) + 10.0],
        [-12.0, 24.0],
    );
    let left = Vertical::new([
        follow,
        road,
        legend,
        TextLogView::new("Events").with_origin("/events").into(),
    ])
    .with_row_shares([3.0, 1.5, 1.2, 1.5]);
    let mut plots: Vec<ContainerLike> = Vec::new();
    for plot in &params.blueprint_series {
        let (id, view) = view_entry(
            TimeSeriesView::new(plot.title.clone())
                .with_origin(format!("/plots/{}", entity_part(&plot.series))),
        );
        if let Some(id) = id {
            if let Some(range) = plot.y_range {
                props.push(ViewProperty {
                    view: id.clone(),
                    archetype: "ScalarAxis",
                    value: Box::new(ScalarAxis::new().with_range(Range1D(range))),
                });
            }
            props.push(ViewProperty {
                view: id,
                archetype: "PlotLegend",
                value: Box::new(PlotLegend::new().with_corner(Corner2D::RightBottom)),
            });
        }
        plots.push(view);
    }
    let root = if plots.is_empty() {
        Horizontal::new([left.into()])
    } else {
        Horizontal::new([left.into(), Vertical::new(plots).into()]).with_column_shares([3.0, 2.0])
    };
    // The side panels start collapsed (the views get the room) and the time panel as its
    // compact bar on `sim_time`; every panel opens with one click.
    let bp = Blueprint::new(root)
        .with_auto_views(false)
        .with_auto_layout(false)
        .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
        .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
        .with_time_panel(
            TimePanel::new()
                .with_state(PanelState::Collapsed)
                .with_timeline(SIM_TIMELINE),
        );
    (bp, props)
}

/// The blueprint's messages (the SDK's own, plus the view properties it cannot write) and the
/// command that makes it the default layout.
fn blueprint_messages(
    app_id: &rerun::ApplicationId,
    params: &RecorderParams,
) -> Result<(Vec<LogMsg>, BlueprintActivationCommand), RecordingError> {
    let (bp, props) = blueprint(params);
    // Let the SDK write its messages into memory.
    let (mem, storage) = RecordingStreamBuilder::new(app_id.clone())
        .enabled(true)
        .memory()?;
    bp.send(
        &mem,
        BlueprintActivation {
            make_active: false,
            make_default: true,
        },
    )?;
    let mut msgs = Vec::new();
    let mut activation = None;
    for msg in storage.take() {
        match msg {
            LogMsg::BlueprintActivationCommand(cmd) => activation = Some(cmd),
            msg if msg.store_id().kind() == StoreKind::Blueprint => msgs.push(msg),
            _ => {}
        }
    }
    let Some(activation) = activation else {
        return Err(RecordingError::InvalidInput {
            call: "blueprint",
            reason: "the SDK wrote no blueprint activation".into(),
        });
    };
    // The view properties, into the same blueprint store.
    let (extra, extra_storage) = RecordingStreamBuilder::new(app_id.clone())
        .enabled(true)
        .recording_id(activation.blueprint_id.recording_id().clone())
        .blueprint()
        .memory()?;
    extra.set_time_sequence("blueprint", 0);
    for p in &props {
        extra.log(
            p.view.join(&EntityPath::from_single_string(p.archetype)),
            p.value.as_ref(),
        )?;
    }
    msgs.extend(
        extra_storage
            .take()
            .into_iter()
            .filter(|m| matches!(m, LogMsg::ArrowMsg(..))),
    );
    Ok((msgs, activation))
}

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

        // `enabled(true)`: an explicit file recording is not switched off by the `RERUN`
        // environment variable; use `Recorder::disabled` for that.
        let app_id =
            rerun::ApplicationId::try_new(app_id).map_err(|e| RecordingError::InvalidInput {
                call: "new_file",
                reason: e.to_string(),
            })?;
        let blueprint = if params.blueprint {
            Some(blueprint_messages(&app_id, &params)?)
        } else {
            None
        };
        let builder = RecordingStreamBuilder::new(app_id).enabled(true);
        // A stale temporary file (or link) of a killed process is removed, never written
        // through.
        if std::fs::symlink_metadata(&tmp_path).is_ok() {
            std::fs::remove_file(&tmp_path).ok();
        }
        let stream = builder.save(&tmp_path)?;
        if let Some((msgs, activation)) = blueprint {
            stream.send_blueprint(msgs, activation);
        }
        let recorder = Self {
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
