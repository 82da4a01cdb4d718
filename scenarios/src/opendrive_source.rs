//! A scenario TOML on an OpenDRIVE road: `[sim.lane_road] opendrive = { file = "road.xodr" }`,
//! the file relative to the TOML. The loader reads it once, keeps its lanes and makes the path
//! absolute (so the scenario runs from any working directory and reads back from `to_toml`).

use std::path::Path;

use sim::road_config::OpenDriveRoadSource;

use crate::scenario::{Line, Scenario, ScenarioError};
use crate::source_location::line_of;

/// Reads the OpenDRIVE file of the scenario's `[sim.lane_road] opendrive`, if any, relative to
/// `base`; a file that cannot be read or gives no consistent road is refused naming the TOML,
/// the line of `opendrive` and the OpenDRIVE file.
pub(crate) fn read_opendrive_source(
    scenario: &mut Scenario,
    base: Option<&Path>,
    origin: &str,
    text: Option<&str>,
) -> Result<(), ScenarioError> {
    let Some(source) = scenario
        .sim
        .lane_road
        .as_mut()
        .and_then(|c| c.opendrive.as_mut())
    else {
        return Ok(());
    };
    let path = match base {
        Some(dir) if source.file.is_relative() => dir.join(&source.file),
        _ => source.file.clone(),
    };
    let absolute = std::path::absolute(&path).unwrap_or(path);
    *source = OpenDriveRoadSource::read(absolute).map_err(|e| ScenarioError::Invalid {
        origin: origin.to_string(),
        line: Line(text.and_then(|t| {
            line_of(
                t,
                &[
                    "sim".to_string(),
                    "lane_road".to_string(),
                    "opendrive".to_string(),
                ],
            )
        })),
        field: Some("sim.lane_road.opendrive.file".into()),
        message: format!("sim.lane_road.opendrive.file: {e}"),
    })?;
    Ok(())
}
