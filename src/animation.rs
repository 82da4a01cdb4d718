//! `merge_sim run --gif`: a top-down animated GIF of a run, drawn on the CPU with plotters (no
//! GPU, no display), from the run's time series — so a run can be shown in a paper or an issue.
//!
//! Each frame shows, as [`GifParams::view`] says, either the whole road with every vehicle
//! (scaled to the picture's width, as the recording's whole-road view; [`GifView::Road`]) or a
//! window that follows one vehicle (the recording's follow view: [`GifParams::behind_m`] behind
//! it, [`GifParams::ahead_m`] ahead, the road's whole width centred on the road's middle, turned
//! so that its lane runs to the right, along a curve too; [`GifView::Follow`]). Any road of lanes is
//! drawn ([`sim::road_drawing::RoadDrawing`]): the drivable area's outer edges solid, the
//! dividers dashed, closed lane ends in red, the merge sections (the tapering stretch of each
//! lane that ends) shaded, the lanes' ids on request ([`GifParams::lane_ids`]); every vehicle as its oriented
//! footprint in its colour ([`sim::recording::vehicle_color`], the same RGB as in the recording
//! and the figures: the GIF's palette keeps these colours exact) with its name, and a header
//! with the time, the followed vehicle's speed and the last collision. Vehicles in a collision
//! are outlined in red from its time on. Playback is real time by default: one frame per
//! `1 / fps` s of simulated time, shown for `1 / fps` s.

mod frame;
mod palette;

pub use frame::FrameGeometry;

use std::path::{Path, PathBuf};

use mergesim_types::lanes::LaneRoad;
use plotters::prelude::*;
use serde::{Deserialize, Serialize};
use sim::recording::vehicle_color;
use sim::road_drawing::RoadDrawing;
use sim::safety::CollisionEvent;
use sim::{RecordedPose, TimeSeriesRow};
use thiserror::Error;

use crate::output::temporary_path;
use crate::plots::ensure_font;
use frame::{FrameScene, draw_frame};

/// Which part of the road the frames show.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GifView {
    /// The whole road with every vehicle in every frame, scaled to the picture's width (across
    /// the road stretched so the lanes stay visible on a long road).
    Road,
    /// A window around the followed vehicle; vehicles outside it are not drawn.
    #[default]
    Follow,
}

impl GifView {
    /// The view `merge_sim run --gif` takes unless told: the whole road when more than two
    /// vehicles run (others would drop out of a window), else the follow view.
    pub fn default_for(vehicles: usize) -> Self {
        if vehicles > 2 {
            GifView::Road
        } else {
            GifView::Follow
        }
    }

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            GifView::Road => "road",
            GifView::Follow => "follow",
        }
    }
}

/// Options of the animation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GifParams {
    /// Frames per second, of simulated time and of playback (real time), in (0, 50]. GIF delays
    /// are whole centiseconds, so the shown rate is 100 / round(100 / fps).
    pub fps: f64,
    /// Width of the picture (pixels), 160 to 4000; the height follows from the window.
    pub width_px: u32,
    /// Road shown behind the followed vehicle (m).
    pub behind_m: f64,
    /// Road shown ahead of the followed vehicle (m).
    pub ahead_m: f64,
    /// Margin beside the road's edges (m).
    pub margin_m: f64,
    /// The whole road or the window around the followed vehicle (`behind_m`, `ahead_m`).
    pub view: GifView,
    /// Write each lane's id on the road (`merge_sim run --lane-ids`).
    pub lane_ids: bool,
}

impl Default for GifParams {
    fn default() -> Self {
        Self {
            fps: 10.0,
            width_px: 800,
            behind_m: 30.0,
            ahead_m: 50.0,
            margin_m: 2.0,
            view: GifView::Follow,
            lane_ids: false,
        }
    }
}

/// What the animation shows of one vehicle.
#[derive(Clone, Debug, PartialEq)]
pub struct GifVehicle {
    /// Its name (as in the time series).
    pub name: String,
    /// Its id (the recording's colour).
    pub id: u32,
    /// Footprint length (m).
    pub length_m: f64,
    /// Footprint width (m).
    pub width_m: f64,
}

/// What was written.
#[derive(Clone, Debug, PartialEq)]
pub struct GifStats {
    /// Number of frames.
    pub frames: usize,
    /// Picture size (pixels).
    pub size_px: (u32, u32),
    /// File size (bytes).
    pub bytes: u64,
}

/// Everything that can go wrong writing an animation.
#[derive(Debug, Error)]
pub enum GifError {
    /// A parameter is out of range.
    #[error("--gif: {0}")]
    Params(String),
    /// The followed vehicle is not in the run.
    #[error("--follow: no vehicle named {name:?} (vehicles: {valid})")]
    UnknownVehicle {
        /// The name asked for.
        name: String,
        /// The run's vehicles.
        valid: String,
    },
    /// The run has no time series to draw.
    #[error("--gif: the run logged no instant to draw")]
    Empty,
    /// plotters failed to draw or encode.
    #[error("--gif {path}: {message}")]
    Draw {
        /// The file.
        path: PathBuf,
        /// plotters' message.
        message: String,
    },
    /// Renaming the finished file failed.
    #[error("--gif {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

impl GifParams {
    /// Checks the ranges documented on the fields.
    pub fn validate(&self) -> Result<(), GifError> {
        let bad = |what: String| Err(GifError::Params(what));
        if !(self.fps.is_finite() && self.fps > 0.0 && self.fps <= 50.0) {
            return bad(format!("fps = {} must be in (0, 50]", self.fps));
        }
        if !(160..=4000).contains(&self.width_px) {
            return bad(format!("width = {} px must be 160 to 4000", self.width_px));
        }
        for (name, v) in [
            ("behind_m", self.behind_m),
            ("ahead_m", self.ahead_m),
            ("margin_m", self.margin_m),
        ] {
            if !(v.is_finite() && (0.0..=1000.0).contains(&v)) {
                return bad(format!("{name} = {v} must be in [0, 1000]"));
            }
        }
        if self.behind_m + self.ahead_m < 5.0 {
            return bad("the window (behind_m + ahead_m) must be at least 5 m".into());
        }
        Ok(())
    }

    /// The picture size (pixels) of the follow view of `lanes` (the road view's depends on the
    /// run: [`FrameGeometry::whole_road`]).
    pub fn size_px(&self, lanes: &LaneRoad) -> (u32, u32) {
        FrameGeometry::follow(lanes, self, [0.0, 0.0]).size_px
    }
}

/// One logged instant: its time and the rows of every vehicle.
fn instants(rows: &[TimeSeriesRow]) -> Vec<&[TimeSeriesRow]> {
    rows.chunk_by(|a, b| a.t_s == b.t_s).collect()
}

/// The instants drawn: the first at or after each multiple of 1 / fps.
fn frame_instants<'a>(all: &[&'a [TimeSeriesRow]], fps: f64) -> Vec<&'a [TimeSeriesRow]> {
    let mut out = Vec::new();
    let mut next_t = f64::NEG_INFINITY;
    for instant in all {
        let t = instant.first().map_or(f64::NAN, |r| r.t_s);
        if t >= next_t - 1e-9 {
            out.push(*instant);
            next_t = if out.len() == 1 { t } else { next_t } + 1.0 / fps;
        }
    }
    out
}

/// Writes the animation of a run to `path` (through a temporary file, renamed when complete):
/// the road `lanes`, the vehicles `vehicles`, their time series `rows` (as `RunOutcome`'s, in
/// time order), the recorded traffic `recorded` (`RunOutcome::recorded_track`, grey), the
/// collisions `collisions`, following the vehicle named `follow`.
/// `title` heads every frame. `progress` gets the fraction of frames written.
#[allow(clippy::too_many_arguments)]
pub fn write_gif(
    path: &Path,
    lanes: &LaneRoad,
    vehicles: &[GifVehicle],
    rows: &[TimeSeriesRow],
    recorded: &[RecordedPose],
    collisions: &[CollisionEvent],
    follow: &str,
    title: &str,
    params: &GifParams,
    mut progress: impl FnMut(f64),
) -> Result<GifStats, GifError> {
    params.validate()?;
    if !vehicles.iter().any(|v| v.name == follow) {
        return Err(GifError::UnknownVehicle {
            name: follow.into(),
            valid: vehicles
                .iter()
                .map(|v| v.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    let frames = frame_instants(&instants(rows), params.fps);
    if frames.is_empty() {
        return Err(GifError::Empty);
    }
    let draw_err = |e: &dyn std::fmt::Display| GifError::Draw {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    ensure_font().map_err(|e| draw_err(&e))?;
    let whole_road = FrameGeometry::whole_road(lanes, params, rows);
    let size = match params.view {
        GifView::Road => whole_road.size_px,
        GifView::Follow => params.size_px(lanes),
    };
    let drawing = RoadDrawing::new(lanes);
    let scene = FrameScene {
        road: &drawing,
        lane_ids: params.lane_ids,
        vehicles,
        recorded,
        collisions,
        follow,
        title,
        view: params.view,
    };
    // The vehicles' colours keep their own palette entries in every frame.
    let keep: Vec<[u8; 3]> = vehicles.iter().map(|v| vehicle_color(v.id)).collect();
    let delay_cs = (100.0 / params.fps).round().max(1.0) as u16;
    let tmp = temporary_path(path);
    let result = (|| {
        let file = std::fs::File::create(&tmp).map_err(|e| draw_err(&e))?;
        let (w16, h16) = (
            u16::try_from(size.0).map_err(|e| draw_err(&e))?,
            u16::try_from(size.1).map_err(|e| draw_err(&e))?,
        );
        let mut encoder = gif::Encoder::new(std::io::BufWriter::new(file), w16, h16, &[])
            .map_err(|e| draw_err(&e))?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(|e| draw_err(&e))?;
        let mut buffer = vec![0u8; 3 * size.0 as usize * size.1 as usize];
        let n = frames.len();
        for (k, instant) in frames.iter().enumerate() {
            let geometry = match params.view {
                GifView::Road => whole_road,
                GifView::Follow => {
                    let centre = instant
                        .iter()
                        .find(|r| r.vehicle == follow)
                        .map_or([0.0, 0.0], |r| [r.x_m, r.y_m]);
                    FrameGeometry::follow(lanes, params, centre)
                }
            };
            {
                let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
                draw_frame(&root, &scene, instant, &geometry).map_err(|e| draw_err(&e))?;
                root.present().map_err(|e| draw_err(&e))?;
            }
            let (colors, indices) = palette::index_frame(&buffer, &keep);
            let mut frame = gif::Frame::from_palette_pixels(w16, h16, &indices, &colors, None);
            frame.delay = delay_cs;
            encoder.write_frame(&frame).map_err(|e| draw_err(&e))?;
            progress((k + 1) as f64 / n as f64);
        }
        let mut writer = encoder.into_inner().map_err(|e| draw_err(&e))?;
        std::io::Write::flush(&mut writer).map_err(|e| draw_err(&e))?;
        Ok::<_, GifError>(n)
    })();
    let n = match result {
        Ok(n) => n,
        Err(e) => {
            std::fs::remove_file(&tmp).ok();
            return Err(e);
        }
    };
    std::fs::rename(&tmp, path).map_err(|source| {
        std::fs::remove_file(&tmp).ok();
        GifError::Io {
            path: path.to_path_buf(),
            source,
        }
    })?;
    let bytes = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
    Ok(GifStats {
        frames: n,
        size_px: size,
        bytes,
    })
}

#[cfg(test)]
mod curved_tests;

#[cfg(test)]
mod road_view_tests;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn footprint_is_rotated_about_the_centre() {
        let c = frame::footprint(10.0, 2.0, std::f64::consts::FRAC_PI_2, 4.0, 2.0);
        // Heading +Y: the front corners are 2 m up.
        assert!((c[0].1 - 4.0).abs() < 1e-12 && (c[0].0 - 9.0).abs() < 1e-12);
    }

    #[test]
    fn frames_are_spaced_by_the_frame_period() {
        let rows: Vec<TimeSeriesRow> = (0..41)
            .map(|k| TimeSeriesRow {
                t_s: 0.05 * f64::from(k),
                vehicle: "ego".into(),
                x_m: 0.0,
                y_m: 0.0,
                yaw_rad: 0.0,
                yaw_rate_radps: 0.0,
                sideslip_rad: 0.0,
                speed_mps: 0.0,
                planned_speed_mps: 0.0,
                accel_long_mps2: 0.0,
                accel_lat_mps2: 0.0,
            })
            .collect();
        let all = instants(&rows);
        assert_eq!(all.len(), 41);
        // 2 s at 10 fps: 21 frames (0, 0.1, ..., 2.0).
        assert_eq!(frame_instants(&all, 10.0).len(), 21);
    }

    pub(super) fn row(vehicle: &str, x_m: f64, y_m: f64) -> TimeSeriesRow {
        TimeSeriesRow {
            t_s: 1.0,
            vehicle: vehicle.into(),
            x_m,
            y_m,
            yaw_rad: 0.0,
            yaw_rate_radps: 0.0,
            sideslip_rad: 0.0,
            speed_mps: 20.0,
            planned_speed_mps: 20.0,
            accel_long_mps2: 0.0,
            accel_lat_mps2: 0.0,
        }
    }

    fn vehicles() -> Vec<GifVehicle> {
        ["ego", "far"]
            .iter()
            .zip(0..)
            .map(|(name, id)| GifVehicle {
                name: (*name).into(),
                id,
                length_m: 4.5,
                width_m: 1.8,
            })
            .collect()
    }

    fn merge_lanes() -> LaneRoad {
        mergesim_types::MergeRoad::default()
            .lane_road()
            .unwrap_or_else(|e| panic!("{e}"))
    }

    /// One frame drawn into memory with `geometry`.
    fn draw(instant: &[TimeSeriesRow], view: GifView, geometry: &FrameGeometry) -> Vec<u8> {
        draw_on(&merge_lanes(), instant, view, geometry, false)
    }

    /// One frame of `lanes` drawn into memory with `geometry`.
    pub(super) fn draw_on(
        lanes: &LaneRoad,
        instant: &[TimeSeriesRow],
        view: GifView,
        geometry: &FrameGeometry,
        lane_ids: bool,
    ) -> Vec<u8> {
        draw_with_recorded(lanes, instant, &[], view, geometry, lane_ids)
    }

    /// One frame of `lanes` with the recorded traffic `recorded`, drawn into memory.
    pub(super) fn draw_with_recorded(
        lanes: &LaneRoad,
        instant: &[TimeSeriesRow],
        recorded: &[RecordedPose],
        view: GifView,
        geometry: &FrameGeometry,
        lane_ids: bool,
    ) -> Vec<u8> {
        let road = RoadDrawing::new(lanes);
        let vehicles = vehicles();
        let size = geometry.size_px;
        let mut buffer = vec![0u8; (size.0 * size.1 * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
            let scene = FrameScene {
                road: &road,
                lane_ids,
                vehicles: &vehicles,
                recorded,
                collisions: &[],
                follow: "ego",
                title: "test",
                view,
            };
            draw_frame(&root, &scene, instant, geometry).unwrap_or_else(|e| panic!("{e}"));
            root.present().unwrap_or_else(|e| panic!("{e}"));
        }
        buffer
    }

    /// One frame of the follow view, following `ego`.
    fn frame(instant: &[TimeSeriesRow]) -> Vec<u8> {
        let centre = instant
            .iter()
            .find(|r| r.vehicle == "ego")
            .map_or([0.0, 0.0], |r| [r.x_m, r.y_m]);
        let geometry = FrameGeometry::follow(&merge_lanes(), &GifParams::default(), centre);
        draw(instant, GifView::Follow, &geometry)
    }

    #[test]
    fn vehicles_outside_the_window_leave_the_frame_untouched() {
        ensure_font().unwrap_or_else(|e| panic!("{e}"));
        let alone = frame(&[row("ego", 100.0, 1.75)]);
        // 100 m behind and 200 m ahead of a window of 30 m behind to 50 m ahead: not drawn,
        // not even their labels at the edge.
        assert_eq!(
            frame(&[row("ego", 100.0, 1.75), row("far", 0.0, 5.25)]),
            alone
        );
        assert_eq!(
            frame(&[row("ego", 100.0, 1.75), row("far", 300.0, 5.25)]),
            alone
        );
        // 20 m ahead: drawn.
        assert_ne!(
            frame(&[row("ego", 100.0, 1.75), row("far", 120.0, 5.25)]),
            alone
        );
    }

    #[test]
    fn the_road_view_shows_every_vehicle_at_its_place() {
        ensure_font().unwrap_or_else(|e| panic!("{e}"));
        let road = mergesim_types::MergeRoad::default();
        // The same two vehicles, 300 m apart: the follow view loses one, the road view has both.
        let instant = [row("ego", 0.0, 1.75), row("far", 300.0, 5.25)];
        let geometry = FrameGeometry::whole_road(&merge_lanes(), &GifParams::default(), &instant);
        assert_eq!(geometry.size_px.0, 800);
        let pixels = draw(&instant, GifView::Road, &geometry);
        let at = |(x, y): (i32, i32)| {
            let i = 3 * (y as usize * geometry.size_px.0 as usize + x as usize);
            [pixels[i], pixels[i + 1], pixels[i + 2]]
        };
        for (id, r) in instant.iter().enumerate() {
            assert_eq!(
                at(geometry.to_px(r.x_m, r.y_m)),
                vehicle_color(id as u32),
                "{} not drawn at its place",
                r.vehicle
            );
        }
        let followed = frame(&instant);
        let has = |buffer: &[u8], rgb: [u8; 3]| buffer.chunks(3).any(|p| p == rgb);
        assert!(has(&followed, vehicle_color(0)) && !has(&followed, vehicle_color(1)));
        // The road and every position fit: the road's ends map inside the picture.
        let (x_start, _) = geometry.to_px(road.start_x_m, road.y_lane_m());
        let (x_end, _) = geometry.to_px(road.end_x_m, road.y_lane_m());
        assert!(x_start >= 0 && x_end < 800, "{x_start} {x_end}");
    }

    #[test]
    fn the_default_view_is_the_road_beyond_two_vehicles() {
        assert_eq!(GifView::default_for(1), GifView::Follow);
        assert_eq!(GifView::default_for(2), GifView::Follow);
        assert_eq!(GifView::default_for(3), GifView::Road);
    }

    #[test]
    fn bad_params_are_refused() {
        for p in [
            GifParams {
                fps: 0.0,
                ..GifParams::default()
            },
            GifParams {
                width_px: 10,
                ..GifParams::default()
            },
            GifParams {
                ahead_m: f64::NAN,
                ..GifParams::default()
            },
        ] {
            assert!(matches!(p.validate(), Err(GifError::Params(_))));
        }
        assert!(GifParams::default().validate().is_ok());
    }
}
