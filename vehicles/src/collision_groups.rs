//! Collision layers shared by the road, the vehicles and the wheel rays.
//!
//! - the road surface is hit by wheel rays; a chassis touches it only if it bottoms out;
//! - road-edge barriers stop chassis but are invisible to wheel rays (a wheel next to a barrier
//!   must not "stand" on it);
//! - chassis collide with each other, with the barriers and with the surface.

use rapier3d::prelude::{Group, InteractionGroups, InteractionTestMode};

/// Layer of the road surface / flat pad.
pub(crate) const ROAD_SURFACE: Group = Group::GROUP_1;
/// Layer of the road-edge barriers.
pub(crate) const ROAD_EDGE: Group = Group::GROUP_2;
/// Layer of the vehicle chassis.
pub(crate) const VEHICLE: Group = Group::GROUP_3;

/// Groups of a road-surface collider.
pub(crate) const fn road_surface() -> InteractionGroups {
    InteractionGroups::new(ROAD_SURFACE, VEHICLE, InteractionTestMode::And)
}

/// Groups of a road-edge barrier collider.
pub(crate) const fn road_edge() -> InteractionGroups {
    InteractionGroups::new(ROAD_EDGE, VEHICLE, InteractionTestMode::And)
}

/// Groups of a vehicle chassis collider.
pub const fn vehicle() -> InteractionGroups {
    InteractionGroups::new(
        VEHICLE,
        Group::from_bits_truncate(ROAD_SURFACE.bits() | ROAD_EDGE.bits() | VEHICLE.bits()),
        InteractionTestMode::And,
    )
}

/// Query groups of a wheel ray: it sees the road surface only.
pub(crate) const fn wheel_ray() -> InteractionGroups {
    InteractionGroups::new(VEHICLE, ROAD_SURFACE, InteractionTestMode::And)
}
