//! Seeded Monte-Carlo statistics of the randomised urgent merge: the paper's per-planner claims,
//! checked on average over randomised instances rather than on one hand-picked run (those that
//! hold with the current planner tuning; see the note at the end of the test for one that does
//! not).
//!
//! Both planners run the same instances (same sweep seed), so the comparisons are paired.

use mergesim::planner::PlannerKind;
use mergesim::scenarios::scenario::Scenario;
use mergesim::summary::RunSummary;
use mergesim::sweep::{
    RunMetrics, Shard, SweepOptions, SweepPlan, SweepSummary, instance_seed, run_sweep,
    simulate_instance,
};

/// Runs per planner: enough for the averages below to be far from their noise (see the
/// margins), few enough for the suite (≈ 0.2 s of CPU per run; 0 collisions in 64 runs bounds
/// the collision rate below 5.7 % at 95 % confidence).
const RUNS: u64 = 64;
const SEED: u64 = 20_240_601;

fn sweep(planner: PlannerKind) -> SweepSummary {
    let plan = SweepPlan {
        scenario: Scenario::load("urgent_merge").unwrap(),
        planner: Some(planner.name().to_string()),
        runs: RUNS,
        seed: SEED,
        shard: Shard::WHOLE,
    };
    run_sweep(&plan, &SweepOptions::default(), &|_| {})
        .unwrap()
        .summary
}

fn metrics(s: &SweepSummary) -> Vec<&RunMetrics> {
    s.samples
        .iter()
        .map(|r| r.metrics.as_ref().unwrap())
        .collect()
}

/// Mean and standard error of the paired differences a − b.
fn paired(a: &[f64], b: &[f64]) -> (f64, f64) {
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

#[test]
fn pf_iso_is_collision_free_and_resolves_the_merge_by_speed_unlike_pf_cs() {
    let iso = sweep(PlannerKind::PfIso);
    let cs = sweep(PlannerKind::PfCs);
    for s in [&iso, &cs] {
        assert_eq!(s.runs, RUNS);
        assert_eq!(s.diverged, 0, "{}: {:?}", s.planner, s.samples);
        // The instances really are randomised: the runs differ.
        let gaps: Vec<f64> = metrics(s).iter().filter_map(|m| m.min_gap_m).collect();
        let spread = gaps.iter().cloned().fold(f64::MIN, f64::max)
            - gaps.iter().cloned().fold(f64::MAX, f64::min);
        assert!(
            spread > 0.05,
            "{}: min gaps barely vary: {gaps:?}",
            s.planner
        );
    }
    // Safety: PF-ISO never collides, and has no more near misses than PF-CS.
    assert_eq!(iso.collisions, 0, "PF-ISO collided: {:?}", iso.samples);
    assert!(
        iso.near_misses <= cs.near_misses,
        "near misses: PF-ISO {} > PF-CS {}",
        iso.near_misses,
        cs.near_misses
    );
    let (mi, mc) = (metrics(&iso), metrics(&cs));
    let diff = |get: fn(&RunMetrics) -> f64| {
        let a: Vec<f64> = mi.iter().map(|m| get(m)).collect();
        let b: Vec<f64> = mc.iter().map(|m| get(m)).collect();
        paired(&a, &b)
    };
    // PF-ISO resolves the conflict by speed (the paper's early braking of the obstacle, 15 → 9.4
    // m/s), PF-CS by definition cannot: the lowest speed of any vehicle is lower with PF-ISO, by
    // more than three standard errors of the paired difference (measured −0.94 ± 0.11 m/s).
    let (d, se) = diff(|m| m.min_speed_mps);
    eprintln!("min speed: PF-ISO − PF-CS = {d:.4} ± {se:.4} m/s");
    assert!(
        d < -3.0 * se,
        "min speed: PF-ISO − PF-CS = {d:.3} ± {se:.3} m/s"
    );
    // Not asserted: the paper (Sec. V, Figs. 7–9) has PF-CS with the largest sideslip, yaw and
    // yaw-rate peaks. For the peaks of `RunMetrics` (the largest of any vehicle, in practice the
    // ego's) that ordering does not hold on average over randomised instances: the ego's peak
    // |r| is higher with PF-ISO (over the 200-run study now in docs/reproduction_history.md,
    // +0.00102 ± 0.00011 rad/s, lower on 37 of 200): with the obstacle further back, the ego
    // changes lanes in one quicker manoeuvre. The obstacle's own peaks do follow the paper: the
    // next test asserts it.
}

/// The obstacle's peak |yaw rate| and |yaw| of one run.
fn obstacle_peaks(summary: &RunSummary) -> (f64, f64) {
    let obstacle = summary
        .vehicles
        .iter()
        .find(|v| v.id == "obstacle")
        .unwrap();
    (obstacle.max_abs_yaw_rate_radps, obstacle.max_abs_yaw_rad)
}

/// The paper's motion-state finding for the vehicle that has to make room (Sec. V, Fig. 4: the
/// obstacle's yaw and yaw rate stay near zero with PF-ISO, and are largest with PF-CS), on the
/// same 64 randomised instances, paired: PF-ISO's obstacle turns less, by more than three
/// standard errors of the paired difference. (Measured with the planner of this commit:
/// |r| −0.0042 ± 0.0006 rad/s; |ψ| −0.0064 ± 0.0008 rad.)
#[test]
fn pf_iso_keeps_the_obstacle_steadier_than_pf_cs_over_randomised_instances() {
    let plan = |planner: PlannerKind| SweepPlan {
        scenario: Scenario::load("urgent_merge").unwrap(),
        planner: Some(planner.name().to_string()),
        runs: RUNS,
        seed: SEED,
        shard: Shard::WHOLE,
    };
    let (iso_plan, cs_plan) = (plan(PlannerKind::PfIso), plan(PlannerKind::PfCs));
    // Instance i of both sweeps, one planner per core.
    let peaks = |plan: &SweepPlan| -> Vec<(f64, f64)> {
        (0..RUNS)
            .map(|i| obstacle_peaks(&simulate_instance(plan, instance_seed(SEED, i)).unwrap()))
            .collect()
    };
    let (iso, cs) = std::thread::scope(|s| {
        let cs = s.spawn(|| peaks(&cs_plan));
        (peaks(&iso_plan), cs.join().unwrap())
    });
    let yaw_rate = |v: &[(f64, f64)]| v.iter().map(|p| p.0).collect::<Vec<_>>();
    let yaw = |v: &[(f64, f64)]| v.iter().map(|p| p.1).collect::<Vec<_>>();
    let (d_r, se_r) = paired(&yaw_rate(&iso), &yaw_rate(&cs));
    let (d_psi, se_psi) = paired(&yaw(&iso), &yaw(&cs));
    eprintln!(
        "obstacle peak |r|: PF-ISO − PF-CS = {d_r:.5} ± {se_r:.5} rad/s; \
         peak |ψ|: {d_psi:.5} ± {se_psi:.5} rad"
    );
    assert!(
        d_r < -3.0 * se_r,
        "obstacle peak |r|: PF-ISO − PF-CS = {d_r:.5} ± {se_r:.5} rad/s"
    );
    assert!(
        d_psi < -3.0 * se_psi,
        "obstacle peak |ψ|: PF-ISO − PF-CS = {d_psi:.5} ± {se_psi:.5} rad"
    );
}

/// Without V2V the interaction term used to race where "the obstacle makes room" and "the ego
/// yields" meet: PF-ISO-PRED collided in 4 of 100 randomised runs of `wet_road` and of
/// `degraded_v2v` (both start the obstacle 45 ± 3 m ahead), with roles decided per time slot
/// from constant-velocity predictions. With the roles fixed from the order now and
/// lane-following predictions, none of those 100 runs (same sweep seed) collides.
#[test]
fn pf_iso_pred_does_not_race_where_the_equilibria_meet() {
    for name in ["wet_road", "degraded_v2v"] {
        let plan = SweepPlan {
            scenario: Scenario::load(name).unwrap(),
            planner: Some(PlannerKind::PfIsoPred.name().to_string()),
            runs: 100,
            seed: 42,
            shard: Shard::WHOLE,
        };
        let summary = run_sweep(&plan, &SweepOptions::default(), &|_| {})
            .unwrap()
            .summary;
        assert_eq!(summary.diverged, 0, "{name}");
        assert_eq!(
            summary.collisions,
            0,
            "{name}: {:?}",
            summary
                .samples
                .iter()
                .filter(|r| r.metrics.as_ref().is_some_and(|m| m.collisions > 0))
                .map(|r| r.seed)
                .collect::<Vec<_>>()
        );
    }
}
