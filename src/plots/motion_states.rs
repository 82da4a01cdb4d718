//! The paper's Fig. 4: sideslip, yaw, yaw rate and speed of one vehicle over time, one line per
//! planner.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::legend::{LegendEntry, Mark, split_for_legend};
use super::{
    PanelLayout, PlannerSeries, collision_marks, font, padded_range, panel_layout, planner_color,
    planner_stroke,
};
use sim::TimeSeriesRow;

/// Fig. 4: sideslip, yaw, yaw rate and speed of `vehicle` over time, one line per planner;
/// each panel's legend right of its chart. Returns where each panel was drawn.
pub(super) fn draw_states(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    series: &[PlannerSeries<'_>],
    vehicle: &str,
) -> Result<Vec<PanelLayout>, String> {
    type Getter = fn(&TimeSeriesRow) -> f64;
    let quantities: [(&str, Getter, f64); 4] = [
        ("sideslip β (rad)", |r| r.sideslip_rad, 0.002),
        ("yaw ψ (rad)", |r| r.yaw_rad, 0.002),
        ("yaw rate r (rad/s)", |r| r.yaw_rate_radps, 0.002),
        ("speed v (m/s)", |r| r.speed_mps, 1.0),
    ];
    let t_range = padded_range(
        series.iter().flat_map(|s| s.rows.iter().map(|r| r.t_s)),
        0.0,
        1.0,
    );
    let style_of = |index: usize, planner: &str| {
        planner_color(planner, index).stroke_width(planner_stroke(index, series.len()))
    };
    let mut entries: Vec<LegendEntry> = series
        .iter()
        .enumerate()
        .map(|(index, s)| LegendEntry {
            label: s.planner.to_string(),
            mark: Mark::Line(style_of(index, s.planner)),
        })
        .collect();
    let crashed = series.iter().any(|s| {
        collision_marks(s.rows, s.collisions)
            .iter()
            .any(|m| m.1 == vehicle)
    });
    if crashed {
        entries.push(LegendEntry {
            label: "collision".into(),
            mark: Mark::Dashed(RED.stroke_width(2)),
        });
    }
    let panels = area.split_evenly((quantities.len(), 1));
    let mut layouts = Vec::new();
    for (panel, (label, get, min_span)) in panels.iter().zip(quantities) {
        let y_range = padded_range(
            series
                .iter()
                .flat_map(|s| s.rows.iter().filter(|r| r.vehicle == vehicle).map(get)),
            0.05,
            min_span,
        );
        let (chart_area, legend_area) = split_for_legend(panel, &entries);
        let mut chart = ChartBuilder::on(&chart_area)
            .caption(format!("{vehicle}: {label}"), font(18))
            .margin(8)
            .margin_right(30)
            .x_label_area_size(34)
            .y_label_area_size(70)
            .build_cartesian_2d(t_range.clone(), y_range)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .label_style(font(14))
            .axis_desc_style(font(14))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| e.to_string())?;
        for (index, s) in series.iter().enumerate() {
            let points: Vec<(f64, f64)> = s
                .rows
                .iter()
                .filter(|r| r.vehicle == vehicle)
                .map(|r| (r.t_s, get(r)))
                .collect();
            chart
                .draw_series(LineSeries::new(points, style_of(index, s.planner)))
                .map_err(|e| e.to_string())?;
        }
        // Collisions of this vehicle: a vertical red line in the planner's run.
        let y = chart.y_range();
        for s in series {
            for (t, _, _, _) in collision_marks(s.rows, s.collisions)
                .into_iter()
                .filter(|m| m.1 == vehicle)
            {
                let line =
                    DashedLineSeries::new([(t, y.start), (t, y.end)], 6, 4, RED.stroke_width(2));
                chart.draw_series(line).map_err(|e| e.to_string())?;
            }
        }
        layouts.push(panel_layout(&chart, &legend_area, &entries)?);
    }
    Ok(layouts)
}
