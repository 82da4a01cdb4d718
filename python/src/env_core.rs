//! The native half of `mergesim.MergeEnv` and `mergesim.parallel_env`: a `World` stepped one
//! planning period at a time, each agent's vehicle driven by the [`External`] behaviour, the
//! others by the scenario's drivers.
//! Observation, reward and termination are computed in Python (`mergesim/env.py`) from the
//! vehicles' states this returns.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

use mergesim_types::VehicleId;
use pyo3::prelude::*;
use scenarios::scenario::Scenario;
use sim::config::Driver;
use sim::recording::Recorder;
use sim::registry::BehaviourRegistry;
use sim::{RunOptions, SimError, World};

use crate::env_agents::{self, AgentChoice, ContactWatch, Contacts, SharedContacts};
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

/// What one environment step did for a single agent (returned to Python as a tuple).
type StepResult = (
    Vec<Vec<f64>>,
    bool,
    bool,
    Option<String>,
    Option<String>,
    f64,
);

/// What one environment step did for every agent: the states, per agent (in agent order)
/// whether it collided with a vehicle and whether it touched a road edge, the vehicle whose front
/// passed the road's end, a simulation error, the time (s).
type AgentsStepResult = (
    Vec<Vec<f64>>,
    Vec<bool>,
    Vec<bool>,
    Option<String>,
    Option<String>,
    f64,
);

/// The simulation behind `mergesim.MergeEnv` and `mergesim.parallel_env` (module doc). Not
/// thread-safe: used from the thread that made it.
#[pyclass(unsendable, module = "mergesim._native")]
pub(crate) struct EnvCore {
    scenario: Scenario,
    planner: Option<String>,
    /// The agents' vehicle indices, in agent order.
    agents: Vec<usize>,
    /// Each agent's command, in agent order.
    commands: Vec<SharedCommand>,
    contacts: SharedContacts,
    registry: BehaviourRegistry,
    world: Option<World>,
    instance: Scenario,
}

impl EnvCore {
    fn target_speeds_mps(scenario: &Scenario, agents: &[usize]) -> Vec<f64> {
        agents
            .iter()
            .filter_map(|&i| scenario.vehicles.get(i))
            .map(|v| v.target_speed_mps)
            .collect()
    }

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

    fn lock_command(command: &SharedCommand) -> std::sync::MutexGuard<'_, Command> {
        // A poisoned lock only means a panic elsewhere; the command itself is plain data.
        command
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Advances one planning period; (road end, error) as the step methods return them.
    fn advance(world: &mut World, py: Python<'_>) -> (Option<String>, Option<String>) {
        // Without the GIL: the world plans on a pool thread, where a Python planner (a
        // neighbour's) takes the GIL for each of its cycles.
        py.detach(|| {
            for _ in 0..world.steps_per_plan() {
                match world.step() {
                    Ok(()) => {}
                    Err(SimError::RoadEnd { vehicle, .. }) => return (Some(vehicle), None),
                    Err(e) => return (None, Some(crate::errors::chain(&e))),
                }
            }
            (None, None)
        })
    }

    /// The contacts since the last look (and none from now on).
    fn take_contacts(&self) -> Vec<Contacts> {
        let mut contacts = self
            .contacts
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        std::mem::replace(&mut *contacts, vec![Contacts::default(); self.agents.len()])
    }

    /// A checked command (speed in m/s, lateral position in m).
    fn command_of(target_speed_mps: f64, target_y_m: f64) -> PyResult<Command> {
        if !target_speed_mps.is_finite() || !target_y_m.is_finite() {
            return Err(BindingError::Input(format!(
                "action ({target_speed_mps}, {target_y_m}): must be finite"
            ))
            .into());
        }
        Ok(Command {
            target_speed_mps: target_speed_mps.max(0.0),
            target_y_m,
            handed_back: false,
        })
    }
}

#[pymethods]
impl EnvCore {
    /// Loads the scenario (as `mergesim.run` does) and picks the agents' vehicles: with neither
    /// `agents` nor `connected_agents`, one agent, `vehicle` by name, or `ego` if there is one,
    /// else the first vehicle (`MergeEnv`); `agents`: these vehicles by name; `connected_agents`:
    /// every connected, planner-driven vehicle. Several agents must each be connected and
    /// planner-driven (the planner takes the vehicle back when its agent is done:
    /// [`EnvCore::hand_back`]).
    #[new]
    #[pyo3(signature = (
        scenario, params_json = None, planner = None, vehicle = None, agents = None,
        connected_agents = false
    ))]
    fn new(
        scenario: &str,
        params_json: Option<&str>,
        planner: Option<String>,
        vehicle: Option<String>,
        agents: Option<Vec<String>>,
        connected_agents: bool,
    ) -> PyResult<Self> {
        let choice = match (vehicle, agents, connected_agents) {
            (vehicle, None, false) => AgentChoice::One(vehicle),
            (None, Some(list), false) => AgentChoice::Many(list),
            (None, None, true) => AgentChoice::EveryConnected,
            _ => {
                return Err(BindingError::Input(
                    "choose the agents one way: vehicle, agents or connected_agents".into(),
                )
                .into());
            }
        };
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
        let agents = env_agents::select(&scenario, &choice)?;
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
        // Its vehicle models (`params={"sim": {"vehicle_model": "ks"}}`), its drivers'
        // planners and their tables, refused here (with the file's line) rather than at the
        // first reset, as `merge_sim run` refuses them.
        scenario
            .check_planners(&registry)
            .map_err(|e| BindingError::input(&e))?;
        let commands: Vec<SharedCommand> = agents
            .iter()
            .map(|&i| {
                Arc::new(Mutex::new(Command {
                    target_speed_mps: scenario.vehicles[i].target_speed_mps,
                    target_y_m: 0.0,
                    handed_back: false,
                }))
            })
            .collect();
        // Vehicle name → its command, and (several agents only) the planner it is handed back
        // to: its own, or `planner` if given (the vehicle keeps its own parameters).
        let by_name: BTreeMap<String, SharedCommand> = agents
            .iter()
            .zip(&commands)
            .map(|(&i, c)| (scenario.vehicles[i].name.clone(), c.clone()))
            .collect();
        let hand_back_to: BTreeMap<String, Driver> = if matches!(choice, AgentChoice::One(_)) {
            BTreeMap::new()
        } else {
            agents
                .iter()
                .map(|&i| {
                    let spec = &scenario.vehicles[i];
                    let mut driver = spec.driver.clone();
                    if let (Some(planner), Driver::Planner { name, .. }) = (&planner, &mut driver) {
                        name.clone_from(planner);
                    }
                    (spec.name.clone(), driver)
                })
                .collect()
        };
        let own_planners = registry.clone();
        let mut registry = registry;
        registry
            .register(
                EXTERNAL_PLANNER,
                Arc::new(move |input: &sim::registry::FactoryInput<'_>| {
                    let name = &input.spec.name;
                    let command = by_name.get(name).cloned().ok_or_else(|| {
                        SimError::InvalidScenario(format!(
                            "vehicle {name}: planner {EXTERNAL_PLANNER:?} drives the \
                             environment's agents only"
                        ))
                    })?;
                    let fallback = match hand_back_to.get(name) {
                        Some(driver) => {
                            Some(env_agents::own_planner(&own_planners, input, driver)?)
                        }
                        None => None,
                    };
                    Ok(Box::new(External { command, fallback })
                        as Box<dyn mergesim_types::Behaviour>)
                }),
            )
            .map_err(|e| BindingError::input(&e))?;
        let contacts: SharedContacts =
            Arc::new(Mutex::new(vec![Contacts::default(); agents.len()]));
        Ok(Self {
            instance: scenario.clone(),
            scenario,
            planner,
            agents,
            commands,
            contacts,
            registry,
            world: None,
        })
    }

    /// Starts an episode on the instance drawn with `seed` (`Scenario::instantiate`, what
    /// `merge_sim run --seed SEED` runs; `None`: the nominal scenario), each agent's vehicle
    /// commanded to hold its lane centre at its target speed (none handed back). Returns the
    /// vehicles' states.
    #[pyo3(signature = (seed = None))]
    fn reset(&mut self, seed: Option<u64>) -> PyResult<Vec<Vec<f64>>> {
        let mut instance = self.scenario.instance(seed);
        // A scenario with `[traffic]` draws its generated vehicles per instance (their number
        // varies): an agent must be one every instance has, at the same place.
        for &agent in &self.agents {
            let nominal = &self.scenario.vehicles[agent].name;
            if instance.vehicles.get(agent).map(|v| &v.name) != Some(nominal) {
                return Err(BindingError::Input(format!(
                    "agent {nominal}: the instance drawn with seed {} has no such vehicle \
                     (scenario {} generates its [traffic] vehicles per instance; an agent \
                     must be a vehicle listed in [[vehicles]])",
                    seed.unwrap_or(0),
                    self.scenario.name
                ))
                .into());
            }
        }
        for (index, spec) in instance.vehicles.iter_mut().enumerate() {
            if self.agents.contains(&index) {
                spec.driver = Driver::planner(EXTERNAL_PLANNER);
            } else if let (Some(planner), Driver::Planner { name, .. }) =
                (&self.planner, &mut spec.driver)
            {
                // The vehicle keeps its own parameters (as `--planner` does).
                name.clone_from(planner);
            }
        }
        for (&agent, command) in self.agents.iter().zip(&self.commands) {
            let spec = &instance.vehicles[agent];
            *Self::lock_command(command) = Command {
                target_speed_mps: spec.target_speed_mps,
                target_y_m: instance.sim.road.lane_center_y_m(
                    spec.lane
                        .merge_lane()
                        .unwrap_or(mergesim_types::Lane::Lower),
                ) + spec.y_offset_m,
                handed_back: false,
            };
        }
        self.take_contacts();
        let options = RunOptions {
            planner_override: None,
            seed: seed.unwrap_or(0),
            keep_time_series: false,
            profile: false,
        };
        // The last episode's world goes first (a failed reset leaves none: step refuses).
        self.world = None;
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
            agents: self.agents.iter().map(|&i| i as VehicleId).collect(),
            contacts: self.contacts.clone(),
        }));
        let states = Self::states(&world);
        self.world = Some(world);
        self.instance = instance;
        Ok(states)
    }

    /// Commands the (first) agent's vehicle (speed in m/s, lateral position `target_y_m` in
    /// the road's y) and advances one planning period. Returns (states, collided with a vehicle,
    /// hit a road edge, the vehicle whose front passed the road's end, a simulation error,
    /// time s); after either of the last two the episode is over.
    fn step(
        &mut self,
        py: Python<'_>,
        target_speed_mps: f64,
        target_y_m: f64,
    ) -> PyResult<StepResult> {
        let (states, vehicle, edge, road_end, error, time_s) =
            self.step_agents(py, vec![(target_speed_mps, target_y_m)])?;
        Ok((
            states,
            vehicle.first().copied().unwrap_or(false),
            edge.first().copied().unwrap_or(false),
            road_end,
            error,
            time_s,
        ))
    }

    /// Commands every agent's vehicle (`commands[i]` = (speed m/s, lateral position m in the
    /// road's y) of agent `i`, in agent order; a handed-back agent's is ignored) and advances one
    /// planning period. Returns (states, per agent: collided with a vehicle, per agent: touched
    /// a road edge, the vehicle whose front passed the road's end, a simulation error, time s);
    /// after either of the last two the episode is over.
    fn step_agents(
        &mut self,
        py: Python<'_>,
        commands: Vec<(f64, f64)>,
    ) -> PyResult<AgentsStepResult> {
        if self.world.is_none() {
            return Err(BindingError::Input("step before reset: call reset() first".into()).into());
        }
        if commands.len() != self.agents.len() {
            return Err(BindingError::Input(format!(
                "{} commands for {} agents: one (target_speed_mps, target_y_m) per agent",
                commands.len(),
                self.agents.len()
            ))
            .into());
        }
        // All checked before any is applied.
        let mut checked = Vec::with_capacity(commands.len());
        for (&(speed_mps, y_m), shared) in commands.iter().zip(&self.commands) {
            let handed_back = Self::lock_command(shared).handed_back;
            checked.push(if handed_back {
                None
            } else {
                Some(Self::command_of(speed_mps, y_m)?)
            });
        }
        for (command, shared) in checked.into_iter().zip(&self.commands) {
            if let Some(command) = command {
                *Self::lock_command(shared) = command;
            }
        }
        let Some(world) = self.world.as_mut() else {
            return Err(BindingError::Input("step before reset: call reset() first".into()).into());
        };
        let (road_end, error) = Self::advance(world, py);
        let states = Self::states(world);
        let time_s = world.time_s();
        if road_end.is_some() || error.is_some() {
            self.world = None;
        }
        let contacts = self.take_contacts();
        Ok((
            states,
            contacts.iter().map(|c| c.vehicle).collect(),
            contacts.iter().map(|c| c.road_edge).collect(),
            road_end,
            error,
            time_s,
        ))
    }

    /// Hands agent `agent`'s vehicle (its position in `agent_indices`) back to its own planner
    /// (the scenario's, or the `planner` given) until the next reset; several agents only.
    fn hand_back(&mut self, agent: usize) -> PyResult<()> {
        let Some(command) = self.commands.get(agent) else {
            return Err(BindingError::Input(format!(
                "agent {agent}: there are {} agents",
                self.agents.len()
            ))
            .into());
        };
        Self::lock_command(command).handed_back = true;
        Ok(())
    }

    /// Index of the (first) agent's vehicle.
    #[getter]
    fn agent_index(&self) -> usize {
        self.agents.first().copied().unwrap_or(0)
    }

    /// Indices of the agents' vehicles, in agent order.
    #[getter]
    fn agent_indices(&self) -> Vec<usize> {
        self.agents.clone()
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

    /// The (first) agent vehicle's target speed in the current episode (m/s).
    #[getter]
    fn agent_target_speed_mps(&self) -> f64 {
        self.agent_target_speeds_mps()
            .first()
            .copied()
            .unwrap_or(0.0)
    }

    /// The (first) agent vehicle's target speed in the nominal scenario (m/s).
    #[getter]
    fn nominal_target_speed_mps(&self) -> f64 {
        self.nominal_target_speeds_mps()
            .first()
            .copied()
            .unwrap_or(0.0)
    }

    /// Each agent vehicle's target speed in the current episode (m/s), in agent order.
    #[getter]
    fn agent_target_speeds_mps(&self) -> Vec<f64> {
        Self::target_speeds_mps(&self.instance, &self.agents)
    }

    /// Each agent vehicle's target speed in the nominal scenario (m/s), in agent order.
    #[getter]
    fn nominal_target_speeds_mps(&self) -> Vec<f64> {
        Self::target_speeds_mps(&self.scenario, &self.agents)
    }

    /// Names of the columns of a state row.
    #[staticmethod]
    fn state_columns() -> Vec<&'static str> {
        STATE_COLUMNS.to_vec()
    }
}
