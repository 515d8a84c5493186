//! The `mbd` command line: one file per subcommand, and what they share: reading the model,
//! compiling it with its diagnostics reported, usage errors, the output files and the
//! progress. The only code that reads files and renders reports.
//! Exit codes: 0 success; 1 the model has errors; 2 bad command-line usage; 3 the simulation
//! failed at run time (the CSV keeps every row computed before the failure); 130 stopped by
//! Ctrl-C (E0607, the rows so far kept).

pub mod check;
pub mod explain;
pub mod merge;
pub mod modes;
pub mod plot;
mod progress;
pub mod run;
pub mod stability;
pub mod study;
mod swept;
pub mod view;

use clap::ValueEnum;
use mbd::diagnostics::{render_human, render_json, summarize, Diagnostic, SHOWN_PER_CODE};
use mbd::loader::FsLoader;
use mbd::settings::Request;
use mbd::source::SourceMap;
use mbd::study::CompileError;
use mbd::Compiled;
use std::io::{IsTerminal, Write};
use std::process::ExitCode;

pub const EXIT_MODEL: u8 = 1;
pub const EXIT_USAGE: u8 = 2;
pub const EXIT_RUNTIME: u8 = 3;
/// Stopped by Ctrl-C (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: u8 = 130;

/// The diagnostics format (`--format`).
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    Human,
    Json,
}

/// Prints a usage error; exit code 2.
pub fn usage(msg: &str) -> ExitCode {
    eprintln!("error: {msg}");
    ExitCode::from(EXIT_USAGE)
}

/// The model file's text; an unreadable file is a usage error, a file that is not UTF-8 a
/// model error (E0104, exit 1).
pub fn read(path: &str) -> Result<String, ExitCode> {
    read_as(path, Format::Human)
}

/// [`read`], its diagnostic in `format`.
pub fn read_as(path: &str, format: Format) -> Result<String, ExitCode> {
    if std::path::Path::new(path).is_dir() {
        return Err(usage(&format!(
            "`{path}` is a directory: give the path of a model file (`.mbd`)"
        )));
    }
    let bytes =
        std::fs::read(path).map_err(|e| usage(&format!("cannot read model file `{path}`: {e}")))?;
    mbd::syntax::decode(path, bytes).map_err(|(d, sources)| {
        report(&[d], &sources, format);
        ExitCode::from(EXIT_MODEL)
    })
}

/// Renders diagnostics on standard error.
pub fn report(diags: &[Diagnostic], sources: &SourceMap, format: Format) {
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
            let (shown, more) = summarize(diags, SHOWN_PER_CODE);
            for d in shown {
                let _ = write!(err, "{}", render_human(d, sources, color));
            }
            for line in more {
                let _ = writeln!(err, "{line}");
            }
        }
    }
}

/// Compiles a model, reporting its warnings; on errors, reports them and gives exit code 1.
pub fn compile(
    path: &str,
    text: &str,
    sets: &[String],
    request: Request,
    format: Format,
) -> Result<Compiled, ExitCode> {
    match mbd::compile_with(path, text, sets, request, &FsLoader::new()) {
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

/// [`compile`], then the sizing lint (`mbd check` and `mbd run`): the lint's warnings are
/// reported with the compiler's.
pub fn compile_linted(
    path: &str,
    text: &str,
    sets: &[String],
    request: Request,
    format: Format,
) -> Result<(Compiled, mbd::lint::Lint), ExitCode> {
    let loader = FsLoader::new();
    match mbd::compile_with(path, text, sets, request.clone(), &loader) {
        Ok(c) => {
            let lint = mbd::lint(&c, path, text, sets, request, &loader);
            let all: Vec<_> = c
                .warnings
                .iter()
                .chain(&lint.diagnostics)
                .cloned()
                .collect();
            report(&all, &c.sources, format);
            Ok((c, lint))
        }
        Err(f) => {
            report(&f.diagnostics, &f.sources, format);
            Err(ExitCode::from(EXIT_MODEL))
        }
    }
}

/// The model of a study or a sweep, compiled again by each job in its worker thread: silently,
/// a failure kept as its first error.
pub struct Jobs<'a> {
    pub path: &'a str,
    pub text: &'a str,
    /// The `--set` params.
    pub sets: &'a [String],
}

impl Jobs<'_> {
    /// Compiled with these solver settings.
    pub fn with_request(&self, request: &Request) -> Result<Compiled, CompileError> {
        mbd::compile_with(
            self.path,
            self.text,
            self.sets,
            request.clone(),
            &FsLoader::new(),
        )
        .map_err(|f| CompileError::of(&f))
    }

    /// Compiled with these `NAME=VALUE` params added to the `--set` ones.
    pub fn with_sets(&self, extra: &[String]) -> Result<Compiled, CompileError> {
        let mut all = self.sets.to_vec();
        all.extend_from_slice(extra);
        mbd::compile_with(
            self.path,
            self.text,
            &all,
            Request::default(),
            &FsLoader::new(),
        )
        .map_err(|f| CompileError::of(&f))
    }
}

/// `println!` that does not panic when stdout is closed (`mbd check ... | head`).
pub fn say(text: &str) {
    let _ = writeln!(std::io::stdout().lock(), "{text}");
}

/// Short numbers for the report: 6 significant digits, no trailing zeros.
pub fn short(x: f64) -> String {
    if !x.is_finite() {
        return "-".to_string();
    }
    let s = format!("{x:.6e}");
    let v: f64 = s.parse().unwrap_or(x);
    format!("{v}")
}

/// `" to PATH"` after a summary when the output went to a file.
fn to_path(output: Option<&str>) -> String {
    output.map(|p| format!(" to {p}")).unwrap_or_default()
}

/// The output file, or standard output.
fn sink(output: Option<&str>) -> Result<Box<dyn Write>, ExitCode> {
    match output {
        Some(p) => std::fs::File::create(p)
            .map(|f| Box::new(f) as Box<dyn Write>)
            .map_err(|e| usage(&format!("cannot create output file `{p}`: {e}"))),
        None => Ok(Box::new(std::io::stdout().lock())),
    }
}

/// A chart's path and its (already created) file.
type ChartFile<'a> = Option<(&'a str, std::fs::File)>;

/// Creates the CSV and the optional chart file before a long analysis, so that an unwritable
/// path fails now (usage error), not after the runs.
pub fn create_outputs<'a>(
    csv: &str,
    chart: Option<&'a str>,
) -> Result<(std::fs::File, ChartFile<'a>), ExitCode> {
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

/// Renders a chart into its file (PNG for a `.png` name, else SVG); a failure is reported, not
/// fatal (the CSV is written).
pub fn draw(path: &str, file: &mut std::fs::File, chart: &mbd::output::charts::Chart) {
    draw_panels(path, file, std::slice::from_ref(chart));
}

/// [`draw`] for panels stacked over one axis.
pub fn draw_panels(path: &str, file: &mut std::fs::File, charts: &[mbd::output::charts::Chart]) {
    match mbd::output::charts::encode(charts, path) {
        Ok(bytes) => {
            if let Err(e) = file.write_all(&bytes) {
                eprintln!("error: cannot write chart file `{path}`: {e}");
            }
        }
        Err(e) => eprintln!("note: no chart drawn in `{path}`: {e}"),
    }
}

/// Exit code 3 when some evaluation failed, else success.
fn exit_unless_failed(failed: bool) -> ExitCode {
    if failed {
        ExitCode::from(EXIT_RUNTIME)
    } else {
        ExitCode::SUCCESS
    }
}
