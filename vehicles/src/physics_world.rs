//! The rapier world the vehicles live in: sets, pipeline, gravity and a fixed step.

use rapier3d::prelude::{
    ColliderBuilder, ColliderHandle, ColliderSet, IntegrationParameters, NarrowPhase,
    PhysicsWorld as RapierWorld, QueryFilter, QueryPipeline, Ray, RayIntersection, Real,
    RigidBodySet, Vector,
};

use crate::collision_groups;
use crate::error::VehicleError;
use crate::road_collider::{RoadColliderParams, RoadColliders, build_lane_road, local_origin_for};

/// Standard gravity used by the world and by the vehicles' static loads (m/s²).
pub const GRAVITY_MPS2: f64 = 9.81;

/// Smallest and largest accepted physics step (s).
pub(crate) const DT_RANGE_S: (f64, f64) = (1e-4, 0.02);

/// Thickness of the flat pad (m); its top face is the plane z = 0.
const FLAT_GROUND_THICKNESS_M: f64 = 1.0;

/// Half extent used by [`PhysicsWorld::add_flat_ground`] when given an unusable value (m).
pub const FALLBACK_GROUND_HALF_EXTENT_M: f64 = 1000.0;

/// World frame: X along the road, Y left, Z up, gravity (0, 0, −9.81). Rapier works in `f32`;
/// this wrapper and the vehicles speak `f64` SI.
///
/// # Local origin
/// Rapier's `f32` resolves 0.5 mm at 6 km but 61 µm below 1 km. Every position handed to
/// Rapier is therefore taken relative to a *local origin* (m, in the road's coordinates):
/// (0, 0) until [`add_lane_road`](Self::add_lane_road) sets it from the road
/// (`local_origin_for`: (0, 0) for a road centred within 2048 m of the origin, else the road
/// bounds' centre snapped to 1024 m). The vehicles convert at their boundary ([`crate::Vehicle::spawn`],
/// [`crate::Vehicle::kinematics`], [`crate::Vehicle::wheel_telemetry`]): everything they take
/// and give is in the road's own coordinates. Only what is read straight from Rapier
/// ([`rapier`](Self::rapier), [`bodies`](Self::bodies), [`colliders`](Self::colliders), scene
/// queries) is local; convert with [`to_local_m`](Self::to_local_m) /
/// [`to_world_m`](Self::to_world_m).
pub struct PhysicsWorld {
    world: RapierWorld,
    dt_s: f64,
    steps: u64,
    /// The local origin (m, road coordinates) Rapier's coordinates are relative to.
    origin_m: [f64; 2],
    /// True once the origin is in use (a body or a road surface was added) or was set.
    origin_fixed: bool,
    /// The colliders wheel rays can stand on (module doc of [`Self::cast_road_ray`]).
    road_surfaces: Vec<ColliderHandle>,
}

impl PhysicsWorld {
    /// A world stepping `dt_s` seconds per [`step`](Self::step); `dt_s` must lie in
    /// `DT_RANGE_S`.
    pub fn new(dt_s: f64) -> Result<Self, VehicleError> {
        if !dt_s.is_finite() || dt_s < DT_RANGE_S.0 || dt_s > DT_RANGE_S.1 {
            return Err(VehicleError::invalid(
                "dt_s",
                dt_s,
                format!("must lie in [{}, {}] s", DT_RANGE_S.0, DT_RANGE_S.1),
            ));
        }
        let world = RapierWorld {
            gravity: Vector::new(0.0, 0.0, -GRAVITY_MPS2 as Real),
            integration_parameters: IntegrationParameters {
                dt: dt_s as Real,
                ..IntegrationParameters::default()
            },
            ..RapierWorld::default()
        };
        Ok(Self {
            world,
            dt_s,
            steps: 0,
            origin_m: [0.0, 0.0],
            origin_fixed: false,
            road_surfaces: Vec::new(),
        })
    }

    /// The physics step (s).
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// Magnitude of gravity (m/s²).
    pub fn gravity_mps2(&self) -> f64 {
        GRAVITY_MPS2
    }

    /// Number of steps taken so far.
    pub fn step_count(&self) -> u64 {
        self.steps
    }

    /// Simulated time, `step_count · dt` (s); computed, not accumulated, so it does not drift.
    pub fn time_s(&self) -> f64 {
        self.steps as f64 * self.dt_s
    }

    /// Adds a square flat pad centred on the origin, top face at z = 0 (for maneuvers). A
    /// non-finite or non-positive size falls back to `FALLBACK_GROUND_HALF_EXTENT_M`; use
    /// [`try_add_flat_ground`](Self::try_add_flat_ground) to get an error instead.
    pub fn add_flat_ground(&mut self, half_extent_m: f64) {
        let half = if half_extent_m.is_finite() && half_extent_m > 0.0 {
            half_extent_m
        } else {
            FALLBACK_GROUND_HALF_EXTENT_M
        };
        self.insert_flat_ground(half);
    }

    /// Like [`add_flat_ground`](Self::add_flat_ground) but rejects a bad size and returns the
    /// pad's collider.
    pub fn try_add_flat_ground(
        &mut self,
        half_extent_m: f64,
    ) -> Result<ColliderHandle, VehicleError> {
        if !half_extent_m.is_finite() || half_extent_m <= 0.0 || half_extent_m > 1e6 {
            return Err(VehicleError::invalid(
                "half_extent_m",
                half_extent_m,
                "must lie in (0, 1e6] m",
            ));
        }
        Ok(self.insert_flat_ground(half_extent_m))
    }

    fn insert_flat_ground(&mut self, half_extent_m: f64) -> ColliderHandle {
        let half_z = 0.5 * FLAT_GROUND_THICKNESS_M;
        self.add_road_surface(
            ColliderBuilder::cuboid(half_extent_m as Real, half_extent_m as Real, half_z as Real)
                .translation(Vector::new(0.0, 0.0, -half_z as Real)),
        )
    }

    /// The local origin (m, road coordinates) that Rapier's coordinates are relative to.
    pub fn local_origin_m(&self) -> [f64; 2] {
        self.origin_m
    }

    /// Sets the local origin (m, road coordinates) instead of letting
    /// [`add_lane_road`](Self::add_lane_road) choose it. Only before anything is added: an
    /// error once a rigid body or a road surface exists, or for a non-finite origin.
    pub fn set_local_origin_m(&mut self, origin_m: [f64; 2]) -> Result<(), VehicleError> {
        for (name, v) in [("origin_m[0]", origin_m[0]), ("origin_m[1]", origin_m[1])] {
            if !v.is_finite() {
                return Err(VehicleError::invalid(name, v, "must be finite"));
            }
        }
        if !(self.world.bodies.is_empty() && self.road_surfaces.is_empty()) {
            return Err(VehicleError::invalid(
                "origin_m",
                origin_m[0],
                "the local origin can only be set before any body or road is added",
            ));
        }
        self.origin_m = origin_m;
        self.origin_fixed = true;
        Ok(())
    }

    /// A point of the road's coordinates in Rapier's (local) coordinates (m).
    pub fn to_local_m(&self, p_m: [f64; 2]) -> [f64; 2] {
        [p_m[0] - self.origin_m[0], p_m[1] - self.origin_m[1]]
    }

    /// A point of Rapier's (local) coordinates in the road's coordinates (m).
    pub fn to_world_m(&self, p_m: [f64; 2]) -> [f64; 2] {
        [p_m[0] + self.origin_m[0], p_m[1] + self.origin_m[1]]
    }

    /// Adds a road made of lanes: a flat surface under it plus edge barriers along each piece
    /// of the drivable area's outer edges (closed lane ends included), with default
    /// [`RoadColliderParams`]. Never panics: degenerate pieces are skipped.
    ///
    /// If no rigid body and no road surface has been added yet and the origin was not set with
    /// [`set_local_origin_m`](Self::set_local_origin_m), this first sets the local origin from
    /// the road (`local_origin_for`); otherwise the road is built around the origin in use.
    pub fn add_lane_road(&mut self, lanes: &mergesim_types::lanes::LaneRoad) -> RoadColliders {
        self.add_lane_road_with(lanes, &RoadColliderParams::default())
    }

    /// [`add_lane_road`](Self::add_lane_road) with explicit barrier / surface dimensions.
    pub(crate) fn add_lane_road_with(
        &mut self,
        lanes: &mergesim_types::lanes::LaneRoad,
        params: &RoadColliderParams,
    ) -> RoadColliders {
        if !self.origin_fixed && self.world.bodies.is_empty() && self.road_surfaces.is_empty() {
            self.origin_m = local_origin_for(lanes);
        }
        self.origin_fixed = true;
        let colliders = build_lane_road(&mut self.world, lanes, params, self.origin_m);
        self.road_surfaces.push(colliders.surface);
        self.refresh_queries();
        colliders
    }

    /// Inserts a fixed collider the wheels can stand on (a ramp, a bump, a second pad), in the
    /// road-surface collision groups. Wheel rays see only the colliders added through this
    /// method, [`add_flat_ground`](Self::add_flat_ground) and
    /// [`add_lane_road`](Self::add_lane_road): a collider inserted through
    /// [`rapier_mut`](Self::rapier_mut) is solid for the chassis (if its groups say so) but
    /// invisible to the wheels.
    pub(crate) fn add_road_surface(&mut self, collider: ColliderBuilder) -> ColliderHandle {
        let collider = collider
            .collision_groups(collision_groups::road_surface())
            .build();
        let handle = self.world.insert_collider(collider, None);
        self.road_surfaces.push(handle);
        self.refresh_queries();
        handle
    }

    /// Updates the broad phase so that scene queries (wheel rays, spawn checks) see colliders
    /// added since the last step.
    pub(crate) fn refresh_queries(&mut self) {
        self.world.detect_collisions(&(), &());
    }

    /// Height of the road surface below (`x_m`, `y_m`) (road coordinates), searched downwards
    /// from `probe_height_m` above z = 0; `None` if no road surface lies below. Refreshes the
    /// scene queries first (a spawn check after colliders were added).
    pub(crate) fn ground_height_m(
        &mut self,
        x_m: f64,
        y_m: f64,
        probe_height_m: f64,
    ) -> Option<f64> {
        self.refresh_queries();
        // Rapier's coordinates are relative to the world's local origin.
        let [x_local_m, y_local_m] = self.to_local_m([x_m, y_m]);
        let probe = Ray::new(
            Vector::new(x_local_m as Real, y_local_m as Real, probe_height_m as Real),
            Vector::new(0.0, 0.0, -1.0),
        );
        self.cast_road_ray(&probe, (2.0 * probe_height_m) as Real)
            .map(|hit| probe_height_m - f64::from(hit.time_of_impact))
    }

    /// One rapier step of `dt_s`.
    pub fn step(&mut self) {
        self.world.step();
        self.steps += 1;
    }

    /// The rigid bodies.
    pub fn bodies(&self) -> &RigidBodySet {
        &self.world.bodies
    }

    /// The rigid bodies, mutable (e.g. to add forces of your own).
    pub(crate) fn bodies_mut(&mut self) -> &mut RigidBodySet {
        &mut self.world.bodies
    }

    /// The colliders (chassis boxes, road surface, barriers).
    pub fn colliders(&self) -> &ColliderSet {
        &self.world.colliders
    }

    /// The narrow phase (contact pairs of the last step).
    pub fn narrow_phase(&self) -> &NarrowPhase {
        &self.world.narrow_phase
    }

    /// The wrapped rapier world, for anything not exposed here.
    pub fn rapier(&self) -> &RapierWorld {
        &self.world
    }

    /// The wrapped rapier world, mutable. Changing `integration_parameters.dt` desynchronises
    /// [`dt_s`](Self::dt_s); don't.
    pub(crate) fn rapier_mut(&mut self) -> &mut RapierWorld {
        &mut self.world
    }

    /// A scene-query view with the given filter.
    pub fn query_pipeline<'a>(&'a self, filter: QueryFilter<'a>) -> QueryPipeline<'a> {
        self.world.query_pipeline_with_filter(filter)
    }

    /// First road-surface hit of a ray (wheel-ray groups), with its normal.
    ///
    /// The ray is cast against the few road-surface colliders directly (those added by
    /// [`add_flat_ground`](Self::add_flat_ground), [`add_lane_road`](Self::add_lane_road) and
    /// [`add_road_surface`](Self::add_road_surface)), not through rapier's query pipeline, whose
    /// tree also holds every chassis: the same parry ray cast on the same shapes at the same
    /// poses (so the same hit, bit for bit, as `tests` checks against the pipeline), without
    /// walking a tree that grows with the number of vehicles. Four rays per vehicle per step
    /// made that walk a measurable share of the tire forces' time.
    pub(crate) fn cast_road_ray(&self, ray: &Ray, max_toi_m: Real) -> Option<RayIntersection> {
        let groups = collision_groups::wheel_ray();
        let mut best: Option<RayIntersection> = None;
        let mut max_toi = max_toi_m;
        for &handle in &self.road_surfaces {
            let Some(collider) = self.world.colliders.get(handle) else {
                continue;
            };
            if !collider.is_enabled() || !collider.collision_groups().test(groups) {
                continue;
            }
            if let Some(hit) =
                collider
                    .shape()
                    .cast_ray_and_get_normal(collider.position(), ray, max_toi, true)
            {
                max_toi = hit.time_of_impact;
                best = Some(hit);
            }
        }
        best
    }

    /// [`cast_road_ray`](Self::cast_road_ray) through rapier's query pipeline (the reference
    /// the direct cast is tested against).
    #[cfg(test)]
    fn cast_road_ray_via_pipeline(&self, ray: &Ray, max_toi_m: Real) -> Option<RayIntersection> {
        let filter = QueryFilter::new().groups(collision_groups::wheel_ray());
        self.world
            .query_pipeline_with_filter(filter)
            .cast_ray_and_get_normal(ray, max_toi_m, true)
            .map(|(_, hit)| hit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_dt() {
        for dt in [0.0, -0.002, f64::NAN, f64::INFINITY, 1.0] {
            let err = PhysicsWorld::new(dt).err().map(|e| e.to_string());
            assert!(
                err.as_deref().is_some_and(|e| e.contains("dt_s")),
                "{dt}: {err:?}"
            );
        }
    }

    #[test]
    fn flat_ground_top_face_is_at_zero() {
        let mut world = PhysicsWorld::new(0.002).unwrap_or_else(|e| panic!("{e}"));
        world.add_flat_ground(50.0);
        let ray = Ray::new(Vector::new(3.0, -7.0, 2.0), Vector::new(0.0, 0.0, -1.0));
        let hit = world.cast_road_ray(&ray, 10.0).map(|h| h.time_of_impact);
        assert_eq!(hit, Some(2.0));
    }

    #[test]
    fn direct_road_rays_hit_what_the_query_pipeline_hits_bit_for_bit() {
        let mut world = PhysicsWorld::new(0.002).unwrap_or_else(|e| panic!("{e}"));
        world.add_lane_road(
            &mergesim_types::MergeRoad::default()
                .lane_road()
                .unwrap_or_else(|e| panic!("{e}")),
        );
        // A tilted ramp overlapping the road, and chassis boxes (invisible to wheel rays) in
        // the pipeline's tree.
        world.add_road_surface(
            ColliderBuilder::cuboid(3.0, 2.0, 0.2)
                .translation(Vector::new(40.0, 1.75, 0.0))
                .rotation(Vector::new(0.0, 0.1, 0.05)),
        );
        for i in 0..20 {
            let chassis = ColliderBuilder::cuboid(2.25, 0.8, 0.7)
                .translation(Vector::new(10.0 * i as Real, 1.75, 0.9))
                .collision_groups(collision_groups::vehicle())
                .build();
            world.rapier_mut().insert_collider(chassis, None);
        }
        world.refresh_queries();
        let mut hits = 0;
        for ix in 0..300 {
            for iy in 0..13 {
                let x = -80.0 + 0.37 * ix as Real * 9.0;
                let y = -6.0 + 1.3 * iy as Real;
                let origin = Vector::new(x, y, 1.2);
                for dir in [
                    Vector::new(0.0, 0.0, -1.0),
                    Vector::new(0.05, -0.02, -1.0).normalize(),
                ] {
                    let ray = Ray::new(origin, dir);
                    let direct = world.cast_road_ray(&ray, 2.0);
                    let reference = world.cast_road_ray_via_pipeline(&ray, 2.0);
                    assert_eq!(
                        direct.map(|h| (
                            h.time_of_impact.to_bits(),
                            h.normal.to_array().map(f32::to_bits)
                        )),
                        reference.map(|h| (
                            h.time_of_impact.to_bits(),
                            h.normal.to_array().map(f32::to_bits)
                        )),
                        "ray from {origin:?} along {dir:?}"
                    );
                    hits += usize::from(direct.is_some());
                }
            }
        }
        // Both some hits and some misses (beyond the road's ends and edges).
        assert!(hits > 1000 && hits < 300 * 13 * 2, "{hits}");
    }
}
