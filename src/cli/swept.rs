//! `--sweep NAME=START:STOP:STEP` of `mbd modes` and `mbd stability`: the param, its values,
//! and the model compiled at the first value.

use super::{compile, usage, Format, FsLoader};
use mbd::settings::Request;
use mbd::study::sweep::{self, RangeError};
use mbd::study::CompileError;
use mbd::Compiled;
use std::process::ExitCode;

/// The swept param and its values in SI.
pub struct Swept {
    pub param: String,
    pub values: Vec<f64>,
}

impl Swept {
    /// `--sweep NAME=START:STOP:STEP`: START, STOP and STEP may carry units
    /// (`Omega=200rpm:400rpm:100rpm`), each read as `--set NAME=VALUE` reads it (so its
    /// dimension is checked against the param's). Usage errors exit 2; `example` is shown when
    /// the flag is not NAME=RANGE.
    pub fn parse(
        path: &str,
        text: &str,
        sets: &[String],
        sweep: &str,
        example: &str,
    ) -> Result<Swept, ExitCode> {
        let Some((param, range)) = sweep.split_once('=') else {
            return Err(usage(&format!(
                "--sweep takes NAME=START:STOP:STEP, e.g. {example}; got `{sweep}`"
            )));
        };
        let param = param.trim().to_string();
        if sets
            .iter()
            .any(|s| s.split_once('=').map(|(n, _)| n.trim()) == Some(param.as_str()))
        {
            return Err(usage(&format!(
                "--set {param}=... conflicts with --sweep {param}=...; drop one"
            )));
        }
        let [a, b, c] = sweep::split_range(range).map_err(range_usage)?;
        let si = |part: &str, what: &str| in_si(path, text, sets, &param, part, what);
        let (start, stop, step) = (si(a, "START")?, si(b, "STOP")?, si(c, "STEP")?);
        let values = sweep::grid(start, stop, step).map_err(range_usage)?;
        Ok(Swept { param, values })
    }

    /// The model compiled (warnings reported once) with the param at the first value; it must
    /// be runnable (exit 1) and have the param (exit 2).
    pub fn compile_first(
        &self,
        path: &str,
        text: &str,
        sets: &[String],
        format: Format,
    ) -> Result<Compiled, ExitCode> {
        let mut first = sets.to_vec();
        first.push(format!("{}={}", self.param, self.values[0]));
        let c = compile(path, text, &first, Request::default(), format)?;
        if !c.model.params.iter().any(|(n, _)| *n == self.param) {
            let known: Vec<&str> = c.model.params.iter().map(|(n, _)| n.as_str()).collect();
            return Err(usage(&format!(
                "model `{path}` has no param `{}`; its params are: {}",
                self.param,
                known.join(", ")
            )));
        }
        Ok(c)
    }
}

fn range_usage(e: RangeError) -> ExitCode {
    usage(&format!("--sweep: {e}"))
}

/// One part of the range in SI: a plain number, or a value with a unit read as the model reads
/// `--set NAME=PART`.
fn in_si(
    path: &str,
    text: &str,
    sets: &[String],
    param: &str,
    part: &str,
    what: &str,
) -> Result<f64, ExitCode> {
    if let Ok(v) = part.parse::<f64>() {
        return Ok(v);
    }
    let mut all = sets.to_vec();
    all.push(format!("{param}={part}"));
    let fail = |why: String| usage(&format!("--sweep: the range's {what} `{part}`: {why}"));
    match mbd::compile_with(path, text, &all, Request::default(), &FsLoader::new()) {
        Ok(c) => c
            .model
            .params
            .iter()
            .find(|(n, _)| *n == param)
            .and_then(|(_, v)| match v {
                mbd::model::Value::Scalar { value, .. } => Some(*value),
                _ => None,
            })
            .ok_or_else(|| fail(format!("the model has no scalar param `{param}`"))),
        Err(f) => Err(fail(match CompileError::of(&f) {
            CompileError::Unexplained => "the model does not compile with it".to_string(),
            e => e.to_string(),
        })),
    }
}
