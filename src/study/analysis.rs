//! The statistics of a study, from its rows (sorted: the result does not depend on how they
//! were computed):
//!
//! - **continuous endpoints**, per cell and planner against the reference, on the instances
//!   where both runs completed and both figures are finite: the paired differences d = planner
//!   − reference, their mean with a 95 % t-interval, the paired t-test and Wilcoxon
//!   signed-rank p-values, the median and p90 (nearest rank) of d, and the effect set against
//!   the endpoint's threshold δ (see [`Verdict`]). The primary endpoint stands alone; the
//!   p-values of the secondary endpoints are Holm-adjusted within the family of one planner
//!   pair in one cell. Motion-state endpoints are tested over the plan's window (before the
//!   first contact by default); the other window's figures are computed beside them, not tested
//!   for a decision (and not in a Holm family);
//! - **collisions**, per cell and planner against the reference: the 2×2 discordance table of
//!   (planner collided, reference collided) over the paired instances, the exact McNemar
//!   p-value, and the paired difference in collision proportions with its 95 % CI (Newcombe's
//!   method for paired proportions).

use serde::{Deserialize, Serialize};

use super::plan::{EndpointWindow, StudyPlan};
use super::runner::StudyRow;
use crate::inference;
use crate::sweep::RunStatus;
use crate::sweep::statistics::nearest_rank_percentile;

/// Confidence of every interval.
pub const CONFIDENCE: f64 = 0.95;

/// How an effect stands against its practical-significance threshold δ, from its 95 % CI
/// `[lo, hi]` of the mean difference.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// The CI lies entirely inside (−δ, δ): any effect is practically negligible.
    Negligible,
    /// The CI lies entirely beyond δ (lo > δ) or below −δ (hi < −δ): practically relevant.
    Relevant,
    /// The CI straddles ±δ: the data cannot tell.
    Inconclusive,
    /// No interval (fewer than two paired differences, or all equal).
    NotEstimable,
}

impl Verdict {
    /// The rule applied to a CI and a threshold.
    pub fn of(ci: Option<[f64; 2]>, threshold: f64) -> Self {
        match ci {
            None => Self::NotEstimable,
            Some([lo, hi]) if lo > -threshold && hi < threshold => Self::Negligible,
            Some([lo, hi]) if lo > threshold || hi < -threshold => Self::Relevant,
            Some(_) => Self::Inconclusive,
        }
    }

    /// Its name in the tables.
    pub fn name(self) -> &'static str {
        match self {
            Self::Negligible => "negligible",
            Self::Relevant => "relevant",
            Self::Inconclusive => "inconclusive",
            Self::NotEstimable => "not estimable",
        }
    }
}

/// One endpoint's paired comparison of a planner with the reference in one cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EndpointComparison {
    /// Cell index.
    pub cell: usize,
    /// Cell label.
    pub cell_label: String,
    /// The compared planner.
    pub planner: String,
    /// The reference planner.
    pub reference: String,
    /// Endpoint name.
    pub endpoint: String,
    /// `primary` or `secondary`.
    pub role: String,
    /// `pre-contact` or `whole-run`.
    pub window: String,
    /// Whether this window is the one the plan tests (else shown beside it).
    pub tested: bool,
    /// Unit of the figure, the differences and the threshold.
    pub unit: String,
    /// Paired differences the statistics are over.
    pub n: usize,
    /// Instances left out: a run failed or a figure was null (e.g. never reached).
    pub n_excluded: usize,
    /// Mean of the reference's figure over the pairs.
    pub reference_mean: Option<f64>,
    /// Mean of the planner's figure over the pairs.
    pub planner_mean: Option<f64>,
    /// Mean difference (planner − reference).
    pub mean_difference: Option<f64>,
    /// Standard deviation of the differences.
    pub sd: Option<f64>,
    /// 95 % t-interval of the mean difference.
    pub ci95: Option<[f64; 2]>,
    /// Paired t-test, two-sided.
    pub p_t: Option<f64>,
    /// Wilcoxon signed-rank test, two-sided.
    pub p_wilcoxon: Option<f64>,
    /// Holm-adjusted `p_t` (tested secondary endpoints only).
    pub p_t_holm: Option<f64>,
    /// Holm-adjusted `p_wilcoxon` (tested secondary endpoints only).
    pub p_wilcoxon_holm: Option<f64>,
    /// Median difference (nearest rank).
    pub median_difference: Option<f64>,
    /// 90th percentile of the differences (nearest rank).
    pub p90_difference: Option<f64>,
    /// Practical-significance threshold δ (in `unit`).
    pub threshold: f64,
    /// The CI against ±δ.
    pub verdict: Verdict,
    /// Why a statistic is missing, if one is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// The collision comparison of a planner with the reference in one cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CollisionComparison {
    /// Cell index.
    pub cell: usize,
    /// Cell label.
    pub cell_label: String,
    /// The compared planner.
    pub planner: String,
    /// The reference planner.
    pub reference: String,
    /// Paired instances (both runs completed).
    pub n: u64,
    /// Both collided.
    pub both: u64,
    /// Only the planner collided.
    pub only_planner: u64,
    /// Only the reference collided.
    pub only_reference: u64,
    /// Neither collided.
    pub neither: u64,
    /// Exact McNemar test (two-sided binomial test on the discordant pairs).
    pub p_mcnemar: f64,
    /// The planner's collision proportion.
    pub planner_rate: Option<f64>,
    /// The reference's collision proportion.
    pub reference_rate: Option<f64>,
    /// Difference of proportions (planner − reference).
    pub difference: Option<f64>,
    /// Its 95 % CI.
    pub ci95: Option<[f64; 2]>,
    /// How the CI was computed.
    pub method: String,
}

/// Every table of a study.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Analysis {
    /// Continuous endpoints.
    pub endpoints: Vec<EndpointComparison>,
    /// Collisions.
    pub collisions: Vec<CollisionComparison>,
    /// Runs that did not complete (they enter no pair).
    pub failed_runs: Vec<StudyRow>,
}

/// Computes every table from the rows (any order).
pub fn analyse(plan: &StudyPlan, rows: &[StudyRow]) -> Analysis {
    let mut rows: Vec<StudyRow> = rows.to_vec();
    super::runner::sort_rows(plan, &mut rows);
    let reference = plan.reference.as_str();
    let find = |cell: usize, planner: &str, instance: u64| {
        rows.iter()
            .find(|r| r.cell == cell && r.planner == planner && r.instance == instance)
            .filter(|r| r.status == RunStatus::Completed)
    };
    let mut endpoints = Vec::new();
    let mut collisions = Vec::new();
    for (cell, _) in &plan.cells {
        for planner in plan.planners.iter().filter(|p| **p != plan.reference) {
            let name = planner.as_str();
            let pairs: Vec<(&StudyRow, &StudyRow)> = (0..plan.instances)
                .filter_map(|i| Some((find(cell.index, name, i)?, find(cell.index, reference, i)?)))
                .collect();
            for window in [EndpointWindow::PreContact, EndpointWindow::WholeRun] {
                let family_start = endpoints.len();
                for (k, endpoint) in plan.endpoints().enumerate() {
                    // Run-level figures have one window: listed once, as tested.
                    if !endpoint.figure.is_motion_state() && window != plan.window {
                        continue;
                    }
                    let tested = !endpoint.figure.is_motion_state() || window == plan.window;
                    let value = |row: &StudyRow| {
                        let v = row.endpoints.get(&endpoint.figure.name)?;
                        match window {
                            EndpointWindow::PreContact => v.pre_contact,
                            EndpointWindow::WholeRun => v.whole_run,
                        }
                        .filter(|x| x.is_finite())
                    };
                    let values: Vec<(f64, f64)> = pairs
                        .iter()
                        .filter_map(|(p, r)| Some((value(p)?, value(r)?)))
                        .collect();
                    let mut comparison = compare(&values, endpoint.threshold);
                    comparison.cell = cell.index;
                    comparison.cell_label = cell.label();
                    comparison.planner = name.to_string();
                    comparison.reference = reference.to_string();
                    comparison.endpoint = endpoint.figure.name.clone();
                    comparison.role = if k == 0 { "primary" } else { "secondary" }.into();
                    comparison.window = if endpoint.figure.is_motion_state() {
                        window.name().into()
                    } else {
                        "whole-run".into()
                    };
                    comparison.tested = tested;
                    comparison.unit = endpoint.unit.clone();
                    comparison.n_excluded = plan.instances as usize - values.len();
                    endpoints.push(comparison);
                }
                // Holm over the tested secondary endpoints of this planner pair and cell.
                let family: Vec<usize> = (family_start..endpoints.len())
                    .filter(|&i| endpoints[i].tested && endpoints[i].role == "secondary")
                    .collect();
                for pick in [0usize, 1] {
                    let members: Vec<(usize, f64)> = family
                        .iter()
                        .filter_map(|&i| {
                            let e = &endpoints[i];
                            Some((i, if pick == 0 { e.p_t? } else { e.p_wilcoxon? }))
                        })
                        .collect();
                    let adjusted =
                        inference::holm(&members.iter().map(|(_, p)| *p).collect::<Vec<_>>());
                    for ((i, _), q) in members.iter().zip(adjusted) {
                        if pick == 0 {
                            endpoints[*i].p_t_holm = Some(q);
                        } else {
                            endpoints[*i].p_wilcoxon_holm = Some(q);
                        }
                    }
                }
            }
            collisions.push(collision_comparison(
                cell.index,
                &cell.label(),
                name,
                reference,
                &pairs,
            ));
        }
    }
    let failed_runs = rows
        .iter()
        .filter(|r| r.status != RunStatus::Completed)
        .cloned()
        .collect();
    Analysis {
        endpoints,
        collisions,
        failed_runs,
    }
}

/// The statistics of (planner, reference) value pairs against `threshold` (labels unset).
fn compare(values: &[(f64, f64)], threshold: f64) -> EndpointComparison {
    let n = values.len();
    let differences: Vec<f64> = values.iter().map(|(p, r)| p - r).collect();
    let mean = |xs: &mut dyn Iterator<Item = f64>| (n > 0).then(|| xs.sum::<f64>() / n as f64);
    let mut sorted = differences.clone();
    sorted.sort_by(f64::total_cmp);
    let mut notes = Vec::new();
    let t = match inference::paired_t(&differences, CONFIDENCE) {
        Ok(t) => Some(t),
        Err(e) => {
            notes.push(format!("t: {e}"));
            None
        }
    };
    let wilcoxon = match inference::wilcoxon_signed_rank(&differences) {
        Ok(w) => Some(w),
        Err(e) => {
            notes.push(format!("Wilcoxon: {e}"));
            None
        }
    };
    let ci95 = t.as_ref().map(|t| t.ci);
    EndpointComparison {
        cell: 0,
        cell_label: String::new(),
        planner: String::new(),
        reference: String::new(),
        endpoint: String::new(),
        role: String::new(),
        window: String::new(),
        tested: false,
        unit: String::new(),
        n,
        n_excluded: 0,
        reference_mean: mean(&mut values.iter().map(|v| v.1)),
        planner_mean: mean(&mut values.iter().map(|v| v.0)),
        mean_difference: mean(&mut differences.iter().copied()),
        sd: t.as_ref().map(|t| t.sd),
        ci95,
        p_t: t.as_ref().map(|t| t.p_two_sided),
        p_wilcoxon: wilcoxon.as_ref().map(|w| w.p_two_sided),
        p_t_holm: None,
        p_wilcoxon_holm: None,
        median_difference: nearest_rank_percentile(&sorted, 50.0),
        p90_difference: nearest_rank_percentile(&sorted, 90.0),
        threshold,
        verdict: Verdict::of(ci95, threshold),
        note: (!notes.is_empty()).then(|| notes.join("; ")),
    }
}

fn collision_comparison(
    cell: usize,
    cell_label: &str,
    planner: &str,
    reference: &str,
    pairs: &[(&StudyRow, &StudyRow)],
) -> CollisionComparison {
    let count = |f: &dyn Fn(bool, bool) -> bool| {
        pairs
            .iter()
            .filter(|(p, r)| f(p.collided, r.collided))
            .count() as u64
    };
    let table = inference::Discordance {
        both: count(&|p, r| p && r),
        only_first: count(&|p, r| p && !r),
        only_second: count(&|p, r| !p && r),
        neither: count(&|p, r| !p && !r),
    };
    let difference = inference::newcombe_paired_difference(&table, CONFIDENCE).ok();
    CollisionComparison {
        cell,
        cell_label: cell_label.to_string(),
        planner: planner.to_string(),
        reference: reference.to_string(),
        n: pairs.len() as u64,
        both: table.both,
        only_planner: table.only_first,
        only_reference: table.only_second,
        neither: table.neither,
        p_mcnemar: inference::mcnemar_exact(&table),
        planner_rate: difference.as_ref().map(|d| d.first),
        reference_rate: difference.as_ref().map(|d| d.second),
        difference: difference.as_ref().map(|d| d.difference),
        ci95: difference.as_ref().map(|d| d.ci),
        method: difference
            .map(|d| d.method.to_string())
            .unwrap_or_else(|| "no paired instance".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verdicts_follow_the_documented_rule() {
        assert_eq!(Verdict::of(Some([-0.5, 0.5]), 1.0), Verdict::Negligible);
        assert_eq!(Verdict::of(Some([1.5, 2.0]), 1.0), Verdict::Relevant);
        assert_eq!(Verdict::of(Some([-3.0, -1.2]), 1.0), Verdict::Relevant);
        assert_eq!(Verdict::of(Some([0.5, 1.5]), 1.0), Verdict::Inconclusive);
        assert_eq!(Verdict::of(Some([-1.0, 0.0]), 1.0), Verdict::Inconclusive);
        assert_eq!(Verdict::of(None, 1.0), Verdict::NotEstimable);
    }

    #[test]
    fn compare_pairs_the_values() {
        let values = [(2.0, 1.0), (3.0, 1.0), (4.0, 1.5), (2.5, 1.5)];
        let c = compare(&values, 0.1);
        assert_eq!(c.n, 4);
        assert_eq!(c.mean_difference, Some(1.625));
        assert_eq!(c.planner_mean, Some(2.875));
        assert_eq!(c.reference_mean, Some(1.25));
        // Differences 1, 2, 2.5, 1 sorted 1, 1, 2, 2.5: nearest-rank median 1, p90 2.5.
        assert_eq!(c.median_difference, Some(1.0));
        assert_eq!(c.p90_difference, Some(2.5));
        assert!(c.ci95.is_some_and(|[lo, hi]| lo < 1.625 && 1.625 < hi));
    }
}
