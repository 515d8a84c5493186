//! One evaluation of a sweep: the model compiled with the param at one value, then its
//! exponents by Floquet analysis or by a transient fit; and why an evaluation failed.

use super::{Method, Point, SweepSpec, Tick};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::{channel_dim, Drive, JointKind, Probe};
use crate::solve::floquet;
use crate::solve::modes::c64;
use crate::study::prony::{matrix_pencil, PencilError, PencilSpec};
use crate::study::thread_cpu_seconds;
use crate::Compiled;
use std::fmt;

/// Why a sweep point (or a fan point) has no exponents. `Display` is the line its row keeps.
#[derive(Clone, Debug, PartialEq)]
pub enum PointError {
    /// The model did not compile with the param at this value (the compile function's
    /// message).
    Compile(String),
    /// Floquet: the period is unknown.
    Period(PeriodError),
    /// Floquet: a perturbed run failed.
    Floquet {
        code: Code,
        message: String,
        run: String,
    },
    /// A run (Prony's transient) or an analysis (a fan point's modes) failed.
    Diagnostic { code: Code, message: String },
    /// The run's CSV could not be read back.
    Output(String),
    /// Prony: a `--signals` channel the model does not write.
    NoChannel { name: String },
    /// Prony: the matrix pencil failed.
    Pencil(PencilError),
    /// Prony: no pole held when the model order grew.
    NoPole { signals: usize, from: f64, to: f64 },
    /// The worker thread panicked.
    Internal,
    /// A failure read back from a sweep's share (`mbd merge`): its line.
    Shared(String),
}

impl PointError {
    pub(crate) fn diagnostic(d: &Diagnostic) -> PointError {
        PointError::Diagnostic {
            code: d.code,
            message: d.message.clone(),
        }
    }
}

impl fmt::Display for PointError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            PointError::Compile(m) | PointError::Output(m) | PointError::Shared(m) => {
                write!(f, "{m}")
            }
            PointError::Period(e) => write!(f, "{e}"),
            PointError::Floquet { code, message, run } => {
                write!(f, "{} {message} (in {run})", code.as_str())
            }
            PointError::Diagnostic { code, message } => write!(f, "{} {message}", code.as_str()),
            PointError::NoChannel { name } => {
                write!(f, "the model has no output channel `{name}`")
            }
            PointError::Pencil(e) => write!(f, "{e}"),
            PointError::NoPole { signals, from, to } => write!(
                f,
                "the transient fit found no pole that holds when the model order grows ({signals} signals over {from:.3}..{to:.3} s): fit fixed-frame signals (--signals, e.g. multiblade coordinates; a two-bladed rotor has none), or a longer --window"
            ),
            PointError::Internal => write!(
                f,
                "the evaluation stopped on an internal error (a bug in mbd)"
            ),
        }
    }
}

impl std::error::Error for PointError {}

/// Why the model's period is unknown (Floquet without `--period`).
#[derive(Clone, Debug, PartialEq)]
pub enum PeriodError {
    /// A revolute joint's prescribed speed varies in time.
    VaryingSpeed { joint: String },
    /// No revolute joint is driven at a constant, non-zero speed.
    NoDrivenJoint,
    /// Two driven joints turn at different speeds (rad/s).
    DifferentSpeeds {
        first: String,
        second: String,
        speed: f64,
        other: f64,
    },
}

impl fmt::Display for PeriodError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            PeriodError::VaryingSpeed { joint } => write!(
                f,
                "joint `{joint}` is driven at a speed that varies in time, so the motion is not periodic; give --period T (s) to analyse one interval, or use --method prony"
            ),
            PeriodError::NoDrivenJoint => write!(
                f,
                "the model has no joint driven at a constant speed, so the period is unknown; give --period T (s): for a steady motion any interval works (e.g. a period of its slowest mode), or use --method prony"
            ),
            PeriodError::DifferentSpeeds {
                first,
                second,
                speed,
                other,
            } => write!(
                f,
                "joints `{first}` and `{second}` turn at different speeds ({speed} and {other} rad/s); give --period T (s), a common period of both"
            ),
        }
    }
}

impl std::error::Error for PeriodError {}

/// The period of the model's steady rotation: `2 pi / |Omega|` of its revolute joints driven
/// at a constant rate, if they share one speed.
pub fn rotor_period(c: &Compiled) -> Result<f64, PeriodError> {
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
                return Err(PeriodError::VaryingSpeed {
                    joint: j.name.clone(),
                });
            }
            if w != 0.0 {
                speeds.push((j.name.clone(), w.abs()));
            }
        }
    }
    let Some((first, w)) = speeds.first() else {
        return Err(PeriodError::NoDrivenJoint);
    };
    if let Some((name, w2)) = speeds.iter().find(|(_, w2)| (w2 - w).abs() > 1e-9 * w) {
        return Err(PeriodError::DifferentSpeeds {
            first: first.clone(),
            second: name.clone(),
            speed: *w,
            other: *w2,
        });
    }
    Ok(2.0 * std::f64::consts::PI / w)
}

/// One evaluation: compile with the param at `value`, then the method.
pub(super) fn evaluate<E: fmt::Display>(
    spec: &SweepSpec,
    value: f64,
    method: Method,
    compile: &super::CompileWith<E>,
    tick: &(dyn Fn(Tick) + Sync),
) -> Point {
    let mut point = Point {
        value,
        method,
        modes: Vec::new(),
        shapes: Vec::new(),
        tracks: Vec::new(),
        rotor_speed: f64::NAN,
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
                Ok(found) => {
                    (point.modes, point.shapes) = found.modes.into_iter().unzip();
                    point.rotor_speed = found.rotor_speed;
                    point.detail = found.detail;
                }
                Err(e) => point.failure = Some(e),
            }
        }
        Err(e) => point.failure = Some(PointError::Compile(e.to_string())),
    }
    tick(Tick::Done(summary(spec, &point)));
    point
}

/// The progress line of a finished evaluation.
fn summary(spec: &SweepSpec, point: &Point) -> String {
    let (value, method) = (point.value, point.method);
    match &point.failure {
        Some(f) => format!("{} = {value} ({}): failed: {f}", spec.param, method.name()),
        None => format!(
            "{} = {value} ({}): largest Re s {:.4e} 1/s, {:.2} s CPU{}",
            spec.param,
            method.name(),
            point.max_real(),
            point.cpu_s,
            // Partial Floquet says what it did; multipliers at round-off, how many.
            ["; partial: ", "; at round-off: "]
                .iter()
                .filter_map(|key| point.detail.split_once(key).map(|(_, p)| (key, p)))
                .map(|(key, p)| {
                    let p = p.split("; ").next().unwrap_or(p);
                    format!(" ({}{p})", &key[2..])
                })
                .collect::<String>()
        ),
    }
}

/// Exponents with `Im s >= 0`, conjugates merged, largest real part first, each with its
/// shape (conjugated with a negative `Im s`; empty when unknown).
fn modes_of(exponents: &[(c64, Vec<c64>)]) -> Vec<(c64, Vec<c64>)> {
    let mut out: Vec<(c64, Vec<c64>)> = Vec::new();
    let mut taken = vec![false; exponents.len()];
    for (i, (s, shape)) in exponents.iter().enumerate() {
        if taken[i] {
            continue;
        }
        taken[i] = true;
        let scale = (s.re * s.re + s.im * s.im).sqrt().max(1e-12);
        // Its conjugate, if present.
        if let Some(j) = (0..exponents.len()).find(|&j| {
            let o = exponents[j].0;
            !taken[j]
                && (o.re - s.re).abs() <= 1e-8 * scale
                && (o.im + s.im).abs() <= 1e-8 * scale
                && s.im != 0.0
        }) {
            taken[j] = true;
        }
        let shape = if s.im < 0.0 {
            shape.iter().map(|x| c64::new(x.re, -x.im)).collect()
        } else {
            shape.clone()
        };
        out.push((c64::new(s.re, s.im.abs()), shape));
    }
    out.sort_by(|a, b| b.0.re.total_cmp(&a.0.re));
    out
}

/// What an evaluation found: the modes (exponent and shape, largest real part first), the
/// rotor speed (rad/s; NaN without one) and the detail line.
struct Found {
    modes: Vec<(c64, Vec<c64>)>,
    rotor_speed: f64,
    detail: String,
}

fn floquet_point(spec: &SweepSpec, c: &Compiled) -> Result<Found, PointError> {
    let l = &c.lowered;
    let period = match spec.period {
        Some(t) => t,
        None => rotor_period(c).map_err(PointError::Period)?,
    };
    let f = floquet::floquet_by(&l.system, &c.settings, period, spec.monodromy, &|| {}).map_err(
        |f| {
            let d = c.failure_diagnostic(&f.failure);
            PointError::Floquet {
                code: d.code,
                message: d.message,
                run: f.which(),
            }
        },
    )?;
    // The frequencies resolved by each mode's dominant harmonic (THEORY §9.2 step 4).
    let resolved: Vec<(c64, Vec<c64>)> = (f.exponents.iter().zip(&f.frequencies))
        .zip(f.shapes)
        .map(|((s, &w), shape)| (c64::new(s.re, w), shape))
        .collect();
    Ok(Found {
        modes: modes_of(&resolved),
        rotor_speed: std::f64::consts::TAU / period,
        detail: format!(
            "{} free coordinates, {} steps of {:.4e} s per period {:.6} s{}",
            f.free,
            f.steps,
            f.dt,
            f.period,
            f.partial.as_ref().map_or(String::new(), |p| format!(
                "; partial: {} multipliers wanted, {} runs of a period carrying {} directions{}",
                p.wanted,
                p.products,
                p.block,
                if p.converged {
                    ""
                } else {
                    " (not converged before the basis spanned the state)"
                }
            )),
        ) + &f.unresolved.as_ref().map_or(String::new(), |u| {
            format!(
                "; at round-off: {} multipliers of modulus below {:.1e}, Re s < {:.4} 1/s, not listed",
                u.count, u.modulus, u.real_below
            )
        }),
    })
}

/// The columns of a decimated transient that Prony fits.
struct Transient {
    signals: Vec<Vec<f64>>,
    /// The signals' groups: signals of one physical dimension share a scale.
    groups: Vec<usize>,
    samples: usize,
    step: f64,
    window: (f64, f64),
}

fn prony_point(spec: &SweepSpec, c: Compiled) -> Result<Found, PointError> {
    let rotor_speed = rotor_period(&c).map_or(f64::NAN, |t| std::f64::consts::TAU / t);
    let t = transient(spec, c)?;
    let (from, to) = t.window;
    let poles = matrix_pencil(&t.signals, Some(&t.groups), t.step, &PencilSpec::default())
        .map_err(PointError::Pencil)?;
    if poles.is_empty() {
        return Err(PointError::NoPole {
            signals: t.signals.len(),
            from,
            to,
        });
    }
    let mut modes: Vec<(c64, Vec<c64>)> = poles.iter().map(|p| (p.s, Vec::new())).collect();
    modes.sort_by(|a, b| b.0.re.total_cmp(&a.0.re));
    Ok(Found {
        modes,
        rotor_speed,
        detail: format!(
            "{} poles from {} signals, {} samples every {:.4e} s over {from:.3}..{to:.3} s",
            poles.len(),
            t.signals.len(),
            t.samples,
            t.step
        ),
    })
}

/// Runs the model to the window's end, written about `spec.samples` times over the window,
/// and reads back the signals inside it.
fn transient(spec: &SweepSpec, mut c: Compiled) -> Result<Transient, PointError> {
    let until = c.settings.until;
    let (from, to) = spec.window.unwrap_or((0.1 * until, until));
    let dt = c.settings.dt;
    let every = (((to - from) / dt / spec.samples.max(12) as f64).floor() as usize).max(1);
    c.settings = c.settings.ending_by(to, every);
    let mut out = Vec::new();
    if let Err(f) = crate::run(&c, &mut out) {
        return Err(PointError::diagnostic(&f.diagnostic));
    }
    let text = String::from_utf8(out).map_err(|e| PointError::Output(e.to_string()))?;
    let (header, rows) = crate::output::read_csv(&text).map_err(PointError::Output)?;
    let wanted = if spec.signals.is_empty() {
        default_signals(&c)
    } else {
        spec.signals.clone()
    };
    let columns = wanted
        .iter()
        .map(|s| {
            header
                .iter()
                .position(|h| h == s)
                .ok_or_else(|| PointError::NoChannel { name: s.clone() })
        })
        .collect::<Result<Vec<usize>, _>>()?;
    let kept: Vec<&Vec<f64>> = rows
        .iter()
        .filter(|r| r[0] >= from - 1e-9 * dt && r[0] <= to + 1e-9 * dt)
        .collect();
    Ok(Transient {
        signals: columns
            .iter()
            .map(|&k| kept.iter().map(|r| r[k]).collect())
            .collect(),
        groups: dimension_groups(&c, &wanted),
        samples: kept.len(),
        step: dt * every as f64,
        window: (from, to),
    })
}

/// For each signal, the first signal of the same physical dimension (itself if none or its
/// dimension is unknown).
fn dimension_groups(c: &Compiled, wanted: &[String]) -> Vec<usize> {
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
    (0..dims.len())
        .map(|i| {
            dims.iter()
                .position(|d| d.is_some() && *d == dims[i])
                .unwrap_or(i)
        })
        .collect()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conjugate_exponents_are_merged_and_sorted_by_real_part() {
        let e = [
            c64::new(-0.1, 2.0),
            c64::new(0.5, 1.0),
            c64::new(-0.1, -2.0),
            c64::new(0.5, -1.0),
            c64::new(-3.0, 0.0),
        ];
        let shaped: Vec<(c64, Vec<c64>)> = e.iter().map(|&s| (s, vec![s])).collect();
        let m = modes_of(&shaped);
        let exponents: Vec<c64> = m.iter().map(|x| x.0).collect();
        assert_eq!(
            exponents,
            vec![c64::new(0.5, 1.0), c64::new(-0.1, 2.0), c64::new(-3.0, 0.0)]
        );
        // Each keeps its own shape, conjugated where the kept exponent was the lower one.
        assert_eq!(m[0].1, vec![c64::new(0.5, 1.0)]);
        assert_eq!(m[1].1, vec![c64::new(-0.1, 2.0)]);
    }
}
