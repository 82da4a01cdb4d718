//! The agent's vehicle in the Gymnasium environment: an "external" behaviour whose decision is
//! built from the last action (a target speed and a lateral position), which the simulator's
//! own pure-pursuit / PID tracker then turns into steering and wheel torques. In the multi-agent
//! environment a finished agent's vehicle is handed back to its own planner (the scenario's),
//! which then drives it until the episode ends.

use std::sync::{Arc, Mutex};

use mergesim_types::{Behaviour, BehaviourError, Decision, Observation, PathPoint};

/// Name the behaviour is registered under (for the agent's vehicle only).
pub(crate) const EXTERNAL_PLANNER: &str = "external";

/// Spacing of the commanded path's points (m).
const STEP_M: f64 = 2.5;
/// Shortest commanded path (m) and its length in seconds of travel at the commanded speed.
const MIN_LENGTH_M: f64 = 50.0;
const LENGTH_S: f64 = 3.0;
/// The lateral move to the commanded position takes this far (m), or this long at the
/// commanded speed (s), whichever is longer.
const MIN_TRANSITION_M: f64 = 20.0;
const TRANSITION_S: f64 = 1.5;
/// Slowest speed used to integrate the path's times (m/s).
const MIN_TIMING_SPEED_MPS: f64 = 0.5;

/// The last action: what the agent's vehicle is asked to do until the next one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Command {
    /// Speed to drive at (m/s, ≥ 0).
    pub target_speed_mps: f64,
    /// Lateral position to drive at (m, the road's y).
    pub target_y_m: f64,
    /// Whether the vehicle is handed back to its own planner ([`External::fallback`]): the
    /// command is then ignored.
    pub handed_back: bool,
}

/// The commanded path, shared between the environment (which writes the command) and the
/// vehicle's behaviour (which reads it at every planning cycle).
pub(crate) type SharedCommand = Arc<Mutex<Command>>;

/// The agent's behaviour (module doc).
pub(crate) struct External {
    /// The command it follows.
    pub command: SharedCommand,
    /// The vehicle's own planner, which plans instead once the command is handed back (None:
    /// the command is followed to the end).
    pub fallback: Option<Box<dyn Behaviour>>,
}

/// The path of `command` from the vehicle at (`x_m`, `y_m`) at time `t_s`: straight ahead at
/// the commanded speed, moving smoothly (a cosine blend) to the commanded lateral position.
pub(crate) fn commanded_path(command: Command, x_m: f64, y_m: f64, t_s: f64) -> Vec<PathPoint> {
    let v = command.target_speed_mps.max(0.0);
    let length_m = (LENGTH_S * v).max(MIN_LENGTH_M);
    let transition_m = (TRANSITION_S * v).max(MIN_TRANSITION_M);
    let points = (length_m / STEP_M).ceil() as usize + 1;
    let timing_speed_mps = v.max(MIN_TIMING_SPEED_MPS);
    (0..points)
        .map(|i| {
            let ahead_m = STEP_M * i as f64;
            let w = (ahead_m / transition_m).min(1.0);
            let blend = 0.5 - 0.5 * (std::f64::consts::PI * w).cos();
            PathPoint {
                x_m: x_m + ahead_m,
                y_m: y_m + blend * (command.target_y_m - y_m),
                speed_mps: v,
                t_s: t_s + ahead_m / timing_speed_mps,
            }
        })
        .collect()
}

impl Behaviour for External {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        // A poisoned lock only means a panic elsewhere; the command itself is plain data.
        let command = *self
            .command
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if command.handed_back
            && let Some(planner) = self.fallback.as_mut()
        {
            return planner.plan(obs);
        }
        let path = commanded_path(command, obs.ego.x_m, obs.ego.y_m, obs.time_s);
        // Shared like a planner's path, so connected PF-ISO vehicles see where it goes.
        Ok(Decision::follow_and_share(path, obs))
    }

    fn is_planner(&self) -> bool {
        false
    }
}
