//! Scans the weight of PF-SP's risk term (w_R) and of PF-ISO's interaction term (w3) against
//! the car-following criterion of `docs/parameters.md`: behind a leader at 15 m/s on a single
//! lane, a follower (target 20 m/s) settles at the D_min of its own field, within ±10 %.
//!
//! `cargo run --release -p planner --example calibrate_following`
//!
//! `-- --arms`: the same criterion in each arm of the `paper` set's attribution (docs/studies/
//! paper_attribution/): U_SLP reading × D_min roles × σ_y form, w_R from PF-SP and w3 from
//! PF-ISO-PRED (as `tests/calibration.rs`), each twice its smallest weight, rounded.

#[path = "../tests/common/mod.rs"]
mod common;

use planner::obstacle_field::LateralForm;
use planner::params::{PlannerParams, SlpReading};
use planner::{ParameterSet, PlannerKind};

fn scan_floor() {
    let base = PlannerParams::default();
    let d_min = common::equal_speed_min_distance_m(15.0, base.interaction_time_gap_s);
    for floor in [0.02, 0.05, 0.1, 0.2] {
        for w in [3.0, 5.0, 10.0, 15.0, 20.0, 30.0, 50.0] {
            let params = PlannerParams {
                interaction_floor: floor,
                interaction_weight: w,
                ..base.clone()
            };
            let (gap, speed, _) =
                common::following(PlannerKind::PfIsoPred, &params, 15.0, 60.0, 60.0);
            println!(
                "floor {floor} w3 {w}: gap {gap:.2} ({:.2} D_min) v {speed:.2}",
                gap / d_min
            );
        }
    }
}

fn scan_epsilon() {
    let base = PlannerParams::default();
    let centre = common::lateral_equilibrium_m(&base, None);
    println!("path field: lane equilibrium {centre:.4} m alone");
    for eps in [1e-4, 2e-4, 3e-4, 5e-4, 7e-4, 1e-3, 2e-3] {
        let params = PlannerParams {
            obstacle_epsilon: eps,
            ..base.clone()
        };
        let shift = (common::lateral_equilibrium_m(&params, Some((0.0, 1.75))) - centre).abs();
        println!(
            "  ε = {eps:e}: shift {:.1} cm with a vehicle alongside",
            100.0 * shift
        );
    }
    let alone = common::first_planned_speed_mps(PlannerKind::PfIsoPred, &base, None);
    println!("interaction: most extreme planned speed alone {alone:.4} m/s");
    for eps in [1e-4, 2e-4, 3e-4, 5e-4, 7e-4, 1e-3, 2e-3] {
        let params = PlannerParams {
            interaction_epsilon: eps,
            ..base.clone()
        };
        let worst = [1.0, 5.0, 10.0, 20.0, 30.0]
            .iter()
            .map(|ahead| {
                (common::first_planned_speed_mps(PlannerKind::PfIsoPred, &params, Some(*ahead))
                    - alone)
                    .abs()
            })
            .fold(0.0, f64::max);
        println!(
            "  ε_I = {eps:e}: largest speed change {worst:.3} m/s with a vehicle 1–30 m ahead in the other lane"
        );
    }
}

fn thresholds() {
    let base = PlannerParams::default();
    for kind in [
        PlannerKind::PfSp,
        PlannerKind::PfIsoPred,
        PlannerKind::PfIso,
    ] {
        let w = common::smallest_following_weight(kind, &base, 1.0, 400.0);
        println!(
            "{kind}: smallest weight that keeps behind a slower leader {w:.2}; twice that {:.1}",
            2.0 * w
        );
    }
}

/// The smallest following weight of `kind` in the arm, searched over [0.1, 1000]; twice it,
/// rounded, or None when no weight in that range keeps the follower behind.
fn arm_weight(kind: PlannerKind, params: &PlannerParams) -> (Option<f64>, Option<f64>) {
    let smallest = common::try_smallest_following_weight(kind, params, 0.1, 1000.0);
    (smallest, smallest.map(|w| (2.0 * w).round()))
}

fn arms() {
    println!(
        "| U_SLP reading | D_min roles | σ_y | w_R: smallest (PF-SP) | w_R = 2×, rounded | w3: smallest (PF-ISO-PRED) | w3 = 2×, rounded |"
    );
    println!("|---|---|---|---|---|---|---|");
    let show = |w: Option<f64>, digits: usize| {
        w.map_or("none in [0.1, 1000]".to_string(), |w| {
            format!("{w:.digits$}")
        })
    };
    for reading in [SlpReading::FixedWaypoints, SlpReading::ArcLength] {
        for by_side in [false, true] {
            for lateral in [LateralForm::FixedDistance, LateralForm::PrintedLaplace] {
                let params = PlannerParams {
                    interaction_slp_reading: reading,
                    obstacle_min_distance_by_side: by_side,
                    obstacle_lateral_form: lateral,
                    ..ParameterSet::Paper.planner_params()
                };
                let (r_small, r_w) = arm_weight(PlannerKind::PfSp, &params);
                let (i_small, i_w) = arm_weight(PlannerKind::PfIsoPred, &params);
                println!(
                    "| {reading:?} | {} | {lateral:?} | {} | {} | {} | {} |",
                    if by_side { "by side" } else { "printed" },
                    show(r_small, 2),
                    show(r_w, 0),
                    show(i_small, 2),
                    show(i_w, 0),
                );
            }
        }
    }
}

fn main() {
    if std::env::args().any(|a| a == "--arms") {
        arms();
        return;
    }
    if std::env::args().any(|a| a == "--thresholds") {
        thresholds();
        return;
    }
    if std::env::args().any(|a| a == "--epsilon") {
        scan_epsilon();
        return;
    }
    if std::env::args().any(|a| a == "--floor") {
        scan_floor();
        return;
    }
    let base = PlannerParams::default();
    let leader_mps = 15.0;
    println!("criterion: steady gap = D_min of the field, ±10 %");
    for (kind, gap_s, name) in [
        (PlannerKind::PfSp, base.obstacle_time_gap_s, "w_R (pf-sp)"),
        (
            PlannerKind::PfIsoPred,
            base.interaction_time_gap_s,
            "w3 (pf-iso-pred)",
        ),
        (
            PlannerKind::PfIso,
            base.interaction_time_gap_s,
            "w3 (pf-iso)",
        ),
    ] {
        let d_min = common::equal_speed_min_distance_m(leader_mps, gap_s);
        println!("{name}: D_min = {d_min:.2} m");
        for w in [1.0, 2.0, 3.0, 5.0, 7.0, 10.0, 15.0, 20.0, 30.0, 50.0, 100.0] {
            let params = PlannerParams {
                risk_weight: w,
                interaction_weight: w,
                ..base.clone()
            };
            let (gap, speed, _) = common::following(kind, &params, leader_mps, 60.0, 60.0);
            println!(
                "  w = {w:>5}: gap {gap:7.2} m ({:5.2} D_min), follower {speed:.2} m/s",
                gap / d_min
            );
        }
    }
}
