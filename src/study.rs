//! Studies as files (`merge_sim study PLAN.toml`): a plan fixed before the runs (scenario,
//! factors, planners and the reference, instances, endpoints with practical-significance
//! thresholds, collision handling), run paired on the same instances, resumable and shardable
//! like a sweep, and reported with the statistics a referee expects.
//!
//! - [`plan`]: the plan format (`PLAN_FORMAT`), checked before any run ([`plan::StudyPlan`]);
//! - `endpoints`: the figures a plan may name and their units;
//! - [`runner`]: the runs and their rows (JSONL), shards and resumption ([`runner::run_study`]);
//! - `analysis`: paired differences, t-interval, t-test, Wilcoxon, Holm, McNemar, Newcombe
//!   (computed by [`crate::inference`]);
//! - `report`, `figure`, [`provenance`]: the report folder and what it cites.

pub(crate) mod analysis;
pub(crate) mod endpoints;
pub(crate) mod figure;
pub mod plan;
pub mod provenance;
pub(crate) mod report;
pub mod runner;

use std::path::Path;

pub use analysis::{Analysis, analyse};
use plan::StudyPlan;
pub(crate) use report::StudyReport;
use runner::{RunOptions, StudyError, run_study};

/// The plan format, as `merge_sim study --help` prints it.
pub(crate) const PLAN_FORMAT: &str = include_str!("study/plan_format.txt");

/// Runs the whole plan (no shard, no resumption, no rows file) and returns its report: what
/// the Python binding calls. The report folder is written if `out` is given.
pub fn run_and_report(
    plan: &StudyPlan,
    options: &RunOptions,
    out: Option<&Path>,
) -> Result<StudyReport, StudyError> {
    if let Some(out) = out {
        report::check_out(out).map_err(|e| StudyError::Invalid(e.to_string()))?;
    }
    let rows = run_study(plan, options, &|_, _| {})?;
    if options
        .interrupt
        .as_ref()
        .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed))
    {
        return Err(StudyError::Run("interrupted".into()));
    }
    runner::check_complete(plan, &rows)?;
    let report = StudyReport::new(
        plan,
        provenance::of_plan(&plan.path, &plan.text),
        analyse(plan, &rows),
    );
    if let Some(out) = out {
        let fail = |e: report::OutputError| StudyError::Run(e.to_string());
        report::create_out(out).map_err(fail)?;
        let mut text = String::new();
        for row in &rows {
            text.push_str(&runner::jsonl_line(plan, row, None));
            text.push('\n');
        }
        crate::output::write_atomically(&out.join(report::ROWS_JSONL), text.as_bytes())
            .map_err(|e| StudyError::Run(e.to_string()))?;
        report::write_report(out, &report).map_err(fail)?;
    }
    Ok(report)
}
