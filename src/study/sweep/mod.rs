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

mod point;
mod range;
pub mod share;
mod tracks;

pub use point::{default_signals, rotor_period, PeriodError, PointError};
pub use range::{grid, parse_range, split_range, RangeError, MAX_POINTS};

use super::{cell, parallel};
use crate::output::charts::{Chart, Series};
use crate::solve::floquet::Monodromy;
use crate::solve::modes::c64;
use crate::Compiled;
use point::evaluate;
use std::fmt::Display;
use std::io::{self, Write};
use std::sync::Mutex;

/// Compiles the model with these extra `NAME=VALUE` params; the error (by default a
/// [`super::CompileError`]) is shown as the point's failure.
pub type CompileWith<'a, E = super::CompileError> =
    dyn Fn(&[String]) -> Result<Compiled, E> + Sync + 'a;

/// The chart of real parts shows modes down to this many times the largest modulus of the
/// points' largest real parts (or of the threshold).
pub const CHART_REACH: f64 = 3.0;

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
    /// Floquet: how the monodromy matrix is built.
    pub monodromy: Monodromy,
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
    /// Each mode's shape (Floquet: at the start, see [`crate::solve::floquet::Floquet`];
    /// Prony: none, empty).
    pub shapes: Vec<Vec<c64>>,
    /// Each mode's track along the grid (0-based, per method; empty off the grid).
    pub tracks: Vec<usize>,
    /// The rotor speed (rad/s) of the per-rev lines; NaN when the model has none.
    pub rotor_speed: f64,
    pub failure: Option<PointError>,
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

/// Runs the sweep: the grid in parallel, its modes followed along it, then each edge's
/// bisection (edges in parallel).
pub fn sweep<E: Display>(
    spec: &SweepSpec,
    compile: &CompileWith<E>,
    tick: &(dyn Fn(Tick) + Sync),
) -> Sweep {
    sweep_streaming(spec, compile, tick, &|_| {})
}

/// [`sweep`], with `rows` called as the grid's points finish: each time the run of finished
/// points from the grid's start grows, with the sweep of that run (its modes followed, no
/// edges yet), whose CSV is the final one's first rows.
pub fn sweep_streaming<E: Display>(
    spec: &SweepSpec,
    compile: &CompileWith<E>,
    tick: &(dyn Fn(Tick) + Sync),
    rows: &(dyn Fn(&Sweep) + Sync),
) -> Sweep {
    let mut points = grid_points(spec, compile, tick, rows);
    tracks::follow(&mut points);
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
    let brackets = brackets(spec, &points, primary);
    let (edges, refinements, notes) = refine_edges(spec, &brackets, primary, compile, tick);
    Sweep {
        param: spec.param.clone(),
        points,
        refinements,
        edges,
        threshold: spec.threshold,
        notes,
    }
}

/// Each bracket bisected (in parallel): the edges, the evaluations and the notes of
/// bisections stopped early, edges and evaluations by value.
fn refine_edges<E: Display>(
    spec: &SweepSpec,
    brackets: &[Bracket],
    primary: Method,
    compile: &CompileWith<E>,
    tick: &(dyn Fn(Tick) + Sync),
) -> (Vec<Edge>, Vec<Point>, Vec<String>) {
    tick(Tick::Planned(brackets.len() * spec.refine));
    let refined = parallel(brackets.len(), |k| {
        bisect(spec, brackets[k], primary, compile, tick)
    });
    let mut edges = Vec::new();
    let mut refinements = Vec::new();
    let mut notes = Vec::new();
    for r in refined.into_iter().flatten() {
        edges.push(r.edge);
        refinements.extend(r.evaluations);
        notes.extend(r.note);
    }
    edges.sort_by(|a, b| a.value.total_cmp(&b.value));
    refinements.sort_by(|a, b| a.value.total_cmp(&b.value));
    (edges, refinements, notes)
}

/// Every value with every method, in parallel; `rows` gets the finished run from the start.
fn grid_points<E: Display>(
    spec: &SweepSpec,
    compile: &CompileWith<E>,
    tick: &(dyn Fn(Tick) + Sync),
    rows: &(dyn Fn(&Sweep) + Sync),
) -> Vec<Point> {
    let jobs: Vec<(f64, Method)> = spec
        .values
        .iter()
        .flat_map(|&v| spec.methods.iter().map(move |&m| (v, m)))
        .collect();
    tick(Tick::Planned(jobs.len()));
    // The points finished beyond the run from the start, and that run as a sweep (its
    // modes followed, their shapes dropped once followed).
    let state = Mutex::new((
        vec![None; jobs.len()],
        tracks::Follower::default(),
        Sweep {
            param: spec.param.clone(),
            points: Vec::new(),
            refinements: Vec::new(),
            edges: Vec::new(),
            threshold: spec.threshold,
            notes: Vec::new(),
        },
    ));
    parallel(jobs.len(), |k| {
        let p = evaluate(spec, jobs[k].0, jobs[k].1, compile, tick);
        if let Ok(mut guard) = state.lock() {
            let (pending, follower, run) = &mut *guard;
            pending[k] = Some(p.clone());
            let from = run.points.len();
            while let Some(mut q) = pending.get_mut(run.points.len()).and_then(Option::take) {
                follower.next(&mut q);
                q.shapes = Vec::new();
                run.points.push(q);
            }
            if run.points.len() > from {
                rows(run);
            }
        }
        p
    })
    .into_iter()
    .enumerate()
    .map(|(k, p)| {
        p.unwrap_or_else(|| Point {
            value: jobs[k].0,
            method: jobs[k].1,
            modes: Vec::new(),
            shapes: Vec::new(),
            tracks: Vec::new(),
            rotor_speed: f64::NAN,
            failure: Some(PointError::Internal),
            cpu_s: f64::NAN,
            detail: String::new(),
        })
    })
    .collect()
}

/// A bracket of an edge: `(lo, hi, lo_unstable)` with `lo` and `hi` of opposite stability.
type Bracket = (f64, f64, bool);

/// Brackets between neighbours of opposite stability (failed points break the chain).
fn brackets(spec: &SweepSpec, points: &[Point], primary: Method) -> Vec<Bracket> {
    let grid: Vec<&Point> = points.iter().filter(|p| p.method == primary).collect();
    let unstable = |p: &Point| p.max_real() > spec.threshold;
    let mut out = Vec::new();
    for w in grid.windows(2) {
        let (a, b) = (w[0], w[1]);
        if a.failure.is_some() || b.failure.is_some() {
            continue;
        }
        if unstable(a) != unstable(b) {
            out.push((a.value, b.value, unstable(a)));
        }
    }
    out
}

/// One edge's bisection.
struct Refined {
    edge: Edge,
    evaluations: Vec<Point>,
    /// Why the bisection stopped early.
    note: Option<String>,
}

/// Bisects a bracket `spec.refine` times with the primary method.
fn bisect<E: Display>(
    spec: &SweepSpec,
    bracket: Bracket,
    primary: Method,
    compile: &CompileWith<E>,
    tick: &(dyn Fn(Tick) + Sync),
) -> Refined {
    let (mut lo, mut hi, lo_unstable) = bracket;
    let mut evaluations = Vec::new();
    let mut note = None;
    for _ in 0..spec.refine {
        let mid = 0.5 * (lo + hi);
        let p = evaluate(spec, mid, primary, compile, tick);
        if let Some(f) = &p.failure {
            note = Some(format!(
                "the edge between {lo} and {hi} was not refined further: at {mid}: {f}"
            ));
            evaluations.push(p);
            break;
        }
        if (p.max_real() > spec.threshold) == lo_unstable {
            lo = mid;
        } else {
            hi = mid;
        }
        evaluations.push(p);
    }
    // `onset` when the motion turns unstable as the param grows.
    let increasing = hi > lo;
    Refined {
        edge: Edge {
            value: 0.5 * (lo + hi),
            bracket: (lo.min(hi), lo.max(hi)),
            onset: lo_unstable != increasing,
        },
        evaluations,
        note,
    }
}

impl Sweep {
    /// The CSV: `PARAM,max_real,min_damping_ratio,method,freq1,real1,freq2,real2,...` (one row
    /// per grid value and method; frequencies in rad/s, real parts in 1/s, modes by decreasing
    /// real part; empty cells where a point failed or has fewer modes), then
    /// `mode1_freq,mode1_real,mode1_damping,...`: the same modes by their track, a column per
    /// followed mode (damping ratio `-Re s / |s|`).
    pub fn write_csv(&self, out: &mut dyn Write) -> io::Result<()> {
        let width = self.points.iter().map(|p| p.modes.len()).max().unwrap_or(0);
        let tracks = tracks::count(&self.points);
        write!(out, "{},max_real,min_damping_ratio,method", self.param)?;
        for k in 1..=width {
            write!(out, ",freq{k},real{k}")?;
        }
        for k in 1..=tracks {
            write!(out, ",mode{k}_freq,mode{k}_real,mode{k}_damping")?;
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
            tracks::write_row(p, tracks, out)?;
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

    /// Real parts against the param: every mode's as markers (down to [`CHART_REACH`] times
    /// the largest modulus of a point's largest real part), the largest as a line per method,
    /// the unstable ranges shaded, `reference` series (e.g. multiblade eigenvalues) on top.
    pub fn chart(&self, title: &str, reference: Vec<Series>) -> Chart {
        let mut series = Vec::new();
        let mut methods: Vec<Method> = Vec::new();
        for p in &self.points {
            if !methods.contains(&p.method) {
                methods.push(p.method);
            }
        }
        // Modes damped far below the largest growth rates (a beam's stiff modes, which the
        // integrator damps at tens of 1/s) are left off the markers: they stay in the CSV.
        let reach = (self.points.iter())
            .filter(|p| p.failure.is_none())
            .map(|p| p.max_real().abs())
            .filter(|x| x.is_finite())
            .fold(self.threshold, f64::max);
        let floor = -CHART_REACH * reach;
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
                    .filter(|&(_, re)| re >= floor)
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
            guides: Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The chart's markers reach down to three times the largest growth rate's modulus: a
    /// stiff mode at -100 1/s is left off (it stays in the CSV), a mode at -2 is drawn.
    #[test]
    fn the_chart_leaves_off_modes_damped_far_below_the_growth_rates() {
        let point = |value: f64| Point {
            value,
            method: Method::Floquet,
            modes: vec![
                c64::new(1.0, 5.0),
                c64::new(-2.0, 5.0),
                c64::new(-100.0, 90.0),
            ],
            shapes: Vec::new(),
            tracks: Vec::new(),
            rotor_speed: f64::NAN,
            failure: None,
            cpu_s: 0.0,
            detail: String::new(),
        };
        let sweep = Sweep {
            param: "Omega_bar".into(),
            points: vec![point(1.0), point(2.0)],
            refinements: Vec::new(),
            edges: Vec::new(),
            threshold: 0.01,
            notes: Vec::new(),
        };
        let chart = sweep.chart("t", Vec::new());
        let markers = chart
            .series
            .iter()
            .find(|s| s.label == "Re s of each mode (floquet)")
            .expect("markers");
        let reals: Vec<f64> = markers.points.iter().map(|p| p.1).collect();
        assert_eq!(reals, vec![1.0, -2.0, 1.0, -2.0]);
    }
}
