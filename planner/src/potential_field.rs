//! The universal potential field U_uni = U_AT + U_LD + U_RE + Σ_j U_OB^j and its force
//! F_uni = −∇U_uni (paper Eq. 5), plus sampling on a grid for drawing.
//!
//! The road terms live in the lane frame (`lane_road_field.rs`, planner/README.md "The road
//! terms in the lane frame"): Eq. 1 pulls along the target lane's centreline (the vehicle's own
//! lane, or the lane it must merge into when its own ends: the lane-end rule), Eqs. 2–3 are the
//! dividers and the drivable area's outer edges, and each obstacle's Eq. 4 heading is taken
//! relative to its lane.

use crate::attractive_field::AttractionParams;
use crate::error::PlannerError;
use crate::lane_road_field::{LaneRoadField, LaneRoadGeometry};
use crate::obstacle_field::{ObstacleField, ObstacleFieldParams, SelfView};
use crate::road_field::RoadFieldParams;
use mergesim_types::{Neighbour, VehicleId, VehicleShape, VehicleState};

pub(crate) use mergesim_types::GridSpec;

/// The numbers of the universal field U_uni = U_AT + U_LD + U_RE + Σ_j U_OB^j (Eq. 5), built
/// once from `PlannerParams` (`derived_params`; `UniversalFieldParams::from(&params)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UniversalFieldParams {
    /// Eq. 1: λ and the moving target's look-ahead.
    pub attraction: AttractionParams,
    /// Eqs. 2–3: the lane dividers and the road edges.
    pub road: RoadFieldParams,
    /// The lane-end rule's walls (Eq. 3's term on the divider towards a lane that ends;
    /// `lane_end_walls`).
    pub lane_end_walls: bool,
    /// Eq. 4 for the path: `PlannerParams::path_field`.
    pub obstacles: ObstacleFieldParams,
}

/// The universal field seen by one planning vehicle at one planning instant.
#[derive(Clone, Debug)]
pub struct PotentialField<'a> {
    /// λ of Eq. 1 (1/m²).
    pub attractive_gain_per_m2: f64,
    /// Look-ahead of the moving target (m).
    pub lookahead_m: f64,
    /// The target lane of Eq. 1 (index into the road's lanes).
    pub target_lane: usize,
    /// s_tar on the target lane for the drawn (fixed-target) field: the ego's s + look-ahead.
    pub target_s_m: f64,
    /// Eqs. 2–3 (with the lane-end rule's walls).
    pub road: LaneRoadField<'a>,
    /// Eq. 4, one per other vehicle, in the order of the neighbours given.
    pub obstacles: Vec<ObstacleField>,
    /// Each obstacle's velocity (m/s), for `PotentialField::stepping_force_at`.
    pub obstacle_velocities_mps: Vec<[f64; 2]>,
}

impl<'a> PotentialField<'a> {
    /// The field of vehicle `ego_id` at `ego` among `neighbours` (its own entry is skipped).
    pub fn new(
        params: &UniversalFieldParams,
        road: &'a LaneRoadGeometry,
        ego_id: VehicleId,
        ego: &VehicleState,
        ego_shape: &VehicleShape,
        neighbours: &[Neighbour],
    ) -> Self {
        let me = SelfView {
            speed_mps: ego.speed_mps,
            shape: *ego_shape,
        };
        let others: Vec<&Neighbour> = neighbours.iter().filter(|n| n.id != ego_id).collect();
        let obstacle_velocities_mps = others
            .iter()
            .map(|n| {
                let (s, c) = n.state.yaw_rad.sin_cos();
                [n.state.speed_mps * c, n.state.speed_mps * s]
            })
            .collect();
        let field_params = &params.obstacles;
        let obstacles = others
            .iter()
            .map(|n| {
                ObstacleField::new(
                    field_params,
                    me,
                    n.state.x_m,
                    n.state.y_m,
                    n.state.yaw_rad,
                    n.state.speed_mps,
                    &n.shape,
                )
                .in_lane_frame(road.lane_heading_at_rad([n.state.x_m, n.state.y_m]))
            })
            .collect();
        let ego_p = [ego.x_m, ego.y_m];
        let target_lane = road.target_lane(road.lane_index_at(ego_p));
        Self {
            attractive_gain_per_m2: params.attraction.gain_per_m2,
            lookahead_m: params.attraction.lookahead_m,
            target_lane,
            target_s_m: road.s_m(target_lane, ego_p) + params.attraction.lookahead_m,
            road: LaneRoadField::for_vehicle(
                road,
                &params.road,
                params.lane_end_walls,
                0.5 * ego_shape.width_m,
                ego,
            ),
            obstacles,
            obstacle_velocities_mps,
        }
    }

    /// U_AT at (x, y), Eq. 1 with the target fixed at the ego's s + look-ahead on the target
    /// lane: ½ λ (s − s_tar)².
    pub(crate) fn attractive_value(&self, x_m: f64, y_m: f64) -> f64 {
        let ds = self.road.geometry.s_m(self.target_lane, [x_m, y_m]) - self.target_s_m;
        0.5 * self.attractive_gain_per_m2 * ds * ds
    }

    /// ∇U_AT = λ (s − s_tar) ∇s (fixed target).
    pub fn attractive_gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let j = self.road.geometry.jacobian(self.target_lane, [x_m, y_m]);
        let k = self.attractive_gain_per_m2 * (j.frame.s_m - self.target_s_m);
        [k * j.grad_s[0], k * j.grad_s[1]]
    }

    /// ∇U_AT with the target re-anchored a look-ahead ahead of (x, y) along the target lane
    /// (Eq. 1, reading 1): −λ·look-ahead·∇s (on a straight road along +x the constant
    /// [−λ·look-ahead, 0]).
    pub(crate) fn moving_target_gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let j = self.road.geometry.jacobian(self.target_lane, [x_m, y_m]);
        let k = -self.attractive_gain_per_m2 * self.lookahead_m;
        [k * j.grad_s[0], k * j.grad_s[1]]
    }

    /// U_LD + U_RE + Σ U_OB: everything but the attraction (what a drawing usually wants:
    /// the attraction is a bowl of size ½ λ Δs² that swamps the rest).
    pub(crate) fn repulsive_value(&self, x_m: f64, y_m: f64) -> f64 {
        self.road.value(x_m, y_m)
            + self
                .obstacles
                .iter()
                .map(|o| o.value(x_m, y_m))
                .sum::<f64>()
    }

    /// U_uni (Eq. 5) with the target fixed at the ego's s + look-ahead.
    pub fn value(&self, x_m: f64, y_m: f64) -> f64 {
        self.attractive_value(x_m, y_m) + self.repulsive_value(x_m, y_m)
    }

    /// ∇(U_LD + U_RE + Σ U_OB).
    pub(crate) fn repulsive_gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let mut g = self.road.gradient(x_m, y_m);
        for o in &self.obstacles {
            let go = o.gradient(x_m, y_m);
            g[0] += go[0];
            g[1] += go[1];
        }
        g
    }

    /// ∇U_uni with the target fixed at the ego's s + look-ahead.
    pub fn gradient(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let mut g = self.repulsive_gradient(x_m, y_m);
        let a = self.attractive_gradient(x_m, y_m);
        g[0] += a[0];
        g[1] += a[1];
        g
    }

    /// F_uni = −∇U_uni (Eq. 5) with the moving target of Eq. 1 (a constant pull
    /// λ·look-ahead along the target lane): the force that steps the local path (Eqs. 6–7).
    pub fn stepping_force(&self, x_m: f64, y_m: f64) -> [f64; 2] {
        let g = self.repulsive_gradient(x_m, y_m);
        let pull = self.moving_target_gradient(x_m, y_m);
        [-(g[0] + pull[0]), -(g[1] + pull[1])]
    }

    /// [`PotentialField::stepping_force`] with every obstacle moved along its velocity for
    /// `elapsed_s` (constant-velocity prediction; 0 gives the current positions).
    pub(crate) fn stepping_force_at(&self, x_m: f64, y_m: f64, elapsed_s: f64) -> [f64; 2] {
        if elapsed_s == 0.0 {
            return self.stepping_force(x_m, y_m);
        }
        let mut g = self.road.gradient(x_m, y_m);
        for (o, v) in self.obstacles.iter().zip(&self.obstacle_velocities_mps) {
            // The field moves with the obstacle: evaluate it at the point shifted back.
            let go = o.gradient(x_m - v[0] * elapsed_s, y_m - v[1] * elapsed_s);
            g[0] += go[0];
            g[1] += go[1];
        }
        let pull = self.moving_target_gradient(x_m, y_m);
        [-(g[0] + pull[0]), -(g[1] + pull[1])]
    }

    /// Samples U (with or without the attraction) on a grid, row after row.
    pub(crate) fn grid(
        &self,
        spec: &GridSpec,
        include_attractive: bool,
    ) -> Result<Vec<f64>, PlannerError> {
        spec.validate()?;
        let mut values = Vec::with_capacity(spec.columns * spec.rows);
        for row in 0..spec.rows {
            let y_m = spec.y_min_m + (row as f64 + 0.5) * spec.cell_m;
            for col in 0..spec.columns {
                let x_m = spec.x_min_m + (col as f64 + 0.5) * spec.cell_m;
                values.push(if include_attractive {
                    self.value(x_m, y_m)
                } else {
                    self.repulsive_value(x_m, y_m)
                });
            }
        }
        Ok(values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::PlannerParams;

    fn state(x_m: f64, y_m: f64, yaw_rad: f64, speed_mps: f64) -> VehicleState {
        VehicleState {
            x_m,
            y_m,
            yaw_rad,
            speed_mps,
        }
    }

    #[test]
    fn universal_gradient_matches_central_differences() {
        let params = UniversalFieldParams::from(&PlannerParams::default());
        let merge = mergesim_types::MergeRoad::default();
        let road = LaneRoadGeometry::new(&merge.lane_road().unwrap());
        let neighbours = [
            Neighbour {
                id: 1,
                state: state(40.0, 5.25, 0.05, 15.0),
                shape: VehicleShape::default(),
            },
            Neighbour {
                id: 2,
                state: state(10.0, 1.9, -0.1, 22.0),
                shape: VehicleShape::default(),
            },
        ];
        let ego = state(20.0, 1.75, 0.0, 20.0);
        let field = PotentialField::new(
            &params,
            &road,
            0,
            &ego,
            &VehicleShape::default(),
            &neighbours,
        );
        assert_eq!(field.obstacles.len(), 2);
        let h = 1e-6;
        for (x, y) in [
            (25.0, 2.0),
            (38.0, 3.5),
            (45.0, 4.9),
            (12.0, 2.6),
            (180.0, 2.5),
        ] {
            let g = field.gradient(x, y);
            let fx = (field.value(x + h, y) - field.value(x - h, y)) / (2.0 * h);
            let fy = (field.value(x, y + h) - field.value(x, y - h)) / (2.0 * h);
            assert!(
                (g[0] - fx).abs() < 1e-6 * (1.0 + fx.abs()),
                "({x},{y}) x: {} vs {fx}",
                g[0]
            );
            assert!(
                (g[1] - fy).abs() < 1e-6 * (1.0 + fy.abs()),
                "({x},{y}) y: {} vs {fy}",
                g[1]
            );
        }
    }

    /// With the default gains the lateral force vanishes within a few centimetres of each
    /// lane centre (found by bisection on F_y), and pushes back towards it on either side.
    #[test]
    fn default_lane_equilibria_sit_at_the_lane_centres() {
        let params = UniversalFieldParams::from(&PlannerParams::default());
        let merge = mergesim_types::MergeRoad::default();
        let road = LaneRoadGeometry::new(&merge.lane_road().unwrap());
        let ego = state(0.0, 1.75, 0.0, 20.0);
        let field = PotentialField::new(&params, &road, 0, &ego, &VehicleShape::default(), &[]);
        for lane in [mergesim_types::Lane::Lower, mergesim_types::Lane::Upper] {
            let centre = merge.lane_center_y_m(lane);
            let fy = |y: f64| field.stepping_force(50.0, y)[1];
            let (mut lo, mut hi) = (centre - 0.6, centre + 0.6);
            assert!(fy(lo) > 0.0 && fy(hi) < 0.0, "restoring on both sides");
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if fy(mid) > 0.0 { lo = mid } else { hi = mid }
            }
            assert!((lo - centre).abs() < 0.05, "{lane:?}: equilibrium at {lo}");
        }
    }

    #[test]
    fn own_entry_among_neighbours_is_skipped() {
        let params = UniversalFieldParams::from(&PlannerParams::default());
        let merge = mergesim_types::MergeRoad::default();
        let road = LaneRoadGeometry::new(&merge.lane_road().unwrap());
        let ego = state(0.0, 1.75, 0.0, 20.0);
        let neighbours = [Neighbour {
            id: 7,
            state: ego,
            shape: VehicleShape::default(),
        }];
        let field = PotentialField::new(
            &params,
            &road,
            7,
            &ego,
            &VehicleShape::default(),
            &neighbours,
        );
        assert!(field.obstacles.is_empty());
    }

    #[test]
    fn grid_samples_cell_centres_row_after_row() {
        let params = UniversalFieldParams::from(&PlannerParams::default());
        let merge = mergesim_types::MergeRoad::default();
        let road = LaneRoadGeometry::new(&merge.lane_road().unwrap());
        let ego = state(0.0, 1.75, 0.0, 20.0);
        let field = PotentialField::new(&params, &road, 0, &ego, &VehicleShape::default(), &[]);
        let spec = GridSpec {
            x_min_m: -10.0,
            y_min_m: 0.0,
            cell_m: 0.5,
            columns: 7,
            rows: 3,
        };
        let values = field.grid(&spec, true).unwrap();
        assert_eq!(values.len(), 21);
        // Row 2, column 5 is at (−10 + 5.5·0.5, 0 + 2.5·0.5).
        assert_eq!(values[2 * 7 + 5], field.value(-7.25, 1.25));
        let bad = GridSpec {
            cell_m: 0.0,
            ..spec
        };
        assert!(field.grid(&bad, true).is_err());
    }
}
