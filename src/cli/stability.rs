//! `mbd stability`: parses the flags, reads the model and any reference file, runs the sweep
//! through `mbd::study::sweep` with a progress bar, writes the CSV and the chart and prints the
//! report. The analysis itself lives in the library.

use super::progress::Evaluations;
use super::swept::Swept;
use super::{
    create_outputs, draw_panels, exit_unless_failed, read, say, short, usage, Format, Jobs,
};
use mbd::output::charts::Series;
use mbd::solve::floquet::Monodromy;
use mbd::study::sweep::{self, Method, SweepSpec};
use mbd::Compiled;
use std::io::{Seek, SeekFrom, Write};
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// `mbd stability --help`.
pub const LONG_ABOUT: &str = "\
Stability sweep: for each value of a param, the characteristic exponents s of the model's \
motion, and the edges of the unstable ranges.

Floquet (--method floquet, the default): the monodromy matrix of the discrete motion over one \
period T (2 pi / Omega of the joint driven at a constant speed, or --period) with the model's \
integrator and step, in the constraint-free subspace (THEORY §9.2): by default from the step's \
own tangent, the state's directions (positions and velocities along the n_m directions with \
inertia; positions without inertia, such as the rotations of beam nodes without rotary inertia, \
follow the others in equilibrium) carried through one run of the period by the converged steps' \
iteration matrices (the HHT and generalized-alpha integrators with incremental rotations; \
--monodromy runs, time finite elements and conformal rotations build it from two perturbed \
runs of one period per direction). With the tangent and a damping integrator the multipliers \
are the discrete map's own: the run goes on past the period by the steps that damp the \
algorithmic part, and the directions not damped out are projected on themselves over a \
period from there (the consistent start's accelerations do not enter). Exponents s = (ln|Lambda| + \
i arg Lambda) / T. A multiplier gives the frequency only modulo 2 pi / T: with the tangent, \
the frequency is the principal branch's plus the dominant harmonic of the mode's time history \
over the period (the blades' frequency for a mode of a rigid-bladed rotor's lag angles; with elastic blades \
without rotary inertia the nodes' inertial translations lead, and a lag mode may read as the \
blades' frequency plus Omega); --monodromy runs \
reports the principal branch, |Im s| <= pi / T. Partial Floquet (--modes K): the K multipliers \
of largest modulus alone, by block Arnoldi on the same map, each block of K + 4 directions \
carried through a run of the period until the wanted ones converge; a run per block, so \
more CPU than the whole analysis on the models measured but a fraction of its memory (chosen \
by itself where the whole analysis would carry more than 2 GiB of directions).

Prony (--method prony): the poles of a transient, the model's own run (its excitation \
included), fitted by the matrix pencil method over --window (default: from a tenth of the run \
to its end), sampled about --samples times, the signals sharing the poles (THEORY §9.3). The \
signals are --signals, or by default every output channel except the blade coordinates that \
a `multiblade` output transforms: rotating-frame signals carry the rotor's harmonics, \
multiblade coordinates are fixed-frame. Signals of one physical dimension share a scale. The \
model order stops at the integration's noise floor, and only poles that hold when the order \
grows by 2, 4 and 6 and that reach 1 % of a signal's peak are kept; a fit that keeps none \
fails (a two-bladed rotor has no fixed-frame lag coordinates: use Floquet).

--method both runs both; the first listed method locates the edges. A point is unstable when \
its largest real part exceeds --threshold. Between neighbouring values of opposite stability \
the edge is bisected --refine times.

The CSV has the columns PARAM,max_real,min_damping_ratio,method, then freq1,real1,freq2,\
real2,... (rad/s and 1/s, modes by decreasing real part, conjugates once with freq >= 0; \
empty cells where a point failed), then mode1_freq,mode1_real,mode1_damping,...: the modes \
followed along the grid (per method), a stable column per mode: each mode continues the one \
of the previous value whose shape it matches best (the modal assurance criterion; Prony's \
poles, which have no shape, by the nearest exponent). --chart-kind real (the default) plots \
the real parts against the param, the largest as a line, with the unstable ranges shaded \
(modes damped below three times the grid's largest |Re s| are left off the chart, not the \
CSV); \
--chart-kind campbell the Campbell diagram: each followed mode's frequency with the \
per-revolution lines n Omega, and below it its real part, the unstable ranges shaded. \
--reference FILE.csv adds the columns of a CSV (its first column the param) as lines on the \
real parts. While the grid runs, the CSV is rewritten about every second with the points \
finished from the grid's start, so a long sweep can be read as it goes.

Examples:
  mbd stability models/windmill.mbd --sweep Omega_bar=0.8:2.6:0.05 -o stab.csv --chart stab.svg
  mbd stability models/windmill.mbd --sweep Omega_bar=0.8:2.6:0.05 -o stab.csv --chart campbell.svg --chart-kind campbell
  mbd stability models/windmill.mbd --sweep Omega_bar=1.0:2.5:0.5 --method both --set blades=3 -o stab.csv";

#[derive(clap::Args)]
pub struct StabilityArgs {
    /// The model file.
    model: String,
    /// The param and its values: NAME=START:STOP:STEP (STOP included).
    #[arg(long, value_name = "NAME=START:STOP:STEP", allow_hyphen_values = true)]
    sweep: String,
    /// floquet, prony or both.
    #[arg(long, value_enum, default_value = "floquet")]
    method: MethodArg,
    /// Floquet: the period in seconds (default: 2 pi / Omega of the driven rotor).
    #[arg(long)]
    period: Option<f64>,
    /// Floquet: the monodromy from the step's own tangent along one run, or from perturbed
    /// runs (4 n_f + 1 runs of a period; the cross-check).
    #[arg(long, value_enum, default_value = "tangent")]
    monodromy: MonodromyArg,
    /// Floquet: partial analysis, the K multipliers of largest modulus (the least stable
    /// modes) by block Arnoldi on the step's tangent over one period, for models too large to
    /// carry every direction (a damping integrator; a state of fewer than 3 (K + 4) entries
    /// gets the whole analysis).
    #[arg(long, value_name = "K", conflicts_with = "monodromy",
          value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..))]
    modes: Option<usize>,
    /// Prony: the channels to fit (comma-separated; default: every output channel).
    #[arg(long, value_name = "LIST")]
    signals: Option<String>,
    /// Prony: the part of the run to fit, FROM:TO in seconds.
    #[arg(long, value_name = "FROM:TO")]
    window: Option<String>,
    /// Prony: about this many samples over the window.
    #[arg(long, default_value_t = 300)]
    samples: usize,
    /// Unstable when the largest real part exceeds this (1/s).
    #[arg(long, default_value_t = 1e-2, allow_negative_numbers = true)]
    threshold: f64,
    /// Bisections of each edge of an unstable range.
    #[arg(long, default_value_t = 6)]
    refine: usize,
    /// Override a param: NAME=VALUE, VALUE in SI units or with units.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
    /// A CSV whose first column is the param and whose other columns are drawn as lines.
    #[arg(long, value_name = "FILE.csv")]
    reference: Option<String>,
    /// Write the sweep's CSV here.
    #[arg(short = 'o', long = "output", value_name = "STAB.csv")]
    output: String,
    /// Write the chart here (PNG for a `.png` name, else SVG).
    #[arg(long, value_name = "STAB.svg")]
    chart: Option<String>,
    /// The chart: the real parts of every mode (real), or the Campbell diagram of the followed
    /// modes, frequency with the per-rev lines above their real parts (campbell).
    #[arg(long, value_enum, default_value = "real")]
    chart_kind: ChartKind,
    /// Run the K-th of N shares of the sweep (1 <= K <= N) and write it to -o as a share
    /// file; `mbd merge` joins the N shares into the sweep's CSV and chart (a Slurm job
    /// array: K = $SLURM_ARRAY_TASK_ID).
    #[arg(long, value_name = "K/N", conflicts_with_all = ["chart", "reference"])]
    shard: Option<String>,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(super) enum ChartKind {
    Real,
    Campbell,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum MonodromyArg {
    Tangent,
    Runs,
}

impl MonodromyArg {
    fn name(self) -> &'static str {
        match self {
            MonodromyArg::Tangent => "tangent",
            MonodromyArg::Runs => "runs",
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum MethodArg {
    Floquet,
    Prony,
    Both,
}

impl MethodArg {
    fn name(self) -> &'static str {
        match self {
            MethodArg::Floquet => "floquet",
            MethodArg::Prony => "prony",
            MethodArg::Both => "both",
        }
    }
}

pub fn stability(a: StabilityArgs) -> ExitCode {
    let text = match read(&a.model) {
        Ok(t) => t,
        Err(code) => return code,
    };
    let swept = match Swept::parse(&a.model, &text, &a.set, &a.sweep, "Omega_bar=0.8:2.6:0.05") {
        Ok(s) => s,
        Err(code) => return code,
    };
    let (methods, window) = match methods_and_window(&a) {
        Ok(x) => x,
        Err(code) => return code,
    };
    let c = match swept.compile_first(&a.model, &text, &a.set, Format::Human) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let signals = match signals(&a, &c, &methods) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let reference = match a.reference.as_deref().map(reference_series).transpose() {
        Ok(r) => r.unwrap_or_default(),
        Err(code) => return code,
    };
    let shard = match a
        .shard
        .as_deref()
        .map(|s| parse_shard(s, swept.values.len()))
    {
        Some(Err(code)) => return code,
        Some(Ok(k)) => Some(k),
        None => None,
    };
    let (mut csv_file, chart_file) = match create_outputs(&a.output, a.chart.as_deref()) {
        Ok(files) => files,
        Err(code) => return code,
    };
    let spec = SweepSpec {
        param: swept.param,
        values: swept.values,
        methods,
        period: a.period,
        monodromy: match (a.modes, a.monodromy) {
            (Some(k), _) => Monodromy::Krylov(k),
            (None, MonodromyArg::Tangent) => Monodromy::Tangent,
            (None, MonodromyArg::Runs) => Monodromy::Runs,
        },
        signals,
        window,
        samples: a.samples,
        threshold: a.threshold,
        refine: a.refine,
    };
    let jobs = Jobs {
        path: &a.model,
        text: &text,
        sets: &a.set,
    };
    let progress = Evaluations::new("evaluations");
    if let Some(shard) = shard {
        let run = describe_run(&a, &text);
        let label = mbd::param_label(&c, &spec.param);
        let names = (run.as_str(), c.model.name.as_str(), label.as_str());
        let share = sweep::share::sweep_share(
            &spec,
            shard,
            &|extra| jobs.with_sets(extra),
            &|t| progress.tick(t),
            names,
        );
        progress.finish();
        return super::merge::write_share(&share, csv_file, &a.output);
    }
    // The CSV rewritten as the grid's points finish (at most every STREAM_EVERY), then whole.
    let stream = Mutex::new((&mut csv_file, None::<Instant>));
    let rows = |partial: &sweep::Sweep| {
        if let Ok(mut g) = stream.lock() {
            let (file, last) = &mut *g;
            if last.is_none_or(|t| t.elapsed() >= STREAM_EVERY) {
                *last = Some(Instant::now());
                // A failure here is reported by the final write.
                let _ = rewrite(file, partial);
            }
        }
    };
    let result = sweep::sweep_streaming(
        &spec,
        &|extra| jobs.with_sets(extra),
        &|t| progress.tick(t),
        &rows,
    );
    progress.finish();
    let label = mbd::param_label(&c, &spec.param);
    let names = (c.model.name.as_str(), label.as_str());
    finish(
        &result,
        (&mut csv_file, &a.output),
        chart_file,
        a.chart_kind,
        names,
        reference,
    )
}

/// The sweep's CSV written whole, its chart drawn (titled with the model's name, the param's
/// axis label), its report printed; the exit code.
pub(super) fn finish(
    result: &sweep::Sweep,
    (csv_file, output): (&mut std::fs::File, &str),
    mut chart_file: super::ChartFile,
    kind: ChartKind,
    (model, label): (&str, &str),
    reference: Vec<Series>,
) -> ExitCode {
    if let Err(e) = rewrite(csv_file, result) {
        return usage(&format!("cannot write `{output}`: {e}"));
    }
    if let Some((p, f)) = chart_file.as_mut() {
        let mut panels = match kind {
            ChartKind::Real => {
                let title = format!("{model}: growth rates Re s against {}", result.param);
                vec![result.chart(&title, reference)]
            }
            ChartKind::Campbell => {
                let title = format!("{model}: Campbell diagram against {}", result.param);
                result.campbell(&title, reference)
            }
        };
        for panel in &mut panels {
            panel.x_label = label.to_string();
        }
        draw_panels(p, f, &panels);
    }
    print_report(result);
    exit_unless_failed(result.points.iter().any(|p| p.failure.is_some()))
}

/// `--shard K/N`: 1 <= K <= N <= the grid's values (usage errors exit 2).
fn parse_shard(s: &str, values: usize) -> Result<(usize, usize), ExitCode> {
    let parsed = s.split_once('/').and_then(|(k, n)| {
        Some((
            k.trim().parse::<usize>().ok()?,
            n.trim().parse::<usize>().ok()?,
        ))
    });
    match parsed {
        Some((k, n)) if k >= 1 && k <= n && n <= values => Ok((k, n)),
        Some((_, n)) if n > values => Err(usage(&format!(
            "--shard {s}: the sweep has {values} values, so at most {values} shares"
        ))),
        _ => Err(usage(&format!(
            "--shard takes K/N with 1 <= K <= N, e.g. --shard 2/8, got `{s}`"
        ))),
    }
}

/// What every share of one sweep must agree on: the model's text (hashed) and the options
/// of the analysis.
fn describe_run(a: &StabilityArgs, text: &str) -> String {
    // FNV-1a: a fingerprint, not a defence against forgery.
    let hash = text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    });
    format!(
        "model {hash:016x}; --sweep {}; --set {:?}; --method {:?}; --period {:?}; --monodromy {:?}; --modes {:?}; --signals {:?}; --window {:?}; --samples {}",
        a.sweep,
        a.set,
        a.method.name(),
        a.period,
        a.monodromy.name(),
        a.modes,
        a.signals,
        a.window,
        a.samples
    )
}

/// How often the CSV is rewritten while the grid runs.
const STREAM_EVERY: Duration = Duration::from_secs(1);

/// The file emptied, then the sweep's CSV written into it.
fn rewrite(file: &mut std::fs::File, s: &sweep::Sweep) -> std::io::Result<()> {
    file.set_len(0)?;
    file.seek(SeekFrom::Start(0))?;
    let mut out = std::io::BufWriter::new(file);
    s.write_csv(&mut out)?;
    out.flush()
}

/// The methods (the primary first) and Prony's window, with the flags that belong to them
/// checked (usage errors exit 2).
fn methods_and_window(a: &StabilityArgs) -> Result<(Vec<Method>, Option<Window>), ExitCode> {
    if let Some(t) = a.period {
        if !(t.is_finite() && t > 0.0) {
            return Err(usage(&format!(
                "--period must be a positive time in seconds, got {t}"
            )));
        }
    }
    if !a.threshold.is_finite() {
        return Err(usage("--threshold must be a number (1/s)"));
    }
    let window = a.window.as_deref().map(parse_window).transpose()?;
    let methods = match a.method {
        MethodArg::Floquet => vec![Method::Floquet],
        MethodArg::Prony => vec![Method::Prony],
        MethodArg::Both => vec![Method::Floquet, Method::Prony],
    };
    let prony = methods.contains(&Method::Prony);
    if !prony && (a.window.is_some() || a.signals.is_some()) {
        return Err(usage(
            "--window and --signals belong to --method prony or both",
        ));
    }
    if prony && a.samples < 12 {
        return Err(usage("--samples must be at least 12"));
    }
    Ok((methods, window))
}

/// Prony's window, FROM and TO in seconds.
type Window = (f64, f64);

/// `--window FROM:TO` in seconds, `0 <= FROM < TO`.
fn parse_window(w: &str) -> Result<Window, ExitCode> {
    let parsed = w
        .split_once(':')
        .and_then(|(f, t)| Some((f.trim().parse::<f64>().ok()?, t.trim().parse::<f64>().ok()?)));
    match parsed {
        Some((f, t)) if f.is_finite() && t.is_finite() && f >= 0.0 && t > f => Ok((f, t)),
        _ => Err(usage(&format!(
            "--window takes FROM:TO in seconds with 0 <= FROM < TO, got `{w}`"
        ))),
    }
}

/// Prony's `--signals` (each an output channel of the model), and what each method needs of
/// the model: Prony channels to fit, Floquet without `--period` a steady rotor speed.
fn signals(a: &StabilityArgs, c: &Compiled, methods: &[Method]) -> Result<Vec<String>, ExitCode> {
    let signals: Vec<String> = a
        .signals
        .as_deref()
        .map(|s| s.split(',').map(|x| x.trim().to_string()).collect())
        .unwrap_or_default();
    let channels: Vec<&str> = c.model.outputs.iter().map(|o| o.column.as_str()).collect();
    if let Some(bad) = signals.iter().find(|s| !channels.contains(&s.as_str())) {
        return Err(usage(&format!(
            "model `{}` has no output channel `{bad}`; its channels are: {}",
            a.model,
            channels.join(", ")
        )));
    }
    if methods.contains(&Method::Prony) && channels.is_empty() && signals.is_empty() {
        return Err(usage(
            "Prony needs output channels to fit: the model declares no `output`",
        ));
    }
    if methods.contains(&Method::Floquet) && a.period.is_none() {
        if let Err(e) = sweep::rotor_period(c) {
            return Err(usage(&e.to_string()));
        }
    }
    Ok(signals)
}

/// The columns of a reference CSV as lines against its first column.
pub(super) fn reference_series(path: &str) -> Result<Vec<Series>, ExitCode> {
    let text =
        std::fs::read_to_string(path).map_err(|e| usage(&format!("cannot read `{path}`: {e}")))?;
    let (header, rows) =
        mbd::output::read_csv(&text).map_err(|e| usage(&format!("`{path}`: {e}")))?;
    if header.len() < 2 {
        return Err(usage(&format!(
            "`{path}` needs the param in its first column and at least one more column"
        )));
    }
    Ok((1..header.len())
        .map(|k| Series {
            label: header[k].clone(),
            points: rows.iter().map(|r| (r[0], r[k])).collect(),
            markers_only: false,
        })
        .collect())
}

pub(super) fn print_report(s: &sweep::Sweep) {
    say(&format!(
        "{:>12}  {:>8}  {:>12}  {:>12}  {:>12}  {:>8}",
        s.param, "method", "max Re s", "min damping", "its freq", "cpu s"
    ));
    for p in &s.points {
        match &p.failure {
            Some(f) => say(&format!(
                "{:>12}  {:>8}  failed: {f}",
                short(p.value),
                p.method.name()
            )),
            None => {
                let top = p.modes.first();
                say(&format!(
                    "{:>12}  {:>8}  {:>12}  {:>12}  {:>12}  {:>8}",
                    short(p.value),
                    p.method.name(),
                    short(p.max_real()),
                    short(p.min_damping_ratio()),
                    top.map(|m| short(m.im)).unwrap_or_default(),
                    format!("{:.2}", p.cpu_s)
                ));
            }
        }
    }
    for r in s.refinements.iter().filter(|r| r.failure.is_some()) {
        say(&format!(
            "refinement at {} failed: {}",
            short(r.value),
            r.failure
                .as_ref()
                .map(|f| f.to_string())
                .unwrap_or_default()
        ));
    }
    for n in &s.notes {
        say(&format!("note: {n}"));
    }
    for e in &s.edges {
        say(&format!(
            "edge: {} = {} (bracket {} .. {}), {} as {} grows",
            s.param,
            short(e.value),
            short(e.bracket.0),
            short(e.bracket.1),
            if e.onset { "unstable" } else { "stable" },
            s.param
        ));
    }
    let ranges = s.unstable_ranges();
    if ranges.is_empty() {
        say(&format!(
            "no unstable range (largest real part at most {} 1/s)",
            s.threshold
        ));
    }
    for (a, b) in ranges {
        say(&format!(
            "unstable: {} < {} < {}",
            short(a),
            s.param,
            short(b)
        ));
    }
}
