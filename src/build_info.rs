//! What the simulator was built from (written by `build.rs`).

/// The git commit the simulator was built from: a 40-digit hash, followed by `+dirty` when
/// tracked files differed from it at build time, or `unknown` when built outside git.
pub const COMMIT: &str = env!("MERGESIM_GIT_COMMIT");

/// [`COMMIT`] shortened for figure captions and table headers: the first 12 hex digits (plus
/// `+dirty`), or `unknown`.
pub fn short_commit() -> String {
    match COMMIT.split_once('+') {
        Some((hash, flag)) => format!("{}+{flag}", &hash[..hash.len().min(12)]),
        None if COMMIT == "unknown" => COMMIT.to_string(),
        None => COMMIT[..COMMIT.len().min(12)].to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_commit_is_a_hash_or_unknown() {
        let hash = COMMIT.split('+').next().unwrap_or_default();
        assert!(
            COMMIT == "unknown"
                || (hash.len() == 40 && hash.chars().all(|c| c.is_ascii_hexdigit())),
            "{COMMIT}"
        );
        assert!(short_commit().len() <= 18);
    }
}
