//! A vehicle's body as an oriented box in the plane, placed in a lane's frame, for the spawn
//! checks on a road of lanes (on the road, no overlap).

use mergesim_types::lanes::Lane;

/// A rectangle: centre, unit axis along its length, half length and half width (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct OrientedBox {
    /// Centre (m).
    pub centre_m: [f64; 2],
    /// Unit vector along the length.
    pub axis: [f64; 2],
    /// Half length (m).
    pub half_length_m: f64,
    /// Half width (m).
    pub half_width_m: f64,
}

impl OrientedBox {
    /// The body centred at (s, d) of `lane`, along the lane's heading at s.
    pub(crate) fn on_lane(
        lane: &Lane,
        s_m: f64,
        d_m: f64,
        half_length_m: f64,
        half_width_m: f64,
    ) -> Self {
        let (sin, cos) = lane.heading_rad(s_m).sin_cos();
        Self {
            centre_m: lane.point(s_m, d_m),
            axis: [cos, sin],
            half_length_m,
            half_width_m,
        }
    }

    /// The four corners.
    pub(crate) fn corners(&self) -> [[f64; 2]; 4] {
        let [c, a] = [self.centre_m, self.axis];
        let n = [-a[1], a[0]];
        let corner = |l: f64, w: f64| {
            [
                c[0] + l * self.half_length_m * a[0] + w * self.half_width_m * n[0],
                c[1] + l * self.half_length_m * a[1] + w * self.half_width_m * n[1],
            ]
        };
        [
            corner(1.0, 1.0),
            corner(1.0, -1.0),
            corner(-1.0, -1.0),
            corner(-1.0, 1.0),
        ]
    }

    /// True if the two rectangles overlap (separating-axis test; touching counts as apart).
    pub(crate) fn overlaps(&self, other: &Self) -> bool {
        let axes = [
            self.axis,
            [-self.axis[1], self.axis[0]],
            other.axis,
            [-other.axis[1], other.axis[0]],
        ];
        let (ca, cb) = (self.corners(), other.corners());
        axes.iter().all(|ax| {
            let project = |cs: &[[f64; 2]; 4]| {
                cs.iter()
                    .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], c| {
                        let p = c[0] * ax[0] + c[1] * ax[1];
                        [lo.min(p), hi.max(p)]
                    })
            };
            let ([a0, a1], [b0, b1]) = (project(&ca), project(&cb));
            a0 < b1 && b0 < a1
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b(x: f64, y: f64, heading: f64) -> OrientedBox {
        OrientedBox {
            centre_m: [x, y],
            axis: [heading.cos(), heading.sin()],
            half_length_m: 2.0,
            half_width_m: 1.0,
        }
    }

    #[test]
    fn overlap_by_separating_axes() {
        assert!(b(0.0, 0.0, 0.0).overlaps(&b(3.0, 0.0, 0.0)));
        assert!(!b(0.0, 0.0, 0.0).overlaps(&b(4.5, 0.0, 0.0)));
        // Side by side in neighbouring lanes at 45°: apart, although their x-y hulls overlap.
        let h = std::f64::consts::FRAC_PI_4;
        let n = [-h.sin(), h.cos()];
        assert!(!b(0.0, 0.0, h).overlaps(&b(3.5 * n[0], 3.5 * n[1], h)));
        assert!(b(0.0, 0.0, h).overlaps(&b(1.5 * n[0], 1.5 * n[1], h)));
    }
}
