//! Each planner's own parameters: the tables a scenario writes for it (`[sim.planners.NAME]`
//! and a vehicle's `driver = { planner = "NAME", params = { … } }`, which overlays the former
//! key by key) and the schema it was registered with (`crate::registry`).
//!
//! A planner registered with [`BehaviourRegistry::register_with_params`] names its parameter
//! type `P: PlannerParameters`: its tables are read into a `P` (unknown keys refused if `P`
//! says `#[serde(deny_unknown_fields)]`; missing keys take `P::default()`'s values if `P` says
//! `#[serde(default)]`), checked by [`PlannerParameters::validate`], and the value reaches its
//! factory. A planner registered without a type refuses any non-empty table. The built-in
//! potential-field planners read their tables into the one `planner::params::PlannerParams`
//! (`planner::params_tables`).
//!
//! [`BehaviourRegistry::register_with_params`]: crate::registry::BehaviourRegistry::register_with_params

use std::any::Any;
use std::sync::Arc;

use serde::de::DeserializeOwned;

/// A planner's parameter table as written (TOML keys and values).
pub type ParamsTable = toml::Table;

/// A planner's parsed and validated parameters, of the type it registered with.
pub(crate) type ParsedParams = Arc<dyn Any + Send + Sync>;

/// A planner's parameter type (`BehaviourRegistry::register_with_params`).
pub trait PlannerParameters: DeserializeOwned + Default + Send + Sync + 'static {
    /// Checks the ranges of the values; the error names the key.
    fn validate(&self) -> Result<(), ParamsError> {
        Ok(())
    }
}

/// Why a planner's parameter table was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{message}", key.as_ref().map(|k| format!("{k}: ")).unwrap_or_default())]
pub struct ParamsError {
    /// The key at fault (top-level key of the table), when there is one.
    pub key: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl ParamsError {
    /// An error about `key`.
    pub fn at(key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            key: Some(key.into()),
            message: message.into(),
        }
    }
}

/// `top` over `base`, key by key (a key of `top` replaces the same key of `base` whole).
pub(crate) fn overlay(base: Option<&ParamsTable>, top: Option<&ParamsTable>) -> ParamsTable {
    let mut table = base.cloned().unwrap_or_default();
    for (key, value) in top.into_iter().flatten() {
        table.insert(key.clone(), value.clone());
    }
    table
}

/// The key a serde error message names (`unknown field `x``, `missing field `x``, `… for key
/// `x``), if any.
pub(crate) fn key_in_message(message: &str, table: &ParamsTable) -> Option<String> {
    for marker in ["unknown field `", "missing field `", "for key `"] {
        if let Some(rest) = message.split(marker).nth(1)
            && let Some(key) = rest.split('`').next()
        {
            return Some(key.rsplit('.').next().unwrap_or(key).to_string());
        }
    }
    // A wrong type: serde names no key, but the toml reader may mention one of the table's.
    table
        .keys()
        .find(|k| message.contains(&format!("`{k}`")))
        .cloned()
}

/// The key of `written` whose value `T` cannot read (`table` = `written` on top of any base):
/// the first whose removal lets `table` be read (a wrong type names no key in serde's message).
pub(crate) fn fault_key<T: DeserializeOwned>(
    table: &ParamsTable,
    written: &ParamsTable,
) -> Option<String> {
    written.keys().find_map(|key| {
        let mut without = table.clone();
        without.remove(key);
        toml::Value::Table(without)
            .try_into::<T>()
            .is_ok()
            .then(|| key.clone())
    })
}

/// Reads `table` into a `P` and validates it.
pub(crate) fn parse_typed<P: PlannerParameters>(
    table: &ParamsTable,
) -> Result<ParsedParams, ParamsError> {
    let value: P = if table.is_empty() {
        P::default()
    } else {
        toml::Value::Table(table.clone())
            .try_into()
            .map_err(|e: toml::de::Error| {
                let message = e.message().trim_end().to_string();
                ParamsError {
                    key: key_in_message(&message, table).or_else(|| fault_key::<P>(table, table)),
                    message,
                }
            })?
    };
    value.validate()?;
    Ok(Arc::new(value))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Default, serde::Deserialize)]
    #[serde(deny_unknown_fields, default)]
    struct Gains {
        gain: f64,
    }
    impl PlannerParameters for Gains {
        fn validate(&self) -> Result<(), ParamsError> {
            if (0.0..=10.0).contains(&self.gain) {
                Ok(())
            } else {
                Err(ParamsError::at(
                    "gain",
                    format!("{} is outside [0, 10]", self.gain),
                ))
            }
        }
    }

    fn table(text: &str) -> ParamsTable {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn typed_tables_are_read_checked_and_their_faults_name_the_key() {
        let parsed = parse_typed::<Gains>(&table("gain = 2.5")).unwrap();
        assert_eq!(parsed.downcast_ref::<Gains>().unwrap().gain, 2.5);
        let empty = parse_typed::<Gains>(&ParamsTable::new()).unwrap();
        assert_eq!(empty.downcast_ref::<Gains>().unwrap().gain, 0.0);
        let e = parse_typed::<Gains>(&table("gian = 1.0")).unwrap_err();
        assert_eq!(e.key.as_deref(), Some("gian"), "{e}");
        let e = parse_typed::<Gains>(&table("gain = 11.0")).unwrap_err();
        assert_eq!(e.key.as_deref(), Some("gain"), "{e}");
        let e = parse_typed::<Gains>(&table("gain = \"high\"")).unwrap_err();
        assert_eq!(e.key.as_deref(), Some("gain"), "{e}");
    }

    #[test]
    fn a_vehicles_table_overlays_the_scenarios_key_by_key() {
        let merged = overlay(Some(&table("a = 1\nb = 2")), Some(&table("b = 3")));
        assert_eq!(merged, table("a = 1\nb = 3"));
    }
}
