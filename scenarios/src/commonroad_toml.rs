//! A scenario TOML on a CommonRoad road: `[sim.road]` holds `commonroad = "path.xml"`
//! (relative to the TOML) and optionally `recorded_traffic = "none" | "replay" | "reactive"`
//! (default `replay`) instead of the straight road's values. The loader reads the TOML without
//! those two keys (their lines are commented out, so every other line keeps its number), then
//! sets the road source `[sim.lane_road] commonroad` and fills the recorded traffic from the
//! file's obstacles (times from the file's time 0). The file's planning problems are not used:
//! the TOML places its own vehicles (`lanelet`, `s_m`, `d_m`, read as `lane`, `x_m`,
//! `y_offset_m`).

use std::path::Path;

use sim::recorded_traffic::TrafficMode;
use sim::road_config::{CommonRoadRoad, LaneRoadConfig};

use crate::scenario::{Line, Scenario, ScenarioError};
use crate::source_location::line_of;

/// `[sim.road] commonroad = …` as found in a TOML text.
#[derive(Clone, Debug)]
pub(crate) struct RoadSource {
    /// The path as written.
    file: String,
    /// The recorded traffic's mode.
    mode: TrafficMode,
    /// The text without the two keys (their lines commented out).
    pub(crate) stripped_text: String,
}

const KEYS: [&str; 2] = ["commonroad", "recorded_traffic"];

fn path_of(keys: &[&str]) -> Vec<String> {
    keys.iter().map(|k| k.to_string()).collect()
}

/// The CommonRoad road source of a TOML scenario, if `[sim.road]` has `commonroad`.
pub(crate) fn road_source(
    table: &toml::Table,
    text: &str,
    origin: &str,
) -> Result<Option<RoadSource>, ScenarioError> {
    let Some(road) = table
        .get("sim")
        .and_then(|s| s.get("road"))
        .and_then(|r| r.as_table())
    else {
        return Ok(None);
    };
    let Some(file) = road.get("commonroad") else {
        if road.contains_key("recorded_traffic") {
            return Err(invalid(
                origin,
                text,
                &["sim", "road", "recorded_traffic"],
                "road.recorded_traffic".into(),
                "recorded_traffic needs a CommonRoad road ([sim.road] commonroad = \"file.xml\")"
                    .into(),
            ));
        }
        return Ok(None);
    };
    fn at(key: &str) -> [&str; 3] {
        ["sim", "road", key]
    }
    let Some(file) = file.as_str() else {
        return Err(invalid(
            origin,
            text,
            &at("commonroad"),
            "road.commonroad".into(),
            "road.commonroad must be the path of a CommonRoad XML file (a string)".into(),
        ));
    };
    let mode = match road.get("recorded_traffic") {
        None => TrafficMode::default(),
        Some(v) => match v.as_str() {
            Some("none") => TrafficMode::None,
            Some("replay") => TrafficMode::Replay,
            Some("reactive") => TrafficMode::Reactive,
            _ => {
                return Err(invalid(
                    origin,
                    text,
                    &at("recorded_traffic"),
                    "road.recorded_traffic".into(),
                    format!(
                        "road.recorded_traffic = {v}: must be \"none\", \"replay\" or \"reactive\""
                    ),
                ));
            }
        },
    };
    if let Some(other) = road.keys().find(|k| !KEYS.contains(&k.as_str())) {
        return Err(invalid(
            origin,
            text,
            &at(other),
            format!("road.{other}"),
            format!(
                "road.{other}: with road.commonroad, [sim.road] takes only commonroad and \
                 recorded_traffic (the road is the file's lanelet network)"
            ),
        ));
    }
    if table
        .get("sim")
        .is_some_and(|s| s.get("lane_road").is_some())
    {
        return Err(invalid(
            origin,
            text,
            &["sim", "lane_road"],
            "lane_road".into(),
            "[sim.road] commonroad and [sim.lane_road] both give the road: keep one".into(),
        ));
    }
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    for key in KEYS {
        if !road.contains_key(key) {
            continue;
        }
        let line = line_of(text, &path_of(&at(key)));
        let own_line = line
            .and_then(|l| lines.get(l - 1))
            .is_some_and(|l| l.trim_start().starts_with(key));
        let (Some(line), true) = (line, own_line) else {
            return Err(invalid(
                origin,
                text,
                &at(key),
                format!("road.{key}"),
                format!("write road.{key} on its own line in a [sim.road] table"),
            ));
        };
        lines[line - 1] = format!("# {}", lines[line - 1]);
    }
    Ok(Some(RoadSource {
        file: file.to_string(),
        mode,
        stripped_text: lines.join("\n"),
    }))
}

fn invalid(
    origin: &str,
    text: &str,
    path: &[&str],
    field: String,
    message: String,
) -> ScenarioError {
    ScenarioError::Invalid {
        origin: origin.to_string(),
        line: Line(line_of(text, &path_of(path))),
        field: Some(field),
        message,
    }
}

/// Reads the file of `source` (relative to `base`) and makes it the scenario's road, with its
/// obstacles as recorded traffic.
pub(crate) fn apply(
    scenario: &mut Scenario,
    source: &RoadSource,
    base: Option<&Path>,
) -> Result<(), ScenarioError> {
    let written = Path::new(&source.file);
    let path = match base {
        Some(dir) if written.is_relative() => dir.join(written),
        _ => written.to_path_buf(),
    };
    let (cr, _lanes) = mergesim_commonroad::read_with_road(&path)?;
    let file = crate::commonroad::absolute(&path);
    scenario.sim.recorded_traffic =
        crate::commonroad::recorded_traffic(&path, &cr, source.mode, 0.0)?;
    scenario.sim.lane_road = Some(LaneRoadConfig {
        commonroad: Some(CommonRoadRoad::of(file, source.mode, &cr)),
        ..LaneRoadConfig::default()
    });
    Ok(())
}

/// Reads the file of a `[sim.lane_road] commonroad = { file = …, recorded_traffic = … }`
/// source (relative to `base`): keeps its lanes and fills the recorded traffic.
pub(crate) fn read_lane_road_source(
    scenario: &mut Scenario,
    base: Option<&Path>,
) -> Result<(), ScenarioError> {
    let Some(road) = scenario
        .sim
        .lane_road
        .as_mut()
        .and_then(|c| c.commonroad.as_mut())
    else {
        return Ok(());
    };
    let path = match base {
        Some(dir) if road.file.is_relative() => dir.join(&road.file),
        _ => road.file.clone(),
    };
    let (cr, _lanes) = mergesim_commonroad::read_with_road(&path)?;
    let mode = road.recorded_traffic;
    *road = CommonRoadRoad::of(crate::commonroad::absolute(&path), mode, &cr);
    scenario.sim.recorded_traffic = crate::commonroad::recorded_traffic(&path, &cr, mode, 0.0)?;
    Ok(())
}

/// A refusal naming a vehicle field by the name the TOML wrote (`lanelet`, `s_m`, `d_m` for
/// `lane`, `x_m`, `y_offset_m`), at that key's line.
pub(crate) fn aliased(
    e: ScenarioError,
    scenario: &Scenario,
    table: &toml::Table,
    text: &str,
) -> ScenarioError {
    let ScenarioError::Invalid {
        origin,
        line,
        field: Some(field),
        message,
    } = e
    else {
        return e;
    };
    let renamed = (|| {
        let rest = field.strip_prefix("vehicles[")?;
        let (name, key) = rest.split_once("].")?;
        let alias = match key {
            "lane" => "lanelet",
            "x_m" => "s_m",
            "y_offset_m" => "d_m",
            _ => return None,
        };
        let index = scenario.vehicles.iter().position(|v| v.name == name)?;
        let written = table
            .get("vehicles")?
            .get(index)?
            .as_table()?
            .contains_key(alias);
        written.then(|| {
            let path = vec!["vehicles".to_string(), index.to_string(), alias.to_string()];
            (
                format!("vehicles[{name}].{key}"),
                format!("vehicles[{name}].{alias}"),
                line_of(text, &path),
            )
        })
    })();
    match renamed {
        Some((old, new, new_line)) => ScenarioError::Invalid {
            origin,
            line: Line(new_line.or(line.0)),
            message: message.replace(&old, &new),
            field: Some(new),
        },
        None => ScenarioError::Invalid {
            origin,
            line,
            field: Some(field),
            message,
        },
    }
}
