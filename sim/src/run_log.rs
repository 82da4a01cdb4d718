//! The built-in observer of a run's figures: per-vehicle metrics (`crate::metrics`, with the
//! paper's figures) and, on request, the time series of `--csv`.

use mergesim_types::VehicleId;

use crate::error::SimError;
use crate::metrics::{VehicleMetrics, VehicleMetricsSummary};
use crate::observer::{PlanView, TickObserver, VehicleView};
use crate::outcome::TimeSeriesRow;

/// Metrics of every vehicle and the optional time series.
#[derive(Clone, Debug)]
pub struct RunLog {
    metrics: Vec<VehicleMetrics>,
    keep_time_series: bool,
    time_series: Vec<TimeSeriesRow>,
    /// Every vehicle's figures frozen at the run's first contact (`None` before any).
    pre_contact: Option<Vec<VehicleMetricsSummary>>,
}

impl RunLog {
    /// Metrics for the vehicles in id order; `keep_time_series` keeps the `--csv` rows.
    pub fn new(metrics: Vec<VehicleMetrics>, keep_time_series: bool) -> Self {
        Self {
            metrics,
            keep_time_series,
            time_series: Vec::new(),
            pre_contact: None,
        }
    }

    /// The summaries, in vehicle order; after a contact each carries its figures as they
    /// stood at the first one (`VehicleMetricsSummary::pre_contact`).
    pub fn summaries(&self) -> Vec<VehicleMetricsSummary> {
        let mut summaries: Vec<VehicleMetricsSummary> =
            self.metrics.iter().map(VehicleMetrics::summary).collect();
        if let Some(frozen) = &self.pre_contact {
            for (summary, before) in summaries.iter_mut().zip(frozen) {
                summary.pre_contact = Some(Box::new(before.clone()));
            }
        }
        summaries
    }

    /// The time series (empty unless kept).
    pub fn into_time_series(self) -> Vec<TimeSeriesRow> {
        self.time_series
    }
}

impl TickObserver for RunLog {
    fn on_log(&mut self, t_s: f64, vehicles: &[VehicleView<'_>]) -> Result<(), SimError> {
        for (metrics, v) in self.metrics.iter_mut().zip(vehicles) {
            metrics.push(v.sample).map_err(|e| SimError::Diverged {
                t_s,
                what: format!("metrics of {}: {e}", v.sample.vehicle),
            })?;
            if self.keep_time_series {
                self.time_series.push(v.sample.clone());
            }
        }
        Ok(())
    }

    fn on_plan(&mut self, _t_s: f64, plan: &PlanView<'_, '_>) -> Result<(), SimError> {
        // Only planner cycles are handed over (the world skips `is_planner() == false`).
        if let Some(m) = self.metrics.get_mut(plan.observation.ego_id as usize) {
            m.push_plan_cycle(plan.optimiser.is_some_and(|r| r.path_fit_bound_active));
        }
        Ok(())
    }

    fn on_collision(&mut self, ids: &[VehicleId]) {
        // The first contact of the run (vehicle–vehicle or road edge) freezes every vehicle's
        // figures: the samples logged so far all precede it (the world checks safety before it
        // logs the instant).
        if self.pre_contact.is_none() {
            self.pre_contact = Some(self.metrics.iter().map(VehicleMetrics::summary).collect());
        }
        for id in ids {
            if let Some(m) = self.metrics.get_mut(*id as usize) {
                m.set_collided();
            }
        }
    }
}
