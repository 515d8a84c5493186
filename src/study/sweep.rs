//! Stability sweeps (`mbd stability`): the characteristic exponents of a model's motion for
//! each value of a param, by Floquet analysis (THEORY §9.2, [`crate::solve::floquet`]) and/or
//! by a matrix-pencil fit of a transient (§9.3, [`super::prony`]), and the edges of the unstable
//! ranges located by bisection.
//!
//! Contract: each point compiles the model with `NAME=VALUE` added to the `--set` params, in a
//! worker thread of [`super::parallel`]; a point that fails (compile or run time) keeps its row
//! with the failure, never ends the sweep. A point is unstable when its largest real part
//! exceeds the threshold. Between two grid points of opposite stability, the edge is bisected
//! `refine` times with the primary method (Floquet when it is among the methods). Must not read
//! or write files.

use super::prony::{matrix_pencil, PencilSpec};
use super::{cell, parallel, thread_cpu_seconds};
use crate::model::{channel_dim, Drive, JointKind, Probe};
use crate::output::charts::{Chart, Series};
use crate::solve::floquet;
use crate::solve::modes::c64;
use crate::Compiled;
use std::io::{self, Write};

/// Compiles the model with these extra `NAME=VALUE` params; the error is a one-line message.
pub type CompileWith<'a> = dyn Fn(&[String]) -> Result<Compiled, String> + Sync + 'a;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    Floquet,
    Prony,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Floquet => "floquet",
            Method::Prony => "prony",
        }
    }
}

/// What to sweep and how.
#[derive(Clone, Debug)]
pub struct SweepSpec {
    pub param: String,
    pub values: Vec<f64>,
    /// The methods, the primary (edge-finding) one first.
    pub methods: Vec<Method>,
    /// Floquet's period (s); `None`: `2 pi / Omega` of the model's prescribed rotor speed.
    pub period: Option<f64>,
    /// Prony: the channels fitted (empty: [`default_signals`]).
    pub signals: Vec<String>,
    /// Prony: the part of the run fitted (s); `None`: from a tenth of the run to its end.
    pub window: Option<(f64, f64)>,
    /// Prony: samples over the window (the output is decimated to about this many).
    pub samples: usize,
    /// A point is unstable when its largest real part exceeds this (1/s).
    pub threshold: f64,
    /// Bisections of each edge.
    pub refine: usize,
}

/// Progress of a sweep: evaluations planned (added to the total), or one done, with a line
/// that says what it found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Tick {
    Planned(usize),
    Done(String),
}

/// The exponents found at one value by one method.
#[derive(Clone, Debug)]
pub struct Point {
    pub value: f64,
    pub method: Method,
    /// One per mode: `Im s >= 0` (conjugates merged), largest real part first.
    pub modes: Vec<c64>,
    pub failure: Option<String>,
    pub cpu_s: f64,
    /// Floquet: the free coordinates and steps per period; Prony: poles kept and the sample
    /// step.
    pub detail: String,
}

impl Point {
    /// Largest real part (1/s); NaN if the point failed.
    pub fn max_real(&self) -> f64 {
        if self.failure.is_some() || self.modes.is_empty() {
            return f64::NAN;
        }
        self.modes
            .iter()
            .map(|s| s.re)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Smallest damping ratio `-Re s / |s|` over the modes.
    pub fn min_damping_ratio(&self) -> f64 {
        if self.failure.is_some() || self.modes.is_empty() {
            return f64::NAN;
        }
        self.modes
            .iter()
            .map(|s| {
                let r = (s.re * s.re + s.im * s.im).sqrt();
                if r > 0.0 {
                    -s.re / r
                } else {
                    0.0
                }
            })
            .fold(f64::INFINITY, f64::min)
    }
}

/// An edge of an unstable range, bracketed by the last bisection.
#[derive(Clone, Debug, PartialEq)]
pub struct Edge {
    /// The bracket's midpoint.
    pub value: f64,
    pub bracket: (f64, f64),
    /// True where the motion turns unstable as the param grows.
    pub onset: bool,
}

#[derive(Clone, Debug)]
pub struct Sweep {
    pub param: String,
    /// The grid points, by value then method.
    pub points: Vec<Point>,
    /// The bisection evaluations (primary method).
    pub refinements: Vec<Point>,
    pub edges: Vec<Edge>,
    pub threshold: f64,
    /// A failure that stopped the edges from being refined.
    pub notes: Vec<String>,
}

/// `START:STOP:STEP` inclusive of STOP (within a millionth of a step).
pub fn parse_range(text: &str) -> Result<Vec<f64>, String> {
    let parts: Vec<&str> = text.split(':').map(str::trim).collect();
    let [a, b, c] = parts[..] else {
        return Err(format!("the range `{text}` is not START:STOP:STEP"));
    };
    let num = |s: &str, what: &str| {
        s.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("the range's {what} `{s}` is not a number"))
    };
    grid(num(a, "START")?, num(b, "STOP")?, num(c, "STEP")?)
}

/// The values from `start` to `stop` (inclusive, within a millionth of a step) by `step`.
pub fn grid(start: f64, stop: f64, step: f64) -> Result<Vec<f64>, String> {
    let text = format!("{start}:{stop}:{step}");
    if !(start.is_finite() && stop.is_finite() && step.is_finite()) {
        return Err(format!("the range {text} is not finite"));
    }
    if step == 0.0 || (stop - start) * step < 0.0 {
        return Err(format!(
            "the range {text} does not reach STOP from START in steps of STEP"
        ));
    }
    let n = ((stop - start) / step + 1e-6).floor() as usize + 1;
    if n > 10_000 {
        return Err(format!("the range {text} has {n} points; at most 10000"));
    }
    Ok((0..n).map(|i| start + i as f64 * step).collect())
}

/// The period of the model's steady rotation: `2 pi / |Omega|` of its revolute joints driven
/// at a constant rate, if they share one speed.
pub fn rotor_period(c: &Compiled) -> Result<f64, String> {
    let until = c.settings.until;
    let mut speeds: Vec<(String, f64)> = Vec::new();
    for j in &c.model.joints {
        if let JointKind::Revolute {
            drive: Drive::Rate { f },
            ..
        } = &j.kind
        {
            let w = f.eval(0.0);
            let steady = (0..=20).all(|k| {
                let t = until * k as f64 / 20.0;
                (f.eval(t) - w).abs() <= 1e-12 * w.abs().max(1e-300)
            });
            if !steady {
                return Err(format!(
                    "joint `{}` is driven at a speed that varies in time, so the motion is not periodic; give --period T (s) to analyse one interval, or use --method prony",
                    j.name
                ));
            }
            if w != 0.0 {
                speeds.push((j.name.clone(), w.abs()));
            }
        }
    }
    match speeds.first() {
        None => Err("the model has no joint driven at a constant speed, so the period is unknown; give --period T (s): for a steady motion any interval works (e.g. a period of its slowest mode), or use --method prony".to_string()),
        Some((_, w)) => {
            if let Some((name, w2)) = speeds.iter().find(|(_, w2)| (w2 - w).abs() > 1e-9 * w) {
                return Err(format!(
                    "joints `{}` and `{name}` turn at different speeds ({w} and {w2} rad/s); give --period T (s), a common period of both",
                    speeds[0].0
                ));
            }
            Ok(2.0 * std::f64::consts::PI / w)
        }
    }
}

/// One evaluation: compile with the param at `value`, then the method.
fn evaluate(
    spec: &SweepSpec,
    value: f64,
    method: Method,
    compile: &CompileWith,
    tick: &(dyn Fn(Tick) + Sync),
) -> Point {
    let mut point = Point {
        value,
        method,
        modes: Vec::new(),
        failure: None,
        cpu_s: f64::NAN,
        detail: String::new(),
    };
    let set = format!("{}={value}", spec.param);
    match compile(&[set]) {
        Ok(c) => {
            let start = thread_cpu_seconds();
            let result = match method {
                Method::Floquet => floquet_point(spec, &c),
                Method::Prony => prony_point(spec, c),
            };
            point.cpu_s = thread_cpu_seconds() - start;
            match result {
                Ok((modes, detail)) => {
                    point.modes = modes;
                    point.detail = detail;
                }
                Err(e) => point.failure = Some(e),
            }
        }
        Err(e) => point.failure = Some(e),
    }
    let summary = match &point.failure {
        Some(f) => format!("{} = {value} ({}): failed: {f}", spec.param, method.name()),
        None => format!(
            "{} = {value} ({}): largest Re s {:.4e} 1/s, {:.2} s CPU",
            spec.param,
            method.name(),
            point.max_real(),
            point.cpu_s
        ),
    };
    tick(Tick::Done(summary));
    point
}

/// Exponents with `Im s >= 0`, conjugates merged, largest real part first.
fn modes_of(exponents: &[c64]) -> Vec<c64> {
    let mut out: Vec<c64> = Vec::new();
    let mut taken = vec![false; exponents.len()];
    for (i, s) in exponents.iter().enumerate() {
        if taken[i] {
            continue;
        }
        taken[i] = true;
        let scale = (s.re * s.re + s.im * s.im).sqrt().max(1e-12);
        // Its conjugate, if present.
        if let Some(j) = (0..exponents.len()).find(|&j| {
            !taken[j]
                && (exponents[j].re - s.re).abs() <= 1e-8 * scale
                && (exponents[j].im + s.im).abs() <= 1e-8 * scale
                && s.im != 0.0
        }) {
            taken[j] = true;
        }
        out.push(c64::new(s.re, s.im.abs()));
    }
    out.sort_by(|a, b| b.re.total_cmp(&a.re));
    out
}

fn floquet_point(spec: &SweepSpec, c: &Compiled) -> Result<(Vec<c64>, String), String> {
    let l = c.lowered.as_ref().map_err(|d| d.message.clone())?;
    let period = match spec.period {
        Some(t) => t,
        None => rotor_period(c)?,
    };
    let f = floquet::floquet(&l.system, &c.settings, period, &|| {}).map_err(|f| {
        let d = c.failure_diagnostic(&f.failure);
        format!("{} {} (in {})", d.code.as_str(), d.message, f.which())
    })?;
    Ok((
        modes_of(&f.exponents),
        format!(
            "{} free coordinates, {} steps of {:.4e} s per period {:.6} s",
            f.free, f.steps, f.dt, f.period
        ),
    ))
}

fn prony_point(spec: &SweepSpec, mut c: Compiled) -> Result<(Vec<c64>, String), String> {
    let until = c.settings.until;
    let (from, to) = spec.window.unwrap_or((0.1 * until, until));
    let dt = c.settings.dt;
    let every = (((to - from) / dt / spec.samples.max(12) as f64).floor() as usize).max(1);
    c.settings = c.settings.ending_by(to, every);
    let mut out = Vec::new();
    let run = crate::run(&c, &mut out);
    if let Err(f) = &run {
        return Err(format!(
            "{} {}",
            f.diagnostic.code.as_str(),
            f.diagnostic.message
        ));
    }
    let text = String::from_utf8(out).map_err(|e| e.to_string())?;
    let (header, rows) = crate::output::read_csv(&text)?;
    let wanted = if spec.signals.is_empty() {
        default_signals(&c)
    } else {
        spec.signals.clone()
    };
    let columns: Vec<usize> = {
        let mut v = Vec::new();
        for s in &wanted {
            match header.iter().position(|h| h == s) {
                Some(k) => v.push(k),
                None => return Err(format!("the model has no output channel `{s}`")),
            }
        }
        v
    };
    let kept: Vec<&Vec<f64>> = rows
        .iter()
        .filter(|r| r[0] >= from - 1e-9 * dt && r[0] <= to + 1e-9 * dt)
        .collect();
    let signals: Vec<Vec<f64>> = columns
        .iter()
        .map(|&k| kept.iter().map(|r| r[k]).collect())
        .collect();
    let step = dt * every as f64;
    // Signals of one physical dimension share a scale.
    let dims: Vec<Option<crate::model::units::Dim>> = wanted
        .iter()
        .map(|w| {
            c.model
                .outputs
                .iter()
                .find(|o| &o.column == w)
                .and_then(|o| channel_dim(&c.model.joints, &o.probe))
        })
        .collect();
    let groups: Vec<usize> = (0..dims.len())
        .map(|i| {
            dims.iter()
                .position(|d| d.is_some() && *d == dims[i])
                .unwrap_or(i)
        })
        .collect();
    let poles = matrix_pencil(&signals, Some(&groups), step, &PencilSpec::default())?;
    if poles.is_empty() {
        return Err(format!(
            "the transient fit found no pole that holds when the model order grows ({} signals over {from:.3}..{to:.3} s): fit fixed-frame signals (--signals, e.g. multiblade coordinates; a two-bladed rotor has none), or a longer --window",
            signals.len()
        ));
    }
    let mut modes: Vec<c64> = poles.iter().map(|p| p.s).collect();
    modes.sort_by(|a, b| b.re.total_cmp(&a.re));
    Ok((
        modes,
        format!(
            "{} poles from {} signals, {} samples every {:.4e} s over {from:.3}..{to:.3} s",
            poles.len(),
            signals.len(),
            kept.len(),
            step
        ),
    ))
}

/// Prony's default signals: every output channel but the blade coordinates that a
/// `multiblade` output transforms (rotating-frame signals carry the rotor's harmonics; their
/// multiblade coordinates are the fixed-frame signals of THEORY §9.3).
pub fn default_signals(c: &Compiled) -> Vec<String> {
    let mut blades: Vec<usize> = Vec::new();
    for o in &c.model.outputs {
        if let Probe::Multiblade { blades: b, .. } = &o.probe {
            blades.extend(b);
        }
    }
    c.model
        .outputs
        .iter()
        .filter(|o| !matches!(&o.probe, Probe::Joint { joint, .. } if blades.contains(joint)))
        .map(|o| o.column.clone())
        .collect()
}

/// Runs the sweep: the grid in parallel, then each edge's bisection (edges in parallel).
pub fn sweep(spec: &SweepSpec, compile: &CompileWith, tick: &(dyn Fn(Tick) + Sync)) -> Sweep {
    let jobs: Vec<(f64, Method)> = spec
        .values
        .iter()
        .flat_map(|&v| spec.methods.iter().map(move |&m| (v, m)))
        .collect();
    tick(Tick::Planned(jobs.len()));
    let points: Vec<Point> = parallel(jobs.len(), |k| {
        evaluate(spec, jobs[k].0, jobs[k].1, compile, tick)
    })
    .into_iter()
    .enumerate()
    .map(|(k, p)| {
        p.unwrap_or_else(|| Point {
            value: jobs[k].0,
            method: jobs[k].1,
            modes: Vec::new(),
            failure: Some("the evaluation stopped on an internal error (a bug in mbd)".into()),
            cpu_s: f64::NAN,
            detail: String::new(),
        })
    })
    .collect();
    let mut notes = Vec::new();
    let Some(&primary) = spec.methods.first() else {
        return Sweep {
            param: spec.param.clone(),
            points,
            refinements: Vec::new(),
            edges: Vec::new(),
            threshold: spec.threshold,
            notes: vec!["no method was given".to_string()],
        };
    };
    let grid: Vec<&Point> = points.iter().filter(|p| p.method == primary).collect();
    let unstable = |p: &Point| p.max_real() > spec.threshold;
    // Brackets between neighbours of opposite stability (failed points break the chain).
    let mut brackets: Vec<(f64, f64, bool)> = Vec::new();
    for w in grid.windows(2) {
        let (a, b) = (w[0], w[1]);
        if a.failure.is_some() || b.failure.is_some() {
            continue;
        }
        if unstable(a) != unstable(b) {
            brackets.push((a.value, b.value, unstable(a)));
        }
    }
    tick(Tick::Planned(brackets.len() * spec.refine));
    let refined = parallel(brackets.len(), |k| {
        let (mut lo, mut hi, lo_unstable) = brackets[k];
        let mut evals = Vec::new();
        let mut note = None;
        for _ in 0..spec.refine {
            let mid = 0.5 * (lo + hi);
            let p = evaluate(spec, mid, primary, compile, tick);
            if let Some(f) = &p.failure {
                note = Some(format!(
                    "the edge between {lo} and {hi} was not refined further: at {mid}: {f}"
                ));
                evals.push(p);
                break;
            }
            if unstable(&p) == lo_unstable {
                lo = mid;
            } else {
                hi = mid;
            }
            evals.push(p);
        }
        (lo, hi, lo_unstable, evals, note)
    });
    let mut edges = Vec::new();
    let mut refinements = Vec::new();
    for (lo, hi, lo_unstable, evals, note) in refined.into_iter().flatten() {
        // `onset` when the motion turns unstable as the param grows.
        let increasing = hi > lo;
        edges.push(Edge {
            value: 0.5 * (lo + hi),
            bracket: (lo.min(hi), lo.max(hi)),
            onset: lo_unstable != increasing,
        });
        refinements.extend(evals);
        notes.extend(note);
    }
    edges.sort_by(|a, b| a.value.total_cmp(&b.value));
    refinements.sort_by(|a, b| a.value.total_cmp(&b.value));
    Sweep {
        param: spec.param.clone(),
        points,
        refinements,
        edges,
        threshold: spec.threshold,
        notes,
    }
}

impl Sweep {
    /// The CSV: `PARAM,max_real,min_damping_ratio,method,freq1,real1,freq2,real2,...` (one row
    /// per grid value and method; frequencies in rad/s, real parts in 1/s, modes by decreasing
    /// real part; empty cells where a point failed or has fewer modes).
    pub fn write_csv(&self, out: &mut dyn Write) -> io::Result<()> {
        let width = self.points.iter().map(|p| p.modes.len()).max().unwrap_or(0);
        write!(out, "{},max_real,min_damping_ratio,method", self.param)?;
        for k in 1..=width {
            write!(out, ",freq{k},real{k}")?;
        }
        writeln!(out)?;
        for p in &self.points {
            let finite = |x: f64| x.is_finite().then_some(x);
            write!(
                out,
                "{},{},{},{}",
                p.value,
                cell(finite(p.max_real())),
                cell(finite(p.min_damping_ratio())),
                p.method.name()
            )?;
            for k in 0..width {
                match (p.failure.is_none(), p.modes.get(k)) {
                    (true, Some(s)) => write!(out, ",{},{}", s.im, s.re)?,
                    _ => write!(out, ",,")?,
                }
            }
            writeln!(out)?;
        }
        Ok(())
    }

    /// The unstable ranges of the primary method: from the edges, open at the grid's ends.
    pub fn unstable_ranges(&self) -> Vec<(f64, f64)> {
        let primary = match self.points.first() {
            Some(p) => p.method,
            None => return Vec::new(),
        };
        let grid: Vec<&Point> = self.points.iter().filter(|p| p.method == primary).collect();
        let (Some(first), Some(last)) = (grid.first(), grid.last()) else {
            return Vec::new();
        };
        let (lo, hi) = (first.value.min(last.value), first.value.max(last.value));
        let mut out = Vec::new();
        let mut open: Option<f64> = None;
        let starts_unstable = {
            let low = if first.value <= last.value {
                first
            } else {
                last
            };
            low.max_real() > self.threshold
        };
        if starts_unstable {
            open = Some(lo);
        }
        for e in &self.edges {
            // Along increasing values: onset opens, the other closes.
            let opens = if first.value <= last.value {
                e.onset
            } else {
                !e.onset
            };
            if opens {
                open = Some(e.value);
            } else if let Some(a) = open.take() {
                out.push((a, e.value));
            }
        }
        if let Some(a) = open {
            out.push((a, hi));
        }
        out
    }

    /// Real parts against the param: every mode's as markers, the largest as a line per method,
    /// the unstable ranges shaded, `reference` series (e.g. multiblade eigenvalues) on top.
    pub fn chart(&self, title: &str, reference: Vec<Series>) -> Chart {
        let mut series = Vec::new();
        let mut methods: Vec<Method> = Vec::new();
        for p in &self.points {
            if !methods.contains(&p.method) {
                methods.push(p.method);
            }
        }
        for m in &methods {
            let mut all: Vec<&Point> = self
                .points
                .iter()
                .chain(&self.refinements)
                .filter(|p| p.method == *m && p.failure.is_none())
                .collect();
            all.sort_by(|a, b| a.value.total_cmp(&b.value));
            series.push(Series {
                label: format!("largest Re s ({})", m.name()),
                points: all.iter().map(|p| (p.value, p.max_real())).collect(),
                markers_only: false,
            });
            series.push(Series {
                label: format!("Re s of each mode ({})", m.name()),
                points: all
                    .iter()
                    .flat_map(|p| p.modes.iter().map(move |s| (p.value, s.re)))
                    .collect(),
                markers_only: true,
            });
        }
        series.extend(reference);
        Chart {
            title: title.to_string(),
            x_label: self.param.clone(),
            y_label: "Re s [1/s]".to_string(),
            log_x: false,
            log_y: false,
            series,
            shaded: self.unstable_ranges(),
        }
    }
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

    #[test]
    fn conjugate_exponents_are_merged_and_sorted_by_real_part() {
        let e = [
            c64::new(-0.1, 2.0),
            c64::new(0.5, 1.0),
            c64::new(-0.1, -2.0),
            c64::new(0.5, -1.0),
            c64::new(-3.0, 0.0),
        ];
        let m = modes_of(&e);
        assert_eq!(
            m,
            vec![c64::new(0.5, 1.0), c64::new(-0.1, 2.0), c64::new(-3.0, 0.0)]
        );
    }
}
