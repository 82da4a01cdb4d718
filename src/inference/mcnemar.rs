//! The exact McNemar test (McNemar 1947, "Note on the sampling error of the difference between
//! correlated proportions or percentages", Psychometrika 12:153–157) of a paired 2×2 table.

use super::distributions::binomial_cdf;

/// A paired 2×2 table of an event (e.g. a collision) over the instances both planners ran:
/// in how many pairs the event happened in both runs, only in the first planner's run, only in
/// the second's, or in neither.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Discordance {
    /// Pairs with the event in both runs.
    pub both: u64,
    /// Pairs with the event only in the first planner's run.
    pub only_first: u64,
    /// Pairs with the event only in the second planner's run.
    pub only_second: u64,
    /// Pairs with the event in neither run.
    pub neither: u64,
}

impl Discordance {
    /// Number of pairs, `both + only_first + only_second + neither`.
    pub fn pairs(&self) -> u64 {
        self.both + self.only_first + self.only_second + self.neither
    }

    /// Number of discordant pairs, `only_first + only_second`.
    pub fn discordant(&self) -> u64 {
        self.only_first + self.only_second
    }
}

/// The two-sided exact McNemar p-value (McNemar 1947; exact binomial form), as
/// `statsmodels.stats.contingency_tables.mcnemar(table, exact=True).pvalue`
/// (statsmodels 0.15.0):
///
/// ```text
/// b = only_first, c = only_second,   X ~ Binomial(b + c, 1/2)
/// p = min(1, 2 · P(X ≤ min(b, c)))
/// ```
///
/// Under "both planners have the same event rate" each discordant pair is equally likely to
/// fall either way; the concordant pairs carry no information. With no discordant pair,
/// `p = 1`.
pub fn mcnemar_exact(table: &Discordance) -> f64 {
    let smaller = table.only_first.min(table.only_second);
    (2.0 * binomial_cdf(smaller, table.discordant(), 0.5)).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(both: u64, only_first: u64, only_second: u64, neither: u64) -> Discordance {
        Discordance {
            both,
            only_first,
            only_second,
            neither,
        }
    }

    #[test]
    fn small_tables_by_hand() {
        // b = 0, c = 5: 2 · (1/2)⁵ = 1/16.
        assert_eq!(mcnemar_exact(&table(3, 0, 5, 10)), 0.0625);
        // b = 1, c = 4: 2 · (1 + 5)/32 = 0.375.
        assert!((mcnemar_exact(&table(0, 4, 1, 0)) - 0.375).abs() < 1e-15);
        // Symmetric table: capped at 1.
        assert_eq!(mcnemar_exact(&table(2, 6, 6, 2)), 1.0);
        // No discordant pairs.
        assert_eq!(mcnemar_exact(&table(7, 0, 0, 3)), 1.0);
        assert_eq!(mcnemar_exact(&table(0, 0, 0, 0)), 1.0);
        assert_eq!(table(1, 2, 3, 4).pairs(), 10);
    }
}
