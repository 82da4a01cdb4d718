//! Where a value sits in a TOML text, so that validation errors (found after parsing, on typed
//! values) can still name the line.

use toml::de::{DeTable, DeValue};

/// The 1-based line of the value at `path` (table keys, or array indices written as numbers),
/// or `None` if the text does not hold it (e.g. a default value, or unparsable text).
pub fn line_of(text: &str, path: &[String]) -> Option<usize> {
    let root = DeTable::parse(text).ok()?;
    let mut span = root.span();
    let root_value = DeValue::Table(root.into_inner());
    let mut current = &root_value;
    for segment in path {
        let next = match current {
            DeValue::Array(_) => current.get(segment.parse::<usize>().ok()?)?,
            DeValue::Table(_) => current.get(segment.as_str())?,
            _ => return None,
        };
        span = next.span();
        current = next.get_ref();
    }
    Some(line_at(text, span.start))
}

/// The 1-based line holding byte `offset` of `text`.
pub(crate) fn line_at(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(parts: &[&str]) -> Vec<String> {
        parts.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn finds_nested_keys_and_array_elements() {
        let text = "name = \"x\"\n\n[sim]\nmu = 0.8\n\n[sim.v2v]\nlatency_s = 0.1\n\n[[vehicles]]\nx_m = 1.0\n\n[[vehicles]]\nx_m = 2.0\n";
        assert_eq!(line_of(text, &p(&["name"])), Some(1));
        assert_eq!(line_of(text, &p(&["sim", "mu"])), Some(4));
        assert_eq!(line_of(text, &p(&["sim", "v2v", "latency_s"])), Some(7));
        assert_eq!(line_of(text, &p(&["vehicles", "1", "x_m"])), Some(13));
        assert_eq!(line_of(text, &p(&["sim", "dt_s"])), None);
        assert_eq!(line_of("not = [toml", &p(&["not"])), None);
    }
}
