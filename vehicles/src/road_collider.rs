//! Colliders of the merge road: a flat surface and thin walls along the road edges.
//!
//! Built from [`mergesim_types::MergeRoad`], the same description the planner's road field uses, so the
//! physical edges and the potential-field edges (paper Eq. 3) coincide. The lower edge is
//! exactly piecewise linear (`lower_edge_polyline()`: straight, linear taper, straight), so one
//! wall per polyline piece reproduces it without approximation.

use rapier3d::prelude::{
    ColliderBuilder, ColliderHandle, PhysicsWorld as RapierWorld, Real, Vector,
};
use serde::{Deserialize, Serialize};

use crate::collision_groups;

/// Dimensions of the road colliders.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RoadColliderParams {
    /// Height of the edge walls above the road (m).
    pub barrier_height_m: f64,
    /// Thickness of the edge walls (m); the walls lie outside the road, their inner face on
    /// the edge line.
    pub barrier_thickness_m: f64,
    /// How far the surface extends beyond the edges and the road's ends (m), so that wheels
    /// of a vehicle pushed against a wall still find ground.
    pub surface_margin_m: f64,
    /// Thickness of the surface slab (m); its top face is the plane z = 0.
    pub surface_thickness_m: f64,
}

impl Default for RoadColliderParams {
    fn default() -> Self {
        Self {
            barrier_height_m: 1.0,
            barrier_thickness_m: 0.3,
            surface_margin_m: 5.0,
            surface_thickness_m: 1.0,
        }
    }
}

/// Handles and geometry of the road's colliders.
#[derive(Clone, Debug, PartialEq)]
pub struct RoadColliders {
    /// The road surface slab.
    pub surface: ColliderHandle,
    /// The wall along the upper edge (None if the road geometry was unusable).
    pub upper_edge: Option<ColliderHandle>,
    /// The walls along the lower edge, one per polyline piece, in X order.
    pub lower_edge: Vec<ColliderHandle>,
    /// The edge lines the walls' inner faces lie on, as [start, end] points (m): the upper edge
    /// first, then the lower-edge pieces.
    pub edge_segments_m: Vec<[[f64; 2]; 2]>,
}

/// Which side of a segment (walking from its start to its end) the road lies on.
#[derive(Clone, Copy)]
enum RoadSide {
    Left,
    Right,
}

/// One wall whose inner face lies on `a → b`, extending away from the road.
fn wall(
    a: [f64; 2],
    b: [f64; 2],
    road_side: RoadSide,
    p: &RoadColliderParams,
) -> Option<ColliderBuilder> {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let length = dx.hypot(dy);
    if !(length.is_finite() && length > 1e-6) {
        return None;
    }
    let (ux, uy) = (dx / length, dy / length);
    // Outward normal: away from the road.
    let (nx, ny) = match road_side {
        RoadSide::Left => (uy, -ux),
        RoadSide::Right => (-uy, ux),
    };
    let half_t = 0.5 * p.barrier_thickness_m;
    let cx = 0.5 * (a[0] + b[0]) + nx * half_t;
    let cy = 0.5 * (a[1] + b[1]) + ny * half_t;
    // Each wall is lengthened by half its thickness at both ends so consecutive pieces overlap
    // at the joints (no gap a corner could slip through).
    let half_len = 0.5 * length + half_t;
    Some(
        ColliderBuilder::cuboid(
            half_len as Real,
            half_t as Real,
            (0.5 * p.barrier_height_m) as Real,
        )
        .translation(Vector::new(
            cx as Real,
            cy as Real,
            (0.5 * p.barrier_height_m) as Real,
        ))
        .rotation(Vector::new(0.0, 0.0, dy.atan2(dx) as Real))
        .collision_groups(collision_groups::road_edge()),
    )
}

fn sane_params(p: &RoadColliderParams) -> RoadColliderParams {
    let d = RoadColliderParams::default();
    let pick = |v: f64, fallback: f64| {
        if v.is_finite() && v > 0.0 {
            v
        } else {
            fallback
        }
    };
    RoadColliderParams {
        barrier_height_m: pick(p.barrier_height_m, d.barrier_height_m),
        barrier_thickness_m: pick(p.barrier_thickness_m, d.barrier_thickness_m),
        surface_margin_m: if p.surface_margin_m.is_finite() && p.surface_margin_m >= 0.0 {
            p.surface_margin_m
        } else {
            d.surface_margin_m
        },
        surface_thickness_m: pick(p.surface_thickness_m, d.surface_thickness_m),
    }
}

/// Inserts the road's colliders into `world` (standalone fixed colliders).
pub(crate) fn build_merge_road(
    world: &mut RapierWorld,
    road: &mergesim_types::MergeRoad,
    params: &RoadColliderParams,
) -> RoadColliders {
    let p = sane_params(params);
    let finite_or = |v: f64, fallback: f64| if v.is_finite() { v } else { fallback };
    let x0 = finite_or(road.start_x_m, 0.0);
    let x1 = finite_or(road.end_x_m, x0 + 1.0).max(x0 + 1.0);
    let y_low = finite_or(road.y_bottom_m, 0.0);
    let y_up = finite_or(road.y_upper_m(), y_low + 7.0).max(y_low + 1.0);
    let half_x = 0.5 * (x1 - x0) + p.surface_margin_m;
    let half_y = 0.5 * (y_up - y_low) + p.surface_margin_m + p.barrier_thickness_m;
    let half_z = 0.5 * p.surface_thickness_m;
    let surface = ColliderBuilder::cuboid(half_x as Real, half_y as Real, half_z as Real)
        .translation(Vector::new(
            (0.5 * (x0 + x1)) as Real,
            (0.5 * (y_low + y_up)) as Real,
            -half_z as Real,
        ))
        .collision_groups(collision_groups::road_surface())
        .build();
    let surface = world.insert_collider(surface, None);

    let mut edge_segments_m = Vec::new();
    let upper = road.upper_edge_polyline();
    let mut upper_edge = None;
    for piece in upper.windows(2) {
        if let Some(builder) = wall(piece[0], piece[1], RoadSide::Right, &p) {
            upper_edge = Some(world.insert_collider(builder.build(), None));
            edge_segments_m.push([piece[0], piece[1]]);
        }
    }
    let mut lower_edge = Vec::new();
    for piece in road.lower_edge_polyline().windows(2) {
        if let Some(builder) = wall(piece[0], piece[1], RoadSide::Left, &p) {
            lower_edge.push(world.insert_collider(builder.build(), None));
            edge_segments_m.push([piece[0], piece[1]]);
        }
    }
    RoadColliders {
        surface,
        upper_edge,
        lower_edge,
        edge_segments_m,
    }
}

#[cfg(test)]
mod tests {
    use rapier3d::prelude::{QueryFilter, Ray};

    use crate::physics_world::PhysicsWorld;

    /// Casts a horizontal ray across the road at `x` from inside and returns where it meets a
    /// wall, in the direction `dir_y`.
    fn wall_y(world: &PhysicsWorld, x: f64, y_inside: f64, dir_y: f64) -> Option<f64> {
        let filter = QueryFilter::new().groups(crate::collision_groups::vehicle());
        let ray = Ray::new(
            rapier3d::prelude::Vector::new(x as f32, y_inside as f32, 0.5),
            rapier3d::prelude::Vector::new(0.0, dir_y as f32, 0.0),
        );
        world
            .query_pipeline(filter)
            .cast_ray(&ray, 50.0, true)
            .map(|(_, toi)| y_inside + dir_y * f64::from(toi))
    }

    #[test]
    fn walls_follow_the_piecewise_lower_edge_and_the_upper_edge() {
        let road = mergesim_types::MergeRoad::default();
        let mut world = PhysicsWorld::new(0.002).unwrap();
        let colliders = world.add_merge_road(&road);
        assert_eq!(colliders.lower_edge.len(), 3);
        assert!(colliders.upper_edge.is_some());
        let y_mid = road.lane_center_y_m(mergesim_types::Lane::Upper);
        for x in [0.0, 150.0, 170.0, 210.0, 255.0, 300.0, 600.0] {
            let lower = wall_y(&world, x, y_mid, -1.0).unwrap();
            // Closed form of the lower edge (Eq. 3 read as Y = k_sl·X + b in the taper).
            assert!(
                (lower - road.lower_edge_y_m(x)).abs() < 1e-3,
                "x {x}: {lower}"
            );
            let upper = wall_y(&world, x, y_mid, 1.0).unwrap();
            assert!((upper - road.y_upper_m()).abs() < 1e-3, "x {x}: {upper}");
        }
    }

    #[test]
    fn degenerate_road_does_not_panic() {
        let road = mergesim_types::MergeRoad {
            lane_width_m: f64::NAN,
            end_x_m: f64::INFINITY,
            ..mergesim_types::MergeRoad::default()
        };
        let mut world = PhysicsWorld::new(0.002).unwrap();
        let _ = world.add_merge_road(&road);
    }
}
