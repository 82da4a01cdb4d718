//! The `[traffic]` tables of a scenario: vehicles generated from traffic flows, drawn per
//! instance from the seed.
//!
//! ```toml
//! [traffic.main]                                # one stream; its name prefixes its vehicles
//! flow_vph = { uniform = [1400.0, 2000.0] }     # total over its lanes, drawn per instance
//! lanes = [1, 2]                                # start lanes (ids, or "upper" / "lower")
//! rear_x_m = 20.0                               # the window the vehicles are placed in,
//! front_x_m = 620.0                             #   along each lane (x_m as a vehicle's)
//! speed_mps = 25.0                              # initial and target speed
//! min_headway_s = 1.0                           # h₀, the shift of the headways
//! driver = { planner = "pf-iso" }               # as a vehicle's `driver` (default PF-ISO)
//! # preset = "bmw_320i", connected = true (defaults)
//! ```
//!
//! # The generated vehicles
//! Vehicles are **placed at t = 0** along each lane of a stream, in the window
//! `[rear_x_m, front_x_m]`; none is inserted later (the world spawns every vehicle at the
//! start). A stream with flow `q` (veh/h, the total over its `n` lanes) gives each lane the flow
//! `q/n` and the mean time headway
//!
//! (1) `μ = 3600·n/q` (s).
//!
//! Time headways are shifted exponential (Buckley's shifted-exponential headway model):
//!
//! (2) `H = h₀ + τ·E`, `τ = μ − h₀ ≥ 0`, `E ~ Exp(1)`, so `E[H] = μ`, `H ≥ h₀`,
//!
//! and a time headway `h` is a spacing `h·v` at the stream's speed `v`. Each lane is one
//! *stationary* renewal process cut to the window: the front vehicle's gap to `front_x_m` is the
//! forward recurrence time `A` of (2), density `P(H > a)/μ`, i.e.
//!
//! (3) `A = U·h₀` with probability `h₀/μ`, else `A = h₀ + τ·E`,
//!
//! then `x₀ = front_x_m − v·A`, `x_{k+1} = x_k − v·H_k`, as long as `x_k ≥ rear_x_m`. For a
//! stationary renewal process the expected count in a window of duration `T` is exactly
//!
//! (4) `E[N] = T/μ`, `T = (front_x_m − rear_x_m)/v`,
//!
//! so the generated flow `3600·N/T` is on average the drawn flow (an ordinary renewal process,
//! starting with a full headway, would undercount by about `(μ² − σ²)/(2μ²)` vehicles per lane).
//! The count `N` varies per instance; the vehicles are named `<stream>_<lane>_<k>` (`k` = 00 for
//! the front one) and follow the scenario's `[[vehicles]]`, in stream-name order, then lane
//! order as listed.
//!
//! The **nominal** instance (no seed) uses the centre of the flow range and every headway at its
//! mean: `x_k = front_x_m − v·μ·(k + ½)`. The flow is drawn uniformly from `flow_vph`.
//!
//! # Streams
//! All draws come from the instance stream of [`crate::randomisation`]: with
//! `base = derive(seed, INSTANCE_STREAM)`, the flow of stream `S` is the first draw of
//! `SplitMix64(derive(base, fnv1a64("traffic.S.flow_vph")))` and the headways of its lane `L`
//! (the lane as written: `1`, `upper`) come, in order (two draws for (3), then one per headway),
//! from `SplitMix64(derive(base, fnv1a64("traffic.S.lane.L")))`. The keys differ from every
//! `[randomise]` key (`sim.…`, `vehicles.…`), so adding a stream changes no other draw.
//!
//! # Checks
//! Every instance is valid if the *densest* one is: every headway at `h₀` (spacing `v·h₀`) from
//! `front_x_m` back to `rear_x_m` (the last one moved to `rear_x_m`), which has the most
//! vehicles any instance can have, the closest spacing and both window ends. The scenario's
//! checks (vehicle count at most `sim::config::MAX_VEHICLES`, run budget, positions on the road,
//! no overlap at spawn over the `[randomise]` box) run on it as well as on the nominal instance.

use std::collections::BTreeMap;

use mergesim_types::bounds::Bound;
use serde::{Deserialize, Serialize};
use sim::config::{Driver, VehicleSpec};
use sim::rng::SplitMix64;
use sim::road_config::StartLane;

use crate::randomisation::{INSTANCE_STREAM, fnv1a64};

/// Default smallest time headway `h₀` (s).
pub const DEFAULT_MIN_HEADWAY_S: f64 = 1.0;

/// Allowed ranges of a `[traffic.<stream>]` table's numbers: `flow_vph` (either end of its
/// range), `speed_mps` (moving traffic: a headway is a spacing only at a speed above zero) and
/// `min_headway_s`. `rear_x_m` and `front_x_m` are checked against the road through the
/// vehicles they place.
pub const TRAFFIC_BOUNDS: &[Bound] = &[
    Bound::closed("flow_vph", 1.0, 10_000.0, "veh/h"),
    Bound::closed("speed_mps", 1.0, 70.0, "m/s"),
    Bound::closed("min_headway_s", 0.1, 60.0, "s"),
];

/// The range of [`TRAFFIC_BOUNDS`] named `field`.
fn range_of(field: &str) -> [f64; 2] {
    TRAFFIC_BOUNDS
        .iter()
        .find(|b| b.field == field)
        .map_or([f64::NAN, f64::NAN], |b| [b.min, b.max])
}

/// The `[traffic]` tables: streams by name.
pub type Traffic = BTreeMap<String, TrafficStream>;

/// A flow range `{ uniform = [lo, hi] }` (veh/h): each instance draws uniformly from it, the
/// nominal instance takes its centre.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlowRange {
    /// `[lo, hi]` (veh/h).
    #[serde(deserialize_with = "crate::distribution::exactly_two")]
    pub uniform: [f64; 2],
}

/// One traffic stream: vehicles generated on one or more lanes from a flow.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrafficStream {
    /// Total flow over `lanes` (veh/h), split equally over them.
    pub flow_vph: FlowRange,
    /// The start lanes (as a vehicle's `lane`).
    pub lanes: Vec<StartLane>,
    /// Rear end of the window the vehicles are placed in (m, along each lane).
    pub rear_x_m: f64,
    /// Front end of the window (m, along each lane).
    pub front_x_m: f64,
    /// Initial and target speed of every vehicle of the stream (m/s).
    pub speed_mps: f64,
    /// Smallest time headway `h₀` (s).
    #[serde(default = "default_min_headway_s")]
    pub min_headway_s: f64,
    /// Vehicle preset.
    #[serde(default = "default_preset")]
    pub preset: String,
    /// Who drives (as a vehicle's `driver`).
    #[serde(default = "default_driver")]
    pub driver: Driver,
    /// Whether its vehicles share their paths (V2V).
    #[serde(default = "default_true")]
    pub connected: bool,
}

fn default_min_headway_s() -> f64 {
    DEFAULT_MIN_HEADWAY_S
}

fn default_preset() -> String {
    "bmw_320i".into()
}

fn default_driver() -> Driver {
    Driver::planner("pf-iso")
}

fn default_true() -> bool {
    true
}

impl Default for TrafficStream {
    fn default() -> Self {
        Self {
            flow_vph: FlowRange {
                uniform: [1000.0, 1600.0],
            },
            lanes: vec![StartLane::Named(mergesim_types::Lane::Upper)],
            rear_x_m: 0.0,
            front_x_m: 400.0,
            speed_mps: 20.0,
            min_headway_s: DEFAULT_MIN_HEADWAY_S,
            preset: default_preset(),
            driver: default_driver(),
            connected: true,
        }
    }
}

/// A `[traffic]` value that is wrong: its key under the stream and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TrafficIssue {
    /// Key under `traffic.<stream>` (`flow_vph`, …); empty for the stream's name.
    pub key: &'static str,
    /// What is wrong.
    pub message: String,
}

/// How the headways of one lane are drawn.
enum Headways<'a> {
    /// Every headway at the mean (the nominal instance).
    Mean,
    /// Every headway at `h₀` (the densest instance, for the checks).
    Min,
    /// Drawn from this generator (an instance).
    Drawn(&'a mut SplitMix64),
}

impl TrafficStream {
    /// Checks the values on their own (the scenario checks the generated vehicles).
    pub(crate) fn validate(&self, name: &str) -> Result<(), TrafficIssue> {
        let issue = |key, message: String| Err(TrafficIssue { key, message });
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        {
            return issue(
                "",
                format!("stream name {name:?}: use letters, digits, '_' or '-'"),
            );
        }
        let [lo, hi] = self.flow_vph.uniform;
        let [min, max] = range_of("flow_vph");
        if !(lo.is_finite() && hi.is_finite() && min <= lo && lo <= hi && hi <= max) {
            return issue(
                "flow_vph",
                format!(
                    "flow_vph = {{ uniform = [{lo}, {hi}] }}: need {min} <= lo <= hi <= {max} veh/h"
                ),
            );
        }
        if self.lanes.is_empty() {
            return issue("lanes", "lanes = []: give at least one lane".into());
        }
        for (i, a) in self.lanes.iter().enumerate() {
            if self.lanes[..i].iter().any(|b| same_lane(*a, *b)) {
                return issue("lanes", format!("lane {} is listed twice", lane_label(*a)));
            }
        }
        let [min, max] = range_of("speed_mps");
        if !(self.speed_mps.is_finite() && (min..=max).contains(&self.speed_mps)) {
            return issue(
                "speed_mps",
                format!("speed_mps = {}: allowed {min} to {max} m/s", self.speed_mps),
            );
        }
        let [min, max] = range_of("min_headway_s");
        if !(self.min_headway_s.is_finite() && (min..=max).contains(&self.min_headway_s)) {
            return issue(
                "min_headway_s",
                format!(
                    "min_headway_s = {}: allowed {min} to {max} s",
                    self.min_headway_s
                ),
            );
        }
        if !(self.rear_x_m.is_finite() && self.front_x_m.is_finite())
            || self.rear_x_m >= self.front_x_m
        {
            return issue(
                "front_x_m",
                format!(
                    "front_x_m = {} must be finite and above rear_x_m = {}",
                    self.front_x_m, self.rear_x_m
                ),
            );
        }
        let mean_headway_s = self.mean_headway_s(hi);
        if mean_headway_s < self.min_headway_s {
            return issue(
                "flow_vph",
                format!(
                    "flow_vph up to {hi} veh/h over {} lane(s) is a mean headway of {mean_headway_s:.3} s, \
                     below min_headway_s = {} s (at most {:.0} veh/h)",
                    self.lanes.len(),
                    self.min_headway_s,
                    3600.0 * self.lanes.len() as f64 / self.min_headway_s
                ),
            );
        }
        Ok(())
    }

    /// Mean time headway in each lane at total flow `flow_vph`, equation (1) (s).
    pub fn mean_headway_s(&self, flow_vph: f64) -> f64 {
        3600.0 * self.lanes.len() as f64 / flow_vph
    }

    /// Duration of the window at the stream's speed, `T` of equation (4) (s).
    pub fn window_s(&self) -> f64 {
        (self.front_x_m - self.rear_x_m) / self.speed_mps
    }

    /// The nominal flow: the centre of the range (veh/h).
    pub fn nominal_flow_vph(&self) -> f64 {
        0.5 * (self.flow_vph.uniform[0] + self.flow_vph.uniform[1])
    }

    /// The flow instance `seed` draws (veh/h).
    pub fn drawn_flow_vph(&self, name: &str, seed: u64) -> f64 {
        let [lo, hi] = self.flow_vph.uniform;
        let mut rng = stream_rng(seed, &format!("traffic.{name}.flow_vph"));
        // lo + (hi − lo)·u with u in [0, 1) stays in [lo, hi] for finite lo <= hi.
        lo + (hi - lo) * rng.next_f64()
    }

    /// The positions of one lane's vehicles, front first (m along the lane).
    fn lane_positions(&self, flow_vph: f64, headways: Headways<'_>) -> Vec<f64> {
        let v = self.speed_mps;
        let h0 = self.min_headway_s;
        let mu = self.mean_headway_s(flow_vph);
        let tail_s = (mu - h0).max(0.0);
        let mut positions = Vec::new();
        match headways {
            Headways::Mean => {
                let mut x = self.front_x_m - 0.5 * v * mu;
                while x >= self.rear_x_m {
                    positions.push(x);
                    x -= v * mu;
                }
            }
            Headways::Min => {
                let mut x = self.front_x_m;
                while x >= self.rear_x_m {
                    positions.push(x);
                    x -= v * h0;
                }
                if let Some(last) = positions.last_mut() {
                    *last = self.rear_x_m;
                }
            }
            Headways::Drawn(rng) => {
                let exp = |rng: &mut SplitMix64| -(1.0 - rng.next_f64()).ln();
                // Equation (3): the forward recurrence time, from two draws.
                let (pick, u) = (rng.next_f64(), rng.next_f64());
                let first_s = if pick * mu < h0 {
                    u * h0
                } else {
                    h0 - tail_s * (1.0 - u).ln()
                };
                let mut x = self.front_x_m - v * first_s;
                while x >= self.rear_x_m {
                    positions.push(x);
                    x -= v * (h0 + tail_s * exp(rng));
                }
            }
        }
        positions
    }

    fn vehicles_from(&self, name: &str, lane: StartLane, positions: Vec<f64>) -> Vec<VehicleSpec> {
        positions
            .into_iter()
            .enumerate()
            .map(|(k, x_m)| VehicleSpec {
                name: format!("{name}_{}_{k:02}", lane_label(lane)),
                preset: self.preset.clone(),
                vehicle_model: None,
                lane,
                x_m,
                y_offset_m: 0.0,
                speed_mps: self.speed_mps,
                target_speed_mps: self.speed_mps,
                driver: self.driver.clone(),
                connected: self.connected,
                goal: None,
                route: None,
            })
            .collect()
    }
}

/// The instance a run uses.
#[derive(Clone, Copy, Debug)]
pub enum TrafficInstance {
    /// Centre flows, mean headways.
    Nominal,
    /// Drawn with this seed.
    Seed(u64),
    /// Every headway at `h₀` (what the checks use).
    Densest,
}

/// The vehicles `traffic` generates for `instance`, in stream-name then lane order.
pub fn generate(traffic: &Traffic, instance: TrafficInstance) -> Vec<VehicleSpec> {
    let mut vehicles = Vec::new();
    for (name, stream) in traffic {
        for &lane in &stream.lanes {
            let positions = match instance {
                TrafficInstance::Nominal => {
                    stream.lane_positions(stream.nominal_flow_vph(), Headways::Mean)
                }
                TrafficInstance::Densest => {
                    stream.lane_positions(stream.nominal_flow_vph(), Headways::Min)
                }
                TrafficInstance::Seed(seed) => {
                    let flow = stream.drawn_flow_vph(name, seed);
                    let key = format!("traffic.{name}.lane.{}", lane_label(lane));
                    let mut rng = stream_rng(seed, &key);
                    stream.lane_positions(flow, Headways::Drawn(&mut rng))
                }
            };
            vehicles.extend(stream.vehicles_from(name, lane, positions));
        }
    }
    vehicles
}

/// The generator of `key` under the instance stream of `seed`.
fn stream_rng(seed: u64, key: &str) -> SplitMix64 {
    let base = SplitMix64::derive(seed, INSTANCE_STREAM);
    SplitMix64::new(SplitMix64::derive(base, fnv1a64(key)))
}

/// A lane as written (`1`, `upper`).
pub fn lane_label(lane: StartLane) -> String {
    match lane {
        StartLane::Named(mergesim_types::Lane::Upper) => "upper".into(),
        StartLane::Named(mergesim_types::Lane::Lower) => "lower".into(),
        StartLane::Id(id) => id.to_string(),
    }
}

/// Whether two start lanes are the same lane (`"upper"` is id 1 on the merge road).
pub(crate) fn same_lane(a: StartLane, b: StartLane) -> bool {
    a == b || (a.merge_lane().is_some() && a.merge_lane() == b.merge_lane())
}

/// The stream whose generated vehicle is called `vehicle`, if any.
pub fn stream_of<'a>(traffic: &'a Traffic, vehicle: &str) -> Option<&'a str> {
    traffic
        .keys()
        .filter(|name| {
            vehicle
                .strip_prefix(name.as_str())
                .is_some_and(|rest| rest.starts_with('_'))
        })
        .max_by_key(|name| name.len())
        .map(String::as_str)
}

#[cfg(test)]
mod tests;
