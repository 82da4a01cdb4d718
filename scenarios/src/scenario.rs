//! The scenario file format and its loading.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sim::{SimConfig, VehicleSpec};
use thiserror::Error;

use crate::builtin;

/// A complete scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Short name, used in output file names and summaries.
    pub name: String,
    /// One line saying what it is.
    #[serde(default)]
    pub description: String,
    /// Shared settings: road, μ, time steps, V2V, planner, tracker, safety thresholds.
    #[serde(default)]
    pub sim: SimConfig,
    /// The vehicles, in id order.
    pub vehicles: Vec<VehicleSpec>,
}

/// Why a scenario could not be loaded.
#[derive(Debug, Error)]
pub enum ScenarioError {
    /// Neither a built-in name nor a readable file.
    #[error("unknown scenario {name:?}: not a built-in ({builtins}) and no such file")]
    Unknown {
        /// What was asked for.
        name: String,
        /// The valid built-in names.
        builtins: String,
    },
    /// The file could not be read.
    #[error("cannot read scenario file {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// TOML syntax error, unknown key or wrong type (the message names line and field).
    #[error("{origin}: {message}")]
    Parse {
        /// File name or `built-in NAME`.
        origin: String,
        /// What the TOML reader said, with line and column.
        message: String,
    },
    /// A value out of its allowed range.
    #[error("{origin}: {source}")]
    Invalid {
        /// File name or `built-in NAME`.
        origin: String,
        /// The simulator's validation error (names the field and value).
        source: sim::SimError,
    },
}

impl Scenario {
    /// Loads a built-in by name, or else a TOML file by path.
    pub fn load(name_or_path: &str) -> Result<Self, ScenarioError> {
        if let Some(text) = builtin::toml_of(name_or_path) {
            return Self::from_toml(text, &format!("built-in {name_or_path}"));
        }
        let path = Path::new(name_or_path);
        if !path.exists() {
            return Err(ScenarioError::Unknown {
                name: name_or_path.to_string(),
                builtins: builtin::names().join(", "),
            });
        }
        let text = std::fs::read_to_string(path).map_err(|source| ScenarioError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// Parses and validates a scenario from TOML text; `origin` names it in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, ScenarioError> {
        let scenario: Scenario = toml::from_str(text).map_err(|e| ScenarioError::Parse {
            origin: origin.to_string(),
            message: e.to_string().trim_end().to_string(),
        })?;
        scenario.validate(origin)?;
        Ok(scenario)
    }

    /// Checks every value (the simulator's own validation, plus the vehicle list).
    pub fn validate(&self, origin: &str) -> Result<(), ScenarioError> {
        let invalid = |source| ScenarioError::Invalid {
            origin: origin.to_string(),
            source,
        };
        self.sim.validate().map_err(invalid)?;
        sim::validate_vehicles(&self.sim, &self.vehicles).map_err(invalid)?;
        Ok(())
    }

    /// The scenario as TOML text.
    pub fn to_toml(&self) -> Result<String, ScenarioError> {
        toml::to_string(self).map_err(|e| ScenarioError::Parse {
            origin: self.name.clone(),
            message: e.to_string(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_loads_and_round_trips() {
        for name in builtin::names() {
            let s = Scenario::load(name).unwrap();
            let text = s.to_toml().unwrap();
            let back = Scenario::from_toml(&text, "round trip").unwrap();
            assert_eq!(s, back, "{name}");
        }
    }

    #[test]
    fn unknown_key_is_named_with_its_line() {
        let text = builtin::toml_of("urgent_merge")
            .unwrap()
            .replace("mu = 0.8", "mu = 0.8\nfriction = 3");
        let err = Scenario::from_toml(&text, "x.toml").unwrap_err().to_string();
        assert!(err.contains("friction") && err.contains("line"), "{err}");
    }

    #[test]
    fn out_of_range_value_is_named() {
        let text = builtin::toml_of("urgent_merge")
            .unwrap()
            .replace("mu = 0.8", "mu = -0.5");
        let err = Scenario::from_toml(&text, "x.toml").unwrap_err().to_string();
        assert!(err.contains("mu") && err.contains("-0.5"), "{err}");
    }

    #[test]
    fn unknown_scenario_lists_builtins() {
        let err = Scenario::load("no_such_scenario").unwrap_err().to_string();
        assert!(err.contains("urgent_merge"), "{err}");
    }
}
