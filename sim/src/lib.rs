//! sim
pub mod error;
pub mod rng;
pub mod v2v;

pub use error::SimError;
