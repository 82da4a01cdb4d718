//! The closed-loop simulation: one `World` owns the physics, the vehicles and their behaviours,
//! the V2V bus and the safety monitor, and advances them in a fixed order every physics step:
//!
//! 1. V2V delivery → 2. planning (each vehicle at its own period, visited by id) and broadcast →
//! 3. tracking → 4. tire and suspension forces, recorded traffic's kinematic targets
//!    (`recorded`), rapier step → 5. parry safety checks → 6. the observers: metrics, time
//!    series and recording (on their own clock; `crate::observer`).
//!
//! Same configuration + same seed ⇒ bitwise identical results: vehicles are visited by index,
//! every map is ordered, and the only randomness (V2V drops) comes from a seeded stream.

use std::time::{Duration, Instant};

use mergesim_types::{PathPoint, SharedLocalPath, VehicleId};
use vehicles::{Kinematics, PhysicsWorld};

use crate::agent::Agent;
use crate::config::{SimConfig, VehicleSpec};
use crate::drivers::lane_path;
use crate::error::SimError;
use crate::event::SimEvent;
use crate::metrics::VehicleMetrics;
use crate::observer::{TickObserver, VehicleView};
use crate::outcome::RunOutcome;
use crate::planner_stats::PlannerStatsObserver;
use crate::profile::{Phase, ProfileObserver};
use crate::recording::Recorder;
use crate::recording_observer::RecordingObserver;
use crate::registry::BehaviourRegistry;
use crate::run_log::RunLog;
use crate::safety::{BodyState, SafetyMonitor};
use crate::traffic_metrics::TrafficMetrics;
use crate::v2v::V2vBus;

mod goals;
mod lanes;
mod outputs;
mod planning;
mod recorded;

/// Options of one run that are not part of the scenario.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Override every `driver = { planner = … }` vehicle's planner with this registered name.
    pub planner_override: Option<String>,
    /// Seed of the run's random streams (V2V drops).
    pub seed: u64,
    /// Keep the time series in the outcome (for `--csv`).
    pub keep_time_series: bool,
    /// Time each phase of the tick (`RunOutcome::profile`).
    pub profile: bool,
}

/// The simulation.
pub struct World {
    config: SimConfig,
    /// The road as lanes, built once from `config.lane_road` or else `config.road` (shared with
    /// the observations and the metrics).
    lanes: std::sync::Arc<mergesim_types::lanes::LaneRoad>,
    physics: PhysicsWorld,
    agents: Vec<Agent>,
    /// The recorded traffic (`recorded`), ids after the agents'.
    recorded: recorded::RecordedFleet,
    bus: V2vBus,
    safety: SafetyMonitor,
    run_log: RunLog,
    /// The traffic figures (`crate::traffic_metrics`).
    traffic: TrafficMetrics,
    /// The recorded traffic's boxes at each log instant, if the time series is kept.
    recorded_track: Option<Vec<crate::outcome::RecordedPose>>,
    recording: RecordingObserver,
    observers: Vec<Box<dyn TickObserver>>,
    events: Vec<SimEvent>,
    planner_stats: PlannerStatsObserver,
    step_index: u64,
    steps_per_plan: u64,
    steps_per_log: u64,
    steps_per_field: u64,
    steps_per_safety: u64,
    reported_collisions: usize,
    reported_edge_contacts: usize,
    /// The built-in phase-time observer (`RunOptions::profile`).
    profile: Option<ProfileObserver>,
    /// Whether some observer wants phase times (the clock is read only then).
    timing: bool,
    planning_pool: Option<std::sync::Arc<rayon::ThreadPool>>,
    /// Per vehicle: when it reached its goal (`crate::goal`; `world/goals.rs`).
    goal_times: Vec<Option<f64>>,
    /// A vehicle left the map: the run has ended (`world/goals.rs`).
    left_map: bool,
    /// Whether some car moves through Rapier's step (`VehicleModel::needs_physics_step`).
    physics_needed: bool,
}

fn steps_for(period_s: f64, dt_s: f64) -> u64 {
    ((period_s / dt_s).round() as u64).max(1)
}

impl World {
    /// Builds the world with the built-in planners: validates everything, spawns the road and
    /// the vehicles.
    pub fn new(
        config: SimConfig,
        specs: &[VehicleSpec],
        options: &RunOptions,
        recorder: Recorder,
    ) -> Result<Self, SimError> {
        Self::with_registry(
            config,
            specs,
            options,
            recorder,
            &BehaviourRegistry::builtin(),
        )
    }

    /// [`World::new`] with the planners of `registry` (a user's own among them).
    pub fn with_registry(
        config: SimConfig,
        specs: &[VehicleSpec],
        options: &RunOptions,
        recorder: Recorder,
        registry: &BehaviourRegistry,
    ) -> Result<Self, SimError> {
        config.validate()?;
        crate::config::validate_vehicles(&config, specs)?;
        let lanes = std::sync::Arc::new(config.lanes()?);
        // The physics world owns the step from here on (`config.dt_s` is its input only).
        let mut physics = PhysicsWorld::new(config.dt_s)?;
        let dt_s = physics.dt_s();
        // Built from the lanes, around a local origin near the road (module doc of
        // `vehicles::PhysicsWorld`); the vehicles report the road's own coordinates.
        physics.add_lane_road(&lanes);
        let mut agents = Vec::with_capacity(specs.len());
        for (index, spec) in specs.iter().enumerate() {
            agents.push(Agent::spawn(
                &config,
                &lanes,
                &mut physics,
                index,
                spec,
                registry,
                options.planner_override.as_deref(),
            )?);
        }
        let agents_need_physics = agents.iter().any(|a| a.vehicle.needs_physics_step());
        let simulated_names: Vec<String> = specs.iter().map(|s| s.name.clone()).collect();
        let recorded = recorded::RecordedFleet::new(
            &config.recorded_traffic,
            &simulated_names,
            &config.idm,
            (config.mu, config.planner_brake_margin),
            &mut physics,
        )?;
        let bus = V2vBus::new(
            config.v2v.clone(),
            crate::rng::SplitMix64::derive(options.seed, 1),
        )?;
        let mut safety = SafetyMonitor::new(config.safety.clone(), lanes.clone())?;
        if !recorded.is_empty() {
            safety.set_recorded_from(agents.len() as VehicleId);
        }
        let metrics = agents
            .iter()
            .map(|a| {
                VehicleMetrics::new(a.spec.name.clone())
                    .with_paper_metrics(lanes.clone(), a.spec.target_speed_mps)
            })
            .collect();
        let traffic = TrafficMetrics::new(
            lanes.clone(),
            agents
                .iter()
                .map(|a| {
                    (
                        a.spec.name.clone(),
                        a.spec.driver.class(options.planner_override.as_deref()),
                        a.spec.target_speed_mps,
                    )
                })
                .collect(),
        );
        let recording = RecordingObserver::new(recorder, &lanes)?;
        Ok(Self {
            steps_per_plan: steps_for(config.planner_period_s, dt_s),
            steps_per_log: steps_for(config.log_period_s, dt_s),
            steps_per_field: steps_for(config.field_log_period_s, dt_s),
            steps_per_safety: steps_for(config.safety_period_s, dt_s),
            config,
            lanes,
            physics,
            agents,
            recorded,
            bus,
            safety,
            run_log: RunLog::new(metrics, options.keep_time_series),
            traffic,
            recorded_track: options.keep_time_series.then(Vec::new),
            recording,
            observers: Vec::new(),
            events: Vec::new(),
            planner_stats: PlannerStatsObserver::default(),
            step_index: 0,
            profile: options.profile.then(ProfileObserver::default),
            timing: options.profile,
            planning_pool: None,
            reported_collisions: 0,
            reported_edge_contacts: 0,
            goal_times: vec![None; specs.len()],
            left_map: false,
            physics_needed: agents_need_physics,
        })
    }

    /// Adds an observer, called after the built-in ones.
    pub fn add_observer(&mut self, observer: Box<dyn TickObserver>) {
        self.timing |= observer.wants_phase_times();
        self.observers.push(observer);
    }

    /// Simulated time now (s).
    pub fn time_s(&self) -> f64 {
        self.step_index as f64 * self.physics.dt_s()
    }

    /// Every vehicle's kinematic state now, in id order (for a caller stepping the world by
    /// hand with [`Self::step`], e.g. a reinforcement-learning environment).
    pub fn kinematics(&self) -> Vec<Kinematics> {
        self.agents
            .iter()
            .map(|a| a.vehicle.kinematics(&self.physics))
            .collect()
    }

    /// Decide the vehicles' plans on `pool` instead of rayon's current pool (the global one
    /// outside a sweep). For embedders: a pool created in the current process keeps a forked
    /// child (Python's multiprocessing) from waiting on the global pool's threads, which a fork
    /// does not copy; a one-thread pool plans in sequence. Results are the same bit for bit
    /// whatever the pool.
    pub fn plan_on(&mut self, pool: std::sync::Arc<rayon::ThreadPool>) {
        self.planning_pool = Some(pool);
    }

    /// Physics steps per planning cycle (`planner_period_s / dt_s`, at least one).
    pub fn steps_per_plan(&self) -> u64 {
        self.steps_per_plan
    }

    /// Number of physics steps of the whole run.
    pub fn total_steps(&self) -> u64 {
        (self.config.duration_s / self.physics.dt_s()).round() as u64
    }

    /// Runs to the end; `progress(fraction)` is called about a hundred times.
    pub fn run(self, progress: impl FnMut(f64)) -> Result<RunOutcome, SimError> {
        self.run_until(progress, || false)
    }

    /// [`Self::run`], stopping with [`SimError::Interrupted`] as soon as `interrupted()` is true
    /// (checked before every physics step; e.g. a flag set by a signal handler). The recording
    /// of an interrupted run is discarded with the world.
    pub fn run_until(
        mut self,
        mut progress: impl FnMut(f64),
        interrupted: impl Fn() -> bool,
    ) -> Result<RunOutcome, SimError> {
        let total = self.total_steps();
        let report_every = (total / 100).max(1);
        while self.step_index < total && !self.left_map {
            if interrupted() {
                return Err(SimError::Interrupted { t_s: self.time_s() });
            }
            match self.step() {
                Ok(()) => {}
                // Leaving the map ends the run with an event, not an error.
                Err(SimError::RoadEnd { vehicle, t_s, lane }) => {
                    self.leave_map(&vehicle, t_s, lane)?;
                    break;
                }
                Err(e) => return Err(e),
            }
            if self.step_index.is_multiple_of(report_every) {
                progress(self.step_index as f64 / total as f64);
            }
        }
        self.finish()
    }

    /// Advances one physics step in the fixed order of the tick (module doc).
    pub fn step(&mut self) -> Result<(), SimError> {
        let t_s = self.time_s();
        // 1. V2V delivery.
        let started = self.clock();
        self.bus.deliver(t_s);
        self.phase_since(Phase::V2v, started)?;
        // 2. Planning, by id.
        if self.step_index.is_multiple_of(self.steps_per_plan) {
            // Timed inside (the observers' share goes to metrics and recording).
            self.plan_all(t_s)?;
        }
        // 3.–4. Tracking, forces.
        let dt_s = self.physics.dt_s();
        let (mut tracking, mut forces) = (Duration::ZERO, Duration::ZERO);
        for agent in &mut self.agents {
            let started = self.timing.then(Instant::now);
            let kin = agent.vehicle.kinematics(&self.physics);
            if agent.path.is_empty() {
                let v = agent.spec.target_speed_mps;
                agent.path = lane_path(
                    &self.lanes,
                    agent.spec.lane.id(),
                    agent.spec.y_offset_m,
                    [kin.x_m, kin.y_m],
                    t_s,
                    |_| v,
                );
            }
            let controls = agent.tracker.update(&kin, &agent.path, dt_s);
            agent.vehicle.set_controls(controls);
            let tracked = self.timing.then(Instant::now);
            agent.vehicle.advance(&mut self.physics, self.config.mu);
            if let (Some(started), Some(tracked)) = (started, tracked) {
                tracking += tracked - started;
                forces += tracked.elapsed();
            }
        }
        self.phase_took(Phase::Tracking, tracking)?;
        self.phase_took(Phase::TireForces, forces)?;
        let started = self.clock();
        // Recorded traffic: kinematic targets for this step (`recorded` module doc).
        if !self.recorded.is_empty() {
            self.advance_recorded(t_s)?;
        }
        // Skipped when no car needs it (`VehicleModel::needs_physics_step`): every car then
        // moves itself, and nothing of the run reads Rapier's bodies.
        if self.physics_needed {
            self.physics.step();
        }
        self.phase_since(Phase::Physics, started)?;
        self.step_index += 1;
        let t_s = self.time_s();
        // 5. Safety checks.
        let need_log = self.step_index.is_multiple_of(self.steps_per_log);
        let need_safety = self.step_index.is_multiple_of(self.steps_per_safety);
        if need_safety || need_log {
            let started = self.clock();
            let kins: Vec<Kinematics> = self
                .agents
                .iter()
                .map(|a| a.vehicle.kinematics(&self.physics))
                .collect();
            for (agent, kin) in self.agents.iter().zip(&kins) {
                check_finite(t_s, &agent.spec.name, kin)?;
                if let Some(lane) = lanes::past_road_end(
                    &self.lanes,
                    agent.lane,
                    kin,
                    0.5 * agent.vehicle.params().length_m,
                ) {
                    return Err(SimError::RoadEnd {
                        vehicle: agent.spec.name.clone(),
                        t_s,
                        lane,
                    });
                }
            }
            let mut bodies = self.body_states(&kins);
            bodies.extend(self.recorded.bodies());
            if need_safety {
                self.safety
                    .check(t_s, &bodies, self.config.safety_period_s)
                    .map_err(|e| SimError::Diverged {
                        t_s,
                        what: e.to_string(),
                    })?;
                self.report_new_collisions()?;
            }
            self.phase_since(Phase::Safety, started)?;
            // 6. Observers (goals first: their events are in this instant's log).
            if need_log {
                self.check_goals(t_s, &kins)?;
                self.log_instant(t_s, &kins, &bodies)?;
            }
        }
        Ok(())
    }

    /// Now, if some observer wants phase times.
    fn clock(&self) -> Option<Instant> {
        self.timing.then(Instant::now)
    }

    /// Tells the observers that want phase times that `phase` took the time since `started`
    /// (from [`Self::clock`]).
    fn phase_since(&mut self, phase: Phase, started: Option<Instant>) -> Result<(), SimError> {
        match started {
            Some(started) => self.phase_took(phase, started.elapsed()),
            None => Ok(()),
        }
    }

    /// Tells the observers that want phase times that `phase` took `wall`.
    fn phase_took(&mut self, phase: Phase, wall: Duration) -> Result<(), SimError> {
        if !self.timing {
            return Ok(());
        }
        self.each_observer(|o| {
            if o.wants_phase_times() {
                o.on_phase(phase, wall);
            }
            Ok(())
        })
    }

    /// Every observer, built-in first.
    fn each_observer(
        &mut self,
        mut f: impl FnMut(&mut dyn TickObserver) -> Result<(), SimError>,
    ) -> Result<(), SimError> {
        if let Some(profile) = self.profile.as_mut() {
            f(profile)?;
        }
        f(&mut self.planner_stats)?;
        f(&mut self.run_log)?;
        f(&mut self.traffic)?;
        f(&mut self.recording)?;
        for observer in &mut self.observers {
            f(observer.as_mut())?;
        }
        Ok(())
    }

    /// Records an event in the run's log and tells the observers.
    fn event(&mut self, event: SimEvent) -> Result<(), SimError> {
        self.each_observer(|o| o.on_event(&event))?;
        self.events.push(event);
        Ok(())
    }

    /// The name of vehicle `id` (simulated or recorded), or `vehicle ID`.
    fn name_of(names: &[String], id: VehicleId) -> String {
        names
            .get(id as usize)
            .cloned()
            .unwrap_or_else(|| format!("vehicle {id}"))
    }

    /// The vehicles' chassis boxes as the safety checks and the recording see them: the
    /// collider's own box (centred on the wheelbase midpoint, not on the CoG).
    fn body_states(&self, kins: &[Kinematics]) -> Vec<BodyState> {
        self.agents
            .iter()
            .zip(kins)
            .map(|(agent, k)| {
                let (s, c) = k.yaw_rad.sin_cos();
                let body_box = agent.vehicle.body_box();
                let [ox, oy, _] = body_box.center_offset_m;
                let [hx, hy, hz] = body_box.half_extents_m;
                // Velocity of the box centre: CoG velocity + ω × offset.
                let vx_mps = k.vx_body_mps * c - k.vy_body_mps * s;
                let vy_mps = k.vx_body_mps * s + k.vy_body_mps * c;
                let off_x = ox * c - oy * s;
                let off_y = ox * s + oy * c;
                BodyState {
                    id: agent.id,
                    x_m: k.x_m + off_x,
                    y_m: k.y_m + off_y,
                    yaw_rad: k.yaw_rad,
                    vx_mps: vx_mps - k.yaw_rate_radps * off_y,
                    vy_mps: vy_mps + k.yaw_rate_radps * off_x,
                    yaw_rate_radps: k.yaw_rate_radps,
                    length_m: 2.0 * hx,
                    width_m: 2.0 * hy,
                    height_m: 2.0 * hz,
                }
            })
            .collect()
    }

    fn report_new_collisions(&mut self) -> Result<(), SimError> {
        let names = self.names();
        while self.reported_collisions < self.safety.collision_events().len() {
            let event = self.safety.collision_events()[self.reported_collisions].clone();
            let ids: Vec<VehicleId> = self
                .agents
                .iter()
                .map(|a| a.id)
                .filter(|id| event.involves(*id))
                .collect();
            let caused_by_replay = event.caused_by_replay;
            self.event(SimEvent::Collision {
                vehicle_a: Self::name_of(&names, event.id_a),
                vehicle_b: Self::name_of(&names, event.id_b),
                event,
            })?;
            // A collision caused by the replay is not the simulated vehicle's (module doc of
            // the safety monitor's `recorded_pairs`): its metrics do not count it.
            if !caused_by_replay {
                self.each_observer(|o| {
                    o.on_collision(&ids);
                    Ok(())
                })?;
            }
            self.reported_collisions += 1;
        }
        while self.reported_edge_contacts < self.safety.edge_contact_events().len() {
            let event = self.safety.edge_contact_events()[self.reported_edge_contacts].clone();
            let vehicle = names.get(event.id as usize).cloned().unwrap_or_default();
            self.event(SimEvent::EdgeContact {
                t_s: event.t_s,
                vehicle,
                edge: event.edge,
            })?;
            self.each_observer(|o| {
                o.on_collision(&[event.id]);
                Ok(())
            })?;
            self.reported_edge_contacts += 1;
        }
        Ok(())
    }

    /// Every vehicle's name by id, the recorded ones after the simulated ones.
    fn names(&self) -> Vec<String> {
        self.agents
            .iter()
            .map(|a| a.spec.name.clone())
            .chain(self.recorded.names().map(str::to_string))
            .collect()
    }

    /// Moves the recorded traffic from `t_s` to the end of this step and logs the handovers.
    fn advance_recorded(&mut self, t_s: f64) -> Result<(), SimError> {
        let simulated = if self.recorded.needs_simulated_bodies() {
            let kins: Vec<Kinematics> = self
                .agents
                .iter()
                .map(|a| a.vehicle.kinematics(&self.physics))
                .collect();
            self.body_states(&kins)
        } else {
            Vec::new()
        };
        let handovers = self.recorded.advance(
            t_s,
            // The world's clock after the step (`Self::time_s`), not t + dt rounded apart.
            (self.step_index + 1) as f64 * self.physics.dt_s(),
            &self.lanes,
            &simulated,
            &mut self.physics,
        )?;
        if !handovers.is_empty() {
            let names = self.names();
            for handover in handovers {
                self.event(SimEvent::RecordedHandover {
                    t_s: handover.t_s,
                    leader: Self::name_of(&names, handover.leader),
                    vehicle: handover.name,
                    gap_m: handover.gap_m,
                    safe_gap_m: handover.safe_gap_m,
                    speed_mps: handover.speed_mps,
                    approach_rate_mps: handover.approach_rate_mps,
                })?;
            }
        }
        Ok(())
    }
}

fn check_finite(t_s: f64, name: &str, k: &Kinematics) -> Result<(), SimError> {
    let values = [
        k.x_m,
        k.y_m,
        k.z_m,
        k.yaw_rad,
        k.speed_mps,
        k.yaw_rate_radps,
    ];
    if values.iter().all(|v| v.is_finite()) && k.z_m.abs() < 50.0 {
        Ok(())
    } else {
        Err(SimError::Diverged {
            t_s,
            what: format!("vehicle {name}: state {values:?}"),
        })
    }
}

// A world can move to another thread (observers and behaviours are `Send`): e.g. a Python
// binding releases the GIL while the world advances.
const _: fn() = || {
    fn send<T: Send>() {}
    send::<World>();
};
