//! Recorded traffic: vehicles that move along recorded states (e.g. a CommonRoad file's dynamic
//! obstacles) instead of being driven by a behaviour.
//!
//! The data is filled by the scenario loader from the road's source file; the world spawns one
//! body per recorded vehicle for its recorded time span. Positions are in the road's
//! coordinates (the file's), like every vehicle position.

use serde::{Deserialize, Serialize};

/// How recorded vehicles move.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TrafficMode {
    /// No recorded vehicles are spawned.
    None,
    /// They follow their recording and never react (CommonRoad's non-reactive benchmark).
    #[default]
    Replay,
    /// They follow their recording until it would bring them closer to a simulated vehicle
    /// ahead than the Intelligent Driver Model's safe gap; then IDM drives them.
    Reactive,
}

impl std::fmt::Display for TrafficMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            TrafficMode::None => "none",
            TrafficMode::Replay => "replay",
            TrafficMode::Reactive => "reactive",
        })
    }
}

/// One recorded state: a recorded vehicle at one instant of its recording. It carries its own
/// time (a recording is a list of them); a planner sees it as a
/// [`mergesim_types::VehicleState`] (`From`), the safety checks as a
/// [`crate::body_state::BodyState`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordedState {
    /// Time since the start of the run (s).
    pub time_s: f64,
    /// Centre of the vehicle's rectangle (m).
    pub position_m: [f64; 2],
    /// Heading (rad, counter-clockwise from +x).
    pub heading_rad: f64,
    /// Speed (m/s).
    pub speed_mps: f64,
}

/// What a planner perceives of a recorded vehicle in this state: its pose and speed (the time
/// is the caller's).
impl From<&RecordedState> for mergesim_types::VehicleState {
    fn from(s: &RecordedState) -> Self {
        Self {
            x_m: s.position_m[0],
            y_m: s.position_m[1],
            yaw_rad: s.heading_rad,
            speed_mps: s.speed_mps,
        }
    }
}

/// One recorded vehicle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordedVehicle {
    /// Its name in outputs (e.g. `cr-214` for CommonRoad obstacle 214); unique among all
    /// vehicles of the run.
    pub name: String,
    /// Its rectangle's length along the heading (m).
    pub length_m: f64,
    /// Its rectangle's width (m).
    pub width_m: f64,
    /// Its states, at strictly increasing times; at least one. It exists from the first
    /// state's time to the last's, interpolated between them (`crate::recorded_motion`); with a
    /// single state it exists for the whole run and stands still there.
    pub states: Vec<RecordedState>,
}

/// The recorded traffic of a run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RecordedTraffic {
    /// How they move.
    pub mode: TrafficMode,
    /// The vehicles.
    pub vehicles: Vec<RecordedVehicle>,
}

impl RecordedTraffic {
    /// True if nothing is to be spawned (no vehicles, or mode `none`).
    pub fn is_empty(&self) -> bool {
        self.mode == TrafficMode::None || self.vehicles.is_empty()
    }
}
