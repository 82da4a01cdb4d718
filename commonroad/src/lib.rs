//! Reads CommonRoad XML scenarios (formats 2020a and 2018b) into typed data: the lanelet
//! network, dynamic and static obstacles, planning problems. [`road::lane_road_spec`] turns the
//! lanelet network into mergesim's road of lanes.
//!
//! What is read:
//! - lanelets: left/right bounds, predecessors/successors, `adjacentLeft`/`adjacentRight`
//!   with their driving direction, `laneletType` (2020a), the speed limit (2018b's
//!   `speedLimit`, or a 2020a maximum-speed traffic sign `274`/`R2-1` the lanelet references);
//! - obstacles (2020a `dynamicObstacle`/`staticObstacle`, 2018b `obstacle` with its `role`):
//!   type, shape (rectangle, circle, polygon), initial state, trajectory states;
//! - planning problems: the initial state and the goal states (position as shapes or
//!   lanelets, orientation, velocity, time).
//!
//! A state's values are exact or intervals ([`model::Value`]); [`model::State::replay`] gives
//! the replayed form: interval midpoints, a position rectangle's centre, time = time step ×
//! the file's `timeStepSize`.
//!
//! Everything stays in the file's coordinates; the road of lanes shifts far maps to a local
//! origin internally.
//!
//! # Public API
//! - Reading: [`read_file`], [`read_str`], and [`read_with_road`] (the scenario and its road of
//!   lanes in one call); errors are [`CommonRoadError`] of an [`ErrorKind`]; input limits
//!   [`MAX_FILE_BYTES`], [`MAX_LANELETS`], [`MAX_OBSTACLES`], [`MAX_STATES_PER_OBSTACLE`].
//! - The data read: [`model`] ([`model::Scenario`] with its [`model::Lanelet`]s,
//!   [`model::Obstacle`]s and [`model::PlanningProblem`]s).
//! - The road of lanes of a lanelet network: [`road::lane_road_spec`] (with
//!   [`road::commonroad_tolerances`]).

pub(crate) mod error;
pub(crate) mod limits;
pub mod model;
mod read;
mod read_lanelets;
pub mod road;

pub use error::{CommonRoadError, ErrorKind};
pub use limits::{MAX_FILE_BYTES, MAX_LANELETS, MAX_OBSTACLES, MAX_STATES_PER_OBSTACLE};
pub use read::{read_file, read_str};

/// Reads a file and builds its road of lanes, in one call.
///
/// # Errors
/// The reader's errors, and [`ErrorKind::Road`] (naming the file and the lanelet's line) when
/// the network does not make a consistent road.
pub fn read_with_road(
    path: &std::path::Path,
) -> Result<(model::Scenario, mergesim_types::lanes::LaneRoad), CommonRoadError> {
    let scenario = read_file(path)?;
    let spec = road::lane_road_spec(&scenario);
    let road = mergesim_types::lanes::LaneRoad::new(&spec).map_err(|e| {
        let lane = lane_of(&e);
        let lanelet = lane.and_then(|id| scenario.lanelet(i64::from(id.0)));
        CommonRoadError {
            path: path.to_path_buf(),
            line: lanelet.map(|l| l.line),
            element: lane.map(|id| format!("lanelet {id}")),
            kind: ErrorKind::Road(e),
        }
    })?;
    Ok((scenario, road))
}

/// The lane a lane-road error names, if any (read from its message's `lane N:` prefix, which
/// every per-lane variant carries).
fn lane_of(e: &mergesim_types::lanes::LaneError) -> Option<mergesim_types::lanes::LaneId> {
    let text = e.to_string();
    let rest = text.strip_prefix("lane ")?;
    let id = rest.split(':').next()?;
    id.trim().parse().ok().map(mergesim_types::lanes::LaneId)
}
