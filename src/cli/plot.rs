//! `mbd plot`: time histories of channels of a run's CSV as an SVG or PNG chart, grouped by unit
//! with `--model`.

use super::{compile, read, usage, Format};
use mbd::settings::Request;
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct PlotArgs {
    /// A CSV written by `mbd run`.
    csv: String,
    /// A channel to draw (repeat for several).
    #[arg(long = "channel", value_name = "NAME", required = true)]
    channels: Vec<String>,
    /// Write the chart here: PNG for a `.png` name, else SVG.
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
}

/// `mbd plot`: exit 0, or 2 for an unreadable CSV, an unknown channel or an unwritable file
/// (1 if `--model` has errors).
pub fn plot(a: PlotArgs) -> ExitCode {
    let (path, output) = (a.csv.as_str(), a.output.as_str());
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) => return usage(&format!("cannot read CSV file `{path}`: {e}")),
    };
    let (header, rows) = match mbd::output::read_csv(&text) {
        Ok(t) => t,
        Err(e) => return usage(&format!("`{path}` is not a CSV written by `mbd run`: {e}")),
    };
    let compiled = match a.model.as_deref().map(|m| model(m, &a.set)).transpose() {
        Ok(c) => c,
        Err(code) => return code,
    };
    let name = std::path::Path::new(path)
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| path.to_string());
    let describe = |column: &str| {
        let c = compiled.as_ref()?;
        Some((
            mbd::channel_quantity(c, column)?,
            mbd::channel_unit(c, column)?,
        ))
    };
    let title = match &compiled {
        Some(c) => format!("{}: time histories ({name})", c.model.name),
        None => name,
    };
    let charts = match mbd::output::charts::time_history(
        a.title.as_deref().unwrap_or(&title),
        &header,
        &rows,
        &a.channels,
        &describe,
    ) {
        Ok(c) => c,
        Err(e) => return usage(&e),
    };
    let bytes = match mbd::output::charts::encode(&charts, output) {
        Ok(s) => s,
        Err(e) => return usage(&format!("cannot draw the chart: {e}")),
    };
    match std::fs::write(output, bytes) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => usage(&format!("cannot create output file `{output}`: {e}")),
    }
}

/// The model that wrote the CSV (its errors exit 1).
fn model(path: &str, sets: &[String]) -> Result<mbd::Compiled, ExitCode> {
    let source = read(path)?;
    compile(path, &source, sets, Request::default(), Format::Human)
}
