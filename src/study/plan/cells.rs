//! The cells of a study plan: `[factors]` (a full factorial) or `[[cells]]` (listed), each
//! factor a dotted path into the scenario's TOML (`sim.mu`, `sim.planner.<parameter>`,
//! `vehicles.<name>.<field>`, `params`), applied to the scenario's text and checked by the
//! scenario loader, so a cell's scenario is exactly what a scenario file with those values
//! would be.

use std::collections::BTreeMap;

use scenarios::scenario::Scenario;
use scenarios::source_location::line_of;

use super::{Cell, PlanError, RawPlan};

/// One factor and its levels, with where the plan writes it.
struct Factor {
    name: String,
    at: Vec<String>,
    levels: Vec<toml::Value>,
}

/// The cells as (factor name, TOML path of the value in the plan, value) lists.
pub(super) type Design = Vec<Vec<(String, Vec<String>, toml::Value)>>;

/// `[factors]` (full factorial) or `[[cells]]` (listed), as designs of factor values.
pub(super) fn factor_levels(
    raw: &RawPlan,
    invalid: &dyn Fn(&[&str], &str, String) -> PlanError,
) -> Result<Design, PlanError> {
    match (&raw.factors, &raw.cells) {
        (Some(_), Some(_)) => Err(invalid(
            &["cells"],
            "cells",
            "give either [factors] (a full factorial) or [[cells]] (listed cells), not both".into(),
        )),
        (None, None) => Ok(vec![Vec::new()]),
        (Some(table), None) => {
            let mut factors = Vec::new();
            flatten(
                table,
                &mut vec!["factors".into()],
                "",
                &mut |name, at, value| match value {
                    toml::Value::Array(levels) => {
                        factors.push(Factor {
                            name,
                            at,
                            levels: levels.clone(),
                        });
                        Ok(())
                    }
                    other => Err((
                        at,
                        name.clone(),
                        format!("{other}: a factor's levels are a list, e.g. [0.8, 0.5]"),
                    )),
                },
            )
            .map_err(|(at, name, m)| {
                invalid(
                    &at.iter().map(String::as_str).collect::<Vec<_>>(),
                    &format!("factors.{name}"),
                    m,
                )
            })?;
            for f in &factors {
                if f.levels.is_empty() {
                    return Err(invalid(
                        &f.at.iter().map(String::as_str).collect::<Vec<_>>(),
                        &format!("factors.{}", f.name),
                        "an empty level list: give at least one level".into(),
                    ));
                }
            }
            let mut design: Design = vec![Vec::new()];
            for f in &factors {
                let mut next = Vec::with_capacity(design.len() * f.levels.len());
                for cell in &design {
                    for (i, level) in f.levels.iter().enumerate() {
                        let mut at = f.at.clone();
                        at.push(i.to_string());
                        let mut c = cell.clone();
                        c.push((f.name.clone(), at, level.clone()));
                        next.push(c);
                    }
                }
                design = next;
            }
            Ok(design)
        }
        (None, Some(cells)) => {
            if cells.is_empty() {
                return Err(invalid(
                    &["cells"],
                    "cells",
                    "an empty list of cells".into(),
                ));
            }
            let mut design = Vec::new();
            for (i, table) in cells.iter().enumerate() {
                let mut cell = Vec::new();
                flatten(
                    table,
                    &mut vec!["cells".into(), i.to_string()],
                    "",
                    &mut |name, at, value| {
                        cell.push((name, at, value.clone()));
                        Ok(())
                    },
                )
                .map_err(|(at, name, m)| {
                    invalid(
                        &at.iter().map(String::as_str).collect::<Vec<_>>(),
                        &format!("cells.{i}.{name}"),
                        m,
                    )
                })?;
                design.push(cell);
            }
            Ok(design)
        }
    }
}

type FlattenError = (Vec<String>, String, String);

/// What [`flatten`] calls for each leaf: (dotted name, TOML path in the plan, value).
type Visitor<'a> = dyn FnMut(String, Vec<String>, &toml::Value) -> Result<(), FlattenError> + 'a;

/// Visits the leaves of `table` as dotted names (`sim.mu` written quoted or as nested keys).
fn flatten(
    table: &toml::Table,
    at: &mut Vec<String>,
    prefix: &str,
    visit: &mut Visitor<'_>,
) -> Result<(), FlattenError> {
    for (key, value) in table {
        let name = if prefix.is_empty() {
            key.clone()
        } else {
            format!("{prefix}.{key}")
        };
        at.push(key.clone());
        match value {
            toml::Value::Table(inner) => flatten(inner, at, &name, visit)?,
            _ => visit(name, at.clone(), value)?,
        }
        at.pop();
    }
    Ok(())
}

/// Applies each cell's values to the scenario and checks the result (an unknown factor or a
/// value out of range names the plan's line).
pub(super) fn resolve_cells(
    scenario: &Scenario,
    design: Design,
    origin: &str,
    text: &str,
) -> Result<Vec<(Cell, Scenario)>, PlanError> {
    let full = toml::Table::try_from(scenario).map_err(|e| PlanError::Parse {
        origin: origin.into(),
        message: e.to_string(),
    })?;
    let base_text = scenario.to_toml().map_err(|e| PlanError::Parse {
        origin: origin.into(),
        message: e.to_string(),
    })?;
    let base: toml::Table = toml::from_str(&base_text).map_err(|e| PlanError::Parse {
        origin: origin.into(),
        message: e.to_string(),
    })?;
    let mut cells = Vec::with_capacity(design.len());
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut checked: std::collections::BTreeSet<(String, String)> = Default::default();
    for (index, values) in design.into_iter().enumerate() {
        let mut table = base.clone();
        let mut labels = Vec::new();
        for (name, at, value) in &values {
            let error = |message: String| PlanError::Invalid {
                origin: origin.into(),
                line: line_of(text, at),
                field: format!("{}.{name}", at[0]),
                message,
            };
            let path = scenario_path(scenario, name);
            if !has_path(&full, &path) {
                return Err(error(format!(
                    "unknown factor {name:?}: not a value of scenario {} (a dotted path into \
                     `merge_sim scenario show {}`: e.g. sim.mu, sim.planner.<parameter>, \
                     vehicles.<name>.<field>, params)",
                    scenario.name, scenario.name
                )));
            }
            set_path(&mut table, &path, value.clone());
            labels.push((name.clone(), value.to_string()));
        }
        let cell = Cell {
            index,
            values: labels,
        };
        let label = cell.label();
        if let Some(first) = seen.insert(label.clone(), index) {
            let (_, at, _) = &values[0];
            return Err(PlanError::Invalid {
                origin: origin.into(),
                line: line_of(text, at),
                field: "cells".into(),
                message: format!("cell {index} ({label}) repeats cell {first}"),
            });
        }
        // Each value alone on the scenario first, so a value out of range names its own line.
        for (name, at, value) in &values {
            if !checked.insert((name.clone(), value.to_string())) {
                continue;
            }
            let mut alone = base.clone();
            set_path(&mut alone, &scenario_path(scenario, name), value.clone());
            let alone_text = toml::to_string(&alone).map_err(|e| PlanError::Parse {
                origin: origin.into(),
                message: e.to_string(),
            })?;
            Scenario::from_toml(
                &alone_text,
                &format!("{} with {name} = {value}", scenario.name),
            )
            .map_err(|e| PlanError::Invalid {
                origin: origin.into(),
                line: line_of(text, at),
                field: format!("{}.{name}", at[0]),
                message: format!("{name} = {value}: {e}"),
            })?;
        }
        let cell_text = toml::to_string(&table).map_err(|e| PlanError::Parse {
            origin: origin.into(),
            message: e.to_string(),
        })?;
        let cell_scenario =
            Scenario::from_toml(&cell_text, &format!("{} in cell {label}", scenario.name))
                .map_err(|e| {
                    let at = values
                        .first()
                        .map(|(_, at, _)| at.clone())
                        .unwrap_or_default();
                    PlanError::Invalid {
                        origin: origin.into(),
                        line: line_of(text, &at),
                        field: values.first().map_or_else(
                            || "scenario".into(),
                            |(name, at, _)| format!("{}.{name}", at[0]),
                        ),
                        message: format!("cell {index} ({label}): {e}"),
                    }
                })?;
        cells.push((cell, cell_scenario));
    }
    Ok(cells)
}

/// A factor's name as a path in the scenario's TOML table (`vehicles.<name>.x` → the index of
/// that vehicle).
fn scenario_path(scenario: &Scenario, name: &str) -> Vec<String> {
    let parts: Vec<String> = name.split('.').map(str::to_string).collect();
    if parts.first().map(String::as_str) == Some("vehicles")
        && let Some(vehicle) = parts.get(1)
        && let Some(index) = scenario.vehicles.iter().position(|v| &v.name == vehicle)
    {
        let mut path = vec!["vehicles".to_string(), index.to_string()];
        path.extend(parts[2..].iter().cloned());
        return path;
    }
    parts
}

fn has_path(table: &toml::Table, path: &[String]) -> bool {
    let mut current: Option<&toml::Value> = None;
    for (i, segment) in path.iter().enumerate() {
        let next = match (i, current) {
            (0, _) => table.get(segment),
            (_, Some(toml::Value::Table(t))) => t.get(segment),
            (_, Some(toml::Value::Array(a))) => {
                segment.parse::<usize>().ok().and_then(|k| a.get(k))
            }
            _ => None,
        };
        match next {
            Some(v) => current = Some(v),
            None => return false,
        }
    }
    // A factor sets a value, not a whole table; but a `driver` (a vehicle's, a `[traffic]`
    // stream's) is one value whose planner form is a table (`{ planner = "pf-iso" }`).
    match current {
        None => false,
        Some(toml::Value::Table(_)) => path.last().is_some_and(|key| key == "driver"),
        Some(_) => true,
    }
}

fn set_path(table: &mut toml::Table, path: &[String], value: toml::Value) {
    let Some((first, rest)) = path.split_first() else {
        return;
    };
    if rest.is_empty() {
        table.insert(first.clone(), value);
        return;
    }
    let entry = table
        .entry(first.clone())
        .or_insert_with(|| toml::Value::Table(toml::Table::new()));
    set_in_value(entry, rest, value);
}

fn set_in_value(target: &mut toml::Value, path: &[String], value: toml::Value) {
    match target {
        toml::Value::Table(t) => set_path(t, path, value),
        toml::Value::Array(a) => {
            let Some((first, rest)) = path.split_first() else {
                return;
            };
            let Some(element) = first.parse::<usize>().ok().and_then(|k| a.get_mut(k)) else {
                return;
            };
            if rest.is_empty() {
                *element = value;
            } else {
                set_in_value(element, rest, value);
            }
        }
        _ => {}
    }
}
