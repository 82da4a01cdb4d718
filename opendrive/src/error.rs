//! Why an OpenDRIVE file gives no road.

use std::path::PathBuf;

use mergesim_types::lanes::LaneError;
use thiserror::Error;

/// Why an OpenDRIVE file could not be turned into a road of lanes. Every variant names the file.
#[derive(Debug, Error)]
pub enum OpenDriveError {
    /// The file could not be read.
    #[error("{path}: cannot read the OpenDRIVE file: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why (in the message, so not also a source).
        error: std::io::Error,
    },
    /// The importer refused the document (not well-formed XML, or no usable lanes); its message
    /// gives the position where it has one.
    #[error("{path}: {message}")]
    Import {
        /// The file.
        path: PathBuf,
        /// What the importer said.
        message: String,
    },
    /// The importer met a fault in the file (a value it could not read, a geometry, lane or
    /// link it dropped): the road would differ from the file.
    #[error("{path}: {message}{}", if *more > 0 { format!(" (and {more} more faults)") } else { String::new() })]
    Fault {
        /// The file.
        path: PathBuf,
        /// The first fault, as the importer words it (it names the road and lane).
        message: String,
        /// How many more faults.
        more: usize,
    },
    /// The document has no drivable lane.
    #[error("{path}: no drivable lane (driving, entry, exit, ramps, …) in the file")]
    NoDrivableLane {
        /// The file.
        path: PathBuf,
    },
    /// More drivable lanes than [`crate::road::MAX_LANES`].
    #[error("{path}: {count} drivable lanes, more than the limit {limit}")]
    TooManyLanes {
        /// The file.
        path: PathBuf,
        /// How many.
        count: usize,
        /// The limit.
        limit: usize,
    },
    /// A lane lies farther from the origin than [`crate::road::MAX_COORDINATE_M`]: the importer
    /// computes in `f32`, too coarse there.
    #[error(
        "{path}: {origin} reaches {coordinate_m:.0} m from the origin, beyond {limit_m:.0} m: the \
         OpenDRIVE importer computes in 32-bit floats (resolution {resolution_m:.3} m there); \
         move the map nearer to the origin (e.g. a geo-referenced map in its local frame)"
    )]
    TooFarFromOrigin {
        /// The file.
        path: PathBuf,
        /// The OpenDRIVE road and lane.
        origin: String,
        /// The largest |x| or |y| of its centreline (m).
        coordinate_m: f64,
        /// The limit (m).
        limit_m: f64,
        /// The `f32` spacing at that coordinate (m).
        resolution_m: f64,
    },
    /// The lanes do not make a consistent road (the message names the mergesim lane; the
    /// OpenDRIVE road and lane are named beside it).
    #[error("{path}: {origin}: {error}")]
    Road {
        /// The file.
        path: PathBuf,
        /// The OpenDRIVE road and lane the refused lane came from, if known.
        origin: String,
        /// What the lane road refused (in the message, so not also a source).
        error: LaneError,
    },
}
