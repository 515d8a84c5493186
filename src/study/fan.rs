//! Fan plots (Campbell diagrams, `mbd modes --sweep`): the modes of a model for each value of a
//! param, followed from one value to the next.
//!
//! Contract: each point compiles the model with `NAME=VALUE` added to the `--set` params in a
//! worker of [`super::parallel`] and takes its modes with [`crate::modes`]; a point that fails
//! (compile time, run time, or E0605 when the model has no steady motion there) keeps its row
//! with the message. Modes are followed across the points by their shapes: each mode continues
//! the track whose last shape it matches best ([`super::tracking`]), so a track keeps its mode
//! where frequencies cross. Must not read or write files.

use super::parallel;
use super::sweep::{CompileWith, PointError, Tick};
use super::tracking::{campbell, Column, Tracker};
use crate::output::charts::Chart;
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
    let mut tracker = Tracker::new();
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
        let keys: Vec<(c64, &[c64])> = modes.iter().map(|md| (md.s, &md.shape[..])).collect();
        let tracks = tracker.follow(&keys);
        points.push(FanPoint {
            value,
            modes: tracks.into_iter().zip(modes).collect(),
            frame: m.frame.label(),
            rotor_speed: m.rotor_speed,
            failure: None,
        });
    }
    Fan {
        param: spec.param.clone(),
        points,
        tracks: tracker.tracks(),
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

    /// The Campbell diagram (see [`campbell`]): each mode's natural frequency (rad/s)
    /// against the param, one line per track, with the per-revolution lines `n Omega` of the
    /// rotor speed where the model spins; below, the real parts, the ranges where a mode grows
    /// shaded.
    pub fn chart(&self, title: &str) -> Vec<Chart> {
        let ok: Vec<&FanPoint> = self.points.iter().filter(|p| p.failure.is_none()).collect();
        let columns: Vec<Column> = ok
            .iter()
            .map(|p| Column {
                value: p.value,
                rotor_speed: p.rotor_speed,
                modes: p
                    .modes
                    .iter()
                    .map(|(t, m)| (*t, c64::new(m.s.re, m.omega())))
                    .collect(),
            })
            .collect();
        campbell(
            title,
            &self.param,
            &columns,
            self.tracks,
            growing(&ok),
            Vec::new(),
        )
    }
}

/// The ranges of the param over which some mode grows (`Re s` above `GROWING` of its
/// modulus, round-off kept out), from the first to the last such point of each run of them.
fn growing(points: &[&FanPoint]) -> Vec<(f64, f64)> {
    let grows = |p: &FanPoint| {
        p.modes
            .iter()
            .any(|(_, m)| m.s.re > GROWING * m.s.re.hypot(m.s.im).max(f64::MIN_POSITIVE))
    };
    let mut out: Vec<(f64, f64)> = Vec::new();
    let mut open: Option<(f64, f64)> = None;
    for p in points {
        match (grows(p), open) {
            (true, Some((a, _))) => open = Some((a, p.value)),
            (true, None) => open = Some((p.value, p.value)),
            (false, Some(r)) => {
                out.push(r);
                open = None;
            }
            (false, None) => {}
        }
    }
    out.extend(open);
    out
}

/// A mode grows when its real part exceeds this share of its modulus.
const GROWING: f64 = 1e-6;
