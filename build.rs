//! Embeds the commit the simulator was built from (`mergesim::build_info`), so that figures,
//! tables and study reports can say which code produced them.
//!
//! The commit is read with `git rev-parse HEAD` at build time; `+dirty` is appended when tracked
//! files differed from it then. Without git (a source tarball) it is `unknown`. The build script
//! re-runs when HEAD or the branch it points to moves.

use std::path::Path;
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let output = Command::new("git").args(args).output().ok()?;
    if !output.status.success() {
        return None;
    }
    Some(String::from_utf8_lossy(&output.stdout).trim().to_string())
}

fn main() {
    let commit = git(&["rev-parse", "HEAD"]);
    let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
        .map(|status| !status.is_empty())
        .unwrap_or(false);
    let described = match commit {
        Some(hash) if dirty => format!("{hash}+dirty"),
        Some(hash) => hash,
        None => "unknown".to_string(),
    };
    println!("cargo:rustc-env=MERGESIM_GIT_COMMIT={described}");
    // Re-run when HEAD moves (a commit, a checkout) or the branch it names moves.
    if let Some(git_dir) = git(&["rev-parse", "--git-dir"]) {
        let head = Path::new(&git_dir).join("HEAD");
        println!("cargo:rerun-if-changed={}", head.display());
        if let Some(reference) = git(&["symbolic-ref", "-q", "HEAD"])
            && let Some(common) = git(&["rev-parse", "--git-common-dir"])
        {
            println!(
                "cargo:rerun-if-changed={}",
                Path::new(&common).join(&reference).display()
            );
            println!(
                "cargo:rerun-if-changed={}",
                Path::new(&common).join("packed-refs").display()
            );
        }
    }
    println!("cargo:rerun-if-changed=build.rs");
}
