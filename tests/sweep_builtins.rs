//! The built-in scenarios as sweeps use them: every one, nominal and randomised, starts and runs
//! cleanly, and the merges that PF-ISO is meant to handle end without collision at nominal.

mod common;

use mergesim::planner::PlannerKind;
use mergesim::scenarios::builtin;
use mergesim::scenarios::scenario::Scenario;
use mergesim::sim::RunOutcome;

fn run(scenario: &Scenario, planner: Option<PlannerKind>, seed: u64) -> RunOutcome {
    common::simulate(scenario, planner, seed, false)
}

#[test]
fn every_builtin_starts_cleanly_at_nominal_and_at_the_corners_of_its_ranges() {
    for name in builtin::names() {
        let nominal = Scenario::load(name).unwrap();
        // The nominal scenario, a random instance and both corners of the randomisation box
        // (every randomised value at its lower / upper end), for the first 1.5 s (the spawn and
        // the first planning cycles, where a bad layout shows): no collision, nothing diverges.
        let corner = |upper: bool| {
            let (sim, vehicles) = nominal
                .randomise
                .corner(&nominal.sim, &nominal.vehicles, upper);
            Scenario {
                sim,
                vehicles,
                ..nominal.clone()
            }
        };
        let cases = [
            (nominal.clone(), 0),
            (nominal.instantiate(1), 1),
            (corner(false), 2),
            (corner(true), 3),
        ];
        for (mut s, seed) in cases {
            s.sim.duration_s = 1.5;
            let outcome = run(&s, None, seed);
            assert!(
                outcome.safety.collisions.is_empty() && outcome.safety.edge_contacts.is_empty(),
                "{name} case {seed}: {:?} {:?}",
                outcome.safety.collisions,
                outcome.safety.edge_contacts
            );
            assert!(
                outcome.safety.min_gap_m.is_some_and(|g| g > 0.5),
                "{name}: {:?}",
                outcome.safety.min_gap_m
            );
        }
    }
}

#[test]
fn pf_iso_merges_the_two_lane_builtins_without_collision_at_nominal() {
    for name in [
        "urgent_merge",
        "relaxed_merge",
        "wet_road",
        "degraded_v2v",
        "dense_merge",
    ] {
        let s = Scenario::load(name).unwrap();
        let outcome = common::simulate(&s, Some(PlannerKind::PfIso), 0, true);
        assert!(
            outcome.safety.collisions.is_empty() && outcome.safety.edge_contacts.is_empty(),
            "{name}: {:?}",
            outcome.events
        );
        // Everybody ends in the through lane, past the merge section.
        let road = &s.sim.road;
        for v in &s.vehicles {
            let last = outcome
                .time_series
                .iter()
                .rev()
                .find(|r| r.vehicle == v.name)
                .unwrap();
            assert!(
                last.x_m > road.merge_end_x_m,
                "{name}/{}: x = {}",
                v.name,
                last.x_m
            );
            assert!(
                last.y_m > road.y_lane_m() && last.y_m < road.y_upper_m(),
                "{name}/{}: y = {}",
                v.name,
                last.y_m
            );
        }
        if name == "degraded_v2v" {
            // 20 % of the per-receiver messages lost: binomial over about 500 messages
            // (standard deviation about 0.018).
            let v2v = &outcome.v2v;
            let lost = v2v.dropped as f64 / (v2v.dropped + v2v.delivered) as f64;
            assert!((lost - 0.2).abs() < 0.06, "{v2v:?}");
        }
    }
}

#[test]
fn builtins_have_the_documented_settings_and_ranges() {
    let s = Scenario::load("degraded_v2v").unwrap();
    assert_eq!(s.sim.v2v.latency_s, 0.1);
    assert_eq!(s.sim.v2v.drop_probability, 0.2);
    let wet = Scenario::load("wet_road").unwrap();
    assert_eq!(wet.sim.mu, 0.5);
    let dense = Scenario::load("dense_merge").unwrap();
    assert!(dense.vehicles.iter().filter(|v| v.connected).count() >= 6);
    let platoon = Scenario::load("platoon_merge_50").unwrap();
    assert_eq!(platoon.vehicles.len(), 50);
    let mixed = Scenario::load("mixed_traffic").unwrap();
    assert!(mixed.vehicles.iter().any(|v| !v.connected));
    assert!(mixed.vehicles.iter().filter(|v| v.connected).count() >= 2);
    // urgent_merge's documented ranges: μ 0.7–0.9, gap ±3 m, speeds ±1 m/s.
    let u = Scenario::load("urgent_merge").unwrap();
    let (lo, hi) = (
        u.randomise.corner(&u.sim, &u.vehicles, false),
        u.randomise.corner(&u.sim, &u.vehicles, true),
    );
    assert!((lo.0.mu - 0.7).abs() < 1e-12 && (hi.0.mu - 0.9).abs() < 1e-12);
    let gap = |v: &[mergesim::sim::config::VehicleSpec]| v[1].x_m - v[0].x_m;
    assert!((gap(&hi.1) - gap(&u.vehicles) - 3.0).abs() < 1e-12);
    assert!((gap(&lo.1) - gap(&u.vehicles) + 3.0).abs() < 1e-12);
    for (l, h, n) in
        lo.1.iter()
            .zip(&hi.1)
            .zip(&u.vehicles)
            .map(|((l, h), n)| (l, h, n))
    {
        assert!(
            (n.speed_mps - l.speed_mps - 1.0).abs() < 1e-12
                && (h.speed_mps - n.speed_mps - 1.0).abs() < 1e-12
        );
    }
}
