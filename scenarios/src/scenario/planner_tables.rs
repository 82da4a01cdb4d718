//! Each planner's own parameter tables in a scenario (`sim::planner_params`):
//! `[sim.planners.NAME]` and a vehicle's `driver = { planner = "NAME", params = { … } }`.
//!
//! The potential-field planners' tables (`pf`, alias `[sim.planner]`; `pf-iso`; `pf-sp`;
//! `planner::params_tables`) are views on the one `PlannerParams`: the loader merges them into
//! the scenario's `planner_overrides`, applied on top of the `--params` set. Any other name's
//! table stays in `sim.planners` for that planner's schema. A vehicle's `params` overlay its
//! planner's table for that vehicle alone (`sim::config::Driver::Planner::params`).

use std::collections::BTreeMap;
use std::sync::Arc;

use planner::params_tables::{self, PF_TABLE, PF_TABLES};
use sim::ParamsError;
use sim::config::Driver;
use sim::registry::BehaviourRegistry;

use super::{Line, Scenario, ScenarioError, ScenarioSource};
use crate::source_location::line_of;

fn path(parts: &[&str]) -> Vec<String> {
    parts.iter().map(|p| p.to_string()).collect()
}

fn invalid(
    origin: &str,
    text: Option<&str>,
    at: &[Vec<String>],
    field: String,
    message: String,
) -> ScenarioError {
    let line = text.and_then(|t| at.iter().find_map(|p| line_of(t, p)));
    ScenarioError::Invalid {
        origin: origin.to_string(),
        line: Line(line),
        message: format!("{field}: {message}"),
        field: Some(field),
    }
}

/// Checks the shape of every vehicle's `driver.params` in the untyped table: a table, beside a
/// planner (`driver = { planner = "NAME", params = { … } }` or a `[vehicles.driver.params]`
/// header); the error names the line and field. (The typed reading refuses these too, without
/// the field.)
pub(crate) fn check_driver_params(
    table: &toml::Table,
    text: &str,
    origin: &str,
) -> Result<(), ScenarioError> {
    let Some(vehicles) = table.get("vehicles").and_then(|v| v.as_array()) else {
        return Ok(());
    };
    for (i, vehicle) in vehicles.iter().enumerate() {
        let Some(driver) = vehicle.get("driver").and_then(|d| d.as_table()) else {
            continue;
        };
        let Some(params) = driver.get("params") else {
            continue;
        };
        let at = path(&["vehicles", &i.to_string(), "driver", "params"]);
        let field = format!("vehicles[#{i}].driver.params");
        if !params.is_table() {
            return Err(invalid(
                origin,
                Some(text),
                &[at],
                field,
                "must be a table of the planner's parameters".into(),
            ));
        }
        if !driver.get("planner").is_some_and(|p| p.is_str()) {
            return Err(invalid(
                origin,
                Some(text),
                &[at],
                field,
                "params go with a planner: driver = { planner = \"NAME\", params = { … } }".into(),
            ));
        }
    }
    Ok(())
}

impl Scenario {
    /// Moves the PF planners' tables (`[sim.planner]`, `[sim.planners.pf]`, `…pf-iso]`,
    /// `…pf-sp]`) into `planner_overrides`, refusing keys of another table, unknown keys and a
    /// key written twice; a table named after a PF planner that reads another table is refused
    /// naming that table.
    pub(crate) fn take_pf_tables(
        &mut self,
        table: &toml::Table,
        origin: &str,
        text: &str,
    ) -> Result<(), ScenarioError> {
        // `[sim.planner]`, the alias of `pf`: as before, every PlannerParams field (an unknown
        // key was refused by the typed reading).
        let mut overrides: toml::Table = table
            .get("sim")
            .and_then(|sim| sim.get("planner"))
            .and_then(|planner| planner.as_table())
            .cloned()
            .unwrap_or_default();
        let mut written_in: BTreeMap<String, Vec<String>> = overrides
            .keys()
            .map(|k| (k.clone(), path(&["sim", "planner", k])))
            .collect();
        let pf_names: Vec<String> = planner::PlannerKind::ALL
            .iter()
            .map(|k| k.name().to_string())
            .collect();
        for (name, keys) in &self.sim.planners {
            let at = |key: Option<&str>| {
                let mut p = path(&["sim", "planners", name]);
                p.extend(key.map(str::to_string));
                p
            };
            if PF_TABLES.contains(&name.as_str()) {
                for (key, value) in keys {
                    let field = format!("planners.{name}.{key}");
                    params_tables::check_key(name, key).map_err(|m| {
                        invalid(origin, Some(text), &[at(Some(key))], field.clone(), m)
                    })?;
                    if let Some(first) = written_in.get(key) {
                        let first_line = line_of(text, first)
                            .map(|l| format!(" (line {l})"))
                            .unwrap_or_default();
                        return Err(invalid(
                            origin,
                            Some(text),
                            &[at(Some(key))],
                            field,
                            format!(
                                "written twice: already in [{}]{first_line}",
                                first[..first.len() - 1].join(".")
                            ),
                        ));
                    }
                    written_in.insert(key.clone(), at(Some(key)));
                    overrides.insert(key.clone(), value.clone());
                }
            } else if let Some(kind) = pf_names
                .iter()
                .position(|n| n == name)
                .map(|i| planner::PlannerKind::ALL[i])
            {
                let own = params_tables::tables_of(kind);
                return Err(invalid(
                    origin,
                    Some(text),
                    &[at(None)],
                    format!("planners.{name}"),
                    format!(
                        "{name} reads the tables {}: write its parameters there",
                        own.iter()
                            .map(|t| format!("[sim.planners.{t}]"))
                            .collect::<Vec<_>>()
                            .join(" and ")
                    ),
                ));
            }
        }
        self.sim
            .planners
            .retain(|name, _| !PF_TABLES.contains(&name.as_str()));
        self.planner_overrides = overrides;
        Ok(())
    }

    /// The TOML path where PF field `key` is written: `[sim.planners.TABLE]` or the alias
    /// `[sim.planner]` (for error lines).
    pub(crate) fn pf_key_path(&self, key: &str) -> Vec<String> {
        let table = params_tables::table_of_field(key).unwrap_or(PF_TABLE);
        let new_form = path(&["sim", "planners", table, key]);
        match &self.source {
            Some(source) if line_of(&source.text, &new_form).is_some() => new_form,
            _ => path(&["sim", "planner", key]),
        }
    }

    /// A simulator field as the file wrote it: `planner.KEY` is `planners.TABLE.KEY` when the
    /// key is written in a `[sim.planners.TABLE]`.
    pub(crate) fn written_field(&self, field: String) -> String {
        match field.strip_prefix("planner.") {
            Some(key) => {
                let path = self.pf_key_path(key);
                if path[1] == "planners" {
                    format!("planners.{}.{key}", path[2])
                } else {
                    field
                }
            }
            None => field,
        }
    }

    /// Checks each planner's tables against its schema in `registry`: `[sim.planners.NAME]`
    /// and every vehicle's `driver.params` (overlaid on it). Refuses a table for a planner
    /// `registry` does not hold, keys the schema does not know, values out of range and any
    /// table for a planner registered without parameters; the error names the file, line and
    /// field. Run it before any work with the registry the run uses (the loader runs it with
    /// the built-in registry, skipping names it does not hold). It checks the scenario's
    /// vehicle models against `registry` too ([`Scenario::check_vehicle_models`]).
    pub fn check_planners(&self, registry: &BehaviourRegistry) -> Result<(), ScenarioError> {
        self.check_vehicle_models(registry)?;
        self.check_planner_tables(registry, false)
    }

    pub(crate) fn check_planner_tables(
        &self,
        registry: &BehaviourRegistry,
        skip_unknown: bool,
    ) -> Result<(), ScenarioError> {
        let origin = self
            .source
            .as_ref()
            .map(|s| s.origin.clone())
            .unwrap_or_else(|| self.name.clone());
        let text = self.source.as_ref().map(|s| s.text.as_str());
        let table_at = |name: &str, key: Option<&str>| {
            let mut p = path(&["sim", "planners", name]);
            p.extend(key.map(str::to_string));
            p
        };
        for name in self.sim.planners.keys() {
            if !registry.contains(name) {
                if skip_unknown {
                    continue;
                }
                return Err(invalid(
                    &origin,
                    text,
                    &[table_at(name, None)],
                    format!("planners.{name}"),
                    format!(
                        "no planner {name:?} is registered (registered: {})",
                        registry.names().join(", ")
                    ),
                ));
            }
            registry.parse_params(name, &self.sim, None).map_err(|e| {
                let key = e.key.clone();
                let mut at = vec![table_at(name, key.as_deref()), table_at(name, None)];
                at.dedup();
                let field = format!(
                    "planners.{name}{}",
                    key.map(|k| format!(".{k}")).unwrap_or_default()
                );
                invalid(&origin, text, &at, field, e.message)
            })?;
        }
        if !skip_unknown {
            self.check_driver_planner_names(registry, &origin, text)?;
        }
        for (i, vehicle) in self.vehicles.iter().enumerate() {
            let Driver::Planner {
                name,
                params: Some(own),
            } = &vehicle.driver
            else {
                continue;
            };
            let own_at = |key: Option<&str>| {
                let mut p = path(&["vehicles", &i.to_string(), "driver", "params"]);
                p.extend(key.map(str::to_string));
                p
            };
            let refused = |e: ParamsError| {
                let in_own = e.key.as_ref().is_some_and(|k| own.contains_key(k));
                let (at, field) = match (&e.key, in_own) {
                    (Some(k), true) => (
                        vec![own_at(Some(k)), own_at(None)],
                        format!("vehicles[{}].driver.params.{k}", vehicle.name),
                    ),
                    (Some(k), false) if self.sim.planners.contains_key(name) => (
                        vec![table_at(name, Some(k)), own_at(None)],
                        format!("planners.{name}.{k}"),
                    ),
                    (Some(k), false) => (
                        vec![self.pf_key_path(k), own_at(None)],
                        format!("vehicles[{}].driver.params.{k}", vehicle.name),
                    ),
                    (None, _) => (
                        vec![own_at(None)],
                        format!("vehicles[{}].driver.params", vehicle.name),
                    ),
                };
                invalid(
                    &origin,
                    text,
                    &at,
                    field,
                    format!("planner {name}: {}", e.message),
                )
            };
            if !registry.contains(name) {
                // The run refuses an unknown planner itself (`SimError::UnknownPlanner`).
                continue;
            }
            if let Some(kind) = registry.pf_kind(name) {
                for key in own.keys() {
                    params_tables::check_vehicle_key(kind, key)
                        .map_err(|m| refused(ParamsError::at(key.clone(), m)))?;
                }
            }
            registry
                .parse_params(name, &self.sim, Some(own))
                .map_err(refused)?;
        }
        Ok(())
    }

    /// Every vehicle's planner name (`driver = { planner = "NAME" }`) and prescribed driver's
    /// `path_planner` is in `registry`; an unknown name is refused with the file, line and
    /// field, as an unknown `[sim.planners.NAME]` table is. (The run would refuse it too, but
    /// without the line.)
    fn check_driver_planner_names(
        &self,
        registry: &BehaviourRegistry,
        origin: &str,
        text: Option<&str>,
    ) -> Result<(), ScenarioError> {
        for (i, vehicle) in self.vehicles.iter().enumerate() {
            let index = i.to_string();
            let (name, key, field) = match &vehicle.driver {
                Driver::Planner { name, .. } => (name, &["planner"][..], "driver.planner"),
                Driver::Prescribed { path_planner, .. } => (
                    path_planner,
                    &["prescribed", "path_planner"][..],
                    "driver.prescribed.path_planner",
                ),
                _ => continue,
            };
            if registry.contains(name) {
                continue;
            }
            let mut exact = path(&["vehicles", &index, "driver"]);
            exact.extend(key.iter().map(|k| k.to_string()));
            return Err(invalid(
                origin,
                text,
                &[
                    exact,
                    path(&["vehicles", &index, "driver"]),
                    path(&["vehicles", &index]),
                ],
                format!("vehicles[{}].{field}", vehicle.name),
                format!(
                    "unknown planner {name:?} (registered: {})",
                    registry.names().join(", ")
                ),
            ));
        }
        Ok(())
    }

    /// Records where the scenario came from (for the lines of later checks).
    pub(crate) fn set_source(&mut self, origin: &str, text: &str) {
        self.source = Some(Arc::new(ScenarioSource {
            origin: origin.to_string(),
            text: text.to_string(),
        }));
    }
}
