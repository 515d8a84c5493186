//! Property values of a declaration: its parts checked against its kind, its block split by
//! property, and each value evaluated as the quantity it must be (a scalar, a vector, a
//! direction, a function of time, a rotation, an integer), with the unit hint of a mismatch.
//! Contract: evaluates through the scopes' `Env`; must not build entities.

use super::{norm, Builder, View};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::model::eval::units::{Dim, Quantity};
use crate::model::eval::Value;
use crate::model::scope::env::ScopeId;
use crate::model::*;
use crate::syntax::ast::{Block, Expr, Prop, PropValue};
use std::collections::HashMap;

/// Where `span` may appear.
pub(super) const SPAN_HINT: &str = "`span` is the arc length along a beam: only a distributed load (`distributed_force`, `distributed_torque`) may depend on it";

impl Builder<'_> {
    /// Checks the parts a declaration has against those its kind takes.
    pub fn shape(
        &mut self,
        v: &View,
        markers: usize,
        on: bool,
        value: bool,
        flags: &[&str],
        example: &str,
    ) -> bool {
        let mut ok = true;
        let kind = v.kind.name.clone();
        let mut bad = |this: &mut Self, span: Span, what: String| {
            ok = false;
            this.error(
                v.scope,
                Diagnostic::error(Code::E0224, format!("`{kind}` {what}"))
                    .at(span, "here")
                    .hint(format!("write it as `{example}`")),
            );
        };
        if v.markers.len() != markers {
            let span = v.markers.first().map(|m| m.span).unwrap_or(v.name_span);
            let what = match markers {
                0 => "does not connect markers".to_string(),
                n => format!("connects {n} markers, found {}", v.markers.len()),
            };
            bad(self, span, what);
        }
        match (&v.on, on) {
            (Some(m), false) => bad(self, m.span, "takes no `on` marker".to_string()),
            (None, true) => bad(self, v.name_span, "needs `on MARKER`".to_string()),
            _ => {}
        }
        match (&v.value, value) {
            (Some(e), false) => bad(self, e.span, "takes no `= value`".to_string()),
            (None, true) => bad(self, v.name_span, "needs `= value`".to_string()),
            _ => {}
        }
        for f in &v.flags {
            if !flags.contains(&f.name.as_str()) {
                bad(self, f.span, format!("takes no flag `{}`", f.name));
            }
        }
        ok
    }

    pub fn has_flag(v: &View, flag: &str) -> bool {
        v.flags.iter().any(|f| f.name == flag)
    }

    /// Splits a block by property name, reporting unknown and repeated properties.
    pub fn props(
        &mut self,
        scope: ScopeId,
        block: Option<&Block>,
        known: &[&'static str],
        of: &str,
    ) -> HashMap<&'static str, Prop> {
        let mut out: HashMap<&'static str, Prop> = HashMap::new();
        let Some(block) = block else {
            return out;
        };
        for p in &block.props {
            match known.iter().find(|k| **k == p.name.name) {
                Some(&k) => {
                    if let Some(first) = out.get(k) {
                        let d =
                            Diagnostic::error(Code::E0203, format!("property `{k}` is set twice"))
                                .at(p.name.span, "second value")
                                .at(first.name.span, "first value")
                                .hint("set each property once");
                        self.error(scope, d);
                    } else {
                        out.insert(k, p.clone());
                    }
                }
                None => {
                    let hint = match did_you_mean(&p.name.name, known.iter().copied()) {
                        Some(s) => format!("did you mean `{s}`? {of} takes: {}", known.join(", ")),
                        None => format!("{of} takes: {}", known.join(", ")),
                    };
                    let d = Diagnostic::error(
                        Code::E0205,
                        format!("{of} has no property `{}`", p.name.name),
                    )
                    .at(p.name.span, "unknown property")
                    .hint(hint);
                    self.error(scope, d);
                }
            }
        }
        out
    }

    /// A property's expression; a `{ ... }` block where a value belongs is an error.
    pub fn expr<'p>(&mut self, scope: ScopeId, p: Option<&'p Prop>) -> Option<&'p Expr> {
        let p = p?;
        match &p.value {
            PropValue::Expr(e) => Some(e),
            PropValue::Block(b) => {
                self.error(
                    scope,
                    Diagnostic::error(
                        Code::E0209,
                        format!("`{}` takes a value, not a block", p.name.name),
                    )
                    .at(b.span, "a block")
                    .hint(format!("write `{} = value`", p.name.name)),
                );
                None
            }
        }
    }

    /// A required property's expression; reports it missing (E0206) when it is not written.
    pub fn required<'p>(
        &mut self,
        scope: ScopeId,
        p: &'p HashMap<&'static str, Prop>,
        key: &str,
        at: Span,
        of: &str,
        example: &str,
    ) -> Option<&'p Expr> {
        match p.get(key) {
            Some(prop) => self.expr(scope, Some(prop)),
            None => {
                self.missing(scope, at, key, of, example);
                None
            }
        }
    }

    pub fn missing(&mut self, scope: ScopeId, at: Span, prop: &str, of: &str, example: &str) {
        self.error(
            scope,
            Diagnostic::error(Code::E0206, format!("{of} needs `{prop}`"))
                .at(at, format!("`{prop}` missing"))
                .hint(format!("add `{prop} = {example}`")),
        );
    }

    pub fn value(&mut self, scope: ScopeId, e: &Expr) -> Option<Value> {
        match self.env.eval_in(scope, e) {
            Ok(v) => Some(v),
            Err(d) => {
                self.error(scope, d);
                None
            }
        }
    }

    /// Evaluates `e` as a constant of the given shape and dimension.
    fn typed(
        &mut self,
        scope: ScopeId,
        e: &Expr,
        want: Quantity,
        what: &str,
        vector: bool,
    ) -> Option<Value> {
        let v = self.value(scope, e)?;
        let error = match (&v, vector) {
            (Value::Signal { parts, .. }, _) if parts.iter().any(TimeFn::has_arc) => {
                Diagnostic::error(
                    Code::E0401,
                    format!("{what} must be a constant, found a function of `span`"),
                )
                .at(e.span, "this varies along a beam")
            }
            (Value::Signal { .. }, _) => Diagnostic::error(
                Code::E0401,
                format!("{what} must be a constant, found a function of time"),
            )
            .at(e.span, "this varies in time"),
            (Value::Scalar { .. }, true)
            | (Value::Vector { .. }, false)
            | (Value::Rotation { .. }, _) => {
                let shape = if vector {
                    "a vector `(x, y, z)`"
                } else {
                    "a scalar"
                };
                Diagnostic::error(
                    Code::E0209,
                    format!("{what} must be {shape}, found {}", v.kind_name()),
                )
                .at(e.span, format!("this is {}", v.kind_name()))
            }
            _ if v.dim() != want.dim => self.mismatch(scope, e, want, v.dim(), what),
            _ => return Some(v),
        };
        let hint = if v
            .parts()
            .is_some_and(|(p, _)| p.iter().any(TimeFn::has_arc))
        {
            SPAN_HINT.to_string()
        } else if let Value::Signal { .. } = v {
            "only loads, prescribed motions and functions may depend on `t`".to_string()
        } else if vector && !matches!(v, Value::Vector { .. }) {
            format!("write `(x, y, z)`; {}", unit_hint(want, vector))
        } else {
            unit_hint(want, vector)
        };
        self.error(scope, error.hint(hint));
        None
    }

    /// E0202 for `e`, found of dimension `found` where `want` is needed: at the use, and at
    /// the definition of the param or let it names.
    fn mismatch(
        &self,
        scope: ScopeId,
        e: &Expr,
        want: Quantity,
        found: Dim,
        what: &str,
    ) -> Diagnostic {
        let found = found.describe();
        let d = Diagnostic::error(
            Code::E0202,
            format!("{what} must be {}, found {found}", want.describe()),
        )
        .at(e.span, format!("this is {found}"));
        match self.env.definition(scope, e) {
            Some((span, how)) => d.at(span, format!("{how} as {found}")),
            None => d,
        }
    }

    pub fn scalar(
        &mut self,
        scope: ScopeId,
        e: &Expr,
        want: impl Into<Quantity>,
        what: &str,
    ) -> Option<f64> {
        match self.typed(scope, e, want.into(), what, false)? {
            Value::Scalar { value, .. } => Some(value),
            _ => None,
        }
    }

    pub fn vector(
        &mut self,
        scope: ScopeId,
        e: &Expr,
        want: impl Into<Quantity>,
        what: &str,
    ) -> Option<[f64; 3]> {
        match self.typed(scope, e, want.into(), what, true)? {
            Value::Vector { value, .. } => Some(value),
            _ => None,
        }
    }

    /// A non-zero direction, normalised. Any dimension is accepted (`(1, 0, 0)`, `(0, 0, 1) m`).
    pub fn direction(&mut self, scope: ScopeId, e: &Expr, what: &str) -> Option<[f64; 3]> {
        let v = self.value(scope, e)?;
        let Value::Vector { value, .. } = v else {
            self.error(
                scope,
                Diagnostic::error(
                    Code::E0209,
                    format!(
                        "{what} must be a constant direction, found {}",
                        v.kind_name()
                    ),
                )
                .at(e.span, format!("this is {}", v.kind_name()))
                .hint("write an axis such as `z` or `(0, 0, 1)`"),
            );
            return None;
        };
        let n = norm(value);
        if n == 0.0 {
            self.error(
                scope,
                Diagnostic::error(Code::E0303, format!("{what} is a zero vector"))
                    .at(e.span, "has no direction")
                    .hint("give a non-zero axis such as `z` or `(0, 0, 1)`"),
            );
            return None;
        }
        Some(value.map(|x| x / n))
    }

    /// A time function (a constant is a constant function) with the given dimension.
    pub fn signal(
        &mut self,
        scope: ScopeId,
        e: &Expr,
        want: impl Into<Quantity>,
        what: &str,
        vector: bool,
    ) -> Option<Vec<TimeFn>> {
        let want = want.into();
        let v = self.value(scope, e)?;
        let parts = v.parts();
        if !self.span_allowed {
            if let Some((p, _)) = &parts {
                if p.iter().any(TimeFn::has_arc) {
                    let d =
                        Diagnostic::error(Code::E0401, format!("{what} cannot depend on `span`"))
                            .at(e.span, "this varies along a beam")
                            .hint(SPAN_HINT);
                    self.error(scope, d);
                    return None;
                }
            }
        }
        let count = if vector { 3 } else { 1 };
        match parts {
            Some((p, d)) if p.len() == count && d == want.dim => Some(p),
            Some((p, d)) if p.len() == count => {
                let error = self.mismatch(scope, e, want, d, what);
                self.error(scope, error.hint(unit_hint(want, vector)));
                None
            }
            _ => {
                let shape = if vector {
                    "a vector (x, y, z)"
                } else {
                    "a scalar"
                };
                self.error(
                    scope,
                    Diagnostic::error(
                        Code::E0209,
                        format!("{what} must be {shape}, found {}", v.kind_name()),
                    )
                    .at(e.span, format!("this is {}", v.kind_name()))
                    .hint(unit_hint(want, vector)),
                );
                None
            }
        }
    }

    pub fn rotation(&mut self, scope: ScopeId, e: &Expr, what: &str) -> Option<Mat3> {
        match self.value(scope, e)? {
            Value::Rotation { matrix } => Some(matrix),
            v => {
                self.error(
                    scope,
                    Diagnostic::error(Code::E0209, format!("{what} must be a rotation, found {}", v.kind_name()))
                        .at(e.span, format!("this is {}", v.kind_name()))
                        .hint("write `rotate(axis, angle)`, e.g. `rotate(z, 90 deg)`, or a product of rotations"),
                );
                None
            }
        }
    }

    pub fn integer(&mut self, scope: ScopeId, e: &Expr, what: &str, min: usize) -> Option<usize> {
        let x = self.scalar(scope, e, Dim::NONE, what)?;
        if x.fract() != 0.0 || x < min as f64 || x > 1e9 {
            self.error(
                scope,
                Diagnostic::error(
                    Code::E0213,
                    format!("{what} must be a whole number of at least {min}"),
                )
                .at(e.span, "not allowed here")
                .hint(format!("write an integer such as {}", min.max(1))),
            );
            return None;
        }
        Some(x as usize)
    }
}

/// "expected a length [m], e.g. `0.5 m`" (a vector of it: "`(0, 0, 0.5) m`").
pub(in crate::model) fn unit_hint(want: Quantity, vector: bool) -> String {
    let example = match (vector, want.dim.is_none()) {
        (false, _) => want.example(),
        (true, true) => "`(1, 0, 0)`".to_string(),
        (true, false) => {
            let e = want.example();
            // `0.5 m` -> `(0, 0, 0.5) m`
            let inner = e.trim_matches('`');
            match inner.split_once(' ') {
                Some((x, unit)) => format!("`(0, 0, {x}) {unit}`"),
                None => format!("`(0, 0, {inner})`"),
            }
        }
    };
    format!("expected {}, e.g. {example}", want.describe())
}
