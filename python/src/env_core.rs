//! The native half of `mergesim.MergeEnv`: a `World` stepped one planning period at a time, the
//! agent's vehicle driven by the [`External`] behaviour, the others by the scenario's drivers.
//! Observation, reward and termination are computed in Python (`mergesim/env.py`) from the
//! vehicles' states this returns.

use std::sync::{Arc, Mutex};

use mergesim_types::VehicleId;
use pyo3::prelude::*;
use scenarios::scenario::Scenario;
use sim::config::Driver;
use sim::recording::Recorder;
use sim::registry::BehaviourRegistry;
use sim::{RunOptions, SimError, TickObserver, World};

use crate::errors::BindingError;
use crate::external::{Command, EXTERNAL_PLANNER, External, SharedCommand};
use crate::source;

/// Columns of a vehicle's state row ([`EnvCore::reset`], [`EnvCore::step`]).
pub(crate) const STATE_COLUMNS: [&str; 9] = [
    "x_m",
    "y_m",
    "yaw_rad",
    "speed_mps",
    "vx_mps",
    "vy_mps",
    "yaw_rate_radps",
    "accel_long_mps2",
    "accel_lat_mps2",
];

/// Contacts of the agent's vehicle since the last look.
#[derive(Clone, Copy, Debug, Default)]
struct Contacts {
    vehicle: bool,
    road_edge: bool,
}

/// Watches the world's collision reports for the agent's vehicle.
struct ContactWatch {
    agent: VehicleId,
    contacts: Arc<Mutex<Contacts>>,
}

impl TickObserver for ContactWatch {
    fn on_collision(&mut self, ids: &[VehicleId]) {
        if !ids.contains(&self.agent) {
            return;
        }
        let mut contacts = self
            .contacts
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        // A collision between vehicles names both; a road-edge contact names one vehicle.
        if ids.len() >= 2 {
            contacts.vehicle = true;
        } else {
            contacts.road_edge = true;
        }
    }
}

/// What one environment step did (returned to Python as a tuple).
type StepResult = (
    Vec<Vec<f64>>,
    bool,
    bool,
    Option<String>,
    Option<String>,
    f64,
);

/// The simulation behind `mergesim.MergeEnv` (module doc). Not thread-safe: used from the thread
/// that made it.
#[pyclass(unsendable, module = "mergesim._native")]
pub(crate) struct EnvCore {
    scenario: Scenario,
    planner: Option<String>,
    agent: usize,
    command: SharedCommand,
    contacts: Arc<Mutex<Contacts>>,
    registry: BehaviourRegistry,
    world: Option<World>,
    instance: Scenario,
}

impl EnvCore {
    fn states(world: &World) -> Vec<Vec<f64>> {
        world
            .kinematics()
            .iter()
            .map(|k| {
                let (s, c) = k.yaw_rad.sin_cos();
                vec![
                    k.x_m,
                    k.y_m,
                    k.yaw_rad,
                    k.speed_mps,
                    k.vx_body_mps * c - k.vy_body_mps * s,
                    k.vx_body_mps * s + k.vy_body_mps * c,
                    k.yaw_rate_radps,
                    k.accel_long_mps2,
                    k.accel_lat_mps2,
                ]
            })
            .collect()
    }
}

#[pymethods]
impl EnvCore {
    /// Loads the scenario (as `mergesim.run` does) and picks the agent's vehicle: `vehicle` by
    /// name, or `ego` if there is one, else the first vehicle.
    #[new]
    #[pyo3(signature = (scenario, params_json = None, planner = None, vehicle = None))]
    fn new(
        scenario: &str,
        params_json: Option<&str>,
        planner: Option<String>,
        vehicle: Option<&str>,
    ) -> PyResult<Self> {
        let scenario = source::load(scenario, params_json)?;
        // The environment's observations, commands and rendering are those of the straight
        // merge road (x along it, y across it); a road of lanes is refused, not misread.
        if !scenario.sim.is_straight_merge_road() {
            return Err(BindingError::Input(format!(
                "scenario {}: MergeEnv runs on the straight [sim.road] merge road only; this \
                 scenario's road is a [sim.lane_road]",
                scenario.name
            ))
            .into());
        }
        let names: Vec<&str> = scenario.vehicles.iter().map(|v| v.name.as_str()).collect();
        let agent = match vehicle {
            Some(name) => names.iter().position(|n| *n == name).ok_or_else(|| {
                BindingError::Input(format!(
                    "vehicle {name:?}: not a vehicle of scenario {} ({})",
                    scenario.name,
                    names.join(", ")
                ))
            })?,
            None => names.iter().position(|n| *n == "ego").unwrap_or(0),
        };
        // The built-in planners and the Python ones registered now.
        let registry = crate::py_planner::registry()?;
        // Checked as `merge_sim run --planner` checks it (the same message).
        if let Some(name) = &planner
            && !registry.contains(name)
        {
            return Err(BindingError::Input(mergesim::experiment::unknown_planner(
                &registry, name,
            ))
            .into());
        }
        // Its vehicle models (`params={"sim": {"vehicle_model": "ks"}}`), refused here rather
        // than at the first reset.
        scenario
            .check_vehicle_models(&registry)
            .map_err(|e| BindingError::input(&e))?;
        let command: SharedCommand = Arc::new(Mutex::new(Command {
            target_speed_mps: scenario.vehicles[agent].target_speed_mps,
            target_y_m: 0.0,
        }));
        let mut registry = registry;
        let shared = command.clone();
        registry
            .register(
                EXTERNAL_PLANNER,
                Arc::new(move |_: &sim::registry::FactoryInput<'_>| {
                    Ok(Box::new(External {
                        command: shared.clone(),
                    }) as Box<dyn mergesim_types::Behaviour>)
                }),
            )
            .map_err(|e| BindingError::input(&e))?;
        Ok(Self {
            instance: scenario.clone(),
            scenario,
            planner,
            agent,
            command,
            contacts: Arc::default(),
            registry,
            world: None,
        })
    }

    /// Starts an episode on the instance drawn with `seed` (`Scenario::instantiate`, what
    /// `merge_sim run --seed SEED` runs; `None`: the nominal scenario), the agent's vehicle
    /// commanded to hold its lane centre at its target speed. Returns the vehicles' states.
    #[pyo3(signature = (seed = None))]
    fn reset(&mut self, seed: Option<u64>) -> PyResult<Vec<Vec<f64>>> {
        let mut instance = self.scenario.instance(seed);
        for (index, spec) in instance.vehicles.iter_mut().enumerate() {
            if index == self.agent {
                spec.driver = Driver::planner(EXTERNAL_PLANNER);
            } else if let (Some(planner), Driver::Planner { name, .. }) =
                (&self.planner, &mut spec.driver)
            {
                // The vehicle keeps its own parameters (as `--planner` does).
                name.clone_from(planner);
            }
        }
        let agent_spec = &instance.vehicles[self.agent];
        *self
            .command
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = Command {
            target_speed_mps: agent_spec.target_speed_mps,
            target_y_m: instance.sim.road.lane_center_y_m(
                agent_spec
                    .lane
                    .merge_lane()
                    .unwrap_or(mergesim_types::Lane::Lower),
            ) + agent_spec.y_offset_m,
        };
        *self
            .contacts
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = Contacts::default();
        let options = RunOptions {
            planner_override: None,
            seed: seed.unwrap_or(0),
            keep_time_series: false,
            profile: false,
        };
        let mut world = World::with_registry(
            instance.sim.clone(),
            &instance.vehicles,
            &options,
            Recorder::disabled(),
            &self.registry,
        )
        .map_err(|e| BindingError::input(&e))?;
        // A one-thread pool created at every reset, in the current process: an environment
        // in a forked child (`AsyncVectorEnv`) never waits on threads the fork did not copy,
        // and vector environments do not oversubscribe the cores (`background`).
        world.plan_on(crate::background::fresh_pool(Some(1))?);
        world.add_observer(Box::new(ContactWatch {
            agent: self.agent as VehicleId,
            contacts: self.contacts.clone(),
        }));
        let states = Self::states(&world);
        self.world = Some(world);
        self.instance = instance;
        Ok(states)
    }

    /// Commands the agent's vehicle (speed in m/s, lateral position `target_y_m` in the road's
    /// y) and advances one planning period. Returns (states, collided with a vehicle, hit a
    /// road edge, the vehicle whose front passed the road's end, a simulation error, time s);
    /// after either of the last two the episode is over.
    fn step(
        &mut self,
        py: Python<'_>,
        target_speed_mps: f64,
        target_y_m: f64,
    ) -> PyResult<StepResult> {
        let Some(world) = self.world.as_mut() else {
            return Err(BindingError::Input("step before reset: call reset() first".into()).into());
        };
        if !target_speed_mps.is_finite() || !target_y_m.is_finite() {
            return Err(BindingError::Input(format!(
                "action ({target_speed_mps}, {target_y_m}): must be finite"
            ))
            .into());
        }
        *self
            .command
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = Command {
            target_speed_mps: target_speed_mps.max(0.0),
            target_y_m,
        };
        // Without the GIL: the world plans on a pool thread, where a Python planner (a
        // neighbour's) takes the GIL for each of its cycles.
        let (road_end, error) = py.detach(|| {
            for _ in 0..world.steps_per_plan() {
                match world.step() {
                    Ok(()) => {}
                    Err(SimError::RoadEnd { vehicle, .. }) => return (Some(vehicle), None),
                    Err(e) => return (None, Some(crate::errors::chain(&e))),
                }
            }
            (None, None)
        });
        let states = Self::states(world);
        let time_s = world.time_s();
        if road_end.is_some() || error.is_some() {
            self.world = None;
        }
        let contacts = std::mem::take(
            &mut *self
                .contacts
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner),
        );
        Ok((
            states,
            contacts.vehicle,
            contacts.road_edge,
            road_end,
            error,
            time_s,
        ))
    }

    /// Index of the agent's vehicle.
    #[getter]
    fn agent_index(&self) -> usize {
        self.agent
    }

    /// Vehicle names, in id order.
    #[getter]
    fn vehicle_names(&self) -> Vec<String> {
        self.scenario
            .vehicles
            .iter()
            .map(|v| v.name.clone())
            .collect()
    }

    /// (length m, width m) of every vehicle, in id order.
    #[getter]
    fn vehicle_sizes_m(&self) -> PyResult<Vec<(f64, f64)>> {
        self.scenario
            .vehicles
            .iter()
            .map(|v| {
                vehicles::VehicleParams::preset(&v.preset)
                    .map(|p| (p.length_m, p.width_m))
                    .map_err(|e| BindingError::input(&e).into())
            })
            .collect()
    }

    /// The current episode's road: lane_width_m, y_bottom_m, merge_start_x_m, merge_end_x_m,
    /// start_x_m, end_x_m.
    #[getter]
    fn road(&self) -> Vec<(String, f64)> {
        let r = &self.instance.sim.road;
        vec![
            ("lane_width_m".into(), r.lane_width_m),
            ("y_bottom_m".into(), r.y_bottom_m),
            ("merge_start_x_m".into(), r.merge_start_x_m),
            ("merge_end_x_m".into(), r.merge_end_x_m),
            ("start_x_m".into(), r.start_x_m),
            ("end_x_m".into(), r.end_x_m),
        ]
    }

    /// The current episode's simulated duration (s).
    #[getter]
    fn duration_s(&self) -> f64 {
        self.instance.sim.duration_s
    }

    /// Planning period = one environment step (s).
    #[getter]
    fn planner_period_s(&self) -> f64 {
        self.instance.sim.planner_period_s
    }

    /// The agent vehicle's target speed in the current episode (m/s).
    #[getter]
    fn agent_target_speed_mps(&self) -> f64 {
        self.instance.vehicles[self.agent].target_speed_mps
    }

    /// The agent vehicle's target speed in the nominal scenario (m/s).
    #[getter]
    fn nominal_target_speed_mps(&self) -> f64 {
        self.scenario.vehicles[self.agent].target_speed_mps
    }

    /// Names of the columns of a state row.
    #[staticmethod]
    fn state_columns() -> Vec<&'static str> {
        STATE_COLUMNS.to_vec()
    }
}
