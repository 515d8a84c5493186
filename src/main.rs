//! The `mbd` command line: the only place that reads files and renders reports.
//! Exit codes: 0 success; 1 the model has errors; 2 bad command-line usage; 3 the simulation
//! failed at run time (the CSV keeps every row computed before the failure).

use clap::{Parser, Subcommand, ValueEnum};
use mbd::diagnostics::{explain, render_human, render_json, Diagnostic};
use mbd::settings::{Method, Request, Rotations, Start};
use mbd::source::SourceMap;
use std::io::{IsTerminal, Write};
use std::process::ExitCode;

/// `println!` that does not panic when stdout is closed (`mbd check ... | head`).
macro_rules! out_line {
    ($($arg:tt)*) => {{
        let _ = writeln!(std::io::stdout().lock(), $($arg)*);
    }};
}

mod modes_cmd;
mod stability_cmd;
mod study_cmd;

#[derive(Parser)]
#[command(
    name = "mbd",
    version,
    about = "Compile and simulate .mbd flexible multibody models"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a model and write its output channels as CSV.
    Run {
        /// The model file.
        model: String,
        /// Write the CSV here (default: standard output).
        #[arg(short = 'o', long = "output")]
        output: Option<String>,
        /// Override a param: NAME=VALUE, VALUE in SI units or with units (V0=5, V0=5m/s).
        #[arg(long = "set", value_name = "NAME=VALUE")]
        set: Vec<String>,
        /// Time integrator.
        #[arg(long, value_enum)]
        integrator: Option<IntegratorArg>,
        /// HHT alpha, in [-1/3, 0].
        #[arg(long, allow_negative_numbers = true)]
        alpha: Option<f64>,
        /// Generalized-alpha spectral radius at infinity, in [0, 1].
        #[arg(long)]
        rho_inf: Option<f64>,
        /// Rotation treatment: incremental (default) or conformal (the paper's).
        #[arg(long, value_enum)]
        rotations: Option<RotationsArg>,
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
        #[arg(long, value_enum)]
        start: Option<StartArg>,
        /// Diagnostics format.
        #[arg(long, value_enum, default_value = "human")]
        format: Format,
    },
    /// Natural frequencies and mode shapes about the initial state, as CSV; with --sweep, a
    /// fan plot against a param.
    #[command(long_about = modes_cmd::LONG_ABOUT)]
    Modes(modes_cmd::ModesArgs),
    /// Check a model and print a summary, or one stage of the compilation.
    Check {
        model: String,
        #[arg(long, value_enum, default_value = "human")]
        format: Format,
        /// Print a stage instead of the summary.
        #[arg(long, value_enum)]
        emit: Option<Emit>,
        #[arg(long = "set", value_name = "NAME=VALUE")]
        set: Vec<String>,
    },
    /// Time histories of channels of a run's CSV, as an SVG chart.
    Plot {
        /// A CSV written by `mbd run`.
        csv: String,
        /// A channel to draw (repeat for several).
        #[arg(long = "channel", value_name = "NAME", required = true)]
        channels: Vec<String>,
        /// Write the SVG here.
        #[arg(short = 'o', long = "output")]
        output: String,
        /// Chart title (default: the CSV's file name).
        #[arg(long)]
        title: Option<String>,
        /// The model that wrote the CSV: channels are then grouped by unit, one panel each,
        /// with their units on the axes.
        #[arg(long, value_name = "MODEL.mbd")]
        model: Option<String>,
        /// With --model: override a param as the run did (NAME=VALUE).
        #[arg(long = "set", value_name = "NAME=VALUE", requires = "model")]
        set: Vec<String>,
    },
    /// Convergence or stability study: many runs of a model, one channel measured.
    #[command(long_about = study_cmd::LONG_ABOUT)]
    Study(study_cmd::StudyArgs),
    /// Stability sweep: characteristic exponents (Floquet, Prony) against a param.
    #[command(long_about = stability_cmd::LONG_ABOUT)]
    Stability(stability_cmd::StabilityArgs),
    /// Explain a diagnostic code, e.g. `mbd explain E0202`.
    Explain { code: String },
}

#[derive(Clone, Copy, ValueEnum)]
enum IntegratorArg {
    Hht,
    GeneralizedAlpha,
    Fet,
    Static,
}

#[derive(Clone, Copy, ValueEnum)]
enum RotationsArg {
    Incremental,
    Conformal,
}

#[derive(Clone, Copy, ValueEnum)]
enum StartArg {
    Consistent,
    Zero,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Format {
    Human,
    Json,
}

#[derive(Clone, Copy, ValueEnum)]
enum Emit {
    Ast,
    Model,
    Dofs,
    #[value(alias = "system")]
    Ir,
}

const EXIT_MODEL: u8 = 1;
const EXIT_USAGE: u8 = 2;
const EXIT_RUNTIME: u8 = 3;

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { EXIT_USAGE } else { 0 });
        }
    };
    match cli.command {
        Command::Explain { code } => match explain(&code) {
            Some(text) => {
                print!("{text}");
                ExitCode::SUCCESS
            }
            None => {
                eprintln!("error: unknown diagnostic code `{code}`");
                ExitCode::from(EXIT_USAGE)
            }
        },
        Command::Check {
            model,
            format,
            emit,
            set,
        } => check(&model, format, emit, &set),
        Command::Study(args) => study_cmd::study(args),
        Command::Stability(args) => stability_cmd::stability(args),
        Command::Plot {
            csv,
            channels,
            output,
            title,
            model,
            set,
        } => plot(
            &csv,
            &channels,
            &output,
            title.as_deref(),
            model.as_deref(),
            &set,
        ),
        Command::Modes(args) => modes_cmd::modes(args),
        Command::Run {
            model,
            output,
            set,
            integrator,
            alpha,
            rho_inf,
            rotations,
            dt,
            steps,
            until,
            every,
            start,
            format,
        } => {
            let request = Request {
                method: integrator.map(|i| match i {
                    IntegratorArg::Hht => Method::Hht,
                    IntegratorArg::GeneralizedAlpha => Method::GeneralizedAlpha,
                    IntegratorArg::Fet => Method::Fet,
                    IntegratorArg::Static => Method::Static,
                }),
                alpha,
                rho_inf,
                rotations: rotations.map(|r| match r {
                    RotationsArg::Incremental => Rotations::Incremental,
                    RotationsArg::Conformal => Rotations::Conformal,
                }),
                dt,
                steps,
                until,
                every,
                start: start.map(|s| match s {
                    StartArg::Consistent => Start::Consistent,
                    StartArg::Zero => Start::ZeroAcceleration,
                }),
                ..Request::default()
            };
            if let Some(bad) = request.check().first() {
                return usage(&bad.flag_message());
            }
            run(&model, output.as_deref(), &set, request, format)
        }
    }
}

/// `mbd plot`: exit 0, or 2 for an unreadable CSV, an unknown channel or an unwritable file
/// (1 if `--model` has errors).
fn plot(
    path: &str,
    channels: &[String],
    output: &str,
    title: Option<&str>,
    model: Option<&str>,
    sets: &[String],
) -> ExitCode {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) => return usage(&format!("cannot read CSV file `{path}`: {e}")),
    };
    let (header, rows) = match mbd::output::read_csv(&text) {
        Ok(t) => t,
        Err(e) => return usage(&format!("`{path}` is not a CSV written by `mbd run`: {e}")),
    };
    let compiled = match model {
        None => None,
        Some(m) => {
            let source = match read(m) {
                Ok(t) => t,
                Err(code) => return code,
            };
            match compile(m, &source, sets, Request::default(), Format::Human) {
                Ok(c) => Some(c),
                Err(code) => return code,
            }
        }
    };
    let name = std::path::Path::new(path)
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| path.to_string());
    let unit = |column: &str| compiled.as_ref().and_then(|c| mbd::channel_unit(c, column));
    let charts = match mbd::output::charts::time_history(
        title.unwrap_or(&name),
        &header,
        &rows,
        channels,
        &unit,
    ) {
        Ok(c) => c,
        Err(e) => return usage(&e),
    };
    let svg = match mbd::output::charts::render_stack(&charts) {
        Ok(s) => s,
        Err(e) => return usage(&format!("cannot draw the chart: {e}")),
    };
    match std::fs::write(output, svg) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => usage(&format!("cannot create output file `{output}`: {e}")),
    }
}

/// Compiles a model, reporting its warnings; on errors, reports them and gives exit code 1.
fn compile(
    path: &str,
    text: &str,
    sets: &[String],
    solve: Request,
    format: Format,
) -> Result<mbd::Compiled, ExitCode> {
    match mbd::compile_with(path, text, sets, solve, &FsLoader::new()) {
        Ok(c) => {
            report(&c.warnings, &c.sources, format);
            Ok(c)
        }
        Err(f) => {
            report(&f.diagnostics, &f.sources, format);
            Err(ExitCode::from(EXIT_MODEL))
        }
    }
}

/// `--sweep NAME=START:STOP:STEP`: the param and its values in SI. START, STOP and STEP may
/// carry units (`Omega=200rpm:400rpm:100rpm`), each read as `--set NAME=VALUE` reads it (so
/// its dimension is checked against the param's). Usage errors exit 2.
pub(crate) fn sweep_values(
    path: &str,
    text: &str,
    sets: &[String],
    sweep: &str,
    example: &str,
) -> Result<(String, Vec<f64>), ExitCode> {
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
    let parts: Vec<&str> = range.split(':').map(str::trim).collect();
    let [a, b, c] = parts[..] else {
        return Err(usage(&format!(
            "--sweep: the range `{range}` is not START:STOP:STEP"
        )));
    };
    let si = |part: &str, what: &str| -> Result<f64, ExitCode> {
        if let Ok(v) = part.parse::<f64>() {
            return Ok(v);
        }
        // A value with a unit: the model reads it as it reads `--set`.
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
            Err(f) => Err(fail(
                f.diagnostics
                    .iter()
                    .find(|d| d.is_error())
                    .map(|d| format!("{} {}", d.code.as_str(), d.message))
                    .unwrap_or_else(|| "the model does not compile with it".to_string()),
            )),
        }
    };
    let (start, stop, step) = (si(a, "START")?, si(b, "STOP")?, si(c, "STEP")?);
    let values =
        mbd::study::sweep::grid(start, stop, step).map_err(|e| usage(&format!("--sweep: {e}")))?;
    Ok((param, values))
}

/// `println!` that does not panic when stdout is closed.
pub(crate) fn say(text: &str) {
    let _ = writeln!(std::io::stdout().lock(), "{text}");
}

/// Short numbers for the report: 6 significant digits, no trailing zeros.
pub(crate) fn short(x: f64) -> String {
    if !x.is_finite() {
        return "-".to_string();
    }
    let s = format!("{x:.6e}");
    let v: f64 = s.parse().unwrap_or(x);
    format!("{v}")
}

/// Creates the CSV and the optional chart file before a long analysis, so that an unwritable
/// path fails now (usage error), not after the runs.
#[allow(clippy::type_complexity)]
pub(crate) fn create_outputs<'a>(
    csv: &str,
    chart: Option<&'a str>,
) -> Result<(std::fs::File, Option<(&'a str, std::fs::File)>), ExitCode> {
    let csv_file = std::fs::File::create(csv)
        .map_err(|e| usage(&format!("cannot create output file `{csv}`: {e}")))?;
    let chart_file = match chart {
        Some(p) => match std::fs::File::create(p) {
            Ok(f) => Some((p, f)),
            Err(e) => return Err(usage(&format!("cannot create chart file `{p}`: {e}"))),
        },
        None => None,
    };
    Ok((csv_file, chart_file))
}

/// Renders a chart into its file; a failure is reported, not fatal (the CSV is written).
pub(crate) fn draw(path: &str, file: &mut std::fs::File, chart: &mbd::output::charts::Chart) {
    match mbd::output::charts::render(chart) {
        Ok(svg) => {
            if let Err(e) = file.write_all(svg.as_bytes()) {
                eprintln!("error: cannot write chart file `{path}`: {e}");
            }
        }
        Err(e) => eprintln!("note: no chart drawn in `{path}`: {e}"),
    }
}

fn usage(msg: &str) -> ExitCode {
    eprintln!("error: {msg}");
    ExitCode::from(EXIT_USAGE)
}

fn read(path: &str) -> Result<String, ExitCode> {
    std::fs::read_to_string(path)
        .map_err(|e| usage(&format!("cannot read model file `{path}`: {e}")))
}

fn report(diags: &[Diagnostic], sources: &SourceMap, format: Format) {
    if diags.is_empty() {
        return;
    }
    let mut err = std::io::stderr().lock();
    match format {
        Format::Json => {
            let _ = writeln!(err, "{}", render_json(diags, sources));
        }
        Format::Human => {
            let color = std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none();
            for d in diags {
                let _ = write!(err, "{}", render_human(d, sources, color));
            }
        }
    }
}

fn check(path: &str, format: Format, emit: Option<Emit>, sets: &[String]) -> ExitCode {
    let text = match read(path) {
        Ok(t) => t,
        Err(code) => return code,
    };
    if mbd::is_library(&text) {
        return match mbd::check_library(path, &text, &FsLoader::new()) {
            Ok((components, warnings)) => {
                report(&warnings.diagnostics, &warnings.sources, format);
                if format == Format::Json {
                    out_line!(
                        "{}",
                        serde_json::json!({ "library": path, "components": components })
                    );
                } else {
                    out_line!(
                        "library {path}: ok\n  components\n    {}",
                        components.join("\n    ")
                    );
                }
                ExitCode::SUCCESS
            }
            Err(f) => {
                report(&f.diagnostics, &f.sources, format);
                ExitCode::from(EXIT_MODEL)
            }
        };
    }
    let c = match compile(path, &text, sets, Request::default(), format) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let json = |v: Result<String, serde_json::Error>| {
        v.unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    };
    let out = match emit {
        Some(Emit::Ast) => json(serde_json::to_string_pretty(&c.ast)),
        Some(Emit::Model) => json(serde_json::to_string_pretty(&c.model)),
        Some(Emit::Dofs) => json(serde_json::to_string_pretty(&c.model.dofs)),
        Some(Emit::Ir) => match &c.lowered {
            Ok(l) => json(serde_json::to_string_pretty(&l.system)),
            Err(d) => {
                report(std::slice::from_ref(d), &c.sources, format);
                return ExitCode::from(EXIT_MODEL);
            }
        },
        None => summary(&c, format),
    };
    out_line!("{out}");
    ExitCode::SUCCESS
}

fn summary(c: &mbd::Compiled, format: Format) -> String {
    let m = &c.model;
    let n = m.dofs.len();
    let mult = m.dofs.multipliers();
    let nodes = m.bodies.len() + m.beams.iter().map(|b| b.nodes.len()).sum::<usize>();
    let columns: Vec<&str> = m.outputs.iter().map(|o| o.column.as_str()).collect();
    let nonzeros = c
        .lowered
        .as_ref()
        .ok()
        .map(|l| mbd::runtime::Pattern::of(n, &l.system.elements).nnz());
    if format == Format::Json {
        return serde_json::json!({
            "model": m.name, "bodies": m.bodies.len(), "beams": m.beams.len(), "nodes": nodes,
            "joints": m.joints.len(), "dofs": n - mult - m.dofs.extras(), "extra_unknowns": m.dofs.extras(),
            "multipliers": mult, "unknowns": n, "bandwidth": m.dofs.bandwidth, "nonzeros": nonzeros,
            "channels": columns, "steps": c.settings.steps, "dt": c.settings.dt, "until": c.settings.until,
            "runnable": c.lowered.is_ok(),
        })
        .to_string();
    }
    let runnable = match &c.lowered {
        Ok(_) => String::new(),
        Err(d) => format!("\n  note: {}", d.message),
    };
    format!(
        "model {}: ok\n{}\n  nonzeros     {}\n  outputs      {}\n  solve        {} steps of {} s to {} s{runnable}",
        m.name,
        mbd::model::topology::report(m),
        nonzeros.map(|x| x.to_string()).unwrap_or_else(|| "-".to_string()),
        std::iter::once("t").chain(columns.iter().copied()).collect::<Vec<_>>().join(", "),
        c.settings.steps,
        c.settings.dt,
        c.settings.until
    )
}

/// Finds `use`d modules next to the importing file, then in the directories of MBD_PATH.
struct FsLoader {
    search: Vec<std::path::PathBuf>,
}

impl FsLoader {
    fn new() -> FsLoader {
        let search = std::env::var_os("MBD_PATH")
            .map(|p| std::env::split_paths(&p).collect())
            .unwrap_or_default();
        FsLoader { search }
    }
}

impl mbd::model::Loader for FsLoader {
    fn load(&self, request: &mbd::model::LoadRequest) -> Result<(String, String), Option<String>> {
        use mbd::model::LoadRequest;
        let (candidates, from): (Vec<std::path::PathBuf>, &str) = match request {
            LoadRequest::Module { path, from } => {
                let mut p = std::path::PathBuf::new();
                for s in path.iter() {
                    p.push(s);
                }
                p.set_extension("mbd");
                (vec![p], from)
            }
            LoadRequest::File { path, from } => (vec![std::path::PathBuf::from(path)], from),
        };
        let here = std::path::Path::new(from)
            .parent()
            .map(|p| p.to_path_buf())
            .unwrap_or_default();
        for dir in std::iter::once(&here).chain(self.search.iter()) {
            for c in &candidates {
                let p = dir.join(c);
                if p.is_file() {
                    return match std::fs::read_to_string(&p) {
                        Ok(text) => Ok((p.display().to_string(), text)),
                        Err(e) => Err(Some(e.to_string())),
                    };
                }
            }
        }
        Err(None)
    }
}

fn run(
    path: &str,
    output: Option<&str>,
    sets: &[String],
    solve: Request,
    format: Format,
) -> ExitCode {
    let text = match read(path) {
        Ok(t) => t,
        Err(code) => return code,
    };
    let c = match compile(path, &text, sets, solve, format) {
        Ok(c) => c,
        Err(code) => return code,
    };
    if let Err(d) = &c.lowered {
        report(std::slice::from_ref(d), &c.sources, format);
        return ExitCode::from(EXIT_MODEL);
    }
    let mut sink: Box<dyn Write> = match output {
        Some(p) => match std::fs::File::create(p) {
            Ok(f) => Box::new(f),
            Err(e) => return usage(&format!("cannot create output file `{p}`: {e}")),
        },
        None => Box::new(std::io::stdout().lock()),
    };
    let started = std::time::Instant::now();
    // A progress bar on a terminal, once a run has taken a second.
    let terminal = std::io::stderr().is_terminal();
    let mut bar: Option<indicatif::ProgressBar> = None;
    let mut progress = |k: usize, n: usize| {
        if !terminal || !k.is_multiple_of(64) && k != n {
            return;
        }
        if bar.is_none() && started.elapsed().as_secs_f64() > 1.0 {
            let b = indicatif::ProgressBar::new(n as u64);
            if let Ok(style) = indicatif::ProgressStyle::with_template(
                "{elapsed_precise} [{bar:40}] step {pos}/{len}, {eta} left",
            ) {
                b.set_style(style.progress_chars("=> "));
            }
            bar = Some(b);
        }
        if let Some(b) = &bar {
            b.set_position(k as u64);
            if k == n {
                b.finish_and_clear();
            }
        }
    };
    let result = mbd::run_with_progress(&c, &mut sink, &mut progress);
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    match result {
        Ok(r) => {
            report(&r.warnings, &c.sources, format);
            if format == Format::Human {
                eprintln!(
                    "{}: {} steps, {} Newton iterations, {} halvings, max |C| {:.2e} m, {} rows{} in {:.1} ms",
                    c.model.name,
                    r.stats.steps,
                    r.stats.newton_iterations,
                    r.stats.halvings,
                    r.stats.max_constraint_violation,
                    r.rows,
                    output.map(|p| format!(" to {p}")).unwrap_or_default(),
                    started.elapsed().as_secs_f64() * 1e3
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
                    output.map(|p| format!(" to {p}")).unwrap_or_default()
                );
            }
            ExitCode::from(EXIT_RUNTIME)
        }
    }
}
