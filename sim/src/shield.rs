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
//!    time), is the lateral gap safe (Definition 7)? Dangerous when neither is.
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
//!
//! An **intervention** is a pair turning dangerous: the world logs a
//! `SimEvent::ShieldIntervened` naming the vehicle, the other and the responses, counted in
//! the run's summary (`shield_interventions`) and written to the recording's event log. The
//! message the vehicle broadcasts over V2V stays its planner's: the others hear the plan, not
//! the bound.

use std::collections::BTreeMap;

use mergesim_types::lanes::Lane;
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
    /// The other vehicle.
    pub other: VehicleId,
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
    memory: BTreeMap<VehicleId, PairMemory>,
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
    /// A shield with `params` and nothing remembered.
    pub fn new(params: RssParams) -> Self {
        Self {
            params,
            memory: BTreeMap::new(),
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
        for n in obs.neighbours {
            seen.push(n.id);
            let g = pair_geometry(lane, &obs.ego, &obs.ego_shape, &n.state, &n.shape);
            let safety = judge(&g, &self.params);
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
                        other: n.id,
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

/// Caps the path's speeds by braking at `brake_mps2` from `speed_mps` at its start; if that
/// lowers any, times its points by the new speeds from `t0_s` (a standing stretch gets the time
/// of a crawl at [`CRAWL_MPS`]).
fn cap_by_braking(path: &mut [PathPoint], speed_mps: f64, brake_mps2: f64, t0_s: f64) {
    let v0_sq = speed_mps.max(0.0).powi(2);
    let mut along_m = 0.0;
    let mut lowered = false;
    for k in 0..path.len() {
        if k > 0 {
            along_m += (path[k].x_m - path[k - 1].x_m).hypot(path[k].y_m - path[k - 1].y_m);
        }
        let cap_mps = (v0_sq - 2.0 * brake_mps2 * along_m).max(0.0).sqrt();
        if path[k].speed_mps > cap_mps {
            path[k].speed_mps = cap_mps;
            lowered = true;
        }
    }
    if !lowered {
        return;
    }
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

/// The speed (m/s) that times a path's standing stretch after the shield stops it.
const CRAWL_MPS: f64 = 0.1;
