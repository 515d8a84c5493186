//! `mbd check`: a model's summary, or one stage of its compilation (`--emit`); a library
//! file's components. Exit 1 when the model has errors.

use super::{compile_linted, read_as, report, say, Format, FsLoader, EXIT_MODEL};
use clap::ValueEnum;
use mbd::settings::Request;
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct CheckArgs {
    model: String,
    #[arg(long, value_enum, default_value = "human")]
    format: Format,
    /// Print a stage instead of the summary.
    #[arg(long, value_enum)]
    emit: Option<Emit>,
    #[arg(long = "set", value_name = "NAME=VALUE")]
    set: Vec<String>,
}

#[derive(Clone, Copy, ValueEnum)]
enum Emit {
    Ast,
    Model,
    Dofs,
    #[value(alias = "system")]
    Ir,
}

pub fn check(a: CheckArgs) -> ExitCode {
    let (path, format, sets) = (a.model.as_str(), a.format, a.set.as_slice());
    let text = match read_as(path, format) {
        Ok(t) => t,
        Err(code) => return code,
    };
    if mbd::is_library(&text) {
        return library(path, &text, format);
    }
    let (c, lint) = match compile_linted(path, &text, sets, Request::default(), format) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let json = |v: Result<String, serde_json::Error>| {
        v.unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    };
    let out = match a.emit {
        Some(Emit::Ast) => json(serde_json::to_string_pretty(&c.ast)),
        Some(Emit::Model) => json(serde_json::to_string_pretty(&c.model)),
        Some(Emit::Dofs) => json(serde_json::to_string_pretty(&c.model.dofs)),
        Some(Emit::Ir) => json(serde_json::to_string_pretty(&c.lowered.system)),
        None => summary(&c, &lint, format),
    };
    say(&out);
    ExitCode::SUCCESS
}

fn summary(c: &mbd::Compiled, lint: &mbd::lint::Lint, format: Format) -> String {
    let m = &c.model;
    let n = m.dofs.len();
    let mult = m.dofs.multipliers();
    let nodes = m.bodies.len() + m.beams.iter().map(|b| b.nodes.len()).sum::<usize>();
    let columns: Vec<&str> = m.outputs.iter().map(|o| o.column.as_str()).collect();
    let nonzeros = mbd::runtime::Pattern::of(n, &c.lowered.system.elements).nnz();
    if format == Format::Json {
        return serde_json::json!({
            "model": m.name, "bodies": m.bodies.len(), "beams": m.beams.len(), "nodes": nodes,
            "joints": m.joints.len(), "dofs": n - mult - m.dofs.extras(), "extra_unknowns": m.dofs.extras(),
            "multipliers": mult, "unknowns": n, "bandwidth": m.dofs.bandwidth, "nonzeros": nonzeros,
            "channels": columns, "steps": c.settings.steps, "dt": c.settings.dt, "until": c.settings.until,
            "runnable": true, "sizing": sizing_json(lint),
        })
        .to_string();
    }
    format!(
        "model {}: ok\n{}\n  nonzeros     {}\n{}  outputs      {}\n  solve        {} steps of {} s to {} s",
        m.name,
        mbd::model::topology::report(m),
        nonzeros,
        sizing(lint),
        std::iter::once("t").chain(columns.iter().copied()).collect::<Vec<_>>().join(", "),
        c.settings.steps,
        c.settings.dt,
        c.settings.until
    )
}

/// The sizing lint's figures: the scene's band, then one line per beam.
fn sizing(lint: &mbd::lint::Lint) -> String {
    if lint.beams.is_empty() && lint.not_sized.is_none() {
        return "  sizing       no beams to size\n".into();
    }
    let mut out = format!("  sizing       scene band {:.3e} rad/s", lint.band);
    if let Some(h) = lint.dt {
        out.push_str(&format!(", step {h} s"));
    }
    out.push('\n');
    if let Some(why) = &lint.not_sized {
        out.push_str(&format!("               beams not sized: {why}\n"));
    }
    for b in &lint.beams {
        let w = b
            .omega
            .map_or("none (held by its joints)".to_string(), |w| {
                let steps = lint
                    .dt
                    .map_or(String::new(), |h| format!(", {:.2e} per step", w * h));
                format!("{w:.3e} rad/s{steps}")
            });
        out.push_str(&format!(
            "               {}{}: lowest elastic {w}, deforms {:.2e} of its length: {}\n",
            b.name,
            if b.rigid { " (rigid; as elastic)" } else { "" },
            b.deflection / b.length,
            b.verdict.label()
        ));
    }
    out
}

fn sizing_json(lint: &mbd::lint::Lint) -> serde_json::Value {
    let beams: Vec<_> = lint
        .beams
        .iter()
        .map(|b| {
            serde_json::json!({
                "beam": b.name, "rigid": b.rigid, "lowest_elastic_rad_s": b.omega,
                "deformation": b.deflection, "length": b.length, "verdict": b.verdict.label(),
            })
        })
        .collect();
    serde_json::json!({ "band_rad_s": lint.band, "dt": lint.dt, "beams": beams, "not_sized": lint.not_sized })
}

/// `mbd check` of a library file: its components.
fn library(path: &str, text: &str, format: Format) -> ExitCode {
    match mbd::check_library(path, text, &FsLoader::new()) {
        Ok((components, warnings)) => {
            report(&warnings.diagnostics, &warnings.sources, format);
            if format == Format::Json {
                say(&serde_json::json!({ "library": path, "components": components }).to_string());
            } else {
                say(&format!(
                    "library {path}: ok\n  components\n    {}",
                    components.join("\n    ")
                ));
            }
            ExitCode::SUCCESS
        }
        Err(f) => {
            report(&f.diagnostics, &f.sources, format);
            ExitCode::from(EXIT_MODEL)
        }
    }
}
