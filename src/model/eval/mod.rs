//! Evaluation of expressions with dimension checking.
//!
//! A value is a constant (scalar, 3-vector, rotation) or a signal: a scalar or vector whose
//! components are functions of time ([`TimeFn`]). Arithmetic on constants folds to constants,
//! so a signal appears only where `t` or a time function does; declarations that need a
//! constant reject signals (E0401).
//!
//! Contract: evaluates one expression through [`Names`]; must not know scopes, declarations or
//! entities.

pub(super) mod angles;
mod arith;
mod builtins;
mod piecewise;
pub mod units;
mod value;

pub use value::{mat_mul, mat_vec, rotation, transpose, Value};

use self::arith::{binary, fold};
use self::units::Dim;
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::runtime::timefn::{Binary, TimeFn};
use crate::source::Span;
use crate::syntax::ast::{Expr, ExprKind, Ident, Path, UnitExpr, UnitOp};

/// Resolves the names used in an expression.
pub trait Names {
    /// The value a path names (a param, a let, a loop variable, a property of a declaration,
    /// `t`, `pi`, the unit vectors `x`, `y`, `z`). Reports unknown names itself.
    fn path(&mut self, path: &Path) -> Result<Value, Diagnostic>;
    /// A user function called as `name(arg)`, if one is declared.
    fn function(&mut self, name: &Ident) -> Result<Option<Value>, Diagnostic>;
    /// `e`, of constant value `value`, is the angle of `what`: warn if it has no unit (W0203).
    fn angle(&mut self, _e: &Expr, _value: f64, _what: &str) {}
}

pub fn eval(expr: &Expr, names: &mut dyn Names) -> Result<Value, Diagnostic> {
    let v = eval_inner(expr, names)?;
    if !v.is_finite() {
        return Err(
            Diagnostic::error(Code::E0213, "this value is not a finite number")
                .at(expr.span, "evaluates to infinity or NaN")
                .hint("check for a division by zero or a number too large for double precision"),
        );
    }
    Ok(v)
}

fn eval_unit(u: &UnitExpr) -> Result<(f64, Dim), Diagnostic> {
    let mut factor = 1.0;
    let mut dim = Dim::NONE;
    for f in &u.factors {
        let Some((uf, ud)) = units::lookup(&f.name.name) else {
            let names = units::UNITS.iter().map(|(n, _, _)| *n);
            let hint = match did_you_mean(&f.name.name, names) {
                Some(s) => format!("did you mean `{s}`? A unit follows its number on the same line; to multiply by a param write `{} * 2 m`", f.name.name),
                None => "known units: kg g m mm cm km s ms min h rad deg rev rpm Hz N kN J W Pa kPa MPa GPa; to multiply a quantity by a param, write the param first (`L * 2 m`)".to_string(),
            };
            return Err(
                Diagnostic::error(Code::E0204, format!("unknown unit `{}`", f.name.name))
                    .at(f.name.span, "not a unit")
                    .hint(hint),
            );
        };
        let e = match f.op {
            UnitOp::Mul => f.exponent,
            UnitOp::Div => -f.exponent,
        };
        factor *= uf.powi(e);
        dim = dim.times(ud.powi(e));
    }
    Ok((factor, dim))
}

fn scalar(v: &Value, span: Span, what: &str) -> Result<(f64, Dim), Diagnostic> {
    match v {
        Value::Scalar { value, dim } => Ok((*value, *dim)),
        Value::Signal { .. } => Err(Diagnostic::error(
            Code::E0401,
            format!("{what} must be a constant, found a function of time"),
        )
        .at(span, "this varies in time")
        .hint("only loads, prescribed motions and functions may depend on `t`")),
        other => Err(Diagnostic::error(
            Code::E0209,
            format!("{what} needs a scalar, found {}", other.kind_name()),
        )
        .at(span, format!("this is {}", other.kind_name()))
        .hint("take one component (`v.x`), or use a scalar expression")),
    }
}

fn dimensionless_fn(v: &Value, span: Span, what: &str) -> Result<TimeFn, Diagnostic> {
    let (parts, d) = scalar_parts(v, span, what)?;
    if !d.is_none() {
        return Err(Diagnostic::error(
            Code::E0202,
            format!("{what} needs a dimensionless argument"),
        )
        .at(span, format!("this is {}", d.describe()))
        .hint(
            "angles are plain numbers (radians); divide by a reference quantity to make a ratio",
        ));
    }
    Ok(parts)
}

/// A scalar argument as a time function (constants included).
fn scalar_parts(v: &Value, span: Span, what: &str) -> Result<(TimeFn, Dim), Diagnostic> {
    match v.parts() {
        Some((mut p, d)) if p.len() == 1 => Ok((p.remove(0), d)),
        _ => Err(Diagnostic::error(
            Code::E0209,
            format!("{what} needs a scalar, found {}", v.kind_name()),
        )
        .at(span, format!("this is {}", v.kind_name()))
        .hint("take one component (`v.x`), or use a scalar expression")),
    }
}

fn same_dim(a: Dim, b: Dim, op: &str, lspan: Span, rspan: Span) -> Result<(), Diagnostic> {
    if a != b {
        return Err(Diagnostic::error(
            Code::E0202,
            format!("cannot {op} {} and {}", a.describe(), b.describe()),
        )
        .at(rspan, format!("this is {}", b.describe()))
        .at(lspan, format!("this is {}", a.describe()))
        .hint(
            "both sides of `+`, `-`, `min` and `max` must have the same dimension; check the units",
        ));
    }
    Ok(())
}

fn eval_inner(expr: &Expr, names: &mut dyn Names) -> Result<Value, Diagnostic> {
    match &expr.kind {
        ExprKind::Quantity { value, unit } => {
            let (f, d) = match unit {
                Some(u) => eval_unit(u)?,
                None => (1.0, Dim::NONE),
            };
            Ok(Value::Scalar {
                value: value * f,
                dim: d,
            })
        }
        ExprKind::Vector { items, unit } => {
            if items.len() != 3 {
                return Err(Diagnostic::error(
                    Code::E0209,
                    format!("a vector needs 3 components, found {}", items.len()),
                )
                .at(expr.span, "here")
                .hint("write `(x, y, z)`"));
            }
            let mut parts = Vec::with_capacity(3);
            let mut dim = None;
            for item in items {
                let v = eval_inner(item, names)?;
                let (p, d) = scalar_parts(&v, item.span, "a vector component")?;
                // A bare `0` fits any dimension: `(0, -L, 0)` is a length.
                if !is_bare_zero(item) {
                    match dim {
                        None => dim = Some((d, item.span)),
                        Some((d0, s0)) => same_dim(d0, d, "mix in one vector", s0, item.span)?,
                    }
                }
                parts.push(p);
            }
            let mut dim = dim.map(|d| d.0).unwrap_or(Dim::NONE);
            if let Some(u) = unit {
                let (f, d) = eval_unit(u)?;
                parts = parts
                    .into_iter()
                    .map(|p| fold(Binary::Mul, p, TimeFn::constant(f)))
                    .collect();
                dim = dim.times(d);
            }
            Ok(Value::from_parts(parts, dim))
        }
        ExprKind::Path { path } => names.path(path),
        ExprKind::Neg { operand } => {
            let v = eval_inner(operand, names)?;
            match v {
                Value::Rotation { .. } => Err(Diagnostic::error(Code::E0209, "a rotation cannot be negated")
                    .at(expr.span, "`-` applied to a rotation")
                    .hint("`-` binds tighter than `*`: write `-(rotate(axis, angle) * v)` to negate the vector, or `rotate(axis, -angle)` for the inverse rotation")),
                v => {
                    let (parts, dim) = v.parts().unwrap_or_default();
                    Ok(Value::from_parts(
                        parts
                            .into_iter()
                            .map(|p| fold(Binary::Sub, TimeFn::constant(0.0), p))
                            .collect(),
                        dim,
                    ))
                }
            }
        }
        ExprKind::Binary { op, lhs, rhs } => {
            let a = eval_inner(lhs, names)?;
            let b = eval_inner(rhs, names)?;
            binary(*op, a, b, lhs.span, rhs.span, expr.span)
        }
        ExprKind::Call { function, args } => builtins::call(function, args, expr.span, names),
        ExprKind::Piecewise { mode, knots } => {
            piecewise::piecewise(mode.as_ref(), knots, expr.span, names)
        }
    }
}

fn is_bare_zero(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::Quantity { value, unit: None } => *value == 0.0,
        ExprKind::Neg { operand } => is_bare_zero(operand),
        _ => false,
    }
}
