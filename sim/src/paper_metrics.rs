//! The paper's per-vehicle findings as numbers (Lin et al., Sec. V): when a vehicle starts
//! slowing, how much it winds inside the merge zone against outside it, how far it strays from
//! its lane centre, and where and when it crosses the lane divider.
//!
//! Fed the same samples as [`crate::metrics::VehicleMetrics`] (one per logged instant), and read
//! through the road of lanes (`crate::lane_membership`), so they mean the same on any road:
//! - **slowing onset**: the first sample more than `slowing_threshold_mps` below the vehicle's
//!   target speed (tracker noise stays within a few cm/s);
//! - **yaw-rate RMS inside / outside the merge zone**: √(∫ r² dt / T) over the intervals whose
//!   midpoint lies inside (outside) the merge zone, r linear between samples (exact integral);
//!   the paper sees the winding between 167 and 272 m, i.e. in the merge section (160–260 m
//!   here) and just after it, so the zone is the ending lane's taper and the 20 m after its end
//!   (one second at 20 m/s, where a path that left the taper settles), measured along the lane
//!   it merges into (`MergeZone`); on a road without an ending lane there is none (every
//!   interval is outside, and `merge_zone_x_m` is `[0, 0]`);
//! - **largest lateral offset from its lane centre**: the distance, in the lane's frame, from the
//!   middle between the two bounds of the lane the vehicle is in (lane membership with
//!   hysteresis): on the merge road, above the divider the through lane's centre, below it
//!   halfway between the tapering lower edge and the divider;
//! - **divider crossing**: the first lane change (the lane membership changing to a lane that is
//!   not a successor), with t and x interpolated linearly between the samples on the crossed
//!   bound, and how many lane changes it made, in either direction.

use std::sync::Arc;

use mergesim_types::lanes::{LaneId, LaneRoad};
use serde::{Deserialize, Serialize};

use crate::lane_membership::{MergeZone, beyond_divider_m, lane_change, lane_of};
use crate::outcome::TimeSeriesRow;

pub use crate::lane_membership::MERGE_ZONE_TAIL_M;

/// A speed drop below the target smaller than this is tracker noise, not slowing (m/s).
pub(crate) const SLOWING_THRESHOLD_MPS: f64 = 0.1;

/// Where and when a vehicle crossed the lane divider.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DividerCrossing {
    /// Time (s).
    pub t_s: f64,
    /// Longitudinal position (m).
    pub x_m: f64,
}

/// The paper's figures of one vehicle (module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PaperMetricsSummary {
    /// Target speed the onset is measured against (m/s).
    pub target_speed_mps: f64,
    /// First time more than 0.1 m/s below the target speed (s); null if never.
    pub slowing_onset_s: Option<f64>,
    /// The world x of the merge zone's ends `[x_start_m, x_end_m]` (module doc).
    pub merge_zone_x_m: [f64; 2],
    /// Yaw-rate RMS over the time spent inside the merge zone (rad/s); null if never inside.
    pub merge_zone_rms_yaw_rate_radps: Option<f64>,
    /// Yaw-rate RMS over the time spent outside it (rad/s); null if never outside.
    pub outside_merge_zone_rms_yaw_rate_radps: Option<f64>,
    /// Time spent inside the merge zone (s).
    pub merge_zone_time_s: f64,
    /// Largest distance from the middle of the lane it is in (m, in the lane's frame).
    pub max_abs_lane_offset_m: f64,
    /// First crossing of the lane divider; null if never.
    pub divider_crossing: Option<DividerCrossing>,
    /// Number of lane changes (divider crossings, either way).
    pub divider_crossings: u32,
}

/// Running paper metrics of one vehicle.
#[derive(Clone, Debug)]
pub(crate) struct PaperMetrics {
    lanes: Arc<LaneRoad>,
    zone: Option<MergeZone>,
    target_speed_mps: f64,
    last: Option<TimeSeriesRow>,
    lane: Option<LaneId>,
    slowing_onset_s: Option<f64>,
    zone_integral_sq: f64,
    zone_time_s: f64,
    outside_integral_sq: f64,
    outside_time_s: f64,
    max_abs_lane_offset_m: f64,
    divider_crossing: Option<DividerCrossing>,
    divider_crossings: u32,
}

impl PaperMetrics {
    /// Empty metrics of a vehicle with `target_speed_mps` on `lanes`; the merge zone is the
    /// ending lane's taper and [`MERGE_ZONE_TAIL_M`] after its end (module doc).
    pub(crate) fn new(lanes: Arc<LaneRoad>, target_speed_mps: f64) -> Self {
        Self {
            zone: MergeZone::of(&lanes),
            lanes,
            target_speed_mps,
            last: None,
            lane: None,
            slowing_onset_s: None,
            zone_integral_sq: 0.0,
            zone_time_s: 0.0,
            outside_integral_sq: 0.0,
            outside_time_s: 0.0,
            max_abs_lane_offset_m: 0.0,
            divider_crossing: None,
            divider_crossings: 0,
        }
    }

    /// Adds the next sample (the caller checks finiteness and increasing time).
    pub fn push(&mut self, s: &TimeSeriesRow) {
        if self.slowing_onset_s.is_none()
            && s.speed_mps < self.target_speed_mps - SLOWING_THRESHOLD_MPS
        {
            self.slowing_onset_s = Some(s.t_s);
        }
        let hit = lane_of(&self.lanes, self.lane, [s.x_m, s.y_m]);
        if let Some(lane) = self.lanes.lane(hit.lane) {
            let mid_d_m = 0.5 * (lane.left_d_m(hit.frame.s_m) + lane.right_d_m(hit.frame.s_m));
            let offset = (hit.frame.d_m - mid_d_m).abs();
            self.max_abs_lane_offset_m = self.max_abs_lane_offset_m.max(offset);
        }
        if let Some(p) = &self.last {
            let dt_s = s.t_s - p.t_s;
            let (r0, r1) = (p.yaw_rate_radps, s.yaw_rate_radps);
            let integral_sq = dt_s * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0;
            let mid_m = [0.5 * (p.x_m + s.x_m), 0.5 * (p.y_m + s.y_m)];
            let inside = self
                .zone
                .as_ref()
                .is_some_and(|z| z.contains(&self.lanes, mid_m));
            if inside {
                self.zone_integral_sq += integral_sq;
                self.zone_time_s += dt_s;
            } else {
                self.outside_integral_sq += integral_sq;
                self.outside_time_s += dt_s;
            }
            if let Some(from) = self.lane
                && lane_change(&self.lanes, from, hit.lane).is_some()
            {
                self.divider_crossings += 1;
                if self.divider_crossing.is_none() {
                    // Linear between the samples, on the bound between the two lanes.
                    let f = match (
                        beyond_divider_m(&self.lanes, from, hit.lane, [p.x_m, p.y_m]),
                        beyond_divider_m(&self.lanes, from, hit.lane, [s.x_m, s.y_m]),
                    ) {
                        (Some(g0), Some(g1)) if g1 != g0 => (g0 / (g0 - g1)).clamp(0.0, 1.0),
                        _ => 1.0,
                    };
                    self.divider_crossing = Some(DividerCrossing {
                        t_s: p.t_s + f * dt_s,
                        x_m: p.x_m + f * (s.x_m - p.x_m),
                    });
                }
            }
        }
        self.lane = Some(hit.lane);
        self.last = Some(s.clone());
    }

    /// The figures so far.
    pub(crate) fn summary(&self) -> PaperMetricsSummary {
        let rms = |integral: f64, time_s: f64| (time_s > 0.0).then(|| (integral / time_s).sqrt());
        PaperMetricsSummary {
            target_speed_mps: self.target_speed_mps,
            slowing_onset_s: self.slowing_onset_s,
            merge_zone_x_m: self.zone.as_ref().map_or([0.0, 0.0], |z| z.x_m),
            merge_zone_rms_yaw_rate_radps: rms(self.zone_integral_sq, self.zone_time_s),
            outside_merge_zone_rms_yaw_rate_radps: rms(
                self.outside_integral_sq,
                self.outside_time_s,
            ),
            merge_zone_time_s: self.zone_time_s,
            max_abs_lane_offset_m: self.max_abs_lane_offset_m,
            divider_crossing: self.divider_crossing,
            divider_crossings: self.divider_crossings,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mergesim_types::MergeRoad;

    fn sample(t_s: f64, x_m: f64, y_m: f64, r: f64, v: f64) -> TimeSeriesRow {
        TimeSeriesRow {
            t_s,
            vehicle: "ego".into(),
            x_m,
            y_m,
            yaw_rad: 0.0,
            yaw_rate_radps: r,
            sideslip_rad: 0.0,
            speed_mps: v,
            planned_speed_mps: v,
            accel_long_mps2: 0.0,
            accel_lat_mps2: 0.0,
        }
    }

    #[test]
    fn onset_zone_rms_offset_and_crossing() {
        let lanes = Arc::new(MergeRoad::default().lane_road().unwrap());
        let mut m = PaperMetrics::new(lanes, 15.0);
        // 0–10 s at x = 150 → 250 m, constant yaw rate 0.02 inside the zone (from 160 m), 0
        // outside; slowing below 14.9 m/s from t = 4 s; crossing the divider at t = 5.5 s.
        for k in 0..=100 {
            let t = 0.1 * k as f64;
            let x = 150.0 + 10.0 * t;
            let r = if x > 160.0 { 0.02 } else { 0.0 };
            let v = if t >= 4.0 { 14.8 } else { 15.0 };
            let y = if t <= 5.0 { 3.0 } else { 4.0 };
            m.push(&sample(t, x, y, r, v));
        }
        let s = m.summary();
        assert_eq!(s.slowing_onset_s, Some(4.0));
        assert_eq!(s.merge_zone_x_m, [160.0, 280.0]);
        // Intervals with mean x > 160 m: all but the first 1 s (9 s inside at r = 0.02 except
        // the interval straddling 160 m, whose r goes 0 → 0.02).
        let inside = s.merge_zone_rms_yaw_rate_radps.unwrap();
        assert!((inside - 0.02).abs() < 2e-4, "{inside}");
        assert_eq!(s.outside_merge_zone_rms_yaw_rate_radps, Some(0.0));
        assert!((s.merge_zone_time_s - 9.0).abs() < 1e-9);
        let crossing = s.divider_crossing.unwrap();
        assert!((crossing.t_s - 5.05).abs() < 1e-9, "{crossing:?}");
        assert!((crossing.x_m - 200.5).abs() < 1e-9);
        assert_eq!(s.divider_crossings, 1);
        // Lower lane at x = 150: centre 1.75 → offset 1.25 at y = 3; upper lane (5.25) at y = 4.
        assert!((s.max_abs_lane_offset_m - 1.25).abs() < 1e-9);
    }

    #[test]
    fn never_slowing_nor_crossing_gives_nulls() {
        let lanes = Arc::new(MergeRoad::default().lane_road().unwrap());
        let mut m = PaperMetrics::new(lanes, 15.0);
        for k in 0..10 {
            m.push(&sample(k as f64, 10.0 * k as f64, 5.25, 0.0, 15.0));
        }
        let s = m.summary();
        assert_eq!(s.slowing_onset_s, None);
        assert_eq!(s.divider_crossing, None);
        assert_eq!(s.merge_zone_rms_yaw_rate_radps, None);
        assert_eq!(s.max_abs_lane_offset_m, 0.0);
    }
}
