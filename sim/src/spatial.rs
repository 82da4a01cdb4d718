//! Which vehicles are near which, without looking at every pair: the vehicles sorted by X (a
//! highway is long and narrow) and swept with a window, O(N log N + k) for k pairs found.
//!
//! Every query has a brute-force twin over all pairs that applies the *same* predicate, and the
//! two give identical answers (tests): the sweep only skips pairs whose X distance exceeds the
//! window, and the window is a bound of the predicate, so no pair the predicate accepts is ever
//! skipped. Floating-point subtraction is monotone and exactly antisymmetric, so once
//! `x_j − x_i` exceeds the window in sorted order, it does for every later `j`; equal X (ties)
//! are ordered by index. Results come out in index (= vehicle id) order, so everything built
//! from them is independent of the sort and of the thread count.

/// Whether the centres `a` and `b` are within `range_m` of each other (Euclidean; a distance
/// equal to the range is within). The X test comes first so that the sweep's window (X only)
/// is exactly the first half of the predicate.
pub(crate) fn within_range(a: [f64; 2], b: [f64; 2], range_m: f64) -> bool {
    let dx = b[0] - a[0];
    dx.abs() <= range_m && dx.hypot(b[1] - a[1]) <= range_m
}

/// The vehicles' X, sorted once, for any number of window queries.
#[derive(Clone, Debug, Default)]
pub(crate) struct XSweep {
    /// Indices sorted by (X, index).
    order: Vec<usize>,
    /// Rank of each index in `order`.
    rank: Vec<usize>,
    /// X of each index.
    xs: Vec<f64>,
}

impl XSweep {
    /// Sorts `xs` (finite values; a NaN sorts last and is never within a window).
    pub(crate) fn new(xs: &[f64]) -> Self {
        let mut order: Vec<usize> = (0..xs.len()).collect();
        order.sort_by(|&a, &b| xs[a].total_cmp(&xs[b]).then(a.cmp(&b)));
        let mut rank = vec![0; xs.len()];
        for (r, &i) in order.iter().enumerate() {
            rank[i] = r;
        }
        Self {
            order,
            rank,
            xs: xs.to_vec(),
        }
    }

    /// Every index `j ≠ i` with |x_j − x_i| ≤ `window_m`, in increasing index order.
    pub(crate) fn within_window(&self, i: usize, window_m: f64) -> Vec<usize> {
        let mut found = Vec::new();
        let Some(&r) = self.rank.get(i) else {
            return found;
        };
        let x = self.xs[i];
        for &j in self.order[r + 1..].iter() {
            if (self.xs[j] - x).abs() > window_m || self.xs[j].is_nan() {
                break;
            }
            found.push(j);
        }
        for &j in self.order[..r].iter().rev() {
            if (self.xs[j] - x).abs() > window_m {
                break;
            }
            found.push(j);
        }
        found.sort_unstable();
        found
    }

    /// Every pair (i, j), i < j, with |x_j − x_i| ≤ `window_m`, in increasing (i, j) order.
    pub(crate) fn pairs_within_window(&self, window_m: f64) -> Vec<(usize, usize)> {
        let mut pairs = Vec::new();
        for (r, &i) in self.order.iter().enumerate() {
            let x = self.xs[i];
            for &j in self.order[r + 1..].iter() {
                if (self.xs[j] - x).abs() > window_m || self.xs[j].is_nan() {
                    break;
                }
                pairs.push((i.min(j), i.max(j)));
            }
        }
        pairs.sort_unstable();
        pairs
    }
}

/// For every vehicle, the others whose centres are [`within_range`] of it, in index order: the
/// sweep.
pub(crate) fn neighbours_within(positions: &[[f64; 2]], range_m: f64) -> Vec<Vec<usize>> {
    let xs: Vec<f64> = positions.iter().map(|p| p[0]).collect();
    let sweep = XSweep::new(&xs);
    (0..positions.len())
        .map(|i| {
            sweep
                .within_window(i, range_m)
                .into_iter()
                .filter(|&j| within_range(positions[i], positions[j], range_m))
                .collect()
        })
        .collect()
}

/// `neighbours_within` by looking at every pair (the reference of the tests).
pub fn neighbours_within_brute_force(positions: &[[f64; 2]], range_m: f64) -> Vec<Vec<usize>> {
    (0..positions.len())
        .map(|i| {
            (0..positions.len())
                .filter(|&j| j != i && within_range(positions[i], positions[j], range_m))
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    /// A highway-like layout: `n` vehicles over `length_m` in three lanes, some on the same X.
    fn layout(seed: u64, n: usize, length_m: f64) -> Vec<[f64; 2]> {
        let mut rng = SplitMix64::new(seed);
        let mut positions: Vec<[f64; 2]> = Vec::with_capacity(n);
        for k in 0..n {
            let lane = (rng.next_f64() * 3.0).floor();
            let x = if k > 0 && rng.next_f64() < 0.2 {
                // Same X as an earlier vehicle (side by side or on top of each other).
                positions[(rng.next_f64() * k as f64) as usize][0]
            } else {
                (rng.next_f64() * length_m).round()
            };
            positions.push([x, 1.75 + 3.5 * lane + 0.3 * (rng.next_f64() - 0.5)]);
        }
        positions
    }

    #[test]
    fn the_sweep_finds_exactly_the_brute_force_neighbours() {
        for seed in 0..40 {
            let n = 1 + (seed as usize * 7) % 90;
            let positions = layout(seed, n, 2000.0);
            for range_m in [0.5, 3.5, 25.0, 50.0, 250.0, 300.0, 5000.0] {
                assert_eq!(
                    neighbours_within(&positions, range_m),
                    neighbours_within_brute_force(&positions, range_m),
                    "seed {seed}, range {range_m} m"
                );
            }
        }
    }

    #[test]
    fn a_vehicle_exactly_at_the_range_is_within_and_one_just_beyond_is_not() {
        let range_m = 250.0;
        let positions = [
            [0.0, 0.0],
            [250.0, 0.0],
            [250.0_f64.next_up(), 0.0],
            [-250.0, 0.0],
            [(-250.0_f64).next_down(), 0.0],
            // 150² + 200² = 250²: on the circle, off the axis.
            [150.0, 200.0],
            [0.0, 0.0],
        ];
        let sweep = neighbours_within(&positions, range_m);
        assert_eq!(sweep, neighbours_within_brute_force(&positions, range_m));
        assert_eq!(sweep[0], vec![1, 3, 5, 6]);
        assert_eq!(sweep[6], vec![0, 1, 3, 5]);
    }

    #[test]
    fn pairs_come_out_in_id_order_and_match_the_window() {
        let positions = layout(3, 60, 1500.0);
        let xs: Vec<f64> = positions.iter().map(|p| p[0]).collect();
        let sweep = XSweep::new(&xs);
        for window_m in [0.0, 10.0, 100.0, 1e5] {
            let expected: Vec<(usize, usize)> = (0..xs.len())
                .flat_map(|i| ((i + 1)..xs.len()).map(move |j| (i, j)))
                .filter(|&(i, j)| (xs[j] - xs[i]).abs() <= window_m)
                .collect();
            assert_eq!(sweep.pairs_within_window(window_m), expected, "{window_m}");
        }
    }
}
