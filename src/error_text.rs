//! How an error reads on the terminal and in Python: the error and its causes joined by `: `,
//! as anyhow's `{:#}` prints them, but without a cause whose text the error's own message
//! already ends with (errors such as `behaviour of vehicle {vehicle}: {source}` print their
//! source themselves; `{:#}` would print it twice).

/// `error` and its sources joined by `: `, each source left out when the text so far already
/// ends with it.
pub fn error_chain(error: &(dyn std::error::Error + 'static)) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        let cause_text = cause.to_string();
        if !text.ends_with(&cause_text) {
            text.push_str(": ");
            text.push_str(&cause_text);
        }
        source = cause.source();
    }
    text
}

#[cfg(test)]
mod tests {
    use super::error_chain;

    #[derive(Debug, thiserror::Error)]
    #[error("behaviour of vehicle {vehicle}: {source}")]
    struct Wrapping {
        vehicle: String,
        source: std::io::Error,
    }

    #[derive(Debug, thiserror::Error)]
    #[error("cannot read the plan")]
    struct Plain {
        source: std::io::Error,
    }

    #[test]
    fn a_cause_is_printed_once() {
        let io = || std::io::Error::other("kaboom");
        let wrapping = Wrapping {
            vehicle: "ego".into(),
            source: io(),
        };
        assert_eq!(error_chain(&wrapping), "behaviour of vehicle ego: kaboom");
        // A cause the message does not print is appended, as anyhow's `{:#}` does.
        assert_eq!(
            error_chain(&Plain { source: io() }),
            "cannot read the plan: kaboom"
        );
        let anyhow_error = anyhow::Error::new(Plain { source: io() }).context("study plan.toml");
        assert_eq!(
            error_chain(anyhow_error.as_ref()),
            format!("{anyhow_error:#}")
        );
    }
}
