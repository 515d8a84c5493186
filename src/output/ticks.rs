//! Axis ticks a reader trusts: linear axes stepped by 1, 2 or 5 times a power of ten, log axes
//! at decades with minor ticks at 2 and 5, and labels written from integers (a mantissa and an
//! exponent), so no float artefact (`0.7000000000000004`) and no `-0` can appear.
//!
//! Contract: every axis gets at least two labelled ticks inside its range, at most
//! [`MAX_LABELS`]; the labels of one axis are distinct.

/// The most labels on one axis (800 px charts: room for labels of up to 8 characters).
pub const MAX_LABELS: usize = 9;

/// Ticks of one axis: labelled positions with their labels, and unlabelled minor positions.
#[derive(Clone, Debug, PartialEq)]
pub struct Ticks {
    pub major: Vec<(f64, String)>,
    pub minor: Vec<f64>,
}

impl Ticks {
    /// The label of the major tick nearest to `v` (what the chart's formatter is asked for).
    pub fn label(&self, v: f64) -> String {
        self.major
            .iter()
            .min_by(|a, b| (a.0 - v).abs().total_cmp(&(b.0 - v).abs()))
            .map(|m| m.1.clone())
            .unwrap_or_default()
    }

    pub fn positions(&self) -> Vec<f64> {
        self.major.iter().map(|m| m.0).collect()
    }
}

/// `m * 10^e` written exactly: plain digits for exponents from -4 to 5, else `m e E`.
fn write(m: i64, e: i32) -> String {
    if m == 0 {
        return "0".to_string();
    }
    let sign = if m < 0 { "-" } else { "" };
    let digits = m.unsigned_abs().to_string();
    if !(-4..=5).contains(&(e + digits.len() as i32 - 1)) {
        // Scientific: one digit before the point.
        let exp = e + digits.len() as i32 - 1;
        let trimmed = digits.trim_end_matches('0');
        let mantissa = match trimmed.len() {
            1 => trimmed.to_string(),
            _ => format!("{}.{}", &trimmed[..1], &trimmed[1..]),
        };
        return format!("{sign}{mantissa}e{exp}");
    }
    if e >= 0 {
        return format!("{sign}{digits}{}", "0".repeat(e as usize));
    }
    let places = (-e) as usize;
    let padded = format!("{digits:0>width$}", width = places + 1);
    let (int, frac) = padded.split_at(padded.len() - places);
    let frac = frac.trim_end_matches('0');
    if frac.is_empty() {
        format!("{sign}{int}")
    } else {
        format!("{sign}{int}.{frac}")
    }
}

/// Linear ticks over `[lo, hi]`: the finest step of 1, 2 or 5 times a power of ten giving at
/// most [`MAX_LABELS`] labels, the next finer step's positions as minor ticks.
pub fn linear(lo: f64, hi: f64) -> Ticks {
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return Ticks {
            major: vec![(lo, write_f64(lo)), (hi, write_f64(hi))],
            minor: Vec::new(),
        };
    }
    let span = hi - lo;
    let mut e = (span / MAX_LABELS as f64).log10().floor() as i32 - 1;
    loop {
        for m in [1i64, 2, 5] {
            let step = m as f64 * 10f64.powi(e);
            let first = (lo / step).ceil() as i64;
            let last = (hi / step).floor() as i64;
            if last - first < MAX_LABELS as i64 {
                let major = (first..=last)
                    .map(|k| (k as f64 * step, write(k * m, e)))
                    .collect();
                let fine = step / if m == 2 { 4.0 } else { 5.0 };
                let minor = ((lo / fine).ceil() as i64..=(hi / fine).floor() as i64)
                    .map(|k| k as f64 * fine)
                    .collect();
                return Ticks { major, minor };
            }
        }
        e += 1;
    }
}

/// A value written with at most 6 significant digits (the fallback of a degenerate axis).
fn write_f64(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return "0".to_string();
    }
    let e = v.abs().log10().floor() as i32 - 5;
    write((v / 10f64.powi(e)).round() as i64, e)
}

/// Log ticks over `[lo, hi]` (both positive): decades labelled; minor ticks at 2 and 5 times
/// them. A range holding fewer than two decades labels 1, 2 and 5 times each power of ten, and
/// one holding fewer than two of those labels every digit 1 to 9. Too many decades: every
/// second (third, ...) decade is labelled.
pub fn log(lo: f64, hi: f64) -> Ticks {
    let (e0, e1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let inside = |v: f64| v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12);
    let at = |m: i64, e: i32| m as f64 * 10f64.powi(e);
    let marks = |mantissas: &[i64]| -> Vec<(i64, i32)> {
        (e0..=e1)
            .flat_map(|e| mantissas.iter().map(move |&m| (m, e)))
            .filter(|&(m, e)| inside(at(m, e)))
            .collect()
    };
    let label = |list: Vec<(i64, i32)>| -> Vec<(f64, String)> {
        list.into_iter()
            .map(|(m, e)| (at(m, e), write(m, e)))
            .collect()
    };
    let decades = marks(&[1]);
    if decades.len() >= 2 {
        let every = decades.len().div_ceil(MAX_LABELS).max(1);
        let major: Vec<(i64, i32)> = decades
            .iter()
            .copied()
            .filter(|&(_, e)| e.rem_euclid(every as i32) == 0)
            .collect();
        let major = if major.len() >= 2 {
            major
        } else {
            decades.clone()
        };
        let minor = marks(&[2, 5]).into_iter().map(|(m, e)| at(m, e));
        return Ticks {
            major: label(major),
            minor: minor.collect(),
        };
    }
    let coarse = marks(&[1, 2, 5]);
    if coarse.len() >= 2 {
        let minor = marks(&[3, 4, 6, 7, 8, 9])
            .into_iter()
            .map(|(m, e)| at(m, e));
        return Ticks {
            major: label(coarse),
            minor: minor.collect(),
        };
    }
    let digits = marks(&[1, 2, 3, 4, 5, 6, 7, 8, 9]);
    if digits.len() >= 2 {
        return Ticks {
            major: label(digits),
            minor: Vec::new(),
        };
    }
    // Less than a digit step: linear ticks read the same on so short a range.
    linear(lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(t: &Ticks) -> Vec<&str> {
        t.major.iter().map(|m| m.1.as_str()).collect()
    }

    #[test]
    fn numbers_are_written_from_their_digits() {
        assert_eq!(write(7, -1), "0.7");
        assert_eq!(write(-5, -3), "-0.005");
        assert_eq!(write(1, -5), "1e-5");
        assert_eq!(write(25, -7), "2.5e-6");
        assert_eq!(write(12, 0), "12");
        assert_eq!(write(3, 6), "3e6");
        assert_eq!(write(0, -3), "0");
        assert_eq!(write(10, -1), "1");
    }

    #[test]
    fn linear_axes_step_by_one_two_or_five_and_never_write_minus_zero() {
        let t = linear(-0.31, 0.72);
        assert_eq!(
            labels(&t),
            ["-0.2", "0", "0.2", "0.4", "0.6"].to_vec(),
            "{t:?}"
        );
        let t = linear(0.0, 1.0);
        assert_eq!(labels(&t), ["0", "0.2", "0.4", "0.6", "0.8", "1"].to_vec());
        let t = linear(-1.2e-5, -1e-6);
        assert!(labels(&t).iter().all(|l| !l.contains("00000")), "{t:?}");
        for (lo, hi) in [(0.0, 3.0), (-7.3, 12.9), (1e-9, 3e-9), (980.0, 1020.0)] {
            let t = linear(lo, hi);
            assert!(
                (2..=MAX_LABELS).contains(&t.major.len()),
                "{lo}..{hi}: {t:?}"
            );
            assert!(t
                .major
                .iter()
                .all(|m| m.0 >= lo - 1e-12 && m.0 <= hi + 1e-12));
        }
    }

    #[test]
    fn log_axes_tick_decades_with_minor_ticks_at_two_and_five() {
        let t = log(3e-7, 2e-2);
        assert_eq!(
            labels(&t),
            ["1e-6", "1e-5", "0.0001", "0.001", "0.01"].to_vec()
        );
        assert!(t.minor.iter().any(|&v| (v - 5e-7).abs() < 1e-20));
        // Within one decade: 1, 2 and 5 times the powers of ten.
        let t = log(0.15, 0.8);
        assert_eq!(labels(&t), ["0.2", "0.5"].to_vec());
        // The P3 chart of issue 19: 0.006 .. 0.01 had piled-up or artefact labels.
        let t = log(0.006, 0.01);
        assert_eq!(
            labels(&t),
            ["0.006", "0.007", "0.008", "0.009", "0.01"].to_vec()
        );
        // Twenty decades: every third labelled, at most MAX_LABELS.
        let t = log(1e-18, 1e2);
        assert!(t.major.len() <= MAX_LABELS && t.major.len() >= 2, "{t:?}");
    }
}
