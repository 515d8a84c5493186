//! The values of a sweep: `START:STOP:STEP`, STOP included.

use std::fmt;

/// A range that gives no values. `Display` is the message (the command line puts `--sweep: `
/// before it).
#[derive(Clone, Debug, PartialEq)]
pub enum RangeError {
    /// Not three parts separated by `:`.
    NotStartStopStep { range: String },
    /// A part (`START`, `STOP` or `STEP`) that is not a number.
    NotANumber { what: &'static str, text: String },
    /// A bound or the step is infinite or NaN.
    NotFinite { range: String },
    /// The step is zero or points away from STOP.
    Unreachable { range: String },
    /// More than [`MAX_POINTS`] values.
    TooManyPoints { range: String, points: usize },
}

/// The most values a range may have.
pub const MAX_POINTS: usize = 10_000;

impl fmt::Display for RangeError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            RangeError::NotStartStopStep { range } => {
                write!(f, "the range `{range}` is not START:STOP:STEP")
            }
            RangeError::NotANumber { what, text } => {
                write!(f, "the range's {what} `{text}` is not a number")
            }
            RangeError::NotFinite { range } => write!(f, "the range {range} is not finite"),
            RangeError::Unreachable { range } => write!(
                f,
                "the range {range} does not reach STOP from START in steps of STEP"
            ),
            RangeError::TooManyPoints { range, points } => write!(
                f,
                "the range {range} has {points} points; at most {MAX_POINTS}"
            ),
        }
    }
}

impl std::error::Error for RangeError {}

/// The three parts of `START:STOP:STEP`, trimmed, as written.
pub fn split_range(text: &str) -> Result<[&str; 3], RangeError> {
    let parts: Vec<&str> = text.split(':').map(str::trim).collect();
    match parts[..] {
        [a, b, c] => Ok([a, b, c]),
        _ => Err(RangeError::NotStartStopStep {
            range: text.to_string(),
        }),
    }
}

/// `START:STOP:STEP` inclusive of STOP (within a millionth of a step).
pub fn parse_range(text: &str) -> Result<Vec<f64>, RangeError> {
    let [a, b, c] = split_range(text)?;
    let num = |s: &str, what: &'static str| {
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| RangeError::NotANumber {
                what,
                text: s.to_string(),
            })
    };
    grid(num(a, "START")?, num(b, "STOP")?, num(c, "STEP")?)
}

/// The values from `start` to `stop` (inclusive, within a millionth of a step) by `step`.
pub fn grid(start: f64, stop: f64, step: f64) -> Result<Vec<f64>, RangeError> {
    let range = format!("{start}:{stop}:{step}");
    if !(start.is_finite() && stop.is_finite() && step.is_finite()) {
        return Err(RangeError::NotFinite { range });
    }
    if step == 0.0 || (stop - start) * step < 0.0 {
        return Err(RangeError::Unreachable { range });
    }
    let n = ((stop - start) / step + 1e-6).floor() as usize + 1;
    if n > MAX_POINTS {
        return Err(RangeError::TooManyPoints { range, points: n });
    }
    Ok((0..n).map(|i| start + i as f64 * step).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_include_their_stop() {
        let v = parse_range("1.0:2.0:0.25").expect("range");
        assert_eq!(v.len(), 5);
        assert!((v[4] - 2.0).abs() < 1e-12);
        assert_eq!(parse_range("3:1:-1").expect("down"), vec![3.0, 2.0, 1.0]);
        for bad in ["1:2", "1:2:0", "2:1:0.5", "a:2:1", "0:1:1e-9"] {
            assert!(parse_range(bad).is_err(), "{bad}");
        }
    }
}
