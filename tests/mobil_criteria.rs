//! The measurements behind two of MOBIL's defaults (docs/parameters.md, "Human drivers who
//! change lanes"): the least time between two lane changes must cover the longest lane change
//! the tracker drives, and the clearance at a lane's end must cover how far the tracker lets a
//! car's body stray from its lane's centreline. Each test measures its figure over the presets
//! and speeds of the criterion, prints it, and fails if the default no longer covers it or is
//! no longer the criterion's rounding of it.
//!
//! `cargo test --release --test mobil_criteria -- --nocapture` prints the figures.

mod common;

use mergesim::mergesim_types::lanes::{ENDING_LANE_ID, LaneId, THROUGH_LANE_ID};
use mergesim::scenarios::scenario::Scenario;
use mergesim::sim::TimeSeriesRow;
use mergesim::sim::config::Driver;
use mergesim::sim::mobil::MobilParams;
use mergesim::vehicles::{BodyBox, PRESET_NAMES, VehicleParams};

/// The merge road's through lane and ending lane.
const THROUGH_LANE: LaneId = THROUGH_LANE_ID;
const ENDING_LANE: LaneId = ENDING_LANE_ID;
/// The speeds of the criterion (m/s).
const SPEEDS_MPS: [f64; 3] = [10.0, 20.0, 30.0];
/// A lane change is over once the centre stays within this of the new lane's centre (m).
const SETTLED_M: f64 = 0.1;
/// The safety checks' contact tolerance (m), added to the clearance by the criterion.
const CONTACT_TOLERANCE_M: f64 = 0.01;

/// `scenario` with only its ego, as `preset` at `speed_mps` (its target speed too), driven by
/// `driver`, for `duration_s`.
fn lone_ego(
    scenario: &str,
    preset: &str,
    speed_mps: f64,
    driver: Driver,
    duration_s: f64,
) -> Scenario {
    let mut s = Scenario::load(scenario).unwrap();
    s.vehicles.retain(|v| v.name == "ego");
    let ego = &mut s.vehicles[0];
    ego.preset = preset.to_string();
    ego.speed_mps = speed_mps;
    ego.target_speed_mps = speed_mps;
    ego.driver = driver;
    s.sim.duration_s = duration_s;
    s.sim.vehicle_model = "rapier".to_string();
    s
}

/// Rounds `value` up to a multiple of `step`.
fn round_up(value: f64, step: f64) -> f64 {
    (value / step - 1e-9).ceil() * step
}

#[test]
fn the_cooldown_covers_the_longest_lane_change() {
    let mut longest_s: f64 = 0.0;
    for preset in PRESET_NAMES {
        for speed_mps in SPEEDS_MPS {
            let scenario = lone_ego("urgent_merge", preset, speed_mps, Driver::IdmMobil, 12.0);
            let lanes = scenario.sim.lanes().unwrap();
            let through = lanes.lane(THROUGH_LANE).unwrap();
            let outcome = common::simulate(&scenario, None, 0, true);
            let rows: Vec<&TimeSeriesRow> = outcome.time_series.iter().collect();
            // The last instant the centre was more than SETTLED_M from the through lane's
            // centre: the change is over at the next logged instant.
            let last_out = rows
                .iter()
                .rposition(|r| through.project([r.x_m, r.y_m]).d_m.abs() > SETTLED_M)
                .unwrap();
            assert!(
                last_out + 1 < rows.len(),
                "{preset} at {speed_mps} m/s never settled in the through lane"
            );
            let duration_s = rows[last_out + 1].t_s;
            println!("lane change, {preset} at {speed_mps} m/s: {duration_s:.2} s");
            longest_s = longest_s.max(duration_s);
        }
    }
    let criterion_s = round_up(longest_s, 0.5);
    println!("longest {longest_s:.2} s → criterion {criterion_s} s");
    let default_s = MobilParams::default().min_time_between_changes_s;
    assert!(default_s >= longest_s, "{default_s} s < {longest_s} s");
    assert_eq!(
        default_s, criterion_s,
        "the default is not the criterion's value"
    );
}

/// The largest excess (m) over the half width of the car's corners' lateral distance from the
/// ending lane's centreline, while the car's front is short of the taper (the lane still at its
/// full width).
fn corner_excess_m(scenario: &Scenario, rows: &[TimeSeriesRow], car: &VehicleParams) -> f64 {
    let lanes = scenario.sim.lanes().unwrap();
    let lane = lanes.lane(ENDING_LANE).unwrap();
    let full_width_m = scenario.sim.road.lane_width_m;
    // The chassis box, centred on the wheelbase midpoint ahead of or behind the centre of
    // gravity the time series gives.
    let body = BodyBox::of(car);
    let [half_l, half_w, _] = body.half_extents_m;
    let ox = body.center_offset_m[0];
    let mut excess_m: f64 = 0.0;
    for r in rows {
        let (sin, cos) = r.yaw_rad.sin_cos();
        let at =
            |lon: f64, lat: f64| [r.x_m + lon * cos - lat * sin, r.y_m + lon * sin + lat * cos];
        let front = lane.project(at(ox + half_l, 0.0));
        if lane.width_m(front.s_m) < full_width_m - 1e-9 {
            break;
        }
        for (lon, lat) in [
            (half_l, half_w),
            (half_l, -half_w),
            (-half_l, half_w),
            (-half_l, -half_w),
        ] {
            excess_m = excess_m.max(lane.project(at(ox + lon, lat)).d_m.abs() - half_w);
        }
    }
    excess_m
}

#[test]
fn the_lane_end_clearance_covers_the_trackers_lateral_excursion() {
    let mut largest_m: f64 = 0.0;
    for scenario_name in ["urgent_merge", "curved_merge"] {
        for preset in PRESET_NAMES {
            let car = VehicleParams::preset(preset).unwrap();
            for speed_mps in SPEEDS_MPS {
                // Long enough for the front to reach the taper at 160 m of the straight road.
                let duration_s = 220.0 / speed_mps;
                let scenario = lone_ego(scenario_name, preset, speed_mps, Driver::Idm, duration_s);
                let outcome = common::simulate(&scenario, None, 0, true);
                let excess_m = corner_excess_m(&scenario, &outcome.time_series, &car);
                println!("{scenario_name}, {preset} at {speed_mps} m/s: {excess_m:.4} m");
                largest_m = largest_m.max(excess_m);
            }
        }
    }
    let criterion_m = round_up(largest_m + CONTACT_TOLERANCE_M, 0.05);
    println!("largest {largest_m:.4} m → criterion {criterion_m} m");
    let default_m = MobilParams::default().end_clearance_m;
    assert!(default_m >= largest_m + CONTACT_TOLERANCE_M);
    assert!(
        (default_m - criterion_m).abs() < 1e-12,
        "the default {default_m} m is not the criterion's value {criterion_m} m"
    );
}
