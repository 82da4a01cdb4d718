//! A regular sampling grid (for drawing potential fields).

use serde::{Deserialize, Serialize};

use crate::error::InvalidParameter;

/// Largest grid accepted (cells).
pub const MAX_GRID_CELLS: usize = 16 * 1024 * 1024;

/// A regular grid of cell centres: cell (row, col) is at
/// (x_min + (col + ½)·cell, y_min + (row + ½)·cell); values are stored row after row.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GridSpec {
    /// Left edge of the window (m).
    pub x_min_m: f64,
    /// Bottom edge of the window (m).
    pub y_min_m: f64,
    /// Cell size (m).
    pub cell_m: f64,
    /// Number of cells along X.
    pub columns: usize,
    /// Number of cells along Y.
    pub rows: usize,
}

impl GridSpec {
    /// Checks that the grid is finite, non-empty and not absurdly large.
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        for (name, value) in [("x_min_m", self.x_min_m), ("y_min_m", self.y_min_m)] {
            if !value.is_finite() {
                return Err(InvalidParameter::new(
                    format!("grid.{name}"),
                    value,
                    "must be finite",
                ));
            }
        }
        if !(self.cell_m.is_finite() && self.cell_m > 0.0) {
            return Err(InvalidParameter::new(
                "grid.cell_m",
                self.cell_m,
                "must be finite and > 0",
            ));
        }
        let cells = self.columns.saturating_mul(self.rows);
        if cells == 0 || cells > MAX_GRID_CELLS {
            return Err(InvalidParameter::new(
                "grid.columns × grid.rows",
                cells as f64,
                format!("must lie in [1, {MAX_GRID_CELLS}]"),
            ));
        }
        Ok(())
    }

    /// Centre of cell (row, col) (m).
    pub fn cell_centre_m(&self, row: usize, col: usize) -> [f64; 2] {
        [
            self.x_min_m + (col as f64 + 0.5) * self.cell_m,
            self.y_min_m + (row as f64 + 0.5) * self.cell_m,
        ]
    }
}
