//! The scenario file format, its validation and its randomised instances.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use mergesim_types::Lane;
use planner::ParameterSet;
use planner::params::PlannerParams;
use serde::{Deserialize, Serialize};
use sim::SimError;
use sim::config::{SimConfig, VehicleSpec};
use thiserror::Error;

use crate::builtin;
use crate::randomisation::Randomisation;
use crate::source_location::line_of;

/// A complete scenario: nominal values plus the ranges a sweep draws instances from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Short name, used in output file names and summaries.
    pub name: String,
    /// One line saying what it is.
    #[serde(default)]
    pub description: String,
    /// The planner parameter set (`paper` or `mergesim`, the default) that `[sim.planner]`
    /// values are applied on top of.
    #[serde(default)]
    pub params: ParameterSet,
    /// Shared settings: road, μ, time steps, V2V, planner, tracker, safety thresholds.
    /// `sim.planner` holds the effective planner parameters: the set's, with the file's
    /// `[sim.planner]` values on top.
    #[serde(default)]
    pub sim: SimConfig,
    /// The vehicles, in id order.
    pub vehicles: Vec<VehicleSpec>,
    /// Randomisation ranges for sweeps and `run --seed` (empty: every instance is nominal).
    #[serde(default, skip_serializing_if = "Randomisation::is_empty")]
    pub randomise: Randomisation,
    /// The PF planners' values the file sets (`[sim.planner]` and `[sim.planners.pf]`,
    /// `[sim.planners.pf-iso]`, `[sim.planners.pf-sp]`, merged; applied on top of `params`).
    #[serde(skip)]
    pub planner_overrides: toml::Table,
    /// The file and text the scenario was read from, for the lines of checks made after
    /// loading ([`Scenario::check_planners`]); `None` for a scenario built in code.
    #[serde(skip)]
    pub source: Option<Arc<ScenarioSource>>,
}

/// Where a scenario was read from (its origin and TOML text).
#[derive(Clone, Debug)]
pub struct ScenarioSource {
    /// File name or `built-in NAME`.
    pub origin: String,
    /// The TOML text as read.
    pub text: String,
}

/// Where a scenario was read from is not part of what it is: two scenarios compare equal
/// whatever their sources.
impl PartialEq for ScenarioSource {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// The planner parameters of `set` with `overrides` (a `[sim.planner]` table) on top.
pub(crate) fn planner_params_with_overrides(
    set: ParameterSet,
    overrides: &toml::Table,
) -> Result<PlannerParams, String> {
    let mut table = toml::Table::try_from(set.planner_params()).map_err(|e| e.to_string())?;
    for (key, value) in overrides {
        table.insert(key.clone(), value.clone());
    }
    toml::Value::Table(table)
        .try_into()
        .map_err(|e: toml::de::Error| e.to_string())
}

/// A CommonRoad file that a scenario TOML names and that cannot be read, refused naming the
/// TOML, the line of the key that names it and the field, then the file's own error.
fn file_error_in_toml(e: ScenarioError, origin: &str, text: &str, key: &[&str]) -> ScenarioError {
    match e {
        ScenarioError::CommonRoad(e) => {
            let path: Vec<String> = key.iter().map(|k| k.to_string()).collect();
            let field = path.join(".");
            ScenarioError::Invalid {
                origin: origin.to_string(),
                line: Line(line_of(text, &path)),
                message: format!("{field}: {e}"),
                field: Some(field),
            }
        }
        other => other,
    }
}

/// A line of a scenario text, shown as `, line N` after the file name (nothing if unknown).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Line(pub Option<usize>);

impl fmt::Display for Line {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(line) => write!(f, ", line {line}"),
            None => Ok(()),
        }
    }
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
    #[error("cannot read scenario file {path}")]
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
    /// The CommonRoad file of the scenario cannot be read or does not make a road (names the
    /// file, the line and the element).
    #[error(transparent)]
    CommonRoad(#[from] mergesim_commonroad::CommonRoadError),
    /// A value out of its allowed range, or values inconsistent with each other.
    #[error("{origin}{line}: {message}")]
    Invalid {
        /// File name or `built-in NAME`.
        origin: String,
        /// Line of the offending value in the text, when known.
        line: Line,
        /// Dotted name of the offending field, when there is one.
        field: Option<String>,
        /// What is wrong (names the field and value).
        message: String,
    },
}

/// Overshoot allowed over a vehicle's highest nominal speed when checking that the road is long
/// enough for the run (the trackers hold speeds within a few per cent of their targets).
pub const ROAD_END_SPEED_ALLOWANCE: f64 = 0.1;

/// The highest speed vehicle `v` can drive (m/s): the largest of its start and target speeds
/// (with the upper ends of their randomisation `b`) and of its prescribed profile, plus
/// [`ROAD_END_SPEED_ALLOWANCE`]: what the road-length checks assume for the whole run.
fn top_speed_mps(v: &VehicleSpec, b: &crate::randomisation::VehicleOffsetBounds) -> f64 {
    let prescribed_max_mps = match &v.driver {
        sim::config::Driver::Prescribed { speed_profile, .. } => speed_profile
            .points
            .iter()
            .map(|p| p[1])
            .fold(0.0, f64::max),
        _ => 0.0,
    };
    (v.speed_mps + b.speed_mps[1])
        .max(v.target_speed_mps + b.target_speed_mps[1])
        .max(prescribed_max_mps)
        * (1.0 + ROAD_END_SPEED_ALLOWANCE)
}

/// Longest scenario file read (bytes): 16 MiB, far beyond 200 vehicles with comments.
pub const MAX_SCENARIO_BYTES: u64 = 16 << 20;

impl Scenario {
    /// Loads a built-in by name, or else a file by path: a CommonRoad XML file (a name ending
    /// in `.xml`, [`Scenario::from_commonroad`], recorded traffic replayed) or a scenario TOML.
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
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("xml"))
        {
            return Self::from_commonroad(path, sim::recorded_traffic::TrafficMode::default());
        }
        let text = mergesim_types::files::read_regular_text(path, MAX_SCENARIO_BYTES).map_err(
            |source| ScenarioError::Io {
                path: path.to_path_buf(),
                source,
            },
        )?;
        Self::from_toml_in(&text, &path.display().to_string(), path.parent())
    }

    /// Parses and validates a scenario from TOML text; `origin` names it in errors. A
    /// `[sim.road] commonroad = "…"` path is relative to the working directory.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, ScenarioError> {
        Self::from_toml_in(text, origin, None)
    }

    /// [`Scenario::from_toml`] for a TOML file in the folder `base` (a `[sim.road]
    /// commonroad = "…"` path is relative to it).
    pub fn from_toml_in(
        text: &str,
        origin: &str,
        base: Option<&Path>,
    ) -> Result<Self, ScenarioError> {
        let parse_error = |e: toml::de::Error| ScenarioError::Parse {
            origin: origin.to_string(),
            message: e.to_string().trim_end().to_string(),
        };
        let table: toml::Table = toml::from_str(text).map_err(parse_error)?;
        // A vehicle's `driver = { planner = …, params = { … } }` (planner_tables.rs): its
        // shape, with the line of what is wrong, before the typed reading.
        planner_tables::check_driver_params(&table, text, origin)?;
        let full_text = text;
        // `[sim.road] commonroad = …` (commonroad_toml.rs): read without those keys.
        let source = crate::commonroad_toml::road_source(&table, text, origin)?;
        let stripped;
        let text_read = match &source {
            Some(s) => {
                stripped = s.stripped_text.clone();
                stripped.as_str()
            }
            None => text,
        };
        let mut scenario: Scenario = toml::from_str(text_read).map_err(parse_error)?;
        if let Some(source) = &source {
            crate::commonroad_toml::apply(&mut scenario, source, base)
                .map_err(|e| file_error_in_toml(e, origin, text, &["sim", "road", "commonroad"]))?;
        } else if scenario.sim.commonroad_road().is_some() {
            // `[sim.lane_road] commonroad = { file = … }` (e.g. a CommonRoad scenario written
            // out by `to_toml`): the same file reading.
            crate::commonroad_toml::read_lane_road_source(&mut scenario, base).map_err(|e| {
                file_error_in_toml(e, origin, text, &["sim", "lane_road", "commonroad"])
            })?;
        }
        // `[sim.lane_road] opendrive = { file = … }`: read once, relative to the TOML.
        crate::opendrive_source::read_opendrive_source(&mut scenario, base, origin, Some(text))?;
        // The PF planners' tables as written, to apply on top of the parameter set.
        scenario.set_source(origin, full_text);
        scenario.take_pf_tables(&table, origin, full_text)?;
        scenario.apply_parameter_set(origin, Some(full_text))?;
        if source.is_none() {
            lane_road_checks::check_one_road(&table, &scenario, origin, text)?;
        }
        scenario
            .check(origin, Some(text))
            .map_err(|e| crate::commonroad_toml::aliased(e, &scenario, &table, text))?;
        scenario.check_planner_tables(&sim::registry::BehaviourRegistry::builtin(), true)?;
        Ok(scenario)
    }

    /// The same scenario with the planner parameter set `set` (its `[sim.planner]` values kept
    /// on top), checked again.
    pub fn with_parameter_set(&self, set: ParameterSet) -> Result<Self, ScenarioError> {
        let mut scenario = self.clone();
        scenario.params = set;
        let origin = format!("{} with --params {set}", self.name);
        scenario.apply_parameter_set(&origin, None)?;
        scenario.check(&origin, None)?;
        scenario.check_planner_tables(&sim::registry::BehaviourRegistry::builtin(), true)?;
        Ok(scenario)
    }

    /// `sim.planner` = the set's parameters with the overrides on top.
    pub(crate) fn apply_parameter_set(
        &mut self,
        origin: &str,
        text: Option<&str>,
    ) -> Result<(), ScenarioError> {
        self.sim.planner = planner_params_with_overrides(self.params, &self.planner_overrides)
            .map_err(|message| {
                // The key that cannot be read: the first whose removal lets the rest be read.
                let key = self.planner_overrides.keys().find(|key| {
                    let mut rest = self.planner_overrides.clone();
                    rest.remove(*key);
                    planner_params_with_overrides(self.params, &rest).is_ok()
                });
                let (path, field) = match key {
                    Some(key) => {
                        let path = self.pf_key_path(key);
                        let field = self.written_field(format!("planner.{key}"));
                        (path, field)
                    }
                    None => (
                        vec!["sim".to_string(), "planner".to_string()],
                        "planner".into(),
                    ),
                };
                ScenarioError::Invalid {
                    origin: origin.to_string(),
                    line: Line(text.and_then(|t| line_of(t, &path))),
                    message: format!(
                        "{field}: the planner values on top of the {} set: {message}",
                        self.params
                    ),
                    field: Some(field),
                }
            })?;
        Ok(())
    }

    /// Checks every value, nominal and randomised (see `Scenario::check`).
    pub fn validate(&self, origin: &str) -> Result<(), ScenarioError> {
        self.check(origin, None)
    }

    /// Checks every value; `text`, if given, is the TOML the scenario came from (for lines).
    ///
    /// 1. The simulator's own checks on the nominal values (ranges of every field).
    /// 2. The randomisation entries (valid distributions, existing vehicle names).
    /// 3. The simulator's checks at both corners of the randomisation box (every randomised
    ///    value at its lower end, then at its upper end): these checks are per-field ranges, so
    ///    passing at both corners means every instance any seed can draw is valid.
    /// 4. Geometry over the whole box: a vehicle in the lower lane starts where that lane exists
    ///    (its front before `road.merge_end_x_m`), and no two vehicles can overlap at spawn.
    pub(crate) fn check(&self, origin: &str, text: Option<&str>) -> Result<(), ScenarioError> {
        let at =
            |entry: Option<Vec<String>>| Line(text.zip(entry).and_then(|(t, p)| line_of(t, &p)));
        let sim_error = |e: SimError, prefix: &str, entry: Option<Vec<String>>| {
            if let SimError::Road(lane_error) = &e {
                let (path, field) = self.lane_error_path(lane_error);
                return ScenarioError::Invalid {
                    origin: origin.to_string(),
                    line: at(Some(path)),
                    message: format!("{prefix}{field}: {lane_error}"),
                    field: Some(field),
                };
            }
            let nominal = sim_error_field(&e).and_then(|f| self.nominal_path(&f));
            let field = sim_error_field(&e).map(|f| self.written_field(f));
            ScenarioError::Invalid {
                origin: origin.to_string(),
                line: at(entry.or(nominal)),
                field,
                message: format!("{prefix}{e}"),
            }
        };
        self.sim.validate().map_err(|e| sim_error(e, "", None))?;
        sim::config::validate_vehicles(&self.sim, &self.vehicles)
            .map_err(|e| sim_error(e, "", None))?;
        self.randomise
            .check_entries(&self.vehicles)
            .map_err(|issue| ScenarioError::Invalid {
                origin: origin.to_string(),
                line: at(Some(issue.path.clone())),
                field: Some(issue.path.join(".")),
                message: format!("{}: {}", issue.path.join("."), issue.message),
            })?;
        for (upper, end) in [(false, "lower"), (true, "upper")] {
            let (sim_c, vehicles_c) = self.randomise.corner(&self.sim, &self.vehicles, upper);
            let entry_of = |e: &SimError| {
                let field = sim_error_field(e)?;
                match split_vehicle_field(&field) {
                    Some((name, key)) => self.randomise.vehicle_entry_path(name, key),
                    None => self.randomise.sim_entry_path(&field),
                }
            };
            let corner_error = |e: SimError| {
                let entry = entry_of(&e);
                let prefix = format!(
                    "{}at the {end} end of the randomisation range: ",
                    entry
                        .as_ref()
                        .map(|p| format!("{}: ", p.join(".")))
                        .unwrap_or_default()
                );
                sim_error(e, &prefix, entry)
            };
            sim_c.validate().map_err(corner_error)?;
            sim::config::validate_vehicles(&sim_c, &vehicles_c).map_err(corner_error)?;
        }
        self.check_geometry(origin, &at)
    }

    /// The TOML path of a nominal field named as the simulator names it (`mu`,
    /// `v2v.latency_s`, `vehicles[ego].x_m`).
    fn nominal_path(&self, field: &str) -> Option<Vec<String>> {
        if field == "vehicles" {
            // Too many vehicles: the first one beyond the limit.
            return Some(vec![
                "vehicles".into(),
                sim::config::MAX_VEHICLES.to_string(),
            ]);
        }
        if let Some((name, key)) = split_vehicle_field(field) {
            // `vehicles[#i]` names the i-th vehicle; a nested key (`driver.prescribed…`) is
            // found at its first component.
            let index = match name.strip_prefix('#') {
                Some(i) => i.parse().ok()?,
                None => self.vehicles.iter().position(|v| v.name == name)?,
            };
            let first = key.split(['.', '[', ' ']).next().unwrap_or(key);
            return Some(vec![
                "vehicles".into(),
                index.to_string(),
                first.to_string(),
            ]);
        }
        if let Some(key) = field.strip_prefix("planner.") {
            return Some(self.pf_key_path(key));
        }
        let mut path = vec!["sim".to_string()];
        path.extend(field.split('.').map(str::to_string));
        Some(path)
    }

    /// The scenario as TOML text. `[sim.planner]` holds only the values that differ from the
    /// parameter set's, so the text reads back to the same effective parameters.
    pub fn to_toml(&self) -> Result<String, ScenarioError> {
        let error = |message: String| ScenarioError::Parse {
            origin: self.name.clone(),
            message,
        };
        let mut table = toml::Table::try_from(self).map_err(|e| error(e.to_string()))?;
        let base = toml::Table::try_from(self.params.planner_params())
            .map_err(|e| error(e.to_string()))?;
        if let Some(sim) = table.get_mut("sim").and_then(|v| v.as_table_mut()) {
            // A road of lanes that does not bend `[sim.road]` stands alone (check_one_road).
            if self
                .sim
                .lane_road
                .as_ref()
                .is_some_and(|c| !c.is_merge_road())
            {
                sim.remove("road");
            }
            let differing: toml::Table = match sim.get("planner").and_then(|p| p.as_table()) {
                Some(planner) => planner
                    .iter()
                    .filter(|(key, value)| base.get(*key) != Some(*value))
                    .map(|(key, value)| (key.clone(), value.clone()))
                    .collect(),
                None => toml::Table::new(),
            };
            if differing.is_empty() {
                sim.remove("planner");
            } else {
                sim.insert("planner".into(), toml::Value::Table(differing));
            }
        }
        toml::to_string(&table).map_err(|e| error(e.to_string()))
    }

    /// The instance drawn with `seed` from the `[randomise]` ranges ("same scenario +
    /// same seed ⇒ same run"). Deterministic; the instance has no randomisation left, so it is
    /// its own nominal scenario. For a scenario that passed `Scenario::check`, every value of
    /// the instance is valid; otherwise `World::new` reports the bad value.
    pub fn instantiate(&self, seed: u64) -> Scenario {
        let (sim, vehicles) = self.randomise.draw(&self.sim, &self.vehicles, seed);
        Scenario {
            name: self.name.clone(),
            description: self.description.clone(),
            params: self.params,
            sim,
            vehicles,
            randomise: Randomisation::default(),
            planner_overrides: self.planner_overrides.clone(),
            source: self.source.clone(),
        }
    }

    /// The scenario a run uses: the nominal one without a seed, else [`Scenario::instantiate`].
    pub fn instance(&self, seed: Option<u64>) -> Scenario {
        match seed {
            Some(seed) => self.instantiate(seed),
            None => self.clone(),
        }
    }
}

/// The field a simulator error names, if any.
fn sim_error_field(e: &SimError) -> Option<String> {
    e.field()
}

/// `vehicles[NAME].key` → (`NAME`, `key`).
fn split_vehicle_field(field: &str) -> Option<(&str, &str)> {
    let rest = field.strip_prefix("vehicles[")?;
    let (name, key) = rest.split_once("].")?;
    Some((name, key))
}

mod geometry_checks;
mod lane_road_checks;
mod planner_tables;
#[cfg(test)]
mod tests;
mod vehicle_model_choice;
