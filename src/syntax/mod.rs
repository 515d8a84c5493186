//! Syntax: text -> typed AST with spans.
//!
//! Contract: pest is confined to this module; what leaves it is the AST of [`ast`] and
//! [`Diagnostic`]s with code E01xx. It resolves no names and evaluates nothing.

pub mod ast;
mod names;
mod parse;

pub use names::rule_name;

use crate::diagnostics::{Code, Diagnostic};
use crate::source::{SourceMap, Span};

/// A model file's bytes as text: UTF-8, a leading byte-order mark dropped. Otherwise E0104 at
/// the first bad byte, with the text decoded lossily to show it in.
pub fn decode(name: &str, bytes: Vec<u8>) -> Result<String, (Diagnostic, SourceMap)> {
    match String::from_utf8(bytes) {
        Ok(text) => Ok(match text.strip_prefix('\u{feff}') {
            Some(rest) => rest.to_string(),
            None => text,
        }),
        Err(e) => {
            let at = e.utf8_error().valid_up_to();
            let bad = e.utf8_error().error_len().unwrap_or(1);
            let mut sources = SourceMap::new();
            let id = sources.add(name, String::from_utf8_lossy(e.as_bytes()).into_owned());
            let (line, column) = sources.line_col(id, at as u32);
            let d = Diagnostic::error(
                Code::E0104,
                format!("the model file is not UTF-8 text: byte 0x{:02X} at line {line}, column {column}", e.as_bytes()[at]),
            )
            .at(Span::new(id, at, at + '\u{fffd}'.len_utf8()), format!("{bad} byte{} not UTF-8 here", if bad == 1 { "" } else { "s" }))
            .hint("save the file as UTF-8 (a `°`, `µ` or `é` from a Latin-1 editor is a common cause), or remove the character");
            Err((d, sources))
        }
    }
}
pub use parse::{parse_expr, parse_file, parse_rule, parse_set_arg, Rule};
