//! mbd: a compiler and runtime for the `.mbd` flexible multibody modelling language.
//!
//! The pipeline, one stage per module, data flowing one way:
//! text -> [`syntax`] (AST with spans) -> [`model`] (names, units, topology, unknown order)
//! -> [`lower`] (runtime System + provenance) -> [`solve`] over [`runtime`] -> [`output`].
//! This file is the library API: [`compile`] and [`run`]. It does no file IO of its own except
//! writing to the writer it is given.

// Numerical kernels index several arrays by one loop variable; iterators would obscure them.
#![allow(clippy::needless_range_loop)]
// Diagnostics are returned by value on cold paths only.
#![allow(clippy::result_large_err)]

pub mod channels;
pub mod diagnostics;
pub mod lint;
pub mod loader;
pub mod lower;
pub mod model;
pub mod output;
mod run;
pub mod runtime;
pub mod settings;
pub mod solve;
pub mod source;
pub mod stdlib;
pub mod study;
pub mod syntax;

pub use channels::{channel_quantity, channel_unit, param_label};
pub use run::{run, run_observed, run_values, run_with_progress, Observer, RunFailure, RunReport};

use diagnostics::{Code, Diagnostic, Sink};
use lower::Provenance;
use model::{Loader, Model, NoFiles, Overrides};
use runtime::System;
use settings::{Method, Request, Settings};
use solve::{FailureKind, RuntimeFailure};
use source::SourceMap;
use std::io::Write;

/// A compiled model: every stage's product, kept for `mbd check --emit`.
pub struct Compiled {
    pub sources: SourceMap,
    pub ast: syntax::ast::File,
    pub model: Model,
    /// The solver settings: the `solve` block with the command line's request laid over it.
    pub settings: Settings,
    /// The runtime system.
    pub lowered: Lowered,
    /// Warnings found while compiling.
    pub warnings: Vec<Diagnostic>,
}

/// The model lowered for the runtime.
pub struct Lowered {
    pub system: System,
    pub provenance: Provenance,
}

/// Compilation failed: the diagnostics (errors and warnings) and the texts they point into.
pub struct CompileFailure {
    pub sources: SourceMap,
    pub diagnostics: Vec<Diagnostic>,
}

/// Compiles model text with the built-in standard library only.
/// `sets` are the raw `NAME=VALUE` texts of `--set` flags; `solve` the command line's solver
/// settings, laid over the model's `solve` block.
pub fn compile(
    name: &str,
    text: &str,
    sets: &[String],
    solve: Request,
) -> Result<Compiled, CompileFailure> {
    compile_with(name, text, sets, solve, &NoFiles)
}

/// Compiles model text; `loader` finds the modules it `use`s outside the standard library.
pub fn compile_with(
    name: &str,
    text: &str,
    sets: &[String],
    solve: Request,
    loader: &dyn Loader,
) -> Result<Compiled, CompileFailure> {
    compile_inner(name, text, sets, solve, loader, false)
}

/// The sizing lint of a compiled model (`mbd explain W0701`): `name`, `text`, `sets`,
/// `solve` and `loader` as `c` was compiled from them, to compile its rigid beams elastic.
pub fn lint(
    c: &Compiled,
    name: &str,
    text: &str,
    sets: &[String],
    solve: Request,
    loader: &dyn Loader,
) -> lint::Lint {
    let has_rigid_beams = c.model.bodies.iter().any(|b| b.beam_axis.is_some());
    let elastic = has_rigid_beams
        .then(|| compile_inner(name, text, sets, solve, loader, true).ok())
        .flatten();
    lint::lint(c, elastic.as_ref())
}

fn compile_inner(
    name: &str,
    text: &str,
    sets: &[String],
    solve: Request,
    loader: &dyn Loader,
    elastic: bool,
) -> Result<Compiled, CompileFailure> {
    let mut overrides = Overrides {
        sets: Vec::new(),
        solve,
        elastic,
    };
    let mut sources = SourceMap::new();
    let id = sources.add(name, text);
    let mut sink = Sink::default();
    for s in sets {
        let sid = sources.add("--set", s.clone());
        match syntax::parse_set_arg(s, sid) {
            Ok(pair) => overrides.sets.push(pair),
            Err(d) => sink.push(
                d.hint("write `--set NAME=VALUE`, e.g. `--set V0=5` (SI units) or `--set V0=5m/s`"),
            ),
        }
    }
    let ast = match syntax::parse_file(text, id) {
        Ok(ast) => ast,
        Err(d) => {
            sink.push(d);
            return Err(CompileFailure {
                sources,
                diagnostics: sink.diagnostics,
            });
        }
    };
    let model = match model::build(&ast, name, &overrides, &mut sources, loader, &mut sink) {
        Some(m) if !sink.has_errors() => m,
        _ => {
            return Err(CompileFailure {
                sources,
                diagnostics: sink.diagnostics,
            })
        }
    };
    // The model stage has reported the settings' mistakes already.
    let settings = match Settings::resolve(&model.solve, &overrides.solve) {
        Ok(s) => s,
        Err(diagnostics) => {
            return Err(CompileFailure {
                sources,
                diagnostics,
            })
        }
    };
    let (system, provenance) = lower::lower(&model);
    let lowered = Lowered { system, provenance };
    Ok(Compiled {
        sources,
        ast,
        model,
        settings,
        lowered,
        warnings: sink.diagnostics,
    })
}

/// True if the text is a library of components rather than a model (no `model` header).
pub fn is_library(text: &str) -> bool {
    // Without the keyword there is no component: no need to parse the text twice.
    if !text.contains("component") {
        return false;
    }
    match syntax::parse_file(text, source::SourceId(0)) {
        Ok(f) => {
            !f.items
                .iter()
                .any(|i| matches!(i, syntax::ast::Item::Model { .. }))
                && f.items
                    .iter()
                    .any(|i| matches!(i, syntax::ast::Item::Component(_)))
        }
        Err(_) => false,
    }
}

/// Checks a library file; returns its components' signatures and any warnings.
pub fn check_library(
    name: &str,
    text: &str,
    loader: &dyn Loader,
) -> Result<(Vec<String>, CompileFailure), CompileFailure> {
    let mut sources = SourceMap::new();
    let id = sources.add(name, text);
    let mut sink = Sink::default();
    let file = match syntax::parse_file(text, id) {
        Ok(f) => f,
        Err(d) => {
            return Err(CompileFailure {
                sources,
                diagnostics: vec![d],
            })
        }
    };
    let components = model::check_library(&file, name, &mut sources, loader, &mut sink);
    let failure = CompileFailure {
        sources,
        diagnostics: sink.diagnostics,
    };
    if failure.diagnostics.iter().any(|d| d.is_error()) {
        Err(failure)
    } else {
        Ok((components, failure))
    }
}

impl Compiled {
    /// A runtime failure as a diagnostic pointing at the entity's declaration.
    pub fn failure_diagnostic(&self, f: &RuntimeFailure) -> Diagnostic {
        let (code, what, hint) = match f.kind {
            FailureKind::NewtonDiverged if self.settings.method == Method::Fet => (Code::E0601, "Newton iteration failed", "time finite elements have no numerical dissipation, and the midpoint rule is not stable for stiff beams in large motion (THEORY §8.2): use `--integrator hht` (alpha -0.1), or try a smaller time step (--dt)"),
            FailureKind::NewtonDiverged => (Code::E0601, "Newton iteration failed", "try a smaller time step (--dt), more numerical dissipation (--alpha -0.3), or check for a load or motion that is discontinuous or too large"),
            FailureKind::Singular => (Code::E0602, "singular iteration matrix", "check that every body has a positive mass and that no two joints constrain the same motion"),
            FailureKind::NonFinite => (Code::E0603, "non-finite values", "try a smaller time step (--dt); check params for extreme values"),
            FailureKind::Inconsistent => (Code::E0608, "redundant constraints inconsistent in motion", "the joints' equations depended on each other at the start but not along the motion (a singular position: a mechanism folded flat, links in line); start the model away from it, or free one of the joints (a spherical instead of a revolute)"),
            FailureKind::Interrupted => (Code::E0607, "run interrupted", "the run was stopped (Ctrl-C); the output keeps every row computed before it"),
            FailureKind::Unsupported => (Code::E0604, "integrator not available", "time finite elements integrate rotations incrementally: drop `--rotations conformal`, or use `--integrator hht` for the conformal treatment"),
        };
        let l = &self.lowered;
        let entity = f
            .entity
            .and_then(|e| l.system.entities.get(e).map(|x| (e, x)));
        let place = match entity {
            Some((_, x)) => format!("; largest residual in {} `{}`", x.kind, x.name),
            None => String::new(),
        };
        let mut d = Diagnostic::error(
            code,
            if matches!(f.kind, FailureKind::Unsupported) {
                format!("{what}: {}", f.detail)
            } else {
                format!(
                    "{what} at t = {} s (step {}){place}: {}",
                    f.t, f.step, f.detail
                )
            },
        )
        .hint(hint);
        if let Some((e, x)) = entity {
            if let Some(span) = l.provenance.spans.get(e) {
                d = d.at(*span, format!("{} `{}` declared here", x.kind, x.name));
            }
        } else {
            d = d.at(self.model.solve.span, "in this solve");
        }
        d
    }
}

/// The model's 3-D scene (`mbd view`): its parts as shapes on anchors that move with the state.
pub fn scene(c: &Compiled) -> runtime::scene::Scene {
    lower::scene(&c.model)
}

/// Modal analysis of a compiled model about its initial state (`mbd modes`): the modes by
/// increasing natural frequency. A state that is not a steady motion is refused (E0605), or
/// with `frozen` gives the frozen-time eigenvalues, marked as such in [`solve::modes::Frame`].
pub fn modes(c: &Compiled, frozen: bool) -> Result<solve::modes::Modes, Diagnostic> {
    let l = &c.lowered;
    solve::modes::modes(&l.system, &c.settings, frozen).map_err(|f| match f {
        solve::modes::ModesFailure::Runtime(f) => c.failure_diagnostic(&f),
        solve::modes::ModesFailure::Unsteady(why) => c.unsteady_diagnostic(&why),
    })
}

/// A number with at most six significant digits, no trailing zeros: `31.4`, `0.001`.
fn num6(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{}", x + 0.0);
    }
    let v: f64 = format!("{x:.5e}").parse().unwrap_or(x);
    format!("{}", v + 0.0)
}

/// A direction: `z`, `-x`, or `(0.6, 0.8, 0)`.
fn direction(v: [f64; 3]) -> String {
    for (k, name) in ["x", "y", "z"].iter().enumerate() {
        let others = (0..3).filter(|&j| j != k).all(|j| v[j].abs() < 1e-9);
        if others && (v[k].abs() - 1.0).abs() < 1e-9 {
            return format!("{}{name}", if v[k] < 0.0 { "-" } else { "" });
        }
    }
    format!("({}, {}, {})", num6(v[0]), num6(v[1]), num6(v[2]))
}

impl Compiled {
    /// E0605: why the initial state has no modes, with the entities it names.
    pub fn unsteady_diagnostic(&self, why: &solve::modes::Unsteady) -> Diagnostic {
        use solve::modes::Unsteady;
        let entity = |e: usize| {
            let l = &self.lowered;
            l.system.entities.get(e).map(|x| {
                (
                    format!("{} `{}`", x.kind, x.name),
                    l.provenance.spans.get(e).copied(),
                )
            })
        };
        let turn = |w: [f64; 3]| {
            let n = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            if n == 0.0 {
                "does not turn".to_string()
            } else {
                format!(
                    "turns at {} rad/s about {}",
                    num6(n),
                    direction([w[0] / n, w[1] / n, w[2] / n])
                )
            }
        };
        let (message, labels, hint) = match why {
            Unsteady::Spins { a, wa, b, wb } => {
                let (na, sa) = entity(*a).unzip();
                let (nb, sb) = entity(*b).unzip();
                (
                    format!(
                        "the model has no steady motion to take modes about: {} {} while {} {}; its linearized equations are periodic",
                        na.clone().unwrap_or_default(),
                        turn(*wa),
                        nb.clone().unwrap_or_default(),
                        turn(*wb)
                    ),
                    vec![(sa.flatten(), turn(*wa)), (sb.flatten(), turn(*wb))],
                    "a rotor on a non-rotating flexible structure, or several rotors, is a periodic system: use `mbd stability` (Floquet analysis over one period) for its stability; `mbd modes --frozen` gives the eigenvalues of the equations frozen at t = 0, which are not its modes",
                )
            }
            Unsteady::Velocities { entity: e, deviation } => {
                let (n, sp) = entity(*e).unzip();
                (
                    format!(
                        "the model has no steady motion to take modes about: the initial velocities are not a rigid rotation ({} moves {deviation:.3e} m/s off it)",
                        n.unwrap_or_default()
                    ),
                    vec![(sp.flatten(), "moves off the rigid rotation".to_string())],
                    "modes are taken about an equilibrium or a steady rotation: start every body at rest, or spinning together (`initial spin of ...`); `mbd modes --frozen` gives the eigenvalues of the equations frozen at t = 0",
                )
            }
            Unsteady::Accelerates {
                entity: e,
                deviation,
                angular,
            } => {
                let (n, sp) = entity(*e).unzip();
                let unit = if *angular { "rad/s^2" } else { "m/s^2" };
                (
                    format!(
                        "the model has no steady motion to take modes about: at t = 0 {} accelerates by {deviation:.3e} {unit} beyond a steady rotation (not an equilibrium)",
                        n.unwrap_or_default()
                    ),
                    vec![(sp.flatten(), format!("accelerates by {deviation:.3e} {unit}"))],
                    "modes are taken about an equilibrium or a steady rotation: start from one (the static deflection under gravity, the steady coning angle, constant drive rates), or use `mbd modes --frozen` for the eigenvalues of the equations frozen at t = 0",
                )
            }
            Unsteady::Periodic { spin, change } => (
                format!(
                    "the model has no steady motion to take modes about: it {} rigidly, but its linearized equations change by {:.1e} of their size over a turn of one radian (gravity across the spin axis, a ground-fixed spring, load or support that is not symmetric about the axis); they are periodic",
                    turn(*spin),
                    change
                ),
                Vec::new(),
                "use `mbd stability` (Floquet analysis over one period) for the stability of a periodic system; `mbd modes --frozen` gives the eigenvalues of the equations frozen at t = 0, which are not its modes",
            ),
        };
        let mut d = Diagnostic::error(Code::E0605, message).hint(hint);
        let mut any = false;
        for (span, text) in labels {
            if let Some(span) = span {
                d = d.at(span, text);
                any = true;
            }
        }
        if !any {
            d = d.at(self.model.solve.span, "the initial state of this model");
        }
        d
    }
}

/// Writes the modes table: `mode, frequency_hz, omega_rad_s, damping_ratio, real_per_s,
/// imag_rad_s, frame` (the first `count`); `frame` is `inertial`, `rotating` or `frozen`.
pub fn write_modes(
    m: &solve::modes::Modes,
    count: usize,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    writeln!(
        out,
        "mode,frequency_hz,omega_rad_s,damping_ratio,real_per_s,imag_rad_s,frame"
    )?;
    let frame = m.frame.label();
    for (i, md) in m.modes.iter().take(count).enumerate() {
        // `{:?}`: the shortest text that reads back to the same f64; `+ 0.0` drops `-0`.
        writeln!(
            out,
            "{},{:?},{:?},{:?},{:?},{:?},{frame}",
            i + 1,
            md.frequency_hz() + 0.0,
            md.omega() + 0.0,
            md.damping_ratio() + 0.0,
            md.s.re + 0.0,
            md.s.im + 0.0
        )?;
    }
    Ok(())
}

/// Writes the mode shapes: `mode, unknown, entity, kind, real, imag`, one row per unknown of
/// each mode (translations in m, rotations in rad, scaled so the largest entry is 1).
pub fn write_shapes(
    c: &Compiled,
    m: &solve::modes::Modes,
    count: usize,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    let l = &c.lowered;
    let sys = &l.system;
    writeln!(out, "mode,unknown,entity,kind,real,imag,frame")?;
    let frame = m.frame.label();
    for (i, md) in m.modes.iter().take(count).enumerate() {
        for (u, z) in md.shape.iter().enumerate() {
            let kind = match sys.unknowns[u] {
                runtime::UnknownKind::Coordinate => "coordinate".to_string(),
                runtime::UnknownKind::Rotation { axis, .. } => {
                    format!("rotation_{}", ["x", "y", "z"][axis])
                }
                _ => continue,
            };
            writeln!(
                out,
                "{},{},{},{},{:?},{:?},{frame}",
                i + 1,
                u,
                sys.entities[sys.owners[u]].name,
                kind,
                z.re + 0.0,
                z.im + 0.0
            )?;
        }
    }
    Ok(())
}
