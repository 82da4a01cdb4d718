//! Typed errors of the simulator.

use thiserror::Error;

pub(crate) use mergesim_types::InvalidParameter;

/// Everything that can stop a simulation. Never a panic.
#[derive(Debug, Error)]
pub enum SimError {
    /// A parameter is out of range (its dotted name, e.g. `v2v.drop_probability`, says which).
    #[error(transparent)]
    InvalidParameter(#[from] InvalidParameter),
    /// A field that is not a number is wrong (its dotted name says which, e.g.
    /// `vehicles[ego].preset`).
    #[error("{field}: {message}")]
    InvalidField {
        /// Dotted name; `vehicles[#i]` names the i-th vehicle (0-based) when its name is the
        /// problem.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// Something about the scenario's vehicles is inconsistent (duplicate ids, ...).
    #[error("invalid scenario: {0}")]
    InvalidScenario(String),
    /// The road's lanes are inconsistent (the error names the lane and what is wrong).
    #[error("road: {0}")]
    Road(#[from] mergesim_types::lanes::LaneError),
    /// The road's CommonRoad file cannot be read or is inconsistent (names the file, line and
    /// element).
    #[error(transparent)]
    CommonRoad(#[from] mergesim_commonroad::CommonRoadError),
    /// The road's OpenDRIVE file cannot be read or gives no consistent road (names the file).
    #[error(transparent)]
    OpenDrive(#[from] mergesim_opendrive::OpenDriveError),
    /// The vehicle model refused its parameters or state.
    #[error(transparent)]
    Vehicle(#[from] vehicles::VehicleError),
    /// The planner refused its input.
    #[error("planner of vehicle {vehicle}: {source}")]
    Planner {
        /// The vehicle's name.
        vehicle: String,
        /// What the planner said.
        source: planner::PlannerError,
    },
    /// A scenario names a planner the registry does not hold.
    #[error("vehicles[{vehicle}].driver: unknown planner {name:?} (registered: {valid})")]
    UnknownPlanner {
        /// The vehicle's name.
        vehicle: String,
        /// The name asked for.
        name: String,
        /// The registered names, comma separated.
        valid: String,
    },
    /// A vehicle's behaviour failed to plan.
    #[error("behaviour of vehicle {vehicle}: {source}")]
    Behaviour {
        /// The vehicle's name.
        vehicle: String,
        /// What it said.
        source: mergesim_types::BehaviourError,
    },
    /// The physics diverged (non-finite or runaway state).
    #[error("simulation diverged at t = {t_s} s: {what}")]
    Diverged {
        /// Time of detection.
        t_s: f64,
        /// What was wrong.
        what: String,
    },
    /// A vehicle reached the end of the road before the run ended (the scenario loader refuses
    /// roads too short for the run; a `World` built directly can still meet this).
    #[error(
        "vehicle {vehicle} reached the end of the road (the end of lane {lane}) at t = {t_s} s; \
         lengthen the road or shorten duration_s"
    )]
    RoadEnd {
        /// The vehicle's name.
        vehicle: String,
        /// When its front passed the end (s).
        t_s: f64,
        /// The lane whose open end it passed (on the merge road, lane 1 ends at road.end_x_m).
        lane: mergesim_types::lanes::LaneId,
    },
    /// The run was interrupted (a signal) before its end.
    #[error("interrupted at t = {t_s} s")]
    Interrupted {
        /// Simulated time reached (s).
        t_s: f64,
    },
    /// Writing an output failed.
    #[error("recording: {0}")]
    Recording(String),
}

impl SimError {
    /// Shorthand for [`SimError::InvalidParameter`].
    pub(crate) fn invalid(name: impl Into<String>, value: f64, reason: impl Into<String>) -> Self {
        Self::InvalidParameter(InvalidParameter::new(name, value, reason))
    }

    /// The dotted name of the field it is about, if any (numeric or not).
    pub fn field(&self) -> Option<String> {
        match self {
            Self::InvalidField { field, .. } => Some(field.clone()),
            Self::UnknownPlanner { vehicle, .. } => Some(format!("vehicles[{vehicle}].driver")),
            other => other.invalid_parameter().map(|p| p.name.clone()),
        }
    }

    /// The parameter it names, if it is about one (also inside a vehicle's or a planner's
    /// error), so a scenario loader can point at the file's line.
    pub fn invalid_parameter(&self) -> Option<&InvalidParameter> {
        match self {
            Self::InvalidParameter(p) => Some(p),
            Self::Vehicle(e) => e.invalid_parameter(),
            Self::Planner { source, .. } => source.invalid_parameter(),
            _ => None,
        }
    }
}

impl From<planner::PlannerError> for SimError {
    /// A planner's refusal of its parameters (`planner.*`, `road.*`) keeps the field's name;
    /// anything else is an invalid scenario.
    fn from(e: planner::PlannerError) -> Self {
        match e {
            planner::PlannerError::InvalidParameter(p) => Self::InvalidParameter(p),
            other => Self::InvalidScenario(other.to_string()),
        }
    }
}

impl From<crate::safety::SafetyError> for SimError {
    /// A safety parameter out of range keeps the field's name (`safety.*`).
    fn from(e: crate::safety::SafetyError) -> Self {
        match e {
            crate::safety::SafetyError::InvalidParameter(p) => Self::InvalidParameter(p),
            other => Self::InvalidScenario(other.to_string()),
        }
    }
}
