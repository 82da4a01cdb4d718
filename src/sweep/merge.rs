//! Merging the shards of one sweep into the aggregate of the whole (`merge_sim merge-results`).

use super::paired::check_paired;
use super::summary::jsonl_line_with;
use super::{
    PairedSweepSummary, Shard, SweepError, SweepIdentity, SweepReport, SweepSummary, instance_seed,
};

/// The JSONL text (one line per run, each ending in a newline) of a whole sweep's rows as
/// `merge_sim merge-results --jsonl` writes them: in instance order, then in the sweep's planner
/// order (the baseline first) — the rows of the unsharded sweep's `--jsonl`, sorted — each with
/// the whole sweep's identity. `wall_time_s` is null: a shard's `--json` keeps no per-run wall
/// times.
pub fn merged_jsonl(report: &SweepReport) -> Result<String, SweepError> {
    let summaries = report.summaries();
    let Some(first) = summaries.first() else {
        return Err(SweepError::Invalid("no planner in the merged sweep".into()));
    };
    let planners = report.planners();
    let identity = SweepIdentity {
        planner: planners.join(","),
        planners,
        ..first.identity()
    };
    let mut text = String::new();
    for row in report.rows() {
        let line = jsonl_line_with(&identity, row, None).map_err(|e| {
            SweepError::Invalid(format!(
                "instance {} ({}): cannot write its row: {e}",
                row.instance, row.planner
            ))
        })?;
        text.push_str(&line);
        text.push('\n');
    }
    Ok(text)
}

/// Why a shard file may carry the wrong shard count: a Slurm array task resubmitted on its own
/// (`sbatch --array=2 script`) is an array of one task, so without `--shard` it ran the whole
/// sweep as shard 0/1. `origin` is the odd file, `count` its shard count, `expected` the others'.
fn shard_count_hint(origin: &str, count: u64, expected: u64) -> String {
    if count == 1 && expected > 1 {
        format!(
            " ({origin} says it is shard 0/1, the whole sweep: was this task run without the \
             shard count, e.g. resubmitted with `sbatch --array=N` (an array of one task)? run \
             that shard again with --shard i/{expected} explicitly, or requeue the original \
             array task: `scontrol requeue JOBID_N`)"
        )
    } else {
        String::new()
    }
}

/// Combines the `--json` reports of the shards of one sweep (`(origin, report)`), single- or
/// multi-planner: a multi-planner sweep is merged planner by planner ([`merge_shards`]) and its
/// paired differences computed again from the merged rows, so they equal the unsharded sweep's.
pub fn merge_reports(parts: Vec<(String, SweepReport)>) -> Result<SweepReport, SweepError> {
    let Some((first_origin, first)) = parts.first() else {
        return Err(SweepError::Invalid("no shard files given".into()));
    };
    let planners = first.planners();
    let paired = matches!(first, SweepReport::Paired(_));
    for (origin, part) in &parts {
        if let SweepReport::Paired(p) = part {
            check_paired(origin, p)?;
        }
        if matches!(part, SweepReport::Paired(_)) != paired || part.planners() != planners {
            return Err(SweepError::Invalid(format!(
                "{origin}: planners = {} differ from {first_origin} ({}): not a shard of the \
                 same sweep",
                part.planners().join(","),
                planners.join(",")
            )));
        }
    }
    if !paired {
        let singles = parts
            .into_iter()
            .filter_map(|(origin, part)| match part {
                SweepReport::Single(s) => Some((origin, *s)),
                SweepReport::Paired(_) => None,
            })
            .collect();
        return merge_shards(singles).map(|s| SweepReport::Single(Box::new(s)));
    }
    let mut wall_time_s = 0.0;
    let mut by_planner: Vec<Vec<(String, SweepSummary)>> = vec![Vec::new(); planners.len()];
    for (origin, part) in parts {
        if let SweepReport::Paired(p) = part {
            wall_time_s += p.wall_time_s;
            for (slot, summary) in by_planner.iter_mut().zip(p.per_planner) {
                slot.push((origin.clone(), summary));
            }
        }
    }
    let summaries = by_planner
        .into_iter()
        .map(merge_shards)
        .collect::<Result<Vec<_>, _>>()?;
    Ok(SweepReport::Paired(PairedSweepSummary::from_summaries(
        summaries,
        wall_time_s,
    )))
}

/// Combines the summaries of shards (`(origin, summary)`, origin naming the file in errors) into
/// the summary of the whole sweep: same identity, every shard `i/n` present exactly once.
pub fn merge_shards(parts: Vec<(String, SweepSummary)>) -> Result<SweepSummary, SweepError> {
    let Some((first_origin, first)) = parts.first() else {
        return Err(SweepError::Invalid("no shard files given".into()));
    };
    let identity = first.identity();
    let count = first.shard.count;
    let mut seen: Vec<Option<&str>> =
        vec![None; usize::try_from(count).unwrap_or(usize::MAX).min(1 << 20)];
    if seen.len() as u64 != count {
        return Err(SweepError::Invalid(format!(
            "{first_origin}: shard count {count} is too large"
        )));
    }
    for (origin, part) in &parts {
        let other = part.identity();
        let fields = [
            (
                "scenario",
                identity.scenario.clone(),
                other.scenario.clone(),
            ),
            (
                "scenario_fingerprint",
                identity.scenario_fingerprint.clone(),
                other.scenario_fingerprint.clone(),
            ),
            ("planner", identity.planner.clone(), other.planner.clone()),
            ("params", identity.params.clone(), other.params.clone()),
            ("seed", identity.seed.to_string(), other.seed.to_string()),
            (
                "total_runs",
                identity.total_runs.to_string(),
                other.total_runs.to_string(),
            ),
            (
                "shard count",
                count.to_string(),
                part.shard.count.to_string(),
            ),
        ];
        for (name, expected, found) in fields {
            if expected != found {
                // Name the file that holds the odd count 1 (a whole sweep), whichever came first.
                let (odd, odd_count, other_count) = if count == 1 {
                    (first_origin.as_str(), count, part.shard.count)
                } else {
                    (origin.as_str(), part.shard.count, count)
                };
                let hint = if name == "shard count" {
                    shard_count_hint(odd, odd_count, other_count)
                } else {
                    String::new()
                };
                return Err(SweepError::Invalid(format!(
                    "{origin}: {name} = {found} differs from {first_origin} ({expected}): not a \
                     shard of the same sweep{hint}"
                )));
            }
        }
        let slot = &mut seen[part.shard.index as usize];
        if let Some(previous) = slot {
            return Err(SweepError::Invalid(format!(
                "{origin}: shard {} given twice (also {previous})",
                part.shard
            )));
        }
        *slot = Some(origin.as_str());
        if part.missing_runs > 0 {
            return Err(SweepError::Invalid(format!(
                "{origin}: shard {} is incomplete ({} of its runs missing: it was interrupted); \
                 finish it with the same `merge_sim sweep` command plus --resume (and its \
                 --jsonl file), then merge",
                part.shard, part.missing_runs
            )));
        }
        let range = part.shard.instances(part.total_runs);
        let instances: Vec<u64> = part.samples.iter().map(|r| r.instance).collect();
        if instances != range.clone().collect::<Vec<_>>()
            || part.instances != [range.start, range.end]
        {
            return Err(SweepError::Invalid(format!(
                "{origin}: shard {} must hold instances {}..{} in order",
                part.shard, range.start, range.end
            )));
        }
        if let Some(bad) = part
            .samples
            .iter()
            .find(|r| r.seed != instance_seed(part.seed, r.instance))
        {
            return Err(SweepError::Invalid(format!(
                "{origin}: instance {} has seed {}, not the derived {}",
                bad.instance,
                bad.seed,
                instance_seed(part.seed, bad.instance)
            )));
        }
    }
    let missing: Vec<String> = seen
        .iter()
        .enumerate()
        .filter(|(_, s)| s.is_none())
        .map(|(i, _)| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(SweepError::Invalid(format!(
            "missing shards: {} (run each again with `merge_sim sweep ... --shard i/{count}`, or \
             requeue its array task: `scontrol requeue JOBID_i`)",
            missing.join(", ")
        )));
    }
    let mut ordered: Vec<&SweepSummary> = parts.iter().map(|(_, p)| p).collect();
    ordered.sort_by_key(|p| p.shard.index);
    let wall_time_s = ordered.iter().map(|p| p.wall_time_s).sum();
    let rows = ordered
        .into_iter()
        .flat_map(|p| p.samples.iter().cloned())
        .collect();
    Ok(SweepSummary::from_rows(
        &identity,
        Shard::WHOLE,
        rows,
        wall_time_s,
    ))
}
