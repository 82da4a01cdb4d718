//! How large a recording will be, before writing it (`merge_sim run` warns above 500 MB).
//!
//! A linear model in what is logged, refitted on 2026-12-02 to the top-down 2D recordings of
//! `urgent_merge` (0 and 2 detail vehicles), `dense_merge` (0, 2 and all) and the default
//! `platoon_merge_50` (113.6 MB): each vehicle at each logged instant (box, planned path, five
//! time series) ≈ 950 B (≈ 620 B measured with 2 to 6 vehicles, ≈ 1.1 kB with 50), each
//! potential-field snapshot (an RGBA image, compressed) ≈ 1.7 kB, each received shared path at
//! each logged instant ≈ 120 B. It is within 20 % of the `dense_merge` and platoon recordings
//! and overestimates the small urgent merge (~40 %); Rerun's own framing and compression make it
//! an estimate, not a bound.

use crate::config::{SimConfig, VehicleSpec};

/// Bytes per vehicle and logged instant (box, planned path, time series).
pub const BYTES_PER_VEHICLE_INSTANT: f64 = 950.0;
/// Bytes per potential-field snapshot.
pub const BYTES_PER_FIELD: f64 = 1_700.0;
/// Bytes per received shared path and logged instant.
pub const BYTES_PER_RECEIVED_PATH: f64 = 120.0;

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
        .filter(|s| !matches!(s.driver, crate::Driver::Idm | crate::Driver::LaneKeeping))
        .count() as f64;
    let listeners = detailed.iter().filter(|s| s.connected).count() as f64;
    BYTES_PER_VEHICLE_INSTANT * vehicles * instants
        + BYTES_PER_FIELD * planners * snapshots
        + BYTES_PER_RECEIVED_PATH * listeners * (connected - 1.0).max(0.0) * instants
}
