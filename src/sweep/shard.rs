//! Splitting a sweep into disjoint shards, for job arrays on a cluster.
//!
//! Shard `i/n` (0-based, `0 ≤ i < n`) runs the contiguous block of instances
//! `[⌊i·N/n⌋, ⌊(i+1)·N/n⌋)` of a sweep of N runs: the blocks partition `0..N` and differ in size
//! by at most one. `merge_sim merge-results --jsonl` writes the shards' rows in instance order
//! (each shard's JSONL is in completion order).
//!
//! Where a shard comes from, first match wins:
//! 1. `--shard i/n` (what cluster scripts should pass: a Slurm task resubmitted alone is an
//!    array of one task, which 2. reads as the whole sweep);
//! 2. a Slurm job array: `SLURM_ARRAY_TASK_ID`, `SLURM_ARRAY_TASK_COUNT`, and if set
//!    `SLURM_ARRAY_TASK_MIN` / `SLURM_ARRAY_TASK_STEP` (so `--array=1-8` and `--array=0-14:2`
//!    work: i = (ID − MIN) / STEP);
//! 3. a Kubernetes Indexed Job: `JOB_COMPLETION_INDEX` with the shard count in
//!    `MERGESIM_SHARD_COUNT` (Kubernetes does not export `completions`; set it to the same
//!    number in the Job's `env`);
//! 4. otherwise the whole sweep, `0/1`.

use std::fmt;
use std::ops::Range;
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// One of `count` disjoint parts of a sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct Shard {
    /// 0-based index.
    pub index: u64,
    /// Number of shards (≥ 1).
    pub count: u64,
}

/// A shard that cannot be.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
pub enum ShardError {
    /// Not of the form `i/n` with `0 ≤ i < n`.
    #[error("{source_name} = {value}: {reason}")]
    Invalid {
        /// Where the value came from (`--shard`, an environment variable).
        source_name: String,
        /// The value.
        value: String,
        /// What is wrong.
        reason: String,
    },
}

impl Shard {
    /// The whole sweep.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// Shard `index` of `count`; `source_name` names the origin in errors.
    pub(crate) fn new(index: u64, count: u64, source_name: &str) -> Result<Self, ShardError> {
        if count == 0 || index >= count {
            return Err(ShardError::Invalid {
                source_name: source_name.to_string(),
                value: format!("{index}/{count}"),
                reason: "need 0 <= index < count (0-based index, count >= 1)".into(),
            });
        }
        Ok(Shard { index, count })
    }

    /// The instances of this shard in a sweep of `runs` runs.
    pub fn instances(&self, runs: u64) -> Range<u64> {
        let bound = |k: u64| (u128::from(k) * u128::from(runs) / u128::from(self.count)) as u64;
        bound(self.index)..bound(self.index + 1)
    }

    /// The shard a cluster scheduler assigned through the environment (see the module doc), or
    /// `None` when no scheduler variable is set. `var` looks a variable up (`std::env::var`).
    pub fn from_environment(
        var: impl Fn(&str) -> Option<String>,
    ) -> Result<Option<Shard>, ShardError> {
        let number = |name: &str| -> Result<Option<u64>, ShardError> {
            match var(name) {
                None => Ok(None),
                Some(text) => {
                    text.trim()
                        .parse::<u64>()
                        .map(Some)
                        .map_err(|_| ShardError::Invalid {
                            source_name: name.to_string(),
                            value: text.clone(),
                            reason: "not a non-negative integer".into(),
                        })
                }
            }
        };
        if let Some(id) = number("SLURM_ARRAY_TASK_ID")? {
            let count = number("SLURM_ARRAY_TASK_COUNT")?.ok_or_else(|| ShardError::Invalid {
                source_name: "SLURM_ARRAY_TASK_COUNT".into(),
                value: "<unset>".into(),
                reason: "unset while SLURM_ARRAY_TASK_ID is set".into(),
            })?;
            let min = number("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            let step = number("SLURM_ARRAY_TASK_STEP")?.unwrap_or(1).max(1);
            if id < min || (id - min) % step != 0 {
                return Err(ShardError::Invalid {
                    source_name: "SLURM_ARRAY_TASK_ID".into(),
                    value: id.to_string(),
                    reason: format!(
                        "not on the array's grid MIN + k·STEP (MIN = {min}, STEP = {step}); use \
                         a contiguous --array=0-{} or pass --shard",
                        count.saturating_sub(1)
                    ),
                });
            }
            return Shard::new(
                (id - min) / step,
                count,
                "SLURM_ARRAY_TASK_ID/SLURM_ARRAY_TASK_COUNT",
            )
            .map(Some);
        }
        if let Some(index) = number("JOB_COMPLETION_INDEX")? {
            let count = number("MERGESIM_SHARD_COUNT")?.ok_or_else(|| ShardError::Invalid {
                source_name: "MERGESIM_SHARD_COUNT".into(),
                value: "<unset>".into(),
                reason: "unset while JOB_COMPLETION_INDEX is set: set it to the Job's completions"
                    .into(),
            })?;
            return Shard::new(index, count, "JOB_COMPLETION_INDEX/MERGESIM_SHARD_COUNT").map(Some);
        }
        Ok(None)
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Shard {
    type Err = ShardError;

    /// Parses `i/n`.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let invalid = |reason: &str| ShardError::Invalid {
            source_name: "--shard".into(),
            value: text.to_string(),
            reason: reason.to_string(),
        };
        let (i, n) = text
            .split_once('/')
            .ok_or_else(|| invalid("expected i/n, e.g. 0/4 (0-based index / count)"))?;
        let parse = |s: &str| {
            s.trim()
                .parse::<u64>()
                .map_err(|_| invalid("expected i/n with non-negative integers"))
        };
        Shard::new(parse(i)?, parse(n)?, "--shard").map_err(|_| invalid("need 0 <= i < n"))
    }
}

impl TryFrom<String> for Shard {
    type Error = ShardError;

    fn try_from(text: String) -> Result<Self, Self::Error> {
        text.parse()
    }
}

impl From<Shard> for String {
    fn from(shard: Shard) -> String {
        shard.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_instances_evenly() {
        for runs in [0u64, 1, 7, 10, 200, 1001] {
            for count in [1u64, 2, 3, 8, 13] {
                let mut next = 0;
                for index in 0..count {
                    let r = Shard::new(index, count, "t").unwrap().instances(runs);
                    assert_eq!(r.start, next, "{runs} runs, shard {index}/{count}");
                    let len = r.end - r.start;
                    assert!(len == runs / count || len == runs / count + 1);
                    next = r.end;
                }
                assert_eq!(next, runs);
            }
        }
        assert_eq!(Shard::WHOLE.instances(5), 0..5);
        // No overflow for huge sweeps.
        let big = Shard::new(2, 3, "t").unwrap().instances(u64::MAX);
        assert_eq!(big.end, u64::MAX);
    }

    #[test]
    fn parses_and_refuses_shard_text() {
        assert_eq!(
            "2/5".parse::<Shard>().unwrap(),
            Shard { index: 2, count: 5 }
        );
        assert_eq!("2/5".parse::<Shard>().unwrap().to_string(), "2/5");
        for bad in ["5/5", "1/0", "x/3", "3", "-1/4", "1/2/3", ""] {
            let err = bad.parse::<Shard>().unwrap_err().to_string();
            assert!(err.contains(&format!("--shard = {bad}:")), "{bad}: {err}");
        }
    }

    #[test]
    fn reads_slurm_and_kubernetes_variables() {
        let env = |pairs: &'static [(&'static str, &'static str)]| {
            move |name: &str| {
                pairs
                    .iter()
                    .find(|(k, _)| *k == name)
                    .map(|(_, v)| v.to_string())
            }
        };
        assert_eq!(Shard::from_environment(env(&[])).unwrap(), None);
        let slurm = env(&[
            ("SLURM_ARRAY_TASK_ID", "3"),
            ("SLURM_ARRAY_TASK_COUNT", "8"),
        ]);
        assert_eq!(
            Shard::from_environment(slurm).unwrap(),
            Some(Shard { index: 3, count: 8 })
        );
        let one_based = env(&[
            ("SLURM_ARRAY_TASK_ID", "8"),
            ("SLURM_ARRAY_TASK_COUNT", "8"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
        ]);
        assert_eq!(
            Shard::from_environment(one_based).unwrap(),
            Some(Shard { index: 7, count: 8 })
        );
        let stepped = env(&[
            ("SLURM_ARRAY_TASK_ID", "6"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
            ("SLURM_ARRAY_TASK_MIN", "0"),
            ("SLURM_ARRAY_TASK_STEP", "2"),
        ]);
        assert_eq!(
            Shard::from_environment(stepped).unwrap(),
            Some(Shard { index: 3, count: 4 })
        );
        let k8s = env(&[
            ("JOB_COMPLETION_INDEX", "0"),
            ("MERGESIM_SHARD_COUNT", "16"),
        ]);
        assert_eq!(
            Shard::from_environment(k8s).unwrap(),
            Some(Shard {
                index: 0,
                count: 16
            })
        );
        let no_count = env(&[("JOB_COMPLETION_INDEX", "2")]);
        assert!(
            Shard::from_environment(no_count)
                .unwrap_err()
                .to_string()
                .contains("MERGESIM_SHARD_COUNT")
        );
        let garbage = env(&[
            ("SLURM_ARRAY_TASK_ID", "abc"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ]);
        assert!(
            Shard::from_environment(garbage)
                .unwrap_err()
                .to_string()
                .contains("abc")
        );
        let outside = env(&[
            ("SLURM_ARRAY_TASK_ID", "9"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ]);
        assert!(
            Shard::from_environment(outside)
                .unwrap_err()
                .to_string()
                .contains("9/4")
        );
    }
}
