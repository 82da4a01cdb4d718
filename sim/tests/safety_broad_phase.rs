//! The safety monitor's broad phase (the X sweep) against visiting every pair: identical
//! reports at every instant and an identical summary, on crowded layouts with contacts, near
//! misses, closing pairs, pairs beyond the followed range and vehicles side by side.

use mergesim_types::MergeRoad;
use sim::rng::SplitMix64;
use sim::safety::{BodyState, SafetyMonitor, SafetyParams, SafetySummary};

/// `n` cars over `length_m` in three lanes with speeds 0–35 m/s and small headings; a fifth of
/// them on the X of an earlier one (side by side, or overlapping when in the same lane).
fn layout(rng: &mut SplitMix64, n: usize, length_m: f64) -> Vec<BodyState> {
    let mut bodies: Vec<BodyState> = Vec::with_capacity(n);
    for id in 0..n {
        let lane = (rng.next_f64() * 3.0).floor();
        let x_m = if id > 0 && rng.next_f64() < 0.2 {
            bodies[(rng.next_f64() * id as f64) as usize].x_m + rng.next_f64() - 0.5
        } else {
            rng.next_f64() * length_m
        };
        let speed_mps = 35.0 * rng.next_f64();
        let yaw_rad = 0.1 * (rng.next_f64() - 0.5);
        bodies.push(BodyState {
            id: id as u32,
            x_m,
            y_m: 1.75 + 3.5 * lane,
            yaw_rad,
            vx_mps: speed_mps * yaw_rad.cos(),
            vy_mps: speed_mps * yaw_rad.sin(),
            yaw_rate_radps: 0.0,
            length_m: 4.508,
            width_m: 1.61,
            height_m: 1.4,
        });
    }
    bodies
}

/// Feeds the same instants to a monitor with and one without the broad phase; every report
/// and the summary must be identical.
/// Returns the number of followed pair instants and the summary.
fn compare(
    params: SafetyParams,
    seed: u64,
    n: usize,
    length_m: f64,
    instants: usize,
) -> (usize, SafetySummary) {
    let road = MergeRoad {
        start_x_m: -100.0,
        end_x_m: length_m + 2000.0,
        merge_start_x_m: length_m + 1000.0,
        merge_end_x_m: length_m + 1100.0,
        ..MergeRoad::default()
    };
    let swept_params = SafetyParams {
        broad_phase: true,
        ..params.clone()
    };
    let all_params = SafetyParams {
        broad_phase: false,
        ..params
    };
    let mut swept =
        SafetyMonitor::new(swept_params, std::sync::Arc::new(road.lane_road().unwrap())).unwrap();
    let mut all =
        SafetyMonitor::new(all_params, std::sync::Arc::new(road.lane_road().unwrap())).unwrap();
    let mut rng = SplitMix64::new(seed);
    let mut bodies = layout(&mut rng, n, length_m);
    let dt_s = 0.05;
    let mut followed = 0;
    for k in 0..instants {
        let t_s = k as f64 * dt_s;
        let a = swept.check(t_s, &bodies, dt_s).unwrap().clone();
        let b = all.check(t_s, &bodies, dt_s).unwrap().clone();
        assert_eq!(a, b, "seed {seed}, t = {t_s}");
        followed += a.pairs.len();
        // Constant velocity with a random lateral nudge: pairs close, touch and separate.
        for body in &mut bodies {
            body.x_m += body.vx_mps * dt_s;
            body.y_m += body.vy_mps * dt_s + 0.2 * (rng.next_f64() - 0.5);
        }
    }
    let summary = swept.summary();
    assert_eq!(summary, all.summary(), "seed {seed}");
    assert_eq!(summary.checked_instants, instants as u64);
    (followed, summary)
}

#[test]
fn the_broad_phase_gives_the_all_pairs_results_on_crowded_layouts() {
    let (mut collisions, mut near_misses, mut closing) = (0, 0, 0);
    for seed in 0..6 {
        let (_, summary) = compare(SafetyParams::default(), seed, 80, 1500.0, 60);
        collisions += summary.collisions.len();
        near_misses += summary.pairs.iter().filter(|p| p.near_miss).count();
        closing += summary
            .pairs
            .iter()
            .filter(|p| p.min_ttc_s.is_some())
            .count();
    }
    // The layouts do contain what is being compared.
    assert!(
        collisions > 0 && near_misses > 0 && closing > 0,
        "{collisions} {near_misses} {closing}"
    );
}

#[test]
fn a_small_fleet_tested_pair_by_pair_gives_the_all_pairs_results() {
    // Below the monitor's small-fleet size the X test runs on every pair instead of the sweep.
    let (mut collisions, mut closing) = (0, 0);
    for seed in 30..36 {
        let (_, summary) = compare(SafetyParams::default(), seed, 20, 300.0, 60);
        collisions += summary.collisions.len();
        closing += summary
            .pairs
            .iter()
            .filter(|p| p.min_ttc_s.is_some())
            .count();
    }
    assert!(collisions > 0 && closing > 0, "{collisions} {closing}");
    // A small window (10 m) leaves pairs out of the X test as well.
    let params = SafetyParams {
        pair_range_m: 10.0,
        ttc_horizon_s: 1.5,
        ..SafetyParams::default()
    };
    let (followed, _) = compare(params, 40, 20, 2000.0, 40);
    assert!(followed < 20 * 19 / 2 * 40 / 2, "{followed}");
}

#[test]
fn the_broad_phase_skips_pairs_beyond_the_followed_range() {
    // Slow traffic over 5 km: most pairs are neither within 250 m nor closing fast enough.
    let params = SafetyParams::default();
    let n = 60;
    let (followed, _) = compare(params, 7, n, 5000.0, 40);
    let all_pairs = n * (n - 1) / 2 * 40;
    assert!(followed < all_pairs / 2, "{followed} of {all_pairs}");
}

#[test]
fn a_small_range_and_short_horizon_still_match() {
    let params = SafetyParams {
        pair_range_m: 10.0,
        ttc_horizon_s: 1.5,
        ..SafetyParams::default()
    };
    for seed in 20..24 {
        compare(params.clone(), seed, 70, 800.0, 60);
    }
}
