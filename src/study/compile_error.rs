//! Why a job's model did not compile, as the one line a study row or a sweep point keeps.

use crate::diagnostics::Code;
use crate::CompileFailure;
use std::fmt;

/// The first error of a failed compile (`E0302 unknown name ...`), or none when the failure
/// carries no error diagnostic.
#[derive(Clone, Debug, PartialEq)]
pub enum CompileError {
    Diagnostic { code: Code, message: String },
    Unexplained,
}

impl CompileError {
    /// The first error diagnostic of `failure`.
    pub fn of(failure: &CompileFailure) -> CompileError {
        match failure.diagnostics.iter().find(|d| d.is_error()) {
            Some(d) => CompileError::Diagnostic {
                code: d.code,
                message: d.message.clone(),
            },
            None => CompileError::Unexplained,
        }
    }
}

impl fmt::Display for CompileError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            CompileError::Diagnostic { code, message } => write!(f, "{} {message}", code.as_str()),
            CompileError::Unexplained => write!(f, "the model does not compile"),
        }
    }
}

impl std::error::Error for CompileError {}
