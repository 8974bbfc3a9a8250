//! The `--hurst` syntax of the CLI and of study files: comma-separated items, each a value
//! or an inclusive range `A:B:STEP` (e.g. `-1:0:0.5,0.8,2:3:1`).
//!
//! A front end's syntax, so it lives in the front-end layer and not in the library, which
//! takes plain lists of H values: the CLI, the Python package and the fuzz target all use
//! this one parser.

use asperity::input::{clip, short_number};
use asperity::{Error, Result};

/// The most values one `A:B:STEP` range may give (a typo such as a step of `1e-9` would
/// otherwise ask for billions of tasks).
pub const MAX_RANGE_VALUES: usize = 100_000;

/// Parses Hurst exponents: comma-separated items, each a value or an inclusive range
/// `A:B:STEP`. Every value is finite; a range gives at most [`MAX_RANGE_VALUES`] values.
pub fn parse_range(text: &str) -> Result<Vec<f64>> {
    let mut values = Vec::new();
    for item in text.split(',') {
        values.extend(parse_range_item(item)?);
    }
    Ok(values)
}

fn parse_range_item(text: &str) -> Result<Vec<f64>> {
    let parts: Vec<&str> = text.split(':').collect();
    let num = |s: &str| {
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                Error::invalid(
                    "hurst",
                    format!("'{}' is not a finite number in '{}'", clip(s), clip(text)),
                )
            })
    };
    match parts.as_slice() {
        [single] => Ok(vec![num(single)?]),
        [a, b, step] => {
            let (a, b, step) = (num(a)?, num(b)?, num(step)?);
            if step.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || b < a {
                return Err(Error::invalid(
                    "hurst",
                    format!("empty range '{}' (need A <= B and STEP > 0)", clip(text)),
                ));
            }
            let count = ((b - a) / step + 1e-9).floor() + 1.0;
            if count.is_nan() || count > MAX_RANGE_VALUES as f64 {
                return Err(Error::invalid(
                    "hurst",
                    format!(
                        "the range '{}' gives {} values, more than {MAX_RANGE_VALUES}",
                        clip(text),
                        short_number(count)
                    ),
                ));
            }
            let count = count as usize;
            // Round to 1e-12 so that 0.1-steps print and key cleanly.
            Ok((0..count)
                .map(|i| ((a + step * i as f64) * 1e12).round() / 1e12)
                .collect())
        }
        _ => Err(Error::invalid(
            "hurst",
            format!("'{}' is neither a value nor A:B:STEP", clip(text)),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::parse_range;

    #[test]
    fn ranges_are_inclusive_and_validated() {
        assert_eq!(
            parse_range("-1:3:0.5").unwrap(),
            vec![-1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]
        );
        assert_eq!(parse_range("0.1:0.3:0.1").unwrap(), vec![0.1, 0.2, 0.3]);
        assert_eq!(parse_range("0.8").unwrap(), vec![0.8]);
        assert_eq!(parse_range("-0.5,0.5:1:0.5").unwrap(), vec![-0.5, 0.5, 1.0]);
        assert!(parse_range("").is_err());
        assert!(parse_range("1:0:0.1").is_err(), "empty range");
        assert!(parse_range("0:1:0").is_err());
        assert!(parse_range("a:b").is_err());
    }

    #[test]
    fn ranges_are_bounded_and_finite() {
        // A range of 4e9 values is refused before any is made.
        let err = parse_range("-1:3:1e-9").unwrap_err().to_string();
        assert!(err.contains("more than 100000"), "{err}");
        assert!(err.contains("4e9"), "{err}");
        // NaN and infinity are not H values.
        for text in ["0:nan:0.1", "nan", "-inf", "0:1:inf"] {
            let err = parse_range(text).unwrap_err().to_string();
            assert!(err.contains("not a finite number"), "{text}: {err}");
        }
        assert_eq!(parse_range("-1e-300").unwrap(), vec![-1e-300]);
    }
}
