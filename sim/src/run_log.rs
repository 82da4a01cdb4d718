//! The built-in observer of a run's figures: per-vehicle metrics (`crate::metrics`, with the
//! paper's figures) and, on request, the time series of `--csv`.

use mergesim_types::VehicleId;

use crate::error::SimError;
use crate::metrics::{VehicleMetrics, VehicleMetricsSummary};
use crate::observer::{TickObserver, VehicleView};
use crate::outcome::TimeSeriesRow;

/// Metrics of every vehicle and the optional time series.
#[derive(Clone, Debug)]
pub struct RunLog {
    metrics: Vec<VehicleMetrics>,
    keep_time_series: bool,
    time_series: Vec<TimeSeriesRow>,
}

impl RunLog {
    /// Metrics for the vehicles in id order; `keep_time_series` keeps the `--csv` rows.
    pub fn new(metrics: Vec<VehicleMetrics>, keep_time_series: bool) -> Self {
        Self {
            metrics,
            keep_time_series,
            time_series: Vec::new(),
        }
    }

    /// The summaries, in vehicle order.
    pub fn summaries(&self) -> Vec<VehicleMetricsSummary> {
        self.metrics.iter().map(VehicleMetrics::summary).collect()
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
                what: format!("metrics of {}: {e}", v.name),
            })?;
            if self.keep_time_series {
                self.time_series.push(TimeSeriesRow::from_sample(
                    v.name,
                    v.sample,
                    v.planned_speed_mps,
                ));
            }
        }
        Ok(())
    }

    fn on_collision(&mut self, ids: &[VehicleId]) {
        for id in ids {
            if let Some(m) = self.metrics.get_mut(*id as usize) {
                m.set_collided();
            }
        }
    }
}
