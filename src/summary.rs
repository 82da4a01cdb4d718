//! The run summary: the JSON contract of `merge_sim run --json` and the human-readable table.

use serde::{Deserialize, Serialize};
use sim::{PlannerStats, RunOutcome};

/// JSON summary of one run (`--json`). Field names are a contract: see the README.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// Scenario name.
    pub scenario: String,
    /// Planner name (`pf-iso`, ..., or `mixed`).
    pub planner: String,
    /// Planner parameter set (`paper` or `mergesim`).
    pub params: String,
    /// Seed of the run (null for the nominal scenario), as a string (exact in every JSON
    /// reader; integers are read too).
    #[serde(with = "crate::exact_seed::option")]
    pub seed: Option<u64>,
    /// The values the seed drew from the scenario's `[randomise]` ranges, by dotted name with
    /// units (as a sweep row's `drawn`); absent for the nominal scenario. Filled by the caller
    /// ([`RunSummary::with_drawn`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drawn: Option<std::collections::BTreeMap<String, f64>>,
    /// Simulated time (s).
    pub duration_s: f64,
    /// Wall-clock time of the simulation (s); the only field that differs between reruns.
    pub wall_time_s: f64,
    /// How the recorded traffic of a CommonRoad road moved (`none`, `replay`, `reactive`);
    /// absent for a scenario on no CommonRoad road. Filled by the caller
    /// ([`RunSummary::with_recorded_traffic`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub recorded_traffic: Option<String>,
    /// What moved the cars (`ks`, `st`, `std`, a user's model, or `mixed`); absent when every
    /// car is the default `rapier` one. Filled by the caller ([`RunSummary::with_vehicle_model`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vehicle_model: Option<String>,
    /// Number of collision events (vehicle–vehicle and vehicle–road edge) of the simulated
    /// vehicles, without those caused by the replay of recorded traffic.
    pub collisions: usize,
    /// Collisions in which a recorded vehicle ran into a simulated one from behind (counted
    /// apart from `collisions`); 0 without recorded traffic.
    #[serde(default)]
    pub collisions_caused_by_replay: usize,
    /// Exact minimum distance between a simulated and a recorded vehicle's boxes (m); null
    /// without recorded traffic within `pair_range_m`.
    #[serde(default)]
    pub min_gap_to_recorded_m: Option<f64>,
    /// Minimum time to collision between a simulated and a recorded vehicle (s); null if no
    /// such pair was ever closing within the horizon.
    #[serde(default)]
    pub min_ttc_to_recorded_s: Option<f64>,
    /// Exact minimum distance between any two vehicle boxes (m); null with a single vehicle
    /// or when no two ever came within `[sim.safety] pair_range_m` (250 m).
    pub min_gap_m: Option<f64>,
    /// Minimum time to collision (s); null if no pair was ever closing within the horizon.
    pub min_ttc_s: Option<f64>,
    /// Near miss: min TTC below the threshold or min gap below its threshold, without collision.
    pub near_miss: bool,
    /// Time spent with TTC below the threshold (s).
    pub tet_s: f64,
    /// How many times a vehicle's safety shield intervened (`[sim] shield`; a pair turning
    /// RSS-dangerous, each an event below); 0 without a shield.
    #[serde(default)]
    pub shield_interventions: usize,
    /// Throughput through the merge, merging before the lane's end, delay and speed loss
    /// against free flow, and the safety figures per vehicle class (`sim::traffic_metrics`).
    #[serde(default)]
    pub traffic: sim::traffic_metrics::TrafficSummary,
    /// Per-vehicle metrics.
    pub vehicles: Vec<sim::metrics::VehicleMetricsSummary>,
    /// Planner counters and timing.
    pub planner_stats: PlannerStats,
    /// Whether the ego (the first vehicle with a goal: a CommonRoad scenario's planning
    /// problem) reached its goal (docs/commonroad.md); null when no vehicle has a goal.
    #[serde(default)]
    pub goal_reached: Option<bool>,
    /// When it first met its goal (s); null if it did not or has none.
    #[serde(default)]
    pub goal_time_s: Option<f64>,
    /// Collision and safety events, in time order.
    pub events: Vec<String>,
    /// Wall time per phase of the tick (`merge_sim run --profile`); absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub profile: Option<sim::profile::ProfileReport>,
}

impl RunSummary {
    /// Builds the summary of a finished run.
    pub fn new(
        scenario: &str,
        params: planner::ParameterSet,
        planner: &str,
        seed: Option<u64>,
        wall_time_s: f64,
        outcome: &RunOutcome,
    ) -> Self {
        Self {
            scenario: scenario.to_string(),
            params: params.name().to_string(),
            planner: planner.to_string(),
            seed,
            drawn: None,
            recorded_traffic: None,
            vehicle_model: None,
            duration_s: outcome.duration_s,
            wall_time_s,
            collisions: outcome.safety.own_collisions() + outcome.safety.edge_contacts.len(),
            collisions_caused_by_replay: outcome.safety.collisions_caused_by_replay as usize,
            min_gap_to_recorded_m: outcome.safety.min_gap_to_recorded_m,
            min_ttc_to_recorded_s: outcome.safety.min_ttc_to_recorded_s,
            min_gap_m: outcome.safety.min_gap_m,
            min_ttc_s: outcome.safety.min_ttc_s,
            near_miss: outcome.safety.near_miss,
            tet_s: outcome.safety.tet_s,
            shield_interventions: outcome
                .events
                .iter()
                .filter(|e| matches!(e, sim::SimEvent::ShieldIntervened { .. }))
                .count(),
            traffic: outcome.traffic.clone(),
            vehicles: outcome.vehicles.clone(),
            planner_stats: outcome.planner_stats.clone(),
            goal_reached: outcome.goals.first().map(|g| g.reached),
            goal_time_s: outcome.goals.first().and_then(|g| g.time_s),
            events: outcome.events.iter().map(ToString::to_string).collect(),
            profile: outcome.profile.clone(),
        }
    }

    /// The summary with `drawn` filled from `scenario` (the scenario the run's instance was
    /// drawn from; nothing for a run without a seed).
    pub fn with_drawn(mut self, scenario: &scenarios::scenario::Scenario) -> Self {
        self.drawn = self
            .seed
            .map(|seed| crate::sweep::drawn_values(scenario, seed));
        self
    }

    /// The summary with `recorded_traffic` named from `sim`: the mode of its CommonRoad road's
    /// recorded traffic, nothing on any other road.
    pub fn with_recorded_traffic(mut self, sim: &sim::config::SimConfig) -> Self {
        self.recorded_traffic = sim
            .commonroad_road()
            .map(|road| road.recorded_traffic.to_string());
        self
    }

    /// The summary with `vehicle_model` named from the vehicles of `sim` and `vehicles`: their
    /// one model, or `mixed`; nothing when every car is `rapier`.
    pub fn with_vehicle_model(
        mut self,
        sim: &sim::config::SimConfig,
        vehicles: &[sim::config::VehicleSpec],
    ) -> Self {
        let mut names: Vec<&str> = vehicles
            .iter()
            .map(|v| sim::vehicle_models::model_of(sim, v).0)
            .collect();
        names.sort_unstable();
        names.dedup();
        self.vehicle_model = match names.as_slice() {
            [] | [sim::vehicle_models::DEFAULT_VEHICLE_MODEL] => None,
            [one] => Some((*one).to_string()),
            _ => Some("mixed".to_string()),
        };
        self
    }

    /// A fixed-width table for the terminal.
    pub fn table(&self) -> String {
        let mut out = String::new();
        let ttc = self
            .min_ttc_s
            .map(|t| format!("{t:.2} s"))
            .unwrap_or_else(|| "never closing".into());
        let vehicles = self
            .vehicle_model
            .as_ref()
            .map(|m| format!("  vehicles {m}"))
            .unwrap_or_default();
        out.push_str(&format!(
            "scenario {}  planner {} ({} parameters){vehicles}  simulated {:.1} s in {:.2} s wall\n",
            self.scenario, self.planner, self.params, self.duration_s, self.wall_time_s
        ));
        out.push_str(&format!(
            "collisions {}  min gap {}  min TTC {}  near miss {}  TET {:.2} s\n",
            self.collisions,
            self.min_gap_m
                .map(|g| format!("{g:.2} m"))
                .unwrap_or_else(|| "-".into()),
            ttc,
            if self.near_miss { "yes" } else { "no" },
            self.tet_s
        ));
        let traffic = &self.traffic;
        if traffic.section_lane.is_some() || traffic.merging > 0 {
            out.push_str(&format!(
                "traffic: {} through the merge ({} crossed)  merged before the lane end {}/{}  \
                 mean delay {}\n",
                traffic
                    .throughput_vph
                    .map(|q| format!("{q:.0} veh/h"))
                    .unwrap_or_else(|| "- veh/h".into()),
                traffic.crossings,
                traffic.merged_before_lane_end,
                traffic.merging,
                traffic
                    .mean_delay_s
                    .map(|d| format!("{d:.2} s"))
                    .unwrap_or_else(|| "-".into()),
            ));
        }
        if self.recorded_traffic.is_some()
            || self.collisions_caused_by_replay > 0
            || self.min_gap_to_recorded_m.is_some()
        {
            let mode = self
                .recorded_traffic
                .as_ref()
                .map(|m| format!(" ({m})"))
                .unwrap_or_default();
            out.push_str(&format!(
                "recorded traffic{mode}: collisions caused by replay {}  min gap {}  min TTC {}\n",
                self.collisions_caused_by_replay,
                self.min_gap_to_recorded_m
                    .map(|g| format!("{g:.2} m"))
                    .unwrap_or_else(|| "-".into()),
                self.min_ttc_to_recorded_s
                    .map(|t| format!("{t:.2} s"))
                    .unwrap_or_else(|| "never closing".into()),
            ));
        }
        if let Some(reached) = self.goal_reached {
            out.push_str(&format!(
                "goal reached {}\n",
                match (reached, self.goal_time_s) {
                    (true, Some(t)) => format!("yes, at t = {t:.2} s"),
                    _ => "no".to_string(),
                }
            ));
        }
        out.push_str(&format!(
            "planner cycles {}  fallbacks {}  p50 {:.0} µs  p99 {:.0} µs\n\n",
            self.planner_stats.plans,
            self.planner_stats.fallbacks,
            self.planner_stats.p50_plan_us,
            self.planner_stats.p99_plan_us
        ));
        out.push_str(&format!(
            "{:<10} {:>11} {:>9} {:>12} {:>10} {:>10} {:>9} {:>8} {:>8}\n",
            "vehicle",
            "|β|max rad",
            "|ψ|max",
            "|r|max rad/s",
            "v_min m/s",
            "at t s",
            "path m",
            "r flips",
            "collided"
        ));
        for v in &self.vehicles {
            out.push_str(&format!(
                "{:<10} {:>11.4} {:>9.4} {:>12.4} {:>10.2} {:>10.2} {:>9.1} {:>8} {:>8}\n",
                v.id,
                v.max_abs_sideslip_rad,
                v.max_abs_yaw_rad,
                v.max_abs_yaw_rate_radps,
                v.min_speed_mps,
                v.t_min_speed_s,
                v.path_length_m,
                v.yaw_rate_sign_changes,
                if v.collided { "yes" } else { "no" }
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mergesim_types::Lane;
    use sim::config::{Driver, SimConfig, VehicleSpec};
    use sim::recorded_traffic::{RecordedState, RecordedTraffic, RecordedVehicle, TrafficMode};
    use sim::recording::Recorder;
    use sim::{RunOptions, World};

    /// A recorded car running into a lane-keeping car from behind (as in
    /// `sim/tests/recorded_traffic.rs`): the summary counts it apart.
    #[test]
    fn collisions_caused_by_recorded_traffic_are_counted_apart_in_the_summary() {
        let state = |time_s: f64, x_m: f64| RecordedState {
            time_s,
            position_m: [x_m, 5.25],
            heading_rad: 0.0,
            speed_mps: 15.0,
        };
        let config = SimConfig {
            duration_s: 20.0,
            recorded_traffic: RecordedTraffic {
                mode: TrafficMode::Replay,
                vehicles: vec![RecordedVehicle {
                    name: "cr-follower".into(),
                    length_m: 4.5,
                    width_m: 1.8,
                    states: vec![state(0.0, 0.0), state(19.6, 294.0)],
                }],
            },
            ..SimConfig::default()
        };
        let ego = VehicleSpec {
            name: "ego".into(),
            preset: "bmw_320i".into(),
            vehicle_model: None,
            lane: Lane::Upper.into(),
            x_m: 100.0,
            y_offset_m: 0.0,
            speed_mps: 10.0,
            target_speed_mps: 10.0,
            driver: Driver::LaneKeeping,
            connected: false,
            goal: None,
            route: None,
        };
        let outcome = World::new(config, &[ego], &RunOptions::default(), Recorder::disabled())
            .and_then(|w| w.run(|_| {}))
            .unwrap_or_else(|e| panic!("{e}"));
        let summary = RunSummary::new(
            "rear_end",
            planner::ParameterSet::default(),
            "lane-keeping",
            None,
            0.0,
            &outcome,
        );
        assert!(!outcome.safety.collisions.is_empty());
        assert_eq!(summary.collisions, outcome.safety.edge_contacts.len());
        assert_eq!(
            summary.collisions_caused_by_replay,
            outcome.safety.collisions.len()
        );
        assert!(summary.min_gap_to_recorded_m.is_some_and(|g| g < 0.01));
        assert_eq!(summary.min_ttc_to_recorded_s, Some(0.0));
        let json = serde_json::to_value(&summary).unwrap_or_default();
        assert_eq!(
            json["collisions_caused_by_replay"],
            serde_json::json!(summary.collisions_caused_by_replay)
        );
        assert!(
            summary
                .table()
                .contains("recorded traffic: collisions caused by replay"),
            "{}",
            summary.table()
        );
    }
}
