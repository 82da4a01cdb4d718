//! mergesim: cooperative autonomous vehicles merging on a highway.
//!
//! The command line is [`cli`] (`merge_sim` is `cli::main`; a user's binary with its own planners
//! calls [`cli::main_with`]). The workspace's crates, re-exported for the `merge_sim` binary, the integration tests and
//! the benchmarks: [`planner`] (pure potential-field planning with interactive speed
//! optimisation), [`vehicles`] (Rapier vehicles and tracker), [`sim`] (the closed loop) and
//! [`scenarios`] (scenario files), and the plain data they all speak, [`mergesim_types`] (vehicle
//! state and shape, paths, roads, the `Behaviour` interface): `mergesim::mergesim_types::X`.
//!
//! # Public API
//! - The command line: [`cli::main`] and [`cli::main_with`] (a registry with the user's own
//!   planners).
//! - One run: [`experiment::run_instance`] and [`experiment::run_quietly`] (with
//!   [`experiment::InstanceOptions`]) give an [`experiment::Finished`] run; its JSON summary is
//!   [`summary`], its text report [`report`], its figures [`plots`] and its animation
//!   [`animation`].
//! - Many runs: Monte-Carlo sweeps ([`sweep`], [`sweep::SweepPlan`], [`sweep::instance_seed`]),
//!   pre-registered studies ([`study`]), the scaling curve ([`scaling`]) and the paired tests
//!   they report ([`inference`]).
//! - Files and provenance: [`output`] (files written whole or not at all), [`exact_seed`]
//!   (seeds kept exact in JSON and CSV) and [`build_info`].
#![warn(missing_docs)]

pub mod animation;
pub mod build_info;
pub mod cli;
pub mod error_text;
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

pub use {mergesim_types, planner, scenarios, sim, vehicles};
