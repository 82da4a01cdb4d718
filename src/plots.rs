//! Figures of a planner comparison (`merge_sim compare --plots DIR`): the paper's Fig. 3 (the
//! paths of both vehicles, one panel per planner) and Fig. 4 (sideslip, yaw, yaw rate and speed
//! over time, one line per planner) as PNG, plus the data behind them as one CSV.
//!
//! Rendering uses plotters' bitmap backend; text goes through `ab_glyph` with DejaVu Sans
//! embedded from `docs/fonts` (proportional, so a minus sign sits next to its number; Bitstream
//! Vera licence, `docs/fonts/LICENSE-DejaVu.txt`), so no
//! system font library (fontconfig, freetype) is needed to build or run.
//!
//! Every figure opens with a caption band naming the scenario, the parameter set and the
//! simulator's commit (`crate::run_caption::RunCaption`); every panel's legend sits right of
//! its chart, outside the plotting area, so it covers no data.
//!
//! Every file is written whole or not at all ([`crate::output::write_atomically`]).

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use mergesim_types::lanes::LaneRoad;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};
use sim::TimeSeriesRow;
use sim::safety::CollisionEvent;

use crate::output::{temporary_path, write_atomically};
use crate::run_caption::RunCaption;

mod legend;
mod motion_states;
mod paths;

pub(crate) use legend::PixelBox;
pub(crate) use legend::{CAPTION_PX, draw_caption};
use legend::{LegendEntry, draw_legend};
use motion_states::draw_states;
use paths::draw_paths;

/// The embedded font (DejaVu Sans).
const FONT_TTF: &[u8] = include_bytes!("../docs/fonts/DejaVuSans.ttf");

/// Font family name the figures ask for; the embedded font is registered under it.
const FONT_FAMILY: &str = "sans-serif";

/// Figure of the paths (paper Fig. 3).
pub const PATHS_PNG: &str = "paths.png";

/// CSV with every plotted sample: `planner,` + [`TimeSeriesRow::CSV_HEADER`].
pub const TIME_SERIES_CSV: &str = "time_series.csv";

/// File name of the motion-state figure of one vehicle (paper Fig. 4 is the obstacle's).
pub fn states_png(vehicle: &str) -> String {
    format!("states_{}.png", crate::output::file_name_part(vehicle))
}

/// Size of every figure (pixels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FigureSize {
    /// Width (px).
    pub width_px: u32,
    /// Height of one panel (px); a figure is as high as its panels.
    pub panel_height_px: u32,
}

impl Default for FigureSize {
    fn default() -> Self {
        Self {
            width_px: 1400,
            panel_height_px: 260,
        }
    }
}

/// The time series of one planner's run.
#[derive(Clone, Copy, Debug)]
pub struct PlannerSeries<'a> {
    /// Planner name (`pf-cs`, ...).
    pub planner: &'a str,
    /// The run's time series (every vehicle, interleaved as the world logs them).
    pub rows: &'a [TimeSeriesRow],
    /// The run's collisions (vehicle ids = order of first appearance in `rows`), marked on the
    /// figures.
    pub collisions: &'a [CollisionEvent],
}

/// Line style of the `index`-th of `count` planners: earlier planners are drawn wider and
/// later ones on top, so identical runs (PF-CS and PF-SP often are) stay visible as a line
/// inside a wider one.
pub(crate) fn planner_stroke(index: usize, count: usize) -> u32 {
    2 + count.saturating_sub(index + 1).min(3) as u32
}

/// Colour of the vehicle with id `index` ([`sim::recording::vehicle_color`]): the same RGB as
/// in the recording and the GIF.
pub(crate) fn vehicle_rgb(index: usize) -> RGBColor {
    let [r, g, b] = sim::recording::vehicle_color(u32::try_from(index).unwrap_or(u32::MAX));
    RGBColor(r, g, b)
}

/// Where a panel of a figure was drawn (figure pixels): its chart's mapping from data to
/// pixels, its plotting area and its legend's box.
#[derive(Clone)]
pub struct PanelLayout {
    /// Data (x, y) to figure pixels, as the chart drew them.
    pub coord: Cartesian2d<RangedCoordf64, RangedCoordf64>,
    /// The plotting area.
    pub plot_px: PixelBox,
    /// The legend's box.
    pub legend_px: PixelBox,
}

impl PanelLayout {
    /// The pixel of data point (x, y).
    pub fn to_px(&self, x: f64, y: f64) -> (i32, i32) {
        self.coord.translate(&(x, y))
    }
}

/// Draws the legend `entries` in `legend_area`, level with the top of `chart`'s plotting area,
/// and returns the panel's layout.
fn panel_layout(
    chart: &ChartContext<'_, BitMapBackend<'_>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    legend_area: &DrawingArea<BitMapBackend<'_>, Shift>,
    entries: &[LegendEntry],
) -> Result<PanelLayout, String> {
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let top = ys.start - legend_area.get_base_pixel().1;
    let legend_px = draw_legend(legend_area, entries, top.max(0))?;
    Ok(PanelLayout {
        coord: chart.as_coord_spec().clone(),
        plot_px: PixelBox {
            x0: xs.start,
            y0: ys.start,
            x1: xs.end,
            y1: ys.end,
        },
        legend_px,
    })
}

/// The position and time of each vehicle of `rows` at each collision of `collisions`: the
/// first logged instant at or after the collision.
pub(crate) fn collision_marks(
    rows: &[TimeSeriesRow],
    collisions: &[CollisionEvent],
) -> Vec<(f64, String, f64, f64)> {
    let names = vehicle_names(rows);
    let mut marks = Vec::new();
    for c in collisions {
        for id in [c.id_a, c.id_b] {
            let Some(name) = names.get(id as usize) else {
                continue;
            };
            if let Some(r) = rows
                .iter()
                .find(|r| r.vehicle == *name && r.t_s >= c.t_s - 1e-9)
            {
                marks.push((c.t_s, name.clone(), r.x_m, r.y_m));
            }
        }
    }
    marks
}

/// Why a figure could not be written.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// Writing or reading a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// plotters failed to draw.
    #[error("drawing {figure}: {message}")]
    Draw {
        /// The figure's file name.
        figure: String,
        /// plotters' message.
        message: String,
    },
    /// The embedded font could not be parsed.
    #[error("the embedded font docs/fonts/DejaVuSans.ttf could not be loaded")]
    Font,
    /// There is nothing to draw.
    #[error("nothing to plot: {0}")]
    Empty(String),
}

/// Checks before a long simulation that `dir` is an existing, writable folder (or one that can
/// be created) and that every file the figures of `vehicles` will be written to is a writable
/// regular file or new (`output::check_output_path`).
pub fn check_plot_dir(dir: &Path, vehicles: &[&str]) -> Result<(), String> {
    if dir.as_os_str().is_empty() {
        return Err("--plots: empty path".into());
    }
    if dir.exists() && !dir.is_dir() {
        return Err(format!(
            "--plots {}: exists and is not a folder",
            dir.display()
        ));
    }
    // A missing folder is created after the runs (one level, like `mkdir`): its parent must
    // exist and be writable.
    let probe_dir = if dir.is_dir() {
        dir
    } else {
        match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        }
    };
    if !probe_dir.is_dir() {
        return Err(format!(
            "--plots {}: folder {} does not exist",
            dir.display(),
            probe_dir.display()
        ));
    }
    let probe = probe_dir.join(".mergesim_plots_probe.tmp");
    std::fs::write(&probe, b"").map_err(|e| format!("--plots {}: {e}", dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    if dir.is_dir() {
        let names = [PATHS_PNG.to_string(), TIME_SERIES_CSV.to_string()]
            .into_iter()
            .chain(vehicles.iter().map(|v| states_png(v)));
        for name in names {
            crate::output::check_output_path(&dir.join(name), "--plots")?;
        }
    }
    Ok(())
}

pub(crate) fn ensure_font() -> Result<(), PlotError> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        [FontStyle::Normal, FontStyle::Bold]
            .into_iter()
            .all(|style| register_font(FONT_FAMILY, style, FONT_TTF).is_ok())
    });
    if ok { Ok(()) } else { Err(PlotError::Font) }
}

/// Line colour of a planner: the paper's (PF-CS red, PF-SP blue, PF-ISO green) and orange for
/// the PF-ISO-PRED ablation; others cycle through plotters' palette.
pub fn planner_color(planner: &str, index: usize) -> RGBColor {
    match planner {
        "pf-cs" => RGBColor(214, 39, 40),
        "pf-sp" => RGBColor(31, 119, 180),
        "pf-iso" => RGBColor(44, 160, 44),
        "pf-iso-pred" => RGBColor(255, 127, 14),
        _ => {
            let c = Palette99::pick(index).to_rgba();
            RGBColor(c.0, c.1, c.2)
        }
    }
}

/// Vehicle names in order of first appearance in the rows.
pub fn vehicle_names(rows: &[TimeSeriesRow]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for row in rows {
        if !names.contains(&row.vehicle) {
            names.push(row.vehicle.clone());
        }
    }
    names
}

/// The CSV of every run: `planner,` + the time-series columns, planners in the given order.
pub fn comparison_csv(series: &[PlannerSeries<'_>]) -> String {
    let mut text = format!("planner,{}\n", TimeSeriesRow::CSV_HEADER);
    for s in series {
        for row in s.rows {
            text.push_str(s.planner);
            text.push(',');
            text.push_str(&row.csv_line());
            text.push('\n');
        }
    }
    text
}

/// Writes [`PATHS_PNG`], one [`states_png`] per vehicle and [`TIME_SERIES_CSV`] into `dir`;
/// returns the written paths in that order. Every figure's caption band says `caption`. The
/// paths figure draws the road `lanes` (any road of lanes, curved or not), with each lane's id
/// if `lane_ids`.
pub fn write_comparison(
    dir: &Path,
    lanes: &LaneRoad,
    lane_ids: bool,
    series: &[PlannerSeries<'_>],
    size: FigureSize,
    caption: &RunCaption,
) -> Result<Vec<PathBuf>, PlotError> {
    if series.is_empty() || series.iter().all(|s| s.rows.is_empty()) {
        return Err(PlotError::Empty(
            "no time series (run with keep_time_series)".into(),
        ));
    }
    ensure_font()?;
    if !dir.is_dir() {
        std::fs::create_dir(dir).map_err(|e| PlotError::Io {
            path: dir.to_path_buf(),
            source: e,
        })?;
    }
    let mut written = Vec::new();
    let mut vehicles: Vec<String> = Vec::new();
    for s in series {
        for name in vehicle_names(s.rows) {
            if !vehicles.contains(&name) {
                vehicles.push(name);
            }
        }
    }

    let path = dir.join(PATHS_PNG);
    render_png(&path, paths_size(size, series.len()), |area| {
        draw_paths_figure(area, lanes, lane_ids, series, &vehicles, caption).map(|_| ())
    })?;
    written.push(path);

    for (id, vehicle) in vehicles.iter().enumerate() {
        let path = dir.join(states_png(vehicle));
        render_png(&path, states_size(size), |area| {
            draw_states_figure(area, series, vehicle, id, caption).map(|_| ())
        })?;
        written.push(path);
    }

    let path = dir.join(TIME_SERIES_CSV);
    write_atomically(&path, comparison_csv(series).as_bytes()).map_err(|source| PlotError::Io {
        path: path.clone(),
        source,
    })?;
    written.push(path);
    Ok(written)
}

pub(crate) type DrawResult = Result<(), String>;

/// Pixel size of the paths figure of `planners` panels.
fn paths_size(size: FigureSize, planners: usize) -> (u32, u32) {
    (
        size.width_px,
        CAPTION_PX + size.panel_height_px * planners as u32,
    )
}

/// Pixel size of a motion-state figure (four panels).
fn states_size(size: FigureSize) -> (u32, u32) {
    (size.width_px, CAPTION_PX + 4 * size.panel_height_px)
}

/// Fig. 3 under its caption band.
fn draw_paths_figure(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    lanes: &LaneRoad,
    lane_ids: bool,
    series: &[PlannerSeries<'_>],
    vehicles: &[String],
    caption: &RunCaption,
) -> Result<Vec<PanelLayout>, String> {
    let rest = draw_caption(area, &caption.line(), None)?;
    draw_paths(&rest, lanes, lane_ids, series, vehicles)
}

/// Fig. 4 of vehicle `id` (`vehicle`) under its caption band, which starts with a square in
/// the vehicle's colour.
fn draw_states_figure(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    series: &[PlannerSeries<'_>],
    vehicle: &str,
    id: usize,
    caption: &RunCaption,
) -> Result<Vec<PanelLayout>, String> {
    let text = format!("{vehicle} — {}", caption.line());
    let rest = draw_caption(area, &text, Some(vehicle_rgb(id)))?;
    draw_states(&rest, series, vehicle)
}

/// Renders into a temporary PNG beside `path` (plotters encodes to a file), then moves the bytes
/// into place with [`write_atomically`].
pub(crate) fn render_png(
    path: &Path,
    size_px: (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> DrawResult,
) -> Result<(), PlotError> {
    let figure = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    // plotters picks the encoder by extension: keep `.png` at the end.
    let render_path = temporary_path(path).with_extension("render.png");
    let result = (|| {
        {
            let backend = BitMapBackend::new(&render_path, size_px);
            let area = backend.into_drawing_area();
            area.fill(&WHITE).map_err(|e| e.to_string())?;
            draw(&area)?;
            area.present().map_err(|e| e.to_string())?;
        }
        Ok::<(), String>(())
    })();
    if let Err(message) = result {
        let _ = std::fs::remove_file(&render_path);
        return Err(PlotError::Draw { figure, message });
    }
    let bytes = std::fs::read(&render_path).map_err(|source| PlotError::Io {
        path: render_path.clone(),
        source,
    });
    let _ = std::fs::remove_file(&render_path);
    write_atomically(path, &bytes?).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        source,
    })
}

pub(crate) fn font(size: u32) -> TextStyle<'static> {
    TextStyle::from((FONT_FAMILY, size).into_font()).color(&BLACK)
}

/// Range covering `values` with a relative margin; a degenerate range is widened to `min_span`.
fn padded_range(values: impl Iterator<Item = f64>, margin: f64, min_span: f64) -> Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if !lo.is_finite() || !hi.is_finite() {
        return 0.0..min_span;
    }
    let span = (hi - lo).max(min_span);
    let mid = 0.5 * (lo + hi);
    let half = 0.5 * span * (1.0 + 2.0 * margin);
    (mid - half)..(mid + half)
}

#[cfg(test)]
mod tests;
