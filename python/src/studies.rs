//! `mbd study` from Python: a convergence or stability study's CSV.

use crate::{compile, interruptible};
use mbd::loader::FsLoader;
use mbd::settings::Request;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

/// What `mbd study` takes, as texts in the command line's syntax (lists comma-separated).
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub(crate) struct StudyArgs {
    channel: String,
    integrators: Option<String>,
    alphas: Option<String>,
    steps: Option<String>,
    dt: Option<String>,
    until: Option<f64>,
    at: Option<f64>,
    reference: Option<String>,
}

/// A study (`mbd study`): `(ok, CSV or diagnostics JSON)`, the CSV of `mbd study -o`: a
/// convergence study with `integrators` (error and CPU per run against the reference), or a
/// stability study with `alphas` (each run's onset of instability).
#[pyfunction]
pub(crate) fn study(
    py: Python<'_>,
    name: String,
    text: String,
    sets: Vec<String>,
    args: StudyArgs,
) -> PyResult<(bool, String)> {
    use mbd::study::{convergence, stability, IntegratorItem, StepList};
    let bad = |e: &dyn std::fmt::Display| PyValueError::new_err(e.to_string());
    let steps = match (&args.steps, &args.dt) {
        (Some(_), Some(_)) => return Err(PyValueError::new_err("give steps or dt, not both")),
        (Some(s), None) => Some(StepList::parse_counts(s).map_err(|e| bad(&e))?),
        (None, Some(d)) => Some(StepList::parse_dt(d).map_err(|e| bad(&e))?),
        (None, None) => None,
    };
    let kind =
        match (&args.integrators, &args.alphas) {
            (Some(i), None) => Ok(IntegratorItem::parse_list(i).map_err(|e| bad(&e))?),
            (None, Some(a)) => Err(mbd::study::parse_alphas(a).map_err(|e| bad(&e))?),
            _ => return Err(PyValueError::new_err(
                "give integrators (a convergence study) or alphas (a stability study), one of them",
            )),
        };
    if kind.is_ok() && steps.is_none() {
        return Err(PyValueError::new_err(
            "a convergence study needs the steps: steps=[100, 200, 400] or dt=[...]",
        ));
    }
    let out = interruptible(py, move || -> Result<Result<String, String>, String> {
        let base = Request {
            every: Some(1),
            until: args.until,
            ..Request::default()
        };
        let c = compile(&name, &text, &sets, base.clone())?;
        let usage = |m: String| serde_json::json!([{ "code": "usage", "message": m }]).to_string();
        if !c.model.outputs.iter().any(|o| o.column == args.channel) {
            return Err(usage(format!(
                "model `{}` has no output channel `{}`",
                c.model.name, args.channel
            )));
        }
        let until = c.settings.until;
        let counts = match &steps {
            Some(s) => s.counts(until).map_err(|e| usage(e.to_string()))?,
            None => vec![c.settings.steps],
        };
        let compile = |r: &Request| {
            mbd::compile_with(&name, &text, &sets, r.clone(), &FsLoader::new())
                .map_err(|f| mbd::study::CompileError::of(&f))
        };
        let mut csv = Vec::new();
        let written = match kind {
            Ok(integrators) => {
                let reference = match args.reference.as_deref() {
                    None | Some("finest") => convergence::ReferenceSpec::Finest,
                    Some("exact") => {
                        match c.model.exact.iter().find(|e| e.column == args.channel) {
                            Some(e) => convergence::ReferenceSpec::Exact(e.f.clone()),
                            None => {
                                return Err(usage(format!(
                                    "reference exact: the model declares no exact solution of `{}`",
                                    args.channel
                                )))
                            }
                        }
                    }
                    Some(file) => {
                        let t = std::fs::read_to_string(file)
                            .map_err(|e| usage(format!("cannot read `{file}`: {e}")))?;
                        let (h, rows) = mbd::output::read_csv(&t)
                            .map_err(|e| usage(format!("`{file}`: {e}")))?;
                        let s = mbd::study::compare::Samples::from_table(&h, &rows, &args.channel)
                            .map_err(|e| usage(format!("`{file}`: {e}")))?;
                        convergence::ReferenceSpec::Samples(s)
                    }
                };
                let spec = convergence::ConvergenceSpec {
                    channel: args.channel.clone(),
                    at: args.at,
                    integrators,
                    steps: counts,
                    until,
                    reference,
                };
                convergence::convergence(&spec, &base, &compile).write_csv(&mut csv)
            }
            Err(alphas) => {
                let spec = stability::StabilitySpec {
                    channel: args.channel.clone(),
                    alphas,
                    steps: counts,
                    until,
                    detector: stability::Detector::default(),
                };
                stability::write_csv(&stability::stability(&spec, &base, &compile), &mut csv)
            }
        };
        Ok(written
            .map(|()| String::from_utf8_lossy(&csv).into_owned())
            .map_err(|e| e.to_string()))
    })?;
    match out {
        Ok(Ok(csv)) => Ok((true, csv)),
        Ok(Err(e)) => Err(PyRuntimeError::new_err(e)),
        Err(json) => Ok((false, json)),
    }
}
