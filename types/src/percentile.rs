//! The one percentile of the project: the nearest-rank percentile, used by the sweep's and the
//! study's figures and by the run's planning-time figures.

/// Nearest-rank percentile of ascending `sorted` values: the smallest value such that at least
/// `percent` % of the values are less than or equal to it, i.e. `sorted[⌈percent/100 · n⌉ − 1]`
/// (rank 1 for `percent` = 0). Always one of the samples (no interpolation), so it is exact and
/// does not depend on how the samples were split. `None` for no samples or `percent` outside
/// [0, 100].
pub fn nearest_rank_percentile(sorted: &[f64], percent: f64) -> Option<f64> {
    if sorted.is_empty() || !(0.0..=100.0).contains(&percent) {
        return None;
    }
    let rank = (percent / 100.0 * sorted.len() as f64).ceil() as usize;
    sorted.get(rank.max(1) - 1).copied()
}
