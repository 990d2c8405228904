//! One message for an error and its causes, as `gpsrx` prints it, `gpsrx batch` writes it in
//! its summary and the Python package raises it.

use std::error::Error;

/// The error and its causes on one line, `outer: cause: root`, each text once: a cause whose
/// text its outer message already includes (errors that print their source and also return
/// it as their source) is left out, and so is an empty text.
pub fn error_message(e: &(dyn Error + 'static)) -> String {
    let mut text = String::new();
    let mut cause: Option<&(dyn Error + 'static)> = Some(e);
    while let Some(c) = cause {
        let t = c.to_string();
        if !t.is_empty() && !text.contains(&t) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&t);
        }
        cause = c.source();
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, thiserror::Error)]
    #[error("{text}")]
    struct Layer {
        text: String,
        #[source]
        source: Option<Box<Layer>>,
    }

    fn layer(text: &str, source: Option<Layer>) -> Layer {
        Layer {
            text: text.into(),
            source: source.map(Box::new),
        }
    }

    #[test]
    fn each_cause_once_and_in_order() {
        let root = layer("No such file or directory (os error 2)", None);
        let mid = layer(
            "cannot read x.bin: No such file or directory (os error 2)",
            Some(root),
        );
        let top = layer("cannot open the recording", Some(mid));
        assert_eq!(
            error_message(&top),
            "cannot open the recording: cannot read x.bin: No such file or directory (os error 2)"
        );
        let empty = layer("", Some(layer("the cause", None)));
        assert_eq!(error_message(&empty), "the cause");
    }
}
