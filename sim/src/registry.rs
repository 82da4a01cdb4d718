//! Planners by name: the registry a scenario's `driver = { planner = "NAME" }`, `--planner NAME`
//! and a prescribed-speed driver's `path_planner` are looked up in.
//!
//! [`BehaviourRegistry::builtin`] holds the paper's planners (`pf-cs`, `pf-sp`, `pf-sp-eq10`,
//! `pf-iso`, `pf-iso-pred`) and merge sequencing `pf-iso-seq` (`planner::sequencing`, its
//! parameters `[sim.planners.pf-iso-seq]`). A user adds their own without editing any crate:
//!
//! ```
//! use std::sync::Arc;
//! use sim::registry::{BehaviourRegistry, FactoryInput};
//! use mergesim_types::{Behaviour, BehaviourError, Decision, Observation};
//!
//! struct Cruise;
//! impl Behaviour for Cruise {
//!     fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
//!         let v = obs.target_speed_mps;
//!         let path = (0..=10)
//!             .map(|i| mergesim_types::PathPoint {
//!                 x_m: obs.ego.x_m + 5.0 * i as f64,
//!                 y_m: obs.ego.y_m,
//!                 speed_mps: v,
//!                 t_s: obs.time_s + 5.0 * i as f64 / v,
//!             })
//!             .collect();
//!         Ok(Decision::follow(path))
//!     }
//! }
//!
//! let mut registry = BehaviourRegistry::builtin();
//! registry
//!     .register("cruise", Arc::new(|_: &FactoryInput<'_>| Ok(Box::new(Cruise) as Box<dyn Behaviour>)))
//!     .unwrap();
//! assert!(registry.names().contains(&"cruise"));
//! ```
//!
//! A planner with parameters registers its parameter type with
//! [`BehaviourRegistry::register_with_params`]: its `[sim.planners.NAME]` table, overlaid by a
//! vehicle's `driver = { planner = "NAME", params = { … } }`, is read into that type, checked
//! by its [`PlannerParameters::validate`] and handed to the factory (`crate::planner_params`).
//! A planner registered with [`BehaviourRegistry::register`] takes no parameters: a non-empty
//! table for it is refused, naming it.
//!
//! ```
//! use std::sync::Arc;
//! use sim::registry::{BehaviourRegistry, FactoryInput};
//! use sim::{ParamsError, PlannerParameters};
//! use mergesim_types::{Behaviour, BehaviourError, Decision, Observation};
//!
//! #[derive(Debug, Default, serde::Deserialize)]
//! #[serde(deny_unknown_fields, default)]
//! struct CruiseParams {
//!     /// Spacing of the path's points (m).
//!     spacing_m: f64,
//! }
//! impl PlannerParameters for CruiseParams {
//!     fn validate(&self) -> Result<(), ParamsError> {
//!         if self.spacing_m > 0.0 && self.spacing_m <= 50.0 {
//!             Ok(())
//!         } else {
//!             Err(ParamsError::at("spacing_m", "must lie in (0, 50] m"))
//!         }
//!     }
//! }
//! # struct Cruise(f64);
//! # impl Behaviour for Cruise {
//! #     fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
//! #         unimplemented!()
//! #     }
//! # }
//! let mut registry = BehaviourRegistry::builtin();
//! registry
//!     .register_with_params("cruise", |_: &FactoryInput<'_>, p: &CruiseParams| {
//!         Ok(Box::new(Cruise(p.spacing_m)) as Box<dyn Behaviour>)
//!     })
//!     .unwrap();
//! ```

use std::collections::BTreeMap;
use std::sync::Arc;

use planner::params::PlannerParams;
use planner::params_tables::{self, PF_TABLES};
use planner::sequencing::{SEQUENCED_PLANNER_NAME, SequencedPlanner, SequencingParams};
use planner::{PfPlanner, PlannerKind};

use crate::config::{SimConfig, VehicleSpec};
use crate::drivers::IdmDriver;
use crate::error::SimError;
use crate::planner_params::{
    ParamsError, ParamsTable, ParsedParams, PlannerParameters, overlay, parse_typed,
};
use crate::vehicle_models::VehicleModelRegistry;
use mergesim_types::Behaviour;

/// What a factory gets to build one vehicle's behaviour.
#[derive(Clone, Copy, Debug)]
pub struct FactoryInput<'a> {
    /// The run's settings (road, μ, planner parameters, …).
    pub config: &'a SimConfig,
    /// The vehicle.
    pub spec: &'a VehicleSpec,
    /// The road as lanes, built once per world (the road every `Observation::lanes` carries).
    pub lanes: &'a Arc<mergesim_types::lanes::LaneRoad>,
    /// The vehicle's planner parameters, parsed and validated by the planner's schema (module
    /// doc): a `P` for a planner registered with `register_with_params::<P>`; for a built-in PF
    /// planner a `planner::params::PlannerParams` when the vehicle has its own (`None`: the
    /// scenario's `config.planner`); `None` for a planner without parameters.
    pub params: Option<&'a (dyn std::any::Any + Send + Sync)>,
}

impl FactoryInput<'_> {
    /// The parameters as a `P` (None if there are none, or they are not a `P`).
    pub(crate) fn params_as<P: 'static>(&self) -> Option<&P> {
        self.params.and_then(|p| p.downcast_ref::<P>())
    }
}

/// Builds a behaviour for one vehicle.
pub type BehaviourFactory =
    Arc<dyn Fn(&FactoryInput<'_>) -> Result<Box<dyn Behaviour>, SimError> + Send + Sync>;

/// Reads a table into a planner's parameter type and validates it.
type ParseParams = Arc<dyn Fn(&ParamsTable) -> Result<ParsedParams, ParamsError> + Send + Sync>;

/// How a planner's parameter tables are read (module doc).
#[derive(Clone)]
enum Schema {
    /// Registered without parameters: any non-empty table is refused.
    None,
    /// A built-in potential-field planner: the tables are views on `PlannerParams`.
    Pf(PlannerKind),
    /// A user's parameter type.
    Typed(ParseParams),
}

/// Planner names → factories and parameter schemas (module doc). Names are kept sorted, so
/// listing them is deterministic.
///
/// It also carries the vehicle models the cars are spawned with
/// ([`crate::vehicle_models::VehicleModelRegistry`], the built-in ones unless
/// [`BehaviourRegistry::with_vehicle_models`] gives others), so that everything that takes a
/// registry (the CLI of `mergesim::cli::main_with`, sweeps, grids, studies) knows a user's
/// models too. Python's API builds its own registry (the built-ins and the planners registered
/// in Python), so it does not see a user's Rust registry.
#[derive(Clone)]
pub struct BehaviourRegistry {
    factories: BTreeMap<String, BehaviourFactory>,
    schemas: BTreeMap<String, Schema>,
    vehicle_models: VehicleModelRegistry,
}

impl Default for BehaviourRegistry {
    /// No planner; the built-in vehicle models.
    fn default() -> Self {
        Self {
            factories: BTreeMap::new(),
            schemas: BTreeMap::new(),
            vehicle_models: VehicleModelRegistry::builtin(),
        }
    }
}

impl std::fmt::Debug for BehaviourRegistry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BehaviourRegistry")
            .field("names", &self.names())
            .finish()
    }
}

/// The name under which the human driver model IDM + MOBIL (`driver = "idm-mobil"`) is also
/// registered as a planner, so that a study, a sweep or `--planner` can put it in place of the
/// planner-driven vehicles' planner: the baseline of a comparison, on the same instances. It
/// takes no planner parameters (its own are `[sim.idm]` and `[sim.mobil]`), shares no path over
/// V2V and is never shielded (`Behaviour::is_planner` is false).
pub const HUMAN_DRIVER_PLANNER_NAME: &str = "idm-mobil";

/// The factory of the IDM + MOBIL driver (`HUMAN_DRIVER_PLANNER_NAME`): the vehicle's start lane
/// and offset, the scenario's IDM and MOBIL parameters, exactly as `driver = "idm-mobil"`.
fn human_driver_factory() -> BehaviourFactory {
    Arc::new(|input: &FactoryInput<'_>| {
        Ok(Box::new(IdmDriver::for_vehicle(input.config, input.spec, true)) as Box<dyn Behaviour>)
    })
}

/// The factory of a potential-field planner of `kind`.
fn pf_factory(kind: PlannerKind) -> BehaviourFactory {
    Arc::new(move |input: &FactoryInput<'_>| {
        let params = input
            .params_as::<PlannerParams>()
            .unwrap_or(&input.config.planner)
            .clone();
        PfPlanner::new(kind, params, Arc::clone(input.lanes))
            .map(|p| match &input.spec.route {
                Some(route) => p.with_route(route),
                None => p,
            })
            .map(|p| Box::new(p) as Box<dyn Behaviour>)
            .map_err(|source| SimError::Planner {
                vehicle: input.spec.name.clone(),
                source,
            })
    })
}

impl BehaviourRegistry {
    /// A registry without planners (with the built-in vehicle models).
    pub fn new() -> Self {
        Self::default()
    }

    /// This registry with `models` as its vehicle models.
    pub fn with_vehicle_models(mut self, models: VehicleModelRegistry) -> Self {
        self.vehicle_models = models;
        self
    }

    /// The vehicle models cars are spawned with.
    pub fn vehicle_models(&self) -> &VehicleModelRegistry {
        &self.vehicle_models
    }

    /// Adds a vehicle model (`VehicleModelRegistry::register`).
    pub fn register_vehicle_model(
        &mut self,
        name: &str,
        description: &str,
        factory: crate::vehicle_models::VehicleModelFactory,
    ) -> Result<(), SimError> {
        self.vehicle_models.register(name, description, factory)
    }

    /// The paper's planners under their names (`PlannerKind::name`), merge sequencing
    /// (`pf-iso-seq`, with its own parameter type) and the IDM + MOBIL human driver
    /// (`idm-mobil`, [`HUMAN_DRIVER_PLANNER_NAME`]).
    pub fn builtin() -> Self {
        let mut registry = Self::new();
        for kind in PlannerKind::ALL {
            registry
                .factories
                .insert(kind.name().to_string(), pf_factory(kind));
            registry
                .schemas
                .insert(kind.name().to_string(), Schema::Pf(kind));
        }
        let sequenced: BehaviourFactory = Arc::new(|input: &FactoryInput<'_>| {
            let params = input
                .params_as::<SequencingParams>()
                .cloned()
                .unwrap_or_default();
            SequencedPlanner::new(
                input.config.planner.clone(),
                params,
                Arc::clone(input.lanes),
            )
            .map(|p| match &input.spec.route {
                Some(route) => p.with_inner(|inner| inner.with_route(route)),
                None => p,
            })
            .map(|p| Box::new(p) as Box<dyn Behaviour>)
            .map_err(|source| SimError::Planner {
                vehicle: input.spec.name.clone(),
                source,
            })
        });
        registry
            .factories
            .insert(SEQUENCED_PLANNER_NAME.to_string(), sequenced);
        registry.schemas.insert(
            SEQUENCED_PLANNER_NAME.to_string(),
            Schema::Typed(Arc::new(parse_typed::<SequencingParams>)),
        );
        registry.factories.insert(
            HUMAN_DRIVER_PLANNER_NAME.to_string(),
            human_driver_factory(),
        );
        registry
            .schemas
            .insert(HUMAN_DRIVER_PLANNER_NAME.to_string(), Schema::None);
        registry
    }

    /// Adds `factory` under `name`. Refuses an empty name, one with whitespace, commas or
    /// quotes, and a name already taken (a built-in cannot be replaced by accident).
    /// It takes no parameters: a non-empty `[sim.planners.NAME]` or `driver.params` table for it
    /// is refused.
    pub fn register(&mut self, name: &str, factory: BehaviourFactory) -> Result<(), SimError> {
        self.insert(name, factory, Schema::None)
    }

    /// Adds `factory` under `name` with its parameter type `P` (module doc): the factory gets
    /// the vehicle's parameters, `[sim.planners.NAME]` overlaid by its `driver.params`, read
    /// into a `P` and validated. Refuses names as [`BehaviourRegistry::register`] does.
    pub fn register_with_params<P, F>(&mut self, name: &str, factory: F) -> Result<(), SimError>
    where
        P: PlannerParameters,
        F: Fn(&FactoryInput<'_>, &P) -> Result<Box<dyn Behaviour>, SimError>
            + Send
            + Sync
            + 'static,
    {
        let planner = name.to_string();
        let wrapped: BehaviourFactory = Arc::new(move |input: &FactoryInput<'_>| {
            // `behaviour_of` always passes the parsed value; a caller building its own input
            // without one gets the table's defaults.
            match input.params_as::<P>() {
                Some(params) => factory(input, params),
                None => factory(input, &P::default()),
            }
            .map_err(|e| match e {
                SimError::InvalidScenario(message) => {
                    SimError::InvalidScenario(format!("planner {planner}: {message}"))
                }
                other => other,
            })
        });
        self.insert(name, wrapped, Schema::Typed(Arc::new(parse_typed::<P>)))
    }

    fn insert(
        &mut self,
        name: &str,
        factory: BehaviourFactory,
        schema: Schema,
    ) -> Result<(), SimError> {
        if name.is_empty() || name.contains(|c: char| c.is_whitespace() || c == ',' || c == '"') {
            return Err(SimError::InvalidField {
                field: "name".into(),
                message: format!(
                    "planner name {name:?} must be non-empty, without spaces, commas or quotes"
                ),
            });
        }
        if self.factories.contains_key(name) {
            return Err(SimError::InvalidField {
                field: "name".into(),
                message: format!("planner name {name:?} is already registered"),
            });
        }
        self.factories.insert(name.to_string(), factory);
        self.schemas.insert(name.to_string(), schema);
        Ok(())
    }

    /// The kind of a built-in potential-field planner registered as `name` (its tables are
    /// views on `PlannerParams`, `planner::params_tables`).
    pub fn pf_kind(&self, name: &str) -> Option<PlannerKind> {
        match self.schemas.get(name) {
            Some(Schema::Pf(kind)) => Some(*kind),
            _ => None,
        }
    }

    /// Whether `name` was registered with a parameter type (or is a built-in PF planner).
    pub fn has_params(&self, name: &str) -> bool {
        !matches!(self.schemas.get(name), None | Some(Schema::None))
    }

    /// The parameters of planner `name` for one vehicle: `[sim.planners.NAME]` of `config`
    /// overlaid by the vehicle's own `vehicle` table, read and checked by the planner's schema
    /// (module doc). `Ok(None)`: the planner takes none (or, for a PF planner, the vehicle has
    /// none of its own and uses `config.planner`). The error names the key; it is in
    /// `vehicle` if that table holds it, else in the scenario's table.
    pub fn parse_params(
        &self,
        name: &str,
        config: &SimConfig,
        vehicle: Option<&ParamsTable>,
    ) -> Result<Option<ParsedParams>, ParamsError> {
        let scenario = config.planners.get(name);
        match self.schemas.get(name).unwrap_or(&Schema::None) {
            Schema::None => {
                let written = overlay(scenario, vehicle);
                match written.keys().next() {
                    None => Ok(None),
                    Some(key) if name == HUMAN_DRIVER_PLANNER_NAME => Err(ParamsError::at(
                        key.clone(),
                        format!(
                            "planner {name} takes no planner parameters: the human driver's \
                             are [sim.idm] and [sim.mobil]"
                        ),
                    )),
                    Some(key) => Err(ParamsError::at(
                        key.clone(),
                        format!(
                            "planner {name} takes no parameters (it was registered without a \
                             parameter type: register it with register_with_params)"
                        ),
                    )),
                }
            }
            Schema::Typed(parse) => parse(&overlay(scenario, vehicle)).map(Some),
            Schema::Pf(_) => {
                // The PF tables a program may put in `planners` (the loader merges them into
                // `config.planner`), then the vehicle's keys: all views on one PlannerParams.
                let mut keys = ParamsTable::new();
                for table_name in PF_TABLES {
                    if let Some(table) = config.planners.get(table_name) {
                        for key in table.keys() {
                            params_tables::check_key(table_name, key)
                                .map_err(|m| ParamsError::at(key.clone(), m))?;
                        }
                        keys = overlay(Some(&keys), Some(table));
                    }
                }
                for key in vehicle.into_iter().flat_map(|v| v.keys()) {
                    // Any PF field: under `--planner` a vehicle's values go with it to another
                    // PF planner (its own table's keys then have no effect there).
                    if params_tables::table_of_field(key).is_none() {
                        return Err(ParamsError::at(
                            key.clone(),
                            params_tables::check_key(params_tables::PF_TABLE, key)
                                .err()
                                .unwrap_or_default(),
                        ));
                    }
                }
                let keys = overlay(Some(&keys), vehicle);
                if keys.is_empty() {
                    return Ok(None);
                }
                pf_params_with(&config.planner, &keys).map(|p| Some(Arc::new(p) as ParsedParams))
            }
        }
    }

    /// Every registered name, sorted.
    pub fn names(&self) -> Vec<&str> {
        self.factories.keys().map(String::as_str).collect()
    }

    /// Whether `name` is registered.
    pub fn contains(&self, name: &str) -> bool {
        self.factories.contains_key(name)
    }

    /// The behaviour `name` for one vehicle.
    pub fn create(
        &self,
        name: &str,
        input: &FactoryInput<'_>,
    ) -> Result<Box<dyn Behaviour>, SimError> {
        let factory = self
            .factories
            .get(name)
            .ok_or_else(|| SimError::UnknownPlanner {
                vehicle: input.spec.name.clone(),
                name: name.to_string(),
                valid: self.names().join(", "),
            })?;
        factory(input)
    }
}

impl PlannerParameters for SequencingParams {
    fn validate(&self) -> Result<(), ParamsError> {
        SequencingParams::validate(self).map_err(|e| ParamsError {
            key: e.invalid_parameter().map(|p| p.name.clone()),
            message: e.to_string(),
        })
    }
}

/// `base` with the values of `keys` on top, validated; the error names the key.
pub fn pf_params_with(
    base: &PlannerParams,
    keys: &ParamsTable,
) -> Result<PlannerParams, ParamsError> {
    let mut table = ParamsTable::try_from(base).map_err(|e| ParamsError {
        key: None,
        message: e.to_string(),
    })?;
    for (key, value) in keys {
        table.insert(key.clone(), value.clone());
    }
    let params: PlannerParams =
        toml::Value::Table(table.clone())
            .try_into()
            .map_err(|e: toml::de::Error| {
                let message = e.message().trim_end().to_string();
                ParamsError {
                    key: crate::planner_params::key_in_message(&message, keys).or_else(|| {
                        crate::planner_params::fault_key::<PlannerParams>(&table, keys)
                    }),
                    message,
                }
            })?;
    params.validate().map_err(|e| {
        let field = e
            .invalid_parameter()
            .map(|p| p.name.trim_start_matches("planner.").to_string());
        ParamsError {
            key: field,
            message: e.to_string(),
        }
    })?;
    Ok(params)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_names_are_the_planner_kinds_and_duplicates_are_refused() {
        let mut registry = BehaviourRegistry::builtin();
        let mut expected: Vec<&str> = PlannerKind::ALL.iter().map(|k| k.name()).collect();
        expected.push(SEQUENCED_PLANNER_NAME);
        expected.push(HUMAN_DRIVER_PLANNER_NAME);
        expected.sort_unstable();
        assert_eq!(registry.names(), expected);
        let factory = pf_factory(PlannerKind::PfCs);
        assert!(registry.register("pf-iso", factory.clone()).is_err());
        assert!(registry.register("my planner", factory.clone()).is_err());
        assert!(registry.register("", factory.clone()).is_err());
        registry.register("mine", factory).unwrap();
        assert!(registry.contains("mine"));
    }
}
