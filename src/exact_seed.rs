//! Seeds in JSON as decimal strings, so every reader keeps them exact.
//!
//! Seeds are `u64`; JSON numbers above 2^53 are silently rounded by JavaScript, `jq`, pandas
//! and pyarrow (they read them as doubles), and replaying a rounded seed silently runs another
//! instance. mergesim therefore writes every seed as a string (`"seed": "9853264649648847181"`)
//! and reads a seed written either way (a string of digits, or an integer that JSON readers
//! with exact integers, such as Rust's, parse whole).
//!
//! Use with `#[serde(with = "crate::exact_seed")]` (or `exact_seed::option` for `Option<u64>`).

use serde::de::{self, Visitor};
use serde::{Deserializer, Serializer};

/// Writes `seed` as a decimal string.
pub fn serialize<S: Serializer>(seed: &u64, serializer: S) -> Result<S::Ok, S::Error> {
    serializer.collect_str(seed)
}

/// Reads a seed from a decimal string or an unsigned integer.
pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<u64, D::Error> {
    deserializer.deserialize_any(SeedVisitor)
}

struct SeedVisitor;

impl Visitor<'_> for SeedVisitor {
    type Value = u64;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a seed: a whole number in 0..2^64, as a string of digits or an integer")
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
        if v.is_empty() || !v.bytes().all(|b| b.is_ascii_digit()) {
            return Err(E::custom(format!(
                "seed {v:?} is not a string of decimal digits"
            )));
        }
        v.parse::<u64>()
            .map_err(|_| E::custom(format!("seed {v:?} does not fit in 64 bits")))
    }
}

/// The same for `Option<u64>` (`null` for none).
pub mod option {
    use serde::{Deserialize, Deserializer, Serializer};

    /// Writes `Some(seed)` as a decimal string, `None` as `null`.
    pub fn serialize<S: Serializer>(seed: &Option<u64>, serializer: S) -> Result<S::Ok, S::Error> {
        match seed {
            Some(seed) => serializer.collect_str(seed),
            None => serializer.serialize_none(),
        }
    }

    /// Reads `null`, a decimal string or an unsigned integer.
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
            r#"{"seed":"18446744073709551615","replay":"9007199254740993"}"#
        );
        // Any JSON reader keeps strings exact; parse the value as a double-based reader would.
        let generic: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert!(generic["seed"].is_string());
        assert_eq!(serde_json::from_str::<Row>(&text).unwrap(), row);
    }

    #[test]
    fn integers_and_null_are_read_too_and_bad_seeds_are_named() {
        let row: Row = serde_json::from_str(r#"{"seed":42,"replay":null}"#).unwrap();
        assert_eq!((row.seed, row.replay), (42, None));
        let row: Row = serde_json::from_str(r#"{"seed":"7"}"#).unwrap();
        assert_eq!((row.seed, row.replay), (7, None));
        for (bad, needle) in [
            (r#"{"seed":-1}"#, "negative"),
            (r#"{"seed":1.5e19}"#, "not a whole number"),
            (r#"{"seed":"12a"}"#, "decimal digits"),
            (r#"{"seed":"99999999999999999999"}"#, "64 bits"),
        ] {
            let err = serde_json::from_str::<Row>(bad).unwrap_err().to_string();
            assert!(err.contains(needle), "{bad}: {err}");
        }
    }
}
