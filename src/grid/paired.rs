//! Paired differences of the grid's planners against the first, per cell, for one vehicle and
//! one figure; and the rows as CSV.

use serde::{Deserialize, Serialize};

use super::{GridCell, GridOutcome, GridRow, VehicleFigures};
use crate::sweep::statistics::{mean, standard_error};

/// The figure a paired comparison looks at, for one vehicle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GridMetric {
    /// Peak |yaw rate| (rad/s).
    PeakYawRate,
    /// Yaw-rate RMS inside the merge zone (rad/s).
    MergeZoneRmsYawRate,
    /// Yaw-rate RMS outside the merge zone (rad/s).
    OutsideRmsYawRate,
    /// Peak |sideslip| (rad).
    PeakSideslip,
    /// Lowest speed (m/s).
    MinSpeed,
    /// First time 0.1 m/s below the target (s); the means are over the pairs where both
    /// slowed, the runs that never slowed are counted in `never` / `reference_never`.
    SlowingOnset,
    /// Path length (m).
    PathLength,
}

impl GridMetric {
    /// Every metric, in table order.
    pub const ALL: [GridMetric; 7] = [
        GridMetric::PeakYawRate,
        GridMetric::MergeZoneRmsYawRate,
        GridMetric::OutsideRmsYawRate,
        GridMetric::PeakSideslip,
        GridMetric::MinSpeed,
        GridMetric::SlowingOnset,
        GridMetric::PathLength,
    ];

    /// Name with unit, for tables.
    pub fn label(self) -> &'static str {
        match self {
            GridMetric::PeakYawRate => "peak |r| (rad/s)",
            GridMetric::MergeZoneRmsYawRate => "RMS r merge zone (rad/s)",
            GridMetric::OutsideRmsYawRate => "RMS r outside (rad/s)",
            GridMetric::PeakSideslip => "peak |β| (rad)",
            GridMetric::MinSpeed => "min speed (m/s)",
            GridMetric::SlowingOnset => "slowing onset (s)",
            GridMetric::PathLength => "path length (m)",
        }
    }

    /// Decimals to print it with.
    pub fn decimals(self) -> usize {
        match self {
            GridMetric::PeakYawRate
            | GridMetric::MergeZoneRmsYawRate
            | GridMetric::OutsideRmsYawRate
            | GridMetric::PeakSideslip => 5,
            GridMetric::MinSpeed | GridMetric::SlowingOnset | GridMetric::PathLength => 2,
        }
    }

    fn of(self, v: &VehicleFigures) -> Option<f64> {
        match self {
            GridMetric::PeakYawRate => Some(v.peak_yaw_rate_radps),
            GridMetric::MergeZoneRmsYawRate => v.merge_zone_rms_yaw_rate_radps,
            GridMetric::OutsideRmsYawRate => v.outside_merge_zone_rms_yaw_rate_radps,
            GridMetric::PeakSideslip => Some(v.peak_sideslip_rad),
            GridMetric::MinSpeed => Some(v.min_speed_mps),
            GridMetric::SlowingOnset => v.slowing_onset_s,
            GridMetric::PathLength => Some(v.path_length_m),
        }
    }
}

/// Paired difference of one planner against the reference in one cell, for one vehicle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairedDifference {
    /// The cell.
    pub cell: GridCell,
    /// The planner compared.
    pub planner: String,
    /// The reference planner.
    pub reference: String,
    /// The metric.
    pub metric: GridMetric,
    /// Instances where both runs completed with the vehicle.
    #[serde(default)]
    pub compared: u64,
    /// Of those, instances where both values exist: the means, the mean difference and `lower`
    /// are over these (the `n` of the tables).
    pub pairs: u64,
    /// Of the compared instances, those where the planner's vehicle never slowed (slowing
    /// onset only: +∞, left out of the means; 0 for the other metrics).
    #[serde(default)]
    pub never: u64,
    /// The same for the reference planner.
    #[serde(default)]
    pub reference_never: u64,
    /// Mean of the planner's metric.
    pub mean: Option<f64>,
    /// Mean of the reference's metric.
    pub reference_mean: Option<f64>,
    /// Mean of (planner − reference).
    pub mean_difference: Option<f64>,
    /// Standard error of that mean (null with fewer than two pairs).
    pub standard_error: Option<f64>,
    /// Instances where the planner's value is lower.
    pub lower: u64,
    /// Collisions of the planner's runs in this cell.
    pub collisions: u64,
    /// Collisions of the reference planner's runs in this cell.
    pub reference_collisions: u64,
}

impl GridOutcome {
    /// Paired differences of every planner against the first, per cell, for `vehicle`.
    pub fn paired_differences(&self, vehicle: &str, metric: GridMetric) -> Vec<PairedDifference> {
        let Some(reference) = self.planners.first() else {
            return Vec::new();
        };
        fn of_vehicle<'a>(row: &'a GridRow, vehicle: &str) -> Option<&'a VehicleFigures> {
            row.vehicles.iter().find(|v| v.vehicle == vehicle)
        }
        let value = |row: &GridRow| of_vehicle(row, vehicle).and_then(|v| metric.of(v));
        let never = |v: &VehicleFigures| {
            metric == GridMetric::SlowingOnset && v.slowing_onset_never == Some(true)
        };
        let mut out = Vec::new();
        for cell in self.axes.cells() {
            let in_cell: Vec<&GridRow> = self.rows.iter().filter(|r| r.cell == cell).collect();
            for planner in &self.planners[1..] {
                let mut values = Vec::new();
                let mut diffs = Vec::new();
                let mut reference_values = Vec::new();
                let mut lower = 0;
                let (mut compared, mut never_count, mut reference_never) = (0, 0, 0);
                for row in in_cell.iter().filter(|r| &r.planner == planner) {
                    let other = in_cell
                        .iter()
                        .find(|r| &r.planner == reference && r.instance == row.instance);
                    if let (Some(a), Some(b)) = (
                        of_vehicle(row, vehicle),
                        other.and_then(|r| of_vehicle(r, vehicle)),
                    ) {
                        compared += 1;
                        never_count += u64::from(never(a));
                        reference_never += u64::from(never(b));
                    }
                    if let (Some(a), Some(b)) = (value(row), other.and_then(|r| value(r))) {
                        values.push(a);
                        reference_values.push(b);
                        diffs.push(a - b);
                        if a < b {
                            lower += 1;
                        }
                    }
                }
                let collisions_of = |name: &String| {
                    in_cell
                        .iter()
                        .filter(|r| &r.planner == name)
                        .map(|r| r.collisions.unwrap_or(0))
                        .sum()
                };
                out.push(PairedDifference {
                    cell,
                    planner: planner.clone(),
                    reference: reference.clone(),
                    metric,
                    compared,
                    pairs: diffs.len() as u64,
                    never: never_count,
                    reference_never,
                    mean: mean(&values),
                    reference_mean: mean(&reference_values),
                    mean_difference: mean(&diffs),
                    standard_error: standard_error(&diffs),
                    lower,
                    collisions: collisions_of(planner),
                    reference_collisions: collisions_of(reference),
                });
            }
        }
        out
    }

    /// The rows as CSV, one line per run and vehicle.
    pub fn csv(&self) -> String {
        let mut text = String::from(
            "predict_obstacles_in_path,substeps,path_time_gap_s,interaction_time_gap_s,planner,\
             instance,seed,collisions,error,vehicle,peak_yaw_rate_radps,\
             merge_zone_rms_yaw_rate_radps,outside_merge_zone_rms_yaw_rate_radps,\
             peak_sideslip_rad,min_speed_mps,slowing_onset_s,slowing_onset_never,path_length_m,\
             collided\n",
        );
        let opt = |v: Option<f64>| v.map(|x| format!("{x}")).unwrap_or_default();
        for row in &self.rows {
            let c = row.cell;
            let head = format!(
                "{},{},{},{},{},{},{},{},{}",
                c.predict_obstacles_in_path,
                c.substeps,
                c.path_time_gap_s,
                c.interaction_time_gap_s,
                row.planner,
                row.instance,
                row.seed
                    .map(crate::exact_seed::format_seed)
                    .unwrap_or_default(),
                row.collisions.map(|n| n.to_string()).unwrap_or_default(),
                row.error
                    .as_deref()
                    .map(|e| format!("\"{}\"", e.replace('"', "'")))
                    .unwrap_or_default(),
            );
            if row.vehicles.is_empty() {
                text.push_str(&format!("{head},,,,,,,,,,\n"));
            }
            for v in &row.vehicles {
                text.push_str(&format!(
                    "{head},{},{},{},{},{},{},{},{},{},{}\n",
                    v.vehicle,
                    v.peak_yaw_rate_radps,
                    opt(v.merge_zone_rms_yaw_rate_radps),
                    opt(v.outside_merge_zone_rms_yaw_rate_radps),
                    v.peak_sideslip_rad,
                    v.min_speed_mps,
                    opt(v.slowing_onset_s),
                    v.slowing_onset_never
                        .map(|b| b.to_string())
                        .unwrap_or_default(),
                    v.path_length_m,
                    v.collided
                ));
            }
        }
        text
    }
}
