//! Where a scenario comes from: a built-in name, a path, or TOML text; optionally with a table
//! of overrides merged over it (`params=` in Python).

use scenarios::scenario::Scenario;
use scenarios::{builtin, scenario::MAX_SCENARIO_BYTES};

use crate::errors::BindingError;

/// Loads `source` as `merge_sim --scenario` does, or parses it as TOML text if it has a line
/// break; `overrides_json` (a JSON object) is merged over the scenario's TOML tables first.
pub(crate) fn load(source: &str, overrides_json: Option<&str>) -> Result<Scenario, BindingError> {
    let is_text = source.contains('\n');
    let Some(overrides_json) = overrides_json else {
        return if is_text {
            Scenario::from_toml(source, "<string>").map_err(|e| BindingError::input(&e))
        } else {
            Scenario::load(source).map_err(|e| BindingError::input(&e))
        };
    };
    let (text, origin) = if is_text {
        (source.to_string(), "<string>".to_string())
    } else if let Some(text) = builtin::toml_of(source) {
        (text.to_string(), format!("built-in {source}"))
    } else if source.to_ascii_lowercase().ends_with(".xml") {
        // A CommonRoad file: the scenario built from it, as TOML (its road source
        // `[sim.lane_road.commonroad]` holds the file and the recorded traffic's mode, which
        // overrides can set).
        let scenario = Scenario::load(source).map_err(|e| BindingError::input(&e))?;
        let text = scenario.to_toml().map_err(|e| BindingError::input(&e))?;
        (text, source.to_string())
    } else {
        // The same errors as the CLI for a missing or unreadable file.
        Scenario::load(source).map_err(|e| BindingError::input(&e))?;
        let path = std::path::Path::new(source);
        let text = mergesim_types::files::read_regular_text(path, MAX_SCENARIO_BYTES)
            .map_err(|e| BindingError::input(&e))?;
        (text, path.display().to_string())
    };
    let merged = merge_overrides(&text, &origin, overrides_json)?;
    Scenario::from_toml(&merged, &format!("{origin} with params"))
        .map_err(|e| BindingError::input(&e))
}

/// The TOML `text` with the JSON object `overrides_json` merged over it: tables are merged key by
/// key, recursively; any other value (numbers, strings, arrays such as `vehicles`) replaces the
/// scenario's.
pub(crate) fn merge_overrides(
    text: &str,
    origin: &str,
    overrides_json: &str,
) -> Result<String, BindingError> {
    let mut table: toml::Table = toml::from_str(text)
        .map_err(|e| BindingError::Input(format!("{origin}: {}", e.to_string().trim_end())))?;
    let overrides: serde_json::Value = serde_json::from_str(overrides_json)
        .map_err(|e| BindingError::Input(format!("params: {e}")))?;
    let overrides = toml::Value::try_from(overrides).map_err(|e| {
        BindingError::Input(format!(
            "params: not representable in TOML (null values are not): {e}"
        ))
    })?;
    let toml::Value::Table(overrides) = overrides else {
        return Err(BindingError::Input(
            "params: must be a dict of the scenario's tables and keys".into(),
        ));
    };
    merge_table(&mut table, overrides);
    toml::to_string(&table).map_err(|e| BindingError::Input(format!("params: {e}")))
}

fn merge_table(base: &mut toml::Table, overrides: toml::Table) {
    for (key, value) in overrides {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(inner)), toml::Value::Table(over)) => merge_table(inner, over),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}
