//! The study plan file (TOML): parsed, checked and resolved (scenario, cells, planners,
//! endpoints, thresholds) before any run; every error names the plan's file, line and field.

use std::path::{Path, PathBuf};

use scenarios::scenario::Scenario;
use scenarios::source_location::line_of;
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::endpoints::{EndpointFigure, canonical_unit};

mod cells;

use cells::{factor_levels, resolve_cells};

/// Most runs of one study: cells × planners × instances (each run keeps a small row in
/// memory; for more, split the study into several plans).
pub const MAX_STUDY_RUNS: u64 = 100_000;

/// Fewest instances (a paired t-interval needs two differences).
pub const MIN_INSTANCES: u64 = 2;

/// Longest plan file read (bytes).
pub const MAX_PLAN_BYTES: u64 = 1 << 20;

/// Why a plan cannot be used: bad input, reported with the file and line (exit code 2).
#[derive(Debug, Error)]
pub enum PlanError {
    /// The file could not be read.
    #[error("cannot read study plan {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A TOML syntax error, an unknown key or a wrong type (the message has line and column).
    #[error("{origin}: {message}")]
    Parse {
        /// The plan file.
        origin: String,
        /// What the TOML reader said.
        message: String,
    },
    /// A value that cannot be used.
    #[error("{origin}{}: {field}: {message}", line.map(|l| format!(", line {l}")).unwrap_or_default())]
    Invalid {
        /// The plan file.
        origin: String,
        /// Line of the offending value, when known.
        line: Option<usize>,
        /// Dotted name of the offending field.
        field: String,
        /// What is wrong.
        message: String,
    },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawPlan {
    name: String,
    #[serde(default)]
    description: String,
    scenario: String,
    planners: Vec<String>,
    reference: String,
    instances: RawInstances,
    #[serde(default)]
    factors: Option<toml::Table>,
    #[serde(default)]
    cells: Option<Vec<toml::Table>>,
    endpoints: RawEndpoints,
    #[serde(default)]
    collisions: RawCollisions,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInstances {
    n: toml::Value,
    seed: toml::Value,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEndpoints {
    primary: RawEndpoint,
    #[serde(default)]
    secondary: Vec<RawEndpoint>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEndpoint {
    figure: String,
    threshold: toml::Value,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawCollisions {
    #[serde(default)]
    endpoints: Option<String>,
}

/// Over which window the motion-state endpoints are tested.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EndpointWindow {
    /// Before the run's first contact (the whole run without contact): the default.
    PreContact,
    /// The whole run, post-contact artefacts included.
    WholeRun,
}

impl EndpointWindow {
    /// Its name in the plan and the report.
    pub fn name(self) -> &'static str {
        match self {
            Self::PreContact => "pre-contact",
            Self::WholeRun => "whole-run",
        }
    }
}

/// One endpoint with its practical-significance threshold.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Endpoint {
    /// The figure.
    pub figure: EndpointFigure,
    /// The smallest |effect| that matters, in `unit` (> 0).
    pub threshold: f64,
    /// The unit of the figure and of the threshold.
    pub unit: String,
}

/// One cell of the design: a value for every factor.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cell {
    /// Index in the plan's order.
    pub index: usize,
    /// `factor = value` for each factor, in the factors' order.
    pub values: Vec<(String, String)>,
}

impl Cell {
    /// `sim.mu=0.8, sim.planner.x=1` (`nominal` without factors).
    pub fn label(&self) -> String {
        if self.values.is_empty() {
            return "nominal".into();
        }
        self.values
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// A checked plan, ready to run.
#[derive(Clone, Debug)]
pub struct StudyPlan {
    /// The plan file.
    pub path: PathBuf,
    /// Its text (what its identity is computed from).
    pub text: String,
    /// Study name.
    pub name: String,
    /// What it asks.
    pub description: String,
    /// The scenario as the plan names it.
    pub scenario_source: String,
    /// The scenario (nominal, before the factors).
    pub scenario: Scenario,
    /// The cells and the scenario of each (factors applied, checked).
    pub cells: Vec<(Cell, Scenario)>,
    /// Planners by registered name, in the plan's order.
    pub planners: Vec<String>,
    /// The reference planner (one of `planners`).
    pub reference: String,
    /// Instances per cell and planner.
    pub instances: u64,
    /// Seed K of the instances: instance i runs with `sweep::instance_seed(K, i)`.
    pub seed: u64,
    /// The primary endpoint.
    pub primary: Endpoint,
    /// The secondary endpoints (one Holm family per planner pair and cell).
    pub secondary: Vec<Endpoint>,
    /// The window motion-state endpoints are tested over.
    pub window: EndpointWindow,
}

impl StudyPlan {
    /// Runs in the whole study: cells × planners × instances.
    pub fn total_runs(&self) -> u64 {
        self.cells.len() as u64 * self.planners.len() as u64 * self.instances
    }

    /// Every endpoint, the primary first.
    pub fn endpoints(&self) -> impl Iterator<Item = &Endpoint> {
        std::iter::once(&self.primary).chain(&self.secondary)
    }

    /// FNV-1a 64 of the plan text (hex): the identity its rows carry.
    pub fn fingerprint(&self) -> String {
        format!("{:016x}", scenarios::randomisation::fnv1a64(&self.text))
    }

    /// Loads and checks the plan at `path`, its planners among the built-in ones.
    pub fn load(path: &Path) -> Result<Self, PlanError> {
        Self::load_with(path, &sim::registry::BehaviourRegistry::builtin())
    }

    /// Loads and checks the plan at `path`, its planners among those of `registry` (a user's
    /// planners by name).
    pub fn load_with(
        path: &Path,
        registry: &sim::registry::BehaviourRegistry,
    ) -> Result<Self, PlanError> {
        let text =
            mergesim_types::files::read_regular_text(path, MAX_PLAN_BYTES).map_err(|source| {
                PlanError::Io {
                    path: path.to_path_buf(),
                    source,
                }
            })?;
        Self::from_text_with(&text, path, registry)
    }

    /// Parses and checks `text`, the plan at `path` (relative paths start from its folder), its
    /// planners among the built-in ones.
    pub fn from_text(text: &str, path: &Path) -> Result<Self, PlanError> {
        Self::from_text_with(text, path, &sim::registry::BehaviourRegistry::builtin())
    }

    /// [`StudyPlan::from_text`] with the planners of `registry`.
    pub fn from_text_with(
        text: &str,
        path: &Path,
        registry: &sim::registry::BehaviourRegistry,
    ) -> Result<Self, PlanError> {
        let origin = path.display().to_string();
        let raw: RawPlan = toml::from_str(text).map_err(|e| PlanError::Parse {
            origin: origin.clone(),
            message: e.to_string().trim_end().to_string(),
        })?;
        let invalid = |at: &[&str], field: &str, message: String| PlanError::Invalid {
            origin: origin.clone(),
            line: line_of(text, &at.iter().map(|s| s.to_string()).collect::<Vec<_>>()),
            field: field.to_string(),
            message,
        };
        // The scenario: a built-in name, else a path relative to the plan.
        let scenario_path = path.parent().unwrap_or(Path::new(".")).join(&raw.scenario);
        let scenario = if scenarios::builtin::toml_of(&raw.scenario).is_some() {
            Scenario::load(&raw.scenario)
        } else {
            Scenario::load(&scenario_path.to_string_lossy())
        }
        .map_err(|e| invalid(&["scenario"], "scenario", e.to_string()))?;
        // Its planners' parameter tables, by the registry the study runs with (the error names
        // the scenario's file, line and field).
        scenario
            .check_planners(registry)
            .map_err(|e| invalid(&["scenario"], "scenario", e.to_string()))?;
        // Planners.
        let unknown = |name: &str| crate::experiment::unknown_planner(registry, name);
        let mut planners: Vec<String> = Vec::new();
        for (i, name) in raw.planners.iter().enumerate() {
            if !registry.contains(name) {
                return Err(invalid(
                    &["planners", &i.to_string()],
                    "planners",
                    unknown(name),
                ));
            }
            if planners.contains(name) {
                return Err(invalid(
                    &["planners", &i.to_string()],
                    "planners",
                    format!("{name} is listed twice"),
                ));
            }
            planners.push(name.clone());
        }
        let reference = raw.reference.clone();
        if !registry.contains(&reference) {
            return Err(invalid(&["reference"], "reference", unknown(&reference)));
        }
        if !planners.contains(&reference) {
            return Err(invalid(
                &["reference"],
                "reference",
                format!(
                    "{} is not one of the planners ({})",
                    raw.reference,
                    raw.planners.join(", ")
                ),
            ));
        }
        if planners.len() < 2 {
            return Err(invalid(
                &["planners"],
                "planners",
                "need the reference and at least one other planner".into(),
            ));
        }
        // Instances.
        let instances = match raw.instances.n.as_integer() {
            Some(n) if n >= MIN_INSTANCES as i64 => n as u64,
            _ => {
                return Err(invalid(
                    &["instances", "n"],
                    "instances.n",
                    format!(
                        "{}: need a whole number of instances >= {MIN_INSTANCES}",
                        raw.instances.n
                    ),
                ));
            }
        };
        let seed = match &raw.instances.seed {
            toml::Value::Integer(k) if *k >= 0 => *k as u64,
            toml::Value::String(s) => s.trim().parse::<u64>().map_err(|_| {
                invalid(
                    &["instances", "seed"],
                    "instances.seed",
                    format!("{s:?}: not a 64-bit unsigned integer"),
                )
            })?,
            other => {
                return Err(invalid(
                    &["instances", "seed"],
                    "instances.seed",
                    format!(
                        "{other}: need a non-negative integer (or a string for seeds above 2^63)"
                    ),
                ));
            }
        };
        // Cells.
        let designs = factor_levels(&raw, &invalid)?;
        let cells = resolve_cells(&scenario, designs, &origin, text)?;
        // Runs.
        let total = cells.len() as u64 * planners.len() as u64 * instances;
        if total > MAX_STUDY_RUNS {
            return Err(invalid(
                &["instances", "n"],
                "instances.n",
                format!(
                    "{} cells × {} planners × {instances} instances = {total} runs: more than \
                     the limit of {MAX_STUDY_RUNS} runs per study (split it into several plans)",
                    cells.len(),
                    planners.len()
                ),
            ));
        }
        // Endpoints.
        let vehicles: Vec<String> = scenario.vehicles.iter().map(|v| v.name.clone()).collect();
        let endpoint = |raw: &RawEndpoint, at: Vec<String>| -> Result<Endpoint, PlanError> {
            let at_of = |key: &str| {
                let mut p = at.clone();
                p.push(key.into());
                p
            };
            let line = |key: &str| line_of(text, &at_of(key));
            let field = format!("{}.", at.join("."));
            let error = |key: &str, message: String| PlanError::Invalid {
                origin: origin.clone(),
                line: line(key),
                field: format!("{field}{key}"),
                message,
            };
            let figure =
                EndpointFigure::parse(&raw.figure, &vehicles).map_err(|m| error("figure", m))?;
            let unit = figure.unit();
            let threshold_text = match &raw.threshold {
                toml::Value::String(s) => s.clone(),
                other => {
                    return Err(error(
                        "threshold",
                        format!(
                            "{other}: a threshold without a unit; write it with the unit of \
                             {} as a string, e.g. \"{other} {unit}\"",
                            raw.figure
                        ),
                    ));
                }
            };
            let mut parts = threshold_text.split_whitespace();
            let value = parts.next().and_then(|v| v.parse::<f64>().ok());
            let written_unit: Vec<&str> = parts.collect();
            let Some(value) = value.filter(|v| v.is_finite() && *v > 0.0) else {
                return Err(error(
                    "threshold",
                    format!(
                        "{threshold_text:?}: expected \"<number > 0> <unit>\", e.g. \"0.01 {unit}\""
                    ),
                ));
            };
            if written_unit.is_empty() {
                return Err(error(
                    "threshold",
                    format!(
                        "{threshold_text:?}: a threshold without a unit; {} is in {unit}: write \
                         \"{value} {unit}\"",
                        raw.figure
                    ),
                ));
            }
            let written = written_unit.join(" ");
            match canonical_unit(&written) {
                Some(u) if u == unit => {}
                _ => {
                    return Err(error(
                        "threshold",
                        format!(
                            "{threshold_text:?}: unit {written:?} does not match the unit of {}, \
                             {unit} (SI units only, no conversion)",
                            raw.figure
                        ),
                    ));
                }
            }
            Ok(Endpoint {
                figure,
                threshold: value,
                unit: unit.to_string(),
            })
        };
        let primary = endpoint(
            &raw.endpoints.primary,
            vec!["endpoints".into(), "primary".into()],
        )?;
        let mut secondary: Vec<Endpoint> = Vec::new();
        for (i, raw_e) in raw.endpoints.secondary.iter().enumerate() {
            let e = endpoint(
                raw_e,
                vec!["endpoints".into(), "secondary".into(), i.to_string()],
            )?;
            if e.figure == primary.figure || secondary.iter().any(|s| s.figure == e.figure) {
                return Err(invalid(
                    &["endpoints", "secondary", &i.to_string(), "figure"],
                    &format!("endpoints.secondary.{i}.figure"),
                    format!("{} is already an endpoint", e.figure.name),
                ));
            }
            secondary.push(e);
        }
        let window = match raw.collisions.endpoints.as_deref() {
            None | Some("pre-contact") => EndpointWindow::PreContact,
            Some("whole-run") => EndpointWindow::WholeRun,
            Some(other) => {
                return Err(invalid(
                    &["collisions", "endpoints"],
                    "collisions.endpoints",
                    format!("{other:?}: expected \"pre-contact\" or \"whole-run\""),
                ));
            }
        };
        Ok(StudyPlan {
            path: path.to_path_buf(),
            text: text.to_string(),
            name: raw.name,
            description: raw.description,
            scenario_source: raw.scenario,
            scenario,
            cells,
            planners,
            reference,
            instances,
            seed,
            primary,
            secondary,
            window,
        })
    }
}
