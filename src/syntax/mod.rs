//! Syntax: text -> typed AST with spans.
//!
//! Contract: pest is confined to this module; what leaves it is the AST of [`ast`] and
//! [`Diagnostic`]s with code E01xx. It resolves no names and evaluates nothing.

pub mod ast;
mod names;
mod parse;

pub use names::rule_name;
pub use parse::{parse_expr, parse_file, parse_rule, parse_set_arg, Rule};
