//! mergesim: cooperative autonomous vehicles merging on a highway.
//!
//! The command line is [`cli`] (`merge_sim` is `cli::main`; a user's binary with its own planners
//! calls [`cli::main_with`]). The workspace's crates, re-exported for the `merge_sim` binary, the integration tests and
//! the benchmarks: [`planner`] (pure potential-field planning with interactive speed
//! optimisation), [`vehicles`] (Rapier vehicles and tracker), [`sim`] (the closed loop) and
//! [`scenarios`] (scenario files).
#![warn(missing_docs)]

pub mod animation;
pub mod build_info;
pub mod cli;
pub mod exact_seed;
pub mod experiment;
pub(crate) mod grid;
pub(crate) mod grid_plot;
pub mod inference;
pub(crate) mod limits;
pub mod output;
pub mod plots;
pub mod report;
pub(crate) mod run_caption;
pub mod scaling;
pub mod study;
pub mod summary;
pub mod sweep;

pub use {planner, scenarios, sim, vehicles};
