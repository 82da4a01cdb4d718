//! Recorded traffic in the world (`crate::recorded_traffic`): one kinematic box per recorded
//! vehicle, moved along its recorded states (`crate::recorded_motion`) or, in reactive mode
//! after its handover, by the Intelligent Driver Model (`crate::idm`).
//!
//! # In the tick
//! Recorded vehicles are advanced right before the Rapier step (after tracking and forces):
//! each one's pose at the end of the step, t + dt, is computed and handed to Rapier as its
//! kinematic target, so after the step the bodies stand where the recording (or IDM) puts them
//! at t + dt, and Rapier's contacts with the simulated chassis are those of that motion. A
//! vehicle whose recorded span starts by t + dt is inserted at its pose there; one whose span
//! has ended is removed. Planners (step 2) and the safety checks (step 5) then read their
//! state at the world's time.
//!
//! # Ids
//! Recorded vehicle k (in `RecordedTraffic::vehicles` order) has id n + k, n being the number
//! of simulated vehicles, whether present or not: ids stay stable and every simulated id is
//! below every recorded one (the safety monitor's order, `SafetyMonitor::set_recorded_from`).
//!
//! # Reactive mode: the handover
//! At each step, a recorded vehicle still following its recording looks for the nearest
//! *simulated* vehicle ahead in its lane, in the frame of the lane it is in (`lane_of`): ahead
//! along the lane (larger s) and within IDM's `corridor_half_width_m` across it (the same
//! leader search as `driver = "idm"`). If the recording's pose at t + dt would leave a bumper
//! gap s (box centres' distance along the lane minus half of both lengths) to it below IDM's
//! safe gap s* = s₀ + max(0, v·T + v·Δv / (2√(a·b))) (v its recorded speed at t + dt,
//! Δv = v − v_leader), it hands over: from its state at t, IDM drives it along its lane
//! (centreline frame: s advanced by the speed, d held, heading the lane's, no lane changes,
//! past the lane's end along the straight continuation of its frame), as nuPlan's and
//! Waymax's reactive agents. After the handover its leaders are every vehicle ahead in its
//! corridor, simulated or recorded; its desired speed is the largest speed of its recording
//! (at most what that driver drove; a standing recording's vehicle never accelerates). The
//! handover is an event. The vehicle still leaves the run at its recording's last time.
//! Parameters: `[sim.idm]` (`crate::idm::IdmParams`), shared with `driver = "idm"`.
//!
//! # What planners see
//! An unconnected vehicle: a `Neighbour` with its state and a `VehicleShape` of its recorded
//! length and width, the default preset's wheelbase and the default braking capability
//! (`VehicleShape::default().max_brake_decel_mps2`, 7 m/s²), within `perception_range_m`;
//! never a shared path.
//!
//! # Outputs
//! The safety monitor checks simulated–recorded pairs, not recorded–recorded ones
//! (`crate::safety`'s `recorded_pairs`). The recording draws recorded vehicles as grey boxes
//! with their names (`world/recorded_vehicles`). They have no rows in the time series (`--csv`)
//! and no entry in `RunOutcome::vehicles`: those stay the simulated vehicles' (a recording's
//! own trajectory is in its source file).

use mergesim_types::lanes::{LaneId, LaneRoad};
use mergesim_types::{Neighbour, VehicleId, VehicleShape, VehicleState, planning_brake_decel_mps2};
use vehicles::{GRAVITY_MPS2, KinematicBox, PhysicsWorld, VehicleParams};

use crate::body_state::BodyState;
use crate::error::SimError;
use crate::idm::{IdmParams, RoadUser, desired_gap_m, find_leader, idm_acceleration};
use crate::lane_membership::lane_of;
use crate::recorded_traffic::{RecordedState, RecordedTraffic, RecordedVehicle, TrafficMode};

/// A recorded vehicle driven by IDM since its handover, in its lane's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
struct IdmMotion {
    lane: LaneId,
    s_m: f64,
    d_m: f64,
    speed_mps: f64,
}

/// One recorded vehicle in the world.
struct Member {
    id: VehicleId,
    vehicle: RecordedVehicle,
    shape: VehicleShape,
    body: Option<KinematicBox>,
    /// Its state at the world's time, `None` outside its span.
    current: Option<RecordedState>,
    /// The lane it was last found in.
    lane: Option<LaneId>,
    /// Set at the handover (reactive mode).
    idm: Option<IdmMotion>,
    desired_speed_mps: f64,
}

/// A handover to IDM (reactive mode), as recorded in the run's events.
#[derive(Clone, Debug, PartialEq)]
pub struct Handover {
    /// The world's time at the handover (s): IDM drives from the state at this time.
    pub t_s: f64,
    /// The recorded vehicle.
    pub name: String,
    /// The simulated vehicle ahead.
    pub leader: VehicleId,
    /// The bumper gap the recording would have left at the next step (m).
    pub gap_m: f64,
    /// IDM's safe gap s* there (m).
    pub safe_gap_m: f64,
    /// Its recorded speed at the next step (m/s).
    pub speed_mps: f64,
    /// Its approach rate Δv to the leader (m/s).
    pub approach_rate_mps: f64,
}

/// The recorded vehicles of a world (module doc).
pub(crate) struct RecordedFleet {
    mode: TrafficMode,
    idm: IdmParams,
    members: Vec<Member>,
    ground_clearance_m: f64,
    body_height_m: f64,
}

impl RecordedFleet {
    /// The fleet of `traffic` with ids from `first_id` on, its vehicles present at time 0
    /// inserted into `physics`. Empty for mode `none`.
    pub(crate) fn new(
        traffic: &RecordedTraffic,
        simulated_names: &[String],
        idm: &IdmParams,
        (mu, planner_brake_margin): (f64, f64),
        physics: &mut PhysicsWorld,
    ) -> Result<Self, SimError> {
        traffic.validate(simulated_names)?;
        let preset = VehicleParams::default();
        let mut fleet = Self {
            mode: traffic.mode,
            idm: idm.clone(),
            members: Vec::new(),
            ground_clearance_m: preset.ground_clearance_m,
            body_height_m: preset.body_height_m,
        };
        if traffic.is_empty() {
            return Ok(fleet);
        }
        let first_id = simulated_names.len() as VehicleId;
        let wheelbase_m = preset.wheelbase_m();
        for (k, vehicle) in traffic.vehicles.iter().enumerate() {
            let shape = VehicleShape {
                length_m: vehicle.length_m,
                width_m: vehicle.width_m,
                wheelbase_m: wheelbase_m.min(vehicle.length_m),
                max_brake_decel_mps2: planning_brake_decel_mps2(
                    mu * GRAVITY_MPS2,
                    planner_brake_margin,
                ),
            };
            let mut member = Member {
                id: first_id + k as VehicleId,
                desired_speed_mps: vehicle.max_speed_mps(),
                vehicle: vehicle.clone(),
                shape,
                body: None,
                current: None,
                lane: None,
                idm: None,
            };
            let state = member.vehicle.state_at(0.0);
            fleet.place(&mut member, state, physics)?;
            fleet.members.push(member);
        }
        Ok(fleet)
    }

    /// Inserts, moves or removes the member's body so that it stands at `state` after the next
    /// physics step (or now, for a body inserted), and makes `state` its current one.
    fn place(
        &self,
        member: &mut Member,
        state: Option<RecordedState>,
        physics: &mut PhysicsWorld,
    ) -> Result<(), SimError> {
        match (state, member.body) {
            (Some(s), Some(body)) => {
                body.set_next_pose(physics, [s.position_m[0], s.position_m[1], s.heading_rad]);
            }
            (Some(s), None) => {
                let body = KinematicBox::spawn(
                    physics,
                    member.vehicle.length_m,
                    member.vehicle.width_m,
                    self.ground_clearance_m,
                    self.body_height_m,
                    [s.position_m[0], s.position_m[1], s.heading_rad],
                )
                .map_err(|e| SimError::InvalidField {
                    field: format!("recorded_traffic.vehicles[{}]", member.vehicle.name),
                    message: e.to_string(),
                })?;
                member.body = Some(body);
            }
            (None, Some(body)) => {
                body.remove(physics);
                member.body = None;
            }
            (None, None) => {}
        }
        member.current = state;
        Ok(())
    }

    /// Whether there is nothing to do.
    pub(crate) fn is_empty(&self) -> bool {
        self.members.is_empty()
    }

    /// Whether the reactive mode needs the simulated bodies in [`Self::advance`].
    pub(crate) fn needs_simulated_bodies(&self) -> bool {
        self.mode == TrafficMode::Reactive && self.members.iter().any(|m| m.current.is_some())
    }

    /// Every recorded vehicle's name, in id order.
    pub(crate) fn names(&self) -> impl Iterator<Item = &str> {
        self.members.iter().map(|m| m.vehicle.name.as_str())
    }

    /// Moves every recorded vehicle from the world's time `t_s` to `next_t_s` (module doc):
    /// sets the kinematic targets of the coming physics step. `simulated` are the simulated
    /// bodies at `t_s` (used in reactive mode only). Returns the handovers of this step.
    pub(crate) fn advance(
        &mut self,
        t_s: f64,
        next_t_s: f64,
        lanes: &LaneRoad,
        simulated: &[BodyState],
        physics: &mut PhysicsWorld,
    ) -> Result<Vec<Handover>, SimError> {
        let dt_s = next_t_s - t_s;
        let mut handovers = Vec::new();
        // Everyone's state now, for the IDM leaders (sequential, id order: deterministic).
        let others: Vec<(VehicleId, RecordedState, f64)> = self
            .members
            .iter()
            .filter_map(|m| m.current.map(|s| (m.id, s, m.vehicle.length_m)))
            .collect();
        let mut members = std::mem::take(&mut self.members);
        for member in &mut members {
            let recorded_next = member.vehicle.state_at(next_t_s);
            let next = match (recorded_next, member.current) {
                (Some(next), Some(now)) if self.mode == TrafficMode::Reactive => {
                    if member.idm.is_none()
                        && let Some(h) = self.handover(member, &next, lanes, simulated, t_s)
                    {
                        let hit = lane_of(lanes, member.lane, now.position_m);
                        member.idm = Some(IdmMotion {
                            lane: hit.lane,
                            s_m: hit.frame.s_m,
                            d_m: hit.frame.d_m,
                            speed_mps: now.speed_mps,
                        });
                        handovers.push(h);
                    }
                    match member.idm {
                        Some(_) => {
                            Some(self.idm_step(member, next_t_s, dt_s, lanes, simulated, &others))
                        }
                        None => Some(next),
                    }
                }
                (next, _) => next,
            };
            self.place(member, next, physics)?;
        }
        self.members = members;
        Ok(handovers)
    }

    /// The handover due now, if following the recording to `next` would bring `member` closer
    /// to the nearest simulated vehicle ahead in its lane than IDM's safe gap (module doc).
    fn handover(
        &self,
        member: &mut Member,
        next: &RecordedState,
        lanes: &LaneRoad,
        simulated: &[BodyState],
        t_s: f64,
    ) -> Option<Handover> {
        let hit = lane_of(lanes, member.lane, next.position_m);
        member.lane = Some(hit.lane);
        let lane = lanes.lane(hit.lane)?;
        let mut users = vec![RoadUser {
            x_m: hit.frame.s_m,
            y_m: hit.frame.d_m,
            speed_mps: next.speed_mps,
            length_m: member.vehicle.length_m,
        }];
        users.extend(simulated.iter().map(|b| {
            let fp = lane.project([b.x_m, b.y_m]);
            RoadUser {
                x_m: fp.s_m,
                y_m: fp.d_m,
                speed_mps: b.speed_mps(),
                length_m: b.length_m,
            }
        }));
        let leader = find_leader(&self.idm, &users, 0)?;
        let v = next.speed_mps;
        let approach_rate_mps = v - leader.speed_mps;
        let safe_gap_m = desired_gap_m(&self.idm, v, approach_rate_mps);
        (leader.gap_m < safe_gap_m).then(|| Handover {
            t_s,
            name: member.vehicle.name.clone(),
            // `users` is the member, then `simulated` in order.
            leader: simulated.get(leader.index - 1).map_or(0, |b| b.id),
            gap_m: leader.gap_m,
            safe_gap_m,
            speed_mps: v,
            approach_rate_mps,
        })
    }

    /// One IDM step of a handed-over member: its state at `next_t_s`.
    fn idm_step(
        &self,
        member: &mut Member,
        next_t_s: f64,
        dt_s: f64,
        lanes: &LaneRoad,
        simulated: &[BodyState],
        others: &[(VehicleId, RecordedState, f64)],
    ) -> RecordedState {
        let Some(mut motion) = member.idm else {
            return member.current.unwrap_or(member.vehicle.states[0]);
        };
        let Some(lane) = lanes.lane(motion.lane) else {
            return member.current.unwrap_or(member.vehicle.states[0]);
        };
        let user = |p: [f64; 2], speed_mps: f64, length_m: f64| {
            let fp = lane.project(p);
            RoadUser {
                x_m: fp.s_m,
                y_m: fp.d_m,
                speed_mps,
                length_m,
            }
        };
        let mut users = vec![RoadUser {
            x_m: motion.s_m,
            y_m: motion.d_m,
            speed_mps: motion.speed_mps,
            length_m: member.vehicle.length_m,
        }];
        users.extend(
            simulated
                .iter()
                .map(|b| user([b.x_m, b.y_m], b.speed_mps(), b.length_m)),
        );
        users.extend(
            others
                .iter()
                .filter(|(id, _, _)| *id != member.id)
                .map(|(_, s, length_m)| user(s.position_m, s.speed_mps, *length_m)),
        );
        let leader = find_leader(&self.idm, &users, 0);
        let mut accel_mps2 = idm_acceleration(
            &self.idm,
            motion.speed_mps,
            member.desired_speed_mps,
            leader.as_ref(),
        );
        if member.desired_speed_mps <= 0.0 {
            accel_mps2 = accel_mps2.min(0.0);
        }
        let v0 = motion.speed_mps;
        let v1 = (v0 + accel_mps2 * dt_s).max(0.0);
        motion.s_m += 0.5 * (v0 + v1) * dt_s;
        motion.speed_mps = v1;
        member.idm = Some(motion);
        RecordedState {
            time_s: next_t_s,
            position_m: lane.point(motion.s_m, motion.d_m),
            heading_rad: lane.heading_rad(motion.s_m),
            speed_mps: v1,
        }
    }

    /// The present recorded vehicles' boxes, in id order: velocity = speed along the heading,
    /// yaw rate 0, the box of [`Self::new`]'s heights.
    pub(crate) fn bodies(&self) -> impl Iterator<Item = BodyState> + '_ {
        let height_m = self.body_height_m - self.ground_clearance_m;
        self.members.iter().filter_map(move |m| {
            let s = m.current?;
            let (sin, cos) = s.heading_rad.sin_cos();
            Some(BodyState {
                id: m.id,
                x_m: s.position_m[0],
                y_m: s.position_m[1],
                yaw_rad: s.heading_rad,
                vx_mps: s.speed_mps * cos,
                vy_mps: s.speed_mps * sin,
                yaw_rate_radps: 0.0,
                length_m: m.vehicle.length_m,
                width_m: m.vehicle.width_m,
                height_m,
            })
        })
    }

    /// The present recorded vehicles as planners perceive them (module doc), in id order.
    pub(crate) fn neighbours(&self) -> Vec<Neighbour> {
        self.members
            .iter()
            .filter_map(|m| {
                let s = m.current?;
                Some(Neighbour {
                    id: m.id,
                    state: VehicleState::from(&s),
                    shape: m.shape,
                })
            })
            .collect()
    }
}
