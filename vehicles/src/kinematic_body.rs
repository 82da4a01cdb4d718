//! A box that moves where it is told: a Rapier kinematic position-based rigid body with one
//! cuboid collider in the vehicle collision groups, for vehicles whose motion is prescribed
//! (recorded traffic) rather than computed from tire forces.
//!
//! The box rests on the road plane like a chassis box: its bottom at `ground_clearance_m`, its
//! top at `body_height_m` (the values of the preset it is built with), so its Z range overlaps
//! every simulated chassis' and Rapier's contacts between them happen. A kinematic body has
//! infinite mass: it pushes a dynamic chassis it touches and is never pushed back.
//!
//! Poses are in the road's coordinates; the conversion to Rapier's local origin happens here
//! (module doc of [`PhysicsWorld`]).

use rapier3d::prelude::{
    ColliderBuilder, Pose, Real, RigidBodyBuilder, RigidBodyHandle, Rotation, Vector,
};

use crate::collision_groups;
use crate::error::VehicleError;
use crate::physics_world::PhysicsWorld;

/// A kinematic box in a [`PhysicsWorld`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KinematicBox {
    body: RigidBodyHandle,
    /// Height of the box centre above the road plane (m).
    centre_z_m: f64,
}

impl KinematicBox {
    /// Inserts a box `length_m × width_m` whose bottom lies `ground_clearance_m` above the road
    /// plane (z = 0) and whose top lies at `body_height_m`, centred on (`x_m`, `y_m`) (road
    /// coordinates), heading `yaw_rad`. Errors on non-finite or non-positive dimensions.
    pub fn spawn(
        world: &mut PhysicsWorld,
        length_m: f64,
        width_m: f64,
        ground_clearance_m: f64,
        body_height_m: f64,
        pose_m: [f64; 3],
    ) -> Result<Self, VehicleError> {
        for (name, value) in [("length_m", length_m), ("width_m", width_m)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(VehicleError::invalid(name, value, "must be finite and > 0"));
            }
        }
        if !(ground_clearance_m.is_finite()
            && body_height_m.is_finite()
            && ground_clearance_m >= 0.0
            && body_height_m > ground_clearance_m)
        {
            return Err(VehicleError::invalid(
                "body_height_m",
                body_height_m,
                "must be finite and above the ground clearance",
            ));
        }
        for (name, value) in [
            ("x_m", pose_m[0]),
            ("y_m", pose_m[1]),
            ("yaw_rad", pose_m[2]),
        ] {
            if !value.is_finite() {
                return Err(VehicleError::invalid(name, value, "must be finite"));
            }
        }
        let centre_z_m = 0.5 * (body_height_m + ground_clearance_m);
        let half_height_m = 0.5 * (body_height_m - ground_clearance_m);
        let mut this = Self {
            body: RigidBodyHandle::invalid(),
            centre_z_m,
        };
        let pose = this.rapier_pose(world, pose_m);
        let body = RigidBodyBuilder::kinematic_position_based()
            .pose(pose)
            .can_sleep(false)
            .build();
        let collider = ColliderBuilder::cuboid(
            (0.5 * length_m) as Real,
            (0.5 * width_m) as Real,
            half_height_m as Real,
        )
        .collision_groups(collision_groups::vehicle())
        .build();
        let rapier = world.rapier_mut();
        this.body = rapier.insert_body(body);
        rapier.insert_collider(collider, Some(this.body));
        Ok(this)
    }

    fn rapier_pose(&self, world: &PhysicsWorld, pose_m: [f64; 3]) -> Pose {
        let [x, y] = world.to_local_m([pose_m[0], pose_m[1]]);
        Pose::from_parts(
            Vector::new(x as Real, y as Real, self.centre_z_m as Real),
            Rotation::from_rotation_z(pose_m[2] as Real),
        )
    }

    /// The rigid body.
    pub fn handle(&self) -> RigidBodyHandle {
        self.body
    }

    /// Where the box will be after the next [`PhysicsWorld::step`]: (x, y, heading) in road
    /// coordinates. Non-finite poses are ignored (the box stays where it is).
    pub fn set_next_pose(&self, world: &mut PhysicsWorld, pose_m: [f64; 3]) {
        if !pose_m.iter().all(|v| v.is_finite()) {
            return;
        }
        let pose = self.rapier_pose(world, pose_m);
        if let Some(body) = world.bodies_mut().get_mut(self.body) {
            body.set_next_kinematic_position(pose);
        }
    }

    /// The box's pose now, (x, y, heading) in road coordinates; `None` once removed.
    pub fn pose_m(&self, world: &PhysicsWorld) -> Option<[f64; 3]> {
        let body = world.bodies().get(self.body)?;
        let t = body.translation();
        let [x, y] = world.to_world_m([f64::from(t.x), f64::from(t.y)]);
        let (axis, angle) = body.rotation().to_axis_angle();
        Some([x, y, f64::from(axis.z * angle)])
    }

    /// Removes the body and its collider from the world.
    pub fn remove(self, world: &mut PhysicsWorld) {
        world.rapier_mut().remove_body(self.body);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moves_to_the_next_pose_in_one_step_and_is_removed() {
        let mut world = PhysicsWorld::new(0.01).unwrap_or_else(|e| panic!("{e}"));
        world.add_flat_ground(100.0);
        let b = KinematicBox::spawn(&mut world, 4.5, 1.8, 0.15, 1.45, [1.0, 2.0, 0.0])
            .unwrap_or_else(|e| panic!("{e}"));
        b.set_next_pose(&mut world, [1.5, 2.0, 0.1]);
        world.step();
        let p = b.pose_m(&world).unwrap_or_else(|| panic!("present"));
        assert!(
            (p[0] - 1.5).abs() < 1e-5 && (p[1] - 2.0).abs() < 1e-5,
            "{p:?}"
        );
        assert!((p[2] - 0.1).abs() < 1e-5, "{p:?}");
        b.remove(&mut world);
        assert!(b.pose_m(&world).is_none());
        // Only the ground is left.
        assert_eq!(world.colliders().len(), 1);
    }

    #[test]
    fn rejects_bad_dimensions() {
        let mut world = PhysicsWorld::new(0.01).unwrap_or_else(|e| panic!("{e}"));
        assert!(KinematicBox::spawn(&mut world, 0.0, 1.8, 0.1, 1.4, [0.0; 3]).is_err());
        assert!(KinematicBox::spawn(&mut world, 4.0, 1.8, 0.1, 0.05, [0.0; 3]).is_err());
        assert!(KinematicBox::spawn(&mut world, 4.0, 1.8, 0.1, 1.4, [f64::NAN, 0.0, 0.0]).is_err());
    }
}
