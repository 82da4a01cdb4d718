//! A human driver: Intelligent Driver Model car following (`crate::idm`) along its lane; never
//! connected. Gaps are measured in the held lane's frame (s along it, d across it), so the model
//! follows curved lanes.
//!
//! Without MOBIL (`mobil: None`, `driver = "idm"`) it never changes lanes. With MOBIL
//! (`crate::mobil`) it considers, at each planning tick after `min_time_between_changes_s`, a
//! change to each neighbouring lane, and takes the one with the larger incentive that passes
//! both criteria. A lane that ends closed ahead (`LaneRoad::distance_to_closed_end_m`) is then
//! a standing obstacle at its end, in the driver's own car following too, so the driver stops
//! before it if no gap opens. A neighbour's desired speed cannot be observed: MOBIL takes it as
//! the neighbour's current speed. A MOBIL driver holds the successor of its lane once past the
//! lane's end (a ramp leading into an acceleration lane), so that it sees that lane's neighbours.
//! A neighbour is a target only where it exists beside the car, and a lane that ends closed
//! ahead only for a car whose own lane ends too.

use mergesim_types::lanes::{Lane, LaneId, LaneRoad, Side};
use mergesim_types::{Behaviour, BehaviourError, Decision, Observation};

use crate::config::{SimConfig, VehicleSpec};
use crate::drivers::lane_path;
use crate::idm::{IdmParams, RoadUser, find_leader, idm_acceleration, speed_after_distance};
use crate::mobil::{LaneDriver, MobilParams, Neighbourhood, Verdict, decide};

/// IDM car following with lane keeping, and MOBIL lane changes if `mobil` is set (module doc).
#[derive(Clone, Debug)]
pub struct IdmDriver {
    /// The model's parameters.
    pub params: IdmParams,
    /// Lane to hold.
    pub lane: LaneId,
    /// Offset from its centre (m, positive to the left).
    pub d_offset_m: f64,
    /// MOBIL's parameters; `None`: the driver keeps its lane.
    pub mobil: Option<MobilParams>,
    /// When the driver last changed lanes (s).
    pub last_change_t_s: Option<f64>,
}

impl IdmDriver {
    /// An IDM driver holding `lane` at `d_offset_m`, with MOBIL lane changes if `mobil` is set.
    pub fn new(
        params: IdmParams,
        lane: LaneId,
        d_offset_m: f64,
        mobil: Option<MobilParams>,
    ) -> Self {
        Self {
            params,
            lane,
            d_offset_m,
            mobil,
            last_change_t_s: None,
        }
    }

    /// The driver of vehicle `spec`: the scenario's IDM parameters (`[sim.idm]`), holding the
    /// vehicle's start lane at its offset, with MOBIL lane changes (`[sim.mobil]`) if
    /// `lane_changes` (`driver = "idm-mobil"`, or the planner name `idm-mobil`), else none
    /// (`driver = "idm"`).
    pub fn for_vehicle(config: &SimConfig, spec: &VehicleSpec, lane_changes: bool) -> Self {
        Self::new(
            config.idm.clone(),
            spec.lane.id(),
            spec.y_offset_m,
            lane_changes.then(|| config.mobil.clone()),
        )
    }
}

/// The observed vehicles in `lane`'s frame, the ego first, as `(s, d, speed, length)`.
fn in_frame(lane: &Lane, obs: &Observation<'_>) -> Vec<RoadUser> {
    let user = |x_m: f64, y_m: f64, speed_mps: f64, length_m: f64| {
        let fp = lane.project([x_m, y_m]);
        RoadUser {
            x_m: fp.s_m,
            y_m: fp.d_m,
            speed_mps,
            length_m,
        }
    };
    std::iter::once(user(
        obs.ego.x_m,
        obs.ego.y_m,
        obs.ego.speed_mps,
        obs.ego_shape.length_m,
    ))
    .chain(obs.neighbours.iter().map(|n| {
        user(
            n.state.x_m,
            n.state.y_m,
            n.state.speed_mps,
            n.shape.length_m,
        )
    }))
    .collect()
}

/// Arc-length step (m) of the search for where a narrowing lane stops fitting the car.
const FIT_STEP_M: f64 = 0.5;

/// Where, between `s_m` and `end_s_m`, the lane stops fitting a car of `width_m` driving on its
/// centreline with `clearance_m` to either bound (its first such point on a 0.5 m grid);
/// `end_s_m` if it fits all the way.
fn last_fit_s_m(lane: &Lane, s_m: f64, end_s_m: f64, width_m: f64, clearance_m: f64) -> f64 {
    let need_m = 0.5 * width_m + clearance_m;
    let steps = ((end_s_m - s_m) / FIT_STEP_M).ceil().clamp(0.0, 1e6) as usize;
    (0..=steps)
        .map(|k| (s_m + FIT_STEP_M * k as f64).min(end_s_m))
        .find(|&s| lane.left_d_m(s) < need_m || -lane.right_d_m(s) < need_m)
        .unwrap_or(end_s_m)
}

/// What the driver needs to know of its car to place a lane's end: its width and clearance.
#[derive(Clone, Copy, Debug)]
struct Fit {
    width_m: f64,
    clearance_m: f64,
}

/// The nearest vehicle ahead and behind `s_m` within the corridor about the lane's centre
/// (`users[0]`, the ego, excluded), and the lane's closed end if it is nearer than the one
/// ahead: a standing obstacle where the lane stops fitting the car (`fit`).
fn around(
    params: &IdmParams,
    lanes: &LaneRoad,
    lane: LaneId,
    users: &[RoadUser],
    s_m: f64,
    fit: Fit,
) -> (Option<LaneDriver>, Option<LaneDriver>) {
    let as_driver = |u: &RoadUser| LaneDriver {
        s_m: u.x_m,
        speed_mps: u.speed_mps,
        desired_speed_mps: u.speed_mps,
        length_m: u.length_m,
    };
    let in_lane = users
        .iter()
        .skip(1)
        .filter(|u| u.y_m.abs() < params.corridor_half_width_m);
    let mut ahead = in_lane
        .clone()
        .filter(|u| u.x_m > s_m)
        .min_by(|a, b| a.x_m.total_cmp(&b.x_m))
        .map(as_driver);
    let behind = in_lane
        .filter(|u| u.x_m <= s_m)
        .max_by(|a, b| a.x_m.total_cmp(&b.x_m))
        .map(as_driver);
    if let (Some(end_m), Some(held)) = (lanes.distance_to_closed_end_m(lane, s_m), lanes.lane(lane))
    {
        let end_s_m = last_fit_s_m(held, s_m, s_m + end_m, fit.width_m, fit.clearance_m);
        let end = LaneDriver::lane_end(end_s_m);
        if ahead.is_none_or(|a| end.s_m < a.s_m - 0.5 * a.length_m) {
            ahead = Some(end);
        }
    }
    (ahead, behind)
}

impl IdmDriver {
    /// Holds the successor of the held lane once the car is past the lane's end (the one
    /// whose centreline is nearest the car, if it has several), so that MOBIL looks at the
    /// neighbours of the lane the car is in: a ramp has none, the acceleration lane it leads
    /// into has the main road beside it. Bounded by the number of lanes.
    fn follow_into_successor(&mut self, lanes: &LaneRoad, p_m: [f64; 2]) {
        for _ in 0..lanes.lanes().len() {
            let Some(held) = lanes.lane(self.lane) else {
                return;
            };
            if held.project(p_m).s_m <= held.length_m() {
                return;
            }
            let next = held
                .successors()
                .iter()
                .filter_map(|id| lanes.lane(*id))
                .min_by(|a, b| {
                    let off = |l: &Lane| l.project(p_m).d_m.abs();
                    off(a).total_cmp(&off(b))
                });
            match next {
                Some(next) => self.lane = next.id(),
                None => return,
            }
        }
    }

    /// MOBIL's choice at this tick: the neighbouring lane to change to, if any (module doc).
    /// `own` is the held lane and `own_users` everybody in its frame ([`in_frame`]).
    fn mobil_target(
        &self,
        mobil: &MobilParams,
        obs: &Observation<'_>,
        own: &Lane,
        own_users: &[RoadUser],
    ) -> Option<LaneId> {
        let lanes = obs.lanes;
        let s_me = own_users[0].x_m;
        let me = LaneDriver {
            s_m: s_me,
            speed_mps: obs.ego.speed_mps,
            desired_speed_mps: obs.target_speed_mps,
            length_m: obs.ego_shape.length_m,
        };
        let fit = Fit {
            width_m: obs.ego_shape.width_m,
            clearance_m: mobil.end_clearance_m,
        };
        let (leader_now, follower_now) =
            around(&self.params, lanes, self.lane, own_users, s_me, fit);
        let own_ends = lanes.distance_to_closed_end_m(self.lane, s_me).is_some();
        let mut best: Option<(LaneId, Verdict)> = None;
        for side in [Side::Left, Side::Right] {
            let Some(target_id) = own.neighbour(side) else {
                continue;
            };
            let Some(target) = lanes.lane(target_id) else {
                continue;
            };
            let users = in_frame(target, obs);
            let s_target = users[0].x_m;
            // A lane that does not exist beside the car yet (or any more) is no target; nor is
            // one that ends closed ahead when the held lane does not (the lane rule of the
            // planners: an acceleration lane is not a lane to overtake in).
            let ends_ahead = lanes
                .distance_to_closed_end_m(target_id, s_target)
                .is_some();
            if !(0.0..=target.length_m()).contains(&s_target) || (ends_ahead && !own_ends) {
                continue;
            }
            let (leader_after, follower_after) =
                around(&self.params, lanes, target_id, &users, s_target, fit);
            // The target lane's drivers in its own frame, me at my arc length there.
            let n = Neighbourhood {
                me: LaneDriver {
                    s_m: s_target,
                    ..me
                },
                leader_now: leader_now.map(|l| LaneDriver {
                    s_m: l.s_m - s_me + s_target,
                    ..l
                }),
                follower_now: follower_now.map(|f| LaneDriver {
                    s_m: f.s_m - s_me + s_target,
                    ..f
                }),
                leader_after,
                follower_after,
                leaving_ending_lane: own_ends && !ends_ahead,
            };
            let verdict = decide(&self.params, mobil, &n);
            if verdict.change && best.is_none_or(|(_, b)| verdict.incentive_mps2 > b.incentive_mps2)
            {
                best = Some((target_id, verdict));
            }
        }
        best.map(|(id, _)| id)
    }
}

impl Behaviour for IdmDriver {
    /// The acceleration of the IDM behind the nearest vehicle ahead in its corridor (with MOBIL:
    /// or the lane's closed end), turned into the speed profile of a lane-keeping path; with
    /// MOBIL, after a lane change if one is due.
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        if self.mobil.is_some() {
            self.follow_into_successor(obs.lanes, [obs.ego.x_m, obs.ego.y_m]);
        }
        // Everybody in the held lane's frame: s along it, d across it.
        let Some(mut lane) = obs.lanes.lane(self.lane) else {
            return Err(format!("lane {} is not on the road", self.lane).into());
        };
        let mut users = in_frame(lane, obs);
        if let Some(mobil) = &self.mobil {
            let rested = self
                .last_change_t_s
                .is_none_or(|t| obs.time_s - t >= mobil.min_time_between_changes_s);
            if rested
                && let Some(target) = self.mobil_target(mobil, obs, lane, &users)
                && let Some(target_lane) = obs.lanes.lane(target)
            {
                self.lane = target;
                self.d_offset_m = 0.0;
                self.last_change_t_s = Some(obs.time_s);
                lane = target_lane;
                users = in_frame(lane, obs);
            }
        }
        let leader = if let Some(mobil) = &self.mobil {
            let s_me = users[0].x_m;
            let fit = Fit {
                width_m: obs.ego_shape.width_m,
                clearance_m: mobil.end_clearance_m,
            };
            around(&self.params, obs.lanes, self.lane, &users, s_me, fit)
                .0
                .map(|l| crate::idm::Leader {
                    index: 0,
                    gap_m: l.s_m - s_me - 0.5 * (l.length_m + obs.ego_shape.length_m),
                    speed_mps: l.speed_mps,
                })
        } else {
            find_leader(&self.params, &users, 0)
        };
        let v = obs.ego.speed_mps;
        let accel_mps2 = idm_acceleration(&self.params, v, obs.target_speed_mps, leader.as_ref());
        Ok(Decision::follow(lane_path(
            obs.lanes,
            self.lane,
            self.d_offset_m,
            [obs.ego.x_m, obs.ego.y_m],
            obs.time_s,
            |d| speed_after_distance(v, accel_mps2, d),
        )))
    }

    fn is_planner(&self) -> bool {
        false
    }
}
