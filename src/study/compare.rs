//! Comparing a channel with a reference: samples, interpolation, the relative error and the
//! observed order of convergence.
//!
//! The error of a run is `|y - y_ref| / max_t |y_ref(t)|`: the difference at a time `T`
//! (`--at`), or its largest value over the run's output times, relative to the largest
//! magnitude of the reference channel over the run (over the run's output times for an exact
//! reference, over the reference's samples within the run's span otherwise; 1, an absolute
//! error, if the reference is zero throughout). Values at a time come from the row at that
//! time (within `1e-9 dt`), else from cubic (4-point Lagrange) interpolation.

use crate::runtime::timefn::TimeFn;
use std::fmt;

/// A table that gives no samples of a channel (a reference file). `Display` is the message.
#[derive(Clone, Debug, PartialEq)]
pub enum SamplesError {
    /// No `t` (or `time`) column.
    NoTime,
    /// No column of the channel; `columns` are the others but time.
    NoColumn {
        channel: String,
        columns: Vec<String>,
    },
    /// The time of this row (1-based, after the header) is not a number.
    TimeNotANumber { row: usize },
    /// The time of this row is not after the previous row's.
    NotIncreasing { row: usize, t: f64, after: f64 },
}

impl fmt::Display for SamplesError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            SamplesError::NoTime => write!(f, "the CSV has no `t` (or `time`) column"),
            SamplesError::NoColumn { channel, columns } => write!(
                f,
                "no column `{channel}`; its columns are: {}",
                columns.join(", ")
            ),
            SamplesError::TimeNotANumber { row } => {
                write!(f, "row {row} has a time that is not a number")
            }
            SamplesError::NotIncreasing { row, t, after } => write!(
                f,
                "the times do not increase at row {row} (t = {t} after {after})"
            ),
        }
    }
}

impl std::error::Error for SamplesError {}

/// One channel against time, times increasing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Samples {
    pub t: Vec<f64>,
    pub y: Vec<f64>,
}

impl Samples {
    /// The time column (`t`, or `time`) and the column `channel` of a CSV table.
    pub fn from_table(
        header: &[String],
        rows: &[Vec<f64>],
        channel: &str,
    ) -> Result<Samples, SamplesError> {
        let time = header
            .iter()
            .position(|h| h == "t")
            .or_else(|| header.iter().position(|h| h == "time"))
            .ok_or(SamplesError::NoTime)?;
        let Some(k) = header.iter().position(|h| h == channel) else {
            let columns: Vec<String> = header
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != time)
                .map(|(_, h)| h.clone())
                .collect();
            return Err(SamplesError::NoColumn {
                channel: channel.to_string(),
                columns,
            });
        };
        Ok(Samples {
            t: rows.iter().map(|r| r[time]).collect(),
            y: rows.iter().map(|r| r[k]).collect(),
        })
    }

    /// An error unless the times are finite and strictly increasing.
    pub fn check_increasing(&self) -> Result<(), SamplesError> {
        if let Some(k) = self.t.iter().position(|t| !t.is_finite()) {
            return Err(SamplesError::TimeNotANumber { row: k + 1 });
        }
        match self.t.windows(2).position(|w| w[1] <= w[0]) {
            Some(k) => Err(SamplesError::NotIncreasing {
                row: k + 2,
                t: self.t[k + 1],
                after: self.t[k],
            }),
            None => Ok(()),
        }
    }

    /// The first and last time.
    pub fn span(&self) -> Option<(f64, f64)> {
        Some((*self.t.first()?, *self.t.last()?))
    }

    /// The value at `t`: the row within `tol` of it, else cubic interpolation; `None`
    /// outside the samples' span.
    pub fn value(&self, t: f64, tol: f64) -> Option<f64> {
        let (first, last) = self.span()?;
        if !(t >= first - tol && t <= last + tol) {
            return None;
        }
        let k = self.t.partition_point(|&x| x < t);
        for j in [k, k.wrapping_sub(1)] {
            if let Some(&tj) = self.t.get(j) {
                if (tj - t).abs() <= tol {
                    return Some(self.y[j]);
                }
            }
        }
        // t_{k-1} < t < t_k: the four points around the interval (fewer if there are fewer).
        let n = self.t.len();
        let width = n.min(4);
        let start = k.saturating_sub(2).min(n - width);
        Some(lagrange(
            &self.t[start..start + width],
            &self.y[start..start + width],
            t,
        ))
    }
}

/// The polynomial through the points `(ts[i], ys[i])`, evaluated at `t`.
pub fn lagrange(ts: &[f64], ys: &[f64], t: f64) -> f64 {
    let mut sum = 0.0;
    for (i, (&ti, &yi)) in ts.iter().zip(ys).enumerate() {
        let mut w = 1.0;
        for (j, &tj) in ts.iter().enumerate() {
            if j != i {
                w *= (t - tj) / (ti - tj);
            }
        }
        sum += w * yi;
    }
    sum
}

/// What a run is compared with.
#[derive(Clone, Debug, PartialEq)]
pub enum Reference {
    /// The model's `exact` solution of the channel.
    Exact(TimeFn),
    /// A finer run, or a file.
    Samples(Samples),
}

impl Reference {
    fn value(&self, t: f64, tol: f64) -> Option<f64> {
        match self {
            Reference::Exact(f) => Some(f.eval(t)),
            Reference::Samples(s) => s.value(t, tol),
        }
    }

    /// The largest magnitude of the reference over the run (1 if it is zero throughout).
    fn scale(&self, run: &Samples, tol: f64) -> f64 {
        let biggest = match (self, run.span()) {
            (_, None) => 0.0,
            (Reference::Exact(f), _) => run.t.iter().map(|&t| f.eval(t).abs()).fold(0.0, f64::max),
            (Reference::Samples(s), Some((first, last))) => {
                s.t.iter()
                    .zip(&s.y)
                    .filter(|(t, _)| **t >= first - tol && **t <= last + tol)
                    .map(|(_, y)| y.abs())
                    .fold(0.0, f64::max)
            }
        };
        if biggest > 0.0 && biggest.is_finite() {
            biggest
        } else {
            1.0
        }
    }
}

/// The relative error of a run with time step `dt` (see the module's doc), at `at` or the
/// largest over the run's output times.
pub fn relative_error(
    run: &Samples,
    reference: &Reference,
    at: Option<f64>,
    dt: f64,
) -> Result<f64, String> {
    let tol = 1e-9 * dt;
    let scale = reference.scale(run, tol);
    let missing = |t: f64| format!("the reference does not cover t = {t} s");
    match at {
        Some(t) => {
            let y = run
                .value(t, tol)
                .ok_or_else(|| format!("the run does not reach t = {t} s"))?;
            let r = reference.value(t, tol).ok_or_else(|| missing(t))?;
            Ok((y - r).abs() / scale)
        }
        None => {
            if run.t.is_empty() {
                return Err("the run wrote no rows".to_string());
            }
            let mut worst: f64 = 0.0;
            for (&t, &y) in run.t.iter().zip(&run.y) {
                let r = reference.value(t, tol).ok_or_else(|| missing(t))?;
                let e = (y - r).abs();
                worst = if e.is_nan() { f64::NAN } else { worst.max(e) };
            }
            Ok(worst / scale)
        }
    }
}

/// The observed order of convergence of one integrator's runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Order {
    /// Least-squares slope of log(error) against log(dt) over all runs.
    pub fit: f64,
    /// The slope between the two finest runs.
    pub finest_pair: f64,
}

/// The order from `(dt, error)` pairs; runs without a finite positive error are left out;
/// `None` with fewer than two distinct steps left.
pub fn observed_order(runs: &[(f64, f64)]) -> Option<Order> {
    let mut pts: Vec<(f64, f64)> = runs
        .iter()
        .filter(|(h, e)| *h > 0.0 && h.is_finite() && *e > 0.0 && e.is_finite())
        .map(|(h, e)| (h.ln(), e.ln()))
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    pts.dedup_by(|a, b| a.0 == b.0);
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    let finest_pair = (pts[1].1 - pts[0].1) / (pts[1].0 - pts[0].0);
    Some(Order {
        fit: sxy / sxx,
        finest_pair,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cubic(t: f64) -> f64 {
        1.0 + t - 2.0 * t * t + 0.5 * t * t * t
    }

    fn samples(ts: &[f64], f: fn(f64) -> f64) -> Samples {
        Samples {
            t: ts.to_vec(),
            y: ts.iter().map(|&t| f(t)).collect(),
        }
    }

    #[test]
    fn interpolation_is_exact_for_cubics_and_takes_rows_as_they_are() {
        let s = samples(&[0.0, 0.1, 0.25, 0.3, 0.5, 0.9, 1.0], cubic);
        for t in [0.05, 0.2, 0.27, 0.4, 0.95, 0.999] {
            let v = s.value(t, 1e-12).unwrap_or(f64::NAN);
            assert!((v - cubic(t)).abs() < 1e-12, "t = {t}: {v}");
        }
        // Within the tolerance of a row: the row itself.
        assert_eq!(s.value(0.3 + 1e-13, 1e-12), Some(cubic(0.3)));
        assert_eq!(s.value(1.5, 1e-12), None);
        assert_eq!(s.value(-0.1, 1e-12), None);
        let two = samples(&[0.0, 1.0], |t| 3.0 * t);
        assert_eq!(two.value(0.5, 1e-12), Some(1.5));
    }

    #[test]
    fn the_error_is_relative_to_the_references_largest_magnitude() {
        let run = samples(&[0.0, 0.5, 1.0], |t| 2.0 * t + 0.01);
        let exact = Reference::Exact(TimeFn::binary(
            crate::runtime::timefn::Binary::Mul,
            TimeFn::constant(2.0),
            TimeFn::Time,
        ));
        let e = relative_error(&run, &exact, None, 0.5).unwrap_or(f64::NAN);
        assert!((e - 0.01 / 2.0).abs() < 1e-15, "{e}");
        let e = relative_error(&run, &exact, Some(0.25), 0.5).unwrap_or(f64::NAN);
        assert!((e - 0.005).abs() < 1e-15, "{e}");
        let fine = Reference::Samples(samples(&[0.0, 0.25, 0.5, 0.75], |t| 2.0 * t));
        assert!(
            relative_error(&run, &fine, None, 0.5).is_err(),
            "t = 1 is not covered"
        );
    }

    #[test]
    fn order_of_a_second_order_method() {
        let runs: Vec<(f64, f64)> = [0.1, 0.05, 0.025, 0.0125]
            .iter()
            .map(|&h| (h, 3.0 * h * h * (1.0 + h)))
            .collect();
        let o = observed_order(&runs).unwrap_or(Order {
            fit: 0.0,
            finest_pair: 0.0,
        });
        assert!(
            (o.fit - 2.0).abs() < 0.1 && (o.finest_pair - 2.0).abs() < 0.02,
            "{o:?}"
        );
        assert!(observed_order(&[(0.1, 1.0), (0.05, f64::NAN)]).is_none());
    }
}
