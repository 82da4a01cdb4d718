//! The extension point: how a vehicle decides its path and speed. A planner — the paper's
//! potential-field planners, a human-driver model, or a user's own — implements [`Behaviour`]:
//! an [`Observation`] in, a [`Decision`] (the path to track, with speeds and times, and the
//! message to broadcast) out. The simulator calls it at every planning period of the vehicle,
//! visiting the vehicles in id order.
//!
//! ```
//! use mergesim_types::{Behaviour, BehaviourError, Decision, Observation, PathPoint};
//!
//! /// Drives straight ahead at its target speed (a user's planner in ten lines).
//! struct Straight;
//!
//! impl Behaviour for Straight {
//!     fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
//!         let v = obs.target_speed_mps.max(0.5);
//!         let path = (0..=20)
//!             .map(|i| PathPoint {
//!                 x_m: obs.ego.x_m + 2.0 * i as f64,
//!                 y_m: obs.ego.y_m,
//!                 speed_mps: v,
//!                 t_s: obs.time_s + 2.0 * i as f64 / v,
//!             })
//!             .collect();
//!         Ok(Decision::follow(path))
//!     }
//! }
//! ```

use crate::grid::GridSpec;
use crate::lanes::LaneRoad;
use crate::path::{PathPoint, SharedLocalPath};
use crate::vehicle::{Neighbour, VehicleId, VehicleShape, VehicleState};

/// Why a behaviour could not plan (its own error, boxed).
pub type BehaviourError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// What a vehicle's driver knows at a planning instant.
#[derive(Clone, Copy, Debug)]
pub struct Observation<'a> {
    /// Planning time (s).
    pub time_s: f64,
    /// The vehicle's id.
    pub ego_id: VehicleId,
    /// Its state.
    pub ego: VehicleState,
    /// Its footprint and braking.
    pub ego_shape: VehicleShape,
    /// Its target speed V_target (m/s).
    pub target_speed_mps: f64,
    /// Tire–road friction μ.
    pub mu: f64,
    /// The road as lanes: centrelines with their (s, d) frames, bounds, links, dividers, outer
    /// edges and lane ends. Planners, metrics and safety checks read the road through it.
    pub lanes: &'a LaneRoad,
    /// The current state of every other vehicle within the perception range (the simulator's
    /// `perception_range_m`, 250 m by default), in id order.
    pub neighbours: &'a [Neighbour],
    /// The shared local paths received over V2V from senders within radio range (empty for a
    /// vehicle that is not connected).
    pub shared_paths: &'a [SharedLocalPath],
}

/// What a behaviour decides.
#[derive(Clone, Debug, PartialEq)]
pub struct Decision {
    /// The path to track: points with speeds and absolute times, starting at the vehicle.
    pub path: Vec<PathPoint>,
    /// The message to broadcast (sent only if the vehicle is connected).
    pub broadcast: Option<SharedLocalPath>,
    /// Why this decision is a fallback (logged and counted), if it is one.
    pub fallback: Option<FallbackReason>,
    /// The degraded mode this decision was made in, if any (e.g. [`DegradedMode::V2vLost`]:
    /// no shared path heard from anybody around); the simulator counts such decisions and logs
    /// when a vehicle enters and leaves a mode.
    pub degraded_mode: Option<DegradedMode>,
}

/// Why a decision is a fallback rather than its planner's regular answer
/// (`Decision::fallback`). `Display` gives the reason as the event log writes it.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum FallbackReason {
    /// The planner's solver did not converge (its message).
    SolverFailed(String),
    /// A non-finite number appeared (where).
    NonFinite(String),
    /// A user's planner's own reason, in its words.
    Other(String),
}

impl std::fmt::Display for FallbackReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // The built-in reasons keep the form the event log has always had.
        match self {
            Self::SolverFailed(message) => write!(f, "SolverFailed({message:?})"),
            Self::NonFinite(what) => write!(f, "NonFinite({what:?})"),
            Self::Other(reason) => f.write_str(reason),
        }
    }
}

/// A degraded mode a decision was made in (`Decision::degraded_mode`). `Display` gives its
/// name as the event log writes it (`v2v-lost`).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DegradedMode {
    /// No shared local path heard from any vehicle around (V2V lost): PF-ISO plans with its
    /// `v2v_loss_fallback` instead of the interaction term.
    V2vLost,
    /// A user's planner's own mode, by its name.
    Other(String),
}

impl std::fmt::Display for DegradedMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::V2vLost => f.write_str("v2v-lost"),
            Self::Other(name) => f.write_str(name),
        }
    }
}

impl Decision {
    /// Follow `path`, broadcast nothing.
    pub fn follow(path: Vec<PathPoint>) -> Self {
        Self {
            path,
            broadcast: None,
            fallback: None,
            degraded_mode: None,
        }
    }

    /// Follow `path` and broadcast it as the vehicle's shared local path, stamped with the
    /// observation's time, the vehicle's id, shape and current speed (what a connected
    /// planner usually shares, so PF-ISO vehicles around see where it goes).
    pub fn follow_and_share(path: Vec<PathPoint>, obs: &Observation<'_>) -> Self {
        let broadcast = SharedLocalPath::from_path(
            obs.ego_id,
            obs.time_s,
            obs.ego_shape,
            obs.ego.speed_mps,
            &path,
        );
        Self {
            broadcast: Some(broadcast),
            ..Self::follow(path)
        }
    }
}

/// How the last cycle's optimiser ended (optional: [`Behaviour::optimiser_report`]); the
/// simulator sums it over a run (`planner_stats`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OptimiserReport {
    /// Convex (or QP) solves of the cycle.
    pub solves: u32,
    /// Whether an iterative optimiser ran out of iterations before meeting its tolerance.
    pub stopped_at_iteration_cap: bool,
    /// Whether the cycle's path fit was limited by one of its bounds (the potential-field
    /// planners: the cubic of Eqs. 8–9 needed its QP because a heading, curvature or
    /// curvature-rate bound was active); `false` for a planner without such a fit.
    pub path_fit_bound_active: bool,
}

/// A vehicle's decision making (module doc). `Send` so the simulator may plan vehicles in
/// parallel.
pub trait Behaviour: Send {
    /// One planning cycle.
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError>;

    /// Whether its cycles count as planner cycles in the run's statistics (timing, fallbacks).
    /// Human-driver models answer `false`.
    fn is_planner(&self) -> bool {
        true
    }

    /// How the last [`plan`](Self::plan)'s optimiser ended, for the run's statistics (`None`:
    /// nothing to report, the default).
    fn optimiser_report(&self) -> Option<OptimiserReport> {
        None
    }

    /// Its potential field on `spec`'s grid, row after row, for drawing; `None` if it has none.
    fn potential_field(&self, _obs: &Observation<'_>, _spec: &GridSpec) -> Option<Vec<f64>> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::FallbackReason;

    #[test]
    fn fallback_reasons_read_as_the_event_log_has_always_written_them() {
        // Before the reason was typed, the log wrote the planner's reason with `{:?}`.
        let solver = FallbackReason::SolverFailed("max \"iterations\"".into());
        assert_eq!(solver.to_string(), format!("{solver:?}"));
        let non_finite = FallbackReason::NonFinite("speed".into());
        assert_eq!(non_finite.to_string(), "NonFinite(\"speed\")");
        // A user's reason is written as given.
        assert_eq!(FallbackReason::Other("no gap".into()).to_string(), "no gap");
    }
}
