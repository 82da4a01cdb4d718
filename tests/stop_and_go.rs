//! Stop and go in the closed loop (planner, tracker, tyres, physics): on a single lane the ego
//! drives at 12 m/s towards a car standing 60 m ahead, stops behind it without touching it,
//! stands still while it stands, and starts again and follows when it drives off. The car
//! ahead is a prescribed-speed driver: standing until 20 s, then 0 → 10 m/s in 5 s. Also a
//! queue of two planner-driven cars, and the simulator's IDM driver in the ego's place.

mod common;

use mergesim::planner::PlannerKind;
use mergesim::scenarios::scenario::Scenario;
use mergesim::sim::{RunOutcome, TimeSeriesRow};

/// Time the car ahead starts (s).
const RESTART_S: f64 = 20.0;

/// The scenario with the ego driven by `driver` (a TOML driver value), planner parameter set
/// `params` ("paper" or "mergesim").
fn scenario(driver: &str, params: &str, restart_s: f64) -> Scenario {
    let text = format!(
        r#"
name = "stop_and_go"
description = "The ego stops behind a standing car and follows it when it drives off."
params = "{params}"

[sim]
mu = 0.8
dt_s = 0.002
duration_s = {duration}
planner_period_s = 0.1

# The merge section ends at x = 50 m: one lane beyond, nobody can pass.
[sim.road]
lane_width_m = 3.5
y_bottom_m = 0.0
merge_start_x_m = 0.0
merge_end_x_m = 50.0
start_x_m = -50.0
end_x_m = 800.0

[[vehicles]]
name = "ego"
preset = "bmw_320i"
lane = "upper"
x_m = 100.0
speed_mps = 12.0
target_speed_mps = 12.0
driver = {driver}

[[vehicles]]
name = "lead"
preset = "bmw_320i"
lane = "upper"
x_m = 160.0
speed_mps = 0.0
target_speed_mps = 10.0
driver = {{ prescribed = {{ path_planner = "pf-cs", speed_profile = [[0.0, 0.0], [{restart_s}, 0.0], [{end}, 10.0]] }} }}
"#,
        end = restart_s + 5.0,
        duration = restart_s + 12.0,
    );
    Scenario::from_toml(&text, "stop_and_go").unwrap()
}

/// A queue: a second car of `kind` 40 m behind the ego (same planner), both at 12 m/s; the
/// car ahead starts at `restart_s`.
fn queue(kind: PlannerKind, params: &str, restart_s: f64) -> Scenario {
    let driver = format!("{{ planner = \"{}\" }}", kind.name());
    let mut scenario = scenario(&driver, params, restart_s);
    let mut second = scenario.vehicles[0].clone();
    second.name = "second".into();
    second.x_m -= 40.0;
    scenario.vehicles.push(second);
    scenario
}

fn rows<'a>(outcome: &'a RunOutcome, name: &str) -> Vec<&'a TimeSeriesRow> {
    outcome
        .time_series
        .iter()
        .filter(|r| r.vehicle == name)
        .collect()
}

/// The row of `rows` nearest to `t_s`.
fn at<'a>(rows: &[&'a TimeSeriesRow], t_s: f64) -> &'a TimeSeriesRow {
    rows.iter()
        .min_by(|a, b| (a.t_s - t_s).abs().total_cmp(&(b.t_s - t_s).abs()))
        .copied()
        .unwrap()
}

fn stops_and_goes(kind: PlannerKind, params: &str) {
    let driver = format!("{{ planner = \"{}\" }}", kind.name());
    drives_stop_and_go(&driver, &format!("{params} / {}", kind.name()), params);
}

fn drives_stop_and_go(driver: &str, what: &str, params: &str) {
    let outcome = common::simulate(&scenario(driver, params, RESTART_S), None, 0, true);
    assert!(
        outcome.safety.collisions.is_empty(),
        "{what}: {:?}",
        outcome.safety.collisions
    );
    let ego = rows(&outcome, "ego");
    let lead = rows(&outcome, "lead");
    let length_m = 4.508; // BMW 320i
    // Stopped behind it before it starts, a standstill gap of metres left.
    let (e, l) = (at(&ego, RESTART_S), at(&lead, RESTART_S));
    let gap_m = l.x_m - e.x_m - length_m;
    let smallest_gap_m = ego
        .iter()
        .zip(&lead)
        .map(|(e, l)| l.x_m - e.x_m - length_m)
        .fold(f64::INFINITY, f64::min);
    // No creep: over the 3 s of standstill before the start.
    let crept_m = e.x_m - at(&ego, RESTART_S - 3.0).x_m;
    let peak_standing_mps = ego
        .iter()
        .filter(|r| r.t_s >= RESTART_S - 3.0 && r.t_s <= RESTART_S)
        .map(|r| r.speed_mps)
        .fold(0.0, f64::max);
    // Started again within a few seconds of the car ahead, and following it.
    let moving_s = ego
        .iter()
        .find(|r| r.t_s > RESTART_S && r.speed_mps > 1.0)
        .map_or(f64::INFINITY, |r| r.t_s);
    let end = ego.last().unwrap();
    eprintln!(
        "{what}: gap at {RESTART_S} s {gap_m:.3} m (smallest {smallest_gap_m:.3} m), speed \
         {:.4} m/s, crept {crept_m:.4} m in 3 s (peak {peak_standing_mps:.4} m/s), moving (> 1 \
         m/s) at {moving_s:.2} s, speed at {:.1} s {:.2} m/s, lead {:.2} m/s",
        e.speed_mps,
        end.t_s,
        end.speed_mps,
        lead.last().unwrap().speed_mps
    );
    assert!(gap_m >= 1.0 && smallest_gap_m >= 1.0, "{what}");
    assert!(e.speed_mps < 0.1, "{what}: not stopped");
    assert!(
        crept_m.abs() < 0.1 && peak_standing_mps < 0.1,
        "{what}: creeps"
    );
    assert!(moving_s < RESTART_S + 4.0, "{what}: slow to start");
    assert!(end.speed_mps > 7.0, "{what}: not following");
}

#[test]
fn pf_iso_stops_behind_a_standing_car_and_starts_again() {
    for params in ["mergesim", "paper"] {
        stops_and_goes(PlannerKind::PfIso, params);
    }
}

#[test]
fn pf_cs_stops_behind_a_standing_car_and_starts_again() {
    for params in ["mergesim", "paper"] {
        stops_and_goes(PlannerKind::PfCs, params);
    }
}

#[test]
fn pf_sp_stops_behind_a_standing_car_and_starts_again() {
    for params in ["mergesim", "paper"] {
        stops_and_goes(PlannerKind::PfSp, params);
    }
}

#[test]
fn pf_sp_eq10_stops_behind_a_standing_car_and_starts_again() {
    stops_and_goes(PlannerKind::PfSpEq10, "mergesim");
}

/// A queue of two cars with the same planner: the second stops behind the first, both start
/// again. The car ahead stands until 30 s: PF-ISO's second car, held back by its interaction
/// term, covers its last metres at v_min (README "Limits") and was still moving at 20 s.
#[test]
fn a_queue_of_two_stops_and_goes() {
    let restart_s = 30.0;
    for kind in [PlannerKind::PfIso, PlannerKind::PfCs] {
        let outcome = common::simulate(&queue(kind, "mergesim", restart_s), None, 0, true);
        let what = kind.name();
        assert!(
            outcome.safety.collisions.is_empty(),
            "{what}: {:?}",
            outcome.safety.collisions
        );
        let (ego, second) = (rows(&outcome, "ego"), rows(&outcome, "second"));
        let length_m = 4.508; // BMW 320i
        let (e, s) = (at(&ego, restart_s), at(&second, restart_s));
        let gap_m = e.x_m - s.x_m - length_m;
        let crept_m = s.x_m - at(&second, restart_s - 3.0).x_m;
        let end = second.last().unwrap();
        eprintln!(
            "{what} queue: second's gap at {restart_s} s {gap_m:.3} m, speed {:.4} m/s, crept \
             {crept_m:.4} m in 3 s, speed at {:.1} s {:.2} m/s",
            s.speed_mps, end.t_s, end.speed_mps
        );
        assert!(gap_m >= 1.0, "{what}");
        assert!(
            s.speed_mps < 0.1 && crept_m.abs() < 0.1,
            "{what}: second not stopped"
        );
        assert!(end.speed_mps > 5.0, "{what}: second not following");
    }
}

/// The simulator's human driver (IDM car following) behind the same car.
#[test]
fn idm_stops_behind_a_standing_car_and_starts_again() {
    drives_stop_and_go("\"idm\"", "idm", "mergesim");
}

#[test]
fn pf_iso_pred_stops_behind_a_standing_car_and_starts_again() {
    stops_and_goes(PlannerKind::PfIsoPred, "mergesim");
}
