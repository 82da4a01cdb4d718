//! The vehicle-model seam: what the simulator needs of a vehicle, whatever moves it.
//!
//! The simulator drives every vehicle through [`VehicleModel`] in the order of the crate doc:
//! read [`VehicleModel::kinematics`], give the tracker's [`Controls`] to
//! [`VehicleModel::set_controls`], let [`VehicleModel::advance`] prepare the coming physics
//! step, step the [`PhysicsWorld`]. Two families implement it here:
//! - [`Vehicle`] (`rapier`): a Rapier rigid body on four ray-cast wheels with Magic-Formula
//!   tyres; `advance` applies the tyre and suspension forces, the physics step moves it.
//! - [`crate::CommonRoadVehicle`] (`ks`, `st`, `std`): CommonRoad's kinematic single-track,
//!   single-track and single-track drift models integrated by RK4; `advance` integrates the
//!   model over the step and hands the pose to a Rapier kinematic box, so contacts with Rapier
//!   vehicles and the recording see the same body.
//!
//! A model of one's own implements the trait and is registered under a name in the
//! simulator's registry (`sim::registry::BehaviourRegistry::register_vehicle_model`); the
//! scenario's `vehicle_model` and the CLI's `--vehicle-model` then choose it by that name.

use crate::controls::Controls;
use crate::kinematics::Kinematics;
use crate::params::VehicleParams;
use crate::physics_world::PhysicsWorld;
use crate::vehicle::{BodyBox, Vehicle};

/// A vehicle as the simulator drives it (module doc).
pub trait VehicleModel: Send + Sync {
    /// The model's registered name (`rapier`, `ks`, `st`, `std`, or a user's).
    fn model_name(&self) -> &str;

    /// The car's parameters (footprint, mass, limits).
    fn params(&self) -> &VehicleParams;

    /// The chassis box in the body frame: what the safety checks, the recording and contacts
    /// see.
    fn body_box(&self) -> BodyBox;

    /// The largest braking deceleration this car can reach on a road of friction `mu` (m/s²);
    /// by default its parameters' [`VehicleParams::braking_limit_mps2`]. The simulator gives
    /// the planners a margin below it (`mergesim_types::planning_brake_decel_mps2`).
    fn braking_limit_mps2(&self, mu: f64) -> f64 {
        self.params().braking_limit_mps2(mu)
    }

    /// The planner's footprint of this car, braking at `max_brake_decel_mps2` (m/s²).
    fn shape(&self, max_brake_decel_mps2: f64) -> mergesim_types::VehicleShape {
        let p = self.params();
        mergesim_types::VehicleShape {
            length_m: p.length_m,
            width_m: p.width_m,
            wheelbase_m: p.wheelbase_m(),
            max_brake_decel_mps2,
        }
    }

    /// Pose, velocities and accelerations of the centre of gravity now (after the last
    /// physics step), in road coordinates.
    fn kinematics(&self, world: &PhysicsWorld) -> Kinematics;

    /// The tracker's inputs for the coming step (steering angle, wheel torques); each model
    /// clamps them to its own limits.
    fn set_controls(&mut self, controls: Controls);

    /// Prepares the coming physics step at road friction `mu`: forces for a rigid body, the
    /// next pose for a model integrated outside Rapier. Called once per vehicle before each
    /// [`PhysicsWorld::step`].
    fn advance(&mut self, world: &mut PhysicsWorld, mu: f64);

    /// Whether the car moves only through [`PhysicsWorld::step`] (true: a rigid body) or moves
    /// itself in [`VehicleModel::advance`] (false). When no car of a run needs the step, the
    /// simulator skips Rapier's step: kinematic bodies have no dynamics of their own, and the
    /// safety checks read the cars' own poses.
    fn needs_physics_step(&self) -> bool {
        true
    }
}

/// The Rapier rigid-body car (`rapier`): `advance` is [`Vehicle::apply_forces`].
impl VehicleModel for Vehicle {
    fn model_name(&self) -> &str {
        "rapier"
    }

    fn params(&self) -> &VehicleParams {
        Vehicle::params(self)
    }

    fn body_box(&self) -> BodyBox {
        Vehicle::body_box(self)
    }

    fn kinematics(&self, world: &PhysicsWorld) -> Kinematics {
        Vehicle::kinematics(self, world)
    }

    fn set_controls(&mut self, controls: Controls) {
        Vehicle::set_controls(self, controls);
    }

    fn advance(&mut self, world: &mut PhysicsWorld, mu: f64) {
        Vehicle::apply_forces(self, world, mu);
    }
}
