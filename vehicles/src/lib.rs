//! Vehicles of mergesim: a rapier rigid-body car on four ray-cast wheels with a slip-based
//! Magic-Formula tyre model, the path tracker that drives it, and the standard handling
//! maneuvers used to validate it against textbook references.
//!
//! World frame: X along the road, Y left, Z up, gravity (0, 0, −9.81). The API speaks `f64`
//! SI units; rapier works in `f32` inside.
//!
//! Order of one physics tick (for the simulator):
//! ```text
//! controls = tracker.update(&vehicle.kinematics(&world), &path, dt);
//! vehicle.set_controls(controls);
//! vehicle.advance(&mut world, mu);        // every vehicle, in id order (VehicleModel)
//! world.step();
//! ```
//!
//! # Public API
//! - The physics scene: [`PhysicsWorld`] (gravity [`GRAVITY_MPS2`]) with the road's walls,
//!   [`road_collider::RoadColliders`] from [`road_collider::RoadColliderParams`]
//!   ([`road_collider`], [`collision_groups`]).
//! - A car: [`Vehicle`] from [`VehicleParams`] and [`TireParams`] (the presets
//!   [`PRESET_NAMES`]), driven by [`Controls`] ([`WHEEL_NAMES`]), read back as [`Kinematics`],
//!   [`BodyBox`] and [`WheelTelemetry`]; a body moved kinematically, [`KinematicBox`].
//! - The path tracker: [`tracker::Tracker`] from [`tracker::TrackerParams`], with its
//!   [`tracker::SpeedController`].
//! - Validation: [`maneuver::run_maneuver`] of a [`maneuver::ManeuverConfig`]
//!   ([`maneuver::ManeuverKind`]) gives a [`maneuver::ManeuverReport`], compared with the linear
//!   single-track model [`LinearSingleTrack`] ([`linear_yaw_rate_radps`]).
//! - Errors: [`VehicleError`].
//! - CommonRoad's vehicle models ks, st and std as pure functions (no rapier), with their
//!   parameter sets and an RK4 step: [`commonroad_models`].
//! - The vehicle-model seam [`VehicleModel`], implemented by [`Vehicle`] (`rapier`) and by
//!   [`CommonRoadVehicle`] ([`CommonRoadModel`] `ks`, `st`, `std`, integrated with
//!   [`CommonRoadIntegration`]'s steps; its state [`CommonRoadModelState`]).
//!
//! Each item has one path: a public module holding more than what the crate root names is
//! the path of its items (`vehicles::tracker::Tracker`).
#![warn(missing_docs)]

pub mod collision_groups;
pub mod commonroad_models;
pub(crate) mod commonroad_vehicle;
pub(crate) mod controls;
pub(crate) mod error;
pub(crate) mod kinematic_body;
pub(crate) mod kinematics;
pub mod maneuver;
pub(crate) mod params;
pub(crate) mod physics_world;
pub(crate) mod presets;
pub mod road_collider;
pub(crate) mod single_track;
pub(crate) mod tire;
pub mod tracker;
pub(crate) mod vehicle;
pub(crate) mod vehicle_model;
pub(crate) mod wheel;

pub use commonroad_vehicle::{
    CommonRoadIntegration, CommonRoadModel, CommonRoadModelState, CommonRoadVehicle,
};
pub use controls::{Controls, WHEEL_NAMES};
pub use error::VehicleError;
pub use kinematic_body::KinematicBox;
pub use kinematics::Kinematics;
pub use params::{TireParams, VehicleParams};
pub use physics_world::{GRAVITY_MPS2, PhysicsWorld};
pub use presets::PRESET_NAMES;
pub use single_track::{LinearSingleTrack, linear_yaw_rate_radps};
pub use vehicle::{BodyBox, Vehicle};
pub use vehicle_model::VehicleModel;
pub use wheel::WheelTelemetry;
