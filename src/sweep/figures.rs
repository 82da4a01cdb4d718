//! What a row of a sweep holds besides the run-level figures: the values the scenario drew for
//! the instance, and each vehicle's figures.

use std::collections::BTreeMap;

use scenarios::scenario::Scenario;
use serde::{Deserialize, Serialize};

use super::RunMetrics;
use crate::summary::RunSummary;

/// The values `Scenario::instantiate(seed)` drew for an instance, by dotted name: the
/// randomised scenario-wide values `sim.mu`, `sim.v2v.latency_s`, `sim.v2v.drop_probability`
/// and per vehicle `vehicles.<name>.x_m`, `.y_offset_m`, `.speed_mps`, `.target_speed_mps`
/// (a `cruise_speed_mps` entry moves both speeds). Each is the value the run used (nominal plus
/// the drawn offset), in the unit its name carries; a value the scenario does not randomise is
/// absent. A scenario with `[traffic]` adds, per stream, the flow it drew,
/// `traffic.<stream>.flow_vph` (veh/h), and how many vehicles it generated,
/// `traffic.<stream>.vehicles` (the per-vehicle values then vary in number between instances).
/// Empty for a scenario without `[randomise]` or `[traffic]`.
pub fn drawn_values(scenario: &Scenario, seed: u64) -> BTreeMap<String, f64> {
    let randomise = &scenario.randomise;
    let mut drawn = BTreeMap::new();
    if randomise.is_empty() && scenario.traffic.is_empty() {
        return drawn;
    }
    let instance = scenario.instantiate(seed);
    for (name, stream) in &scenario.traffic {
        drawn.insert(
            format!("traffic.{name}.flow_vph"),
            stream.drawn_flow_vph(name, seed),
        );
        let count = instance.vehicles[scenario.fixed_vehicles().len()..]
            .iter()
            .filter(|v| scenarios::traffic::stream_of(&scenario.traffic, &v.name) == Some(name))
            .count();
        drawn.insert(format!("traffic.{name}.vehicles"), count as f64);
    }
    let sim = [
        ("mu", instance.sim.mu),
        ("v2v.latency_s", instance.sim.v2v.latency_s),
        ("v2v.drop_probability", instance.sim.v2v.drop_probability),
    ];
    for (field, value) in sim {
        if randomise.sim_entry_path(field).is_some() {
            drawn.insert(format!("sim.{field}"), value);
        }
    }
    for vehicle in &instance.vehicles {
        let fields = [
            ("x_m", vehicle.x_m),
            ("y_offset_m", vehicle.y_offset_m),
            ("speed_mps", vehicle.speed_mps),
            ("target_speed_mps", vehicle.target_speed_mps),
        ];
        for (field, value) in fields {
            if randomise.vehicle_entry_path(&vehicle.name, field).is_some() {
                drawn.insert(format!("vehicles.{}.{field}", vehicle.name), value);
            }
        }
    }
    drawn
}

/// The unit of a drawn value, read off its name (names carry their unit): `veh/h` for `_vph`,
/// `m/s` for `_mps`,
/// `m` for `_m`, `s` for `_s`, nothing for `mu` and `drop_probability` (dimensionless).
pub fn drawn_unit(name: &str) -> &'static str {
    if name.ends_with("_vph") {
        "veh/h"
    } else if name.ends_with("_mps") {
        "m/s"
    } else if name.ends_with("_m") {
        "m"
    } else if name.ends_with("_s") {
        "s"
    } else {
        ""
    }
}

/// What `merge_sim run --seed` prints on stderr before the run: the seed (as the result files
/// write it, with the sweep and instance it replays when given) and every value it drew, one
/// `name = value unit` a line, the value printed exactly (shortest round-trip form).
pub fn describe_instance(scenario: &Scenario, seed: u64, sweep: Option<(u64, u64)>) -> String {
    let seed_text = crate::exact_seed::format_seed(seed);
    let mut out = match sweep {
        Some((sweep_seed, instance)) => format!(
            "seed {seed_text} (= {seed}; instance {instance} of sweep seed {})",
            crate::exact_seed::format_seed(sweep_seed)
        ),
        None => format!("seed {seed_text} (= {seed})"),
    };
    let drawn = drawn_values(scenario, seed);
    if drawn.is_empty() {
        out.push_str(&format!(
            ": scenario {} randomises nothing (the seed only seeds the V2V drops)\n",
            scenario.name
        ));
        return out;
    }
    out.push_str(&format!(" drew {} values:\n", drawn.len()));
    for (name, value) in &drawn {
        let unit = drawn_unit(name);
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        out.push_str(&format!("  {name} = {value}{unit}\n"));
    }
    out
}

/// The figures of one vehicle in one run (from `RunSummary.vehicles`, flat: the paper's
/// figures are `null` when the run kept none).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleRow {
    /// Vehicle name.
    pub name: String,
    /// Involved in a collision (vehicle or road edge).
    pub collided: bool,
    /// Peak |sideslip| (rad).
    pub max_abs_sideslip_rad: f64,
    /// Peak |yaw| (rad).
    pub max_abs_yaw_rad: f64,
    /// Peak |yaw rate| (rad/s).
    pub max_abs_yaw_rate_radps: f64,
    /// Lowest speed (m/s).
    pub min_speed_mps: f64,
    /// When it was first reached (s).
    pub t_min_speed_s: f64,
    /// Highest speed (m/s).
    pub max_speed_mps: f64,
    /// Speed at the end (m/s).
    pub final_speed_mps: f64,
    /// Path length (m).
    pub path_length_m: f64,
    /// Yaw-rate sign changes.
    pub yaw_rate_sign_changes: u64,
    /// ∫ |yaw rate| dt (rad).
    pub integral_abs_yaw_rate_rad: f64,
    /// Peak |longitudinal acceleration| (m/s²).
    pub peak_abs_accel_long_mps2: f64,
    /// RMS longitudinal acceleration (m/s²).
    pub rms_accel_long_mps2: f64,
    /// Peak |lateral acceleration| (m/s²).
    pub peak_abs_accel_lat_mps2: f64,
    /// RMS lateral acceleration (m/s²).
    pub rms_accel_lat_mps2: f64,
    /// Peak |longitudinal jerk| (m/s³).
    pub peak_abs_jerk_long_mps3: f64,
    /// Peak |lateral jerk| (m/s³).
    pub peak_abs_jerk_lat_mps3: f64,
    /// RMS longitudinal jerk (m/s³).
    pub rms_jerk_long_mps3: f64,
    /// RMS lateral jerk (m/s³).
    pub rms_jerk_lat_mps3: f64,
    /// The paper's: first time 0.1 m/s below the target speed (s); null if never.
    pub slowing_onset_s: Option<f64>,
    /// The paper's: yaw-rate RMS inside the merge zone (rad/s); null if never inside.
    pub merge_zone_rms_yaw_rate_radps: Option<f64>,
    /// The paper's: yaw-rate RMS outside the merge zone (rad/s); null if never outside.
    pub outside_merge_zone_rms_yaw_rate_radps: Option<f64>,
    /// The paper's: largest |y − lane centre| (m).
    pub max_abs_lane_offset_m: Option<f64>,
    /// The paper's: time of the first lane-divider crossing (s); null if never.
    pub divider_crossing_t_s: Option<f64>,
    /// The paper's: position of the first lane-divider crossing (m); null if never.
    pub divider_crossing_x_m: Option<f64>,
    /// The paper's: lane-divider crossings.
    pub divider_crossings: Option<u64>,
}

impl VehicleRow {
    /// Whether the vehicle never slowed 0.1 m/s below its target (`slowing_onset_s` is `None`:
    /// +∞, the latest onset); `None` when the run kept no paper figures (not measured).
    pub fn slowing_onset_never(&self) -> Option<bool> {
        self.max_abs_lane_offset_m
            .map(|_| self.slowing_onset_s.is_none())
    }

    /// Whether the vehicle never crossed the lane divider (`divider_crossing_t_s` and `_x_m`
    /// are `None`: +∞); `None` when the run kept no paper figures (not measured).
    pub fn divider_crossing_never(&self) -> Option<bool> {
        self.max_abs_lane_offset_m
            .map(|_| self.divider_crossing_t_s.is_none())
    }

    /// The row of one vehicle's summary.
    pub fn of(v: &sim::metrics::VehicleMetricsSummary) -> Self {
        let paper = v.paper_metrics.as_ref();
        let crossing = paper.and_then(|p| p.divider_crossing);
        VehicleRow {
            name: v.id.clone(),
            collided: v.collided,
            max_abs_sideslip_rad: v.max_abs_sideslip_rad,
            max_abs_yaw_rad: v.max_abs_yaw_rad,
            max_abs_yaw_rate_radps: v.max_abs_yaw_rate_radps,
            min_speed_mps: v.min_speed_mps,
            t_min_speed_s: v.t_min_speed_s,
            max_speed_mps: v.max_speed_mps,
            final_speed_mps: v.final_speed_mps,
            path_length_m: v.path_length_m,
            yaw_rate_sign_changes: u64::from(v.yaw_rate_sign_changes),
            integral_abs_yaw_rate_rad: v.integral_abs_yaw_rate_rad,
            peak_abs_accel_long_mps2: v.peak_abs_accel_long_mps2,
            rms_accel_long_mps2: v.rms_accel_long_mps2,
            peak_abs_accel_lat_mps2: v.peak_abs_accel_lat_mps2,
            rms_accel_lat_mps2: v.rms_accel_lat_mps2,
            peak_abs_jerk_long_mps3: v.peak_abs_jerk_long_mps3,
            peak_abs_jerk_lat_mps3: v.peak_abs_jerk_lat_mps3,
            rms_jerk_long_mps3: v.rms_jerk_long_mps3,
            rms_jerk_lat_mps3: v.rms_jerk_lat_mps3,
            slowing_onset_s: paper.and_then(|p| p.slowing_onset_s),
            merge_zone_rms_yaw_rate_radps: paper.and_then(|p| p.merge_zone_rms_yaw_rate_radps),
            outside_merge_zone_rms_yaw_rate_radps: paper
                .and_then(|p| p.outside_merge_zone_rms_yaw_rate_radps),
            max_abs_lane_offset_m: paper.map(|p| p.max_abs_lane_offset_m),
            divider_crossing_t_s: crossing.map(|c| c.t_s),
            divider_crossing_x_m: crossing.map(|c| c.x_m),
            divider_crossings: paper.map(|p| u64::from(p.divider_crossings)),
        }
    }
}

/// What a run gives a sweep: the run-level figures and each vehicle's.
#[derive(Clone, Debug, PartialEq)]
pub struct RunFigures {
    /// Run-level figures.
    pub metrics: RunMetrics,
    /// Per vehicle, in the scenario's order.
    pub vehicles: Vec<VehicleRow>,
}

impl RunFigures {
    /// The figures of a run summary.
    pub fn of(summary: &RunSummary) -> Self {
        RunFigures {
            metrics: RunMetrics::of(summary),
            vehicles: summary.vehicles.iter().map(VehicleRow::of).collect(),
        }
    }
}
