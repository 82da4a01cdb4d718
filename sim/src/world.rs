//! The closed-loop simulation: one `World` owns the physics, the vehicles, their planners and
//! trackers, the V2V bus, the safety monitor, the metrics and the recorder, and advances them in
//! the fixed order of the tick (README, "Layout"):
//!
//! 1. V2V delivery → 2. planning (each vehicle at its own period, visited by id) and broadcast →
//! 3. tracking → 4. tire and suspension forces, rapier step → 5. parry safety checks →
//! 6. metrics, time series and recording (on their own clock).
//!
//! Same configuration + same seed ⇒ bitwise identical results: vehicles are visited by index,
//! every map is ordered, and the only randomness (V2V drops) comes from a seeded stream.

use std::time::Instant;

use planner::{
    Neighbour, PathPoint, PfPlanner, Plan, PlanRequest, PlannerKind, SharedLocalPath, VehicleId,
    VehicleShape, VehicleState,
};
use serde::{Deserialize, Serialize};
use vehicles::{Kinematics, PhysicsWorld, Tracker, Vehicle, VehicleParams};

use crate::config::{Driver, SimConfig, VehicleSpec};
use crate::error::SimError;
use crate::idm::{RoadUser, find_leader, idm_acceleration, speed_after_distance};
use crate::metrics::{MetricsSample, VehicleMetrics, VehicleMetricsSummary};
use crate::recording::{EventLevel, Recorder};
use crate::safety::{BodyState, SafetyMonitor, SafetySummary};

fn rec(e: crate::recording::RecordingError) -> SimError {
    SimError::Recording(e.to_string())
}
use crate::v2v::{V2vBus, V2vStats};

/// One row of the time series (`--csv`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimeSeriesRow {
    /// Simulated time (s).
    pub t_s: f64,
    /// Vehicle name.
    pub vehicle: String,
    /// Position (m).
    pub x_m: f64,
    /// Position (m).
    pub y_m: f64,
    /// Heading (rad).
    pub yaw_rad: f64,
    /// Yaw rate (rad/s).
    pub yaw_rate_radps: f64,
    /// Sideslip at the centre of gravity (rad).
    pub sideslip_rad: f64,
    /// Speed (m/s).
    pub speed_mps: f64,
    /// Speed the current plan asks for now (m/s).
    pub planned_speed_mps: f64,
    /// Longitudinal acceleration, body frame (m/s²).
    pub accel_long_mps2: f64,
    /// Lateral acceleration, body frame (m/s²).
    pub accel_lat_mps2: f64,
}

impl TimeSeriesRow {
    /// The row of vehicle `name` for one metrics sample and the speed its plan asked for.
    pub fn from_sample(name: &str, sample: &MetricsSample, planned_speed_mps: f64) -> Self {
        Self {
            t_s: sample.t_s,
            vehicle: name.to_string(),
            x_m: sample.x_m,
            y_m: sample.y_m,
            yaw_rad: sample.yaw_rad,
            yaw_rate_radps: sample.yaw_rate_radps,
            sideslip_rad: sample.sideslip_rad,
            speed_mps: sample.speed_mps,
            planned_speed_mps,
            accel_long_mps2: sample.accel_long_mps2,
            accel_lat_mps2: sample.accel_lat_mps2,
        }
    }

    /// CSV header, in the order of [`TimeSeriesRow::csv_line`].
    pub const CSV_HEADER: &'static str = "t_s,vehicle,x_m,y_m,yaw_rad,yaw_rate_radps,sideslip_rad,speed_mps,planned_speed_mps,accel_long_mps2,accel_lat_mps2";

    /// One CSV line (no newline).
    pub fn csv_line(&self) -> String {
        format!(
            "{:.4},{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6}",
            self.t_s,
            self.vehicle,
            self.x_m,
            self.y_m,
            self.yaw_rad,
            self.yaw_rate_radps,
            self.sideslip_rad,
            self.speed_mps,
            self.planned_speed_mps,
            self.accel_long_mps2,
            self.accel_lat_mps2
        )
    }
}

/// Planner timing and fault counters over a run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlannerStats {
    /// Planning cycles run.
    pub plans: u64,
    /// Cycles that returned a fallback plan.
    pub fallbacks: u64,
    /// Median wall time of one cycle (µs). Wall-clock: not part of the determinism contract.
    pub p50_plan_us: f64,
    /// 99th percentile wall time of one cycle (µs).
    pub p99_plan_us: f64,
}

/// The result of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunOutcome {
    /// Simulated time (s).
    pub duration_s: f64,
    /// Exact safety results.
    pub safety: SafetySummary,
    /// Per-vehicle metrics, in vehicle order.
    pub vehicles: Vec<VehicleMetricsSummary>,
    /// Planner counters.
    pub planner_stats: PlannerStats,
    /// V2V counters.
    pub v2v: V2vStats,
    /// Time series at the log period (empty unless requested).
    pub time_series: Vec<TimeSeriesRow>,
    /// Event log lines (collisions, near misses, fallbacks), in time order.
    pub events: Vec<String>,
}

/// A vehicle of the world with its decision making.
struct Agent {
    id: VehicleId,
    spec: VehicleSpec,
    shape: VehicleShape,
    vehicle: Vehicle,
    planner: Option<PfPlanner>,
    tracker: Tracker,
    /// The path being tracked (plan output or lane-keeping line).
    path: Vec<PathPoint>,
    last_plan: Option<Plan>,
    metrics: VehicleMetrics,
    /// Whether a vehicle that started in the ending lane has crossed the divider yet.
    merged: bool,
}

/// Options of one run that are not part of the scenario.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Override every planner vehicle's planner kind.
    pub planner_override: Option<PlannerKind>,
    /// Seed of the run's random streams (V2V drops).
    pub seed: u64,
    /// Keep the time series in the outcome (for `--csv`).
    pub keep_time_series: bool,
}

/// The simulation.
pub struct World {
    config: SimConfig,
    physics: PhysicsWorld,
    agents: Vec<Agent>,
    bus: V2vBus,
    safety: SafetyMonitor,
    recorder: Recorder,
    keep_time_series: bool,
    time_series: Vec<TimeSeriesRow>,
    events: Vec<String>,
    plan_times_us: Vec<f64>,
    fallbacks: u64,
    step_index: u64,
    steps_per_plan: u64,
    steps_per_log: u64,
    steps_per_field: u64,
    steps_per_safety: u64,
    reported_collisions: usize,
    reported_edge_contacts: usize,
}

fn steps_for(period_s: f64, dt_s: f64) -> u64 {
    ((period_s / dt_s).round() as u64).max(1)
}

impl World {
    /// Builds the world: validates everything, spawns the road and the vehicles.
    pub fn new(
        config: SimConfig,
        specs: &[VehicleSpec],
        options: &RunOptions,
        recorder: Recorder,
    ) -> Result<Self, SimError> {
        config.validate()?;
        crate::config::validate_vehicles(&config, specs)?;
        let mut physics = PhysicsWorld::new(config.dt_s)?;
        physics.add_merge_road(&config.road);
        let mut agents = Vec::with_capacity(specs.len());
        for (index, spec) in specs.iter().enumerate() {
            agents.push(Self::spawn_agent(
                &config,
                &mut physics,
                index,
                spec,
                options,
            )?);
        }
        let bus = V2vBus::new(
            config.v2v.clone(),
            crate::rng::SplitMix64::derive(options.seed, 1),
        )?;
        let safety =
            SafetyMonitor::new(config.safety.clone(), &config.road).map_err(SimError::from)?;
        let mut world = Self {
            steps_per_plan: steps_for(config.planner_period_s, config.dt_s),
            steps_per_log: steps_for(config.log_period_s, config.dt_s),
            steps_per_field: steps_for(config.field_log_period_s, config.dt_s),
            steps_per_safety: steps_for(config.safety_period_s, config.dt_s),
            config,
            physics,
            agents,
            bus,
            safety,
            recorder,
            keep_time_series: options.keep_time_series,
            time_series: Vec::new(),
            events: Vec::new(),
            plan_times_us: Vec::new(),
            fallbacks: 0,
            step_index: 0,
            reported_collisions: 0,
            reported_edge_contacts: 0,
        };
        world.recorder.log_road(&world.config.road).map_err(rec)?;
        Ok(world)
    }

    fn spawn_agent(
        config: &SimConfig,
        physics: &mut PhysicsWorld,
        index: usize,
        spec: &VehicleSpec,
        options: &RunOptions,
    ) -> Result<Agent, SimError> {
        let params = VehicleParams::preset(&spec.preset)?;
        let y_m = config.road.lane_center_y_m(spec.lane) + spec.y_offset_m;
        let vehicle = Vehicle::spawn(physics, &params, spec.x_m, y_m, 0.0, spec.speed_mps)?;
        let shape = vehicle.shape(VehicleShape::default().max_brake_decel_mps2);
        let planner = match &spec.driver {
            Driver::Prescribed { path_planner, .. } => Some(
                PfPlanner::new(*path_planner, config.planner.clone(), config.road.clone())
                    .map_err(|source| SimError::Planner {
                        vehicle: spec.name.clone(),
                        source,
                    })?,
            ),
            Driver::Planner(kind) => {
                let kind = options.planner_override.unwrap_or(*kind);
                Some(
                    PfPlanner::new(kind, config.planner.clone(), config.road.clone()).map_err(
                        |source| SimError::Planner {
                            vehicle: spec.name.clone(),
                            source,
                        },
                    )?,
                )
            }
            Driver::LaneKeeping | Driver::Idm => None,
        };
        let tracker = Tracker::new(config.tracker.clone(), &params);
        Ok(Agent {
            id: index as VehicleId,
            spec: spec.clone(),
            shape,
            vehicle,
            planner,
            tracker,
            path: Vec::new(),
            last_plan: None,
            metrics: VehicleMetrics::new(spec.name.clone())
                .with_paper_metrics(&config.road, spec.target_speed_mps),
            merged: spec.lane == planner::Lane::Upper,
        })
    }

    /// Simulated time now (s).
    pub fn time_s(&self) -> f64 {
        self.step_index as f64 * self.config.dt_s
    }

    /// Number of physics steps of the whole run.
    pub fn total_steps(&self) -> u64 {
        (self.config.duration_s / self.config.dt_s).round() as u64
    }

    /// Runs to the end; `progress(fraction)` is called about a hundred times.
    pub fn run(mut self, mut progress: impl FnMut(f64)) -> Result<RunOutcome, SimError> {
        let total = self.total_steps();
        let report_every = (total / 100).max(1);
        while self.step_index < total {
            self.step()?;
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
        self.bus.deliver(t_s);
        // 2. Planning, by id.
        if self.step_index.is_multiple_of(self.steps_per_plan) {
            self.plan_all(t_s)?;
        }
        // 3.–4. Tracking, forces.
        let dt_s = self.config.dt_s;
        for agent in &mut self.agents {
            let kin = agent.vehicle.kinematics(&self.physics);
            if agent.path.is_empty() {
                agent.path = lane_keeping_path(&self.config, &agent.spec, &kin, t_s);
            }
            let controls = agent.tracker.update(&kin, &agent.path, dt_s);
            agent.vehicle.set_controls(controls);
            agent
                .vehicle
                .apply_forces(&mut self.physics, self.config.mu);
        }
        self.physics.step();
        self.step_index += 1;
        let t_s = self.time_s();
        // 5. Safety checks.
        let need_log = self.step_index.is_multiple_of(self.steps_per_log);
        let need_safety = self.step_index.is_multiple_of(self.steps_per_safety);
        if need_safety || need_log {
            let kins: Vec<Kinematics> = self
                .agents
                .iter()
                .map(|a| a.vehicle.kinematics(&self.physics))
                .collect();
            for (agent, kin) in self.agents.iter().zip(&kins) {
                check_finite(t_s, &agent.spec.name, kin)?;
            }
            let bodies = self.body_states(&kins);
            if need_safety {
                self.safety
                    .check(t_s, &bodies, self.config.safety_period_s)
                    .map_err(|e| SimError::Diverged {
                        t_s,
                        what: e.to_string(),
                    })?;
                self.report_new_collisions()?;
            }
            // 6. Metrics, time series, recording.
            if need_log {
                self.log_instant(t_s, &kins, &bodies)?;
            }
        }
        Ok(())
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
        let collisions = self.safety.collision_events();
        while self.reported_collisions < collisions.len() {
            let event = &collisions[self.reported_collisions];
            let text = event.describe(&names);
            self.recorder
                .log_event(&text, EventLevel::Error)
                .map_err(rec)?;
            self.events.push(text);
            for agent in &mut self.agents {
                if event.involves(agent.id) {
                    agent.metrics.set_collided();
                }
            }
            self.reported_collisions += 1;
        }
        let contacts = self.safety.edge_contact_events();
        while self.reported_edge_contacts < contacts.len() {
            let event = &contacts[self.reported_edge_contacts];
            let name = names.get(event.id as usize).cloned().unwrap_or_default();
            let text = format!(
                "t = {:.3} s: vehicle {name} hit the {:?} road edge",
                event.t_s, event.edge
            );
            self.recorder
                .log_event(&text, EventLevel::Error)
                .map_err(rec)?;
            self.events.push(text);
            for agent in &mut self.agents {
                if agent.id == event.id {
                    agent.metrics.set_collided();
                }
            }
            self.reported_edge_contacts += 1;
        }
        Ok(())
    }

    fn names(&self) -> Vec<String> {
        self.agents.iter().map(|a| a.spec.name.clone()).collect()
    }

    fn plan_all(&mut self, t_s: f64) -> Result<(), SimError> {
        let kins: Vec<Kinematics> = self
            .agents
            .iter()
            .map(|a| a.vehicle.kinematics(&self.physics))
            .collect();
        let states: Vec<VehicleState> = kins
            .iter()
            .map(|k| VehicleState {
                x_m: k.x_m,
                y_m: k.y_m,
                yaw_rad: k.yaw_rad,
                speed_mps: k.speed_mps,
            })
            .collect();
        let ids: Vec<VehicleId> = self.agents.iter().map(|a| a.id).collect();
        let mut broadcasts: Vec<SharedLocalPath> = Vec::new();
        for index in 0..self.agents.len() {
            check_finite(t_s, &self.agents[index].spec.name, &kins[index])?;
            let neighbours: Vec<Neighbour> = self
                .agents
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != index)
                .map(|(j, other)| Neighbour {
                    id: other.id,
                    state: states[j],
                    shape: other.shape,
                })
                .collect();
            if self.agents[index].spec.driver == Driver::Idm {
                let users: Vec<RoadUser> = self
                    .agents
                    .iter()
                    .zip(&kins)
                    .map(|(a, k)| RoadUser {
                        x_m: k.x_m,
                        y_m: k.y_m,
                        speed_mps: k.speed_mps,
                        length_m: a.shape.length_m,
                    })
                    .collect();
                let leader = find_leader(&self.config.idm, &users, index);
                let agent = &mut self.agents[index];
                let v = kins[index].speed_mps;
                let accel_mps2 = idm_acceleration(
                    &self.config.idm,
                    v,
                    agent.spec.target_speed_mps,
                    leader.as_ref(),
                );
                agent.path = lane_path(&self.config, &agent.spec, &kins[index], t_s, |d| {
                    speed_after_distance(v, accel_mps2, d)
                });
                continue;
            }
            let agent = &mut self.agents[index];
            let Some(planner) = agent.planner.as_mut() else {
                agent.path = lane_keeping_path(&self.config, &agent.spec, &kins[index], t_s);
                continue;
            };
            let shared_paths = if agent.spec.connected {
                self.bus.fresh_paths(agent.id, t_s)
            } else {
                Vec::new()
            };
            let request = PlanRequest {
                time_s: t_s,
                ego_id: agent.id,
                ego: states[index],
                ego_shape: agent.shape,
                target_speed_mps: agent.spec.target_speed_mps,
                mu: self.config.mu,
                neighbours: &neighbours,
                shared_paths: &shared_paths,
            };
            let started = Instant::now();
            let plan = planner.plan(&request).map_err(|source| SimError::Planner {
                vehicle: agent.spec.name.clone(),
                source,
            })?;
            self.plan_times_us
                .push(started.elapsed().as_secs_f64() * 1e6);
            if let Some(reason) = &plan.fallback {
                self.fallbacks += 1;
                let text = format!(
                    "t = {t_s:.2} s: planner fallback of {}: {reason:?}",
                    agent.spec.name
                );
                self.recorder
                    .log_event(&text, EventLevel::Warn)
                    .map_err(rec)?;
                self.events.push(text);
            }
            if self.step_index.is_multiple_of(self.steps_per_field) && self.recorder.is_enabled() {
                log_field(&mut self.recorder, planner, &request, &agent.spec.name)?;
            }
            let plan = match &agent.spec.driver {
                Driver::Prescribed { speed_profile, .. } if plan.fallback.is_none() => {
                    plan.with_speed_profile(speed_profile)
                }
                _ => plan,
            };
            agent.path = plan.path.clone();
            if agent.spec.connected {
                broadcasts.push(plan.shared.clone());
            }
            agent.last_plan = Some(plan);
        }
        // Broadcast after everybody planned on the same information (a synchronous round).
        for message in &broadcasts {
            let receivers: Vec<VehicleId> = ids
                .iter()
                .copied()
                .filter(|id| self.agents[*id as usize].spec.connected)
                .collect();
            self.bus.broadcast(t_s, message, &receivers);
        }
        Ok(())
    }

    fn log_instant(
        &mut self,
        t_s: f64,
        kins: &[Kinematics],
        bodies: &[BodyState],
    ) -> Result<(), SimError> {
        if self.recorder.is_enabled() {
            let names = self.names();
            self.recorder.set_time(t_s).map_err(rec)?;
            self.recorder.log_vehicles(bodies, &names).map_err(rec)?;
        }
        let y_lane_m = self.config.road.y_lane_m();
        for (agent, k) in self.agents.iter_mut().zip(kins) {
            if !agent.merged && k.y_m > y_lane_m {
                agent.merged = true;
                let text = format!(
                    "t = {t_s:.2} s: {} crossed the lane divider at x = {:.1} m",
                    agent.spec.name, k.x_m
                );
                self.recorder
                    .log_event(&text, EventLevel::Info)
                    .map_err(rec)?;
                self.events.push(text);
            }
            let planned_speed_mps = planned_speed_at(&agent.path, t_s).unwrap_or(k.speed_mps);
            let sample = MetricsSample {
                t_s,
                x_m: k.x_m,
                y_m: k.y_m,
                yaw_rad: k.yaw_rad,
                yaw_rate_radps: k.yaw_rate_radps,
                sideslip_rad: k.sideslip_rad,
                speed_mps: k.speed_mps,
                accel_long_mps2: k.accel_long_mps2,
                accel_lat_mps2: k.accel_lat_mps2,
            };
            agent
                .metrics
                .push(&sample)
                .map_err(|e| SimError::Diverged {
                    t_s,
                    what: format!("metrics of {}: {e}", agent.spec.name),
                })?;
            if self.recorder.is_enabled() {
                let name = &agent.spec.name;
                self.recorder
                    .log_scalars(
                        name,
                        &[
                            ("sideslip_rad", k.sideslip_rad),
                            ("yaw_rad", k.yaw_rad),
                            ("yaw_rate_radps", k.yaw_rate_radps),
                            ("speed_mps", k.speed_mps),
                            ("planned_speed_mps", planned_speed_mps),
                        ],
                    )
                    .map_err(rec)?;
                self.recorder
                    .log_planned_path(name, &agent.path)
                    .map_err(rec)?;
                if agent.spec.connected {
                    let received = self.bus.fresh_paths(agent.id, t_s);
                    self.recorder
                        .log_received_paths(name, &received)
                        .map_err(rec)?;
                }
            }
            if self.keep_time_series {
                self.time_series.push(TimeSeriesRow::from_sample(
                    &agent.spec.name,
                    &sample,
                    planned_speed_mps,
                ));
            }
        }
        Ok(())
    }

    fn finish(mut self) -> Result<RunOutcome, SimError> {
        let safety = self.safety.summary();
        if safety.near_miss {
            let text = format!(
                "near miss: min gap {} m, min TTC {}",
                safety
                    .min_gap_m
                    .map(|g| format!("{g:.2}"))
                    .unwrap_or_else(|| "-".into()),
                safety
                    .min_ttc_s
                    .map(|t| format!("{t:.2} s"))
                    .unwrap_or_else(|| "none".into())
            );
            self.recorder
                .log_event(&text, EventLevel::Warn)
                .map_err(rec)?;
            self.events.push(text);
        }
        let mut times = self.plan_times_us.clone();
        times.sort_by(f64::total_cmp);
        let planner_stats = PlannerStats {
            plans: times.len() as u64,
            fallbacks: self.fallbacks,
            p50_plan_us: percentile(&times, 0.50),
            p99_plan_us: percentile(&times, 0.99),
        };
        let vehicles = self.agents.iter().map(|a| a.metrics.summary()).collect();
        let v2v = self.bus.stats();
        let duration_s = self.time_s();
        self.recorder.finish().map_err(rec)?;
        Ok(RunOutcome {
            duration_s,
            safety,
            vehicles,
            planner_stats,
            v2v,
            time_series: self.time_series,
            events: self.events,
        })
    }
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let rank = (q * (sorted.len() - 1) as f64).round() as usize;
    sorted[rank.min(sorted.len() - 1)]
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

/// The speed the path asks for at time `t_s` (linear in time between its points).
fn planned_speed_at(path: &[PathPoint], t_s: f64) -> Option<f64> {
    let first = path.first()?;
    if t_s <= first.t_s {
        return Some(first.speed_mps);
    }
    for pair in path.windows(2) {
        if t_s <= pair[1].t_s {
            let span = pair[1].t_s - pair[0].t_s;
            let w = if span > 0.0 {
                (t_s - pair[0].t_s) / span
            } else {
                1.0
            };
            return Some(pair[0].speed_mps + w * (pair[1].speed_mps - pair[0].speed_mps));
        }
    }
    path.last().map(|p| p.speed_mps)
}

/// A straight path along the spawn lane's centre at the target speed (driver without planner).
fn lane_keeping_path(
    config: &SimConfig,
    spec: &VehicleSpec,
    k: &Kinematics,
    t_s: f64,
) -> Vec<PathPoint> {
    let v = spec.target_speed_mps;
    lane_path(config, spec, k, t_s, |_| v)
}

/// A straight path along the spawn lane's centre, 50 m ahead in 2.5 m steps, with the speed
/// `speed_at(distance ahead)` and times integrated from the mean speed of each step.
fn lane_path(
    config: &SimConfig,
    spec: &VehicleSpec,
    k: &Kinematics,
    t_s: f64,
    speed_at: impl Fn(f64) -> f64,
) -> Vec<PathPoint> {
    const STEP_M: f64 = 2.5;
    const POINTS: usize = 21;
    let y_m = config.road.lane_center_y_m(spec.lane) + spec.y_offset_m;
    let mut points = Vec::with_capacity(POINTS);
    let mut t = t_s;
    let mut previous_speed = speed_at(0.0);
    for i in 0..POINTS {
        let ahead_m = STEP_M * i as f64;
        let speed_mps = speed_at(ahead_m);
        if i > 0 {
            t += STEP_M / (0.5 * (previous_speed + speed_mps)).max(0.1);
        }
        previous_speed = speed_mps;
        points.push(PathPoint {
            x_m: k.x_m + ahead_m,
            y_m,
            speed_mps,
            t_s: t,
        });
    }
    points
}

/// Samples the ego's potential field on a window around it and logs it as an image.
fn log_field(
    recorder: &mut Recorder,
    planner: &PfPlanner,
    request: &PlanRequest,
    name: &str,
) -> Result<(), SimError> {
    let cell_m = 0.5;
    let x0_m = request.ego.x_m - 20.0;
    let road = planner.road();
    let y0_m = road.y_bottom_m;
    let width = 240usize;
    let height = ((road.y_upper_m() - road.y_bottom_m) / cell_m).ceil() as usize;
    let mut values = Vec::with_capacity(width * height);
    for row in 0..height {
        let y_m = y0_m + (row as f64 + 0.5) * cell_m;
        for col in 0..width {
            let x_m = x0_m + (col as f64 + 0.5) * cell_m;
            values.push(planner.field_value(request, x_m, y_m));
        }
    }
    recorder
        .log_field(name, x0_m, y0_m, cell_m, width, height, &values)
        .map_err(rec)
}
