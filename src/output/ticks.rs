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

/// `m * 10^e`, dividing for negative `e` so that `3e-1` is the double nearest 0.3.
fn power(m: f64, e: i32) -> f64 {
    if e < 0 {
        m / 10f64.powi(-e)
    } else {
        m * 10f64.powi(e)
    }
}

/// Log ticks over `[lo, hi]` (both positive): decades labelled (`1e-4`, `1e-3`, `0.01` ...
/// `1000`, `1e4`); minor ticks at 2 and 5 times them. A range holding fewer than three
/// decades but spanning one labels 1, 2 and 5 times each power of ten, a shorter one every digit
/// 1 to 9. Too many decades: every second (third, ...) decade is labelled.
pub fn log(lo: f64, hi: f64) -> Ticks {
    let (e0, e1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let inside = |v: f64| v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12);
    let at = |m: i64, e: i32| power(m as f64, e);
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
    // Two decades alone leave much of the range unlabelled: 1, 2 and 5 then.
    if decades.len() >= 3 {
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
        // Decades read alike: `1e-6`, `1e-5`, `1e-4`, `1e-3`, `0.01`, ..., `1000`, `1e4`.
        let decade = |e: i32| match e {
            -2..=3 => write(1, e),
            _ => format!("1e{e}"),
        };
        let minor = marks(&[2, 5]).into_iter().map(|(m, e)| at(m, e));
        return Ticks {
            major: major
                .into_iter()
                .map(|(m, e)| (at(m, e), decade(e)))
                .collect(),
            minor: minor.collect(),
        };
    }
    // Within a decade every digit reads better than 1, 2 and 5 (thinned if crowded).
    let coarse = marks(&[1, 2, 5]);
    if coarse.len() >= 2 && hi / lo >= 10.0 {
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

/// A log range widened to the labelled marks just outside it when they are close (a factor
/// 2 for decades over two decades, 1.3 for 1-2-5 marks over one, 1.1 for digits within one),
/// so that labels reach both ends of the data.
pub fn widen_log(lo: f64, hi: f64) -> (f64, f64) {
    if !(lo > 0.0 && hi > lo && hi.is_finite()) {
        return (lo, hi);
    }
    let (mantissas, reach): (&[f64], f64) = if hi / lo >= 100.0 {
        (&[1.0], 2.0)
    } else if hi / lo >= 10.0 {
        (&[1.0, 2.0, 5.0], 1.3)
    } else {
        (&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0], 1.1)
    };
    let marks = |e: i32| mantissas.iter().map(move |&m| power(m, e));
    let below = (lo.log10().floor() as i32 - 1..=lo.log10().floor() as i32)
        .flat_map(marks)
        .filter(|&m| m <= lo)
        .fold(0.0f64, f64::max);
    let above = (hi.log10().floor() as i32..=hi.log10().floor() as i32 + 1)
        .flat_map(marks)
        .filter(|&m| m >= hi)
        .fold(f64::INFINITY, f64::min);
    let lo = if below > 0.0 && lo / below < reach {
        below
    } else {
        lo
    };
    let hi = if above.is_finite() && above / hi < reach {
        above
    } else {
        hi
    };
    (lo, hi)
}

/// The least gap between neighbouring tick labels (px).
const LABEL_GAP: f64 = 10.0;

/// Drops tick labels (keeping their ticks) until neighbours are `LABEL_GAP` apart on an axis
/// of `pixels` px, each label `sizes[i]` px long along the axis; two labels are always kept.
pub fn thin(t: &mut Ticks, (lo, hi): (f64, f64), log: bool, pixels: f64, sizes: &[f64]) {
    let at = |v: f64| {
        let u = if log {
            (v / lo).ln() / (hi / lo).ln()
        } else {
            (v - lo) / (hi - lo)
        };
        u * pixels
    };
    let n = t.major.len();
    for stride in 1..n.max(2) {
        let keep: Vec<usize> = (0..n).step_by(stride).collect();
        let clear = keep.windows(2).all(|w| {
            let gap = (at(t.major[w[1]].0) - at(t.major[w[0]].0)).abs();
            gap >= (sizes[w[0]] + sizes[w[1]]) / 2.0 + LABEL_GAP
        });
        if clear || keep.len() <= 2 {
            let dropped = (0..n).filter(|i| i % stride != 0).map(|i| t.major[i].0);
            t.minor.extend(dropped);
            t.major = keep.iter().map(|&i| t.major[i].clone()).collect();
            return;
        }
    }
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
            ["1e-6", "1e-5", "1e-4", "1e-3", "0.01"].to_vec()
        );
        assert!(t.minor.iter().any(|&v| (v - 5e-7).abs() < 1e-20));
        // Within one decade every digit; over one, 1, 2 and 5 times the powers of ten.
        let t = log(0.15, 0.8);
        assert_eq!(
            labels(&t),
            ["0.2", "0.3", "0.4", "0.5", "0.6", "0.7", "0.8"].to_vec()
        );
        let t = log(0.15, 3.0);
        assert_eq!(labels(&t), ["0.2", "0.5", "1", "2"].to_vec());
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

    #[test]
    fn crowded_labels_are_thinned_and_two_always_stay() {
        let mut t = linear(0.0, 1.0);
        let n = t.major.len();
        // Six labels 30 px wide on 100 px: every second one fits (40 px apart).
        thin(&mut t, (0.0, 1.0), false, 100.0, &vec![30.0; n]);
        assert_eq!(labels(&t), ["0", "0.4", "0.8"].to_vec(), "{t:?}");
        let minor = |v: f64| t.minor.iter().any(|m| (m - v).abs() < 1e-12);
        assert!([0.2, 0.6, 1.0].into_iter().all(minor), "{t:?}");
        let mut t = linear(0.0, 1.0);
        thin(&mut t, (0.0, 1.0), false, 800.0, &vec![30.0; n]);
        assert_eq!(t.major.len(), n, "room for all");
    }

    #[test]
    fn log_ranges_widen_to_nearby_marks() {
        assert_eq!(widen_log(0.205, 2.2), (0.2, 2.2));
        assert_eq!(widen_log(0.31, 0.95), (0.3, 1.0));
        assert_eq!(widen_log(0.0059, 0.0102), (0.0059, 0.0102));
        assert_eq!(widen_log(1.5e-7, 6e-3), (1e-7, 1e-2));
        assert_eq!(widen_log(3e-7, 3e-3), (3e-7, 3e-3));
    }
}
