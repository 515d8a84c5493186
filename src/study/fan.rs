//! Fan plots (Campbell diagrams, `mbd modes --sweep`): the modes of a model for each value of a
//! param, followed from one value to the next.
//!
//! Contract: each point compiles the model with `NAME=VALUE` added to the `--set` params in a
//! worker of [`super::parallel`] and takes its modes with [`crate::modes`]; a point that fails
//! (compile time, run time, or E0605 when the model has no steady motion there) keeps its row
//! with the message. Modes are followed across the points by their shapes: each mode continues
//! the track whose last shape it matches best (the modal assurance criterion), so a track keeps
//! its mode where frequencies cross. Must not read or write files.

use super::parallel;
use super::sweep::{CompileWith, PointError, Tick};
use crate::output::charts::{Chart, Series};
use crate::solve::modes::{c64, Mode};
use std::fmt::Display;
use std::io::{self, Write};

/// What to sweep.
#[derive(Clone, Debug)]
pub struct FanSpec {
    pub param: String,
    pub values: Vec<f64>,
    /// Modes per point, by increasing natural frequency.
    pub count: usize,
    /// Frozen-time eigenvalues where the motion is not steady (see [`crate::modes`]).
    pub frozen: bool,
}

/// The modes at one value of the param.
#[derive(Clone, Debug)]
pub struct FanPoint {
    pub value: f64,
    /// `(track, mode)`, by increasing frequency.
    pub modes: Vec<(usize, Mode)>,
    /// The frame label (`inertial`, `rotating`, `frozen`).
    pub frame: &'static str,
    /// The fastest spin of any node at the start (rad/s): the rotor speed of the per-rev lines.
    pub rotor_speed: f64,
    pub failure: Option<PointError>,
}

#[derive(Clone, Debug)]
pub struct Fan {
    pub param: String,
    pub points: Vec<FanPoint>,
    pub tracks: usize,
}

/// The modal assurance criterion `|a^H b|^2 / (|a|^2 |b|^2)` of two shapes.
fn mac(a: &[c64], b: &[c64]) -> f64 {
    if a.len() != b.len() {
        return 0.0;
    }
    let (mut re, mut im, mut na, mut nb) = (0.0, 0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        re += x.re * y.re + x.im * y.im;
        im += x.re * y.im - x.im * y.re;
        na += x.re * x.re + x.im * x.im;
        nb += y.re * y.re + y.im * y.im;
    }
    if na == 0.0 || nb == 0.0 {
        0.0
    } else {
        (re * re + im * im) / (na * nb)
    }
}

/// Runs the sweep (points in parallel) and follows the modes across it.
pub fn fan<E: Display>(
    spec: &FanSpec,
    compile: &CompileWith<E>,
    tick: &(dyn Fn(Tick) + Sync),
) -> Fan {
    tick(Tick::Planned(spec.values.len()));
    let raw = parallel(spec.values.len(), |k| {
        let value = spec.values[k];
        let result = compile(&[format!("{}={value}", spec.param)])
            .map_err(|e| PointError::Compile(e.to_string()))
            .and_then(|c| crate::modes(&c, spec.frozen).map_err(|d| PointError::diagnostic(&d)));
        let summary = match &result {
            Ok(m) => format!(
                "{} = {value}: {} modes, lowest {:.6} rad/s",
                spec.param,
                m.modes.len().min(spec.count),
                m.modes.first().map_or(f64::NAN, Mode::omega)
            ),
            Err(e) => format!("{} = {value}: failed: {e}", spec.param),
        };
        tick(Tick::Done(summary));
        result
    });
    let mut points = Vec::new();
    // The last shape of each track.
    let mut last: Vec<Vec<c64>> = Vec::new();
    for (k, r) in raw.into_iter().enumerate() {
        let value = spec.values[k];
        let r = r.unwrap_or(Err(PointError::Internal));
        let m = match r {
            Ok(m) => m,
            Err(e) => {
                points.push(FanPoint {
                    value,
                    modes: Vec::new(),
                    frame: "",
                    rotor_speed: f64::NAN,
                    failure: Some(e),
                });
                continue;
            }
        };
        let modes: Vec<Mode> = m.modes.into_iter().take(spec.count).collect();
        // Greedy assignment by decreasing MAC; a mode matching no track well starts one.
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (i, md) in modes.iter().enumerate() {
            for (t, s) in last.iter().enumerate() {
                pairs.push((mac(&md.shape, s), i, t));
            }
        }
        pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut track = vec![usize::MAX; modes.len()];
        let mut taken = vec![false; last.len()];
        for (v, i, t) in pairs {
            if v >= 0.5 && track[i] == usize::MAX && !taken[t] {
                track[i] = t;
                taken[t] = true;
            }
        }
        let mut out = Vec::new();
        for (i, md) in modes.into_iter().enumerate() {
            let t = if track[i] == usize::MAX {
                last.push(Vec::new());
                last.len() - 1
            } else {
                track[i]
            };
            last[t].clone_from(&md.shape);
            out.push((t, md));
        }
        points.push(FanPoint {
            value,
            modes: out,
            frame: m.frame.label(),
            rotor_speed: m.rotor_speed,
            failure: None,
        });
    }
    Fan {
        param: spec.param.clone(),
        points,
        tracks: last.len(),
    }
}

impl Fan {
    /// The CSV: `PARAM,mode,frequency_hz,omega_rad_s,damping_ratio,real_per_s,imag_rad_s,frame,
    /// rotor_speed_rad_s`, one row per point and mode (`mode` is the track, 1-based); a failed
    /// point keeps one row with empty cells.
    pub fn write_csv(&self, out: &mut dyn Write) -> io::Result<()> {
        writeln!(
            out,
            "{},mode,frequency_hz,omega_rad_s,damping_ratio,real_per_s,imag_rad_s,frame,rotor_speed_rad_s",
            self.param
        )?;
        for p in &self.points {
            if p.failure.is_some() {
                writeln!(out, "{:?},,,,,,,,", p.value + 0.0)?;
                continue;
            }
            for (t, m) in &p.modes {
                writeln!(
                    out,
                    "{:?},{},{:?},{:?},{:?},{:?},{:?},{},{:?}",
                    p.value + 0.0,
                    t + 1,
                    m.frequency_hz() + 0.0,
                    m.omega() + 0.0,
                    m.damping_ratio() + 0.0,
                    m.s.re + 0.0,
                    m.s.im + 0.0,
                    p.frame,
                    p.rotor_speed + 0.0
                )?;
            }
        }
        Ok(())
    }

    /// Natural frequency (rad/s) of each mode against the param, one line per track, with the
    /// per-revolution lines `n Omega` of the rotor speed where the model spins.
    pub fn chart(&self, title: &str) -> Chart {
        let mut series: Vec<Series> = (0..self.tracks)
            .map(|t| Series {
                label: format!("mode {}", t + 1),
                points: self
                    .points
                    .iter()
                    .flat_map(|p| {
                        p.modes
                            .iter()
                            .filter(move |(k, _)| *k == t)
                            .map(move |(_, m)| (p.value, m.omega()))
                    })
                    .collect(),
                markers_only: false,
            })
            .collect();
        let ok: Vec<&FanPoint> = self.points.iter().filter(|p| p.failure.is_none()).collect();
        let top = ok
            .iter()
            .flat_map(|p| p.modes.iter().map(|(_, m)| m.omega()))
            .fold(0.0f64, f64::max);
        let fastest = ok.iter().map(|p| p.rotor_speed).fold(0.0f64, f64::max);
        if fastest > 0.0 && top > 0.0 {
            let revs = ((top / fastest).ceil() as usize).clamp(1, 8);
            for n in 1..=revs {
                series.push(Series {
                    label: format!("{n}/rev"),
                    points: ok
                        .iter()
                        .map(|p| (p.value, n as f64 * p.rotor_speed))
                        .collect(),
                    markers_only: false,
                });
            }
        }
        Chart {
            title: title.to_string(),
            x_label: self.param.clone(),
            y_label: "natural frequency [rad/s]".to_string(),
            log_x: false,
            log_y: false,
            series,
            shaded: Vec::new(),
            guides: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mac_is_one_for_scaled_shapes_and_zero_for_orthogonal_ones() {
        let a = [c64::new(1.0, 0.0), c64::new(0.0, 2.0)];
        let b = [c64::new(0.0, 3.0), c64::new(-6.0, 0.0)];
        assert!((mac(&a, &b) - 1.0).abs() < 1e-15);
        let c = [c64::new(2.0, 0.0), c64::new(0.0, -1.0)];
        assert!(mac(&a, &c).abs() < 1e-15);
    }
}
