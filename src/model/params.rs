//! Params: evaluated lazily in dependency order, so declaration order does not matter;
//! cycles are reported, not overflowed.

use super::eval::{eval, Names, Value};
use crate::diagnostics::{Code, Diagnostic};
use crate::source::Span;
use crate::syntax::ast::Expr;
use std::collections::HashMap;

#[derive(Clone, Debug)]
enum State {
    Pending,
    InProgress,
    Done(Value),
    Failed,
}

struct Entry {
    name: String,
    span: Span,
    expr: Expr,
    /// A `--set` override, evaluated in place of `expr`.
    set: Option<Expr>,
    state: State,
    used: bool,
}

pub struct ParamTable {
    entries: Vec<Entry>,
    index: HashMap<String, usize>,
    /// Errors found while evaluating params on demand.
    pub errors: Vec<Diagnostic>,
}

impl ParamTable {
    pub fn new() -> ParamTable {
        ParamTable {
            entries: Vec::new(),
            index: HashMap::new(),
            errors: Vec::new(),
        }
    }

    /// Returns false if the name is taken.
    pub fn declare(&mut self, name: &str, span: Span, expr: Expr) -> bool {
        if self.index.contains_key(name) {
            return false;
        }
        self.index.insert(name.to_string(), self.entries.len());
        self.entries.push(Entry {
            name: name.to_string(),
            span,
            expr,
            set: None,
            state: State::Pending,
            used: false,
        });
        true
    }

    pub fn span_of(&self, name: &str) -> Option<Span> {
        self.index.get(name).map(|&i| self.entries[i].span)
    }

    pub fn set_override(&mut self, name: &str, expr: Expr) -> bool {
        match self.index.get(name) {
            Some(&i) => {
                self.entries[i].set = Some(expr);
                true
            }
            None => false,
        }
    }

    pub fn names(&self) -> Vec<String> {
        self.entries.iter().map(|e| e.name.clone()).collect()
    }

    /// Evaluates every param (reporting errors once each) and returns their values.
    pub fn evaluate_all(&mut self) -> Vec<(String, Value)> {
        let mut out = Vec::new();
        for i in 0..self.entries.len() {
            if let Some(v) = self.value(i) {
                out.push((self.entries[i].name.clone(), v));
            }
        }
        out
    }

    /// Params nothing refers to (W0201).
    pub fn unused(&self) -> Vec<(String, Span)> {
        self.entries
            .iter()
            .filter(|e| !e.used)
            .map(|e| (e.name.clone(), e.span))
            .collect()
    }

    fn value(&mut self, i: usize) -> Option<Value> {
        match self.entries[i].state.clone() {
            State::Done(v) => return Some(v),
            State::Failed => return None,
            State::InProgress => {
                let e = &self.entries[i];
                self.errors.push(
                    Diagnostic::error(Code::E0207, format!("param `{}` is defined in terms of itself", e.name))
                        .at(e.span, "this definition depends on itself")
                        .hint("break the cycle: give one of these params a value that does not refer back"),
                );
                self.entries[i].state = State::Failed;
                return None;
            }
            State::Pending => {}
        }
        self.entries[i].state = State::InProgress;
        let expr = self.entries[i].expr.clone();
        let declared = eval(&expr, self);
        let result = match (declared, self.entries[i].set.clone()) {
            (Ok(v), None) => Ok(v),
            (Err(e), _) => Err(e),
            (Ok(decl), Some(set)) => eval(&set, self).and_then(|v| match (decl, v) {
                // A bare number given with --set is read in SI units of the declared dimension.
                (_, v) if v.dim().is_none() && !decl.dim().is_none() => Ok(v.with_dim(decl.dim())),
                (_, v) if v.dim() == decl.dim() => Ok(v),
                (_, v) => Err(Diagnostic::error(
                    Code::E0202,
                    format!("`--set {}` has the wrong dimension", self.entries[i].name),
                )
                .at(set.span, format!("this is a {}", v.dim().describe()))
                .hint(format!(
                    "`{}` is a {}; give a plain number in SI units or a value with matching units",
                    self.entries[i].name,
                    decl.dim().describe()
                ))),
            }),
        };
        match result {
            Ok(v) => {
                self.entries[i].state = State::Done(v);
                Some(v)
            }
            Err(e) => {
                // A failure inside another param was reported where it happened.
                if !is_secondary(&e) {
                    self.errors.push(e);
                }
                self.entries[i].state = State::Failed;
                None
            }
        }
    }
}

/// Raised inside expression evaluation when a param failed: its error is already reported.
const FAILED_PARAM: &str = "(failed param)";

/// True for the placeholder error of a param whose own error was reported already.
pub fn is_secondary(d: &Diagnostic) -> bool {
    d.message == FAILED_PARAM
}

impl Names for ParamTable {
    fn lookup(&mut self, name: &str, span: Span) -> Result<Option<Value>, Diagnostic> {
        if name == "pi" {
            return Ok(Some(Value::Scalar {
                value: std::f64::consts::PI,
                dim: super::units::Dim::NONE,
            }));
        }
        let Some(&i) = self.index.get(name) else {
            return Ok(None);
        };
        self.entries[i].used = true;
        match self.value(i) {
            Some(v) => Ok(Some(v)),
            None => Err(Diagnostic::error(Code::E0201, FAILED_PARAM).at(span, "")),
        }
    }

    fn candidates(&self) -> Vec<String> {
        let mut c = self.names();
        c.push("pi".to_string());
        c
    }
}
