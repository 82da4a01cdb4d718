//! The paper's Fig. 4: sideslip, yaw, yaw rate and speed of one vehicle over time, one line per
//! planner.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{
    DrawResult, PlannerSeries, collision_marks, font, padded_range, planner_color, planner_stroke,
};
use sim::TimeSeriesRow;

/// The legend box of one panel, in the same style on every figure.
pub(super) fn draw_legend<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> Result<(), String>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    CT: CoordTranslate,
{
    chart
        .configure_series_labels()
        .position(position)
        .label_font(font(14))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())
}

/// Fig. 4: sideslip, yaw, yaw rate and speed of `vehicle` over time, one line per planner.
pub(super) fn draw_states(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    series: &[PlannerSeries<'_>],
    vehicle: &str,
) -> DrawResult {
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
    let panels = area.split_evenly((quantities.len(), 1));
    for (panel, (label, get, min_span)) in panels.iter().zip(quantities) {
        let y_range = padded_range(
            series
                .iter()
                .flat_map(|s| s.rows.iter().filter(|r| r.vehicle == vehicle).map(get)),
            0.05,
            min_span,
        );
        let mut chart = ChartBuilder::on(panel)
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
            let color = planner_color(s.planner, index);
            let style = color.stroke_width(planner_stroke(index, series.len()));
            let points: Vec<(f64, f64)> = s
                .rows
                .iter()
                .filter(|r| r.vehicle == vehicle)
                .map(|r| (r.t_s, get(r)))
                .collect();
            chart
                .draw_series(LineSeries::new(points, style))
                .map_err(|e| e.to_string())?
                .label(s.planner.to_string())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], style));
        }
        // Collisions of this vehicle: a vertical red line in the planner's run.
        let y = chart.y_range();
        let mut labelled = false;
        for s in series {
            for (t, _, _, _) in collision_marks(s.rows, s.collisions)
                .into_iter()
                .filter(|m| m.1 == vehicle)
            {
                let line =
                    DashedLineSeries::new([(t, y.start), (t, y.end)], 6, 4, RED.stroke_width(2));
                let anchor = chart.draw_series(line).map_err(|e| e.to_string())?;
                if !labelled {
                    labelled = true;
                    anchor.label("collision").legend(|(x, y)| {
                        PathElement::new([(x, y), (x + 20, y)], RED.stroke_width(2))
                    });
                }
            }
        }
        draw_legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
    }
    Ok(())
}
