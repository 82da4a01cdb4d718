//! `merge_sim study PLAN.toml`: checks the plan and the output folder, runs the study (or a
//! shard of it, or resumes it), appending each run's row to the rows file as it finishes, then
//! writes the report; `--merge` makes the report from the rows of every shard.

use std::io::{IsTerminal, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::study::plan::StudyPlan;
use crate::study::report::{
    self, REPORT_MD, ROWS_JSONL, StudyReport, check_out, create_out, default_out, shard_rows_file,
};
use crate::study::runner::{self, StudyRow, jsonl_line, read_rows};
use crate::study::runner::{RunOptions, StudyError, run_study};
use crate::study::{analyse, provenance};
use crate::sweep::Shard;
use anyhow::{Context, anyhow};
use clap::Args;
use mergesim_types::files::read_regular_text;

use crate::cli::args::{parse_shard, parse_threads};
use crate::cli::commands::progress_bar;
use crate::cli::{Failure, Session, input, interrupted, out, outln, run_failure};

/// Longest rows file read back (`--resume`, `--merge`).
const MAX_ROWS_BYTES: u64 = 1 << 30;

#[derive(Args, Debug)]
#[command(after_long_help = crate::study::PLAN_FORMAT)]
pub(crate) struct StudyArgs {
    /// The study plan (TOML; its format is below).
    #[arg(value_name = "PLAN.toml")]
    pub(crate) plan: PathBuf,
    /// The report folder [default: <plan stem>.report beside the plan]. An existing folder is
    /// used only if it is empty or an earlier report (it holds a .mergesim-study file).
    #[arg(long, value_name = "DIR")]
    pub(crate) out: Option<PathBuf>,
    /// Worker threads [default: one per core]; the report does not depend on it.
    #[arg(long, value_name = "N", value_parser = parse_threads)]
    pub(crate) threads: Option<usize>,
    /// Run only shard i of n (0-based): instances [⌊i·N/n⌋, ⌊(i+1)·N/n⌋) of every cell and
    /// planner, rows to DIR/rows.shard-i-of-n.jsonl, no report (then --merge). Default: from a
    /// Slurm job array or a Kubernetes Indexed Job (as `sweep`), else the whole study.
    #[arg(long, value_name = "i/n", value_parser = parse_shard, conflicts_with = "merge")]
    pub(crate) shard: Option<Shard>,
    /// Keep the rows of an interrupted attempt (the rows file of the same plan text and shard)
    /// and run only the missing runs; without an earlier rows file it starts afresh.
    #[arg(long, conflicts_with = "merge")]
    pub(crate) resume: bool,
    /// Make the report from the rows of every shard (DIR/rows.shard-*-of-n.jsonl): each run
    /// must be there exactly once.
    #[arg(long)]
    pub(crate) merge: bool,
    /// Print nothing but errors (the shard banner still goes to stderr).
    #[arg(long, short)]
    pub(crate) quiet: bool,
}

fn study_failure(e: StudyError) -> Failure {
    match e {
        StudyError::Invalid(_) => input(e),
        StudyError::Run(_) => run_failure(e),
    }
}

/// `merge_sim study`.
pub(crate) fn cmd_study(args: &StudyArgs, session: &Session) -> Result<(), Failure> {
    let interrupt = &session.interrupt;
    let plan = StudyPlan::load_with(&args.plan, &session.registry).map_err(input)?;
    let out = args.out.clone().unwrap_or_else(|| default_out(&args.plan));
    check_out(&out).map_err(input)?;
    if args.merge {
        return merge(args, &plan, &out);
    }
    let shard = match args.shard {
        Some(shard) => shard,
        None => Shard::from_environment(|name| std::env::var(name).ok())
            .map_err(input)?
            .unwrap_or(Shard::WHOLE),
    };
    let rows_path = out.join(if shard == Shard::WHOLE {
        ROWS_JSONL.to_string()
    } else {
        shard_rows_file(shard)
    });
    // Rows of an earlier attempt (--resume), checked before any run.
    let mut resume = Vec::new();
    let mut keep_len = None;
    if args.resume && rows_path.is_file() {
        let text = read_regular_text(&rows_path, MAX_ROWS_BYTES)
            .with_context(|| format!("cannot read {}", rows_path.display()))
            .map_err(input)?;
        let (rows, complete_len, torn) =
            read_rows(&plan, &text, &rows_path.display().to_string()).map_err(study_failure)?;
        if torn && !args.quiet {
            eprintln!(
                "warning: {}: the last line was cut short; it is dropped and its run runs again",
                rows_path.display()
            );
        }
        resume = rows;
        keep_len = Some(complete_len);
    }
    let keys = runner::run_keys(&plan, shard);
    let to_run = keys.len() as u64 - resume.len() as u64;
    let resumed = resume.len();
    let options = RunOptions {
        threads: args.threads,
        shard: Some(shard),
        interrupt: Some(interrupt.flag.clone()),
        resume,
        registry: std::sync::Arc::clone(&session.registry),
    };
    // Every check done: the folder and the rows file.
    create_out(&out).map_err(input)?;
    if shard == Shard::WHOLE {
        report::remove_stale(&out).map_err(run_failure)?;
    }
    let file = open_rows(&rows_path, keep_len)?;
    let range = shard.instances(plan.instances);
    eprintln!(
        "study {}: {} cells × {} planners × instances {}..{} of {} (shard {shard}) = {} runs{}",
        plan.name,
        plan.cells.len(),
        plan.planners.len(),
        range.start,
        range.end,
        plan.instances,
        keys.len(),
        if resumed > 0 {
            format!(", resuming: {resumed} finished, {to_run} to run")
        } else {
            String::new()
        }
    );
    let bar = progress_bar(args.quiet, to_run, format!("study {}", plan.name));
    let lines = !args.quiet && !std::io::stderr().is_terminal();
    let finished = AtomicU64::new(0);
    let writer = Mutex::new(file);
    let write_error: Mutex<Option<String>> = Mutex::new(None);
    let on_run = |row: &StudyRow, wall_time_s: f64| {
        bar.inc(1);
        let done = finished.fetch_add(1, Ordering::Relaxed) + 1;
        // Progress lines for logs (a cluster job's stderr): every tenth of the runs.
        if lines && (done * 10 / to_run.max(1) != (done - 1) * 10 / to_run.max(1)) {
            eprintln!("study {}: {done}/{to_run} runs", plan.name);
        }
        let line = jsonl_line(&plan, row, Some(wall_time_s));
        let mut file = writer.lock().unwrap_or_else(|p| p.into_inner());
        if let Err(e) = writeln!(file, "{line}").and_then(|()| file.flush()) {
            let mut slot = write_error.lock().unwrap_or_else(|p| p.into_inner());
            slot.get_or_insert(e.to_string());
            interrupt.flag.store(true, Ordering::Relaxed);
        }
    };
    let rows = run_study(&plan, &options, &on_run).map_err(study_failure)?;
    bar.finish_and_clear();
    let file = writer.into_inner().unwrap_or_else(|p| p.into_inner());
    file.sync_all().ok();
    if let Some(e) = write_error.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(run_failure(anyhow!(
            "cannot append to {}: {e}; the study stopped (rows written so far are kept)",
            rows_path.display()
        )));
    }
    if rows.len() < keys.len() {
        return Err(interrupted(
            interrupt,
            &format!(
                "{} of {} runs finished; their rows are in {}: resume with the same command \
                 plus --resume",
                rows.len(),
                keys.len(),
                rows_path.display()
            ),
        ));
    }
    if shard != Shard::WHOLE {
        if !args.quiet {
            outln!(
                "shard {shard}: {} rows in {}; once every shard has finished: merge_sim study {} \
                 --merge --out {}",
                rows.len(),
                rows_path.display(),
                args.plan.display(),
                out.display()
            );
        }
        return Ok(());
    }
    finish(args, &plan, &out, &rows)
}

/// Analyses complete rows, writes the report and prints where it is.
fn finish(
    args: &StudyArgs,
    plan: &StudyPlan,
    out: &Path,
    rows: &[StudyRow],
) -> Result<(), Failure> {
    runner::check_complete(plan, rows).map_err(study_failure)?;
    let report = StudyReport::new(
        plan,
        provenance::of_plan(&plan.path, &plan.text),
        analyse(plan, rows),
    );
    report::write_report(out, &report).map_err(run_failure)?;
    if !args.quiet {
        print_summary(&report, out);
    }
    let failed = report.analysis.failed_runs.len();
    if failed > 0 {
        return Err(run_failure(anyhow!(
            "{failed} of {} runs did not complete (listed in {}); they enter no pair",
            rows.len(),
            out.join(REPORT_MD).display()
        )));
    }
    Ok(())
}

fn print_summary(report: &StudyReport, out: &Path) {
    outln!(
        "study {}: {} runs; report in {}{}",
        report.study,
        report.runs,
        out.join(REPORT_MD).display(),
        if report.provenance.exploratory {
            format!(" (exploratory: {})", report.provenance.reasons.join("; "))
        } else {
            String::new()
        }
    );
    for r in report
        .analysis
        .endpoints
        .iter()
        .filter(|r| r.role == "primary" && r.tested)
    {
        outln!(
            "  {} | {} − {} | {}: mean diff {} {} (95 % CI {}), {}",
            r.cell_label,
            r.planner,
            r.reference,
            r.endpoint,
            r.mean_difference
                .map(|m| format!("{m:.4}"))
                .unwrap_or_else(|| "–".into()),
            r.unit,
            r.ci95
                .map(|[lo, hi]| format!("[{lo:.4}, {hi:.4}]"))
                .unwrap_or_else(|| "–".into()),
            r.verdict.name()
        );
    }
}

/// `--merge`: the rows of every shard of one count, each run once, then the report.
fn merge(args: &StudyArgs, plan: &StudyPlan, out: &Path) -> Result<(), Failure> {
    let entries = std::fs::read_dir(out)
        .with_context(|| format!("--merge: cannot read {}", out.display()))
        .map_err(input)?;
    let mut files: Vec<(Shard, PathBuf)> = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(rest) = name
            .strip_prefix("rows.shard-")
            .and_then(|r| r.strip_suffix(".jsonl"))
        else {
            continue;
        };
        let shard = rest
            .split_once("-of-")
            .and_then(|(i, n)| Shard::new(i.parse().ok()?, n.parse().ok()?, &name).ok())
            .ok_or_else(|| input(anyhow!("--merge: {name}: not a shard rows file name")))?;
        files.push((shard, entry.path()));
    }
    files.sort_by_key(|(s, _)| (s.count, s.index));
    let Some(count) = files.first().map(|(s, _)| s.count) else {
        return Err(input(anyhow!(
            "--merge: no rows.shard-i-of-n.jsonl in {}: run the shards first (--shard i/n)",
            out.display()
        )));
    };
    if let Some((other, path)) = files.iter().find(|(s, _)| s.count != count) {
        return Err(input(anyhow!(
            "--merge: {} is shard {other} but {} holds shards of {count}: remove the rows of the \
             other split",
            path.display(),
            out.display()
        )));
    }
    let missing: Vec<String> = (0..count)
        .filter(|i| !files.iter().any(|(s, _)| s.index == *i))
        .map(|i| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(input(anyhow!(
            "--merge: shard(s) {} missing in {}",
            missing.join(", "),
            out.display()
        )));
    }
    let mut rows = Vec::new();
    for (shard, path) in &files {
        let text = read_regular_text(path, MAX_ROWS_BYTES)
            .with_context(|| format!("cannot read {}", path.display()))
            .map_err(input)?;
        let (part, _, torn) =
            read_rows(plan, &text, &path.display().to_string()).map_err(study_failure)?;
        if torn {
            return Err(input(anyhow!(
                "--merge: {}: the last line is cut short: resume shard {shard} first",
                path.display()
            )));
        }
        rows.extend(part);
    }
    runner::check_complete(plan, &rows).map_err(study_failure)?;
    runner::sort_rows(plan, &mut rows);
    let mut text = String::new();
    for row in &rows {
        text.push_str(&jsonl_line(plan, row, None));
        text.push('\n');
    }
    crate::output::write_atomically(&out.join(ROWS_JSONL), text.as_bytes())
        .with_context(|| format!("cannot write {}", out.join(ROWS_JSONL).display()))
        .map_err(run_failure)?;
    finish(args, plan, out, &rows)
}

/// Opens the rows file: created afresh, or (resuming) cut to its complete lines and appended.
fn open_rows(path: &Path, keep_len: Option<usize>) -> Result<std::fs::File, Failure> {
    let context = || format!("cannot open {}", path.display());
    let mut file = match keep_len {
        None => std::fs::File::create(path)
            .with_context(context)
            .map_err(run_failure)?,
        Some(len) => {
            let file = std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .with_context(context)
                .map_err(run_failure)?;
            file.set_len(len as u64)
                .with_context(context)
                .map_err(run_failure)?;
            file
        }
    };
    file.seek(std::io::SeekFrom::End(0))
        .with_context(context)
        .map_err(run_failure)?;
    Ok(file)
}
