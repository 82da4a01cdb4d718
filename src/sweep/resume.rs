//! Reading the JSONL of an interrupted sweep back (`merge_sim sweep … --resume`).

use super::rows::JsonlRecord;
use super::{FinishedRun, SweepError, SweepIdentity};

/// The finished runs of a JSONL file and what was wrong with its end.
#[derive(Clone, Debug, Default)]
pub struct ResumedRows {
    /// The runs, in file order.
    pub runs: Vec<FinishedRun>,
    /// Bytes of complete lines: a last line without its newline (a write cut short by a hard
    /// kill) lies beyond this and is dropped, its run run again.
    pub complete_len: usize,
    /// Whether such a torn last line was found.
    pub torn_last_line: bool,
}

/// Reads the runs of the JSONL `text` (from `origin`, named in errors) written by a sweep
/// with identity `identity`. Every complete line must be a row of that sweep: a line of another
/// sweep (scenario, fingerprint, parameter set, planner list, seed or run count differ), of
/// an older mergesim, or one that does not parse is an error naming its line and field.
pub fn read_jsonl(
    text: &str,
    origin: &str,
    identity: &SweepIdentity,
    instances: std::ops::Range<u64>,
) -> Result<ResumedRows, SweepError> {
    let complete_len = text.rfind('\n').map_or(0, |i| i + 1);
    let mut runs = Vec::new();
    let mut seen = std::collections::BTreeMap::new();
    for (index, line) in text[..complete_len].lines().enumerate() {
        let number = index + 1;
        if line.trim().is_empty() {
            continue;
        }
        let record: JsonlRecord = serde_json::from_str(line).map_err(|e| {
            SweepError::Invalid(format!(
                "{origin}, line {number}: not a row of `merge_sim sweep --jsonl`: {e}"
            ))
        })?;
        let Some(planners) = &record.planners else {
            return Err(SweepError::Invalid(format!(
                "{origin}, line {number}: no `planners`: a row written by an older mergesim \
                 (rows now carry `planner`, `drawn` and `vehicles`); start a new sweep (a new \
                 --jsonl file)"
            )));
        };
        let fields = [
            ("scenario", &identity.scenario, &record.scenario),
            ("params", &identity.params, &record.params),
            (
                "scenario_fingerprint",
                &identity.scenario_fingerprint,
                &record.scenario_fingerprint,
            ),
            (
                "planners",
                &identity.planners.join(","),
                &planners.join(","),
            ),
            (
                "sweep_seed",
                &identity.seed.to_string(),
                &record.sweep_seed.to_string(),
            ),
            (
                "total_runs",
                &identity.total_runs.to_string(),
                &record.total_runs.to_string(),
            ),
        ];
        for (field, expected, found) in fields {
            if expected != found {
                return Err(SweepError::Invalid(format!(
                    "{origin}, line {number}: {field} = {found}, but this sweep has {field} = \
                     {expected}: the file holds rows of another sweep (resume with the same \
                     scenario, parameters, planner, --runs and --seed)"
                )));
            }
        }
        let instance = record.row.instance;
        if !instances.contains(&instance) {
            return Err(SweepError::Invalid(format!(
                "{origin}, line {number}: instance {instance} lies outside this shard's \
                 instances {}..{} (resume with the same --shard)",
                instances.start, instances.end
            )));
        }
        let expected = super::instance_seed(identity.seed, instance);
        if record.row.seed != expected {
            return Err(SweepError::Invalid(format!(
                "{origin}, line {number}: instance {instance} has seed {}, not {expected}: not \
                 a row of this sweep",
                record.row.seed
            )));
        }
        let planner = &record.row.planner;
        if !identity.planners.contains(planner) {
            return Err(SweepError::Invalid(format!(
                "{origin}, line {number}: planner = {planner}, not one of this sweep's planners \
                 ({}): the file holds rows of another sweep",
                identity.planners.join(",")
            )));
        }
        if let Some(first) = seen.insert((instance, planner.clone()), number) {
            return Err(SweepError::Invalid(format!(
                "{origin}, line {number}: instance {instance} ({planner}) appears twice (also \
                 line {first})"
            )));
        }
        runs.push(FinishedRun {
            row: record.row,
            wall_time_s: record.wall_time_s.unwrap_or(0.0),
        });
    }
    Ok(ResumedRows {
        runs,
        complete_len,
        torn_last_line: complete_len < text.len(),
    })
}
