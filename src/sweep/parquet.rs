//! The rows of a sweep as one Parquet file (`merge_sim sweep --parquet`), flat for pandas:
//! one row per (instance, planner), in (instance, planner) order, with the columns
//!
//! - `sweep_seed` (uint64), `instance` (uint64): `merge_sim run --sweep-seed K --instance I`
//!   replays the row; `planner` (string), `seed` (uint64: exact, unlike JSON numbers; the
//!   JSON files write it as a `0x` hex string), `status` (`completed`, `diverged`, `panicked`),
//!   `error` (string, null unless failed);
//! - every run-level figure of the JSONL rows (`collisions`, `near_miss`, `min_ttc_s`,
//!   `min_ttc_never`, ...), null for a failed run;
//! - on a CommonRoad road only (`--scenario file.xml`, or `[sim.road] commonroad`):
//!   `recorded_traffic` (string: `none`, `replay`, `reactive`), `collisions_caused_by_replay`
//!   (uint64), `min_gap_to_recorded_m`, `min_ttc_to_recorded_s` (float64), `goal_reached`
//!   (boolean), `goal_time_s` (float64), null for a failed run;
//! - `drawn.<name>` (float64): the values the scenario drew (`drawn.sim.mu`,
//!   `drawn.vehicles.obstacle.speed_mps`, ...);
//! - `<vehicle>.<figure>` per vehicle (`ego.min_speed_mps`, `obstacle.slowing_onset_s`,
//!   `obstacle.slowing_onset_never`, ...), null for a failed run.
//!
//! "Never" is represented as in the JSONL: the figure null (NaN in pandas) and its boolean
//! `..._never` column true, so a null with `..._never` false or null is "not measured".
//!
//! The sweep's identity (scenario, fingerprint, parameter set, planners, seed, runs) is in the
//! file's key-value metadata under `mergesim.sweep` (JSON). No wall times: the file of a sweep
//! is the same bytes whatever the thread count.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use arrow_array::{ArrayRef, BooleanArray, Float64Array, RecordBatch, StringArray, UInt64Array};
use arrow_schema::{DataType, Field, Schema};
use parquet::arrow::ArrowWriter;
use parquet::basic::Compression;
use parquet::file::metadata::KeyValue;
use parquet::file::properties::WriterProperties;
use thiserror::Error;

use super::{RunMetrics, RunRow, RunStatus, SweepReport, VehicleRow};

/// Key of the sweep's identity in the file's metadata.
pub const METADATA_KEY: &str = "mergesim.sweep";

/// Why the Parquet file could not be made or written.
#[derive(Debug, Error)]
pub enum ParquetOutputError {
    /// Two columns would have the same name (e.g. a vehicle named like a figure).
    #[error("two Parquet columns would be named {0:?}: rename a vehicle")]
    DuplicateColumn(String),
    /// Arrow refused the columns.
    #[error("cannot build the Parquet columns: {0}")]
    Arrow(#[from] arrow_schema::ArrowError),
    /// The Parquet encoder failed.
    #[error("cannot encode Parquet: {0}")]
    Parquet(#[from] parquet::errors::ParquetError),
    /// Writing the file failed.
    #[error("cannot write {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The error.
        source: std::io::Error,
    },
}

/// One cell of a typed column.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Cell {
    U64(Option<u64>),
    F64(Option<f64>),
    Bool(Option<bool>),
}

/// A column being filled.
enum Column {
    U64(Vec<Option<u64>>),
    F64(Vec<Option<f64>>),
    Bool(Vec<Option<bool>>),
    Text(Vec<Option<String>>),
}

impl Column {
    fn of(cell: Cell) -> Self {
        match cell {
            Cell::U64(_) => Column::U64(Vec::new()),
            Cell::F64(_) => Column::F64(Vec::new()),
            Cell::Bool(_) => Column::Bool(Vec::new()),
        }
    }

    fn push(&mut self, cell: Cell) {
        match (self, cell) {
            (Column::U64(v), Cell::U64(x)) => v.push(x),
            (Column::F64(v), Cell::F64(x)) => v.push(x),
            (Column::Bool(v), Cell::Bool(x)) => v.push(x),
            // Each column is made from one accessor, so its cells have one type.
            (Column::U64(v), _) => v.push(None),
            (Column::F64(v), _) => v.push(None),
            (Column::Bool(v), _) => v.push(None),
            (Column::Text(v), _) => v.push(None),
        }
    }

    fn into_array(self) -> (DataType, ArrayRef) {
        match self {
            Column::U64(v) => (DataType::UInt64, Arc::new(UInt64Array::from(v))),
            Column::F64(v) => (DataType::Float64, Arc::new(Float64Array::from(v))),
            Column::Bool(v) => (DataType::Boolean, Arc::new(BooleanArray::from(v))),
            Column::Text(v) => (DataType::Utf8, Arc::new(StringArray::from(v))),
        }
    }
}

/// The run-level figures of a row (nulls of the same types for a failed run).
fn run_cells(m: Option<&RunMetrics>) -> [(&'static str, Cell); 20] {
    let u = |f: fn(&RunMetrics) -> u64| Cell::U64(m.map(f));
    let f = |f: fn(&RunMetrics) -> f64| Cell::F64(m.map(f));
    [
        ("collisions", u(|m| m.collisions)),
        ("near_miss", Cell::Bool(m.map(|m| m.near_miss))),
        ("min_ttc_s", Cell::F64(m.and_then(|m| m.min_ttc_s))),
        (
            "min_ttc_never",
            Cell::Bool(m.map(RunMetrics::min_ttc_never)),
        ),
        ("min_gap_m", Cell::F64(m.and_then(|m| m.min_gap_m))),
        (
            "min_gap_never",
            Cell::Bool(m.map(RunMetrics::min_gap_never)),
        ),
        ("tet_s", f(|m| m.tet_s)),
        ("peak_yaw_rate_radps", f(|m| m.peak_yaw_rate_radps)),
        ("peak_sideslip_rad", f(|m| m.peak_sideslip_rad)),
        ("peak_yaw_rad", f(|m| m.peak_yaw_rad)),
        ("min_speed_mps", f(|m| m.min_speed_mps)),
        ("yaw_rate_sign_changes", u(|m| m.yaw_rate_sign_changes)),
        ("fallbacks", u(|m| m.fallbacks)),
        ("degraded_plans", u(|m| m.degraded_plans)),
        ("plans", u(|m| m.plans)),
        ("shield_interventions", u(|m| m.shield_interventions)),
        (
            "throughput_vph",
            Cell::F64(m.and_then(|m| m.throughput_vph)),
        ),
        ("merging_vehicles", u(|m| m.merging_vehicles)),
        ("merged_before_lane_end", u(|m| m.merged_before_lane_end)),
        ("mean_delay_s", Cell::F64(m.and_then(|m| m.mean_delay_s))),
    ]
}

/// The figures of a run on a CommonRoad road, after its `recorded_traffic` text column (nulls
/// of the same types for a failed run).
fn commonroad_cells(m: Option<&RunMetrics>) -> [(&'static str, Cell); 5] {
    let c = m.and_then(|m| m.commonroad.as_ref());
    [
        (
            "collisions_caused_by_replay",
            Cell::U64(c.map(|c| c.collisions_caused_by_replay)),
        ),
        (
            "min_gap_to_recorded_m",
            Cell::F64(c.and_then(|c| c.min_gap_to_recorded_m)),
        ),
        (
            "min_ttc_to_recorded_s",
            Cell::F64(c.and_then(|c| c.min_ttc_to_recorded_s)),
        ),
        ("goal_reached", Cell::Bool(c.and_then(|c| c.goal_reached))),
        ("goal_time_s", Cell::F64(c.and_then(|c| c.goal_time_s))),
    ]
}

/// A vehicle's figures (nulls of the same types when the row has no such vehicle).
fn vehicle_cells(v: Option<&VehicleRow>) -> [(&'static str, Cell); 28] {
    let f = |f: fn(&VehicleRow) -> f64| Cell::F64(v.map(f));
    let o = |f: fn(&VehicleRow) -> Option<f64>| Cell::F64(v.and_then(f));
    [
        ("collided", Cell::Bool(v.map(|v| v.collided))),
        ("max_abs_sideslip_rad", f(|v| v.max_abs_sideslip_rad)),
        ("max_abs_yaw_rad", f(|v| v.max_abs_yaw_rad)),
        ("max_abs_yaw_rate_radps", f(|v| v.max_abs_yaw_rate_radps)),
        ("min_speed_mps", f(|v| v.min_speed_mps)),
        ("t_min_speed_s", f(|v| v.t_min_speed_s)),
        ("max_speed_mps", f(|v| v.max_speed_mps)),
        ("final_speed_mps", f(|v| v.final_speed_mps)),
        ("path_length_m", f(|v| v.path_length_m)),
        (
            "yaw_rate_sign_changes",
            Cell::U64(v.map(|v| v.yaw_rate_sign_changes)),
        ),
        (
            "integral_abs_yaw_rate_rad",
            f(|v| v.integral_abs_yaw_rate_rad),
        ),
        (
            "peak_abs_accel_long_mps2",
            f(|v| v.peak_abs_accel_long_mps2),
        ),
        ("rms_accel_long_mps2", f(|v| v.rms_accel_long_mps2)),
        ("peak_abs_accel_lat_mps2", f(|v| v.peak_abs_accel_lat_mps2)),
        ("rms_accel_lat_mps2", f(|v| v.rms_accel_lat_mps2)),
        ("peak_abs_jerk_long_mps3", f(|v| v.peak_abs_jerk_long_mps3)),
        ("peak_abs_jerk_lat_mps3", f(|v| v.peak_abs_jerk_lat_mps3)),
        ("rms_jerk_long_mps3", f(|v| v.rms_jerk_long_mps3)),
        ("rms_jerk_lat_mps3", f(|v| v.rms_jerk_lat_mps3)),
        ("slowing_onset_s", o(|v| v.slowing_onset_s)),
        (
            "slowing_onset_never",
            Cell::Bool(v.and_then(VehicleRow::slowing_onset_never)),
        ),
        (
            "merge_zone_rms_yaw_rate_radps",
            o(|v| v.merge_zone_rms_yaw_rate_radps),
        ),
        (
            "outside_merge_zone_rms_yaw_rate_radps",
            o(|v| v.outside_merge_zone_rms_yaw_rate_radps),
        ),
        ("max_abs_lane_offset_m", o(|v| v.max_abs_lane_offset_m)),
        ("divider_crossing_t_s", o(|v| v.divider_crossing_t_s)),
        ("divider_crossing_x_m", o(|v| v.divider_crossing_x_m)),
        (
            "divider_crossing_never",
            Cell::Bool(v.and_then(VehicleRow::divider_crossing_never)),
        ),
        (
            "divider_crossings",
            Cell::U64(v.and_then(|v| v.divider_crossings)),
        ),
    ]
}

fn status_name(status: RunStatus) -> &'static str {
    match status {
        RunStatus::Completed => "completed",
        RunStatus::Diverged => "diverged",
        RunStatus::Panicked => "panicked",
    }
}

/// The rows of the sweep with seed `sweep_seed` as one Arrow record batch (the columns of the
/// module doc).
pub fn record_batch(rows: &[&RunRow], sweep_seed: u64) -> Result<RecordBatch, ParquetOutputError> {
    let mut drawn_names: Vec<&str> = rows
        .iter()
        .flat_map(|r| r.drawn.keys().map(String::as_str))
        .collect();
    drawn_names.sort_unstable();
    drawn_names.dedup();
    let mut vehicles: Vec<&str> = Vec::new();
    for row in rows {
        for v in &row.vehicles {
            if !vehicles.contains(&v.name.as_str()) {
                vehicles.push(&v.name);
            }
        }
    }
    let mut columns: Vec<(String, bool, Column)> = vec![
        ("sweep_seed".into(), false, Column::U64(Vec::new())),
        ("instance".into(), false, Column::U64(Vec::new())),
        ("planner".into(), false, Column::Text(Vec::new())),
        ("seed".into(), false, Column::U64(Vec::new())),
        ("status".into(), false, Column::Text(Vec::new())),
        ("error".into(), true, Column::Text(Vec::new())),
    ];
    for (name, cell) in run_cells(None) {
        columns.push((name.into(), true, Column::of(cell)));
    }
    let on_commonroad = rows
        .iter()
        .any(|r| r.metrics.as_ref().is_some_and(|m| m.commonroad.is_some()));
    if on_commonroad {
        columns.push(("recorded_traffic".into(), true, Column::Text(Vec::new())));
        for (name, cell) in commonroad_cells(None) {
            columns.push((name.into(), true, Column::of(cell)));
        }
    }
    for name in &drawn_names {
        columns.push((format!("drawn.{name}"), true, Column::F64(Vec::new())));
    }
    for vehicle in &vehicles {
        for (name, cell) in &vehicle_cells(None) {
            columns.push((format!("{vehicle}.{name}"), true, Column::of(*cell)));
        }
    }
    let mut seen = std::collections::BTreeSet::new();
    for (name, _, _) in &columns {
        if !seen.insert(name.as_str()) {
            return Err(ParquetOutputError::DuplicateColumn(name.clone()));
        }
    }
    for row in rows {
        let mut cells: Vec<Cell> = vec![
            Cell::U64(Some(sweep_seed)),
            Cell::U64(Some(row.instance)),
            Cell::Bool(None),
            Cell::U64(Some(row.seed)),
            Cell::Bool(None),
            Cell::Bool(None),
        ];
        cells.extend(run_cells(row.metrics.as_ref()).map(|(_, c)| c));
        if on_commonroad {
            cells.push(Cell::Bool(None));
            cells.extend(commonroad_cells(row.metrics.as_ref()).map(|(_, c)| c));
        }
        cells.extend(
            drawn_names
                .iter()
                .map(|name| Cell::F64(row.drawn.get(*name).copied())),
        );
        for vehicle in &vehicles {
            let v = row.vehicles.iter().find(|v| v.name == *vehicle);
            cells.extend(vehicle_cells(v).map(|(_, c)| c));
        }
        let texts = [
            Some(row.planner.clone()),
            Some(status_name(row.status).to_string()),
            row.error.clone(),
            row.metrics
                .as_ref()
                .and_then(|m| m.commonroad.as_ref())
                .map(|c| c.recorded_traffic.clone()),
        ];
        let mut texts = texts.into_iter();
        for ((_, _, column), cell) in columns.iter_mut().zip(cells) {
            match column {
                Column::Text(v) => v.push(texts.next().flatten()),
                other => other.push(cell),
            }
        }
    }
    let mut fields = Vec::with_capacity(columns.len());
    let mut arrays = Vec::with_capacity(columns.len());
    for (name, nullable, column) in columns {
        let (data_type, array) = column.into_array();
        fields.push(Field::new(name, data_type, nullable));
        arrays.push(array);
    }
    Ok(RecordBatch::try_new(Arc::new(Schema::new(fields)), arrays)?)
}

/// The Parquet bytes of `rows` of the sweep with seed `sweep_seed` (Snappy-compressed), with
/// `metadata` on the Arrow schema (which pyarrow reads back as `table.schema.metadata`) and in
/// the file's key-value metadata.
pub fn parquet_bytes(
    rows: &[&RunRow],
    sweep_seed: u64,
    metadata: &BTreeMap<String, String>,
) -> Result<Vec<u8>, ParquetOutputError> {
    let batch = record_batch(rows, sweep_seed)?;
    let schema = Arc::new(
        batch
            .schema()
            .as_ref()
            .clone()
            .with_metadata(metadata.clone().into_iter().collect()),
    );
    let batch = batch.with_schema(schema.clone())?;
    let properties = WriterProperties::builder()
        .set_compression(Compression::SNAPPY)
        .set_key_value_metadata(Some(
            metadata
                .iter()
                .map(|(k, v)| KeyValue::new(k.clone(), v.clone()))
                .collect(),
        ))
        .build();
    let mut bytes = Vec::new();
    let mut writer = ArrowWriter::try_new(&mut bytes, schema, Some(properties))?;
    writer.write(&batch)?;
    writer.close()?;
    Ok(bytes)
}

/// The identity of a report as the metadata value of [`METADATA_KEY`].
fn identity_metadata(report: &SweepReport) -> BTreeMap<String, String> {
    let first = report.summaries().first().map(|s| {
        serde_json::json!({
            "scenario": s.scenario,
            "scenario_fingerprint": s.scenario_fingerprint,
            "params": s.params,
            "planners": report.planners(),
            "sweep_seed": crate::exact_seed::format_seed(s.seed),
            "total_runs": s.total_runs,
            "shard": s.shard.to_string(),
        })
    });
    first
        .map(|value| BTreeMap::from([(METADATA_KEY.to_string(), value.to_string())]))
        .unwrap_or_default()
}

/// Writes the rows of `report` to `path` as Parquet: to a temporary file in the same folder,
/// then renamed, so a failure never leaves half a file.
pub fn write_parquet(path: &Path, report: &SweepReport) -> Result<(), ParquetOutputError> {
    let sweep_seed = report.summaries().first().map_or(0, |s| s.seed);
    let bytes = parquet_bytes(&report.rows(), sweep_seed, &identity_metadata(report))?;
    crate::output::write_atomically(path, &bytes).map_err(|source| ParquetOutputError::Io {
        path: path.display().to_string(),
        source,
    })
}
