//! Colliders of a road made of lanes ([`LaneRoad`]): a flat surface under the whole road and
//! thin walls along the drivable area's outer edges, closed lane ends included.
//!
//! Built from the same lane geometry the planners' road terms use (the outer edges of
//! [`LaneRoad::outer_edges`], Eq. 3), curved or straight, so the physical edges and the
//! potential-field edges coincide. Each outer edge is a polyline (exact for the straight merge
//! road: straight, linear taper, straight; 1 m chords on arcs, within c²/(8R) = 0.4 mm of a
//! 300 m-radius arc); one wall per polyline piece reproduces it. Which side of a piece the road
//! lies on is found by probing the drivable area ([`LaneRoad::is_drivable`]) just beside the
//! piece's midpoint; the wall goes on the other side. Open road starts and ends have no wall.
//!
//! Every coordinate handed to Rapier is relative to the world's local origin
//! ([`crate::PhysicsWorld::local_origin_m`]), so a road kilometres from the origin is built near
//! it; [`RoadColliders::edge_segments_m`] stay in the road's own coordinates.

use mergesim_types::lanes::{LaneRoad, Side};
use rapier3d::prelude::{
    ColliderBuilder, ColliderHandle, PhysicsWorld as RapierWorld, Real, Vector,
};
use serde::{Deserialize, Serialize};

use crate::collision_groups;

/// Grid the local origin snaps to (m): a power of two, so the shift is exact.
pub(crate) const LOCAL_ORIGIN_GRID_M: f64 = 1024.0;

/// A road whose bounds' centre lies within this of the world origin in both coordinates is
/// not moved (m): every built-in road (the 3050 m platoon road's centre is at x = 1475 m)
/// keeps its Rapier coordinates, and so its results, bit for bit. Beyond it (a map kilometres
/// away) the f32 resolution (0.49 mm at 4 to 8 km) is worth the shift.
pub(crate) const LOCAL_ORIGIN_KEEP_M: f64 = 2048.0;

/// How far beside an edge piece the drivable area is probed to tell the road's side (m): more
/// than the lanes' sliver tolerance ([`mergesim_types::lanes::SLIVER_M`], 5 mm).
const SIDE_PROBE_M: f64 = 0.05;

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
    /// The edge walls, one per outer-edge piece, in the order of [`LaneRoad::outer_edges`]
    /// and along each edge.
    pub barriers: Vec<ColliderHandle>,
    /// The edge lines the walls' inner faces lie on, as [start, end] points in the road's own
    /// coordinates (m), one per wall (same order).
    pub edge_segments_m: Vec<[[f64; 2]; 2]>,
    /// For each wall, the index of the outer edge it lies on ([`LaneRoad::outer_edges`]).
    pub outer_edge_index: Vec<usize>,
    /// For each wall, the side of its segment (walking from start to end) the road lies on.
    pub road_sides: Vec<RoadSide>,
}

/// Which side of a segment (walking from its start to its end) the road lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RoadSide {
    /// The road lies to the left (a right-hand edge in the direction of travel, or a closed
    /// lane end).
    Left,
    /// The road lies to the right (a left-hand edge in the direction of travel).
    Right,
}

/// The side of segment `a → b` the drivable area lies on: probed `SIDE_PROBE_M` to the left
/// and to the right of the segment's midpoint. `None` for a degenerate segment or when the
/// probe cannot tell (both sides drivable or neither).
pub fn road_side_of(lanes: &LaneRoad, a: [f64; 2], b: [f64; 2]) -> Option<RoadSide> {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let length = dx.hypot(dy);
    if !(length.is_finite() && length > 1e-9) {
        return None;
    }
    let (nx, ny) = (-dy / length, dx / length);
    let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let left = lanes.is_drivable([mid[0] + SIDE_PROBE_M * nx, mid[1] + SIDE_PROBE_M * ny]);
    let right = lanes.is_drivable([mid[0] - SIDE_PROBE_M * nx, mid[1] - SIDE_PROBE_M * ny]);
    match (left, right) {
        (true, false) => Some(RoadSide::Left),
        (false, true) => Some(RoadSide::Right),
        _ => None,
    }
}

/// The bounding box of every lane's bounds, `[min, max]` in the road's coordinates (m).
pub(crate) fn road_bounds_m(lanes: &LaneRoad) -> [[f64; 2]; 2] {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for lane in lanes.lanes() {
        for side in [Side::Left, Side::Right] {
            for p in lane.bound_polyline(side) {
                for k in 0..2 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
        }
    }
    [lo, hi]
}

/// The local origin a road is built around (m): (0, 0) if the centre of [`road_bounds_m`] lies
/// within [`LOCAL_ORIGIN_KEEP_M`] of the world origin in both coordinates, else that centre
/// rounded to the nearest multiple of [`LOCAL_ORIGIN_GRID_M`] in each coordinate: a road
/// 5.9 km away is shifted so that its Rapier coordinates stay within half its extent + 512 m
/// of the local origin.
pub(crate) fn local_origin_for(lanes: &LaneRoad) -> [f64; 2] {
    let [lo, hi] = road_bounds_m(lanes);
    let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
    if !centre.iter().all(|c| c.is_finite())
        || centre.iter().all(|c| c.abs() <= LOCAL_ORIGIN_KEEP_M)
    {
        return [0.0, 0.0];
    }
    centre.map(|c| (c / LOCAL_ORIGIN_GRID_M).round() * LOCAL_ORIGIN_GRID_M)
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

/// Inserts the road's colliders into `world` (standalone fixed colliders), every position
/// relative to `origin_m` (the physics world's local origin).
pub(crate) fn build_lane_road(
    world: &mut RapierWorld,
    lanes: &LaneRoad,
    params: &RoadColliderParams,
    origin_m: [f64; 2],
) -> RoadColliders {
    let p = sane_params(params);
    let local = |q: [f64; 2]| [q[0] - origin_m[0], q[1] - origin_m[1]];
    let [lo, hi] = road_bounds_m(lanes);
    let (lo, hi) = (local(lo), local(hi));
    // The surface covers the bounds' box plus the margin (and the walls' thickness): the road
    // is flat, so one slab is exact under every lane, straight or curved.
    let reach = p.surface_margin_m + p.barrier_thickness_m;
    let half_x = 0.5 * (hi[0] - lo[0]) + reach;
    let half_y = 0.5 * (hi[1] - lo[1]) + reach;
    let half_z = 0.5 * p.surface_thickness_m;
    let surface = ColliderBuilder::cuboid(half_x as Real, half_y as Real, half_z as Real)
        .translation(Vector::new(
            (0.5 * (lo[0] + hi[0])) as Real,
            (0.5 * (lo[1] + hi[1])) as Real,
            -half_z as Real,
        ))
        .collision_groups(collision_groups::road_surface())
        .build();
    let surface = world.insert_collider(surface, None);

    let mut colliders = RoadColliders {
        surface,
        barriers: Vec::new(),
        edge_segments_m: Vec::new(),
        outer_edge_index: Vec::new(),
        road_sides: Vec::new(),
    };
    for (index, edge) in lanes.outer_edges().iter().enumerate() {
        for piece in edge.polyline_m.windows(2) {
            let (a, b) = (piece[0], piece[1]);
            // Outer edges run along the travel direction with the road on their right (left
            // bounds) or on their left (right bounds, closed lane ends); the probe tells which.
            let Some(side) = road_side_of(lanes, a, b) else {
                continue;
            };
            if let Some(builder) = wall(local(a), local(b), side, &p) {
                colliders
                    .barriers
                    .push(world.insert_collider(builder.build(), None));
                colliders.edge_segments_m.push([a, b]);
                colliders.outer_edge_index.push(index);
                colliders.road_sides.push(side);
            }
        }
    }
    colliders
}

#[cfg(test)]
mod tests {
    use mergesim_types::MergeRoad;
    use mergesim_types::lanes::{LaneRoad, LaneRoadSpec, curved_merge_spec};
    use rapier3d::prelude::{QueryFilter, Ray};

    use super::*;
    use crate::physics_world::PhysicsWorld;

    /// Casts a horizontal ray from `from` (road coordinates) along `dir` and returns where it
    /// meets a wall, in road coordinates.
    fn wall_hit(world: &PhysicsWorld, from: [f64; 2], dir: [f64; 2]) -> Option<[f64; 2]> {
        let filter = QueryFilter::new().groups(crate::collision_groups::vehicle());
        let o = world.to_local_m(from);
        let ray = Ray::new(
            rapier3d::prelude::Vector::new(o[0] as f32, o[1] as f32, 0.5),
            rapier3d::prelude::Vector::new(dir[0] as f32, dir[1] as f32, 0.0),
        );
        world
            .query_pipeline(filter)
            .cast_ray(&ray, 50.0, true)
            .map(|(_, toi)| {
                let t = f64::from(toi);
                [from[0] + t * dir[0], from[1] + t * dir[1]]
            })
    }

    fn merge_lanes() -> (MergeRoad, LaneRoad) {
        let road = MergeRoad::default();
        let lanes = road.lane_road().unwrap_or_else(|e| panic!("{e}"));
        (road, lanes)
    }

    #[test]
    fn walls_follow_the_piecewise_lower_edge_and_the_upper_edge() {
        let (road, lanes) = merge_lanes();
        let mut world = PhysicsWorld::new(0.002).unwrap();
        let colliders = world.add_lane_road(&lanes);
        // The straight merge road keeps its Rapier coordinates (origin not moved).
        assert_eq!(world.local_origin_m(), [0.0, 0.0]);
        // One upper wall, three lower (straight, taper, straight).
        let lower = colliders
            .road_sides
            .iter()
            .filter(|s| **s == RoadSide::Left)
            .count();
        let upper = colliders
            .road_sides
            .iter()
            .filter(|s| **s == RoadSide::Right)
            .count();
        assert_eq!((lower, upper), (3, 1), "{:?}", colliders.edge_segments_m);
        let y_mid = road.lane_center_y_m(mergesim_types::Lane::Upper);
        for x in [0.0, 150.0, 170.0, 210.0, 255.0, 300.0, 600.0] {
            let lower = wall_hit(&world, [x, y_mid], [0.0, -1.0]).unwrap();
            // Closed form of the lower edge (Eq. 3 read as Y = k_sl·X + b in the taper).
            assert!(
                (lower[1] - road.lower_edge_y_m(x)).abs() < 1e-3,
                "x {x}: {lower:?}"
            );
            let upper = wall_hit(&world, [x, y_mid], [0.0, 1.0]).unwrap();
            assert!(
                (upper[1] - road.y_upper_m()).abs() < 1e-3,
                "x {x}: {upper:?}"
            );
        }
    }

    /// On the 300 m-radius curved merge road, the walls lie on the arcs of the outer edges:
    /// rays cast radially from the through lane's centre meet them at the outer radius (right edge,
    /// lower lane's right bound) and the inner radius (left edge), within the 1 m chords'
    /// sagitta (0.4 mm) and f32 rounding.
    #[test]
    fn walls_follow_a_curved_road() {
        let road = MergeRoad::default();
        let radius_m = 300.0;
        let spec = curved_merge_spec(&road, radius_m).unwrap_or_else(|e| panic!("{e}"));
        let lanes = LaneRoad::new(&spec).unwrap_or_else(|e| panic!("{e}"));
        let mut world = PhysicsWorld::new(0.002).unwrap();
        let colliders = world.add_lane_road(&lanes);
        assert!(
            colliders.barriers.len() > 600,
            "{}",
            colliders.barriers.len()
        );
        let y_lane = road.y_lane_m();
        let centre = [0.0, y_lane + radius_m];
        let w = road.lane_width_m;
        for s in [20.0, 100.0, 250.0, 400.0, 600.0] {
            let phi: f64 = s / radius_m;
            // The through lane's centre, at radius R − w/2.
            let r_c = radius_m - 0.5 * w;
            let on_divider = [r_c * phi.sin(), y_lane + radius_m - r_c * phi.cos()];
            let outward = [phi.sin(), -phi.cos()];
            let inward = [-outward[0], -outward[1]];
            // Upper (left, inner) edge at radius R - w.
            let up = wall_hit(&world, on_divider, inward).unwrap();
            let r_up = (up[0] - centre[0]).hypot(up[1] - centre[1]);
            assert!((r_up - (radius_m - w)).abs() < 2e-3, "s {s}: {r_up}");
            // Lower (right, outer) edge: the lower lane's right bound while it lasts, then the
            // divider itself.
            let low = wall_hit(&world, on_divider, outward);
            let expected = radius_m - (road.lower_edge_y_m(s) - y_lane);
            let r_low = low.map(|p| (p[0] - centre[0]).hypot(p[1] - centre[1]));
            assert!(
                r_low.is_some_and(|r| (r - expected).abs() < 2e-3),
                "s {s}: {r_low:?} vs {expected}"
            );
        }
    }

    /// The platoon's 3050 m road (bounds' centre at x = 1475 m) is not moved (its results stay
    /// bit for bit); the same road 3 km further is, by whole grid steps.
    #[test]
    fn a_long_road_near_the_origin_is_not_moved() {
        let road = MergeRoad {
            merge_start_x_m: 1300.0,
            merge_end_x_m: 1400.0,
            start_x_m: -50.0,
            end_x_m: 3000.0,
            ..MergeRoad::default()
        };
        let lanes = road.lane_road().unwrap_or_else(|e| panic!("{e}"));
        let mut world = PhysicsWorld::new(0.002).unwrap();
        world.add_lane_road(&lanes);
        assert_eq!(world.local_origin_m(), [0.0, 0.0]);
        let further = MergeRoad {
            merge_start_x_m: 4300.0,
            merge_end_x_m: 4400.0,
            start_x_m: 2950.0,
            end_x_m: 6000.0,
            ..MergeRoad::default()
        };
        let lanes = further.lane_road().unwrap_or_else(|e| panic!("{e}"));
        let mut world = PhysicsWorld::new(0.002).unwrap();
        world.add_lane_road(&lanes);
        // Centre x = 4475 m: 4.37 grid steps.
        assert_eq!(world.local_origin_m(), [4096.0, 0.0]);
    }

    #[test]
    fn far_road_is_built_near_the_local_origin() {
        let road = MergeRoad::default();
        let mut spec = curved_merge_spec(&road, 300.0).unwrap_or_else(|e| panic!("{e}"));
        translate(&mut spec, [5900.0, -3000.0]);
        let lanes = LaneRoad::new(&spec).unwrap_or_else(|e| panic!("{e}"));
        let mut world = PhysicsWorld::new(0.002).unwrap();
        let colliders = world.add_lane_road(&lanes);
        let origin = world.local_origin_m();
        assert_eq!(origin, [6144.0, -3072.0]);
        // Every collider lies within 1 km of the local origin.
        for (_, c) in world.colliders().iter() {
            let t = c.translation();
            assert!(t.x.abs() < 1000.0 && t.y.abs() < 1000.0, "{t:?}");
        }
        // The segments keep the road's coordinates.
        let first = colliders.edge_segments_m[0][0];
        assert!(first[0] > 5000.0 && first[1] < -2000.0, "{first:?}");
    }

    pub(crate) fn translate(spec: &mut LaneRoadSpec, by_m: [f64; 2]) {
        for lane in &mut spec.lanes {
            for p in &mut lane.centreline_m {
                p[0] += by_m[0];
                p[1] += by_m[1];
            }
        }
    }
}
