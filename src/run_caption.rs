//! What a figure or a table shows: the scenario, the planner parameter set (`paper`,
//! `mergesim`, or custom when the scenario file changes `[sim.planner]` values), the instance
//! and the commit the simulator was built from ([`crate::build_info`]), as one caption line —
//! the PNG figures' caption band, the GIF's header, the `compare` table's header.

use serde::Serialize;

/// The caption of a figure or table.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct RunCaption {
    /// Scenario name.
    pub scenario: String,
    /// Parameter set: `paper`, `mergesim`, or `custom (SET + [sim.planner] KEYS)`.
    pub params: String,
    /// Seed of the instance (null: the nominal scenario), as a string (exact in every JSON
    /// reader).
    #[serde(with = "crate::exact_seed::option")]
    pub seed: Option<u64>,
    /// The simulator's commit, shortened ([`crate::build_info::short_commit`]).
    pub commit: String,
    /// How the recorded traffic of a CommonRoad road moves (`none`, `replay`, `reactive`);
    /// `None` on any other road (and then not in the line).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub recorded_traffic: Option<String>,
}

impl RunCaption {
    /// The caption of `scenario`'s instance `seed` (None: nominal), with this build's commit.
    pub fn of_scenario(scenario: &scenarios::scenario::Scenario, seed: Option<u64>) -> Self {
        let keys: Vec<&str> = scenario
            .planner_overrides
            .keys()
            .map(String::as_str)
            .collect();
        Self {
            scenario: scenario.name.clone(),
            params: params_label(scenario.params.name(), &keys),
            seed,
            commit: crate::build_info::short_commit(),
            recorded_traffic: scenario
                .sim
                .commonroad_road()
                .map(|road| road.recorded_traffic.to_string()),
        }
    }

    /// One line: `scenario S · parameters P · nominal|seed N · mergesim COMMIT`, with
    /// `· recorded traffic MODE` after the instance on a CommonRoad road.
    pub fn line(&self) -> String {
        let instance = self
            .seed
            .map_or_else(|| "nominal".to_string(), |s| format!("seed {s}"));
        self.line_with(&instance)
    }

    /// The line with `instance` in place of the seed (e.g. the instances of a grid).
    pub fn line_with(&self, instance: &str) -> String {
        let traffic = self
            .recorded_traffic
            .as_ref()
            .map(|mode| format!(" · recorded traffic {mode}"))
            .unwrap_or_default();
        format!(
            "scenario {} · parameters {} · {instance}{traffic} · mergesim {}",
            self.scenario, self.params, self.commit
        )
    }
}

/// The parameter set's name, or `custom (SET + [sim.planner] k1, k2, …)` when a scenario file
/// sets `[sim.planner]` values on top of it (at most three keys named).
pub fn params_label(set: &str, overrides: &[&str]) -> String {
    if overrides.is_empty() {
        return set.to_string();
    }
    let mut keys = overrides
        .iter()
        .take(3)
        .copied()
        .collect::<Vec<_>>()
        .join(", ");
    if overrides.len() > 3 {
        keys.push_str(&format!(" and {} more", overrides.len() - 3));
    }
    format!("custom ({set} + [sim.planner] {keys})")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_line_names_scenario_set_instance_and_commit() {
        let caption = RunCaption {
            scenario: "urgent_merge".into(),
            params: "paper".into(),
            seed: Some(7),
            commit: "0123456789ab".into(),
            recorded_traffic: None,
        };
        assert_eq!(
            caption.line(),
            "scenario urgent_merge · parameters paper · seed 7 · mergesim 0123456789ab"
        );
        let on_commonroad = RunCaption {
            recorded_traffic: Some("reactive".into()),
            ..caption
        };
        assert_eq!(
            on_commonroad.line(),
            "scenario urgent_merge · parameters paper · seed 7 · recorded traffic reactive · \
             mergesim 0123456789ab"
        );
    }

    #[test]
    fn a_builtin_is_its_set_and_overrides_make_it_custom() {
        let scenario =
            scenarios::scenario::Scenario::load("urgent_merge").unwrap_or_else(|e| panic!("{e}"));
        let caption = RunCaption::of_scenario(&scenario, None);
        assert_eq!(caption.params, scenario.params.name());
        assert_eq!(caption.commit, crate::build_info::short_commit());
        assert_eq!(caption.recorded_traffic, None);
        assert!(caption.line().contains("· nominal ·"), "{}", caption.line());
        assert_eq!(
            params_label("mergesim", &["substeps", "path_time_gap_s"]),
            "custom (mergesim + [sim.planner] substeps, path_time_gap_s)"
        );
        assert_eq!(
            params_label("paper", &["a", "b", "c", "d", "e"]),
            "custom (paper + [sim.planner] a, b, c and 2 more)"
        );
    }
}
