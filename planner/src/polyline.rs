//! A polyline parametrised by arc length: the ego's planned path in the interaction term
//! (Eq. 10) and the geometry of the fallback plan.

/// Points with their cumulative arc length.
#[derive(Clone, Debug, PartialEq)]
pub struct Polyline {
    points: Vec<[f64; 2]>,
    arc_m: Vec<f64>,
}

impl Polyline {
    /// A polyline through `points` (at least one). Repeated points are kept (zero-length
    /// segments are skipped when looking up tangents).
    pub fn new(points: Vec<[f64; 2]>) -> Option<Self> {
        let mut iter = points.into_iter();
        let start = iter.next()?;
        Some(Self::with_start(start, iter))
    }

    /// A polyline starting at `start` (never empty, so this cannot fail).
    pub(crate) fn with_start(start: [f64; 2], rest: impl IntoIterator<Item = [f64; 2]>) -> Self {
        let mut points = vec![start];
        points.extend(rest);
        let mut arc_m = Vec::with_capacity(points.len());
        let mut s = 0.0;
        arc_m.push(0.0);
        for w in points.windows(2) {
            s += ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt();
            arc_m.push(s);
        }
        Self { points, arc_m }
    }

    /// The vertices.
    pub(crate) fn points(&self) -> &[[f64; 2]] {
        &self.points
    }

    /// Cumulative arc length at each vertex (m).
    pub(crate) fn arc_lengths_m(&self) -> &[f64] {
        &self.arc_m
    }

    /// Total length (m).
    pub fn length_m(&self) -> f64 {
        self.arc_m.last().copied().unwrap_or(0.0)
    }

    /// Lengths of the segments (m), one fewer than the points.
    pub(crate) fn segment_lengths_m(&self) -> Vec<f64> {
        self.arc_m.windows(2).map(|w| w[1] - w[0]).collect()
    }

    /// Point and unit tangent at arc length `s_m`. Before the start and past the end the
    /// polyline continues straight along its first / last non-degenerate segment; a polyline
    /// of one point (or of coincident points) has tangent `fallback_tangent`.
    pub(crate) fn point_and_tangent(
        &self,
        s_m: f64,
        fallback_tangent: [f64; 2],
    ) -> ([f64; 2], [f64; 2]) {
        let n = self.points.len();
        // Index k of the segment [k, k+1] holding s (clamped to the first / last).
        let k = self
            .arc_m
            .partition_point(|&a| a <= s_m)
            .saturating_sub(1)
            .min(n.saturating_sub(2));
        // Find a non-degenerate segment at or around k.
        let segment = (k..n.saturating_sub(1))
            .chain((0..k).rev())
            .find(|&j| self.arc_m[j + 1] - self.arc_m[j] > 1e-9);
        let Some(j) = segment else {
            return (self.points[0], fallback_tangent);
        };
        let length = self.arc_m[j + 1] - self.arc_m[j];
        let a = self.points[j];
        let b = self.points[j + 1];
        let tangent = [(b[0] - a[0]) / length, (b[1] - a[1]) / length];
        let along = s_m - self.arc_m[j];
        (
            [a[0] + along * tangent[0], a[1] + along * tangent[1]],
            tangent,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_extrapolates_by_arc_length() {
        let line = Polyline::new(vec![[0.0, 0.0], [3.0, 4.0], [3.0, 4.0], [3.0, 10.0]]).unwrap();
        assert_eq!(line.length_m(), 11.0);
        let (p, t) = line.point_and_tangent(2.5, [1.0, 0.0]);
        assert!((p[0] - 1.5).abs() < 1e-12 && (p[1] - 2.0).abs() < 1e-12);
        assert!((t[0] - 0.6).abs() < 1e-12 && (t[1] - 0.8).abs() < 1e-12);
        let (p, t) = line.point_and_tangent(13.0, [1.0, 0.0]);
        assert!((p[0] - 3.0).abs() < 1e-12 && (p[1] - 12.0).abs() < 1e-12);
        assert_eq!(t, [0.0, 1.0]);
        let (p, _) = line.point_and_tangent(-1.0, [1.0, 0.0]);
        assert!((p[0] + 0.6).abs() < 1e-12 && (p[1] + 0.8).abs() < 1e-12);
    }

    #[test]
    fn single_point_uses_the_fallback_tangent() {
        let line = Polyline::new(vec![[1.0, 2.0]]).unwrap();
        assert_eq!(
            line.point_and_tangent(5.0, [0.0, 1.0]),
            ([1.0, 2.0], [0.0, 1.0])
        );
    }
}
