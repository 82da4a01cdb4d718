//! Allowed ranges of parameters, declared once: validation checks them and the documentation
//! lists them (`merge_sim limits`, README "Limits"), so the two cannot disagree.
//!
//! Every bound is finite on both sides: a value must be finite and lie in the range. The ranges
//! keep the physics (single-precision Rapier) and the planner meaningful and every run's work
//! bounded.

use crate::error::InvalidParameter;

/// The allowed range of one parameter: `[min, max]`, either end possibly open.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound {
    /// The field's name (without its section).
    pub field: &'static str,
    /// Lower end.
    pub min: f64,
    /// Whether the lower end is excluded.
    pub min_open: bool,
    /// Upper end.
    pub max: f64,
    /// Whether the upper end is excluded.
    pub max_open: bool,
    /// Unit, as written after the range (empty if dimensionless).
    pub unit: &'static str,
}

impl Bound {
    /// `[min, max]`.
    pub const fn closed(field: &'static str, min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            field,
            min,
            min_open: false,
            max,
            max_open: false,
            unit,
        }
    }

    /// `(min, max]`: above `min`.
    pub const fn above(field: &'static str, min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            field,
            min,
            min_open: true,
            max,
            max_open: false,
            unit,
        }
    }

    /// `(min, max)`.
    pub const fn open(field: &'static str, min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            field,
            min,
            min_open: true,
            max,
            max_open: true,
            unit,
        }
    }

    /// Whether `value` is finite and in the range.
    pub fn contains(&self, value: f64) -> bool {
        value.is_finite()
            && (if self.min_open {
                value > self.min
            } else {
                value >= self.min
            })
            && (if self.max_open {
                value < self.max
            } else {
                value <= self.max
            })
    }

    /// The range as text, e.g. `(0, 10] s`.
    pub fn range_text(&self) -> String {
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        format!(
            "{}{}, {}{}{unit}",
            if self.min_open { '(' } else { '[' },
            self.min,
            self.max,
            if self.max_open { ')' } else { ']' },
        )
    }

    /// The field's dotted name in `section` (`planner.step_time_s`; just the field when the
    /// section is empty).
    pub fn name_in(&self, section: &str) -> String {
        if section.is_empty() {
            self.field.to_string()
        } else {
            format!("{section}.{}", self.field)
        }
    }

    /// Checks `value` of the field in `section` (`planner`, `road`, …; empty for top-level
    /// fields).
    pub fn check(&self, section: &str, value: f64) -> Result<(), InvalidParameter> {
        if self.contains(value) {
            Ok(())
        } else {
            Err(InvalidParameter::new(
                self.name_in(section),
                value,
                format!("must be finite and lie in {}", self.range_text()),
            ))
        }
    }
}

/// Checks every `(field, value)` against its bound in `bounds`, in the order of `values`.
/// A field without a bound is a programming error and is reported as such.
pub fn check_all(
    section: &str,
    bounds: &[Bound],
    values: &[(&'static str, f64)],
) -> Result<(), InvalidParameter> {
    for (field, value) in values {
        match bounds.iter().find(|b| b.field == *field) {
            Some(bound) => bound.check(section, *value)?,
            None => {
                return Err(InvalidParameter::new(
                    if section.is_empty() {
                        field.to_string()
                    } else {
                        format!("{section}.{field}")
                    },
                    *value,
                    "has no declared bound",
                ));
            }
        }
    }
    Ok(())
}

/// The bounds of one scenario table as markdown rows (`| [table] field | range |`).
pub fn markdown_rows(table: &str, bounds: &[Bound]) -> String {
    bounds
        .iter()
        .map(|b| format!("| `[{table}]` `{}` | {} |\n", b.field, b.range_text()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_check_finiteness_and_both_ends() {
        let b = Bound::above("step_time_s", 0.0, 2.0, "s");
        assert!(b.contains(0.4) && b.contains(2.0));
        assert!(!b.contains(0.0) && !b.contains(2.1) && !b.contains(f64::NAN));
        assert!(!b.contains(f64::INFINITY));
        assert_eq!(b.range_text(), "(0, 2] s");
        let err = b.check("planner", 1e300).unwrap_err();
        assert_eq!(err.name, "planner.step_time_s");
        assert!(err.reason.contains("(0, 2] s"), "{err}");
        assert_eq!(Bound::open("f", 0.0, 1.0, "").range_text(), "(0, 1)");
    }

    #[test]
    fn check_all_names_the_first_bad_field_and_refuses_unbounded_ones() {
        let bounds = [
            Bound::closed("a", 0.0, 1.0, ""),
            Bound::closed("b", 0.0, 1.0, ""),
        ];
        assert!(check_all("s", &bounds, &[("a", 0.5), ("b", 1.0)]).is_ok());
        let err = check_all("s", &bounds, &[("a", 0.5), ("b", 2.0)]).unwrap_err();
        assert_eq!(err.name, "s.b");
        let err = check_all("s", &bounds, &[("c", 0.0)]).unwrap_err();
        assert!(err.reason.contains("no declared bound"));
    }
}
