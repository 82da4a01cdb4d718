//! Merge sequencing for connected vehicles (`pf-iso-seq`), after Rios-Torres & Malikopoulos,
//! "Automated and Cooperative Vehicle Merging at Highway On-Ramps", IEEE T-ITS 18(4), 2017:
//! a control zone upstream of the merging zone, a first-in-first-out crossing order agreed
//! from what every car hears over V2V, and energy-optimal speed profiles into the assigned
//! crossing times, with the speed, acceleration and rear-end safety constraints enforced on
//! top (the unconstrained solution alone does not guarantee them).
//!
//! - [`geometry`]: where the merge is, from the road's lanes;
//! - [`queue`]: the FIFO queue, the crossing times, and what late, lost or duplicated messages do;
//! - [`profile`]: the closed-form energy-optimal profile and the constrained one;
//! - [`planner`]: the `pf-iso-seq` behaviour (PF-ISO's path, the sequenced speeds);
//! - [`params`]: its parameters.

pub mod geometry;
pub mod params;
pub mod planner;
pub mod profile;
pub mod queue;

pub use params::{SEQUENCING_BOUNDS, SequencingParams};
pub use planner::{SequencedPlanner, SequencingState};

/// The registry name of the sequenced planner.
pub const SEQUENCED_PLANNER_NAME: &str = "pf-iso-seq";
