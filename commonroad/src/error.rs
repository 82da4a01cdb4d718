//! The typed refusal of a CommonRoad file: every error names the file, the line (from the XML
//! parser's node positions, where there is one) and the element's id.

use std::path::PathBuf;

use mergesim_types::lanes::LaneError;
use thiserror::Error;

/// A CommonRoad file that cannot be read.
#[derive(Debug, Error)]
#[error("{}{}{}: {kind}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default(), element.as_ref().map(|e| format!(": {e}")).unwrap_or_default())]
pub struct CommonRoadError {
    /// The file.
    pub path: PathBuf,
    /// The line (1-based), where the parser or the offending element gives one.
    pub line: Option<u32>,
    /// The element at fault with its id, e.g. `lanelet 12` or `dynamicObstacle 373`.
    pub element: Option<String>,
    /// What is wrong.
    pub kind: ErrorKind,
}

/// What is wrong with a CommonRoad file.
#[derive(Debug, Error)]
pub enum ErrorKind {
    /// The file cannot be read.
    #[error("cannot read the file: {0}")]
    Io(#[from] std::io::Error),
    /// The file is larger than [`MAX_FILE_BYTES`](crate::MAX_FILE_BYTES).
    #[error("the file has {bytes} bytes (at most {max} accepted)")]
    TooLarge {
        /// The file's size.
        bytes: u64,
        /// The limit.
        max: u64,
    },
    /// Not well-formed XML (the parser's message).
    #[error("malformed XML: {0}")]
    Xml(String),
    /// The root element is not `commonRoad`.
    #[error("the root element is <{found}>, not <commonRoad>")]
    NotCommonRoad {
        /// The root element's name.
        found: String,
    },
    /// A `commonRoadVersion` other than the supported ones.
    #[error("commonRoadVersion \"{found}\" is not supported (supported: 2020a, 2018b)")]
    UnsupportedVersion {
        /// The version found.
        found: String,
    },
    /// A required element or attribute is missing.
    #[error("missing {what}")]
    Missing {
        /// The element or attribute.
        what: String,
    },
    /// A number that does not parse or is not finite.
    #[error("{field}: \"{text}\" is not a finite number")]
    BadNumber {
        /// The element holding it.
        field: String,
        /// Its text.
        text: String,
    },
    /// A value outside its allowed range.
    #[error("{field}: {reason}")]
    BadValue {
        /// The element or attribute.
        field: String,
        /// Why.
        reason: String,
    },
    /// Two elements of one kind with the same id.
    #[error("id {id} is used twice (first on line {first_line})")]
    DuplicateId {
        /// The id.
        id: i64,
        /// Where it was first used.
        first_line: u32,
    },
    /// A reference to a lanelet the network does not have.
    #[error("{field} refers to lanelet {target}, which does not exist")]
    UnknownLanelet {
        /// The referring element (`successor`, `adjacentLeft`, ...).
        field: String,
        /// The unknown id.
        target: i64,
    },
    /// Left and right bounds with different numbers of points.
    #[error("leftBound has {left} points, rightBound {right} (they must be equal)")]
    BoundPointCounts {
        /// Points of the left bound.
        left: usize,
        /// Points of the right bound.
        right: usize,
    },
    /// More elements of one kind than the documented limit.
    #[error("{count} {what} (at most {max})")]
    TooMany {
        /// What was counted (`lanelets`, `obstacles`, `states of one trajectory`).
        what: &'static str,
        /// How many the file has.
        count: usize,
        /// The limit.
        max: usize,
    },
    /// The lanelet network does not make a road of lanes.
    #[error("the lanelet network is not a consistent road of lanes: {0}")]
    Road(#[from] LaneError),
}
