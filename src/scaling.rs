//! The scaling curve: what one simulated vehicle-second costs as the platoon grows
//! (`examples/scaling_curve.rs`; README "Performance").
//!
//! Each size runs unrecorded, without time series, on rayon's default pool (the vehicles of a
//! tick plan in parallel), a few times; the run of median wall time counts. The cost is wall time per simulated vehicle-second,
//! `wall_time_s / (vehicles × duration_s)`, so a simulator whose per-vehicle work does not grow
//! with the number of vehicles draws a flat line. Performance is measured here, never asserted
//! in a test.

use std::path::Path;

use plotters::prelude::*;
use scenarios::scenario::Scenario;

use crate::experiment::{Finished, InstanceOptions, RunError, run_quietly};
use crate::plots::{PlotError, ensure_font, font, render_png};

/// One measured run.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ScalingPoint {
    /// Scenario name.
    pub scenario: String,
    /// Number of vehicles.
    pub vehicles: usize,
    /// Simulated time (s).
    pub duration_s: f64,
    /// Wall-clock time of the run (s).
    pub wall_time_s: f64,
    /// Median planning cycle (µs).
    pub planner_p50_us: f64,
    /// 99th percentile planning cycle (µs).
    pub planner_p99_us: f64,
    /// Collision and road-edge contact episodes (so a faster run is not a different run).
    pub collisions: usize,
}

impl ScalingPoint {
    /// The point of a finished run.
    pub fn of(finished: &Finished, vehicles: usize) -> Self {
        let s = &finished.summary;
        Self {
            scenario: s.scenario.clone(),
            vehicles,
            duration_s: s.duration_s,
            wall_time_s: s.wall_time_s,
            planner_p50_us: s.planner_stats.p50_plan_us,
            planner_p99_us: s.planner_stats.p99_plan_us,
            collisions: s.collisions,
        }
    }

    /// Simulated vehicle-seconds.
    pub fn vehicle_seconds(&self) -> f64 {
        self.vehicles as f64 * self.duration_s
    }

    /// Wall time per simulated vehicle-second (µs).
    pub fn us_per_vehicle_second(&self) -> f64 {
        1e6 * self.wall_time_s / self.vehicle_seconds()
    }
}

/// Runs `scenario` (nominal, unrecorded) `repeats` times (at least once) and returns the run
/// of median wall time (the runs are identical but for their timing).
pub fn measure(scenario: &Scenario, repeats: usize) -> Result<ScalingPoint, RunError> {
    let mut points = Vec::with_capacity(repeats.max(1));
    for _ in 0..repeats.max(1) {
        let finished = run_quietly(scenario, &InstanceOptions::default())?;
        points.push(ScalingPoint::of(&finished, scenario.vehicles.len()));
    }
    points.sort_by(|a, b| a.wall_time_s.total_cmp(&b.wall_time_s));
    Ok(points.swap_remove(points.len() / 2))
}

/// The Markdown table: one row per point, its cost also as a ratio to `platoon_reference` (the
/// smallest platoon) and to `reference` (the two-vehicle `urgent_merge`).
pub fn markdown_table(
    points: &[ScalingPoint],
    platoon_reference: &ScalingPoint,
    reference: &ScalingPoint,
) -> String {
    let mut text = format!(
        "| scenario | vehicles | simulated vehicle-s | wall s | wall µs per vehicle-s | \
         vs. {} | vs. {} | planner p50 µs | planner p99 µs | collisions |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        platoon_reference.scenario, reference.scenario
    );
    for p in points.iter().chain(std::iter::once(reference)) {
        text.push_str(&format!(
            "| `{}` | {} | {:.0} | {:.2} | {:.0} | {:.2}× | {:.2}× | {:.0} | {:.0} | {} |\n",
            p.scenario,
            p.vehicles,
            p.vehicle_seconds(),
            p.wall_time_s,
            p.us_per_vehicle_second(),
            p.us_per_vehicle_second() / platoon_reference.us_per_vehicle_second(),
            p.us_per_vehicle_second() / reference.us_per_vehicle_second(),
            p.planner_p50_us,
            p.planner_p99_us,
            p.collisions,
        ));
    }
    text
}

/// Writes the curve to `path` (PNG): wall µs per vehicle-second over the number of vehicles,
/// with the two-vehicle `reference` and 1.5 × it (the target) as dashed lines.
pub fn write_png(
    path: &Path,
    points: &[ScalingPoint],
    reference: &ScalingPoint,
    caption: &str,
) -> Result<(), PlotError> {
    if points.is_empty() {
        return Err(PlotError::Empty("no scaling points".into()));
    }
    ensure_font()?;
    let cost: Vec<(f64, f64)> = points
        .iter()
        .map(|p| (p.vehicles as f64, p.us_per_vehicle_second()))
        .collect();
    let reference_cost = reference.us_per_vehicle_second();
    let target = 1.5 * reference_cost;
    let y_max = cost.iter().map(|c| c.1).chain([target]).fold(0.0, f64::max) * 1.2;
    let x_max = cost.iter().map(|c| c.0).fold(0.0, f64::max) * 1.08;
    render_png(path, (1000, 620), |area| {
        let mut chart = ChartBuilder::on(area)
            .caption(caption, font(19))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..x_max, 0.0..y_max)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("vehicles")
            .y_desc("wall µs per simulated vehicle-second")
            .label_style(font(14))
            .axis_desc_style(font(15))
            .light_line_style(WHITE)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y:.0}"))
            .draw()
            .map_err(|e| e.to_string())?;
        let green = RGBColor(44, 160, 44);
        let red = RGBColor(214, 39, 40);
        for (level, color, label) in [
            (
                reference_cost,
                green,
                format!("{} (2 vehicles)", reference.scenario),
            ),
            (target, red, format!("1.5 × {}", reference.scenario)),
        ] {
            chart
                .draw_series(DashedLineSeries::new(
                    [(0.0, level), (x_max, level)],
                    8,
                    6,
                    color.stroke_width(2),
                ))
                .map_err(|e| e.to_string())?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2))
                });
        }
        let blue = RGBColor(31, 119, 180);
        chart
            .draw_series(LineSeries::new(cost.iter().copied(), blue.stroke_width(2)))
            .map_err(|e| e.to_string())?
            .label("platoon of N (the pattern of platoon_merge_50)")
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], blue.stroke_width(2)));
        chart
            .draw_series(cost.iter().map(|&(x, y)| {
                EmptyElement::at((x, y))
                    + Circle::new((0, 0), 5, blue.filled())
                    + Text::new(format!("{y:.0}"), (-14, -24), font(14).color(&blue))
            }))
            .map_err(|e| e.to_string())?;
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .label_font(font(14))
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .draw()
            .map_err(|e| e.to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(scenario: &str, vehicles: usize, wall_time_s: f64) -> ScalingPoint {
        ScalingPoint {
            scenario: scenario.into(),
            vehicles,
            duration_s: 10.0,
            wall_time_s,
            planner_p50_us: 100.0,
            planner_p99_us: 200.0,
            collisions: 0,
        }
    }

    #[test]
    fn the_table_gives_the_cost_per_vehicle_second_and_the_ratios() {
        let small = point("platoon_merge_2", 2, 0.02);
        let big = point("platoon_merge_10", 10, 0.3);
        let reference = point("urgent_merge", 2, 0.01);
        assert_eq!(small.us_per_vehicle_second(), 1000.0);
        let table = markdown_table(&[small.clone(), big], &small, &reference);
        assert!(
            table.contains("| `platoon_merge_10` | 10 | 100 | 0.30 | 3000 | 3.00× | 6.00× |"),
            "{table}"
        );
        assert!(
            table.contains("| `urgent_merge` | 2 | 20 | 0.01 | 500 | 0.50× | 1.00× |"),
            "{table}"
        );
    }
}
