//! Stability sweeps from Python: whole, as one share, or shares joined (`mbd merge`).

use crate::{compile, interruptible};
use mbd::loader::FsLoader;
use mbd::settings::Request;
use mbd::solve::floquet::Monodromy;
use mbd::study::sweep::{self, share, SweepSpec};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// The stability analysis's options from `mbd.Model.stability`'s keywords.
fn spec(param: String, values: Vec<f64>, o: &Bound<'_, PyDict>) -> PyResult<SweepSpec> {
    let get = |k: &str| -> PyResult<Option<Bound<'_, PyAny>>> {
        Ok(o.get_item(k)?.filter(|v| !v.is_none()))
    };
    let method: String = get("method")?.map_or(Ok("floquet".to_string()), |v| v.extract())?;
    let methods = match method.as_str() {
        "floquet" => vec![sweep::Method::Floquet],
        "prony" => vec![sweep::Method::Prony],
        "both" => vec![sweep::Method::Floquet, sweep::Method::Prony],
        m => {
            return Err(PyValueError::new_err(format!(
                "method must be floquet, prony or both, got `{m}`"
            )))
        }
    };
    let monodromy = match (
        get("modes")?.map(|v| v.extract::<usize>()).transpose()?,
        get("monodromy")?,
    ) {
        (Some(0), _) => return Err(PyValueError::new_err("modes must be at least 1")),
        (Some(k), _) => Monodromy::Krylov(k),
        (None, None) => Monodromy::Tangent,
        (None, Some(v)) => match v.extract::<String>()?.as_str() {
            "tangent" => Monodromy::Tangent,
            "runs" => Monodromy::Runs,
            m => {
                return Err(PyValueError::new_err(format!(
                    "monodromy must be tangent or runs, got `{m}`"
                )))
            }
        },
    };
    if values.is_empty() || values.iter().any(|v| !v.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "the values of `{param}` must be finite numbers, at least one"
        )));
    }
    Ok(SweepSpec {
        param,
        values,
        methods,
        period: get("period")?.map(|v| v.extract()).transpose()?,
        monodromy,
        signals: get("signals")?
            .map(|v| v.extract())
            .transpose()?
            .unwrap_or_default(),
        window: get("window")?.map(|v| v.extract()).transpose()?,
        samples: get("samples")?.map_or(Ok(300), |v| v.extract())?,
        threshold: get("threshold")?.map_or(Ok(1e-2), |v| v.extract())?,
        refine: get("refine")?.map_or(Ok(6), |v| v.extract())?,
    })
}

/// What a sweep needs of the model, checked on the first value (as `mbd stability` checks
/// it): it compiles, has the param, the channels Prony fits, and a period for Floquet.
fn precheck(name: &str, text: &str, sets: &[String], s: &SweepSpec) -> Result<(), String> {
    let mut first = sets.to_vec();
    first.push(format!("{}={}", s.param, s.values[0]));
    let c = compile(name, text, &first, Request::default())?;
    let value_error =
        |m: String| serde_json::json!([{ "code": "usage", "message": m }]).to_string();
    if !c.model.params.iter().any(|(n, _)| *n == s.param) {
        return Err(value_error(format!(
            "model `{}` has no param `{}`",
            c.model.name, s.param
        )));
    }
    let channels: Vec<&str> = c.model.outputs.iter().map(|o| o.column.as_str()).collect();
    if let Some(bad) = s.signals.iter().find(|x| !channels.contains(&x.as_str())) {
        return Err(value_error(format!(
            "model `{}` has no output channel `{bad}`",
            c.model.name
        )));
    }
    if s.methods.contains(&sweep::Method::Floquet) && s.period.is_none() {
        sweep::rotor_period(&c).map_err(|e| value_error(e.to_string()))?;
    }
    Ok(())
}

/// A stability sweep: `(ok, CSV or diagnostics JSON, report)`, the CSV of `mbd stability -o`;
/// `report`: edges `(value, lo, hi, onset)`, unstable ranges, notes, failed points.
#[pyfunction]
pub(crate) fn stability(
    py: Python<'_>,
    name: String,
    text: String,
    sets: Vec<String>,
    param: String,
    values: Vec<f64>,
    options: &Bound<'_, PyDict>,
) -> PyResult<(bool, String, Py<PyDict>)> {
    let s = spec(param, values, options)?;
    let out = interruptible(py, move || {
        precheck(&name, &text, &sets, &s)?;
        let compile = |extra: &[String]| at_point(&name, &text, &sets, extra);
        let result = sweep::sweep(&s, &compile, &|_| {});
        Ok::<_, String>(result)
    })?;
    match out {
        Err(json) => Ok((false, json, PyDict::new(py).unbind())),
        Ok(result) => {
            let (csv, report) = tables(py, &result)?;
            Ok((true, csv, report))
        }
    }
}

/// The model compiled at a sweep's point: the `sets` and the point's `NAME=VALUE`.
fn at_point(
    name: &str,
    text: &str,
    sets: &[String],
    extra: &[String],
) -> Result<mbd::Compiled, mbd::study::CompileError> {
    let all = [sets, extra].concat();
    mbd::compile_with(name, text, &all, Request::default(), &FsLoader::new())
        .map_err(|f| mbd::study::CompileError::of(&f))
}

/// A sweep's CSV and report (see [`stability`]).
fn tables(py: Python<'_>, result: &sweep::Sweep) -> PyResult<(String, Py<PyDict>)> {
    let mut csv = Vec::new();
    result
        .write_csv(&mut csv)
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    let d = PyDict::new(py);
    let edges: Vec<(f64, f64, f64, bool)> = (result.edges.iter())
        .map(|e| (e.value, e.bracket.0, e.bracket.1, e.onset))
        .collect();
    d.set_item("edges", edges)?;
    d.set_item("unstable", result.unstable_ranges())?;
    d.set_item("notes", PyList::new(py, &result.notes)?)?;
    let failed: Vec<(f64, String)> = (result.points.iter().chain(&result.refinements))
        .filter_map(|p| p.failure.as_ref().map(|f| (p.value, f.to_string())))
        .collect();
    d.set_item("failed", failed)?;
    Ok((String::from_utf8_lossy(&csv).into_owned(), d.unbind()))
}

/// Share `k` of `n` of a stability sweep, as the JSON that `mbd stability --shard K/N`
/// writes: `(ok, share JSON or diagnostics JSON)`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub(crate) fn stability_share(
    py: Python<'_>,
    name: String,
    text: String,
    sets: Vec<String>,
    param: String,
    values: Vec<f64>,
    options: &Bound<'_, PyDict>,
    k: usize,
    n: usize,
) -> PyResult<(bool, String)> {
    let s = spec(param, values, options)?;
    if !(1 <= k && k <= n && n <= s.values.len()) {
        return Err(PyValueError::new_err(format!(
            "share {k} of {n}: need 1 <= k <= n <= {} (the values)",
            s.values.len()
        )));
    }
    let out = interruptible(py, move || {
        precheck(&name, &text, &sets, &s)?;
        let compile = |extra: &[String]| at_point(&name, &text, &sets, extra);
        let run = format!("{text}\u{0}{sets:?}\u{0}{:?}", s.methods);
        let share = share::sweep_share(&s, (k, n), &compile, &|_| {}, (&run, "", &s.param));
        serde_json::to_string(&share).map_err(|e| e.to_string())
    })?;
    Ok(match out {
        Ok(json) => (true, json),
        Err(json) => (false, json),
    })
}

/// The shares joined (`mbd merge`): the sweep's CSV and report, as [`stability`] gives them.
#[pyfunction]
pub(crate) fn merge(py: Python<'_>, shares: Vec<String>) -> PyResult<(String, Py<PyDict>)> {
    let parsed = shares
        .iter()
        .map(|s| serde_json::from_str::<share::Share>(s))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| PyValueError::new_err(format!("not a share of a sweep: {e}")))?;
    let (result, _) = share::merge(parsed).map_err(|e| PyValueError::new_err(e.to_string()))?;
    tables(py, &result)
}
