//! `mbd modes`: the flags, usage errors (exit 2), the printed summary; the analysis is
//! `mbd::modes` (one state) and `mbd::study::fan` (a sweep).

use super::progress::Evaluations;
use super::swept::Swept;
use super::{
    compile, create_outputs, draw_panels, exit_unless_failed, read_as, report, sink, to_path,
    usage, Format, Jobs, EXIT_RUNTIME,
};
use mbd::settings::Request;
use mbd::solve::modes::{Frame, Modes};
use mbd::study::fan::{self, FanSpec};
use std::process::ExitCode;

pub const LONG_ABOUT: &str = "\
Natural frequencies and mode shapes about the initial state, as CSV.

The linearized equations about the consistent state at t = 0 (THEORY §3.6), reduced to the \
constraint-free subspace, solved as a quadratic eigenproblem. Modes exist only about a steady \
motion: an equilibrium, or a rigid rotation of the whole model at one rate about one axis \
(every acceleration centripetal) in a model symmetric about that axis; the modes are then \
referred to the frame turning with it (column frame = rotating, else inertial). A model with no \
steady motion (a rotor on a non-rotating flexible structure, two rotors, gravity across the spin \
axis, a state that accelerates) is refused with E0605 (exit 3): its equations are periodic or \
time-varying; use `mbd stability`. --frozen computes the eigenvalues of the equations frozen at \
t = 0 anyway and marks every output frame = frozen: they are not modes.

The table: mode,frequency_hz,omega_rad_s,damping_ratio,real_per_s,imag_rad_s,frame (omega = \
|s|, frequency = Im s / 2 pi, damping ratio = -Re s / |s|), by increasing omega, the first \
--count. Motions without inertia have no frequency: a model has as many modes as degrees of \
freedom with inertia. --shapes writes mode,unknown,entity,kind,real,imag,frame (each shape \
scaled so that its largest entry is 1).

--sweep NAME=START:STOP:STEP (units allowed: Omega=200rpm:400rpm:100rpm) takes the modes at \
every value (in parallel) and follows each mode by its shape; -o gets \
NAME,mode,frequency_hz,omega_rad_s,damping_ratio,real_per_s,imag_rad_s,frame,rotor_speed_rad_s \
(NAME in SI; mode is the followed mode's number), --chart a Campbell diagram: each mode's \
natural frequency against the param, with the per-revolution lines n Omega of the rotor speed, \
and below it each mode's real part, the ranges where a mode grows shaded. A value that fails \
keeps a row of empty cells, and the exit code is 3.

Examples:
  mbd modes models/cantilever.mbd
  mbd modes rotor.mbd --count 6 -o modes.csv --shapes shapes.csv
  mbd modes rotor.mbd --sweep Omega=0rpm:600rpm:50rpm -o fan.csv --chart fan.svg";

#[derive(clap::Args)]
pub struct ModesArgs {
    /// The model file.
    model: String,
    /// Write the frequency table here (default: standard output).
    #[arg(short = 'o', long = "output")]
    output: Option<String>,
    /// Write the mode shapes here.
    #[arg(long, conflicts_with = "sweep")]
    shapes: Option<String>,
    /// How many modes, by increasing frequency.
    #[arg(long, default_value_t = 10)]
    count: usize,
    /// Eigenvalues of the equations frozen at t = 0 where the motion is not steady (marked
    /// `frozen`): not modes.
    #[arg(long)]
    frozen: bool,
    /// Modes against a param: NAME=START:STOP:STEP (STOP included; units allowed).
    #[arg(long, value_name = "NAME=START:STOP:STEP", allow_hyphen_values = true)]
    sweep: Option<String>,
    /// With --sweep: write the fan plot here (PNG for a `.png` name, else SVG).
    #[arg(long, value_name = "FAN.svg", requires = "sweep")]
    chart: Option<String>,
    /// Override a param: NAME=VALUE, VALUE in SI units or with units.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
    /// Diagnostics format.
    #[arg(long, value_enum, default_value = "human")]
    format: Format,
}

pub fn modes(a: ModesArgs) -> ExitCode {
    if a.count == 0 {
        return usage("--count must be at least 1");
    }
    let text = match read_as(&a.model, a.format) {
        Ok(t) => t,
        Err(code) => return code,
    };
    match &a.sweep {
        Some(spec) => sweep(&a, &text, spec),
        None => at_start(&a, &text),
    }
}

/// The modes about the initial state: the table, the shapes, the summary.
fn at_start(a: &ModesArgs, text: &str) -> ExitCode {
    let c = match compile(&a.model, text, &a.set, Request::default(), a.format) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let m = match mbd::modes(&c, a.frozen) {
        Ok(m) => m,
        Err(d) => {
            report(std::slice::from_ref(&d), &c.sources, a.format);
            return ExitCode::from(EXIT_RUNTIME);
        }
    };
    let mut table = match sink(a.output.as_deref()) {
        Ok(s) => s,
        Err(code) => return code,
    };
    if let Err(e) = mbd::write_modes(&m, a.count, &mut table) {
        return usage(&format!("cannot write the modes: {e}"));
    }
    drop(table);
    if let Some(p) = &a.shapes {
        let mut shapes = match sink(Some(p)) {
            Ok(s) => s,
            Err(code) => return code,
        };
        if let Err(e) = mbd::write_shapes(&c, &m, a.count, &mut shapes) {
            return usage(&format!("cannot write the shapes: {e}"));
        }
    }
    if a.format == Format::Human {
        eprintln!("{}", summary(&c, &m, a.count, a.output.as_deref()));
    }
    ExitCode::SUCCESS
}

/// The line after the table: how many modes, in which frame, and why fewer than asked for.
fn summary(c: &mbd::Compiled, m: &Modes, count: usize, output: Option<&str>) -> String {
    let shown = m.modes.len().min(count);
    let frame = match &m.frame {
        Frame::Inertial => String::new(),
        Frame::Rotating { spin } => format!(
            ", referred to the frame spinning at ({:.6}, {:.6}, {:.6}) rad/s",
            spin[0], spin[1], spin[2]
        ),
        Frame::Frozen { .. } => ", FROZEN-TIME eigenvalues at t = 0 (the motion is not steady: these are not the model's modes; `mbd stability` analyses a periodic system)".to_string(),
    };
    let mut line = format!("{}: {shown} modes{frame}{}", c.model.name, to_path(output));
    if m.moved > 0.0 {
        line.push_str(&format!(
            "\nnote: about the steady motion found from the initial state, which it moves by up to {:.3e} m",
            m.moved
        ));
    }
    if count > m.modes.len() {
        line.push_str(&format!(
            "\nnote: {count} modes were asked for; the model has {}: {} degrees of freedom{}",
            m.modes.len(),
            m.dofs,
            if m.massless > 0 {
                format!(", {} of them without inertia (no frequency)", m.massless)
            } else {
                String::new()
            }
        ));
    }
    line
}

/// `--sweep`: the modes at every value, followed across them (a fan plot).
fn sweep(a: &ModesArgs, text: &str, spec: &str) -> ExitCode {
    let Some(output) = &a.output else {
        return usage("--sweep needs -o FAN.csv");
    };
    let swept = match Swept::parse(&a.model, text, &a.set, spec, "Omega=0:600rpm:50rpm") {
        Ok(s) => s,
        Err(code) => return code,
    };
    let c = match swept.compile_first(&a.model, text, &a.set, a.format) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let (mut csv, mut chart) = match create_outputs(output, a.chart.as_deref()) {
        Ok(f) => f,
        Err(code) => return code,
    };
    let jobs = Jobs {
        path: &a.model,
        text,
        sets: &a.set,
    };
    let progress = Evaluations::new("values");
    let param = swept.param;
    let spec = FanSpec {
        param: param.clone(),
        values: swept.values,
        count: a.count,
        frozen: a.frozen,
    };
    let result = fan::fan(&spec, &|extra| jobs.with_sets(extra), &|t| progress.tick(t));
    progress.finish();
    if let Err(e) = result.write_csv(&mut csv) {
        return usage(&format!("cannot write `{output}`: {e}"));
    }
    if let Some((p, f)) = chart.as_mut() {
        let title = format!("{}: Campbell diagram against {param}", c.model.name);
        let mut panels = result.chart(&title);
        let label = mbd::param_label(&c, &param);
        for panel in &mut panels {
            panel.x_label.clone_from(&label);
        }
        draw_panels(p, f, &panels);
    }
    let mut failed = false;
    for p in &result.points {
        if let Some(e) = &p.failure {
            eprintln!("error: {param} = {}: {e}", p.value);
            failed = true;
        }
    }
    if a.format == Format::Human {
        eprintln!(
            "{}: {} values of {param}, {} modes followed, to {output}{}",
            c.model.name,
            result.points.len(),
            result.tracks,
            a.chart
                .as_deref()
                .map(|p| format!(" and {p}"))
                .unwrap_or_default()
        );
    }
    exit_unless_failed(failed)
}
