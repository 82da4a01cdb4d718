//! The paper's comparison of PF-CS, PF-SP and PF-ISO (Lin et al., Sec. V) on the built-in urgent
//! merge, with both parameter sets: `paper` (the paper's literal reading) and `mergesim` (ours).
//! Every parameter is fixed by a criterion that does not look at this comparison
//! (docs/parameters.md, `planner/tests/calibration.rs`); only the findings that hold are
//! asserted, the others are reported with numbers and causes in docs/reproduction.md.
//!
//! Variants: the nominal scenario and eight one-at-a-time perturbations (obstacle start ±3 m,
//! either speed ±1 m/s, μ 0.7 / 0.9), and the worst corner of that box.

mod common;

use mergesim::planner::{ParameterSet, PlannerKind};
use mergesim::scenarios::scenario::Scenario;
use mergesim::sim::RunOutcome;
use mergesim::sim::metrics::VehicleMetricsSummary;
use mergesim::sim::paper_metrics::PaperMetricsSummary;

const EGO: &str = "ego";
const OBSTACLE: &str = "obstacle";

/// The obstacle "makes room" in a run where PF-ISO slows it by more than this (m/s); below it
/// the ego merges far enough ahead that nobody has to interact.
const MAKES_ROOM_MPS: f64 = 0.5;

fn run(scenario: &Scenario, kind: PlannerKind) -> RunOutcome {
    common::simulate(scenario, Some(kind), 0, false)
}

/// Runs every kind on one scenario, two at a time (two cores).
fn run_kinds<const N: usize>(scenario: &Scenario, kinds: [PlannerKind; N]) -> [RunOutcome; N] {
    std::thread::scope(|s| {
        let handles: Vec<_> = kinds
            .chunks(2)
            .map(|pair| {
                let pair = pair.to_vec();
                s.spawn(move || {
                    pair.into_iter()
                        .map(|k| run(scenario, k))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        let all: Vec<RunOutcome> = handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect();
        all.try_into().unwrap_or_else(|_| unreachable!())
    })
}

#[derive(Clone, Copy, Debug)]
enum Perturbation {
    Nominal,
    ObstacleStartM(f64),
    EgoSpeedMps(f64),
    ObstacleSpeedMps(f64),
    Mu(f64),
    /// Obstacle 3 m further ahead, ego 1 m/s slower, obstacle 1 m/s faster.
    WorstCorner,
}

const PERTURBATIONS: [Perturbation; 9] = [
    Perturbation::Nominal,
    Perturbation::ObstacleStartM(-3.0),
    Perturbation::ObstacleStartM(3.0),
    Perturbation::EgoSpeedMps(-1.0),
    Perturbation::EgoSpeedMps(1.0),
    Perturbation::ObstacleSpeedMps(-1.0),
    Perturbation::ObstacleSpeedMps(1.0),
    Perturbation::Mu(0.7),
    Perturbation::Mu(0.9),
];

fn vehicle_mut<'a>(
    scenario: &'a mut Scenario,
    name: &str,
) -> &'a mut mergesim::sim::config::VehicleSpec {
    scenario
        .vehicles
        .iter_mut()
        .find(|v| v.name == name)
        .unwrap()
}

fn shift_speed(scenario: &mut Scenario, name: &str, dv: f64) {
    let v = vehicle_mut(scenario, name);
    v.speed_mps += dv;
    v.target_speed_mps += dv;
}

/// The built-in scenario with the parameter set and one perturbation (a speed change moves the
/// initial and the target speed together, as the scenario's [randomise] table does).
fn variant(set: ParameterSet, p: Perturbation) -> Scenario {
    let mut scenario = Scenario::load("urgent_merge")
        .unwrap()
        .with_parameter_set(set)
        .unwrap();
    match p {
        Perturbation::Nominal => {}
        Perturbation::ObstacleStartM(dx) => vehicle_mut(&mut scenario, OBSTACLE).x_m += dx,
        Perturbation::EgoSpeedMps(dv) => shift_speed(&mut scenario, EGO, dv),
        Perturbation::ObstacleSpeedMps(dv) => shift_speed(&mut scenario, OBSTACLE, dv),
        Perturbation::Mu(mu) => scenario.sim.mu = mu,
        Perturbation::WorstCorner => {
            vehicle_mut(&mut scenario, OBSTACLE).x_m += 3.0;
            shift_speed(&mut scenario, EGO, -1.0);
            shift_speed(&mut scenario, OBSTACLE, 1.0);
        }
    }
    scenario
}

fn vehicle<'a>(outcome: &'a RunOutcome, name: &str) -> &'a VehicleMetricsSummary {
    outcome.vehicles.iter().find(|v| v.id == name).unwrap()
}

fn paper<'a>(outcome: &'a RunOutcome, name: &str) -> &'a PaperMetricsSummary {
    vehicle(outcome, name).paper_metrics.as_ref().unwrap()
}

fn collisions(outcome: &RunOutcome) -> usize {
    outcome.safety.collisions.len() + outcome.safety.edge_contacts.len()
}

fn zone_rms(outcome: &RunOutcome, name: &str) -> f64 {
    paper(outcome, name).merge_zone_rms_yaw_rate_radps.unwrap()
}

/// The obstacle's motion states of the paper's Fig. 4 (peak |β|, |ψ|, |r|) and the yaw-rate
/// RMS in the merge zone.
fn motion_states(outcome: &RunOutcome) -> [(&'static str, f64); 4] {
    let o = vehicle(outcome, OBSTACLE);
    [
        ("peak |sideslip|", o.max_abs_sideslip_rad),
        ("peak |yaw|", o.max_abs_yaw_rad),
        ("peak |yaw rate|", o.max_abs_yaw_rate_radps),
        (
            "RMS yaw rate in the merge zone",
            zone_rms(outcome, OBSTACLE),
        ),
    ]
}

/// The findings of the `mergesim` set on one variant; returns whether the obstacle made room.
fn check_mergesim_findings(p: Perturbation) -> bool {
    use PlannerKind::*;
    let scenario = variant(ParameterSet::Mergesim, p);
    let road = scenario.sim.road.clone();
    let spec = |name: &str| scenario.vehicles.iter().find(|v| v.name == name).unwrap();
    let (ego, obstacle) = (spec(EGO).clone(), spec(OBSTACLE).clone());
    let [cs, sp, iso, pred] = run_kinds(&scenario, [PfCs, PfSp, PfIso, PfIsoPred]);

    // No collision with any planner, and the ego has merged by the end.
    for (kind, outcome) in [(PfCs, &cs), (PfSp, &sp), (PfIso, &iso), (PfIsoPred, &pred)] {
        assert_eq!(collisions(outcome), 0, "{p:?} {kind}: {:?}", outcome.events);
        let crossing = paper(outcome, EGO).divider_crossing;
        assert!(
            crossing.is_some_and(|c| c.x_m < road.merge_end_x_m),
            "{p:?} {kind}: ego crossing {crossing:?}"
        );
    }
    // PF-CS never brakes.
    assert_eq!(paper(&cs, OBSTACLE).slowing_onset_s, None, "{p:?}");

    let iso_onset = paper(&iso, OBSTACLE).slowing_onset_s;
    let makes_room =
        vehicle(&iso, OBSTACLE).min_speed_mps < obstacle.target_speed_mps - MAKES_ROOM_MPS;
    // Wherever PF-SP's obstacle brakes, PF-ISO's started slowing earlier.
    if let Some(sp_onset) = paper(&sp, OBSTACLE).slowing_onset_s {
        assert!(
            iso_onset.is_some_and(|t| t < sp_onset),
            "{p:?}: onset PF-ISO {iso_onset:?} vs PF-SP {sp_onset}"
        );
    }
    if iso_onset.is_some() {
        // PF-ISO: the obstacle starts slowing before the ego has reached the merge section
        // (still in its own lane: only its shared path says where it is going) ...
        let ego_at_merge_s = (road.merge_start_x_m - ego.x_m) / ego.speed_mps;
        assert!(
            iso_onset.is_some_and(|t| t < ego_at_merge_s),
            "{p:?}: onset {iso_onset:?}, ego at the merge section at {ego_at_merge_s:.2} s"
        );
        // ... accelerates back to its target by the end ...
        let last = vehicle(&iso, OBSTACLE).final_speed_mps;
        assert!(
            (last - obstacle.target_speed_mps).abs() < 0.3,
            "{p:?}: final speed {last}"
        );
        // ... has the shortest path of the three (pre-braking) and winds least in the merge
        // zone, PF-SP between PF-ISO and PF-CS.
        let iso_path = vehicle(&iso, OBSTACLE).path_length_m;
        for (kind, outcome) in [(PfCs, &cs), (PfSp, &sp)] {
            let other = vehicle(outcome, OBSTACLE).path_length_m;
            assert!(
                iso_path < other,
                "{p:?}: path PF-ISO {iso_path} vs {kind} {other}"
            );
        }
        let [i, s, c] = [&iso, &sp, &cs].map(|o| zone_rms(o, OBSTACLE));
        assert!(i < s && s < c, "{p:?}: merge-zone RMS r {i} / {s} / {c}");
    }
    if makes_room {
        // Where it has to give up more than 0.5 m/s, PF-ISO's obstacle has the smallest of
        // every motion state of the paper's Fig. 4, and PF-SP's yaw states lie between PF-ISO's
        // and PF-CS's. PF-SP's peak sideslip is not asserted against PF-CS's: since path points
        // carry the speed of their own instant (2026-12-02) it lies above PF-CS's in 2 of the 6
        // variants where the obstacle makes room (ego 19 m/s: 0.000253 vs 0.000229 rad;
        // obstacle 16 m/s: 0.000314 vs 0.000236 rad; CHANGELOG, docs/reproduction_history.md).
        for (k, (state, iso_value)) in motion_states(&iso).into_iter().enumerate() {
            let sp_value = motion_states(&sp)[k].1;
            let cs_value = motion_states(&cs)[k].1;
            let sp_between = state == "peak |sideslip|" || sp_value < cs_value;
            assert!(
                iso_value < sp_value && iso_value < cs_value && sp_between,
                "{p:?}: obstacle {state}: PF-ISO {iso_value:.6}, PF-SP {sp_value:.6}, PF-CS {cs_value:.6}"
            );
        }
    }
    if iso_onset.is_none() {
        // Nobody has to make room: every planner drives the obstacle alike (within 10 % of
        // PF-CS's merge-zone yaw-rate RMS).
        let reference = zone_rms(&cs, OBSTACLE);
        for (kind, outcome) in [(PfSp, &sp), (PfIso, &iso), (PfIsoPred, &pred)] {
            let value = zone_rms(outcome, OBSTACLE);
            assert!(
                (value - reference).abs() < 0.1 * reference,
                "{p:?} {kind}: {value} vs PF-CS {reference}"
            );
        }
    }
    makes_room
}

#[test]
fn mergesim_set_nominal_and_perturbed_merges() {
    let made_room = PERTURBATIONS
        .into_iter()
        .filter(|p| check_mergesim_findings(*p))
        .count();
    // The obstacle has to make room in most variants (6 of 9 measured): the branch above that
    // asserts the paper's findings is not the rare one.
    assert!(made_room >= 5, "{made_room}");
}

#[test]
fn mergesim_set_nominal_magnitudes() {
    let scenario = variant(ParameterSet::Mergesim, Perturbation::Nominal);
    let [cs, iso] = run_kinds(&scenario, [PlannerKind::PfCs, PlannerKind::PfIso]);
    // The obstacle starts slowing about when the paper's does (3.1 s).
    let onset = paper(&iso, OBSTACLE).slowing_onset_s.unwrap();
    assert!((2.0..4.5).contains(&onset), "{onset}");
    // Its peak yaw rate is below PF-CS's, and the ego never slows for it. (It was less than
    // half of PF-CS's, 0.42, while the tracker followed speeds shifted one step ahead; with
    // path points carrying the speed of their own instant the ratio is 0.502: CHANGELOG.)
    let peak = |o: &RunOutcome| vehicle(o, OBSTACLE).max_abs_yaw_rate_radps;
    assert!(peak(&iso) < peak(&cs), "{} vs {}", peak(&iso), peak(&cs));
    assert_eq!(paper(&iso, EGO).slowing_onset_s, None);
}

/// The worst corner of the perturbation box (the ego draws level only at the end of the
/// taper): PF-CS and its control PF-SP-EQ10, which cannot brake, run into the obstacle; the
/// planners that brake for risk (PF-SP) or interact (PF-ISO, PF-ISO-PRED) do not.
#[test]
fn mergesim_set_worst_corner_only_the_planners_that_can_brake_avoid_the_collision() {
    use PlannerKind::*;
    let scenario = variant(ParameterSet::Mergesim, Perturbation::WorstCorner);
    let [cs, eq10, sp, iso, pred] = run_kinds(&scenario, [PfCs, PfSpEq10, PfSp, PfIso, PfIsoPred]);
    assert!(collisions(&cs) > 0);
    assert!(collisions(&eq10) > 0);
    for (kind, outcome) in [(PfSp, &sp), (PfIso, &iso), (PfIsoPred, &pred)] {
        assert_eq!(collisions(outcome), 0, "{kind}: {:?}", outcome.events);
    }
}

/// Where the two outcomes meet (obstacle start 45–53 m: first the obstacle makes room, then the
/// ego yields): with roles fixed from the order now, neither PF-ISO nor PF-ISO-PRED collides
/// (with per-slot roles on constant-velocity predictions PF-ISO-PRED raced into the obstacle at
/// 47.2–50.8 m; docs/reproduction_history.md, "Where the two equilibria meet").
#[test]
fn mergesim_set_switch_between_the_equilibria_is_collision_free_with_and_without_v2v() {
    for start_m in 45..=53 {
        let mut scenario = variant(ParameterSet::Mergesim, Perturbation::Nominal);
        vehicle_mut(&mut scenario, OBSTACLE).x_m = f64::from(start_m);
        let [iso, pred] = run_kinds(&scenario, [PlannerKind::PfIso, PlannerKind::PfIsoPred]);
        for (kind, outcome) in [("pf-iso", &iso), ("pf-iso-pred", &pred)] {
            assert_eq!(
                collisions(outcome),
                0,
                "{kind}, obstacle start {start_m} m: {:?}",
                outcome.events
            );
        }
    }
}

/// The `paper` set (the paper's literal Eq. 4 and Eq. 7, D_min without a time gap) shows the
/// paper's phenomenon: PF-CS's obstacle winds inside the merge zone.
#[test]
fn paper_set_pf_cs_obstacle_winds_in_the_merge_zone() {
    let scenario = variant(ParameterSet::Paper, Perturbation::Nominal);
    let cs = run(&scenario, PlannerKind::PfCs);
    let m = paper(&cs, OBSTACLE);
    let inside = m.merge_zone_rms_yaw_rate_radps.unwrap();
    let outside = m.outside_merge_zone_rms_yaw_rate_radps.unwrap();
    assert!(inside >= 5.0 * outside, "{inside} vs {outside}");
    let peak = vehicle(&cs, OBSTACLE).max_abs_yaw_rate_radps;
    assert!(peak >= 0.03, "{peak}");
    assert_eq!(collisions(&cs), 0);
}

/// The `paper` set, car for car: PF-ISO slows its *ego* first, and its obstacle does not slow
/// before PF-SP's. With the printed D_min the planning vehicle is always the follower, so the
/// interaction term slows the faster vehicle (docs/reproduction.md). Measured 2026-12-02 on
/// the nominal run: PF-SP's obstacle brakes at 10.45 s (to 14.50 m/s); PF-ISO's ego slows at
/// 8.80 s, its obstacle at 10.65 s. Over 100 paired instances (docs/studies/paper_sensitivity,
/// 8 s horizon) PF-ISO's obstacle slows +0.13 s [−0.08, +0.34] after PF-SP's where both slow.
/// An earlier version of this test set PF-ISO's first slowing car (the ego) against PF-SP's
/// obstacle, which compared different cars.
#[test]
fn paper_set_pf_iso_slows_the_ego_and_not_the_obstacle_before_pf_sp() {
    let scenario = variant(ParameterSet::Paper, Perturbation::Nominal);
    let [sp, iso] = run_kinds(&scenario, [PlannerKind::PfSp, PlannerKind::PfIso]);
    let sp_obstacle = paper(&sp, OBSTACLE).slowing_onset_s.expect("PF-SP brakes");
    let iso_ego = paper(&iso, EGO)
        .slowing_onset_s
        .expect("PF-ISO slows the ego");
    if let Some(iso_obstacle) = paper(&iso, OBSTACLE).slowing_onset_s {
        assert!(iso_ego < iso_obstacle, "{iso_ego} vs {iso_obstacle}");
        assert!(
            iso_obstacle >= sp_obstacle,
            "PF-ISO's obstacle at {iso_obstacle} s, PF-SP's at {sp_obstacle} s"
        );
    }
    for outcome in [&sp, &iso] {
        assert_eq!(collisions(outcome), 0);
    }
}

/// The paper's causal claim, without the optimiser: the obstacle on PF-CS paths (`paper` set)
/// but at the speed profile the paper reports for PF-ISO (15 → 9.4 m/s) winds less than at its
/// constant 15 m/s, in the nominal merge and with the gap or the ego's speed perturbed.
#[test]
fn paper_set_prescribed_pre_braking_calms_pf_cs_s_winding() {
    let prebraking = Scenario::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/experiments/prebraking_paper_profile.toml"
    ))
    .unwrap()
    .with_parameter_set(ParameterSet::Paper)
    .unwrap();
    for p in [
        Perturbation::Nominal,
        Perturbation::ObstacleStartM(-3.0),
        Perturbation::ObstacleStartM(3.0),
        Perturbation::EgoSpeedMps(-1.0),
        Perturbation::EgoSpeedMps(1.0),
    ] {
        let constant = variant(ParameterSet::Paper, p);
        let mut prescribed = constant.clone();
        prescribed.vehicles[1].driver = prebraking.vehicles[1].driver.clone();
        let [a, b] = std::thread::scope(|s| {
            let b = s.spawn(|| run(&prescribed, PlannerKind::PfCs));
            [run(&constant, PlannerKind::PfCs), b.join().unwrap()]
        });
        assert!(
            vehicle(&b, OBSTACLE).min_speed_mps < 9.6,
            "{p:?}: profile followed"
        );
        for (state, value) in [
            (
                "RMS yaw rate in the merge zone",
                zone_rms as fn(&RunOutcome, &str) -> f64,
            ),
            ("peak |yaw rate|", |o, n| {
                vehicle(o, n).max_abs_yaw_rate_radps
            }),
        ] {
            let (at_constant, braking) = (value(&a, OBSTACLE), value(&b, OBSTACLE));
            assert!(
                braking < at_constant,
                "{p:?}: obstacle {state} {braking} with pre-braking vs {at_constant}"
            );
        }
        assert_eq!(collisions(&b), 0, "{p:?}: {:?}", b.events);
    }
}

/// PF-CS and PF-SP do not use the interaction term's parameters: changing every one of them
/// leaves their runs bit for bit identical (and PF-ISO's not).
#[test]
fn interaction_parameters_do_not_move_the_baselines() {
    let base = variant(ParameterSet::Mergesim, Perturbation::Nominal);
    let mut changed = base.clone();
    let p = &mut changed.sim.planner;
    p.interaction_time_gap_s = 1.0;
    p.interaction_epsilon = 2e-3;
    p.interaction_lateral_safety_m = 4.0;
    p.interaction_fraction_at_min_distance = 0.2;
    p.interaction_floor = 0.05;
    p.interaction_weight = 30.0;
    p.interaction_rear_only = false;
    p.interaction_slows_only = true;
    p.interaction_slp_reading = mergesim::planner::params::SlpReading::FixedWaypoints;
    for kind in [PlannerKind::PfCs, PlannerKind::PfSp, PlannerKind::PfSpEq10] {
        let a = common::simulate(&base, Some(kind), 0, true);
        let b = common::simulate(&changed, Some(kind), 0, true);
        assert_eq!(a.time_series, b.time_series, "{kind}");
    }
    let a = run(&base, PlannerKind::PfIso);
    let b = run(&changed, PlannerKind::PfIso);
    assert_ne!(a.vehicles, b.vehicles);
}
