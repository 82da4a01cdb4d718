//! Ready-made roads of lanes for the built-ins and the tests: the merge road (straight or bent
//! on a circular arc) and an on-ramp with a parallel acceleration lane.

use serde::{Deserialize, Serialize};

use super::spec::{LaneId, LaneKind, LaneRoadSpec, LaneSpec, LaneTolerances};
use crate::bounds::{Bound, check_all};
use crate::error::InvalidParameter;
use crate::road::MergeRoad;

/// Id of the merge road's through lane (the upper lane, [`crate::Lane::Upper`]).
pub const THROUGH_LANE_ID: LaneId = LaneId(1);
/// Id of the merge road's ending lane (the lower lane, [`crate::Lane::Lower`]).
pub const ENDING_LANE_ID: LaneId = LaneId(2);

/// Longest chord used to sample a circular arc (m): 1 m keeps the polyline within
/// 1/(8R) m (0.4 mm at R = 300 m) of the arc.
pub const ARC_STEP_M: f64 = 1.0;

/// Breakpoints `knots` densified so that no step exceeds `step_m` (`step_m` = ∞: the knots).
fn densify(knots: &[f64], step_m: f64) -> Vec<f64> {
    let mut out = vec![knots[0]];
    for w in knots.windows(2) {
        let n = if step_m.is_finite() {
            ((w[1] - w[0]) / step_m).ceil().max(1.0) as usize
        } else {
            1
        };
        out.extend((1..=n).map(|k| w[0] + (w[1] - w[0]) * k as f64 / n as f64));
    }
    out
}

/// The merge road's two lanes in its straight frame (x along, y to the left), with every x
/// mapped through `map` and sampled at most `step_m` apart. The ending lane's right bound is
/// the lower edge of Eq. 3 (the taper crosses its centreline: right width from +w/2 to −w/2).
fn merge_lanes(road: &MergeRoad, step_m: f64, map: &dyn Fn(f64, f64) -> [f64; 2]) -> LaneRoadSpec {
    let w = road.lane_width_m;
    let y_up = road.lane_center_y_m(crate::Lane::Upper);
    let y_low = road.lane_center_y_m(crate::Lane::Lower);
    let through_x = densify(&[road.start_x_m, road.end_x_m], step_m);
    let ending_x = densify(
        &[road.start_x_m, road.merge_start_x_m, road.merge_end_x_m],
        step_m,
    );
    let through = LaneSpec {
        right: Some(ENDING_LANE_ID),
        ..LaneSpec::new(
            THROUGH_LANE_ID,
            through_x.iter().map(|&x| map(x, y_up)).collect(),
            w,
        )
    };
    // Right width: distance from the centre line down to the lower edge (negative in the taper
    // once the edge has crossed the centre line).
    let right_width_m: Vec<f64> = ending_x
        .iter()
        // The taper's tip has width 0; keep rounding from making it negative.
        .map(|&x| (y_low - road.lower_edge_y_m(x)).max(-0.5 * w))
        .collect();
    let ending = LaneSpec {
        id: ENDING_LANE_ID,
        kind: LaneKind::Main,
        centreline_m: ending_x.iter().map(|&x| map(x, y_low)).collect(),
        width_m: Vec::new(),
        left_width_m: vec![0.5 * w],
        right_width_m,
        left: Some(THROUGH_LANE_ID),
        right: None,
        successors: Vec::new(),
        predecessors: Vec::new(),
    };
    LaneRoadSpec {
        lanes: vec![through, ending],
        tolerances: LaneTolerances::default(),
    }
}

/// The straight merge road as lanes: the through lane (id 1) and the ending lane (id 2), whose
/// right bound is the piecewise lower edge of Eq. 3 and which ends, closed, at `merge_end_x_m`.
pub fn merge_road_spec(road: &MergeRoad) -> LaneRoadSpec {
    merge_lanes(road, f64::INFINITY, &|x, y| [x, y])
}

/// The merge road bent on a circular arc turning left: the divider (y = `y_lane_m`) becomes an
/// arc of radius `radius_m` starting at (0, y_lane) heading +x; a point (x, y) of the straight
/// road goes to angle x / R on the circle of radius R − (y − y_lane) about (0, y_lane + R), so
/// lateral offsets are kept and arc length along the divider equals x. Centrelines are sampled
/// at most [`ARC_STEP_M`] apart (on the divider's scale). A negative radius turns right.
///
/// Refused (naming the field): a road [`MergeRoad::validate`] refuses, or |radius| outside
/// [`CURVED_MERGE_RADIUS_M`](crate::lanes::CURVED_MERGE_RADIUS_M) or smaller than the road's length / 6 (the lanes must not turn
/// further than 6 rad).
pub fn curved_merge_spec(
    road: &MergeRoad,
    radius_m: f64,
) -> Result<LaneRoadSpec, InvalidParameter> {
    road.validate()?;
    let [lo, hi] = CURVED_MERGE_RADIUS_M;
    let length_m = road.end_x_m - road.start_x_m;
    if !(radius_m.is_finite() && (lo..=hi).contains(&radius_m.abs()))
        || length_m / radius_m.abs() > 6.0
    {
        return Err(InvalidParameter::new(
            "radius_m",
            radius_m,
            format!(
                "|radius| must lie in [{lo}, {hi}] m and be at least the road's length / 6 ({} m)",
                length_m / 6.0
            ),
        ));
    }
    let y_lane = road.y_lane_m();
    Ok(merge_lanes(road, ARC_STEP_M, &|x, y| {
        let phi = x / radius_m;
        let r = radius_m - (y - y_lane);
        [r * phi.sin(), y_lane + radius_m - r * phi.cos()]
    }))
}

/// Allowed |radius| of [`curved_merge_spec`] (m).
pub const CURVED_MERGE_RADIUS_M: [f64; 2] = [20.0, 100_000.0];

/// An on-ramp: a two-lane main road along +x with a parallel acceleration lane on its right,
/// entered from a ramp on a circular arc.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OnRampParams {
    /// Width of every lane (m).
    pub lane_width_m: f64,
    /// Radius of the ramp's arc (m); it turns right onto the acceleration lane, tangent to it.
    pub ramp_radius_m: f64,
    /// Angle the ramp turns through (rad).
    pub ramp_angle_rad: f64,
    /// Where the acceleration lane begins (m, x on the main road).
    pub accel_start_x_m: f64,
    /// Length of the acceleration lane at full width (m).
    pub accel_length_m: f64,
    /// Length of its taper (m); 0 ends it square, closed by an edge across its end.
    pub taper_length_m: f64,
    /// Length of the main road from x = 0 (m).
    pub main_length_m: f64,
}

impl Default for OnRampParams {
    fn default() -> Self {
        Self {
            lane_width_m: 3.5,
            ramp_radius_m: 150.0,
            ramp_angle_rad: 0.35,
            accel_start_x_m: 150.0,
            accel_length_m: 250.0,
            taper_length_m: 50.0,
            main_length_m: 650.0,
        }
    }
}

/// Allowed ranges of [`OnRampParams`].
pub const ON_RAMP_BOUNDS: &[Bound] = &[
    Bound::closed("lane_width_m", 2.0, 6.0, "m"),
    Bound::closed("ramp_radius_m", 20.0, 10_000.0, "m"),
    Bound::closed("ramp_angle_rad", 0.01, 1.6, "rad"),
    Bound::closed("accel_start_x_m", 0.0, 10_000.0, "m"),
    Bound::closed("accel_length_m", 10.0, 5_000.0, "m"),
    Bound::closed("taper_length_m", 0.0, 1_000.0, "m"),
    Bound::closed("main_length_m", 10.0, 20_000.0, "m"),
];

impl OnRampParams {
    /// Checks every field against [`ON_RAMP_BOUNDS`](crate::lanes::ON_RAMP_BOUNDS), and that the main road reaches past the
    /// acceleration lane and the ramp starts at x ≥ 0.
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        check_all(
            "on_ramp",
            ON_RAMP_BOUNDS,
            &[
                ("lane_width_m", self.lane_width_m),
                ("ramp_radius_m", self.ramp_radius_m),
                ("ramp_angle_rad", self.ramp_angle_rad),
                ("accel_start_x_m", self.accel_start_x_m),
                ("accel_length_m", self.accel_length_m),
                ("taper_length_m", self.taper_length_m),
                ("main_length_m", self.main_length_m),
            ],
        )?;
        let accel_end_m = self.accel_start_x_m + self.accel_length_m + self.taper_length_m;
        if self.main_length_m <= accel_end_m {
            return Err(InvalidParameter::new(
                "on_ramp.main_length_m",
                self.main_length_m,
                format!("must exceed the acceleration lane's end, x = {accel_end_m} m"),
            ));
        }
        let ramp_start_x_m = self.accel_start_x_m - self.ramp_radius_m * self.ramp_angle_rad.sin();
        if ramp_start_x_m < 0.0 {
            return Err(InvalidParameter::new(
                "on_ramp.accel_start_x_m",
                self.accel_start_x_m,
                format!("the ramp would start at x = {ramp_start_x_m:.1} m, before the main road"),
            ));
        }
        Ok(())
    }
}

/// Ids of the on-ramp road's lanes.
pub mod on_ramp_ids {
    use super::LaneId;
    /// Main road, left lane.
    pub const MAIN_LEFT: LaneId = LaneId(1);
    /// Main road, right lane.
    pub const MAIN_RIGHT: LaneId = LaneId(2);
    /// The acceleration lane.
    pub const ACCELERATION: LaneId = LaneId(3);
    /// The ramp.
    pub const RAMP: LaneId = LaneId(4);
}

/// The on-ramp road: main lanes 1 (left, centre y = 1.5 w) and 2 (right, y = 0.5 w) from x = 0
/// to `main_length_m`; the acceleration lane 3 (centre y = −0.5 w) from `accel_start_x_m`,
/// `accel_length_m` at full width, then its taper; the ramp 4, an arc of `ramp_radius_m` turning
/// right through `ramp_angle_rad` to meet lane 3's start tangentially (sampled ≤ 1 m apart).
/// Refused (naming the field) when [`OnRampParams::validate`] refuses.
pub fn on_ramp_spec(p: &OnRampParams) -> Result<LaneRoadSpec, InvalidParameter> {
    use on_ramp_ids::*;
    p.validate()?;
    let w = p.lane_width_m;
    let main = |id, y, left, right| LaneSpec {
        left,
        right,
        ..LaneSpec::new(id, vec![[0.0, y], [p.main_length_m, y]], w)
    };
    let a0 = p.accel_start_x_m;
    let a1 = a0 + p.accel_length_m;
    let mut accel_x = vec![a0, a1];
    let mut accel_right = vec![0.5 * w, 0.5 * w];
    if p.taper_length_m > 0.0 {
        accel_x.push(a1 + p.taper_length_m);
        accel_right.push(-0.5 * w);
    }
    let accel = LaneSpec {
        id: ACCELERATION,
        kind: LaneKind::Entry,
        centreline_m: accel_x.iter().map(|&x| [x, -0.5 * w]).collect(),
        width_m: Vec::new(),
        left_width_m: vec![0.5 * w],
        right_width_m: accel_right,
        left: Some(MAIN_RIGHT),
        right: None,
        successors: Vec::new(),
        predecessors: vec![RAMP],
    };
    // Right turn about (a0, −w/2 − R): φ from −angle to 0, position C + R (sin φ, cos φ).
    let r = p.ramp_radius_m;
    let n = ((r * p.ramp_angle_rad) / ARC_STEP_M).ceil().max(1.0) as usize;
    let ramp_pts: Vec<[f64; 2]> = (0..=n)
        .map(|k| {
            let phi = -p.ramp_angle_rad * (1.0 - k as f64 / n as f64);
            [a0 + r * phi.sin(), -0.5 * w - r + r * phi.cos()]
        })
        .collect();
    let ramp = LaneSpec {
        kind: LaneKind::Entry,
        successors: vec![ACCELERATION],
        ..LaneSpec::new(RAMP, ramp_pts, w)
    };
    Ok(LaneRoadSpec {
        lanes: vec![
            main(MAIN_LEFT, 1.5 * w, None, Some(MAIN_RIGHT)),
            main(MAIN_RIGHT, 0.5 * w, Some(MAIN_LEFT), Some(ACCELERATION)),
            accel,
            ramp,
        ],
        tolerances: LaneTolerances::default(),
    })
}
