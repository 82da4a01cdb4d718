//! `pf-iso-seq`: PF-ISO's path with the speeds of merge sequencing.
//!
//! Each cycle: PF-ISO plans (path, speeds, shared path) as usual; then, for a car on either
//! side of the merge ([`MergeGeometry`]) between the control zone's start and the ending
//! lane's end,
//! 1. the queue ([`MergeQueue`]) takes in the car's own report and every received shared
//!    local path (first waypoint = the sender's position at its stamp, with its speed), and
//!    gives the car its crossing time t_f;
//! 2. before the merging zone, the wanted speed is the energy-optimal profile reaching the
//!    merging zone's entry at t_f ([`EnergyOptimalProfile`]); inside the merging zone (and
//!    when t_f is already past) it is PF-ISO's planned speed at that point of the path;
//! 3. the speeds the car follows are the constrained profile of that wanted speed
//!    ([`constrained_profile`]: v_min, v_max, |u| ≤ u_max, and the rear-end constraint to the
//!    nearest car ahead in the same lane, from the car's perception), sampled at the path's
//!    points, which get their new times; the shared path broadcast is this re-timed path.
//!
//! Why PF-ISO's path and the sequenced speeds rather than PF-ISO's speed optimisation aimed
//! at t_f: the crossing time is a constraint of the paper's problem, not a cost, and the
//! closed-form profile meets it exactly when the constraints are inactive; PF-ISO's path
//! field still moves the car laterally (lane change, keeping off the others' paths).
//!
//! Elsewhere (outside the zone, another lane, a road without a closed lane end, or a fallback
//! plan) the decision is PF-ISO's, unchanged.

use std::sync::Arc;

use mergesim_types::lanes::LaneRoad;
use mergesim_types::{
    Behaviour, BehaviourError, Decision, GridSpec, Observation, OptimiserReport, PathPoint,
};

use super::geometry::{MergeGeometry, MergeSide};
use super::params::SequencingParams;
use super::profile::{
    EnergyOptimalProfile, Leader, ProfileLimits, ProfileSample, constrained_profile,
};
use super::queue::{MergeQueue, QueueSettings, Report, Slot, Zones};
use crate::error::PlannerError;
use crate::params::PlannerParams;
use crate::planner_kind::PlannerKind;
use crate::planners::PfPlanner;
use crate::stop_and_go::segment_time_s;

/// Gravity (m/s²), for the friction limit of the braking bound.
const GRAVITY_MPS2: f64 = 9.81;
/// Most steps of one constrained profile (bounds a cycle's work).
const MAX_PROFILE_STEPS: usize = 4000;

/// What the last cycle did (for tests and diagnostics).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SequencingState {
    /// Whether the speeds were the sequenced ones.
    pub sequenced: bool,
    /// The car's slot, if it is in the queue.
    pub slot: Option<Slot>,
    /// Whether the rear-end constraint lowered a speed.
    pub rear_end_active: bool,
}

/// PF-ISO with merge sequencing (module doc).
#[derive(Clone, Debug)]
pub struct SequencedPlanner {
    inner: PfPlanner,
    params: SequencingParams,
    geometry: Option<MergeGeometry>,
    queue: MergeQueue,
    state: SequencingState,
}

impl SequencedPlanner {
    /// PF-ISO with `pf` on `lanes`, sequenced with `params`.
    pub fn new(
        pf: PlannerParams,
        params: SequencingParams,
        lanes: impl Into<Arc<LaneRoad>>,
    ) -> Result<Self, PlannerError> {
        params.validate()?;
        let lanes = lanes.into();
        let geometry = MergeGeometry::of(&lanes);
        Ok(Self {
            inner: PfPlanner::new(PlannerKind::PfIso, pf, lanes)?,
            params,
            geometry,
            queue: MergeQueue::new(),
            state: SequencingState::default(),
        })
    }

    /// The PF-ISO planner inside (e.g. to give it a route).
    pub fn with_inner(mut self, f: impl FnOnce(PfPlanner) -> PfPlanner) -> Self {
        self.inner = f(self.inner);
        self
    }

    /// The merge it sequences, if the road has one.
    pub fn geometry(&self) -> Option<&MergeGeometry> {
        self.geometry.as_ref()
    }

    /// The queue as this car knows it.
    pub fn queue(&self) -> &MergeQueue {
        &self.queue
    }

    /// What the last cycle did.
    pub fn last_state(&self) -> SequencingState {
        self.state
    }

    fn settings(&self) -> QueueSettings {
        QueueSettings {
            headway_s: self.params.headway_s,
            side_headway_s: self.params.side_headway_s,
            message_timeout_s: self.params.message_timeout_s,
            speed_floor_mps: self.inner.params().min_speed_mps,
        }
    }

    fn zones(&self, g: &MergeGeometry) -> Zones {
        Zones {
            control_start_m: g.merge_start_m - self.params.control_zone_length_m,
            merge_start_m: g.merge_start_m,
            merge_end_m: g.merge_end_m,
        }
    }

    /// A report of a position/speed at a stamp, if it is on either side of the merge.
    fn report(
        g: &MergeGeometry,
        road: &LaneRoad,
        id: mergesim_types::VehicleId,
        stamp_s: f64,
        p_m: [f64; 2],
        speed_mps: f64,
    ) -> Option<Report> {
        let side = g.side(road, p_m)?;
        let (s_m, _) = g.frame(road, p_m)?;
        Some(Report {
            id,
            stamp_s,
            s_m,
            speed_mps,
            on_ending_lane: side == MergeSide::Ending,
        })
    }

    /// The nearest car ahead in the ego's lane (lateral overlap plus the margin), from the
    /// perceived neighbours.
    fn leader(&self, g: &MergeGeometry, obs: &Observation<'_>) -> Option<Leader> {
        let (s_e, d_e) = g.frame(obs.lanes, [obs.ego.x_m, obs.ego.y_m])?;
        obs.neighbours
            .iter()
            .filter_map(|n| {
                let (s_n, d_n) = g.frame(obs.lanes, [n.state.x_m, n.state.y_m])?;
                let lateral_limit =
                    0.5 * (obs.ego_shape.width_m + n.shape.width_m) + self.params.lateral_margin_m;
                let gap_m = s_n - s_e - 0.5 * (obs.ego_shape.length_m + n.shape.length_m);
                (s_n > s_e && (d_n - d_e).abs() < lateral_limit).then_some(Leader {
                    gap_m,
                    speed_mps: n.state.speed_mps,
                })
            })
            .min_by(|a, b| a.gap_m.total_cmp(&b.gap_m))
    }

    /// The sequenced, constrained re-timing of `path` (module doc), or `None` to keep
    /// PF-ISO's decision.
    fn sequence(&mut self, obs: &Observation<'_>, path: &[PathPoint]) -> Option<Vec<PathPoint>> {
        let g = self.geometry.clone()?;
        let zones = self.zones(&g);
        let set = self.settings();
        let ego = Self::report(
            &g,
            obs.lanes,
            obs.ego_id,
            obs.time_s,
            [obs.ego.x_m, obs.ego.y_m],
            obs.ego.speed_mps,
        );
        let mut reports: Vec<Report> = obs
            .shared_paths
            .iter()
            .filter(|m| m.vehicle_id != obs.ego_id)
            .filter_map(|m| {
                let w = m.waypoints.first()?;
                Self::report(
                    &g,
                    obs.lanes,
                    m.vehicle_id,
                    m.stamp_s,
                    [w.x_m, w.y_m],
                    m.speed_mps,
                )
            })
            .collect();
        reports.extend(ego);
        self.queue.update(obs.time_s, &reports, &zones, &set);
        let ego = ego?;
        if ego.s_m < zones.control_start_m || ego.s_m >= zones.merge_end_m {
            return None;
        }
        let slot = self.queue.slot_of(obs.ego_id, &set);
        self.state.slot = slot;
        let pf = self.inner.params();
        let limits = ProfileLimits {
            min_speed_mps: pf.min_speed_mps,
            max_speed_mps: pf.speed_limit_mps,
            max_accel_mps2: self.params.max_accel_mps2,
            max_brake_mps2: obs
                .ego_shape
                .max_brake_decel_mps2
                .min(obs.mu * GRAVITY_MPS2)
                .max(self.params.max_accel_mps2),
            standstill_gap_m: self.params.standstill_gap_m,
            reaction_time_s: self.params.reaction_time_s,
            step_s: self.params.profile_step_s,
        };
        // Cumulative arc length of the path and PF-ISO's speeds along it.
        let mut along = Vec::with_capacity(path.len());
        let mut total = 0.0;
        for (k, p) in path.iter().enumerate() {
            if k > 0 {
                total += (p.x_m - path[k - 1].x_m).hypot(p.y_m - path[k - 1].y_m);
            }
            along.push(total);
        }
        let pf_speed = |s: f64| -> f64 {
            let k = along.partition_point(|&a| a < s).min(path.len() - 1);
            path[k].speed_mps
        };
        let optimal = slot.and_then(|slot| {
            (ego.s_m < zones.merge_start_m).then_some(())?;
            EnergyOptimalProfile::new(
                obs.time_s,
                obs.ego.speed_mps,
                zones.merge_start_m - ego.s_m,
                slot.crossing_s - obs.time_s,
            )
        });
        let desired = |tau: f64, s: f64| match &optimal {
            Some(p) => p.speed_mps(tau),
            None => pf_speed(s),
        };
        let leader = self.leader(&g, obs);
        let samples = constrained_profile(
            obs.ego.speed_mps,
            &limits,
            leader,
            total,
            MAX_PROFILE_STEPS,
            &desired,
        );
        let unconstrained = constrained_profile(
            obs.ego.speed_mps,
            &limits,
            None,
            total,
            MAX_PROFILE_STEPS,
            &desired,
        );
        self.state.rear_end_active = samples
            .iter()
            .zip(&unconstrained)
            .any(|(a, b)| a.speed_mps < b.speed_mps - 1e-9);
        self.state.sequenced = true;
        Some(retime(path, &along, &samples, obs.time_s))
    }
}

/// Local time at which the profile has covered `s_m`, if it does.
fn time_at(samples: &[ProfileSample], s_m: f64) -> Option<f64> {
    let k = samples.partition_point(|x| x.distance_m < s_m);
    let b = samples.get(k)?;
    match k.checked_sub(1).and_then(|i| samples.get(i)) {
        Some(a) if b.distance_m > a.distance_m => Some(
            a.tau_s + (b.tau_s - a.tau_s) * (s_m - a.distance_m) / (b.distance_m - a.distance_m),
        ),
        _ => Some(b.tau_s),
    }
}

/// `path` with the times and speeds of the profile (`PathPoint`'s convention: point k carries
/// the speed of the segment ending at it, t_k = t_{k−1} + Δs_k / v_k). A point the profile
/// reaches gets its time on the profile and the segment's mean speed; a point beyond what the
/// profile covers (it stopped behind a car ahead, or ran out of steps) gets the profile's last
/// speed, possibly 0, timed as the stop-and-go paths are (`stop_and_go::segment_time_s`: at
/// least 1 cm/s in the time only).
fn retime(
    path: &[PathPoint],
    along: &[f64],
    samples: &[ProfileSample],
    now_s: f64,
) -> Vec<PathPoint> {
    let last_speed = samples.last().map_or(0.0, |s| s.speed_mps);
    let mut out: Vec<PathPoint> = Vec::with_capacity(path.len());
    for (k, p) in path.iter().enumerate() {
        let (t_s, speed_mps) = match out.last() {
            None => (now_s, samples.first().map_or(p.speed_mps, |s| s.speed_mps)),
            Some(prev) => {
                let ds = along[k] - along[k - 1];
                match time_at(samples, along[k]) {
                    Some(tau) if now_s + tau > prev.t_s && ds > 0.0 => {
                        (now_s + tau, ds / (now_s + tau - prev.t_s))
                    }
                    Some(_) => (prev.t_s, prev.speed_mps),
                    None => (prev.t_s + segment_time_s(ds, last_speed), last_speed),
                }
            }
        };
        out.push(PathPoint {
            x_m: p.x_m,
            y_m: p.y_m,
            speed_mps,
            t_s,
        });
    }
    out
}

impl Behaviour for SequencedPlanner {
    fn plan(&mut self, obs: &Observation<'_>) -> Result<Decision, BehaviourError> {
        self.state = SequencingState::default();
        let decision = Behaviour::plan(&mut self.inner, obs)?;
        if decision.fallback.is_some() || decision.path.is_empty() {
            return Ok(decision);
        }
        match self.sequence(obs, &decision.path) {
            None => Ok(decision),
            // The sequenced path, shared as PF-ISO shares its own (the fallback is `None`
            // here: checked above).
            Some(path) => Ok(Decision {
                degraded_mode: decision.degraded_mode,
                ..Decision::follow_and_share(path, obs)
            }),
        }
    }

    fn optimiser_report(&self) -> Option<OptimiserReport> {
        self.inner.optimiser_report()
    }

    fn potential_field(&self, obs: &Observation<'_>, spec: &GridSpec) -> Option<Vec<f64>> {
        self.inner.potential_field(obs, spec)
    }
}
