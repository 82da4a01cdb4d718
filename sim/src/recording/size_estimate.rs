//! How large a recording will be, before writing it (`merge_sim run` warns above 500 MB).
//!
//! A linear model in what is logged, refitted on 2026-12-02 to the recordings written since they
//! are byte-identical (chunks of up to 256 rows or 256 KiB per entity, `rrd_writer`):
//! `urgent_merge` (25 s; 0 and 2 detail vehicles: 570 737 and 872 694 B) and `dense_merge`
//! (10 s; 0, 2 and all 6: 695 239, 1 033 381 and 1 636 872 B) (`merge_sim run --scenario S
//! [--duration 10] --record-detail N --rrd F`): each vehicle at each logged instant (box, planned
//! path, five time series) ≈ 570 B, each potential-field snapshot (an RGBA image, compressed)
//! ≈ 1.65 kB, each received shared path at each logged instant ≈ 134 B. It is within 5 % of
//! those recordings; it overestimates the default 50-vehicle platoon about 2.3 times (35.1 MB
//! written: its 50 boxes share one row, and a vehicle receives only the paths in V2V range), so
//! it errs on the side of the warning. Compression makes it an estimate, not a bound.

use crate::config::{SimConfig, VehicleSpec};

/// Bytes per vehicle and logged instant (box, planned path, time series).
pub const BYTES_PER_VEHICLE_INSTANT: f64 = 570.0;
/// Bytes per potential-field snapshot.
pub const BYTES_PER_FIELD: f64 = 1_650.0;
/// Bytes per received shared path and logged instant.
pub const BYTES_PER_RECEIVED_PATH: f64 = 134.0;

/// The estimated size (bytes) of the recording of a run of `specs` with `config`, fields and
/// received paths for the first `detail_vehicles` vehicles (`None`: all).
pub fn estimated_bytes(
    config: &SimConfig,
    specs: &[VehicleSpec],
    detail_vehicles: Option<usize>,
) -> f64 {
    let vehicles = specs.len() as f64;
    let instants = (config.duration_s / config.log_period_s).floor() + 1.0;
    let snapshots = (config.duration_s / config.field_log_period_s).floor() + 1.0;
    let connected = specs.iter().filter(|s| s.connected).count() as f64;
    let detail = detail_vehicles.unwrap_or(specs.len()).min(specs.len());
    let detailed = &specs[..detail];
    let planners = detailed
        .iter()
        .filter(|s| {
            !matches!(
                s.driver,
                crate::config::Driver::Idm
                    | crate::config::Driver::IdmMobil
                    | crate::config::Driver::LaneKeeping
            )
        })
        .count() as f64;
    let listeners = detailed.iter().filter(|s| s.connected).count() as f64;
    BYTES_PER_VEHICLE_INSTANT * vehicles * instants
        + BYTES_PER_FIELD * planners * snapshots
        + BYTES_PER_RECEIVED_PATH * listeners * (connected - 1.0).max(0.0) * instants
}
