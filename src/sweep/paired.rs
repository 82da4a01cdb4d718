//! A multi-planner sweep's report: each planner's aggregate and the paired differences of every
//! planner against the first (the baseline), instance by instance.
//!
//! For a planner P and the baseline B, a figure is compared on every instance where both runs
//! completed (and, for a vehicle's figure, both have that vehicle). A figure that is `null` for
//! a reason that makes it the best or latest possible value (no closing pair: min TTC; no pair
//! in range: min gap; never slowed: slowing onset; never crossed: divider crossing) counts as
//! +∞ in the better / worse / tied counts; one that is `null` because it is undefined (the
//! yaw-rate RMS of a zone never entered) leaves the instance out. The mean, the mean difference
//! P − B and its standard error (sample standard deviation / √n) are over the instances where
//! both values are finite (`pairs`, the `n` of the table); `compared` counts every instance in
//! the better / worse / tied counts, and `never` / `baseline_never` how many of those had the
//! +∞ ("never") value, so an instance that is in `compared` but not in `pairs` is accounted for.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::statistics::{mean, standard_error};
use super::{RunMetrics, RunRow, Shard, SweepError, SweepSummary, VehicleRow};

/// Which way a figure is better.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BetterWhen {
    /// Lower is better (collisions, peak yaw rate, ...).
    Lower,
    /// Higher is better (min gap, min TTC, min speed).
    Higher,
}

/// What a `null` figure means in the comparison.
#[derive(Clone, Copy)]
enum WhenNull {
    /// +∞ (never happened / never closing): counted, not in the mean.
    Infinite,
    /// Undefined: the instance is left out.
    Skip,
}

/// One compared figure: name, direction, meaning of null, value.
struct Figure<T> {
    name: &'static str,
    better_when: Option<BetterWhen>,
    when_null: WhenNull,
    value: fn(&T) -> Option<f64>,
}

const fn figure<T>(
    name: &'static str,
    better_when: Option<BetterWhen>,
    when_null: WhenNull,
    value: fn(&T) -> Option<f64>,
) -> Figure<T> {
    Figure {
        name,
        better_when,
        when_null,
        value,
    }
}

const LOWER: Option<BetterWhen> = Some(BetterWhen::Lower);
const HIGHER: Option<BetterWhen> = Some(BetterWhen::Higher);

/// The run-level figures compared.
const RUN_FIGURES: [Figure<RunMetrics>; 11] = [
    figure("collisions", LOWER, WhenNull::Skip, |m| {
        Some(m.collisions as f64)
    }),
    figure("near_miss", LOWER, WhenNull::Skip, |m| {
        Some(f64::from(u8::from(m.near_miss)))
    }),
    figure("min_gap_m", HIGHER, WhenNull::Infinite, |m| m.min_gap_m),
    figure("min_ttc_s", HIGHER, WhenNull::Infinite, |m| m.min_ttc_s),
    figure("tet_s", LOWER, WhenNull::Skip, |m| Some(m.tet_s)),
    figure("peak_yaw_rate_radps", LOWER, WhenNull::Skip, |m| {
        Some(m.peak_yaw_rate_radps)
    }),
    figure("peak_sideslip_rad", LOWER, WhenNull::Skip, |m| {
        Some(m.peak_sideslip_rad)
    }),
    figure("min_speed_mps", HIGHER, WhenNull::Skip, |m| {
        Some(m.min_speed_mps)
    }),
    figure("shield_interventions", LOWER, WhenNull::Skip, |m| {
        Some(m.shield_interventions as f64)
    }),
    figure("throughput_vph", HIGHER, WhenNull::Skip, |m| {
        m.throughput_vph
    }),
    figure("mean_delay_s", LOWER, WhenNull::Skip, |m| m.mean_delay_s),
];

/// Each vehicle's figures compared: its motion and the paper's figures.
const VEHICLE_FIGURES: [Figure<VehicleRow>; 10] = [
    figure("max_abs_yaw_rate_radps", LOWER, WhenNull::Skip, |v| {
        Some(v.max_abs_yaw_rate_radps)
    }),
    figure("max_abs_sideslip_rad", LOWER, WhenNull::Skip, |v| {
        Some(v.max_abs_sideslip_rad)
    }),
    figure("min_speed_mps", HIGHER, WhenNull::Skip, |v| {
        Some(v.min_speed_mps)
    }),
    figure("slowing_onset_s", None, WhenNull::Infinite, |v| {
        v.slowing_onset_s
    }),
    figure(
        "merge_zone_rms_yaw_rate_radps",
        LOWER,
        WhenNull::Skip,
        |v| v.merge_zone_rms_yaw_rate_radps,
    ),
    figure(
        "outside_merge_zone_rms_yaw_rate_radps",
        LOWER,
        WhenNull::Skip,
        |v| v.outside_merge_zone_rms_yaw_rate_radps,
    ),
    figure("max_abs_lane_offset_m", LOWER, WhenNull::Skip, |v| {
        v.max_abs_lane_offset_m
    }),
    figure("divider_crossing_t_s", None, WhenNull::Infinite, |v| {
        v.divider_crossing_t_s
    }),
    figure("divider_crossings", None, WhenNull::Skip, |v| {
        v.divider_crossings.map(|n| n as f64)
    }),
    figure("path_length_m", None, WhenNull::Skip, |v| {
        Some(v.path_length_m)
    }),
];

/// The paired difference of one planner against the baseline for one figure.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairedDifference {
    /// The planner compared.
    pub planner: String,
    /// The baseline (the first planner of the sweep).
    pub baseline: String,
    /// The figure (a run-level field of the rows, or with `vehicle` a field of that vehicle's).
    pub metric: String,
    /// The vehicle of a per-vehicle figure; null for a run-level one.
    pub vehicle: Option<String>,
    /// Which way is better; null where neither is (e.g. the slowing onset).
    pub better_when: Option<BetterWhen>,
    /// Instances compared (both runs completed, the figure defined for both).
    pub compared: u64,
    /// Of those, instances where both values are finite: the means are over these (the `n` of
    /// the table).
    pub pairs: u64,
    /// Of the compared instances, those where the planner's value is "never" (+∞: no closing
    /// pair, no pair in range, never slowed, never crossed); 0 for figures without one.
    #[serde(default)]
    pub never: u64,
    /// The same for the baseline.
    #[serde(default)]
    pub baseline_never: u64,
    /// Mean of the planner's values.
    pub mean: Option<f64>,
    /// Mean of the baseline's values.
    pub baseline_mean: Option<f64>,
    /// Mean of (planner − baseline).
    pub mean_difference: Option<f64>,
    /// Standard error of that mean (null with fewer than two pairs).
    pub standard_error: Option<f64>,
    /// Instances where the planner's value is lower than the baseline's.
    pub lower: u64,
    /// Instances where it is higher.
    pub higher: u64,
    /// Instances where they are equal.
    pub tied: u64,
    /// Instances where the planner is better (null without a direction).
    pub better: Option<u64>,
    /// Instances where the planner is worse (null without a direction).
    pub worse: Option<u64>,
}

/// Compares `figure` over the instances both planners completed.
fn compare<T>(
    (planner, baseline): (&str, &str),
    vehicle: Option<&str>,
    figure: &Figure<T>,
    pairs: &[(&T, &T)],
) -> PairedDifference {
    let as_ordered = |v: Option<f64>| match (v, figure.when_null) {
        (Some(x), _) => Some(x),
        (None, WhenNull::Infinite) => Some(f64::INFINITY),
        (None, WhenNull::Skip) => None,
    };
    let (mut lower, mut higher, mut tied, mut compared) = (0, 0, 0, 0);
    let (mut never, mut baseline_never) = (0, 0);
    let (mut values, mut baseline_values, mut differences) = (Vec::new(), Vec::new(), Vec::new());
    for (mine, theirs) in pairs {
        let (Some(a), Some(b)) = (
            as_ordered((figure.value)(mine)),
            as_ordered((figure.value)(theirs)),
        ) else {
            continue;
        };
        match a.partial_cmp(&b) {
            Some(std::cmp::Ordering::Less) => lower += 1,
            Some(std::cmp::Ordering::Greater) => higher += 1,
            Some(std::cmp::Ordering::Equal) => tied += 1,
            None => continue,
        }
        compared += 1;
        never += u64::from(a == f64::INFINITY);
        baseline_never += u64::from(b == f64::INFINITY);
        if a.is_finite() && b.is_finite() {
            values.push(a);
            baseline_values.push(b);
            differences.push(a - b);
        }
    }
    let (better, worse) = match figure.better_when {
        Some(BetterWhen::Lower) => (Some(lower), Some(higher)),
        Some(BetterWhen::Higher) => (Some(higher), Some(lower)),
        None => (None, None),
    };
    PairedDifference {
        planner: planner.to_string(),
        baseline: baseline.to_string(),
        metric: figure.name.to_string(),
        vehicle: vehicle.map(str::to_string),
        better_when: figure.better_when,
        compared,
        pairs: differences.len() as u64,
        never,
        baseline_never,
        mean: mean(&values),
        baseline_mean: mean(&baseline_values),
        mean_difference: mean(&differences),
        standard_error: standard_error(&differences),
        lower,
        higher,
        tied,
        better,
        worse,
    }
}

/// The paired differences of every planner against the first, from their rows: run-level
/// figures first, then each vehicle's (vehicles in the order they first appear in the rows).
pub fn paired_differences(summaries: &[SweepSummary]) -> Vec<PairedDifference> {
    let Some((baseline, others)) = summaries.split_first() else {
        return Vec::new();
    };
    type Completed<'a> = (&'a RunRow, &'a RunMetrics);
    fn completed(s: &SweepSummary) -> BTreeMap<u64, Completed<'_>> {
        s.samples
            .iter()
            .filter_map(|r| r.metrics.as_ref().map(|m| (r.instance, (r, m))))
            .collect()
    }
    let reference = completed(baseline);
    let mut vehicles: Vec<&str> = Vec::new();
    for row in summaries.iter().flat_map(|s| &s.samples) {
        for v in &row.vehicles {
            if !vehicles.contains(&v.name.as_str()) {
                vehicles.push(&v.name);
            }
        }
    }
    let mut out = Vec::new();
    for other in others {
        let names = (other.planner.as_str(), baseline.planner.as_str());
        let mine = completed(other);
        let both: Vec<(&Completed, &Completed)> = mine
            .iter()
            .filter_map(|(i, a)| reference.get(i).map(|b| (a, b)))
            .collect();
        let run_pairs: Vec<(&RunMetrics, &RunMetrics)> =
            both.iter().map(|(a, b)| (a.1, b.1)).collect();
        for figure in &RUN_FIGURES {
            out.push(compare(names, None, figure, &run_pairs));
        }
        for vehicle in &vehicles {
            fn find<'a>(row: &'a RunRow, vehicle: &str) -> Option<&'a VehicleRow> {
                row.vehicles.iter().find(|v| v.name == vehicle)
            }
            let vehicle_pairs: Vec<(&VehicleRow, &VehicleRow)> = both
                .iter()
                .filter_map(|(a, b)| Some((find(a.0, vehicle)?, find(b.0, vehicle)?)))
                .collect();
            for figure in &VEHICLE_FIGURES {
                out.push(compare(names, Some(vehicle), figure, &vehicle_pairs));
            }
        }
    }
    out
}

/// The `--json` aggregate of a multi-planner sweep (or of one shard of it).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairedSweepSummary {
    /// Scenario name.
    pub scenario: String,
    /// See [`SweepSummary::scenario_fingerprint`].
    pub scenario_fingerprint: String,
    /// Planner parameter set.
    pub params: String,
    /// The planners, the first the baseline of the paired differences.
    pub planners: Vec<String>,
    /// Sweep seed K (a string in JSON).
    #[serde(with = "crate::exact_seed")]
    pub seed: u64,
    /// Instances in the whole sweep (each run once per planner).
    pub total_runs: u64,
    /// Which part of the sweep this is.
    pub shard: Shard,
    /// The instances of this part, `[start, end)`.
    pub instances: [u64; 2],
    /// (instance, planner) runs of this part without a row (0 for a complete part).
    pub missing_runs: u64,
    /// Wall-clock time (s): of the sweep, or the sum over merged shards. Not reproducible.
    pub wall_time_s: f64,
    /// Every planner against the first.
    pub paired_differences: Vec<PairedDifference>,
    /// Each planner's aggregate with its rows, in the order of `planners`.
    pub per_planner: Vec<SweepSummary>,
}

impl PairedSweepSummary {
    /// The report of the per-planner aggregates `summaries` (one sweep, same shard; the first
    /// the baseline).
    pub fn from_summaries(summaries: Vec<SweepSummary>, wall_time_s: f64) -> Self {
        let first = summaries.first();
        PairedSweepSummary {
            scenario: first.map(|s| s.scenario.clone()).unwrap_or_default(),
            scenario_fingerprint: first
                .map(|s| s.scenario_fingerprint.clone())
                .unwrap_or_default(),
            params: first.map(|s| s.params.clone()).unwrap_or_default(),
            planners: summaries.iter().map(|s| s.planner.clone()).collect(),
            seed: first.map_or(0, |s| s.seed),
            total_runs: first.map_or(0, |s| s.total_runs),
            shard: first.map_or(Shard::WHOLE, |s| s.shard),
            instances: first.map_or([0, 0], |s| s.instances),
            missing_runs: summaries.iter().map(|s| s.missing_runs).sum(),
            wall_time_s,
            paired_differences: paired_differences(&summaries),
            per_planner: summaries,
        }
    }

    /// The paired differences as a table for the terminal.
    pub fn table(&self) -> String {
        let opt = |v: Option<f64>| v.map_or_else(|| "-".into(), |x| format!("{x:.4}"));
        let count = |v: Option<u64>| v.map_or_else(|| "-".into(), |n| n.to_string());
        let mut out = format!(
            "paired differences against the baseline {}: compared = instances where both \
             completed (better / worse / tied are over these; never = +inf: min gap, min TTC, \
             onset, crossing); never P/B = of those, the planner's / the baseline's runs with \
             the never value; n = pairs with both values finite: the means and the mean \
             difference are over these n only\n{:<8} {:<9} {:<38} {:>8} {:>9} {:>4} {:>11} \
             {:>11} {:>20} {:>6} {:>6} {:>5} {:>7} {:>7}\n",
            self.planners.first().map_or("-", String::as_str),
            "planner",
            "vehicle",
            "metric",
            "compared",
            "never P/B",
            "n",
            "baseline",
            "planner",
            "mean diff ± SE",
            "better",
            "worse",
            "tied",
            "lower",
            "higher"
        );
        for d in &self.paired_differences {
            let difference = match (d.mean_difference, d.standard_error) {
                (Some(m), Some(se)) => format!("{m:+.4} ± {se:.4}"),
                (Some(m), None) => format!("{m:+.4}"),
                _ => "-".into(),
            };
            out.push_str(&format!(
                "{:<8} {:<9} {:<38} {:>8} {:>9} {:>4} {:>11} {:>11} {:>20} {:>6} {:>6} {:>5} {:>7} {:>7}\n",
                d.planner,
                d.vehicle.as_deref().unwrap_or("(run)"),
                d.metric,
                d.compared,
                format!("{}/{}", d.never, d.baseline_never),
                d.pairs,
                opt(d.baseline_mean),
                opt(d.mean),
                difference,
                count(d.better),
                count(d.worse),
                d.tied,
                d.lower,
                d.higher,
            ));
        }
        out
    }
}

/// What `merge_sim sweep --json` writes: a single planner's aggregate (as before multi-planner
/// sweeps existed) or a multi-planner sweep's.
#[derive(Clone, Debug, PartialEq)]
pub enum SweepReport {
    /// One planner.
    Single(Box<SweepSummary>),
    /// Several planners, paired.
    Paired(PairedSweepSummary),
}

impl SweepReport {
    /// Reads a `--json` file's text (either kind: a multi-planner file has
    /// `paired_differences`).
    pub fn from_json(text: &str) -> Result<Self, serde_json::Error> {
        let value: serde_json::Value = serde_json::from_str(text)?;
        if value.get("paired_differences").is_some() {
            serde_json::from_value(value).map(SweepReport::Paired)
        } else {
            serde_json::from_value(value).map(|s| SweepReport::Single(Box::new(s)))
        }
    }

    /// The JSON text (pretty).
    pub fn to_json_pretty(&self) -> Result<String, serde_json::Error> {
        match self {
            SweepReport::Single(s) => serde_json::to_string_pretty(s),
            SweepReport::Paired(p) => serde_json::to_string_pretty(p),
        }
    }

    /// Each planner's aggregate, the baseline first.
    pub fn summaries(&self) -> Vec<&SweepSummary> {
        match self {
            SweepReport::Single(s) => vec![s.as_ref()],
            SweepReport::Paired(p) => p.per_planner.iter().collect(),
        }
    }

    /// Every row, in (instance, planner) order (planners in the sweep's order).
    pub fn rows(&self) -> Vec<&RunRow> {
        let mut rows: Vec<(u64, usize, &RunRow)> = self
            .summaries()
            .into_iter()
            .enumerate()
            .flat_map(|(p, s)| s.samples.iter().map(move |r| (r.instance, p, r)))
            .collect();
        rows.sort_by_key(|&(i, p, _)| (i, p));
        rows.into_iter().map(|(_, _, r)| r).collect()
    }

    /// The terminal output: each planner's aggregate, then the paired differences.
    pub fn table(&self) -> String {
        self.table_resumed(0)
    }

    /// [`table`](Self::table) of a sweep of which `resumed` runs were read back (`--resume`):
    /// its rate counts only the runs of this attempt.
    pub fn table_resumed(&self, resumed: u64) -> String {
        match self {
            SweepReport::Single(s) => s.table_resumed(resumed),
            SweepReport::Paired(p) => {
                let mut out = String::new();
                let all_runs: u64 = p.per_planner.iter().map(|s| s.runs).sum();
                for s in &p.per_planner {
                    out.push_str(&s.table_in_paired_sweep(all_runs, resumed));
                    out.push('\n');
                }
                out + &p.table()
            }
        }
    }

    /// The sweep's planners, the first the baseline.
    pub fn planners(&self) -> Vec<String> {
        self.summaries().iter().map(|s| s.planner.clone()).collect()
    }
}

/// Checks that a multi-planner report is consistent (its per-planner aggregates are its
/// planners, in order); `origin` names the file in errors.
pub(super) fn check_paired(origin: &str, p: &PairedSweepSummary) -> Result<(), SweepError> {
    let labels: Vec<&str> = p.per_planner.iter().map(|s| s.planner.as_str()).collect();
    if labels != p.planners.iter().map(String::as_str).collect::<Vec<_>>() {
        return Err(SweepError::Invalid(format!(
            "{origin}: per_planner holds {} but planners = {}: not a `merge_sim sweep --json` \
             file as written",
            labels.join(","),
            p.planners.join(",")
        )));
    }
    Ok(())
}
