//! A study report's provenance: a plan in a git repository, committed as it is, gives a
//! confirmatory report citing its blob hash and the commit that first added it; modified
//! (uncommitted, or committed again) or outside git, the report is exploratory.

mod common;

use std::path::Path;
use std::process::Command;

use common::{merge_sim, scratch, stderr};
use mergesim::study::provenance::of_plan;

/// A tiny plan: 2 planners × 2 instances of the urgent merge cut to 1 s.
const PLAN: &str = r#"name = "tiny"
scenario = "urgent_merge"
planners = ["pf-sp", "pf-iso"]
reference = "pf-sp"

[instances]
n = 2
seed = 3

[factors]
"sim.duration_s" = [1.0]

[endpoints]
primary = { figure = "obstacle.max_abs_yaw_rate_radps", threshold = "0.01 rad/s" }
"#;

fn git(dir: &Path, args: &[&str]) -> String {
    let out = Command::new("git")
        .arg("-C")
        .arg(dir)
        .args(["-c", "user.name=Test", "-c", "user.email=test@example.org"])
        .args(args)
        .output()
        .expect("git runs");
    assert!(out.status.success(), "git {args:?}: {}", stderr(&out));
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

#[test]
fn committed_plans_are_confirmatory_and_changed_ones_exploratory() {
    let repo = scratch("study_provenance_repo");
    git(&repo, &["init", "-q"]);
    let dir = repo.join("plans");
    std::fs::create_dir(&dir).unwrap();
    let plan = dir.join("tiny.toml");
    std::fs::write(&plan, PLAN).unwrap();
    git(&repo, &["add", "plans/tiny.toml"]);
    git(&repo, &["commit", "-q", "-m", "add the plan"]);
    let added = git(&repo, &["rev-parse", "HEAD"]);
    let blob = git(&repo, &["hash-object", "plans/tiny.toml"]);

    // Committed as it is: confirmatory.
    let p = of_plan(&plan, PLAN);
    assert!(!p.exploratory, "{:?}", p.reasons);
    assert_eq!(p.plan_blob.as_deref(), Some(blob.as_str()));
    assert_eq!(p.plan_added_in.as_deref(), Some(added.as_str()));
    assert_eq!(p.simulator_commit, mergesim::build_info::COMMIT);
    // A later commit touching something else keeps it so, and the first commit is still cited.
    std::fs::write(repo.join("other.txt"), "x").unwrap();
    git(&repo, &["add", "other.txt"]);
    git(&repo, &["commit", "-q", "-m", "other"]);
    let p = of_plan(&plan, PLAN);
    assert!(!p.exploratory, "{:?}", p.reasons);
    assert_eq!(p.plan_added_in.as_deref(), Some(added.as_str()));

    // The CLI's report says the same.
    let out = merge_sim(&["study", plan.to_str().unwrap(), "--quiet"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let md = std::fs::read_to_string(dir.join("tiny.report/report.md")).unwrap();
    assert!(!md.contains("**exploratory**"), "{md}");
    assert!(md.contains("confirmatory"), "{md}");
    assert!(md.contains(&blob) && md.contains(&added), "{md}");

    // Modified, not committed: exploratory.
    let changed = PLAN.replace("seed = 3", "seed = 4");
    std::fs::write(&plan, &changed).unwrap();
    let p = of_plan(&plan, &changed);
    assert!(p.exploratory);
    assert!(
        p.reasons.iter().any(|r| r.contains("uncommitted changes")),
        "{:?}",
        p.reasons
    );
    let out = merge_sim(&["study", plan.to_str().unwrap(), "--quiet"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let md = std::fs::read_to_string(dir.join("tiny.report/report.md")).unwrap();
    assert!(md.contains("> **exploratory**"), "{md}");

    // Modified and committed again: still not the version first added, still exploratory.
    git(
        &repo,
        &["commit", "-q", "-am", "change the seed after the fact"],
    );
    let p = of_plan(&plan, &changed);
    assert!(p.exploratory);
    assert_eq!(p.plan_added_in.as_deref(), Some(added.as_str()));
    assert!(
        p.reasons
            .iter()
            .any(|r| r.contains("differs from the version")),
        "{:?}",
        p.reasons
    );
}

#[test]
fn a_plan_outside_git_is_exploratory() {
    let dir = scratch("study_provenance_nogit");
    let plan = dir.join("tiny.toml");
    std::fs::write(&plan, PLAN).unwrap();
    let p = of_plan(&plan, PLAN);
    assert!(p.exploratory);
    assert_eq!(p.plan_added_in, None);
    // The blob hash does not need a repository.
    assert_eq!(p.plan_blob.as_ref().map(String::len), Some(40));
}
