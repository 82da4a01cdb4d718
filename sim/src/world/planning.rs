//! Step 2 of the tick: every vehicle observes, decides and broadcasts. The observations are
//! built and the decisions handled (counted, fallbacks and degraded modes logged, observers
//! called, broadcasts sent) in id order; the decisions themselves are computed in parallel on
//! rayon's pool (the sweep's pool inside a sweep), which changes no result: each depends only
//! on its vehicle's behaviour and observation.
//!
//! A vehicle perceives the others whose centres are within `perception_range_m`, and a
//! broadcast reaches the connected vehicles within the V2V `range_m` of its sender, both found
//! by the X sweep of `crate::spatial` (O(N log N + k) rather than O(N²)), in id order.

use std::time::{Duration, Instant};

use mergesim_types::{
    Decision, GridSpec, Neighbour, Observation, SharedLocalPath, VehicleId, VehicleState,
};
use vehicles::Kinematics;

use rayon::prelude::*;

use super::{World, check_finite};
use crate::agent::Agent;
use crate::error::SimError;
use crate::event::SimEvent;
use crate::observer::{PlanView, TickObserver};
use crate::profile::Phase;
use crate::spatial::neighbours_within;

impl World {
    pub(super) fn plan_all(&mut self, t_s: f64) -> Result<(), SimError> {
        let started = self.clock();
        let (mut metrics, mut recording) = (Duration::ZERO, Duration::ZERO);
        let kins: Vec<Kinematics> = self
            .agents
            .iter()
            .map(|a| a.vehicle.kinematics(&self.physics))
            .collect();
        let states: Vec<VehicleState> = kins.iter().map(VehicleState::from).collect();
        let field_due = self.step_index.is_multiple_of(self.steps_per_field);
        // The observation borrows these while the world records events.
        let lanes = std::sync::Arc::clone(&self.lanes);
        let mu = self.config.mu;
        let mut broadcasts: Vec<(usize, SharedLocalPath)> = Vec::new();
        for (agent, kin) in self.agents.iter().zip(&kins) {
            check_finite(t_s, &agent.spec.name, kin)?;
        }
        let positions: Vec<[f64; 2]> = states.iter().map(|s| [s.x_m, s.y_m]).collect();
        // Recorded traffic is perceived like any unconnected vehicle (`super::recorded`): its
        // indices follow the agents', as its ids do.
        let recorded = self.recorded.neighbours();
        let perceived = if recorded.is_empty() {
            neighbours_within(&positions, self.config.perception_range_m)
        } else {
            let mut all = positions.clone();
            all.extend(recorded.iter().map(|n| [n.state.x_m, n.state.y_m]));
            let mut perceived = neighbours_within(&all, self.config.perception_range_m);
            perceived.truncate(positions.len());
            perceived
        };
        let n_agents = self.agents.len();
        self.bus.forget_stale(t_s);
        // 1. What each vehicle perceives and has received (sequential, by id).
        let mut inputs: Vec<(Vec<Neighbour>, Vec<SharedLocalPath>)> =
            Vec::with_capacity(self.agents.len());
        for (index, others) in perceived.iter().enumerate() {
            let neighbours: Vec<Neighbour> = others
                .iter()
                .map(|&j| match j.checked_sub(n_agents) {
                    Some(k) => recorded[k],
                    None => Neighbour {
                        id: self.agents[j].id,
                        state: states[j],
                        shape: self.agents[j].shape,
                    },
                })
                .collect();
            let agent = &self.agents[index];
            let shared_paths = if agent.spec.connected {
                self.bus.fresh_paths(agent.id, t_s)
            } else {
                Vec::new()
            };
            inputs.push((neighbours, shared_paths));
        }
        let observation_of = |index: usize, agent: &Agent| Observation {
            time_s: t_s,
            ego_id: agent.id,
            ego: states[index],
            ego_shape: agent.shape,
            target_speed_mps: agent.spec.target_speed_mps,
            mu,
            lanes: &lanes,
            neighbours: &inputs[index].0,
            shared_paths: &inputs[index].1,
        };
        // 2. Every vehicle decides, in parallel: a decision depends only on its own behaviour
        // and observation, so the results are those of one thread, bit for bit.
        let decide = |index: usize, agent: &mut Agent| {
            let observation = observation_of(index, agent);
            let started = Instant::now();
            let decision =
                agent
                    .behaviour
                    .plan(&observation)
                    .map_err(|source| SimError::Behaviour {
                        vehicle: agent.spec.name.clone(),
                        source,
                    });
            (decision, started.elapsed().as_secs_f64() * 1e6)
        };
        // With fewer than two planners (IDM drivers, lane keepers: microseconds each) handing
        // the decisions to the thread pool costs more than they do: they run here, in order.
        let planners = self
            .agents
            .iter()
            .filter(|a| a.behaviour.is_planner())
            .take(2)
            .count();
        let agents = &mut self.agents;
        let decided: Vec<(Result<Decision, SimError>, f64)> = if planners < 2 {
            agents
                .iter_mut()
                .enumerate()
                .map(|(index, agent)| decide(index, agent))
                .collect()
        } else {
            let mut decide_all = || -> Vec<(Result<Decision, SimError>, f64)> {
                agents
                    .par_iter_mut()
                    .enumerate()
                    .map(|(index, agent)| decide(index, agent))
                    .collect()
            };
            match &self.planning_pool {
                Some(pool) => pool.install(decide_all),
                None => decide_all(),
            }
        };
        // 3. Counting, events, observers and broadcasts (sequential, by id).
        for (index, (decision, elapsed_us)) in decided.into_iter().enumerate() {
            let mut decision = decision?;
            let observation = observation_of(index, &self.agents[index]);
            // The shield bounds the decided path before anybody sees it (`crate::shield`).
            if let Some(shield) = &mut self.agents[index].shield {
                let started = shield.apply(&observation, &mut decision);
                for intervention in started {
                    let event = SimEvent::ShieldIntervened {
                        t_s,
                        vehicle: self.agents[index].spec.name.clone(),
                        other: match intervention.other {
                            Some(id) => Self::name_of(&self.names(), id),
                            None => "the road's edge ahead".to_string(),
                        },
                        response: intervention.responses.name().to_string(),
                        lon_gap_m: intervention.lon_gap_m,
                        safe_lon_gap_m: intervention.safety.safe_lon_gap_m,
                    };
                    self.event(event)?;
                }
            }
            let agent = &self.agents[index];
            let is_planner = agent.behaviour.is_planner();
            let name = agent.spec.name.clone();
            let connected = agent.spec.connected;
            if is_planner {
                let optimiser = agent.behaviour.optimiser_report();
                if decision.degraded_mode != self.agents[index].degraded_mode {
                    let event = match (&decision.degraded_mode, &self.agents[index].degraded_mode) {
                        (Some(mode), _) => Some(SimEvent::DegradedModeEntered {
                            t_s,
                            vehicle: name.clone(),
                            mode: mode.clone(),
                        }),
                        (None, Some(mode)) => Some(SimEvent::DegradedModeLeft {
                            t_s,
                            vehicle: name.clone(),
                            mode: mode.clone(),
                        }),
                        // Unequal modes are never both absent.
                        (None, None) => None,
                    };
                    self.agents[index].degraded_mode = decision.degraded_mode.clone();
                    if let Some(event) = event {
                        self.event(event)?;
                    }
                }
                if let Some(reason) = &decision.fallback {
                    self.event(SimEvent::PlannerFallback {
                        t_s,
                        vehicle: name.clone(),
                        reason: reason.clone(),
                    })?;
                }
                let behaviour = &self.agents[index].behaviour;
                let field = |spec: &GridSpec| behaviour.potential_field(&observation, spec);
                let view = PlanView {
                    name: &name,
                    observation: &observation,
                    decision: &decision,
                    field: &field,
                    field_due,
                    plan_time_us: elapsed_us,
                    optimiser,
                };
                let observed = self.timing.then(Instant::now);
                self.planner_stats.on_plan(t_s, &view)?;
                self.run_log.on_plan(t_s, &view)?;
                for observer in &mut self.observers {
                    observer.on_plan(t_s, &view)?;
                }
                let recorded = self.timing.then(Instant::now);
                self.recording.on_plan(t_s, &view)?;
                if let (Some(observed), Some(recorded)) = (observed, recorded) {
                    metrics += recorded - observed;
                    recording += recorded.elapsed();
                }
            }
            let agent = &mut self.agents[index];
            agent.path = decision.path;
            if connected && let Some(message) = decision.broadcast {
                broadcasts.push((index, message));
            }
        }
        // Broadcast after everybody planned on the same information (a synchronous round), to
        // the connected vehicles in radio range of the sender.
        if !broadcasts.is_empty() {
            let in_radio_range = neighbours_within(&positions, self.bus.params().range_m);
            for (sender, message) in &broadcasts {
                let receivers: Vec<VehicleId> = in_radio_range[*sender]
                    .iter()
                    .map(|&j| &self.agents[j])
                    .filter(|a| a.spec.connected)
                    .map(|a| a.id)
                    .collect();
                self.bus.broadcast(t_s, message, &receivers);
            }
        }
        if let Some(started) = started {
            let planning = started.elapsed().saturating_sub(metrics + recording);
            self.phase_took(Phase::Planning, planning)?;
            self.phase_took(Phase::Metrics, metrics)?;
            self.phase_took(Phase::Recording, recording)?;
        }
        Ok(())
    }
}
