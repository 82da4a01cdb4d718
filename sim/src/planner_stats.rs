//! The built-in observer of the planners' counters (`RunOutcome::planner_stats`): cycles,
//! fallbacks, degraded-mode decisions, optimiser solves and iteration caps, and the wall time
//! of a cycle. The world only times each decision and hands it over ([`PlanView`]).

use mergesim_types::percentile::nearest_rank_percentile;

use crate::error::SimError;
use crate::observer::{PlanView, TickObserver};
use crate::outcome::PlannerStats;

/// Counts the planners' decisions (module doc).
#[derive(Clone, Debug, Default)]
pub(crate) struct PlannerStatsObserver {
    plan_times_us: Vec<f64>,
    fallbacks: u64,
    degraded_plans: u64,
    optimiser_solves: u64,
    optimiser_iteration_cap_cycles: u64,
}

impl PlannerStatsObserver {
    /// The counters so far; the cycle times' median and 99th percentile are nearest-rank
    /// percentiles (0 without any cycle).
    pub(crate) fn stats(&self) -> PlannerStats {
        let mut times = self.plan_times_us.clone();
        times.sort_by(f64::total_cmp);
        let percentile = |percent: f64| nearest_rank_percentile(&times, percent).unwrap_or(0.0);
        PlannerStats {
            plans: times.len() as u64,
            fallbacks: self.fallbacks,
            degraded_plans: self.degraded_plans,
            optimiser_solves: self.optimiser_solves,
            optimiser_iteration_cap_cycles: self.optimiser_iteration_cap_cycles,
            p50_plan_us: percentile(50.0),
            p99_plan_us: percentile(99.0),
        }
    }
}

impl TickObserver for PlannerStatsObserver {
    fn on_plan(&mut self, _t_s: f64, plan: &PlanView<'_, '_>) -> Result<(), SimError> {
        self.plan_times_us.push(plan.plan_time_us);
        if let Some(report) = plan.optimiser {
            self.optimiser_solves += u64::from(report.solves);
            if report.stopped_at_iteration_cap {
                self.optimiser_iteration_cap_cycles += 1;
            }
        }
        if plan.decision.degraded_mode.is_some() {
            self.degraded_plans += 1;
        }
        if plan.decision.fallback.is_some() {
            self.fallbacks += 1;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_cycle_gives_zero_figures_and_the_percentiles_are_samples() {
        let empty = PlannerStatsObserver::default().stats();
        assert_eq!(
            (empty.plans, empty.p50_plan_us, empty.p99_plan_us),
            (0, 0.0, 0.0)
        );
        let observer = PlannerStatsObserver {
            plan_times_us: (1..=200).rev().map(f64::from).collect(),
            ..PlannerStatsObserver::default()
        };
        let stats = observer.stats();
        assert_eq!(stats.plans, 200);
        // ⌈0.5 · 200⌉ = 100th and ⌈0.99 · 200⌉ = 198th smallest.
        assert_eq!((stats.p50_plan_us, stats.p99_plan_us), (100.0, 198.0));
    }
}
