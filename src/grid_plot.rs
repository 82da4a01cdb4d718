//! The sensitivity grid as a figure: one heat map per compared planner, cells coloured by the
//! ratio of its mean metric to the reference planner's (below 1: calmer than the reference).
//! Rows: the four (prediction, sub-steps) combinations; columns: τ × τ_I. A cell whose runs
//! collided is outlined in black and marked with the compared planner's collision count, and
//! the reference planner's below it ("ref ×n").

use std::path::Path;

use plotters::prelude::*;

use crate::grid::{GridMetric, GridOutcome};
use crate::plots::{CAPTION_PX, PlotError, draw_caption, ensure_font, font, render_png};
use crate::run_caption::RunCaption;

/// Colour of a ratio: green below 1, white at 1, red above (saturating at ½ and 2).
fn ratio_color(ratio: f64) -> RGBColor {
    if !ratio.is_finite() {
        return RGBColor(200, 200, 200);
    }
    let t = ratio.log2().clamp(-1.0, 1.0);
    let mix = |a: u8, b: u8, f: f64| (a as f64 + (b as f64 - a as f64) * f).round() as u8;
    if t < 0.0 {
        let f = -t;
        RGBColor(mix(255, 46, f), mix(255, 160, f), mix(255, 67, f))
    } else {
        RGBColor(mix(255, 214, t), mix(255, 39, t), mix(255, 40, t))
    }
}

/// The caption line of the grid figure: `caption` with the grid's instances.
pub fn grid_caption_line(caption: &RunCaption, outcome: &GridOutcome) -> String {
    let instances = if outcome.runs == 0 {
        "nominal".to_string()
    } else {
        format!(
            "{} instances per cell, sweep seed {}",
            outcome.runs, outcome.seed
        )
    };
    caption.line_with(&instances)
}

/// Writes the figure of `metric` for `vehicle` to `path`, under a caption band saying
/// [`grid_caption_line`].
pub fn write_grid_png(
    path: &Path,
    outcome: &GridOutcome,
    vehicle: &str,
    metric: GridMetric,
    caption: &RunCaption,
) -> Result<(), PlotError> {
    ensure_font()?;
    let diffs = outcome.paired_differences(vehicle, metric);
    let compared: Vec<&String> = outcome.planners.iter().skip(1).collect();
    if compared.is_empty() {
        return Err(PlotError::Empty(
            "the grid figure needs at least two planners".into(),
        ));
    }
    let axes = &outcome.axes;
    let rows: Vec<(bool, bool)> = axes
        .predict_obstacles_in_path
        .iter()
        .flat_map(|&p| axes.substeps.iter().map(move |&s| (p, s)))
        .collect();
    let cols: Vec<(f64, f64)> = axes
        .path_time_gap_s
        .iter()
        .flat_map(|&t| axes.interaction_time_gap_s.iter().map(move |&ti| (t, ti)))
        .collect();
    let (cell_w, cell_h) = (96i32, 44i32);
    let (left, top, panel_gap) = (190i32, 70i32, 60i32);
    let panel_h = top + cell_h * rows.len() as i32 + 40;
    let caption_line = grid_caption_line(caption, outcome);
    // Wide enough for the caption too (about 8 px per character at its size).
    let width = ((left + cell_w * cols.len() as i32 + 30) as u32)
        .max(8 * caption_line.chars().count() as u32 + 20);
    let height = (panel_h * compared.len() as i32 + panel_gap) as u32 + CAPTION_PX;
    let metric_name = metric.label();
    render_png(path, (width, height), |root| {
        let area = &draw_caption(root, &caption_line, None)?;
        for (k, planner) in compared.iter().enumerate() {
            let y0 = k as i32 * panel_h + 10;
            let title = format!(
                "{vehicle}: {metric_name}, {planner} / {} (mean over {} instance{}; {} set)",
                outcome.planners[0],
                outcome.runs.max(1),
                if outcome.runs.max(1) == 1 { "" } else { "s" },
                outcome.params
            );
            area.draw(&Text::new(title, (10, y0), font(17)))
                .map_err(|e| e.to_string())?;
            // Column headers: τ and τ_I.
            for (j, (tau, tau_i)) in cols.iter().enumerate() {
                let x = left + j as i32 * cell_w;
                area.draw(&Text::new(
                    format!("τ {tau} τI {tau_i}"),
                    (x + 6, y0 + 34),
                    font(13),
                ))
                .map_err(|e| e.to_string())?;
            }
            for (i, (predict, substeps)) in rows.iter().enumerate() {
                let y = y0 + top - 16 + i as i32 * cell_h;
                let label = format!(
                    "{}, {}",
                    if *predict {
                        "predicted"
                    } else {
                        "current pos."
                    },
                    if *substeps { "sub-steps" } else { "1 step" }
                );
                area.draw(&Text::new(label, (10, y + cell_h / 2 - 8), font(13)))
                    .map_err(|e| e.to_string())?;
                for (j, (tau, tau_i)) in cols.iter().enumerate() {
                    let x = left + j as i32 * cell_w;
                    let d = diffs.iter().find(|d| {
                        &d.planner == *planner
                            && d.cell.predict_obstacles_in_path == *predict
                            && d.cell.substeps == *substeps
                            && d.cell.path_time_gap_s == *tau
                            && d.cell.interaction_time_gap_s == *tau_i
                    });
                    let ratio = d
                        .and_then(|d| Some(d.mean? / d.reference_mean?))
                        .unwrap_or(f64::NAN);
                    area.draw(&Rectangle::new(
                        [(x, y), (x + cell_w - 2, y + cell_h - 2)],
                        ratio_color(ratio).filled(),
                    ))
                    .map_err(|e| e.to_string())?;
                    let collisions = d.map_or(0, |d| d.collisions);
                    let reference_collisions = d.map_or(0, |d| d.reference_collisions);
                    if collisions > 0 || reference_collisions > 0 {
                        area.draw(&Rectangle::new(
                            [(x, y), (x + cell_w - 2, y + cell_h - 2)],
                            BLACK.stroke_width(3),
                        ))
                        .map_err(|e| e.to_string())?;
                    }
                    let text = if ratio.is_finite() {
                        format!("{ratio:.2}")
                    } else {
                        "-".into()
                    };
                    let text = if collisions > 0 {
                        format!("{text} ×{collisions}")
                    } else {
                        text
                    };
                    area.draw(&Text::new(text, (x + 8, y + 6), font(15)))
                        .map_err(|e| e.to_string())?;
                    if reference_collisions > 0 {
                        area.draw(&Text::new(
                            format!("ref ×{reference_collisions}"),
                            (x + 8, y + cell_h - 20),
                            font(12),
                        ))
                        .map_err(|e| e.to_string())?;
                    }
                }
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ratio_colours_are_green_below_one_and_red_above() {
        assert_eq!(ratio_color(1.0), RGBColor(255, 255, 255));
        let below = ratio_color(0.5);
        assert!(below.1 > below.0);
        let above = ratio_color(2.0);
        assert!(above.0 > above.1);
        assert_eq!(ratio_color(f64::NAN), RGBColor(200, 200, 200));
    }
}
