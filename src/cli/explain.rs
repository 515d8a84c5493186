//! `mbd explain CODE`: the long text of a diagnostic code; exit 2 for an unknown code.

use super::EXIT_USAGE;
use std::process::ExitCode;

pub fn explain(code: &str) -> ExitCode {
    match mbd::diagnostics::explain(code) {
        Some(text) => {
            print!("{text}");
            ExitCode::SUCCESS
        }
        None => {
            eprintln!("error: unknown diagnostic code `{code}`");
            ExitCode::from(EXIT_USAGE)
        }
    }
}
