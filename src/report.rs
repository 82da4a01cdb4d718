//! Text reports of runs, comparisons and grids, as the command line prints them.

use sim::TimeSeriesRow;

use crate::grid::{GridMetric, GridOutcome, PairedDifference};
use crate::run_caption::RunCaption;
use crate::summary::RunSummary;

/// The `--csv` time series: a header and one line per vehicle per logged instant.
pub fn time_series_csv(rows: &[TimeSeriesRow]) -> String {
    let mut text = String::from(TimeSeriesRow::CSV_HEADER);
    text.push('\n');
    for row in rows {
        text.push_str(&row.csv_line());
        text.push('\n');
    }
    text
}

/// The side-by-side table of `merge_sim compare`: its caption line (scenario, parameter set,
/// instance, commit), then the safety figures, every vehicle's motion states and the paper's
/// figures, one column per run.
pub fn comparison_table(caption: &RunCaption, summaries: &[RunSummary]) -> String {
    let rows = comparison_rows(summaries);
    let mut out = format!("{}\n", caption.line());
    out.push_str(&format!("{:<28}", "metric"));
    for s in summaries {
        out.push_str(&format!("{:>13}", s.planner));
    }
    out.push('\n');
    for (label, values) in rows {
        out.push_str(&format!("{label:<28}"));
        for value in values {
            out.push_str(&format!("{value:>13}"));
        }
        out.push('\n');
    }
    out
}

/// The same table in Markdown (`merge_sim compare --markdown`): the caption as a paragraph,
/// then one row per figure, one column per run.
pub fn comparison_markdown(caption: &RunCaption, summaries: &[RunSummary]) -> String {
    let mut out = format!("{}\n\n| metric |", caption.line());
    for s in summaries {
        out.push_str(&format!(" {} |", s.planner));
    }
    out.push_str("\n|---|");
    for _ in summaries {
        out.push_str("---:|");
    }
    out.push('\n');
    for (label, values) in comparison_rows(summaries) {
        out.push_str(&format!("| {} |", label.replace('|', "\\|")));
        for value in values {
            out.push_str(&format!(" {} |", value.replace('|', "\\|")));
        }
        out.push('\n');
    }
    out
}

/// The JSON of `merge_sim compare --json`: the caption's fields (`recorded_traffic` on a
/// CommonRoad road only), then the runs' summaries.
pub fn comparison_json(caption: &RunCaption, summaries: &[RunSummary]) -> serde_json::Value {
    let mut json = serde_json::json!({
        "scenario": caption.scenario,
        "params": caption.params,
        "seed": caption.seed.map(|s| s.to_string()),
        "commit": caption.commit,
        "caption": caption.line(),
        "runs": summaries,
    });
    if let (Some(mode), Some(fields)) = (&caption.recorded_traffic, json.as_object_mut()) {
        fields.insert("recorded_traffic".into(), mode.clone().into());
    }
    json
}

/// The rows of the comparison: (label, one value per run).
fn comparison_rows(summaries: &[RunSummary]) -> Vec<(String, Vec<String>)> {
    let mut rows: Vec<(String, Vec<String>)> = Vec::new();
    let mut row = |label: &str, value: &dyn Fn(&RunSummary) -> String| {
        rows.push((label.to_string(), summaries.iter().map(value).collect()));
    };
    row("collisions", &|s| s.collisions.to_string());
    row("min gap m", &|s| {
        s.min_gap_m
            .map(|g| format!("{g:.2}"))
            .unwrap_or_else(|| "-".into())
    });
    row("min TTC s", &|s| {
        s.min_ttc_s
            .map(|t| format!("{t:.2}"))
            .unwrap_or_else(|| "-".into())
    });
    row("near miss", &|s| s.near_miss.to_string());
    if summaries.iter().any(|s| s.recorded_traffic.is_some()) {
        row("caused by replay", &|s| {
            s.collisions_caused_by_replay.to_string()
        });
        row("min gap to recorded m", &|s| {
            s.min_gap_to_recorded_m
                .map(|g| format!("{g:.2}"))
                .unwrap_or_else(|| "-".into())
        });
        row("min TTC to recorded s", &|s| {
            s.min_ttc_to_recorded_s
                .map(|t| format!("{t:.2}"))
                .unwrap_or_else(|| "-".into())
        });
    }
    row("fallbacks", &|s| s.planner_stats.fallbacks.to_string());
    if summaries.iter().any(|s| s.goal_reached.is_some()) {
        row(
            "goal reached at s",
            &|s| match (s.goal_reached, s.goal_time_s) {
                (Some(true), Some(t)) => format!("{t:.2}"),
                (Some(false), _) => "no".into(),
                _ => "-".into(),
            },
        );
    }
    let names: Vec<String> = summaries
        .first()
        .map(|s| s.vehicles.iter().map(|v| v.id.clone()).collect())
        .unwrap_or_default();
    for (i, name) in names.iter().enumerate() {
        let get = |s: &RunSummary| s.vehicles.get(i).cloned();
        row(&format!("{name} |β|max rad"), &|s| {
            get(s)
                .map(|v| format!("{:.4}", v.max_abs_sideslip_rad))
                .unwrap_or_default()
        });
        row(&format!("{name} |ψ|max rad"), &|s| {
            get(s)
                .map(|v| format!("{:.4}", v.max_abs_yaw_rad))
                .unwrap_or_default()
        });
        row(&format!("{name} |r|max rad/s"), &|s| {
            get(s)
                .map(|v| format!("{:.4}", v.max_abs_yaw_rate_radps))
                .unwrap_or_default()
        });
        row(&format!("{name} v_min m/s"), &|s| {
            get(s)
                .map(|v| format!("{:.2}", v.min_speed_mps))
                .unwrap_or_default()
        });
        row(&format!("{name} path m"), &|s| {
            get(s)
                .map(|v| format!("{:.1}", v.path_length_m))
                .unwrap_or_default()
        });
        row(&format!("{name} r sign changes"), &|s| {
            get(s)
                .map(|v| v.yaw_rate_sign_changes.to_string())
                .unwrap_or_default()
        });
        let paper = |s: &RunSummary| get(s).and_then(|v| v.paper_metrics);
        let opt = |value: Option<f64>, digits: usize| {
            value
                .map(|x| format!("{x:.digits$}"))
                .unwrap_or_else(|| "-".into())
        };
        row(&format!("{name} slowing onset s"), &|s| {
            opt(paper(s).and_then(|p| p.slowing_onset_s), 2)
        });
        row(&format!("{name} RMS r merge zone"), &|s| {
            opt(paper(s).and_then(|p| p.merge_zone_rms_yaw_rate_radps), 4)
        });
        row(&format!("{name} RMS r outside"), &|s| {
            opt(
                paper(s).and_then(|p| p.outside_merge_zone_rms_yaw_rate_radps),
                4,
            )
        });
        row(&format!("{name} max lane offset m"), &|s| {
            opt(paper(s).map(|p| p.max_abs_lane_offset_m), 2)
        });
        row(&format!("{name} crosses divider x m"), &|s| {
            opt(paper(s).and_then(|p| p.divider_crossing).map(|c| c.x_m), 1)
        });
    }
    rows
}

/// The grid's table: per cell and planner, the mean of its peak yaw rate and of its merge-zone
/// yaw-rate RMS of `vehicle` over the reference planner's, and the collisions of both.
pub fn grid_table(outcome: &GridOutcome, vehicle: &str) -> String {
    let peak = outcome.paired_differences(vehicle, GridMetric::PeakYawRate);
    let zone = outcome.paired_differences(vehicle, GridMetric::MergeZoneRmsYawRate);
    let mut out = format!(
        "grid {} ({} set), {} instance(s) per cell, vehicle {vehicle}: mean of each planner / mean of {} \
         (peak |r|; RMS r in the merge zone), each over its n pairs (instances where both \
         values exist) of the compared instances (both runs completed), collisions\n",
        outcome.scenario,
        outcome.params,
        outcome.runs.max(1),
        outcome.planners.first().map(String::as_str).unwrap_or("-")
    );
    let ratio = |d: &PairedDifference| match (d.mean, d.reference_mean) {
        (Some(a), Some(b)) if b > 0.0 => format!("{:.2}", a / b),
        _ => "-".into(),
    };
    for (p, z) in peak.iter().zip(&zone) {
        out.push_str(&format!(
            "{:<22} {:<12} peak {:>5} (n {} of {})  zone {:>5} (n {} of {})  collisions {} ({} {})\n",
            p.cell.label(),
            p.planner,
            ratio(p),
            p.pairs,
            p.compared,
            ratio(z),
            z.pairs,
            z.compared,
            p.collisions,
            p.reference,
            p.reference_collisions
        ));
    }
    out
}

/// Paired differences of every planner against the first, for every vehicle and figure, and
/// the collisions of each planner (a single-cell grid).
pub fn study_table(outcome: &GridOutcome) -> String {
    let mut out = String::new();
    let vehicles: Vec<String> = outcome
        .rows
        .iter()
        .flat_map(|r| r.vehicles.iter().map(|v| v.vehicle.clone()))
        .fold(Vec::new(), |mut acc, v| {
            if !acc.contains(&v) {
                acc.push(v);
            }
            acc
        });
    let reference = &outcome.planners[0];
    out.push_str(&format!(
        "paired differences against {reference} (mean ± standard error over n: the pairs where \
         both values exist, of `of` instances where both runs completed; never P/R: of those, \
         the planner's / the reference's runs that never slowed (+inf, not in the means); \
         lower: of the n pairs, those where the planner's value is lower)\n"
    ));
    for planner in &outcome.planners {
        let rows: Vec<_> = outcome
            .rows
            .iter()
            .filter(|r| &r.planner == planner)
            .collect();
        let collisions: u64 = rows.iter().map(|r| r.collisions.unwrap_or(0)).sum();
        let colliding_runs = rows
            .iter()
            .filter(|r| r.collisions.unwrap_or(0) > 0)
            .count();
        let failed = rows.iter().filter(|r| r.error.is_some()).count();
        out.push_str(&format!(
            "{planner:<12} collisions {collisions} in {colliding_runs} of {} runs{}\n",
            rows.len(),
            if failed > 0 {
                format!(", {failed} failed")
            } else {
                String::new()
            }
        ));
    }
    for vehicle in &vehicles {
        for metric in GridMetric::ALL {
            for d in outcome.paired_differences(vehicle, metric) {
                let digits = metric.decimals();
                let fmt = |v: Option<f64>| {
                    v.map(|x| format!("{x:.digits$}"))
                        .unwrap_or_else(|| "-".into())
                };
                out.push_str(&format!(
                    "{vehicle:<10} {:<26} {:<12} {:>9} vs {:>9}  diff {:>9} ± {:<7} n {:>3} of {:>3}{} lower {:>3}\n",
                    metric.label(),
                    d.planner,
                    fmt(d.mean),
                    fmt(d.reference_mean),
                    fmt(d.mean_difference),
                    fmt(d.standard_error),
                    d.pairs,
                    d.compared,
                    if metric == GridMetric::SlowingOnset {
                        format!(" never P/R {}/{}", d.never, d.reference_never)
                    } else {
                        String::new()
                    },
                    d.lower
                ));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn caption() -> RunCaption {
        RunCaption {
            scenario: "dense_merge".into(),
            params: "custom (paper + [sim.planner] substeps)".into(),
            seed: Some(18_446_744_073_709_551_615),
            commit: "0123456789ab".into(),
            recorded_traffic: None,
        }
    }

    #[test]
    fn every_comparison_output_opens_with_the_caption() {
        let line = caption().line();
        let text = comparison_table(&caption(), &[]);
        assert_eq!(text.lines().next(), Some(line.as_str()));
        assert!(text.lines().nth(1).is_some_and(|l| l.starts_with("metric")));
        let markdown = comparison_markdown(&caption(), &[]);
        assert_eq!(markdown.lines().next(), Some(line.as_str()));
        assert!(markdown.contains("| metric |"), "{markdown}");
        let json = comparison_json(&caption(), &[]);
        assert_eq!(json["scenario"], "dense_merge");
        assert_eq!(json["params"], "custom (paper + [sim.planner] substeps)");
        assert_eq!(json["seed"], "18446744073709551615");
        assert_eq!(json["commit"], "0123456789ab");
        assert_eq!(json["caption"], line.as_str());
        assert!(json["runs"].as_array().is_some_and(Vec::is_empty));
    }
}
