//! Solver settings, in one place: the methods, rotation treatments and starts, the settings of
//! a run with their defaults and valid ranges, and the one check of them.
//!
//! Contract: plain data. A model's `solve` block (evaluated by the model stage, which only
//! records what the file wrote: a [`Written`]) and the command line (`mbd run`, `mbd study`'s
//! integrator items) each give a [`Request`]; [`Settings::resolve`] lays the command line's
//! over the file's, fills in the defaults and checks every value ([`Request::check`]),
//! returning coded diagnostics. The solve stage reads [`Settings`] only; Floquet and Prony
//! derive theirs with [`Settings::over`] and [`Settings::ending_by`].
//! Must not know: the syntax, the model, the runtime, the integrators' algorithms.

use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::source::Span;
use serde::Serialize;

mod options;
pub use options::{Method, NewtonMode, Rotations, Start, AUTO_RATE, MODIFIED_RATE};

/// A closed range of a real setting, its default and how it is written in messages.
#[derive(Clone, Copy, Debug)]
pub struct Range {
    pub min: f64,
    pub max: f64,
    pub default: f64,
    pub text: &'static str,
}

impl Range {
    /// Inside, with a round-off allowance (`-1/3` written as `-0.3333333333333333`).
    pub fn contains(&self, x: f64) -> bool {
        (self.min - 1e-12..=self.max + 1e-12).contains(&x)
    }
}

/// HHT alpha.
pub const ALPHA: Range = Range {
    min: -1.0 / 3.0,
    max: 0.0,
    default: -0.1,
    text: "[-1/3, 0]",
};
/// Generalized-alpha spectral radius at infinite frequency.
pub const RHO_INF: Range = Range {
    min: 0.0,
    max: 1.0,
    default: 0.8,
    text: "[0, 1]",
};
/// The Newton increment tolerance lies in the open interval (0, this).
pub const TOLERANCE_MAX: f64 = 1e-2;
pub const TOLERANCE_DEFAULT: f64 = 1e-10;
pub const RESIDUAL_TOLERANCE: f64 = 1e-8;
pub const MAX_ITERATIONS_DEFAULT: usize = 25;
/// Halvings of a failing time step; a failing load step of statics is split further.
pub const HALVINGS: usize = 3;
pub const STATIC_HALVINGS: usize = 4;
/// The largest count a `solve` block may write (steps, every, max_iterations).
pub const COUNT_MAX: usize = 1_000_000_000;

/// The settings of a run, resolved and checked.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Settings {
    /// The time integrator. Default HHT.
    pub method: Method,
    /// HHT alpha, in [`ALPHA`] = [-1/3, 0], default -0.1. More negative damps high
    /// frequencies more (spectral radius at infinity `(1 + alpha)/(1 - alpha)`); 0 is the
    /// trapezoidal rule. Used by HHT and statics' constants only.
    pub alpha: f64,
    /// Generalized-alpha spectral radius at infinity, in [`RHO_INF`] = [0, 1], default 0.8:
    /// 1 adds no dissipation, 0 the most. Used by generalized-alpha only.
    pub rho_inf: f64,
    /// The rotation treatment. Default incremental; FET always integrates incrementally
    /// and fails on conformal (E0604).
    pub rotations: Rotations,
    /// The time step [s], > 0: `until / steps`. From the `solve` block's `dt` (rounded down so
    /// that a whole number of steps ends at `until`) or `steps`.
    pub dt: f64,
    /// The number of steps, >= 1.
    pub steps: usize,
    /// The end time [s], > 0: `steps * dt` up to round-off, as written.
    pub until: f64,
    /// Write every K-th step, K >= 1. Default 1.
    pub every: usize,
    /// How the first step starts. Default consistent.
    pub start: Start,
    /// Newton increment tolerance relative to the model's length scale (in radians for
    /// rotations), in (0, [`TOLERANCE_MAX`]); default 1e-10. Also bounds the constraint
    /// violation a step may leave.
    pub increment_tolerance: f64,
    /// Residual tolerance relative to the largest force of the step: 1e-8 (not settable).
    pub residual_tolerance: f64,
    /// Newton iterations per step before the step is halved, >= 1. Default 25.
    pub max_iterations: usize,
    /// How many times a failing step is halved before the run fails: [`HALVINGS`] = 3, and
    /// [`STATIC_HALVINGS`] = 4 for statics (not settable).
    pub max_halvings: usize,
    /// How the iteration matrix is kept. Default full ([`NewtonMode::Full`]).
    pub newton: NewtonMode,
}

impl Default for Settings {
    /// The defaults, with 1,000 steps of 1 ms (a `solve` block always gives its own time).
    fn default() -> Settings {
        Settings {
            method: Method::Hht,
            alpha: ALPHA.default,
            rho_inf: RHO_INF.default,
            rotations: Rotations::Incremental,
            dt: 1e-3,
            steps: 1000,
            until: 1.0,
            every: 1,
            start: Start::Consistent,
            increment_tolerance: TOLERANCE_DEFAULT,
            residual_tolerance: RESIDUAL_TOLERANCE,
            max_iterations: MAX_ITERATIONS_DEFAULT,
            max_halvings: HALVINGS,
            newton: NewtonMode::Full,
        }
    }
}

/// One setting, as a `solve` block and the command line name it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    Method,
    Alpha,
    RhoInf,
    Rotations,
    Dt,
    Steps,
    Until,
    Every,
    Start,
    Tolerance,
    MaxIterations,
    Newton,
}

/// What a setting's value is, for the model stage to evaluate it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A time [s].
    Time,
    /// A dimensionless number.
    Number,
    /// A whole number of at least 1.
    Count,
    /// One of the named options.
    Choice,
}

impl Field {
    /// The settings a `solve` block's properties may give (the method is its header).
    pub const IN_BLOCK: [Field; 11] = [
        Field::Alpha,
        Field::RhoInf,
        Field::Rotations,
        Field::Dt,
        Field::Steps,
        Field::Until,
        Field::Every,
        Field::Start,
        Field::Tolerance,
        Field::MaxIterations,
        Field::Newton,
    ];

    /// The property's name in a `solve` block.
    pub fn key(self) -> &'static str {
        match self {
            Field::Method => "method",
            Field::Alpha => "alpha",
            Field::RhoInf => "rho_inf",
            Field::Rotations => "rotations",
            Field::Dt => "dt",
            Field::Steps => "steps",
            Field::Until => "until",
            Field::Every => "every",
            Field::Start => "start",
            Field::Tolerance => "tolerance",
            Field::MaxIterations => "max_iterations",
            Field::Newton => "newton",
        }
    }

    /// The command-line flag.
    pub fn flag(self) -> &'static str {
        match self {
            Field::Method => "--integrator",
            Field::Alpha => "--alpha",
            Field::RhoInf => "--rho-inf",
            Field::Rotations => "--rotations",
            Field::Dt => "--dt",
            Field::Steps => "--steps",
            Field::Until => "--until",
            Field::Every => "--every",
            Field::Start => "--start",
            Field::Tolerance => "--tolerance",
            Field::MaxIterations => "--max-iterations",
            Field::Newton => "--newton",
        }
    }

    pub fn kind(self) -> Kind {
        match self {
            Field::Method | Field::Rotations | Field::Start | Field::Newton => Kind::Choice,
            Field::Dt | Field::Until => Kind::Time,
            Field::Alpha | Field::RhoInf | Field::Tolerance => Kind::Number,
            Field::Steps | Field::Every | Field::MaxIterations => Kind::Count,
        }
    }
}

/// Settings as a `solve` block or the command line asked for them: `None` where nothing was
/// said. Values in SI units.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Request {
    pub method: Option<Method>,
    pub alpha: Option<f64>,
    pub rho_inf: Option<f64>,
    pub rotations: Option<Rotations>,
    pub dt: Option<f64>,
    pub steps: Option<usize>,
    pub until: Option<f64>,
    pub every: Option<usize>,
    pub start: Option<Start>,
    pub tolerance: Option<f64>,
    pub max_iterations: Option<usize>,
    pub newton: Option<NewtonMode>,
}

/// A setting's value that is out of its range.
#[derive(Clone, Debug, PartialEq)]
pub struct Invalid {
    pub field: Field,
    pub value: f64,
}

impl Invalid {
    /// The message for a command-line flag (a usage error).
    pub fn flag_message(&self) -> String {
        let (flag, v) = (self.field.flag(), self.value);
        match self.field {
            Field::Alpha => format!("{flag} {v} is outside {}", ALPHA.text),
            Field::RhoInf => format!("{flag} {v} is outside {}", RHO_INF.text),
            Field::Dt | Field::Until => {
                format!("{flag} must be a positive number of seconds, got {v}")
            }
            Field::Tolerance => format!("{flag} {v} is outside (0, {TOLERANCE_MAX})"),
            _ => format!("{flag} must be at least 1, got {v}"),
        }
    }

    /// The diagnostic for a value written in a `solve` block at `span`.
    pub fn diagnostic(&self, span: Span) -> Diagnostic {
        let (name, v) = (self.field.key(), self.value);
        let d = match self.field {
            Field::Alpha => Diagnostic::error(
                Code::E0213,
                format!("HHT alpha = {v} is outside {}", ALPHA.text),
            )
            .at(span, "out of range")
            .hint("alpha = -0.1 is the usual choice; 0 adds no numerical dissipation, -1/3 the most"),
            Field::RhoInf => Diagnostic::error(
                Code::E0213,
                format!("rho_inf = {v} is outside {}", RHO_INF.text),
            )
            .at(span, "out of range")
            .hint("rho_inf is the spectral radius at infinite frequency: 1 adds no dissipation, 0 the most; 0.8 is usual"),
            Field::Dt | Field::Until => {
                Diagnostic::error(Code::E0213, format!("`{name}` must be positive"))
                    .at(span, "not positive")
                    .hint("times are positive durations, e.g. `dt = 0.005 s`")
            }
            Field::Tolerance => {
                Diagnostic::error(Code::E0213, "`tolerance` must lie in (0, 0.01)")
                    .at(span, "out of range")
                    .hint("the default 1e-10 is right for most models")
            }
            _ => Diagnostic::error(
                Code::E0213,
                format!("`{name}` must be a whole number of at least 1"),
            )
            .at(span, "not allowed here")
            .hint("write an integer such as 1"),
        };
        d
    }
}

impl Request {
    /// Every value that is out of its range.
    pub fn check(&self) -> Vec<Invalid> {
        let mut bad = Vec::new();
        let mut real = |field, v: Option<f64>, ok: &dyn Fn(f64) -> bool| {
            if let Some(v) = v.filter(|&v| !ok(v)) {
                bad.push(Invalid { field, value: v });
            }
        };
        let positive = |v: f64| v > 0.0 && v.is_finite();
        real(Field::Alpha, self.alpha, &|v| ALPHA.contains(v));
        real(Field::RhoInf, self.rho_inf, &|v| RHO_INF.contains(v));
        real(Field::Dt, self.dt, &positive);
        real(Field::Until, self.until, &positive);
        real(Field::Tolerance, self.tolerance, &|v| {
            v > 0.0 && v < TOLERANCE_MAX
        });
        for (field, n) in [
            (Field::Steps, self.steps),
            (Field::Every, self.every),
            (Field::MaxIterations, self.max_iterations),
        ] {
            if let Some(n) = n.filter(|&n| n == 0 || n > COUNT_MAX) {
                bad.push(Invalid {
                    field,
                    value: n as f64,
                });
            }
        }
        bad
    }

    /// Sets a named option from the word a `solve` block wrote (`None`: not a word), or says
    /// why it is none of the options.
    pub fn choose(
        &mut self,
        field: Field,
        word: Option<&str>,
        span: Span,
    ) -> Result<(), Diagnostic> {
        let w = word.unwrap_or("");
        let known = match field {
            Field::Method => Method::parse(w).map(|m| self.method = Some(m)),
            Field::Rotations => match w {
                "incremental" => Some(Rotations::Incremental),
                "conformal" => Some(Rotations::Conformal),
                _ => None,
            }
            .map(|r| self.rotations = Some(r)),
            Field::Start => match w {
                "consistent" => Some(Start::Consistent),
                "zero_acceleration" => Some(Start::ZeroAcceleration),
                _ => None,
            }
            .map(|s| self.start = Some(s)),
            Field::Newton => NewtonMode::FLAGS
                .iter()
                .find(|(n, _)| *n == w)
                .map(|(_, m)| self.newton = Some(*m)),
            _ => None,
        };
        if known.is_some() {
            return Ok(());
        }
        Err(match field {
            Field::Method => {
                let hint = match did_you_mean(w, Method::NAMES.map(|(n, _)| n)) {
                    Some(s) => format!("did you mean `{s}`? Solvers: hht, generalized_alpha, fet, static"),
                    None => "solvers: hht (HHT-alpha), generalized_alpha, fet (time finite elements), static (load steps)".to_string(),
                };
                Diagnostic::error(Code::E0211, format!("unknown solver `{w}`"))
                    .at(span, "not a solver")
                    .hint(hint)
            }
            Field::Rotations => Diagnostic::error(Code::E0211, "unknown rotation treatment").at(span, "not a rotation treatment").hint("`rotations = incremental` (default: stored rotations, incremental parameters) or `rotations = conformal` (the paper's total conformal rotation vector, rescaled past pi)"),
            Field::Newton => Diagnostic::error(Code::E0211, "unknown Newton mode").at(span, "not a Newton mode").hint("`newton = full` (default: a new matrix every iteration), `newton = modified` (kept while Newton contracts twofold an iteration) or `newton = auto` (kept while it contracts fivefold, where that costs less)"),
            _ => Diagnostic::error(Code::E0211, "unknown start").at(span, "not a start option").hint("`start = consistent` (default) or `start = zero_acceleration` (the paper's start)"),
        })
    }

    /// Sets a number (`Kind::Time` or `Kind::Number`) or a count (`Kind::Count`, given as a
    /// whole number).
    pub fn set(&mut self, field: Field, value: f64) {
        let count = Some(value as usize);
        match field {
            Field::Alpha => self.alpha = Some(value),
            Field::RhoInf => self.rho_inf = Some(value),
            Field::Dt => self.dt = Some(value),
            Field::Until => self.until = Some(value),
            Field::Tolerance => self.tolerance = Some(value),
            Field::Steps => self.steps = count,
            Field::Every => self.every = count,
            Field::MaxIterations => self.max_iterations = count,
            Field::Method | Field::Rotations | Field::Start | Field::Newton => {}
        }
    }

    /// This request with `over`'s values laid on top. A time step and a step count replace
    /// each other.
    pub fn overlaid(&self, over: &Request) -> Request {
        let (dt, steps) = match (over.dt, over.steps) {
            (None, None) => (self.dt, self.steps),
            (dt, steps) => (dt, steps),
        };
        Request {
            method: over.method.or(self.method),
            alpha: over.alpha.or(self.alpha),
            rho_inf: over.rho_inf.or(self.rho_inf),
            rotations: over.rotations.or(self.rotations),
            dt,
            steps,
            until: over.until.or(self.until),
            every: over.every.or(self.every),
            start: over.start.or(self.start),
            tolerance: over.tolerance.or(self.tolerance),
            max_iterations: over.max_iterations.or(self.max_iterations),
            newton: over.newton.or(self.newton),
        }
    }
}

/// What a model's `solve` block wrote, as the model stage evaluated it, and where.
#[derive(Clone, Debug, Serialize)]
pub struct Written {
    #[serde(skip)]
    pub request: Request,
    /// Where each setting was written.
    #[serde(skip)]
    pub spans: Vec<(Field, Span)>,
    /// The block (or, without one, the model's header).
    pub span: Span,
    /// Whether the file has a `solve` block.
    pub present: bool,
}

impl Written {
    fn span_of(&self, field: Field) -> Span {
        self.spans
            .iter()
            .find(|(f, _)| *f == field)
            .map_or(self.span, |(_, s)| *s)
    }
}

/// Most steps a run may take: at a few microseconds a step, hours of CPU.
pub const MAX_STEPS: usize = 1_000_000_000;

impl Settings {
    /// The settings of a run: the command line's request laid over the `solve` block's, the
    /// defaults filled in, every value checked. Errors are coded diagnostics at the values
    /// the file wrote (the command line is checked by its parser first, with
    /// [`Request::check`]).
    pub fn resolve(file: &Written, cli: &Request) -> Result<Settings, Vec<Diagnostic>> {
        let mut errors: Vec<Diagnostic> = file
            .request
            .check()
            .iter()
            .map(|i| i.diagnostic(file.span_of(i.field)))
            .chain(cli.check().iter().map(|i| {
                Diagnostic::error(Code::E0213, i.flag_message())
                    .at(file.span, "for this solve")
                    .hint("see `mbd run --help` for the ranges")
            }))
            .collect();
        if !file.present && (cli.until.is_none() || (cli.dt.is_none() && cli.steps.is_none())) {
            errors.push(
                Diagnostic::error(Code::E0229, "the model has no `solve` block")
                    .at(file.span, "this model has no `solve` block")
                    .hint("add one at the top level of the model file, e.g. `solve hht { dt = 1 ms, until = 1 s }`: the method, the time step and the end time"),
            );
            return Err(errors);
        }
        if !errors.is_empty() {
            return Err(errors);
        }
        let r = file.request.overlaid(cli);
        let missing = |prop: &str, example: &str| {
            vec![
                Diagnostic::error(Code::E0206, format!("the solve block needs `{prop}`"))
                    .at(file.span, format!("`{prop}` missing"))
                    .hint(format!("add `{prop} = {example}`")),
            ]
        };
        let until = r.until.ok_or_else(|| missing("until", "1 s"))?;
        let count = match (r.dt, r.steps) {
            (_, Some(n)) => n as f64,
            // The last step is shortened by at most round-off: dt is rounded to fit `until`.
            (Some(d), None) => (until / d - 1e-9).ceil().max(1.0),
            (None, None) => return Err(missing("dt", "0.005 s")),
        };
        if count > MAX_STEPS as f64 {
            let field = if r.steps.is_some() {
                Field::Steps
            } else {
                Field::Dt
            };
            return Err(vec![Diagnostic::error(
                Code::E0230,
                format!("the run takes {count:.3e} steps: more than {MAX_STEPS:.0e}, so it cannot finish"),
            )
            .at(file.span_of(field), "the step for this end time")
            .hint(format!(
                "lengthen the step or shorten `until` (now {until} s) so the run takes at most {MAX_STEPS:.0e} steps; `mbd run --dt` and `--until` override the solve block"
            ))]);
        }
        let steps = count as usize;
        let dt = until / count;
        let method = r.method.unwrap_or_default();
        Ok(Settings {
            method,
            alpha: r.alpha.unwrap_or(ALPHA.default),
            rho_inf: r.rho_inf.unwrap_or(RHO_INF.default),
            rotations: r.rotations.unwrap_or_default(),
            dt,
            steps,
            until,
            every: r.every.unwrap_or(1),
            start: r.start.unwrap_or_default(),
            increment_tolerance: r.tolerance.unwrap_or(TOLERANCE_DEFAULT),
            residual_tolerance: RESIDUAL_TOLERANCE,
            max_iterations: r.max_iterations.unwrap_or(MAX_ITERATIONS_DEFAULT),
            max_halvings: if method == Method::Static {
                STATIC_HALVINGS
            } else {
                HALVINGS
            },
            newton: r.newton.unwrap_or_default(),
        })
    }

    /// These settings over `duration` seconds in a whole number of steps no longer than
    /// `dt` (Floquet's period), started consistently.
    pub fn over(&self, duration: f64) -> Settings {
        let steps = ((duration / self.dt) * (1.0 - 1e-12)).ceil().max(1.0) as usize;
        Settings {
            dt: duration / steps as f64,
            steps,
            until: duration,
            start: Start::Consistent,
            ..self.clone()
        }
    }

    /// These settings ending at the first step at or after `t`, if that is sooner (Prony's
    /// window), written every `every` steps.
    pub fn ending_by(&self, t: f64, every: usize) -> Settings {
        let need = ((t / self.dt) * (1.0 - 1e-12)).ceil().max(1.0) as usize;
        let mut s = Settings {
            every,
            ..self.clone()
        };
        if need < s.steps {
            s.steps = need;
            s.until = need as f64 * s.dt;
        }
        s
    }
}

#[cfg(test)]
mod tests;
