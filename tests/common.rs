//! Helpers shared by the integration tests.

use mbd::settings::Request;
use std::path::PathBuf;

pub fn repo(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path)
}

pub fn read(path: &str) -> String {
    std::fs::read_to_string(repo(path)).unwrap_or_else(|e| panic!("cannot read {path}: {e}"))
}

/// A simulated trajectory: column names and rows.
pub struct Trace {
    pub header: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Trace {
    pub fn col(&self, name: &str) -> Vec<f64> {
        let k = self
            .header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name} in {:?}", self.header));
        self.rows.iter().map(|r| r[k]).collect()
    }
}

/// Compiles and runs a shipped model through the library API, as `mbd run` does.
pub fn simulate(model: &str, sets: &[&str], overrides: Request) -> Trace {
    let text = read(model);
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let compiled = match mbd::compile(model, &text, &sets, overrides) {
        Ok(c) => c,
        Err(f) => panic!("{model} does not compile: {:?}", f.diagnostics),
    };
    let mut out = Vec::new();
    if let Err(f) = mbd::run(&compiled, &mut out) {
        panic!("{model} failed: {}", f.diagnostic.message);
    }
    let (header, rows) =
        mbd::output::read_csv(&String::from_utf8(out).expect("utf-8 CSV")).expect("CSV");
    Trace { header, rows }
}

/// Compiles and runs model text; on a run-time failure returns the rows written before it and
/// the failure message.
pub fn simulate_text(name: &str, text: &str, overrides: Request) -> Result<Trace, (Trace, String)> {
    simulate_text_with(name, text, &[], overrides)
}

/// `simulate_text` with params set as by `--set NAME=VALUE`.
pub fn simulate_text_with(
    name: &str,
    text: &str,
    sets: &[&str],
    overrides: Request,
) -> Result<Trace, (Trace, String)> {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let compiled = match mbd::compile(name, text, &sets, overrides) {
        Ok(c) => c,
        Err(f) => panic!("{name} does not compile: {:?}", f.diagnostics),
    };
    let mut out = Vec::new();
    let failure = mbd::run(&compiled, &mut out).err();
    let (header, rows) =
        mbd::output::read_csv(&String::from_utf8(out).expect("utf-8 CSV")).expect("CSV");
    let trace = Trace { header, rows };
    match failure {
        None => Ok(trace),
        Some(f) => Err((trace, f.diagnostic.message)),
    }
}

/// Asserts `measured <= bound` (a NaN fails). With `MBD_BOUNDS=FILE` in the environment, each
/// call appends `file:line<TAB>what<TAB>measured<TAB>bound` to FILE: the table from which every
/// bound is set at about three times its measured value (written beside it).
#[track_caller]
pub fn within(what: &str, measured: f64, bound: f64) {
    let at = std::panic::Location::caller();
    record(at, what, measured, bound);
    assert!(
        measured <= bound,
        "{what}: {measured:.3e} exceeds its bound {bound:.2e} ({at})"
    );
}

/// Asserts `measured >= floor`, recorded as [`within`] records.
#[track_caller]
pub fn above(what: &str, measured: f64, floor: f64) {
    let at = std::panic::Location::caller();
    record(at, what, measured, floor);
    assert!(
        measured >= floor,
        "{what}: {measured:.3e} is below its floor {floor:.2e} ({at})"
    );
}

fn record(at: &std::panic::Location, what: &str, measured: f64, bound: f64) {
    use std::io::Write;
    if let Some(path) = std::env::var_os("MBD_BOUNDS") {
        let line = format!(
            "{}:{}\t{what}\t{measured:.3e}\t{bound:.3e}\n",
            at.file(),
            at.line()
        );
        if let Ok(mut f) = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
        {
            let _ = f.write_all(line.as_bytes());
        }
    }
}
