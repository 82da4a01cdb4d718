//! Seeds in JSON and CSV as hexadecimal strings, so every reader keeps them exact.
//!
//! Seeds are `u64`. JSON numbers above 2^53 are silently rounded by JavaScript, `jq`, pandas
//! and pyarrow (they read them as doubles), and replaying a rounded seed silently runs another
//! instance. A string of decimal digits is no cure: `pandas.read_json` (3.1.1, its default
//! dtype inference) turns a column of digit strings into float64, rounding it just the same.
//! mergesim therefore writes every seed as `0x` and 16 hexadecimal digits
//! (`"seed": "0x88be3e3d6d9f1a2d"`), which no reader takes for a number, and reads a seed
//! written any of the ways mergesim ever wrote one: that hex string, a string of decimal digits
//! (older files), or an integer that JSON readers with exact integers, such as Rust's, parse
//! whole. A fractional or exponent form (`9.853264649648847e18`, what pandas prints for a
//! rounded seed) is refused: it cannot be an exact seed.
//!
//! Use with `#[serde(with = "crate::exact_seed")]` (or `exact_seed::option` for `Option<u64>`);
//! [`parse_seed`] reads a seed given on the command line or to the Python API.

use serde::de::{self, Visitor};
use serde::{Deserializer, Serializer};
use thiserror::Error;

/// Why a text is not a seed.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum SeedError {
    /// Looks like a number but not a whole one (e.g. a seed that went through a double).
    #[error(
        "seed {0:?} is not a whole number: a seed read as a float (as pandas reads the decimal \
         seeds of older sweep files) has lost its last digits and would replay another instance; \
         take the seed from the file as written (\"0x...\"), or replay by --sweep-seed K \
         --instance I"
    )]
    NotWhole(String),
    /// Neither decimal digits nor `0x` and hexadecimal digits.
    #[error("seed {0:?} is not a seed: expected decimal digits or 0x and 1 to 16 hex digits")]
    Malformed(String),
    /// More than 64 bits.
    #[error("seed {0:?} does not fit in 64 bits (0 to 18446744073709551615)")]
    TooLarge(String),
}

/// A seed as mergesim writes it: `0x` and 16 lowercase hexadecimal digits.
pub fn format_seed(seed: u64) -> String {
    format!("0x{seed:016x}")
}

/// Reads a seed: `0x`/`0X` and 1 to 16 hexadecimal digits, or decimal digits (surrounding
/// spaces allowed). A number with a fraction or an exponent is [`SeedError::NotWhole`].
pub fn parse_seed(text: &str) -> Result<u64, SeedError> {
    let t = text.trim();
    if let Some(hex) = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        if hex.is_empty() || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
            return Err(SeedError::Malformed(text.to_string()));
        }
        return u64::from_str_radix(hex, 16).map_err(|_| SeedError::TooLarge(text.to_string()));
    }
    if !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit()) {
        return t
            .parse::<u64>()
            .map_err(|_| SeedError::TooLarge(text.to_string()));
    }
    if !t.starts_with('-') && t.parse::<f64>().is_ok_and(f64::is_finite) {
        return Err(SeedError::NotWhole(text.to_string()));
    }
    Err(SeedError::Malformed(text.to_string()))
}

/// Writes `seed` as [`format_seed`] does.
pub fn serialize<S: Serializer>(seed: &u64, serializer: S) -> Result<S::Ok, S::Error> {
    serializer.serialize_str(&format_seed(*seed))
}

/// Reads a seed from a hex or decimal string or an unsigned integer.
pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<u64, D::Error> {
    deserializer.deserialize_any(SeedVisitor)
}

struct SeedVisitor;

impl Visitor<'_> for SeedVisitor {
    type Value = u64;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(
            "a seed: a whole number in 0..2^64, as \"0x\" and hex digits, a string of decimal \
             digits or an integer",
        )
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<u64, E> {
        Ok(v)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<u64, E> {
        u64::try_from(v).map_err(|_| E::custom(format!("seed {v} is negative")))
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<u64, E> {
        Err(E::custom(format!(
            "seed {v} is not a whole number (a seed above 2^53 written as a JSON number loses \
             digits; write it as a string)"
        )))
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<u64, E> {
        parse_seed(v).map_err(E::custom)
    }
}

/// The same for `Option<u64>` (`null` for none).
pub(crate) mod option {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Writes `Some(seed)` as [`format_seed`](super::format_seed) does, `None` as `null`.
    pub fn serialize<S: Serializer>(seed: &Option<u64>, serializer: S) -> Result<S::Ok, S::Error> {
        match seed {
            Some(seed) => serializer.serialize_str(&super::format_seed(*seed)),
            None => serializer.serialize_none(),
        }
    }

    /// Reads `null`, a hex or decimal string or an unsigned integer.
    pub fn deserialize<'de, D: Deserializer<'de>>(
        deserializer: D,
    ) -> Result<Option<u64>, D::Error> {
        #[derive(Deserialize)]
        struct Wrapped(#[serde(with = "super")] u64);
        Ok(Option::<Wrapped>::deserialize(deserializer)?.map(|w| w.0))
    }
}

#[cfg(test)]
mod tests {
    use serde::{Deserialize, Serialize};

    use super::{SeedError, format_seed, parse_seed};

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Row {
        #[serde(with = "super")]
        seed: u64,
        #[serde(with = "super::option", default)]
        replay: Option<u64>,
    }

    #[test]
    fn seeds_above_2_53_survive_a_double_based_reader() {
        let row = Row {
            seed: u64::MAX,
            replay: Some((1 << 53) + 1),
        };
        let text = serde_json::to_string(&row).unwrap();
        assert_eq!(
            text,
            r#"{"seed":"0xffffffffffffffff","replay":"0x0020000000000001"}"#
        );
        // Any JSON reader keeps strings exact; parse the value as a double-based reader would.
        let generic: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert!(generic["seed"].is_string());
        assert_eq!(serde_json::from_str::<Row>(&text).unwrap(), row);
    }

    #[test]
    fn older_decimal_strings_integers_and_null_are_read_too_and_bad_seeds_are_named() {
        let row: Row = serde_json::from_str(r#"{"seed":42,"replay":null}"#).unwrap();
        assert_eq!((row.seed, row.replay), (42, None));
        let row: Row = serde_json::from_str(r#"{"seed":"7"}"#).unwrap();
        assert_eq!((row.seed, row.replay), (7, None));
        let row: Row =
            serde_json::from_str(r#"{"seed":"9853264649648847181","replay":"0X1F"}"#).unwrap();
        assert_eq!((row.seed, row.replay), (9853264649648847181, Some(31)));
        for (bad, needle) in [
            (r#"{"seed":-1}"#, "negative"),
            (r#"{"seed":1.5e19}"#, "not a whole number"),
            (r#"{"seed":"9.853264649648847e18"}"#, "not a whole number"),
            (r#"{"seed":"12a"}"#, "not a seed"),
            (r#"{"seed":"0x"}"#, "not a seed"),
            (r#"{"seed":"99999999999999999999"}"#, "64 bits"),
            (r#"{"seed":"0x10000000000000000"}"#, "64 bits"),
        ] {
            let err = serde_json::from_str::<Row>(bad).unwrap_err().to_string();
            assert!(err.contains(needle), "{bad}: {err}");
        }
    }

    #[test]
    fn the_written_form_reads_back_and_floats_are_refused() {
        for seed in [0, 1, 12, 1 << 53, 9853264649648847181, u64::MAX] {
            let text = format_seed(seed);
            assert_eq!(text.len(), 18, "{text}");
            assert_eq!(parse_seed(&text), Ok(seed));
            assert_eq!(parse_seed(&seed.to_string()), Ok(seed));
        }
        assert_eq!(
            parse_seed("9.853264649648847e18"),
            Err(SeedError::NotWhole("9.853264649648847e18".into()))
        );
        assert!(matches!(parse_seed("12.0"), Err(SeedError::NotWhole(_))));
        assert!(matches!(parse_seed("-3"), Err(SeedError::Malformed(_))));
        assert!(matches!(parse_seed("nan"), Err(SeedError::Malformed(_))));
        assert!(matches!(parse_seed(""), Err(SeedError::Malformed(_))));
    }
}
