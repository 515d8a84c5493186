//! `mbd run`: the solver flags (checked by `settings::Request::check`, exit 2), the CSV on a
//! file or standard output, the progress bar and the closing summary; exit 3 when the
//! simulation fails (the rows before the failure are kept).

use super::progress::Steps;
use super::view::Recorder;
use super::{compile_linted, read_as, report, sink, to_path, usage, Format, EXIT_RUNTIME};
use clap::builder::{PossibleValuesParser, TypedValueParser};
use mbd::settings::{Method, NewtonMode, Request, Rotations, Start};
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct RunArgs {
    /// The model file.
    model: String,
    /// Write the CSV here (default: standard output).
    #[arg(short = 'o', long = "output")]
    output: Option<String>,
    /// Write an animated 3-D view of the run here: one HTML file that opens offline
    /// (`mbd view --help`).
    #[arg(long, value_name = "VIEW.html")]
    view: Option<String>,
    /// Write the run's scene and motion as a glTF 2.0 binary here.
    #[arg(long, value_name = "OUT.glb")]
    gltf: Option<String>,
    /// Override a param: NAME=VALUE, VALUE in SI units or with units (V0=5, V0=5m/s).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
    /// Time integrator.
    #[arg(long, value_parser = choice(&Method::FLAGS))]
    integrator: Option<Method>,
    /// HHT alpha, in [-1/3, 0].
    #[arg(long, allow_negative_numbers = true)]
    alpha: Option<f64>,
    /// Generalized-alpha spectral radius at infinity, in [0, 1].
    #[arg(long)]
    rho_inf: Option<f64>,
    /// Rotation treatment: incremental (default) or conformal (the paper's).
    #[arg(long, value_parser = choice(&Rotations::FLAGS))]
    rotations: Option<Rotations>,
    /// Time step in seconds.
    #[arg(long, conflicts_with = "steps")]
    dt: Option<f64>,
    /// Number of steps (the time step becomes until/N).
    #[arg(long)]
    steps: Option<usize>,
    /// End time in seconds.
    #[arg(long)]
    until: Option<f64>,
    /// Write every K-th step.
    #[arg(long)]
    every: Option<usize>,
    /// Initial accelerations: consistent (default) or zero (the paper's start).
    #[arg(long, value_parser = choice(&Start::FLAGS))]
    start: Option<Start>,
    /// Newton's iteration matrix: full (default: new every iteration), modified (kept while
    /// Newton contracts twofold) or auto (kept while it contracts fivefold, where that pays).
    #[arg(long, value_parser = choice(&NewtonMode::FLAGS))]
    newton: Option<NewtonMode>,
    /// Diagnostics format.
    #[arg(long, value_enum, default_value = "human")]
    format: Format,
}

/// A flag's parser for one of the settings' named options (`Method::FLAGS`, ...).
fn choice<T: Copy + Send + Sync + 'static>(
    table: &'static [(&'static str, T)],
) -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(table.iter().map(|(name, _)| *name)).map(move |s| {
        table
            .iter()
            .find(|(name, _)| *name == s)
            .map_or(table[0].1, |(_, v)| *v)
    })
}

impl RunArgs {
    /// What the flags ask of the solver (not yet checked).
    fn request(&self) -> Request {
        Request {
            method: self.integrator,
            alpha: self.alpha,
            rho_inf: self.rho_inf,
            rotations: self.rotations,
            dt: self.dt,
            steps: self.steps,
            until: self.until,
            every: self.every,
            start: self.start,
            newton: self.newton,
            ..Request::default()
        }
    }
}

pub fn run(a: RunArgs) -> ExitCode {
    let request = a.request();
    if let Some(bad) = request.check().first() {
        return usage(&bad.flag_message());
    }
    let (format, output) = (a.format, a.output.as_deref());
    let text = match read_as(&a.model, format) {
        Ok(t) => t,
        Err(code) => return code,
    };
    let c = match compile_linted(&a.model, &text, &a.set, request, format) {
        Ok((c, _)) => c,
        Err(code) => return code,
    };
    let mut sink = match sink(output) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let started = std::time::Instant::now();
    let mut progress = Steps::new(started);
    let wants_view = a.view.is_some() || a.gltf.is_some();
    let rows = c.settings.steps / c.settings.every.max(1) + 2;
    let mut recorder = wants_view.then(|| Recorder::new(&c, rows));
    let mut observe = |st: &mbd::runtime::State, v: &[f64]| {
        if let Some(r) = recorder.as_mut() {
            r.sample(st, v);
        }
    };
    let result = mbd::run_observed(
        &c,
        &mut sink,
        &mut |k, n| progress.update(k, n),
        wants_view.then_some(&mut observe as &mut dyn FnMut(&mbd::runtime::State, &[f64])),
    );
    progress.finish();
    if let Some(r) = recorder.as_mut() {
        // Written after a failure too: the view ends where the run stopped.
        if let Err(code) = r.write(&c, a.view.as_deref(), a.gltf.as_deref()) {
            return code;
        }
    }
    match result {
        Ok(r) => {
            report(&r.warnings, &c.sources, format);
            let ms = started.elapsed().as_secs_f64() * 1e3;
            if format == Format::Human {
                eprintln!(
                    "{}: {} steps, {} Newton iterations ({} factorizations), {} halvings{}, max |C| {:.2e} m, {} rows{} in {:.*} ms",
                    c.model.name,
                    r.stats.steps,
                    r.stats.newton_iterations,
                    r.stats.factorizations,
                    r.stats.halvings,
                    match r.stats.repredictions {
                        0 => String::new(),
                        k => format!(", {k} steps started again from constant velocities"),
                    },
                    r.stats.max_constraint_violation,
                    r.rows,
                    to_path(output),
                    // Short runs to the microsecond (the side-by-side benchmark reads it).
                    if ms < 10.0 { 3 } else { 1 },
                    ms
                );
            }
            ExitCode::SUCCESS
        }
        Err(f) => {
            report(&f.warnings, &c.sources, format);
            report(std::slice::from_ref(&f.diagnostic), &c.sources, format);
            if format == Format::Human {
                eprintln!(
                    "{} rows written before the failure{}",
                    f.rows,
                    to_path(output)
                );
            }
            ExitCode::from(EXIT_RUNTIME)
        }
    }
}
