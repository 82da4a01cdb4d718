//! The paper's comparison of PF-CS, PF-SP and PF-ISO (Lin et al., Sec. V; DESIGN §5) on the
//! built-in urgent merge and on perturbed variants (obstacle start ±3 m, each vehicle's speed
//! ±1 m/s, μ 0.7 and 0.9; one perturbation at a time), with the same code and parameters for
//! every planner. Only the findings that hold in this simulator are asserted; the others are
//! listed, with numbers, in docs/reproduction.md.
//!
//! The planner runs with its defaults (`PlannerParams::default()`), which include the two
//! calibration choices this comparison rests on: obstacles stepped against at their predicted
//! positions in the path integration, and a 3 s following gap (docs/reproduction.md,
//! "Calibration").

mod common;

use mergesim::planner::PlannerKind;
use mergesim::scenarios::Scenario;
use mergesim::sim::{RunOutcome, TimeSeriesRow};

const EGO: &str = "ego";
const OBSTACLE: &str = "obstacle";

/// A speed drop smaller than this is tracker noise, not braking (m/s).
const SLOWING_THRESHOLD_MPS: f64 = 0.1;

fn run(scenario: &Scenario, kind: PlannerKind) -> RunOutcome {
    common::simulate(scenario, Some(kind), 0, true)
}

/// `[PF-CS, PF-SP, PF-ISO, PF-ISO-PRED]` on one scenario, two at a time (two cores).
fn run_all(scenario: &Scenario) -> [RunOutcome; 4] {
    let pair = |first: PlannerKind, second: PlannerKind| {
        std::thread::scope(|s| {
            let other = s.spawn(|| run(scenario, second));
            (run(scenario, first), other.join().unwrap())
        })
    };
    let (cs, sp) = pair(PlannerKind::PfCs, PlannerKind::PfSp);
    let (iso, pred) = pair(PlannerKind::PfIso, PlannerKind::PfIsoPred);
    [cs, sp, iso, pred]
}

#[derive(Clone, Copy, Debug)]
enum Perturbation {
    Nominal,
    ObstacleStartM(f64),
    EgoSpeedMps(f64),
    ObstacleSpeedMps(f64),
    Mu(f64),
}

fn vehicle_mut<'a>(scenario: &'a mut Scenario, name: &str) -> &'a mut mergesim::sim::VehicleSpec {
    scenario
        .vehicles
        .iter_mut()
        .find(|v| v.name == name)
        .unwrap()
}

/// The built-in scenario with one perturbation (a speed change moves the initial and the
/// target speed together, as the scenario's [randomise] table does).
fn variant(p: Perturbation) -> Scenario {
    let mut scenario = Scenario::load("urgent_merge").unwrap();
    match p {
        Perturbation::Nominal => {}
        Perturbation::ObstacleStartM(dx) => vehicle_mut(&mut scenario, OBSTACLE).x_m += dx,
        Perturbation::EgoSpeedMps(dv) => {
            let v = vehicle_mut(&mut scenario, EGO);
            v.speed_mps += dv;
            v.target_speed_mps += dv;
        }
        Perturbation::ObstacleSpeedMps(dv) => {
            let v = vehicle_mut(&mut scenario, OBSTACLE);
            v.speed_mps += dv;
            v.target_speed_mps += dv;
        }
        Perturbation::Mu(mu) => scenario.sim.mu = mu,
    }
    scenario
}

fn rows<'a>(outcome: &'a RunOutcome, vehicle: &'a str) -> impl Iterator<Item = &'a TimeSeriesRow> {
    outcome
        .time_series
        .iter()
        .filter(move |r| r.vehicle == vehicle)
}

fn min_speed_mps(outcome: &RunOutcome, vehicle: &str) -> f64 {
    rows(outcome, vehicle)
        .map(|r| r.speed_mps)
        .fold(f64::INFINITY, f64::min)
}

/// First time the vehicle is more than [`SLOWING_THRESHOLD_MPS`] below `target_mps`.
fn slowing_onset_s(outcome: &RunOutcome, vehicle: &str, target_mps: f64) -> Option<f64> {
    rows(outcome, vehicle)
        .find(|r| r.speed_mps < target_mps - SLOWING_THRESHOLD_MPS)
        .map(|r| r.t_s)
}

fn path_length_m(outcome: &RunOutcome, vehicle: &str) -> f64 {
    let points: Vec<(f64, f64)> = rows(outcome, vehicle).map(|r| (r.x_m, r.y_m)).collect();
    points
        .windows(2)
        .map(|w| ((w[1].0 - w[0].0).powi(2) + (w[1].1 - w[0].1).powi(2)).sqrt())
        .sum()
}

/// Largest |value| of one motion state of one vehicle over the run.
fn peak_abs(outcome: &RunOutcome, vehicle: &str, state: fn(&TimeSeriesRow) -> f64) -> f64 {
    rows(outcome, vehicle)
        .map(|r| state(r).abs())
        .fold(0.0, f64::max)
}

/// Root mean square of the yaw rate over the run (rad/s).
fn rms_yaw_rate_radps(outcome: &RunOutcome, vehicle: &str) -> f64 {
    let (sum, n) = rows(outcome, vehicle).fold((0.0, 0usize), |(s, n), r| {
        (s + r.yaw_rate_radps * r.yaw_rate_radps, n + 1)
    });
    (sum / n as f64).sqrt()
}

/// A named scalar measure of a run.
type Measure = (&'static str, fn(&RunOutcome) -> f64);

/// The obstacle's motion states the paper compares (Fig. 4): peak |β|, |ψ|, |r| and RMS r.
const MOTION_STATES: [Measure; 4] = [
    ("peak |sideslip|", |o| {
        peak_abs(o, OBSTACLE, |r| r.sideslip_rad)
    }),
    ("peak |yaw|", |o| peak_abs(o, OBSTACLE, |r| r.yaw_rad)),
    ("peak |yaw rate|", |o| {
        peak_abs(o, OBSTACLE, |r| r.yaw_rate_radps)
    }),
    ("RMS yaw rate", |o| rms_yaw_rate_radps(o, OBSTACLE)),
];

fn collisions(outcome: &RunOutcome) -> usize {
    outcome.safety.collisions.len() + outcome.safety.edge_contacts.len()
}

/// Asserts every finding that holds, on one variant.
fn check_findings(p: Perturbation) {
    let scenario = variant(p);
    let road = scenario.sim.road.clone();
    let ego = scenario
        .vehicles
        .iter()
        .find(|v| v.name == EGO)
        .unwrap()
        .clone();
    let obstacle_target_mps = scenario
        .vehicles
        .iter()
        .find(|v| v.name == OBSTACLE)
        .unwrap()
        .target_speed_mps;
    let [cs, sp, iso, pred] = run_all(&scenario);
    let label = |kind: &str| format!("{p:?} {kind}");

    // No collision (vehicle–vehicle or road edge) with any planner, and the ego has merged.
    for (kind, outcome) in [
        ("pf-cs", &cs),
        ("pf-sp", &sp),
        ("pf-iso", &iso),
        ("pf-iso-pred", &pred),
    ] {
        assert_eq!(
            collisions(outcome),
            0,
            "{}: {:?}",
            label(kind),
            outcome.events
        );
        assert!(
            outcome.safety.min_gap_m.is_some_and(|g| g > 0.0),
            "{}",
            label(kind)
        );
        let last = rows(outcome, EGO).last().unwrap();
        assert!(
            last.x_m > road.merge_end_x_m && last.y_m > road.y_lane_m(),
            "{}: ego ended at ({}, {})",
            label(kind),
            last.x_m,
            last.y_m
        );
    }

    // PF-ISO: the obstacle starts slowing early, before the ego has even reached the merge
    // section (it is still in its own lane, so nothing but the shared path can tell the
    // obstacle where the ego is going).
    let ego_at_merge_s = (road.merge_start_x_m - ego.x_m) / ego.speed_mps;
    let onset_s = slowing_onset_s(&iso, OBSTACLE, obstacle_target_mps);
    assert!(
        onset_s.is_some_and(|t| t < ego_at_merge_s),
        "{}: slowing onset {onset_s:?}, ego reaches the merge section at {ego_at_merge_s:.2} s",
        label("pf-iso")
    );
    // ... earlier than with constant-velocity predictions instead of the SLP (PF-ISO-PRED):
    // what V2V adds beyond the interaction term.
    let pred_onset_s = slowing_onset_s(&pred, OBSTACLE, obstacle_target_mps);
    assert!(
        pred_onset_s.is_none_or(|t| onset_s.is_some_and(|o| o < t)),
        "{p:?}: PF-ISO onset {onset_s:?} vs PF-ISO-PRED {pred_onset_s:?}"
    );
    // ... then accelerates back to its target by the end of the run.
    let last = rows(&iso, OBSTACLE).last().unwrap();
    assert!(
        (last.speed_mps - obstacle_target_mps).abs() < 0.3,
        "{}: final speed {}",
        label("pf-iso"),
        last.speed_mps
    );
    // ... so its path over the run is the shortest of the three (pre-braking).
    let iso_path_m = path_length_m(&iso, OBSTACLE);
    for (kind, outcome) in [("pf-cs", &cs), ("pf-sp", &sp)] {
        let other_m = path_length_m(outcome, OBSTACLE);
        assert!(
            iso_path_m < other_m,
            "{p:?}: obstacle path PF-ISO {iso_path_m:.2} m vs {kind} {other_m:.2} m"
        );
        // PF-CS and PF-SP do not brake for the merging ego at all (see docs/reproduction.md:
        // the paper's late braking of PF-SP is not reproduced).
        assert!(min_speed_mps(outcome, OBSTACLE) > obstacle_target_mps - SLOWING_THRESHOLD_MPS);
    }
    // PF-ISO: the obstacle's motion states stay the smallest of the three planners (paper
    // Fig. 4): its peak sideslip, yaw and yaw rate, and its RMS yaw rate, are below those with
    // PF-CS and PF-SP. (The paper also has PF-CS above PF-SP; here the two are equal to within
    // 1 %, since our PF-SP never brakes: see docs/reproduction.md.)
    for (state, value) in MOTION_STATES {
        let iso_value = value(&iso);
        for (kind, outcome) in [("pf-cs", &cs), ("pf-sp", &sp)] {
            let other = value(outcome);
            assert!(
                iso_value < other,
                "{p:?}: obstacle {state} PF-ISO {iso_value:.5} vs {kind} {other:.5}"
            );
        }
    }
    // Not asserted: the ego's peak yaw rate lower with PF-ISO than with PF-CS. It is higher
    // (nominal 0.0192 vs 0.0167 rad/s): with the obstacle further back, the ego changes lanes in
    // one quicker manoeuvre. See docs/reproduction.md.
}

#[test]
fn nominal_urgent_merge_reproduces_the_findings_that_hold() {
    check_findings(Perturbation::Nominal);
    // On the nominal scenario the obstacle's slowing starts about when the paper's does
    // (3.1 s): before 5 s, while the ego is still 60+ m short of the merge section.
    let scenario = variant(Perturbation::Nominal);
    let iso = run(&scenario, PlannerKind::PfIso);
    let onset_s = slowing_onset_s(&iso, OBSTACLE, 15.0).unwrap();
    assert!(onset_s < 5.0, "{onset_s}");
    // It gives up at least 0.5 m/s (paper: 5.6 m/s; see docs/reproduction.md for why ours is
    // smaller) and the ego never slows for it.
    assert!(min_speed_mps(&iso, OBSTACLE) < 15.0 - 0.5);
    assert!(min_speed_mps(&iso, EGO) > 20.0 - SLOWING_THRESHOLD_MPS);
    // Its yaw rate stays "near zero" (paper): at most half of PF-CS's peak.
    let cs = run(&scenario, PlannerKind::PfCs);
    let peak_r = |o: &RunOutcome| peak_abs(o, OBSTACLE, |r| r.yaw_rate_radps);
    assert!(
        peak_r(&iso) < 0.5 * peak_r(&cs),
        "obstacle peak |r|: PF-ISO {} vs PF-CS {}",
        peak_r(&iso),
        peak_r(&cs)
    );
}

#[test]
fn findings_survive_a_different_initial_gap() {
    check_findings(Perturbation::ObstacleStartM(-3.0));
    check_findings(Perturbation::ObstacleStartM(3.0));
}

#[test]
fn findings_survive_a_different_ego_speed() {
    check_findings(Perturbation::EgoSpeedMps(-1.0));
    check_findings(Perturbation::EgoSpeedMps(1.0));
}

#[test]
fn findings_survive_a_different_obstacle_speed() {
    check_findings(Perturbation::ObstacleSpeedMps(-1.0));
    check_findings(Perturbation::ObstacleSpeedMps(1.0));
}

#[test]
fn findings_survive_a_different_friction() {
    check_findings(Perturbation::Mu(0.7));
    check_findings(Perturbation::Mu(0.9));
}

/// The worst corner of the perturbation box (obstacle 3 m further ahead, ego 1 m/s slower,
/// obstacle 1 m/s faster: the ego draws level only at x ≈ 240 m): PF-CS and PF-SP, which cannot
/// yield, run into the obstacle; PF-ISO resolves it with the ego slowing and merging behind.
#[test]
fn in_the_worst_corner_only_the_interactive_planner_avoids_the_collision() {
    let mut scenario = variant(Perturbation::ObstacleStartM(3.0));
    let ego = vehicle_mut(&mut scenario, EGO);
    ego.speed_mps -= 1.0;
    ego.target_speed_mps -= 1.0;
    let obstacle = vehicle_mut(&mut scenario, OBSTACLE);
    obstacle.speed_mps += 1.0;
    obstacle.target_speed_mps += 1.0;
    let [cs, sp, iso, pred] = run_all(&scenario);
    assert!(collisions(&cs) > 0);
    assert!(collisions(&sp) > 0);
    for outcome in [&iso, &pred] {
        assert_eq!(collisions(outcome), 0, "{:?}", outcome.events);
        // The ego yields: it ends up behind the obstacle.
        let ego_last = rows(outcome, EGO).last().unwrap();
        let obstacle_last = rows(outcome, OBSTACLE).last().unwrap();
        assert!(ego_last.x_m < obstacle_last.x_m);
    }
}

/// Where the two outcomes meet (obstacle start 45–53 m: up to 46 m the obstacle makes room,
/// from 47 m the ego yields): with the shared paths PF-ISO switches between them without a
/// collision; with constant-velocity predictions instead (PF-ISO-PRED, no V2V) the two vehicles
/// misread each other's intent and race into each other at some starts (47.2–50.8 m measured;
/// docs/reproduction.md, "Where the two equilibria meet").
#[test]
fn at_the_switch_between_the_equilibria_only_shared_paths_avoid_the_collision() {
    let mut pred_collisions = 0;
    for start_m in 45..=53 {
        let mut scenario = variant(Perturbation::Nominal);
        vehicle_mut(&mut scenario, OBSTACLE).x_m = f64::from(start_m);
        let (iso, pred) = std::thread::scope(|s| {
            let pred = s.spawn(|| run(&scenario, PlannerKind::PfIsoPred));
            (run(&scenario, PlannerKind::PfIso), pred.join().unwrap())
        });
        assert_eq!(
            collisions(&iso),
            0,
            "PF-ISO, obstacle start {start_m} m: {:?}",
            iso.events
        );
        pred_collisions += usize::from(collisions(&pred) > 0);
    }
    assert!(pred_collisions > 0, "PF-ISO-PRED never collided");
}
