//! Runs of a compiled model: the time loop's rows to a CSV writer as they come, or each row's
//! values to an observer; a failure mapped to its coded diagnostic, the rows before it kept.

use crate::diagnostics::{Code, Diagnostic};
use crate::settings::{Method, Rotations};
use crate::solve::{self, FailureKind, NoticeKind, RunStats, RuntimeFailure};
use crate::{output, runtime, Compiled};
use std::io::Write;

/// What a finished run reports.
pub struct RunReport {
    pub stats: RunStats,
    pub warnings: Vec<Diagnostic>,
    pub rows: usize,
}

/// A failed run: the failure as a diagnostic, plus what was done before it.
pub struct RunFailure {
    pub diagnostic: Diagnostic,
    pub failure: Option<RuntimeFailure>,
    pub warnings: Vec<Diagnostic>,
    pub rows: usize,
}

/// Simulates a compiled model, writing CSV rows to `out` as they are computed.
pub fn run(c: &Compiled, out: &mut dyn Write) -> Result<RunReport, RunFailure> {
    run_with_progress(c, out, &mut |_, _| {})
}

/// [`run`], calling `progress(step, steps)` after every step.
pub fn run_with_progress(
    c: &Compiled,
    out: &mut dyn Write,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<RunReport, RunFailure> {
    run_observed(c, out, progress, None)
}

/// What [`run_observed`] calls at every written row: the state and the row's values.
pub type Observer<'a> = &'a mut dyn FnMut(&runtime::State, &[f64]);

/// [`run_with_progress`], calling `observe(state, values)` at every written row (the start
/// included) with the row's channel values: what a 3-D view samples.
pub fn run_observed(
    c: &Compiled,
    out: &mut dyn Write,
    progress: &mut dyn FnMut(usize, usize),
    observe: Option<Observer<'_>>,
) -> Result<RunReport, RunFailure> {
    run_rows(c, Some(out), progress, observe)
}

/// [`run_observed`] without the CSV: `observe` takes every row's values (the start included),
/// each the `f64` the CSV writes the shortest text of (a negative zero aside). For callers
/// that keep the values themselves (the Python package), which the text would cost more
/// than the pendulum's steps.
pub fn run_values(
    c: &Compiled,
    progress: &mut dyn FnMut(usize, usize),
    observe: Observer<'_>,
) -> Result<RunReport, RunFailure> {
    run_rows(c, None, progress, Some(observe))
}

fn run_rows(
    c: &Compiled,
    out: Option<&mut dyn Write>,
    progress: &mut dyn FnMut(usize, usize),
    mut observe: Option<Observer<'_>>,
) -> Result<RunReport, RunFailure> {
    let set = &c.settings;
    let l = &c.lowered;
    let sys = &l.system;
    let io_fail = |e: std::io::Error, rows| RunFailure {
        diagnostic: Diagnostic::error(Code::E0603, format!("cannot write the output: {e}"))
            .hint("check the output path and free disk space"),
        failure: None,
        warnings: Vec::new(),
        rows,
    };
    if set.method == Method::Fet && set.rotations == Rotations::Conformal {
        let f = RuntimeFailure {
            kind: FailureKind::Unsupported,
            t: 0.0,
            step: 0,
            entity: None,
            detail: "time finite elements with the conformal rotation treatment".to_string(),
        };
        return Err(RunFailure {
            diagnostic: c.failure_diagnostic(&f),
            failure: Some(f),
            warnings: Vec::new(),
            rows: 0,
        });
    }
    let mut csv = match out {
        Some(out) => Some(output::CsvWriter::new(out, sys).map_err(|e| io_fail(e, 0))?),
        None => None,
    };
    let mut warnings = Vec::new();
    let fail = |f: RuntimeFailure,
                csv: &mut Option<output::CsvWriter<&mut dyn Write>>,
                warnings: Vec<Diagnostic>,
                rows| {
        if let Some(csv) = csv {
            let _ = csv.flush();
        }
        RunFailure {
            diagnostic: c.failure_diagnostic(&f),
            failure: Some(f),
            warnings,
            rows,
        }
    };
    let mut hht = match solve::Integrator::new(sys, set) {
        Ok(h) => h,
        Err(f) => return Err(fail(f, &mut csv, warnings, 0)),
    };
    match hht.initialize() {
        Ok(notices) => {
            for n in notices {
                let code = match n.kind {
                    NoticeKind::VelocityProjected => Code::W0601,
                    NoticeKind::PositionProjected => Code::W0602,
                };
                let mut d = Diagnostic::warning(code, n.detail).hint(code.doc().to_string());
                if let Some(span) = n.entity.and_then(|e| l.provenance.spans.get(e)) {
                    d = d.at(*span, "this joint");
                }
                warnings.push(d);
            }
        }
        Err(f) => return Err(fail(f, &mut csv, warnings, 0)),
    }
    if let Some(csv) = csv.as_mut() {
        csv.row(sys, hht.state(), hht.augment())
            .map_err(|e| io_fail(e, 0))?;
    }
    let mut values = Vec::with_capacity(sys.channels.len());
    let mut look = |st: &runtime::State, aug| {
        if let Some(observe) = observe.as_mut() {
            values.clear();
            sys.probe_each(sys.channels.iter().map(|ch| &ch.probe), st, aug, |x| {
                values.push(x)
            });
            observe(st, &values);
        }
    };
    look(hht.state(), hht.augment());
    let mut rows = 1;
    let ran = hht.run(|k, it| {
        progress(k, set.steps);
        if k % set.every == 0 || k == set.steps {
            if let Some(csv) = csv.as_mut() {
                csv.row(sys, it.state(), it.augment())?;
            }
            look(it.state(), it.augment());
            rows += 1;
        }
        Ok(())
    });
    match ran {
        Ok(()) => {}
        Err(solve::Stop::Failed(f)) => return Err(fail(f, &mut csv, warnings, rows)),
        Err(solve::Stop::Stopped(e)) => return Err(io_fail(e, rows)),
    }
    if let Some(csv) = csv.as_mut() {
        csv.flush().map_err(|e| io_fail(e, rows))?;
    }
    Ok(RunReport {
        stats: hht.stats().clone(),
        warnings,
        rows,
    })
}
