//! `sweep` and `merge-results`: seeded Monte-Carlo sweeps (one planner or several, paired),
//! their JSONL rows, resumption, Parquet, and merging the shards of a sweep.

use std::io::{Seek, Write};
use std::path::{Path, PathBuf};

use crate::output::check_output_path;
use anyhow::{Context, anyhow};
use mergesim_types::files::read_regular_text;

use crate::cli::args::{MergeResultsArgs, SweepArgs};
use crate::cli::commands::{check_outputs, progress_bar, scenario_file};
use crate::cli::simulation::load_source;
use crate::cli::{
    Failure, Session, input, interrupted, out, outln, run_failure, sweep_failure, write_output,
};

/// Longest sweep result file read back (`--resume`, `merge-results`): 4 GiB, beyond the rows
/// of `sweep::MAX_RUNS` runs.
const MAX_RESULT_FILE_BYTES: u64 = 4 << 30;

/// `merge_sim sweep`: checks every input and output, then runs (or resumes) the sweep.
pub(crate) fn cmd_sweep(args: &SweepArgs, session: &Session) -> Result<(), Failure> {
    let interrupt = &session.interrupt;
    use crate::sweep::{
        PairedSweepPlan, Shard, SweepIdentity, SweepOptions, resume::read_jsonl, run_paired_sweep,
        validate_paired,
    };
    let scenario = load_source(&args.source, &session.registry)?;
    // An existing JSONL passes (a regular file): --resume reads it back, else it is refused
    // below.
    check_outputs(
        &[
            (args.json.as_deref(), "--json"),
            (args.jsonl.as_deref(), "--jsonl"),
            (args.parquet.as_deref(), "--parquet"),
        ],
        &scenario_file(&args.source.scenario),
    )?;
    let shard = match args.shard {
        Some(shard) => shard,
        None => {
            let shard = Shard::from_environment(|name| std::env::var(name).ok()).map_err(input)?;
            if let (Some(shard), Ok(count)) = (shard, std::env::var("SLURM_ARRAY_TASK_COUNT"))
                && shard.count == 1
            {
                // Printed even with --quiet: it explains a shard file of the wrong count.
                eprintln!(
                    "warning: SLURM_ARRAY_TASK_COUNT = {count}: an array of one task runs the \
                     whole sweep (shard 0/1); to run one shard of a sweep again (e.g. after \
                     `sbatch --array=2`) pass --shard i/n, or requeue the task instead"
                );
            }
            shard.unwrap_or(Shard::WHOLE)
        }
    };
    // `--planner P` and `--planners P` are the same sweep.
    let planners = match &args.planner {
        Some(name) => vec![name.clone()],
        None => args.planners.clone(),
    };
    let plan = PairedSweepPlan {
        scenario,
        planners,
        runs: args.runs,
        seed: args.seed,
        shard,
    };
    let identity = SweepIdentity::of_paired(&plan);
    // The JSONL: a fresh file, or (--resume) the rows of the interrupted attempt.
    let mut resume = Vec::new();
    let jsonl = match &args.jsonl {
        None => None,
        Some(path) => {
            let exists = std::fs::symlink_metadata(path).is_ok();
            if exists && !args.resume {
                return Err(input(anyhow!(
                    "--jsonl {}: exists; pass --resume to complete the sweep it holds, or \
                     remove it or choose another path",
                    path.display()
                )));
            }
            if exists {
                check_output_path(path, "--jsonl").map_err(|e| input(anyhow!(e)))?;
                let text = read_regular_text(path, MAX_RESULT_FILE_BYTES)
                    .with_context(|| format!("cannot read {}", path.display()))
                    .map_err(input)?;
                let read = read_jsonl(
                    &text,
                    &path.display().to_string(),
                    &identity,
                    shard.instances(args.runs),
                )
                .map_err(sweep_failure)?;
                if read.torn_last_line && !args.quiet {
                    eprintln!(
                        "warning: {}: the last line was cut short (the process was killed while \
                         writing it); it is dropped and its run runs again",
                        path.display()
                    );
                }
                resume = read.runs;
                Some((path.clone(), Some(read.complete_len)))
            } else {
                check_output_path(path, "--jsonl").map_err(|e| input(anyhow!(e)))?;
                Some((path.clone(), None))
            }
        }
    };
    let options = SweepOptions {
        threads: args.threads,
        interrupt: Some(interrupt.flag.clone()),
        resume,
        registry: std::sync::Arc::clone(&session.registry),
    };
    // Every check before any work or any write.
    validate_paired(&plan, &options).map_err(sweep_failure)?;
    let writer = match &jsonl {
        None => None,
        Some((path, complete_len)) => Some(std::sync::Mutex::new(open_jsonl(path, *complete_len)?)),
    };
    let instances = shard.instances(args.runs);
    let planner_count = identity.planners.len() as u64;
    let expected_runs = (instances.end - instances.start) * planner_count;
    let to_run = expected_runs - options.resume.len() as u64;
    // The shard banner goes to stderr even with --quiet: a job log then says what ran.
    eprintln!(
        "sweep {} {}: seed {}, shard {shard} = instances {}..{} of {}{}",
        plan.scenario.name,
        identity.planner,
        args.seed,
        instances.start,
        instances.end,
        args.runs,
        if options.resume.is_empty() {
            String::new()
        } else {
            format!(
                ", resuming: {} finished, {to_run} to run",
                options.resume.len()
            )
        }
    );
    if let Some(warning) = crate::sweep::unrandomised_warning(&plan.scenario)
        && !args.quiet
    {
        eprintln!("warning: {warning}");
    }
    let bar = progress_bar(
        args.quiet,
        to_run,
        format!("sweep {} shard {shard}", plan.scenario.name),
    );
    let write_error: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);
    let on_run = |run: &crate::sweep::FinishedRun| {
        bar.inc(1);
        let Some(writer) = &writer else { return };
        let line = match crate::sweep::jsonl_line(&identity, &run.row, run.wall_time_s) {
            Ok(line) => line,
            Err(e) => {
                record_first(&write_error, e.to_string());
                return;
            }
        };
        let mut file = match writer.lock() {
            Ok(file) => file,
            Err(poisoned) => poisoned.into_inner(),
        };
        if let Err(e) = writeln!(file, "{line}").and_then(|()| file.flush()) {
            record_first(&write_error, e.to_string());
            // Stop the sweep: rows that cannot be kept must not be computed.
            interrupt
                .flag
                .store(true, std::sync::atomic::Ordering::Relaxed);
        }
    };
    let outcome = run_paired_sweep(&plan, &options, &on_run).map_err(sweep_failure)?;
    bar.finish_and_clear();
    if let Some(writer) = writer {
        let file = match writer.into_inner() {
            Ok(file) => file,
            Err(poisoned) => poisoned.into_inner(),
        };
        file.sync_all().ok();
    }
    let write_error = match write_error.into_inner() {
        Ok(e) => e,
        Err(poisoned) => poisoned.into_inner(),
    };
    if let Some(e) = write_error {
        return Err(run_failure(anyhow!(
            "cannot append to --jsonl {}: {e}; the sweep stopped (rows written so far are kept)",
            jsonl
                .map(|(p, _)| p.display().to_string())
                .unwrap_or_default()
        )));
    }
    let report = outcome.report();
    write_report(&report, args.json.as_deref(), args.parquet.as_deref())?;
    if !args.quiet {
        out!("{}", report.table_resumed(options.resume.len() as u64));
        let several = planner_count > 1;
        for row in report.rows().into_iter().filter(|r| r.error.is_some()) {
            outln!(
                "run {}{} (seed {}) {:?}: {}",
                row.instance,
                if several {
                    format!(" {}", row.planner)
                } else {
                    String::new()
                },
                crate::exact_seed::format_seed(row.seed),
                row.status,
                row.error.as_deref().unwrap_or_default()
            );
        }
    }
    let finished: u64 = outcome.summaries.iter().map(|s| s.runs).sum();
    use crate::sweep::SweepVerdict;
    match outcome.verdict() {
        SweepVerdict::Complete => Ok(()),
        SweepVerdict::Interrupted { missing } => Err(interrupted(
            interrupt,
            &format!(
                "{} of {} runs finished ({} in this attempt), {missing} missing; {}resume with \
                 the same command plus --resume{}",
                finished,
                expected_runs,
                outcome.new_runs,
                if args.json.is_some() {
                    "the --json aggregate covers the finished runs (missing_runs > 0); "
                } else {
                    ""
                },
                if args.jsonl.is_some() {
                    ""
                } else {
                    " (needs --jsonl: without it the finished rows are only in the --json file)"
                }
            ),
        )),
        SweepVerdict::RunsFailed { failed, of } => Err(run_failure(anyhow!(
            "{failed} of {of} runs failed (panicked {}); their errors are listed above and in \
             the rows",
            outcome.summaries.iter().map(|s| s.panicked).sum::<u64>()
        ))),
    }
}

/// Keeps the first error of the JSONL writer.
fn record_first(slot: &std::sync::Mutex<Option<String>>, error: String) {
    let mut slot = match slot.lock() {
        Ok(slot) => slot,
        Err(poisoned) => poisoned.into_inner(),
    };
    slot.get_or_insert(error);
}

/// Opens the JSONL for appending: created afresh (`complete_len` None), or an existing one
/// cut to its complete lines (`Some(len)`, a torn last line dropped).
fn open_jsonl(
    path: &std::path::Path,
    complete_len: Option<usize>,
) -> Result<std::fs::File, Failure> {
    let context = || format!("cannot open --jsonl {}", path.display());
    let file = match complete_len {
        None => std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(path)
            .with_context(context)
            .map_err(input)?,
        Some(len) => {
            let file = std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .with_context(context)
                .map_err(input)?;
            file.set_len(len as u64)
                .with_context(context)
                .map_err(input)?;
            file
        }
    };
    let mut file = file;
    file.seek(std::io::SeekFrom::End(0))
        .with_context(context)
        .map_err(input)?;
    Ok(file)
}

/// Writes a sweep's report: the aggregate as JSON, the rows as Parquet.
fn write_report(
    report: &crate::sweep::SweepReport,
    json: Option<&Path>,
    parquet: Option<&Path>,
) -> Result<(), Failure> {
    if let Some(path) = json {
        let text = report.to_json_pretty().map_err(run_failure)?;
        write_output(path, &text)?;
    }
    if let Some(path) = parquet {
        crate::sweep::parquet::write_parquet(path, report).map_err(run_failure)?;
    }
    Ok(())
}

/// `merge_sim merge-results`: validates the shards of one sweep and writes their aggregate.
pub(crate) fn cmd_merge_results(args: &MergeResultsArgs) -> Result<(), Failure> {
    use crate::sweep::{SweepReport, merge_reports};
    let inputs: Vec<&Path> = args.inputs.iter().map(PathBuf::as_path).collect();
    check_outputs(
        &[
            (args.json.as_deref(), "--json"),
            (args.jsonl.as_deref(), "--jsonl"),
            (args.parquet.as_deref(), "--parquet"),
        ],
        &inputs,
    )?;
    let mut parts = Vec::with_capacity(args.inputs.len());
    for path in &args.inputs {
        let origin = path.display().to_string();
        let text = read_regular_text(path, MAX_RESULT_FILE_BYTES)
            .with_context(|| format!("cannot read {origin}"))
            .map_err(input)?;
        let part = SweepReport::from_json(&text)
            .with_context(|| format!("{origin}: not a `merge_sim sweep --json` file"))
            .map_err(input)?;
        parts.push((origin, part));
    }
    let merged = merge_reports(parts).map_err(sweep_failure)?;
    // Every output is made before any is written: a bad row writes none of them.
    let rows = match &args.jsonl {
        Some(path) => Some((
            path,
            crate::sweep::merged_jsonl(&merged).map_err(run_failure)?,
        )),
        None => None,
    };
    write_report(&merged, args.json.as_deref(), args.parquet.as_deref())?;
    if let Some((path, text)) = rows {
        write_output(path, &text)?;
    }
    if !args.quiet {
        out!("{}", merged.table());
        outln!(
            "(wall time: the sum of the {} shards' wall times, not the elapsed time)",
            args.inputs.len()
        );
    }
    Ok(())
}
