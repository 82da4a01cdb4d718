//! `merge_sim run --gif`: a top-down animated GIF of a run, drawn on the CPU with plotters (no
//! GPU, no display), from the run's time series — so a run can be shown in a paper or an issue.
//!
//! Each frame shows a window of road that follows one vehicle (the same window as the Rerun
//! follow view: [`GifParams::behind_m`] behind it, [`GifParams::ahead_m`] ahead, the road's
//! whole width), the road edges, the lane divider, the merge section (orange), every vehicle as
//! its oriented footprint in its colour (the recording's palette) with its name, and a header
//! with the time, the followed vehicle's speed and the last collision. Vehicles in a collision
//! are outlined in red from its time on. Playback is real time by default: one frame per
//! `1 / fps` s of simulated time, shown for `1 / fps` s.

use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;
use serde::{Deserialize, Serialize};
use sim::TimeSeriesRow;
use sim::recording::vehicle_color;
use sim::safety::CollisionEvent;
use thiserror::Error;

use crate::output::temporary_path;
use crate::plots::{ensure_font, font};

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
}

impl Default for GifParams {
    fn default() -> Self {
        Self {
            fps: 10.0,
            width_px: 800,
            behind_m: 30.0,
            ahead_m: 50.0,
            margin_m: 2.0,
        }
    }
}

/// Height of the header line (pixels).
const HEADER_PX: u32 = 22;

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

    /// The picture size (pixels) for a road of width `road_width_m`.
    pub fn size_px(&self, road_width_m: f64) -> (u32, u32) {
        let px_per_m = f64::from(self.width_px) / (self.behind_m + self.ahead_m);
        let road_px = ((road_width_m + 2.0 * self.margin_m) * px_per_m).ceil();
        (
            self.width_px,
            HEADER_PX + road_px.clamp(16.0, 4000.0) as u32,
        )
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

/// The corners of a footprint centred at (x, y) with heading `yaw`.
fn footprint(x: f64, y: f64, yaw: f64, length: f64, width: f64) -> [(f64, f64); 4] {
    let (s, c) = yaw.sin_cos();
    let (hl, hw) = (0.5 * length, 0.5 * width);
    [(hl, hw), (-hl, hw), (-hl, -hw), (hl, -hw)]
        .map(|(dx, dy)| (x + c * dx - s * dy, y + s * dx + c * dy))
}

/// Writes the animation of a run to `path` (through a temporary file, renamed when complete):
/// the road `road`, the vehicles `vehicles`, their time series `rows` (as `RunOutcome`'s, in
/// time order), the collisions `collisions`, following the vehicle named `follow`.
/// `title` heads every frame. `progress` gets the fraction of frames written.
#[allow(clippy::too_many_arguments)]
pub fn write_gif(
    path: &Path,
    road: &sim::MergeRoad,
    vehicles: &[GifVehicle],
    rows: &[TimeSeriesRow],
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
    let road_width_m = road.y_upper_m() - road.y_bottom_m;
    let size = params.size_px(road_width_m);
    let delay_cs = (100.0 / params.fps).round().max(1.0);
    let tmp = temporary_path(path);
    let result = (|| {
        let backend =
            BitMapBackend::gif(&tmp, size, (10.0 * delay_cs) as u32).map_err(|e| draw_err(&e))?;
        let root = backend.into_drawing_area();
        let n = frames.len();
        for (k, instant) in frames.iter().enumerate() {
            draw_frame(
                &root, road, vehicles, instant, collisions, follow, title, params, size,
            )
            .map_err(|e| draw_err(&e))?;
            root.present().map_err(|e| draw_err(&e))?;
            progress((k + 1) as f64 / n as f64);
        }
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

#[allow(clippy::too_many_arguments)]
fn draw_frame(
    root: &DrawingArea<BitMapBackend<'_>, Shift>,
    road: &sim::MergeRoad,
    vehicles: &[GifVehicle],
    instant: &[TimeSeriesRow],
    collisions: &[CollisionEvent],
    follow: &str,
    title: &str,
    params: &GifParams,
    (w, _h): (u32, u32),
) -> Result<(), String> {
    let e = |err: &dyn std::fmt::Display| err.to_string();
    root.fill(&RGBColor(40, 40, 44)).map_err(|x| e(&x))?;
    let t_s = instant.first().map_or(0.0, |r| r.t_s);
    let followed = instant.iter().find(|r| r.vehicle == follow);
    let x_c = followed.map_or(0.0, |r| r.x_m);
    let px_per_m = f64::from(w) / (params.behind_m + params.ahead_m);
    let x0 = x_c - params.behind_m;
    let y_top = road.y_upper_m() + params.margin_m;
    // Road coordinates to pixels: X to the right, Y up.
    let to_px = |x: f64, y: f64| -> (i32, i32) {
        (
            ((x - x0) * px_per_m).round() as i32,
            (f64::from(HEADER_PX) + (y_top - y) * px_per_m).round() as i32,
        )
    };
    // Merge section.
    let (mx0, my0) = to_px(road.merge_start_x_m, road.y_upper_m());
    let (mx1, my1) = to_px(road.merge_end_x_m, road.y_bottom_m);
    root.draw(&Rectangle::new(
        [(mx0, my0), (mx1, my1)],
        RGBColor(75, 58, 38).filled(),
    ))
    .map_err(|x| e(&x))?;
    // Edges and divider.
    let line = |pts: &[[f64; 2]]| pts.iter().map(|p| to_px(p[0], p[1])).collect::<Vec<_>>();
    for edge in [road.upper_edge_polyline(), road.lower_edge_polyline()] {
        root.draw(&PathElement::new(
            line(&edge),
            ShapeStyle::from(&RGBColor(230, 230, 230)).stroke_width(2),
        ))
        .map_err(|x| e(&x))?;
    }
    let divider = [
        [road.start_x_m, road.y_lane_m()],
        [road.merge_end_x_m, road.y_lane_m()],
    ];
    root.draw(&PathElement::new(
        line(&divider),
        ShapeStyle::from(&RGBColor(240, 200, 60)).stroke_width(1),
    ))
    .map_err(|x| e(&x))?;
    // Vehicles.
    for row in instant {
        let Some(v) = vehicles.iter().find(|v| v.name == row.vehicle) else {
            continue;
        };
        if ![row.x_m, row.y_m, row.yaw_rad]
            .iter()
            .all(|c| c.is_finite())
        {
            continue;
        }
        let corners = footprint(row.x_m, row.y_m, row.yaw_rad, v.length_m, v.width_m)
            .map(|(x, y)| to_px(x, y));
        // Outside the window: not drawn (its label would be pinned to the picture's edge).
        if corners.iter().all(|&(x, _)| x < 0) || corners.iter().all(|&(x, _)| x >= w as i32) {
            continue;
        }
        let [r, g, b] = vehicle_color(v.id);
        root.draw(&Polygon::new(corners.to_vec(), RGBColor(r, g, b).filled()))
            .map_err(|x| e(&x))?;
        let crashed = collisions
            .iter()
            .any(|c| c.t_s <= t_s + 1e-9 && c.involves(v.id));
        if crashed {
            let mut outline = corners.to_vec();
            outline.push(corners[0]);
            root.draw(&PathElement::new(
                outline,
                ShapeStyle::from(&RGBColor(255, 40, 40)).stroke_width(3),
            ))
            .map_err(|x| e(&x))?;
        }
        let (lx, ly) = to_px(row.x_m - 0.5 * v.length_m, row.y_m + 0.5 * v.width_m);
        root.draw(&Text::new(
            v.name.clone(),
            (lx, ly - 13),
            font(12).color(&RGBColor(235, 235, 235)),
        ))
        .map_err(|x| e(&x))?;
    }
    // Header.
    root.draw(&Rectangle::new(
        [(0, 0), (w as i32, HEADER_PX as i32)],
        RGBColor(20, 20, 22).filled(),
    ))
    .map_err(|x| e(&x))?;
    let speed = followed.map_or(String::new(), |r| {
        format!("  {follow} {:.1} m/s  x = {:.0} m", r.speed_mps, r.x_m)
    });
    let crash = collisions
        .iter()
        .rfind(|c| c.t_s <= t_s + 1e-9)
        .map_or(String::new(), |c| format!("  COLLISION at {:.2} s", c.t_s));
    root.draw(&Text::new(
        format!("{title}  t = {t_s:5.2} s{speed}{crash}"),
        (6, 4),
        font(14).color(&RGBColor(240, 240, 240)),
    ))
    .map_err(|x| e(&x))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn footprint_is_rotated_about_the_centre() {
        let c = footprint(10.0, 2.0, std::f64::consts::FRAC_PI_2, 4.0, 2.0);
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

    fn row(vehicle: &str, x_m: f64, y_m: f64) -> TimeSeriesRow {
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

    /// One frame drawn into memory.
    fn frame(instant: &[TimeSeriesRow]) -> Vec<u8> {
        let road = sim::MergeRoad::default();
        let params = GifParams::default();
        let size = params.size_px(road.y_upper_m() - road.y_bottom_m);
        let vehicles: Vec<GifVehicle> = ["ego", "far"]
            .iter()
            .zip(0..)
            .map(|(name, id)| GifVehicle {
                name: (*name).into(),
                id,
                length_m: 4.5,
                width_m: 1.8,
            })
            .collect();
        let mut buffer = vec![0u8; (size.0 * size.1 * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
            draw_frame(
                &root,
                &road,
                &vehicles,
                instant,
                &[],
                "ego",
                "test",
                &params,
                size,
            )
            .unwrap_or_else(|e| panic!("{e}"));
            root.present().unwrap_or_else(|e| panic!("{e}"));
        }
        buffer
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
