//! The study's figure (`effects.png`): every tested effect (planner − reference, per cell and
//! endpoint) as its mean difference with the 95 % CI, divided by the endpoint's threshold δ,
//! so all endpoints share one axis; the band (−1, 1) is "negligible".

use std::path::Path;

use plotters::prelude::*;

use super::report::StudyReport;
use crate::plots::{PlotError, ensure_font, font, render_png};

/// Writes the figure of `report` to `path`.
pub fn write_effects_png(path: &Path, report: &StudyReport) -> Result<(), PlotError> {
    ensure_font()?;
    let rows: Vec<_> = report
        .analysis
        .endpoints
        .iter()
        .filter(|r| r.tested)
        .collect();
    let row_h = 26i32;
    let label = |r: &super::analysis::EndpointComparison| {
        format!(
            "{} | {} − {} | {}{}",
            r.cell_label,
            r.planner,
            r.reference,
            r.endpoint,
            if r.role == "primary" {
                " (primary)"
            } else {
                ""
            }
        )
    };
    // About 7 px per character of the 13 px font, and a margin.
    let longest = rows
        .iter()
        .map(|r| label(r).chars().count())
        .max()
        .unwrap_or(0);
    let left = (30 + 7 * longest as i32).max(300);
    let (right, top) = (40i32, 70i32);
    let plot_w = 560i32;
    let width = (left + plot_w + right) as u32;
    let height = (top + row_h * rows.len().max(1) as i32 + 50) as u32;
    // Scaled CIs; the axis covers [−2, 2] at least and every finite end.
    let scaled: Vec<Option<(f64, f64, f64)>> = rows
        .iter()
        .map(|r| {
            let [lo, hi] = r.ci95?;
            let mean = r.mean_difference?;
            Some((lo / r.threshold, mean / r.threshold, hi / r.threshold))
        })
        .collect();
    let extent = scaled
        .iter()
        .flatten()
        .flat_map(|(lo, _, hi)| [lo.abs(), hi.abs()])
        .filter(|v| v.is_finite())
        .fold(2.0f64, f64::max)
        .min(1e6);
    let x_of = |v: f64| left + ((v + extent) / (2.0 * extent) * plot_w as f64).round() as i32;
    render_png(path, (width, height), |area| {
        let title = format!(
            "{}: effects / threshold (95 % CI), {} window{}",
            report.study,
            report.window,
            if report.provenance.exploratory {
                " — exploratory"
            } else {
                ""
            }
        );
        area.draw(&Text::new(title, (10, 12), font(18)))
            .map_err(|e| e.to_string())?;
        let y_end = top + row_h * rows.len().max(1) as i32;
        // The negligible band and the axis.
        area.draw(&Rectangle::new(
            [(x_of(-1.0), top - 6), (x_of(1.0), y_end)],
            RGBColor(225, 240, 225).filled(),
        ))
        .map_err(|e| e.to_string())?;
        for v in [-extent, -1.0, 0.0, 1.0, extent] {
            area.draw(&PathElement::new(
                vec![(x_of(v), top - 6), (x_of(v), y_end)],
                RGBColor(120, 120, 120),
            ))
            .map_err(|e| e.to_string())?;
            area.draw(&Text::new(
                format!("{v:.3}"),
                (x_of(v) - 14, y_end + 6),
                font(13),
            ))
            .map_err(|e| e.to_string())?;
        }
        area.draw(&Text::new(
            format!("axis: (planner − reference) / δ, from −{extent:.3} to {extent:.3}"),
            (left, y_end + 24),
            font(13),
        ))
        .map_err(|e| e.to_string())?;
        for (k, (r, s)) in rows.iter().zip(&scaled).enumerate() {
            let y = top + k as i32 * row_h + row_h / 2;
            area.draw(&Text::new(label(r), (10, y - 8), font(13)))
                .map_err(|e| e.to_string())?;
            let Some((lo, mean, hi)) = s else {
                area.draw(&Text::new("not estimable", (left + 4, y - 8), font(13)))
                    .map_err(|e| e.to_string())?;
                continue;
            };
            let colour = match r.verdict {
                super::analysis::Verdict::Negligible => RGBColor(46, 140, 67),
                super::analysis::Verdict::Relevant => RGBColor(214, 39, 40),
                _ => RGBColor(60, 60, 60),
            };
            area.draw(&PathElement::new(
                vec![(x_of(*lo), y), (x_of(*hi), y)],
                colour.stroke_width(2),
            ))
            .map_err(|e| e.to_string())?;
            area.draw(&Circle::new((x_of(*mean), y), 4, colour.filled()))
                .map_err(|e| e.to_string())?;
        }
        Ok(())
    })
}
