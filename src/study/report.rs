//! The report of a study: `report.md` (Markdown), the tables as CSV (`endpoints.csv`,
//! `collisions.csv`) and JSON (`report.json`, everything), and a figure (`effects.png`), each
//! file written whole or not at all. It cites the plan's git blob hash, the commit that first
//! added the plan and the simulator's commit, and is marked **exploratory** when the plan is
//! not that committed version.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::analysis::{Analysis, CONFIDENCE, CollisionComparison, EndpointComparison};
use super::plan::StudyPlan;
use super::provenance::Provenance;
use crate::output::write_atomically;

/// The file that marks a folder as a study report (a folder without it is never written to,
/// unless empty).
pub const MARKER: &str = ".mergesim-study";
/// The Markdown report.
pub const REPORT_MD: &str = "report.md";
/// Everything as JSON.
pub const REPORT_JSON: &str = "report.json";
/// The continuous endpoints' table.
pub const ENDPOINTS_CSV: &str = "endpoints.csv";
/// The collisions' table.
pub const COLLISIONS_CSV: &str = "collisions.csv";
/// The figure of the effects against their thresholds.
pub const EFFECTS_PNG: &str = "effects.png";
/// The rows of an unsharded run (and of a merge).
pub const ROWS_JSONL: &str = "rows.jsonl";

/// The rows file of shard `i/n`.
pub fn shard_rows_file(shard: crate::sweep::Shard) -> String {
    format!("rows.shard-{}-of-{}.jsonl", shard.index, shard.count)
}

/// What `report.json` holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyReport {
    /// Study name.
    pub study: String,
    /// What it asks.
    pub description: String,
    /// The plan file as given.
    pub plan: String,
    /// Where the plan came from, and whether the report is exploratory.
    pub provenance: Provenance,
    /// The scenario as the plan names it.
    pub scenario: String,
    /// The cells (`factor=value` labels), in order.
    pub cells: Vec<String>,
    /// Planners.
    pub planners: Vec<String>,
    /// The reference planner.
    pub reference: String,
    /// Instances per cell and planner.
    pub instances: u64,
    /// Seed K of the instances (a string).
    #[serde(with = "crate::exact_seed")]
    pub seed: u64,
    /// Runs (cells × planners × instances).
    pub runs: u64,
    /// The window motion-state endpoints are tested over.
    pub window: String,
    /// The tables.
    pub analysis: Analysis,
}

impl StudyReport {
    /// The report of `analysis` for `plan`.
    pub fn new(plan: &StudyPlan, provenance: Provenance, analysis: Analysis) -> Self {
        StudyReport {
            study: plan.name.clone(),
            description: plan.description.clone(),
            plan: plan.path.display().to_string(),
            provenance,
            scenario: plan.scenario_source.clone(),
            cells: plan.cells.iter().map(|(c, _)| c.label()).collect(),
            planners: plan.planners.clone(),
            reference: plan.reference.clone(),
            instances: plan.instances,
            seed: plan.seed,
            runs: plan.total_runs(),
            window: plan.window.name().to_string(),
            analysis,
        }
    }
}

/// Why an output folder cannot be used or written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The folder is not ours (exit code 2, before any run).
    #[error("{0}")]
    Refused(String),
    /// Writing failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// The default report folder of a plan: `<plan stem>.report` beside it.
pub fn default_out(plan: &Path) -> PathBuf {
    let stem = plan
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "study".into());
    plan.with_file_name(format!("{stem}.report"))
}

/// Checks that `out` is a report folder (has [`MARKER`]), an empty folder or new, in an
/// existing parent: anything else is refused.
pub fn check_out(out: &Path) -> Result<(), OutputError> {
    match std::fs::symlink_metadata(out) {
        Err(_) => {
            let parent = match out.parent() {
                Some(p) if !p.as_os_str().is_empty() => p,
                _ => Path::new("."),
            };
            if !parent.is_dir() {
                return Err(OutputError::Refused(format!(
                    "--out {}: folder {} does not exist",
                    out.display(),
                    parent.display()
                )));
            }
            Ok(())
        }
        Ok(meta) if !meta.is_dir() => Err(OutputError::Refused(format!(
            "--out {}: exists and is not a folder",
            out.display()
        ))),
        Ok(_) => {
            let empty = std::fs::read_dir(out)
                .map(|mut d| d.next().is_none())
                .unwrap_or(false);
            if empty || out.join(MARKER).is_file() {
                Ok(())
            } else {
                Err(OutputError::Refused(format!(
                    "--out {}: an existing folder that is not a study report (no {MARKER} in \
                     it): refusing to write into it; choose another --out",
                    out.display()
                )))
            }
        }
    }
}

/// Creates the report folder (checked by [`check_out`]) with its marker.
pub fn create_out(out: &Path) -> Result<(), OutputError> {
    let io = |source| OutputError::Io {
        path: out.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(out).map_err(io)?;
    let marker = out.join(MARKER);
    if !marker.is_file() {
        write_atomically(&marker, b"a merge_sim study report folder\n").map_err(io)?;
    }
    Ok(())
}

/// Removes the report files of an earlier run from `out` (before a new run, so an interrupted
/// one never leaves an old report beside new rows).
pub fn remove_stale(out: &Path) -> Result<(), OutputError> {
    for name in [
        REPORT_MD,
        REPORT_JSON,
        ENDPOINTS_CSV,
        COLLISIONS_CSV,
        EFFECTS_PNG,
    ] {
        let path = out.join(name);
        match std::fs::remove_file(&path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(OutputError::Io { path, source: e });
            }
            _ => {}
        }
    }
    Ok(())
}

/// Writes every report file into `out` (created with [`create_out`]).
pub fn write_report(out: &Path, report: &StudyReport) -> Result<(), OutputError> {
    let write = |name: &str, bytes: &[u8]| {
        let path = out.join(name);
        write_atomically(&path, bytes).map_err(|source| OutputError::Io { path, source })
    };
    let json = serde_json::to_string_pretty(report).map_err(|e| OutputError::Io {
        path: out.join(REPORT_JSON),
        source: std::io::Error::other(e),
    })?;
    super::figure::write_effects_png(&out.join(EFFECTS_PNG), report).map_err(|e| {
        OutputError::Io {
            path: out.join(EFFECTS_PNG),
            source: std::io::Error::other(e.to_string()),
        }
    })?;
    write(
        ENDPOINTS_CSV,
        endpoints_csv(&report.analysis.endpoints).as_bytes(),
    )?;
    write(
        COLLISIONS_CSV,
        collisions_csv(&report.analysis.collisions).as_bytes(),
    )?;
    write(REPORT_JSON, json.as_bytes())?;
    write(REPORT_MD, markdown(report).as_bytes())
}

fn opt(v: Option<f64>) -> String {
    v.map(|x| format!("{x}")).unwrap_or_default()
}

fn csv_text(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// The endpoints' table as CSV (full precision).
pub fn endpoints_csv(rows: &[EndpointComparison]) -> String {
    let mut out = String::from(
        "cell,cell_label,planner,reference,endpoint,role,window,tested,unit,n,n_excluded,\
         reference_mean,planner_mean,mean_difference,sd,ci95_low,ci95_high,p_t,p_wilcoxon,\
         p_t_holm,p_wilcoxon_holm,median_difference,p90_difference,threshold,verdict\n",
    );
    for r in rows {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            r.cell,
            csv_text(&r.cell_label),
            r.planner,
            r.reference,
            r.endpoint,
            r.role,
            r.window,
            r.tested,
            r.unit,
            r.n,
            r.n_excluded,
            opt(r.reference_mean),
            opt(r.planner_mean),
            opt(r.mean_difference),
            opt(r.sd),
            opt(r.ci95.map(|c| c[0])),
            opt(r.ci95.map(|c| c[1])),
            opt(r.p_t),
            opt(r.p_wilcoxon),
            opt(r.p_t_holm),
            opt(r.p_wilcoxon_holm),
            opt(r.median_difference),
            opt(r.p90_difference),
            r.threshold,
            r.verdict.name()
        );
    }
    out
}

/// The collisions' table as CSV.
pub fn collisions_csv(rows: &[CollisionComparison]) -> String {
    let mut out = String::from(
        "cell,cell_label,planner,reference,n,both,only_planner,only_reference,neither,\
         p_mcnemar,planner_rate,reference_rate,difference,ci95_low,ci95_high,method\n",
    );
    for r in rows {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            r.cell,
            csv_text(&r.cell_label),
            r.planner,
            r.reference,
            r.n,
            r.both,
            r.only_planner,
            r.only_reference,
            r.neither,
            r.p_mcnemar,
            opt(r.planner_rate),
            opt(r.reference_rate),
            opt(r.difference),
            opt(r.ci95.map(|c| c[0])),
            opt(r.ci95.map(|c| c[1])),
            csv_text(&r.method)
        );
    }
    out
}

/// A number for the Markdown tables: 4 significant digits.
fn num(v: Option<f64>) -> String {
    match v {
        None => "–".into(),
        Some(0.0) => "0".into(),
        Some(x) if x.abs() >= 1e4 || x.abs() < 1e-3 => format!("{x:.3e}"),
        Some(x) => {
            let digits = (3 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
            format!("{x:.digits$}")
        }
    }
}

fn p(v: Option<f64>) -> String {
    match v {
        None => "–".into(),
        Some(x) if x < 1e-4 => "< 0.0001".into(),
        Some(x) => format!("{x:.4}"),
    }
}

fn ci(v: Option<[f64; 2]>) -> String {
    v.map(|[lo, hi]| format!("[{}, {}]", num(Some(lo)), num(Some(hi))))
        .unwrap_or_else(|| "–".into())
}

fn endpoint_table(out: &mut String, rows: &[&EndpointComparison], holm: bool) {
    out.push_str(
        "| cell | planner − reference | endpoint | window | n (excl.) | mean ref | mean planner | \
         mean diff | 95 % CI | median diff | p90 diff | p (t) | p (Wilcoxon) |",
    );
    if holm {
        out.push_str(" p (t) Holm | p (W) Holm |");
    }
    out.push_str(" threshold | verdict |\n|");
    let columns = if holm { 17 } else { 15 };
    out.push_str(&"---|".repeat(columns));
    out.push('\n');
    for r in rows {
        let _ = write!(
            out,
            "| {} | {} − {} | {} | {} | {} ({}) | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.cell_label,
            r.planner,
            r.reference,
            r.endpoint,
            r.window,
            r.n,
            r.n_excluded,
            num(r.reference_mean),
            num(r.planner_mean),
            num(r.mean_difference),
            ci(r.ci95),
            num(r.median_difference),
            num(r.p90_difference),
            p(r.p_t),
            p(r.p_wilcoxon),
        );
        if holm {
            let _ = write!(out, " {} | {} |", p(r.p_t_holm), p(r.p_wilcoxon_holm));
        }
        let _ = writeln!(
            out,
            " {} {} | {} |",
            num(Some(r.threshold)),
            r.unit,
            r.verdict.name()
        );
    }
    out.push('\n');
}

/// The Markdown report.
pub fn markdown(report: &StudyReport) -> String {
    let mut out = String::new();
    let prov = &report.provenance;
    let _ = writeln!(out, "# Study: {}\n", report.study);
    if prov.exploratory {
        let _ = writeln!(
            out,
            "> **exploratory**: {}. Only a report of the plan exactly as first committed is \
             confirmatory.\n",
            prov.reasons.join("; ")
        );
    }
    if !report.description.is_empty() {
        let _ = writeln!(out, "{}\n", report.description);
    }
    out.push_str("## Provenance\n\n");
    let _ = writeln!(out, "- plan: `{}`", report.plan);
    let _ = writeln!(
        out,
        "- plan's git blob hash (`git hash-object`): `{}`",
        prov.plan_blob.as_deref().unwrap_or("unavailable")
    );
    let _ = writeln!(
        out,
        "- commit that first added the plan: `{}`",
        prov.plan_added_in
            .as_deref()
            .unwrap_or("none (never committed)")
    );
    let _ = writeln!(out, "- simulator commit: `{}`", prov.simulator_commit);
    let _ = writeln!(
        out,
        "- status: {}\n",
        if prov.exploratory {
            "**exploratory**"
        } else {
            "confirmatory (the plan is the version first committed)"
        }
    );
    out.push_str("## Design\n\n");
    let _ = writeln!(out, "- scenario: `{}`", report.scenario);
    let _ = writeln!(
        out,
        "- planners: {} (reference: **{}**)",
        report.planners.join(", "),
        report.reference
    );
    let _ = writeln!(
        out,
        "- instances: n = {} per cell and planner, seed K = {} (instance i runs with seed \
         SplitMix64::derive(K, i), the same for every cell and planner: the comparisons are \
         paired)",
        report.instances, report.seed
    );
    let _ = writeln!(out, "- runs: {}", report.runs);
    out.push_str("- cells:\n");
    for (i, c) in report.cells.iter().enumerate() {
        let _ = writeln!(out, "  - {i}: {c}");
    }
    let _ = writeln!(
        out,
        "\n## Method\n\n\
         - Paired differences d = planner − reference on each instance where both runs \
         completed and both figures are finite (`n`; `excl.` counts the others).\n\
         - Mean of d with its {:.0} % t-interval; two-sided paired t-test and Wilcoxon \
         signed-rank p-values; median and p90 of d by nearest rank.\n\
         - Verdict against the threshold δ: **negligible** when the CI lies entirely inside \
         (−δ, δ); **relevant** when it lies entirely beyond δ or below −δ; else \
         **inconclusive**; **not estimable** (`not-estimable` in the JSON) when fewer than two \
         differences remain or all are equal — e.g. a figure that is \"never\" (+∞: min TTC, \
         min gap, slowing onset, divider crossing) in every run, since such runs are left out.\n\
         - The primary endpoint stands alone (no correction). Holm's correction runs over the \
         secondary endpoints of one planner pair in one cell: that is the family.\n\
         - Collisions: motion-state endpoints (per-vehicle figures) are tested over the **{}** \
         window (before the run's first contact; a run without contact: the whole run), so no \
         run is dropped for colliding and post-contact peaks do not count; the other window's \
         figures stand beside them, untested. Run-level figures (min gap, min TTC, TET) cover \
         the whole run.\n",
        CONFIDENCE * 100.0,
        report.window
    );
    let rows = &report.analysis.endpoints;
    out.push_str("## Primary endpoint\n\n");
    let primary: Vec<&EndpointComparison> = rows
        .iter()
        .filter(|r| r.role == "primary" && r.tested)
        .collect();
    endpoint_table(&mut out, &primary, false);
    out.push_str(
        "## Secondary endpoints\n\nHolm-adjusted within the family of one planner pair in one \
         cell.\n\n",
    );
    let secondary: Vec<&EndpointComparison> = rows
        .iter()
        .filter(|r| r.role == "secondary" && r.tested)
        .collect();
    if secondary.is_empty() {
        out.push_str("(none)\n\n");
    } else {
        endpoint_table(&mut out, &secondary, true);
    }
    out.push_str("## Beside them: the other window (not tested)\n\n");
    let beside: Vec<&EndpointComparison> = rows.iter().filter(|r| !r.tested).collect();
    if beside.is_empty() {
        out.push_str("(none)\n\n");
    } else {
        endpoint_table(&mut out, &beside, false);
    }
    out.push_str(
        "## Collisions\n\nPer planner pair and cell: the 2×2 discordance table over the paired \
         instances, the exact McNemar test, and the difference in collision proportions \
         (planner − reference) with its 95 % CI.\n\n\
         | cell | planner − reference | n | both | only planner | only reference | neither | \
         p (McNemar, exact) | rate planner | rate ref | difference | 95 % CI | method |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for c in &report.analysis.collisions {
        let _ = writeln!(
            out,
            "| {} | {} − {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.cell_label,
            c.planner,
            c.reference,
            c.n,
            c.both,
            c.only_planner,
            c.only_reference,
            c.neither,
            p(Some(c.p_mcnemar)),
            num(c.planner_rate),
            num(c.reference_rate),
            num(c.difference),
            ci(c.ci95),
            c.method
        );
    }
    out.push_str("\n## Figure\n\n");
    let _ = writeln!(
        out,
        "![effects]({EFFECTS_PNG})\n\nEach tested effect's mean difference and 95 % CI \
         divided by its threshold δ: inside the band (−1, 1) negligible, beyond it relevant.\n"
    );
    let failed = &report.analysis.failed_runs;
    out.push_str("## Runs that did not complete\n\n");
    if failed.is_empty() {
        out.push_str("None.\n\n");
    } else {
        for r in failed {
            let _ = writeln!(
                out,
                "- cell {} instance {} ({}, seed {}): {:?}: {}",
                r.cell,
                r.instance,
                r.planner,
                r.seed,
                r.status,
                r.error.as_deref().unwrap_or_default()
            );
        }
        out.push('\n');
    }
    let _ = writeln!(
        out,
        "## Files\n\n- `{ENDPOINTS_CSV}`, `{COLLISIONS_CSV}`: the tables (full precision)\n\
         - `{REPORT_JSON}`: everything above\n- `{EFFECTS_PNG}`: the figure\n\
         - `{ROWS_JSONL}`: one row per run (replay one with `merge_sim run --seed <seed>` on \
         the cell's scenario)"
    );
    out
}
