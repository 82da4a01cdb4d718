//! A safety shield any planner can wear (`[sim] shield = "rss"`, parameters `[sim.rss]`): after
//! a vehicle's planner decides, the shield checks every perceived vehicle against RSS's rules
//! (`rss_rules`) and, in a dangerous situation, bounds the decided path by RSS's proper
//! response before the tracker follows it. Off by default (`shield = "none"`), and so in the
//! paper comparison. Vehicles driven by human-driver models (`driver = "idm"`, `"idm-mobil"`)
//! are not shielded.
//!
//! Each planning tick, for each other vehicle, in the shielded car's lane frame (s along its
//! lane, d across, positive to the left; speeds resolved along and across the lane's heading):
//!
//! 1. **Judge** the pair: is the longitudinal gap safe (Definition 1; the rear car's response
//!    time), is the lateral gap safe (Definition 7)? Dangerous when neither is. The pair is
//!    judged twice: now, and at the next check (one planning period ahead) with the shielded
//!    car where its decided path puts it and the other coasting. Dangerous at either is
//!    dangerous. The planners accelerate sideways far harder than RSS assumes of a car
//!    (a^lat_max,accel), so a judgement of the present alone would let a plan turn the pair
//!    dangerous between two checks, and release and re-engage the bound tick after tick.
//! 2. **Blame time.** While a pair is not dangerous, the shield remembers its judgement. When it
//!    turns dangerous, the remembered judgement fixes the proper response (Definition 10): the
//!    longitudinal one if the longitudinal gap was safe just before, the lateral one if the
//!    lateral gap was. A pair first seen already dangerous gets both. The responses hold until
//!    the pair is no longer dangerous.
//! 3. **Respond.**
//!    - Longitudinal, with the other ahead: the path's speeds are capped by braking at
//!      a_min,brake from the current speed, v ≤ √(v₀² − 2 a_min,brake · distance along the
//!      path), and its times follow the new speeds. (The front car's duty, braking no harder
//!      than a_max,brake, is left to its planner: the planners here never brake harder than
//!      their car's limit.)
//!    - Lateral: the path's points may not move toward the other beyond the car's lateral
//!      position now (d clamped at the current d on the other's side); the tracker then brings
//!      the lateral speed toward the other to zero as fast as it follows the path, not at
//!      exactly a^lat_min,brake.
//! 4. **The road's edge** is a standing object (RSS's front car at speed 0). Walk the bounded
//!    path, and past its end its last direction, up to the safe gap to a standing object. The
//!    edge is ahead at the first point where the car's side would come within the lateral
//!    margin μ of it, closer than it is now. If the gap to that point, less half the car's
//!    length, is below the safe one, the path's speeds are capped to stop there braking at
//!    a_min,brake. Without this a lateral bound could hold a car on its course into a lane
//!    that closes.
//!
//! An **intervention** is a pair (or the edge ahead) turning dangerous: the world logs a
//! `SimEvent::ShieldIntervened` naming the vehicle, the other and the responses, counted in
//! the run's summary (`shield_interventions`) and written to the recording's event log. The
//! message the vehicle broadcasts over V2V stays its planner's: the others hear the plan, not
//! the bound.

use std::collections::BTreeMap;

use mergesim_types::lanes::{Lane, LaneRoad};
use mergesim_types::{Decision, Observation, PathPoint, VehicleId, VehicleShape, VehicleState};
use serde::{Deserialize, Serialize};

pub mod rss_rules;
#[cfg(test)]
mod tests;

pub use rss_rules::{PairGeometry, PairSafety, Responses, RssParams, judge};

/// Which shield the planner-driven vehicles wear (`[sim] shield`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShieldKind {
    /// No shield: the planner's path is tracked as decided (the default).
    #[default]
    None,
    /// Responsibility-Sensitive Safety (`[sim.rss]`).
    Rss,
}

impl ShieldKind {
    /// Whether this is [`ShieldKind::None`].
    pub fn is_none(&self) -> bool {
        *self == Self::None
    }
}

/// What the shield remembers of one other vehicle.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PairMemory {
    /// The judgement at the last tick the pair was not dangerous.
    last_safe: Option<PairSafety>,
    /// The responses in force while the pair is dangerous.
    responding: Option<Responses>,
}

/// A pair that turned dangerous this tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intervention {
    /// The other vehicle; `None`: the road's edge ahead on the path.
    pub other: Option<VehicleId>,
    /// The responses the blame time called for.
    pub responses: Responses,
    /// The judgement that found the pair dangerous.
    pub safety: PairSafety,
    /// The bumper-to-bumper gap along the lane then (m).
    pub lon_gap_m: f64,
}

/// The RSS shield of one vehicle (module doc).
#[derive(Clone, Debug)]
pub struct RssShield {
    params: RssParams,
    /// How far ahead (s) the decided path is checked: the time to the next check, one planning
    /// period.
    check_ahead_s: f64,
    memory: BTreeMap<VehicleId, PairMemory>,
    /// Whether the road's edge ahead on the path was dangerous at the last tick.
    edge_dangerous: bool,
}

/// The car's state where `path` puts it at `t_s` (linear between its points by their times;
/// heading along the path); `None` for a path of fewer than two points.
fn state_on_path(path: &[PathPoint], t_s: f64) -> Option<VehicleState> {
    let k = path
        .windows(2)
        .position(|w| w[1].t_s >= t_s)
        .unwrap_or(path.len().checked_sub(2)?);
    let (a, b) = (path.get(k)?, path.get(k + 1)?);
    let span_s = b.t_s - a.t_s;
    let w = if span_s > 0.0 {
        ((t_s - a.t_s) / span_s).clamp(0.0, 1.0)
    } else {
        1.0
    };
    Some(VehicleState {
        x_m: a.x_m + w * (b.x_m - a.x_m),
        y_m: a.y_m + w * (b.y_m - a.y_m),
        yaw_rad: (b.y_m - a.y_m).atan2(b.x_m - a.x_m),
        speed_mps: a.speed_mps + w * (b.speed_mps - a.speed_mps),
    })
}

/// The state `dt_s` later at constant speed and heading.
fn coasting(s: &VehicleState, dt_s: f64) -> VehicleState {
    let (sin, cos) = s.yaw_rad.sin_cos();
    VehicleState {
        x_m: s.x_m + s.speed_mps * cos * dt_s,
        y_m: s.y_m + s.speed_mps * sin * dt_s,
        ..*s
    }
}

/// Speed along and across a lane of heading `heading_rad` (m/s).
fn resolve(state: &VehicleState, heading_rad: f64) -> (f64, f64) {
    let (sin, cos) = (state.yaw_rad - heading_rad).sin_cos();
    (state.speed_mps * cos, state.speed_mps * sin)
}

/// The pair's geometry in `lane`'s frame (module doc).
pub fn pair_geometry(
    lane: &Lane,
    me: &VehicleState,
    my_shape: &VehicleShape,
    other: &VehicleState,
    other_shape: &VehicleShape,
) -> PairGeometry {
    let mine = lane.project([me.x_m, me.y_m]);
    let theirs = lane.project([other.x_m, other.y_m]);
    let (my_lon_mps, my_lat_mps) = resolve(me, lane.heading_rad(mine.s_m));
    let (other_lon_mps, other_lat_mps) = resolve(other, lane.heading_rad(theirs.s_m));
    let ds_m = theirs.s_m - mine.s_m;
    let dd_m = theirs.d_m - mine.d_m;
    PairGeometry {
        ds_m,
        dd_m,
        lon_gap_m: ds_m.abs() - 0.5 * (my_shape.length_m + other_shape.length_m),
        lat_gap_m: dd_m.abs() - 0.5 * (my_shape.width_m + other_shape.width_m),
        my_lon_mps,
        other_lon_mps,
        my_lat_mps,
        other_lat_mps,
    }
}

impl RssShield {
    /// A shield with `params` and nothing remembered, checking the decided path `check_ahead_s`
    /// ahead (the planning period: until the next check).
    pub fn new(params: RssParams, check_ahead_s: f64) -> Self {
        Self {
            params,
            check_ahead_s,
            memory: BTreeMap::new(),
            edge_dangerous: false,
        }
    }

    /// Judges every perceived vehicle, bounds `decision`'s path by the responses in force, and
    /// returns the pairs that turned dangerous this tick (module doc).
    pub fn apply(&mut self, obs: &Observation<'_>, decision: &mut Decision) -> Vec<Intervention> {
        let hit = obs.lanes.nearest_lane([obs.ego.x_m, obs.ego.y_m]);
        let Some(lane) = obs.lanes.lane(hit.lane) else {
            return Vec::new();
        };
        let mut started = Vec::new();
        let mut brake = false;
        // The lateral bounds in force: d no more than `left_limit`, no less than `right_limit`.
        let mut left_limit_m = f64::INFINITY;
        let mut right_limit_m = f64::NEG_INFINITY;
        let my_d_m = lane.project([obs.ego.x_m, obs.ego.y_m]).d_m;
        let mut seen: Vec<VehicleId> = Vec::with_capacity(obs.neighbours.len());
        // Where the decided path puts the car at the next check.
        let t_next_s = obs.time_s + self.check_ahead_s;
        let me_next = state_on_path(&decision.path, t_next_s).unwrap_or(obs.ego);
        for n in obs.neighbours {
            seen.push(n.id);
            let g = pair_geometry(lane, &obs.ego, &obs.ego_shape, &n.state, &n.shape);
            let now = judge(&g, &self.params);
            let n_next = coasting(&n.state, self.check_ahead_s);
            let g_next = pair_geometry(lane, &me_next, &obs.ego_shape, &n_next, &n.shape);
            let next = judge(&g_next, &self.params);
            // Dangerous now, or at the next check if the path is followed: the judgement that
            // says so stands for the pair this tick.
            let safety = if now.dangerous() || !next.dangerous() {
                now
            } else {
                next
            };
            let memory = self.memory.entry(n.id).or_insert(PairMemory {
                last_safe: None,
                responding: None,
            });
            if !safety.dangerous() {
                memory.last_safe = Some(safety);
                memory.responding = None;
                continue;
            }
            let responses = match memory.responding {
                Some(r) => r,
                None => {
                    let r = Responses::at_blame_time(memory.last_safe.as_ref());
                    memory.responding = Some(r);
                    started.push(Intervention {
                        other: Some(n.id),
                        responses: r,
                        safety,
                        lon_gap_m: g.lon_gap_m,
                    });
                    r
                }
            };
            if responses.longitudinal && g.ds_m >= 0.0 {
                brake = true;
            }
            if responses.lateral {
                if g.dd_m >= 0.0 {
                    left_limit_m = left_limit_m.min(my_d_m);
                } else {
                    right_limit_m = right_limit_m.max(my_d_m);
                }
            }
        }
        self.memory.retain(|id, _| seen.contains(id));
        if left_limit_m.is_finite() || right_limit_m.is_finite() {
            hold_lateral(&mut decision.path, lane, right_limit_m, left_limit_m);
        }
        if brake {
            cap_by_braking(
                &mut decision.path,
                obs.ego.speed_mps,
                self.params.brake_min_mps2,
                obs.time_s,
            );
        }
        // The road's edge, a standing object: where the (bounded) path would bring the car's
        // side within the lateral margin of it, closer than the car is now.
        let need_m = 0.5 * obs.ego_shape.width_m + self.params.lat_margin_m;
        let safe_m = rss_rules::safe_longitudinal_gap_m(
            obs.ego.speed_mps,
            0.0,
            self.params.response_time_s,
            &self.params,
        );
        let half_length_m = 0.5 * obs.ego_shape.length_m;
        let edge = edge_ahead_m(&decision.path, obs.lanes, need_m, safe_m + half_length_m)
            .map(|along_m| along_m - half_length_m);
        let edge_dangerous = edge.map(|gap_m| (gap_m, safe_m, gap_m < safe_m));
        match edge_dangerous {
            Some((gap_m, safe_m, true)) => {
                if !self.edge_dangerous {
                    started.push(Intervention {
                        other: None,
                        responses: Responses {
                            longitudinal: true,
                            lateral: false,
                        },
                        safety: PairSafety {
                            lon_safe: false,
                            lat_safe: false,
                            safe_lon_gap_m: safe_m,
                            safe_lat_gap_m: need_m,
                        },
                        lon_gap_m: gap_m,
                    });
                }
                self.edge_dangerous = true;
                stop_before(
                    &mut decision.path,
                    gap_m,
                    self.params.brake_min_mps2,
                    obs.time_s,
                );
            }
            _ => self.edge_dangerous = false,
        }
        started
    }
}

/// Clamps each path point's lateral offset in `lane`'s frame to [`min_d_m`, `max_d_m`] (either
/// may be infinite), keeping its arc length.
fn hold_lateral(path: &mut [PathPoint], lane: &Lane, min_d_m: f64, max_d_m: f64) {
    for p in path.iter_mut() {
        let f = lane.project([p.x_m, p.y_m]);
        let d_m = f.d_m.max(min_d_m).min(max_d_m);
        if d_m != f.d_m {
            let [x_m, y_m] = lane.point(f.s_m, d_m);
            p.x_m = x_m;
            p.y_m = y_m;
        }
    }
}

/// How far along `path` (m) the first point lies whose distance to the road's edge is below
/// `need_m` and below the path's start's: the path heads toward the edge there. Past the path's
/// end, its last segment is extended straight in [`EDGE_STEP_M`] steps up to `look_m` along
/// the path. `None` if no point does.
fn edge_ahead_m(path: &[PathPoint], lanes: &LaneRoad, need_m: f64, look_m: f64) -> Option<f64> {
    let first = path.first()?;
    let start_m = lanes.signed_distance_to_edge_m([first.x_m, first.y_m]);
    let blocked = |p: [f64; 2]| {
        let clearance_m = lanes.signed_distance_to_edge_m(p);
        clearance_m < need_m && clearance_m < start_m
    };
    let mut along_m = 0.0;
    for k in 1..path.len() {
        let (a, b) = (&path[k - 1], &path[k]);
        along_m += (b.x_m - a.x_m).hypot(b.y_m - a.y_m);
        if blocked([b.x_m, b.y_m]) {
            return Some(along_m);
        }
    }
    // The last segment's direction, extended.
    let (a, b) = match path {
        [.., a, b] => (a, b),
        _ => return None,
    };
    let length_m = (b.x_m - a.x_m).hypot(b.y_m - a.y_m);
    if length_m <= 0.0 {
        return None;
    }
    let (ux, uy) = ((b.x_m - a.x_m) / length_m, (b.y_m - a.y_m) / length_m);
    let steps = ((look_m - along_m) / EDGE_STEP_M).ceil().clamp(0.0, 1e4) as usize;
    (1..=steps)
        .map(|k| k as f64 * EDGE_STEP_M)
        .find(|&beyond_m| blocked([b.x_m + ux * beyond_m, b.y_m + uy * beyond_m]))
        .map(|beyond_m| along_m + beyond_m)
}

/// Step (m) of the look past a path's end for the road's edge.
const EDGE_STEP_M: f64 = 1.0;

/// Caps the path's speeds to stop `stop_m` along it, braking at `brake_mps2`,
/// v ≤ √(2 · brake · (stop − distance along)), and times its points by the new speeds if any
/// was lowered.
fn stop_before(path: &mut [PathPoint], stop_m: f64, brake_mps2: f64, t0_s: f64) {
    let mut along_m = 0.0;
    let mut lowered = false;
    for k in 0..path.len() {
        if k > 0 {
            along_m += (path[k].x_m - path[k - 1].x_m).hypot(path[k].y_m - path[k - 1].y_m);
        }
        let cap_mps = (2.0 * brake_mps2 * (stop_m - along_m)).max(0.0).sqrt();
        if path[k].speed_mps > cap_mps {
            path[k].speed_mps = cap_mps;
            lowered = true;
        }
    }
    if lowered {
        retime(path, t0_s);
    }
}

/// Times the path's points by their speeds from `t0_s` (a standing stretch gets the time of a
/// crawl at [`CRAWL_MPS`]).
fn retime(path: &mut [PathPoint], t0_s: f64) {
    for k in 0..path.len() {
        path[k].t_s = if k == 0 {
            t0_s
        } else {
            let (a, b) = (&path[k - 1], &path[k]);
            let ds_m = (b.x_m - a.x_m).hypot(b.y_m - a.y_m);
            a.t_s + ds_m / (0.5 * (a.speed_mps + b.speed_mps)).max(CRAWL_MPS)
        };
    }
}

/// Caps the path's speeds by braking at `brake_mps2` from `speed_mps` at its start: a stop
/// ([`stop_before`]) where that braking ends, v₀² / (2 · brake) along the path.
fn cap_by_braking(path: &mut [PathPoint], speed_mps: f64, brake_mps2: f64, t0_s: f64) {
    let v0_mps = speed_mps.max(0.0);
    stop_before(path, v0_mps * v0_mps / (2.0 * brake_mps2), brake_mps2, t0_s);
}

/// The speed (m/s) that times a path's standing stretch after the shield stops it.
const CRAWL_MPS: f64 = 0.1;
