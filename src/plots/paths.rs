//! The paper's Fig. 3: the road and each vehicle's path, one panel per planner.

use mergesim_types::lanes::LaneRoad;
use plotters::coord::Shift;
use plotters::prelude::*;
use sim::road_drawing::RoadDrawing;

use super::legend::{LegendEntry, Mark, split_for_legend};
use super::{
    PanelLayout, PlannerSeries, collision_marks, font, padded_range, panel_layout, vehicle_rgb,
};

/// Fig. 3: the road (any road of lanes: outer edges solid, dividers dashed, closed lane ends,
/// merge sections shaded, lane ids if `lane_ids`) and each vehicle's path, one panel per
/// planner; the first vehicle solid, the others dashed, in the vehicles' colours (the
/// recording's and the GIF's, by id: `vehicles` is in id order); collisions marked with red
/// crosses; each panel's legend right of its chart. Returns where each panel was drawn.
pub(super) fn draw_paths(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    lanes: &LaneRoad,
    lane_ids: bool,
    series: &[PlannerSeries<'_>],
    vehicles: &[String],
) -> Result<Vec<PanelLayout>, String> {
    let road = RoadDrawing::new(lanes);
    let x_range = padded_range(
        series.iter().flat_map(|s| s.rows.iter().map(|r| r.x_m)),
        0.01,
        10.0,
    );
    // Across: the road over the drawn X range (on the straight merge road its two edges), and
    // every path.
    let [mut y_lo, mut y_hi] = road.y_range_over_m(lanes, [x_range.start, x_range.end]);
    for r in series.iter().flat_map(|s| s.rows.iter()) {
        if r.y_m.is_finite() {
            y_lo = y_lo.min(r.y_m);
            y_hi = y_hi.max(r.y_m);
        }
    }
    let y_range = (y_lo - 0.5)..(y_hi + 0.5);
    let style_of = |k: usize| vehicle_rgb(k).stroke_width(2);
    let mut entries: Vec<LegendEntry> = vehicles
        .iter()
        .enumerate()
        .map(|(k, vehicle)| LegendEntry {
            label: vehicle.clone(),
            mark: if k == 0 {
                Mark::Line(style_of(k))
            } else {
                Mark::Dashed(style_of(k))
            },
        })
        .collect();
    if series
        .iter()
        .any(|s| !collision_marks(s.rows, s.collisions).is_empty())
    {
        entries.push(LegendEntry {
            label: "collision".into(),
            mark: Mark::Cross,
        });
    }
    let panels = area.split_evenly((series.len(), 1));
    let mut layouts = Vec::new();
    for (panel, s) in panels.iter().zip(series) {
        let (chart_area, legend_area) = split_for_legend(panel, &entries);
        let mut chart = ChartBuilder::on(&chart_area)
            .caption(format!("{}: paths", s.planner), font(20))
            .margin(8)
            .margin_right(30)
            .x_label_area_size(34)
            .y_label_area_size(56)
            .build_cartesian_2d(x_range.clone(), y_range.clone())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("x (m)")
            .y_desc("y (m)")
            .label_style(font(14))
            .axis_desc_style(font(14))
            .light_line_style(WHITE)
            .draw()
            .map_err(|e| e.to_string())?;
        // Merge sections, shaded as in the paper.
        let merge = RGBColor(255, 200, 120).mix(0.35);
        chart
            .draw_series(road.merge_sections.iter().map(|section| {
                Polygon::new(
                    section.iter().map(|p| (p[0], p[1])).collect::<Vec<_>>(),
                    merge.filled(),
                )
            }))
            .map_err(|e| e.to_string())?;
        let edge = BLACK.stroke_width(2);
        for line in &road.outer_edges {
            chart
                .draw_series(LineSeries::new(line.iter().map(|p| (p[0], p[1])), edge))
                .map_err(|e| e.to_string())?;
        }
        for line in &road.dividers {
            chart
                .draw_series(DashedLineSeries::new(
                    line.iter().map(|p| (p[0], p[1])),
                    8,
                    6,
                    RGBColor(120, 120, 120).stroke_width(1),
                ))
                .map_err(|e| e.to_string())?;
        }
        for end in &road.closed_ends {
            chart
                .draw_series(LineSeries::new(
                    end.iter().map(|p| (p[0], p[1])),
                    RGBColor(200, 40, 30).stroke_width(3),
                ))
                .map_err(|e| e.to_string())?;
        }
        if lane_ids {
            chart
                .draw_series(
                    road.lane_labels
                        .iter()
                        .map(|l| Text::new(l.text.clone(), (l.at_m[0], l.at_m[1]), font(12))),
                )
                .map_err(|e| e.to_string())?;
        }
        for (k, vehicle) in vehicles.iter().enumerate() {
            let points: Vec<(f64, f64)> = s
                .rows
                .iter()
                .filter(|r| r.vehicle == *vehicle)
                .map(|r| (r.x_m, r.y_m))
                .collect();
            if k == 0 {
                chart
                    .draw_series(LineSeries::new(points, style_of(k)))
                    .map_err(|e| e.to_string())?;
            } else {
                chart
                    .draw_series(DashedLineSeries::new(points, 10, 5, style_of(k)))
                    .map_err(|e| e.to_string())?;
            }
        }
        // Collisions: a red cross at each vehicle involved, where it was.
        let marks = collision_marks(s.rows, s.collisions);
        if !marks.is_empty() {
            chart
                .draw_series(
                    marks
                        .iter()
                        .map(|m| Cross::new((m.2, m.3), 7, RED.stroke_width(3))),
                )
                .map_err(|e| e.to_string())?;
        }
        layouts.push(panel_layout(&chart, &legend_area, &entries)?);
    }
    Ok(layouts)
}
