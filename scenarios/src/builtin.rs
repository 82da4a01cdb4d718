//! Built-in scenarios, embedded as TOML so that `merge_sim scenario show NAME` prints exactly
//! what `--scenario PATH` reads back. Each carries default randomisation ranges for sweeps.

/// (name, TOML text) of every built-in scenario.
pub const BUILTINS: &[(&str, &str)] = &[
    ("urgent_merge", include_str!("../builtin/urgent_merge.toml")),
    (
        "relaxed_merge",
        include_str!("../builtin/relaxed_merge.toml"),
    ),
    ("dense_merge", include_str!("../builtin/dense_merge.toml")),
    (
        "mixed_traffic",
        include_str!("../builtin/mixed_traffic.toml"),
    ),
    ("degraded_v2v", include_str!("../builtin/degraded_v2v.toml")),
    ("wet_road", include_str!("../builtin/wet_road.toml")),
    (
        "platoon_merge_50",
        include_str!("../builtin/platoon_merge_50.toml"),
    ),
    ("curved_merge", include_str!("../builtin/curved_merge.toml")),
    ("on_ramp", include_str!("../builtin/on_ramp.toml")),
    ("on_ramp_flow", include_str!("../builtin/on_ramp_flow.toml")),
    ("merge_flow", include_str!("../builtin/merge_flow.toml")),
];

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
