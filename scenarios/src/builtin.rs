//! Built-in scenarios, embedded as TOML so that `merge_sim scenario show NAME` prints exactly
//! what `--scenario PATH` reads back.

/// (name, TOML text) of every built-in scenario.
pub const BUILTINS: &[(&str, &str)] =
    &[("urgent_merge", include_str!("../builtin/urgent_merge.toml"))];

/// Names of the built-in scenarios.
pub fn names() -> Vec<&'static str> {
    BUILTINS.iter().map(|(name, _)| *name).collect()
}

/// The TOML text of a built-in scenario.
pub fn toml_of(name: &str) -> Option<&'static str> {
    BUILTINS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
}
