//! `mbd study`: parses and checks the flags, reads the model and any reference file, runs the
//! study through `mbd::study`, writes its CSV and chart and prints the report. The study
//! itself (runs, errors, orders, onsets) lives in the library.

use super::{
    compile, create_outputs, draw, read, say, short, usage, ChartFile, Format, Jobs, EXIT_RUNTIME,
};
use mbd::settings::Request;
use mbd::study::compare::Samples;
use mbd::study::convergence::{self, ConvergenceSpec, ReferenceSpec};
use mbd::study::stability::{self, Detector, StabilitySpec};
use mbd::study::{parse_alphas, IntegratorItem, StepList};
use std::fs::File;
use std::process::ExitCode;

/// `mbd study --help`.
pub const LONG_ABOUT: &str = "\
Convergence or stability study: runs the model once per integrator (or alpha) and step, in \
parallel over the cores, and measures one output channel.

Convergence (--integrator LIST): for each run, the error of the channel against the reference,

    error = |y - y_ref| / max_t |y_ref(t)|

at the time --at T, or without --at the largest over the run's output times; the denominator \
is the reference channel's largest magnitude over the run (1 if it is zero throughout). Values \
at a time are the row at that time (within 1e-9 dt), else cubic (4-point Lagrange) \
interpolation. The CSV has the columns integrator,dt,steps,error,cpu_s,newton_iters (cpu_s: \
thread CPU time of the run alone); a failed run keeps its row with empty cells. The chart \
plots error against CPU time on log-log axes, one line per integrator with its observed order \
in the legend, a dashed guide of order 2 (and 4 when an integrator exceeds 3), dotted lines at \
the target errors 1e-3 and 1e-6; SVG, or PNG for a .png name. Printed: the table, and \
each integrator's observed order (least-squares slope of log(error) against log(dt), and the \
slope between its two finest runs).

Stability (--alpha LIST): HHT at each alpha (and each step of --steps/--dt, else the model's \
step). For each run, the onset time at which the channel (an acceleration or a joint force) \
starts to grow without bound, or none. Detector: the alternating part o_k = |y(k+1) - 2 y(k) + \
y(k-1)| / 4 and its envelope e_k (largest o over the last 40 steps); growth starts where o_k > \
1e-2 max|y| so far and e_k >= 10 e_(k-40); it was bounded once e falls below a tenth of its \
peak or sets no new peak for 200 steps; growth still under way when the run ends or fails is \
unbounded, with its onset the last time before the peak at which e was at most 1/100 of the \
peak. A failed run's onset is the earlier of that and the failure time. The CSV has the \
columns integrator,alpha,dt,steps,onset_s,failed_s,cpu_s,newton_iters (empty cell: none); the \
chart plots |channel| against time, one line per run.

Examples:
  mbd study models/pendulum.mbd --channel x --integrator hht:-0.1,generalized-alpha --steps 100,200,400,800 -o study.csv --chart study.svg
  mbd study models/rotating_beam.mbd --channel phi --at 0.032001554992256216 --integrator hht --steps 12,36,108 --reference exact -o beam.csv --chart beam.svg
  mbd study models/two_bar.mbd --channel ayc2 --alpha 0,-0.1 -o stability.csv --chart stability.svg";

#[derive(clap::Args)]
pub struct StudyArgs {
    /// The model file.
    model: String,
    /// The output channel to study (a CSV column of the model's `output`).
    #[arg(long)]
    channel: String,
    /// Compare at this time (s) only; default: the largest error over the run.
    #[arg(long, allow_negative_numbers = true)]
    at: Option<f64>,
    /// Convergence: hht, hht:ALPHA, generalized-alpha, generalized-alpha:RHO_INF, fet (comma-separated).
    #[arg(long, value_name = "LIST")]
    integrator: Option<String>,
    /// Stability: HHT alphas in [-1/3, 0] (comma-separated).
    #[arg(long, value_name = "LIST", allow_hyphen_values = true)]
    alpha: Option<String>,
    /// Step counts (comma-separated); dt = until / N.
    #[arg(long, value_name = "LIST")]
    steps: Option<String>,
    /// Time steps in seconds (comma-separated); N = round(until / dt).
    #[arg(long, value_name = "LIST")]
    dt: Option<String>,
    /// End time in seconds (default: the model's).
    #[arg(long)]
    until: Option<f64>,
    /// exact (the model's `exact` solution), finest (default: a run at a quarter of the
    /// smallest step) or a CSV file with a `t` (or `time`) column and the channel's.
    #[arg(long, value_name = "exact|finest|FILE.csv")]
    reference: Option<String>,
    /// Override a param: NAME=VALUE, VALUE in SI units or with units (V0=5, V0=5m/s).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
    /// Write the study's CSV here.
    #[arg(short = 'o', long = "output", value_name = "STUDY.csv")]
    output: String,
    /// Write the chart here (PNG for a `.png` name, else SVG).
    #[arg(long, value_name = "STUDY.svg")]
    chart: Option<String>,
}

pub fn study(a: StudyArgs) -> ExitCode {
    let stability = match is_stability(&a) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let steps = match step_list(&a, stability) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let text = match read(&a.model) {
        Ok(t) => t,
        Err(code) => return code,
    };
    if let Some(t) = a.until {
        if !(t.is_finite() && t > 0.0) {
            return usage(&format!(
                "--until must be a positive time in seconds, got {t}"
            ));
        }
    }
    let base = Request {
        every: Some(1),
        until: a.until,
        ..Request::default()
    };
    let c = match compile(&a.model, &text, &a.set, base.clone(), Format::Human) {
        Ok(c) => c,
        Err(code) => return code,
    };
    if let Err(code) = has_channel(&a, &c) {
        return code;
    }
    let until = c.settings.until;
    let counts = match &steps {
        Some(s) => match s.counts(until) {
            Ok(n) => n,
            Err(e) => return usage(&e.to_string()),
        },
        None => vec![c.settings.steps],
    };
    // Fail on unwritable outputs now, not after the runs.
    let (csv, chart) = match create_outputs(&a.output, a.chart.as_deref()) {
        Ok(files) => files,
        Err(code) => return code,
    };
    let run = Runs {
        jobs: Jobs {
            path: &a.model,
            text: &text,
            sets: &a.set,
        },
        base,
        counts,
        until,
        title: c.model.name.clone(),
        csv,
        chart,
    };
    if stability {
        run.stability(&a)
    } else {
        run.convergence(&a, &c)
    }
}

/// A stability study (`--alpha`) or a convergence study (`--integrator`); the flags that
/// belong to the other kind are usage errors.
fn is_stability(a: &StudyArgs) -> Result<bool, ExitCode> {
    let stability = match (&a.integrator, &a.alpha) {
        (Some(_), Some(_)) => {
            return Err(usage("give --integrator LIST (a convergence study) or --alpha LIST (a stability study), not both"))
        }
        (None, None) => {
            return Err(usage("say what to study: --integrator LIST (convergence, e.g. `--integrator hht,generalized-alpha`) or --alpha LIST (stability, e.g. `--alpha 0,-0.1`)"))
        }
        (None, Some(_)) => true,
        (Some(_), None) => false,
    };
    if stability && (a.reference.is_some() || a.at.is_some()) {
        return Err(usage("--reference and --at belong to convergence studies (--integrator), not to stability studies (--alpha)"));
    }
    Ok(stability)
}

/// `--steps LIST` or `--dt LIST`; `None`: the model's step (stability studies only).
fn step_list(a: &StudyArgs, stability: bool) -> Result<Option<StepList>, ExitCode> {
    let steps = match (&a.steps, &a.dt) {
        (Some(_), Some(_)) => return Err(usage("give --steps LIST or --dt LIST, not both")),
        (Some(s), None) => StepList::parse_counts(s).map(Some),
        (None, Some(d)) => StepList::parse_dt(d).map(Some),
        (None, None) if stability => Ok(None),
        (None, None) => {
            return Err(usage("a convergence study needs the steps: --steps LIST (e.g. 100,200,400) or --dt LIST (seconds)"))
        }
    };
    steps.map_err(|e| usage(&e.to_string()))
}

/// The studied channel must be one of the model's outputs.
fn has_channel(a: &StudyArgs, c: &mbd::Compiled) -> Result<(), ExitCode> {
    let channels: Vec<&str> = c.model.outputs.iter().map(|o| o.column.as_str()).collect();
    if channels.contains(&a.channel.as_str()) {
        return Ok(());
    }
    let known = if channels.is_empty() {
        "the model declares no outputs".to_string()
    } else {
        format!("its channels are: {}", channels.join(", "))
    };
    Err(usage(&format!(
        "model `{}` has no output channel `{}`; {known}",
        a.model, a.channel
    )))
}

/// What both kinds of study share: the jobs' model and settings, the steps, the outputs.
struct Runs<'a> {
    jobs: Jobs<'a>,
    base: Request,
    counts: Vec<usize>,
    until: f64,
    title: String,
    csv: File,
    chart: ChartFile<'a>,
}

impl Runs<'_> {
    fn stability(mut self, a: &StudyArgs) -> ExitCode {
        let alphas = match parse_alphas(a.alpha.as_deref().unwrap_or_default()) {
            Ok(v) => v,
            Err(e) => return usage(&e.to_string()),
        };
        let spec = StabilitySpec {
            channel: a.channel.clone(),
            alphas,
            steps: self.counts,
            until: self.until,
            detector: Detector::default(),
        };
        let compile = |r: &Request| self.jobs.with_request(r);
        let rows = stability::stability(&spec, &self.base, &compile);
        if let Err(e) = stability::write_csv(&rows, &mut self.csv) {
            return usage(&format!("cannot write `{}`: {e}", a.output));
        }
        if let Some((p, f)) = self.chart.as_mut() {
            draw(p, f, &stability::chart(&rows, &self.title, &a.channel));
        }
        print_stability(&rows, self.until);
        ExitCode::SUCCESS
    }

    fn convergence(mut self, a: &StudyArgs, c: &mbd::Compiled) -> ExitCode {
        let integrators =
            match IntegratorItem::parse_list(a.integrator.as_deref().unwrap_or_default()) {
                Ok(i) => i,
                Err(e) => return usage(&e.to_string()),
            };
        let until = self.until;
        if let Some(t) = a.at {
            if !(t >= -1e-9 * until && t <= until * (1.0 + 1e-9)) {
                return usage(&format!(
                    "--at {t} lies outside the run, which goes from 0 to {until} s"
                ));
            }
        }
        let reference = match reference(a, c, until) {
            Ok(r) => r,
            Err(code) => return code,
        };
        let spec = ConvergenceSpec {
            channel: a.channel.clone(),
            at: a.at,
            integrators,
            steps: self.counts,
            until,
            reference,
        };
        let compile = |r: &Request| self.jobs.with_request(r);
        let study = convergence::convergence(&spec, &self.base, &compile);
        if let Err(e) = study.write_csv(&mut self.csv) {
            return usage(&format!("cannot write `{}`: {e}", a.output));
        }
        if let Some((p, f)) = self.chart.as_mut() {
            draw(p, f, &study.chart(&self.title, &a.channel));
        }
        print_convergence(&study, &spec);
        match study.finest.as_ref().and_then(|f| f.failure.as_ref()) {
            Some(_) => ExitCode::from(EXIT_RUNTIME),
            None => ExitCode::SUCCESS,
        }
    }
}

/// The reference of a convergence study; usage errors exit 2.
fn reference(a: &StudyArgs, c: &mbd::Compiled, until: f64) -> Result<ReferenceSpec, ExitCode> {
    match a.reference.as_deref() {
        None | Some("finest") => Ok(ReferenceSpec::Finest),
        Some("exact") => match c.model.exact.iter().find(|e| e.column == a.channel) {
            Some(e) => Ok(ReferenceSpec::Exact(e.f.clone())),
            None => Err(usage(&format!(
                "--reference exact: model `{}` declares no exact solution of `{}`\n  hint: add `exact {} = EXPRESSION of t` to the model (see `mbd explain E0405`), or use `--reference finest`",
                a.model, a.channel, a.channel
            ))),
        },
        Some(file) => {
            let text = std::fs::read_to_string(file)
                .map_err(|e| usage(&format!("cannot read reference file `{file}`: {e}")))?;
            let (header, rows) = mbd::output::read_csv(&text)
                .map_err(|e| usage(&format!("reference file `{file}` is not a numeric CSV: {e}")))?;
            let s = Samples::from_table(&header, &rows, &a.channel)
                .map_err(|e| usage(&format!("reference file `{file}`: {e}")))?;
            s.check_increasing()
                .map_err(|e| usage(&format!("reference file `{file}`: {e}")))?;
            let covers = match s.span() {
                Some((first, last)) => first <= 1e-9 * until && last >= until * (1.0 - 1e-9),
                None => false,
            };
            if !covers {
                return Err(usage(&format!(
                    "reference file `{file}` must cover the run, from 0 to {until} s{}",
                    s.span()
                        .map(|(f, l)| format!("; it goes from {f} to {l} s"))
                        .unwrap_or_else(|| "; it has no rows".to_string())
                )));
            }
            Ok(ReferenceSpec::Samples(s))
        }
    }
}

/// The convergence report: the reference, the table, the failures, the observed orders and
/// the CPU time to reach an error.
fn print_convergence(study: &convergence::Convergence, spec: &ConvergenceSpec) {
    match (&spec.reference, &study.finest) {
        (ReferenceSpec::Exact(_), _) => say(&format!(
            "reference: the exact solution of {}",
            spec.channel
        )),
        (ReferenceSpec::Samples(_), _) => say("reference: the reference file"),
        (ReferenceSpec::Finest, Some(f)) => {
            say(&format!(
                "reference: finest run, {} with dt = {} s ({} steps, {} s CPU)",
                f.integrator,
                short(f.dt),
                f.steps,
                short(f.cpu_s)
            ));
            if let Some(m) = &f.failure {
                say(&format!("  the reference run failed: {m}"));
            }
        }
        (ReferenceSpec::Finest, None) => {}
    }
    let width = study
        .rows
        .iter()
        .map(|r| r.integrator.len())
        .max()
        .unwrap_or(0)
        .max("integrator".len());
    say(&format!(
        "{:<width$}  {:>12}  {:>8}  {:>12}  {:>10}  {:>8}",
        "integrator", "dt [s]", "steps", "error", "cpu [s]", "newton"
    ));
    for r in &study.rows {
        let num = |x: Option<f64>, p: usize| match x {
            Some(v) => format!("{v:.p$e}"),
            None => "-".to_string(),
        };
        say(&format!(
            "{:<width$}  {:>12}  {:>8}  {:>12}  {:>10}  {:>8}",
            r.integrator,
            num(Some(r.dt), 4),
            r.steps,
            num(r.error, 4),
            num(r.cpu_s, 3),
            r.newton_iterations
                .map(|n| n.to_string())
                .unwrap_or_else(|| "-".to_string())
        ));
    }
    for r in study.rows.iter().filter(|r| r.failure.is_some()) {
        say(&format!(
            "{}, {} steps: {}",
            r.integrator,
            r.steps,
            r.failure.as_deref().unwrap_or_default()
        ));
    }
    for (name, order) in study.orders() {
        match order {
            Some(o) => say(&format!(
                "{name}  observed order {:.2} (finest pair {:.2})",
                o.fit, o.finest_pair
            )),
            None => say(&format!(
                "{name}  observed order: fewer than two runs with an error"
            )),
        }
    }
    for (name, _) in study.orders() {
        let reach = |target: f64| match study.cpu_to_reach(&name, target) {
            Some((c, false)) => format!("{} s", short(c)),
            Some((c, true)) => format!("{} s (extrapolated)", short(c)),
            None => "-".to_string(),
        };
        let [coarse, fine] = mbd::study::convergence::TARGETS;
        say(&format!(
            "{name}  CPU to reach {coarse:e}: {}; {fine:e}: {}",
            reach(coarse),
            reach(fine)
        ));
    }
}

/// The stability report: the table, then each run's onset.
fn print_stability(rows: &[stability::StabilityRow], until: f64) {
    let several_steps = rows.iter().any(|r| r.steps != rows[0].steps);
    say(&format!(
        "{:>8}  {:>12}  {:>8}  {:>10}  {:>10}  {:>10}  {:>8}",
        "alpha", "dt [s]", "steps", "onset [s]", "failed [s]", "cpu [s]", "newton"
    ));
    let opt = |x: Option<f64>| x.map(short).unwrap_or_else(|| "-".to_string());
    for r in rows {
        say(&format!(
            "{:>8}  {:>12}  {:>8}  {:>10}  {:>10}  {:>10}  {:>8}",
            r.alpha,
            short(r.dt),
            r.steps,
            opt(r.onset),
            opt(r.failed),
            r.cpu_s
                .map(|c| format!("{c:.3e}"))
                .unwrap_or_else(|| "-".to_string()),
            r.newton_iterations
                .map(|n| n.to_string())
                .unwrap_or_else(|| "-".to_string())
        ));
    }
    for r in rows {
        let which = if several_steps {
            format!("alpha = {}, dt = {} s", r.alpha, short(r.dt))
        } else {
            format!("alpha = {}", r.alpha)
        };
        let failed = r
            .failed
            .map(|f| format!(" (the run failed at {f:.2} s)"))
            .unwrap_or_default();
        match r.onset {
            Some(t) => say(&format!("{which}: onset at {t:.2} s{failed}")),
            None => match &r.failure {
                Some(m) => say(&format!("{which}: the run failed: {m}")),
                None => say(&format!("{which}: no growth through {} s", short(until))),
            },
        }
    }
}
