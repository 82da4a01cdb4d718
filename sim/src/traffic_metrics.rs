//! The figures a traffic engineer reads off a merge: throughput through the merge, whether the
//! vehicles of the ending lane merged before it ended, delay and speed loss against free flow,
//! and the safety figures (near misses, TET, collisions, shield interventions) per vehicle
//! class.
//!
//! # Definitions
//! - **Ending lanes**: the lanes that end closed, and every lane whose successors are all
//!   ending lanes (on the on-ramp road the acceleration lane and the ramp feeding it; on the
//!   two-into-one road the lower lane). A vehicle whose start lane is one of them is a
//!   *merging* vehicle.
//! - **Merged**: a merging vehicle has merged at the first log instant at which its lane
//!   (the lane membership of `crate::lane_membership`, with its hysteresis) is not an ending
//!   lane. It merged **before its lane ended** if it merged and had no road-edge contact
//!   before that instant (a vehicle squeezed against the taper or the lane's closed end did
//!   not).
//! - **Measurement section**: the end of the merge zone (`crate::lane_membership::MergeZone`:
//!   [`MERGE_ZONE_TAIL_M`] past the end of the ending lane), as an arc length along the lane
//!   the ending lane merges into. A vehicle crosses it when it is in that lane, a
//!   same-direction neighbour of it or a successor of either, and its centre's arc length
//!   along that lane passes the section's; the crossing time is interpolated linearly between
//!   the two log instants around it. Roads without an ending lane have no section.
//! - **Throughput** (vehicles per hour): with n ≥ 2 crossings at times t₁ ≤ … ≤ tₙ,
//!   3600 · (n − 1) / (tₙ − t₁): the inverse of the mean headway at the section, the flow an
//!   observer standing there counts while the vehicles pass. A run places its vehicles at the
//!   start, so this is the flow the merge let through, not a capacity.
//! - **Delay** (s): the run's time T minus the time the vehicle would have needed for the
//!   distance D it drove at its target speed: T − D / V_target (negative for a vehicle faster
//!   than its target). **Speed loss**: 1 − (D / T) / V_target. D integrates the speed over the
//!   log instants with the trapezoidal rule.
//! - **TET** of a vehicle: the time during which at least one of its pairs had TTC below the
//!   threshold (`crate::safety`); a class's TET is the sum over its vehicles (Minderhoud &
//!   Bovy 2001).
//! - **Class**: the vehicle's driver as it ran: the planner's registered name (after
//!   `--planner`), or `idm`, `idm-mobil`, `lane-keeping`, `prescribed`.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

use mergesim_types::VehicleId;
use mergesim_types::lanes::{LaneId, LaneRoad};
use serde::{Deserialize, Serialize};

use crate::error::SimError;
use crate::event::SimEvent;
use crate::lane_membership::{MergeZone, lane_of};
use crate::observer::{TickObserver, VehicleView};
use crate::safety::SafetySummary;

pub use crate::lane_membership::MERGE_ZONE_TAIL_M;

/// One vehicle's traffic figures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VehicleTraffic {
    /// Its name.
    pub vehicle: String,
    /// Its class (module doc).
    pub class: String,
    /// The lane it started in (`None` if it was never logged).
    pub start_lane: Option<LaneId>,
    /// Whether it started in an ending lane (module doc).
    pub merging: bool,
    /// When it left the ending lanes (s); `None` if it did not, or is not merging.
    pub merged_at_s: Option<f64>,
    /// Whether it merged before its lane ended (module doc); `None` if it is not merging.
    pub merged_before_lane_end: Option<bool>,
    /// When it crossed the measurement section (s); `None` if it did not.
    pub crossed_section_at_s: Option<f64>,
    /// Distance driven (m).
    pub distance_m: f64,
    /// Delay against driving at its target speed (s).
    pub delay_s: f64,
    /// Speed loss against its target speed (fraction, 0 at the target speed).
    pub speed_loss: f64,
    /// Time exposed to a TTC below the threshold (s).
    pub tet_s: f64,
    /// Whether one of its pairs is a near miss.
    pub near_miss: bool,
    /// Collision episodes it was in (vehicle–vehicle).
    pub collisions: u32,
    /// Road-edge contact episodes.
    pub edge_contacts: u32,
    /// Times its safety shield intervened.
    pub shield_interventions: u32,
}

/// The figures of one class of vehicles (module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClassTraffic {
    /// The class.
    pub class: String,
    /// Its vehicles.
    pub vehicles: u32,
    /// Of them, merging ones.
    pub merging: u32,
    /// Merging ones that merged before their lane ended.
    pub merged_before_lane_end: u32,
    /// Vehicles that crossed the measurement section.
    pub crossed_section: u32,
    /// Mean delay (s).
    pub mean_delay_s: f64,
    /// Mean speed loss (fraction).
    pub mean_speed_loss: f64,
    /// Summed TET of its vehicles (s).
    pub tet_s: f64,
    /// Its vehicles with a near miss.
    pub near_misses: u32,
    /// Collision episodes involving one of its vehicles (an episode between two of them counts
    /// once).
    pub collisions: u32,
    /// Road-edge contact episodes of its vehicles.
    pub edge_contacts: u32,
    /// Shield interventions of its vehicles.
    pub shield_interventions: u32,
}

/// The run's traffic figures (module doc).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TrafficSummary {
    /// The lane the section is measured along; `None` without an ending lane.
    pub section_lane: Option<LaneId>,
    /// The section's arc length along it (m).
    pub section_s_m: Option<f64>,
    /// Vehicles that crossed the section.
    pub crossings: u32,
    /// Throughput at the section (vehicles per hour); `None` with fewer than two crossings.
    pub throughput_vph: Option<f64>,
    /// Merging vehicles.
    pub merging: u32,
    /// Merging vehicles that merged before their lane ended.
    pub merged_before_lane_end: u32,
    /// Mean delay over the vehicles (s); `None` without vehicles.
    pub mean_delay_s: Option<f64>,
    /// Per class, sorted by class name.
    pub classes: Vec<ClassTraffic>,
    /// Per vehicle, in vehicle order.
    pub vehicles: Vec<VehicleTraffic>,
}

/// One vehicle as the observer follows it.
#[derive(Clone, Debug)]
struct Track {
    name: String,
    class: String,
    target_speed_mps: f64,
    lane: Option<LaneId>,
    start_lane: Option<LaneId>,
    merged_at_s: Option<f64>,
    crossed_at_s: Option<f64>,
    /// Arc length along the section lane at the last log instant, while eligible.
    last_section_s: Option<(f64, f64)>,
    first_t_s: Option<f64>,
    last: Option<(f64, f64)>,
    distance_m: f64,
    first_edge_contact_s: Option<f64>,
    edge_contacts: u32,
    shield_interventions: u32,
}

/// The observer of the traffic figures: fed every log instant and event, summed up with the
/// safety monitor's figures at the end ([`TrafficMetrics::summary`]).
#[derive(Clone, Debug)]
pub struct TrafficMetrics {
    lanes: Arc<LaneRoad>,
    ending: BTreeSet<LaneId>,
    section: Option<(LaneId, f64)>,
    counted_lanes: BTreeSet<LaneId>,
    tracks: Vec<Track>,
    by_name: BTreeMap<String, usize>,
}

impl TrafficMetrics {
    /// The observer for vehicles given as `(name, class, target speed (m/s))`, in id order, on
    /// the road `lanes`.
    pub fn new(lanes: Arc<LaneRoad>, vehicles: Vec<(String, String, f64)>) -> Self {
        let ending = ending_lanes(&lanes);
        let zone = MergeZone::of(&lanes);
        let section = zone.as_ref().map(|z| (z.along, z.s_m[1]));
        let counted_lanes = section
            .map(|(along, _)| counted_lanes(&lanes, along, &ending))
            .unwrap_or_default();
        let by_name = vehicles
            .iter()
            .enumerate()
            .map(|(i, (name, _, _))| (name.clone(), i))
            .collect();
        let tracks = vehicles
            .into_iter()
            .map(|(name, class, target_speed_mps)| Track {
                name,
                class,
                target_speed_mps,
                lane: None,
                start_lane: None,
                merged_at_s: None,
                crossed_at_s: None,
                last_section_s: None,
                first_t_s: None,
                last: None,
                distance_m: 0.0,
                first_edge_contact_s: None,
                edge_contacts: 0,
                shield_interventions: 0,
            })
            .collect();
        Self {
            lanes,
            ending,
            section,
            counted_lanes,
            tracks,
            by_name,
        }
    }

    /// The figures of the run, with the safety monitor's per-vehicle figures.
    pub fn summary(&self, safety: &SafetySummary) -> TrafficSummary {
        let exposure: BTreeMap<VehicleId, f64> = safety.vehicle_tet_s.iter().copied().collect();
        let mut near_miss = vec![false; self.tracks.len()];
        for pair in safety.pairs.iter().filter(|p| p.near_miss) {
            for id in [pair.id_a, pair.id_b] {
                if let Some(flag) = near_miss.get_mut(id as usize) {
                    *flag = true;
                }
            }
        }
        let mut collisions = vec![0u32; self.tracks.len()];
        for c in &safety.collisions {
            for id in [c.id_a, c.id_b] {
                if let Some(n) = collisions.get_mut(id as usize) {
                    *n += 1;
                }
            }
        }
        let vehicles: Vec<VehicleTraffic> = self
            .tracks
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let merging = t.start_lane.is_some_and(|l| self.ending.contains(&l));
                let elapsed_s = match (t.first_t_s, t.last) {
                    (Some(first), Some((last, _))) => last - first,
                    _ => 0.0,
                };
                let free_time_s = if t.target_speed_mps > 0.0 {
                    t.distance_m / t.target_speed_mps
                } else {
                    0.0
                };
                let speed_loss = if elapsed_s > 0.0 && t.target_speed_mps > 0.0 {
                    1.0 - (t.distance_m / elapsed_s) / t.target_speed_mps
                } else {
                    0.0
                };
                VehicleTraffic {
                    vehicle: t.name.clone(),
                    class: t.class.clone(),
                    start_lane: t.start_lane,
                    merging,
                    merged_at_s: t.merged_at_s.filter(|_| merging),
                    merged_before_lane_end: merging.then(|| {
                        t.merged_at_s.is_some_and(|m| {
                            t.first_edge_contact_s.is_none_or(|contact| contact > m)
                        })
                    }),
                    crossed_section_at_s: t.crossed_at_s,
                    distance_m: t.distance_m,
                    delay_s: elapsed_s - free_time_s,
                    speed_loss,
                    tet_s: exposure.get(&(i as VehicleId)).copied().unwrap_or(0.0),
                    near_miss: near_miss[i],
                    collisions: collisions[i],
                    edge_contacts: t.edge_contacts,
                    shield_interventions: t.shield_interventions,
                }
            })
            .collect();
        let classes = class_figures(&vehicles, safety);
        let mut crossing_times: Vec<f64> = vehicles
            .iter()
            .filter_map(|v| v.crossed_section_at_s)
            .collect();
        crossing_times.sort_by(f64::total_cmp);
        let throughput_vph = match (crossing_times.first(), crossing_times.last()) {
            (Some(&first), Some(&last)) if crossing_times.len() >= 2 && last > first => {
                Some(3600.0 * (crossing_times.len() - 1) as f64 / (last - first))
            }
            _ => None,
        };
        let mean_delay_s = (!vehicles.is_empty())
            .then(|| vehicles.iter().map(|v| v.delay_s).sum::<f64>() / vehicles.len() as f64);
        TrafficSummary {
            section_lane: self.section.map(|(lane, _)| lane),
            section_s_m: self.section.map(|(_, s)| s),
            crossings: crossing_times.len() as u32,
            throughput_vph,
            merging: vehicles.iter().filter(|v| v.merging).count() as u32,
            merged_before_lane_end: vehicles
                .iter()
                .filter(|v| v.merged_before_lane_end == Some(true))
                .count() as u32,
            mean_delay_s,
            classes,
            vehicles,
        }
    }

    /// Follows vehicle `index` to the log instant `t_s` at `p_m`, driving at `speed_mps`.
    fn follow(&mut self, index: usize, t_s: f64, p_m: [f64; 2], speed_mps: f64) {
        let lanes = &self.lanes;
        let Some(track) = self.tracks.get_mut(index) else {
            return;
        };
        let lane = lane_of(lanes, track.lane, p_m).lane;
        track.lane = Some(lane);
        if track.start_lane.is_none() {
            track.start_lane = Some(lane);
            track.first_t_s = Some(t_s);
        }
        if let Some((t0, v0)) = track.last {
            track.distance_m += 0.5 * (v0 + speed_mps) * (t_s - t0);
        }
        track.last = Some((t_s, speed_mps));
        if track.merged_at_s.is_none()
            && track.start_lane.is_some_and(|l| self.ending.contains(&l))
            && !self.ending.contains(&lane)
        {
            track.merged_at_s = Some(t_s);
        }
        let Some((along, section_s_m)) = self.section else {
            return;
        };
        if track.crossed_at_s.is_some() {
            return;
        }
        if !self.counted_lanes.contains(&lane) {
            track.last_section_s = None;
            return;
        }
        let Some(s_m) = lanes.lane(along).map(|l| l.project(p_m).s_m) else {
            return;
        };
        if s_m >= section_s_m {
            track.crossed_at_s = Some(match track.last_section_s {
                Some((t0, s0)) if s_m > s0 && s0 < section_s_m => {
                    t0 + (section_s_m - s0) / (s_m - s0) * (t_s - t0)
                }
                // Already past it at its first counted instant: it started there (or changed
                // into a counted lane past it), and crosses now.
                _ => t_s,
            });
        }
        track.last_section_s = Some((t_s, s_m));
    }

    fn track_of(&mut self, name: &str) -> Option<&mut Track> {
        let index = *self.by_name.get(name)?;
        self.tracks.get_mut(index)
    }
}

impl TickObserver for TrafficMetrics {
    fn on_log(&mut self, t_s: f64, vehicles: &[VehicleView<'_>]) -> Result<(), SimError> {
        for v in vehicles {
            let sample = v.sample;
            self.follow(
                v.id as usize,
                t_s,
                [sample.x_m, sample.y_m],
                sample.speed_mps,
            );
        }
        Ok(())
    }

    fn on_event(&mut self, event: &SimEvent) -> Result<(), SimError> {
        match event {
            SimEvent::EdgeContact { t_s, vehicle, .. } => {
                if let Some(track) = self.track_of(vehicle) {
                    track.edge_contacts += 1;
                    track.first_edge_contact_s.get_or_insert(*t_s);
                }
            }
            SimEvent::ShieldIntervened { vehicle, .. } => {
                if let Some(track) = self.track_of(vehicle) {
                    track.shield_interventions += 1;
                }
            }
            _ => {}
        }
        Ok(())
    }
}

/// The per-class figures of `vehicles`, sorted by class.
fn class_figures(vehicles: &[VehicleTraffic], safety: &SafetySummary) -> Vec<ClassTraffic> {
    let mut classes: BTreeMap<&str, ClassTraffic> = BTreeMap::new();
    for v in vehicles {
        let c = classes.entry(&v.class).or_insert_with(|| ClassTraffic {
            class: v.class.clone(),
            vehicles: 0,
            merging: 0,
            merged_before_lane_end: 0,
            crossed_section: 0,
            mean_delay_s: 0.0,
            mean_speed_loss: 0.0,
            tet_s: 0.0,
            near_misses: 0,
            collisions: 0,
            edge_contacts: 0,
            shield_interventions: 0,
        });
        c.vehicles += 1;
        c.merging += u32::from(v.merging);
        c.merged_before_lane_end += u32::from(v.merged_before_lane_end == Some(true));
        c.crossed_section += u32::from(v.crossed_section_at_s.is_some());
        c.mean_delay_s += v.delay_s;
        c.mean_speed_loss += v.speed_loss;
        c.tet_s += v.tet_s;
        c.near_misses += u32::from(v.near_miss);
        c.edge_contacts += v.edge_contacts;
        c.shield_interventions += v.shield_interventions;
    }
    for c in classes.values_mut() {
        let n = f64::from(c.vehicles.max(1));
        c.mean_delay_s /= n;
        c.mean_speed_loss /= n;
    }
    // A collision episode counts once per class it involves.
    for collision in &safety.collisions {
        let involved: BTreeSet<&str> = [collision.id_a, collision.id_b]
            .iter()
            .filter_map(|&id| vehicles.get(id as usize))
            .map(|v| v.class.as_str())
            .collect();
        for class in involved {
            if let Some(c) = classes.get_mut(class) {
                c.collisions += 1;
            }
        }
    }
    classes.into_values().collect()
}

/// The ending lanes of `lanes` (module doc): closed at their end, or leading only into such.
fn ending_lanes(lanes: &LaneRoad) -> BTreeSet<LaneId> {
    let mut ending: BTreeSet<LaneId> = lanes
        .lane_ends()
        .iter()
        .filter(|e| e.closed)
        .map(|e| e.lane)
        .collect();
    loop {
        let before = ending.len();
        for lane in lanes.lanes() {
            let successors = lane.successors();
            if !successors.is_empty() && successors.iter().all(|s| ending.contains(s)) {
                ending.insert(lane.id());
            }
        }
        if ending.len() == before {
            return ending;
        }
    }
}

/// The lanes in which a vehicle counts at the section along `along`: `along`, its
/// same-direction neighbours (transitively) and their successors (transitively), ending lanes
/// excepted.
fn counted_lanes(lanes: &LaneRoad, along: LaneId, ending: &BTreeSet<LaneId>) -> BTreeSet<LaneId> {
    let mut counted = BTreeSet::new();
    let mut queue = vec![along];
    while let Some(id) = queue.pop() {
        if ending.contains(&id) || !counted.insert(id) {
            continue;
        }
        if let Some(lane) = lanes.lane(id) {
            queue.extend(lane.left_neighbour());
            queue.extend(lane.right_neighbour());
            queue.extend(lane.successors().iter().copied());
        }
    }
    counted
}

#[cfg(test)]
#[path = "traffic_metrics_tests.rs"]
mod tests;
