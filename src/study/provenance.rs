//! Where a plan comes from: its git blob hash, the commit that first added it, whether the
//! file on disk is that committed version, and the simulator's commit. Read with the `git`
//! command in the plan's folder; a plan outside a repository (or without git) is exploratory.

use std::path::Path;
use std::process::Command;

use serde::{Deserialize, Serialize};

/// The provenance of a plan, cited by the report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// `git hash-object` of the plan file (null if git could not run).
    pub plan_blob: Option<String>,
    /// The commit that first added the plan (`git log --diff-filter=A`, the oldest), null if
    /// the plan was never committed.
    pub plan_added_in: Option<String>,
    /// The simulator's commit (`mergesim::build_info::COMMIT`).
    pub simulator_commit: String,
    /// Whether the report is exploratory: the plan has uncommitted changes, differs from the
    /// version the commit that first added it holds, or is not in git at all.
    pub exploratory: bool,
    /// Why it is exploratory (empty if it is not).
    pub reasons: Vec<String>,
}

/// Runs git in `dir`; its trimmed stdout if it succeeded.
fn git(dir: &Path, args: &[&str]) -> Option<String> {
    let output = Command::new("git")
        .arg("-C")
        .arg(dir)
        .args(args)
        .output()
        .ok()?;
    output
        .status
        .success()
        .then(|| String::from_utf8_lossy(&output.stdout).trim().to_string())
}

/// The provenance of the plan file at `path` whose text is `text`.
pub fn of_plan(path: &Path, text: &str) -> Provenance {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let file = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut reasons = Vec::new();
    let plan_blob = git(dir, &["hash-object", "--", &file]);
    let in_repo = git(dir, &["rev-parse", "--is-inside-work-tree"]).as_deref() == Some("true");
    let plan_added_in = if in_repo {
        git(dir, &["log", "--diff-filter=A", "--format=%H", "--", &file])
            .and_then(|out| out.lines().last().map(str::to_string))
            .filter(|s| !s.is_empty())
    } else {
        None
    };
    match &plan_added_in {
        None => reasons.push(if in_repo {
            "the plan was never committed".to_string()
        } else {
            "the plan is not in a git repository".to_string()
        }),
        Some(commit) => {
            let dirty = git(dir, &["status", "--porcelain", "--", &file])
                .map(|s| !s.is_empty())
                .unwrap_or(true);
            if dirty {
                reasons.push("the plan has uncommitted changes".into());
            }
            let prefix = git(dir, &["rev-parse", "--show-prefix"]).unwrap_or_default();
            let committed = git(dir, &["show", &format!("{commit}:{prefix}{file}")]);
            // `git show` trims nothing but our helper trims stdout: compare trimmed texts.
            if committed.as_deref() != Some(text.trim()) {
                reasons.push(format!(
                    "the plan differs from the version commit {} first added",
                    &commit[..commit.len().min(12)]
                ));
            }
        }
    }
    if plan_blob.is_none() {
        reasons.push("git could not hash the plan".into());
    }
    Provenance {
        plan_blob,
        plan_added_in,
        simulator_commit: crate::build_info::COMMIT.to_string(),
        exploratory: !reasons.is_empty(),
        reasons,
    }
}
