//! Pure planning library of mergesim: road geometry, potential fields (paper Eqs. 1–7),
//! constrained cubic fit (Eqs. 8–9) and interactive speed optimisation (Eq. 10).
//!
//! No physics engine, no logging backend: plain state in, plan out, so it can run on a car.

pub mod error;
pub mod road;
pub mod types;

pub use error::PlannerError;
pub use road::{Lane, MergeRoad};
pub use types::*;
