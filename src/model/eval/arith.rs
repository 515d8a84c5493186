//! Arithmetic on values: `+ - * / ^` with dimension checking, rotations composing and acting
//! on vectors, constants folded. Contract: one operator on two evaluated values; must not
//! evaluate expressions or know names.

use super::units::Dim;
use super::value::mat_mul;
use super::{same_dim, scalar_parts, Value};
use crate::diagnostics::{Code, Diagnostic};
use crate::runtime::timefn::{Binary, TimeFn, Unary};
use crate::source::Span;
use crate::syntax::ast::BinOp;

/// Folds constant operands; builds a tree otherwise.
pub(super) fn fold(op: Binary, a: TimeFn, b: TimeFn) -> TimeFn {
    if let (Some(x), Some(y)) = (a.as_constant(), b.as_constant()) {
        let v = match op {
            Binary::Add => x + y,
            Binary::Sub => x - y,
            Binary::Mul => x * y,
            Binary::Div => x / y,
            Binary::Atan2 => x.atan2(y),
            Binary::Min => x.min(y),
            Binary::Max => x.max(y),
        };
        return TimeFn::constant(v);
    }
    TimeFn::binary(op, a, b)
}

pub(super) fn unary(op: Unary, a: TimeFn) -> TimeFn {
    if let Some(x) = a.as_constant() {
        return TimeFn::constant(
            TimeFn::Unary {
                op,
                arg: Box::new(TimeFn::constant(x)),
            }
            .eval(0.0),
        );
    }
    TimeFn::Unary {
        op,
        arg: Box::new(a),
    }
}

pub(super) fn binary(
    op: BinOp,
    a: Value,
    b: Value,
    ls: Span,
    rs: Span,
    span: Span,
) -> Result<Value, Diagnostic> {
    if let Some(r) = rotations(op, &a, &b, rs, span) {
        return r;
    }
    let (pa, da) = a.parts().unwrap_or_default();
    let (pb, db) = b.parts().unwrap_or_default();
    match op {
        BinOp::Add | BinOp::Sub => add(op, (&a, pa, da), (&b, pb, db), (ls, rs, span)),
        BinOp::Mul => {
            let parts: Vec<TimeFn> = match (pa.len(), pb.len()) {
                (1, _) => pb
                    .into_iter()
                    .map(|y| fold(Binary::Mul, pa[0].clone(), y))
                    .collect(),
                (_, 1) => pa
                    .into_iter()
                    .map(|x| fold(Binary::Mul, x, pb[0].clone()))
                    .collect(),
                _ => {
                    return Err(Diagnostic::error(
                        Code::E0209,
                        "cannot multiply two vectors with `*`",
                    )
                    .at(span, "here")
                    .hint("use `dot(a, b)` or `cross(a, b)`, or scale a vector by a scalar"))
                }
            };
            Ok(Value::from_parts(parts, da.times(db)))
        }
        BinOp::Div => divide((pa, da), (&b, pb, db), rs),
        BinOp::Pow => power(&a, b, ls, rs),
    }
}

/// Rotations compose and act on vectors; `None` if neither operand is a rotation.
fn rotations(
    op: BinOp,
    a: &Value,
    b: &Value,
    rs: Span,
    span: Span,
) -> Option<Result<Value, Diagnostic>> {
    Some(match (a, b, op) {
        (Value::Rotation { matrix: r }, Value::Rotation { matrix: q }, BinOp::Mul) => {
            Ok(Value::Rotation {
                matrix: mat_mul(*r, *q),
            })
        }
        (Value::Rotation { matrix: r }, v, BinOp::Mul) => {
            let (p, d) = v.parts().unwrap_or_default();
            if p.len() != 3 {
                return Some(Err(Diagnostic::error(
                    Code::E0209,
                    "a rotation multiplies a vector",
                )
                .at(rs, format!("this is {}", v.kind_name()))
                .hint("write `rotate(axis, angle) * (x, y, z)`")));
            }
            let rows = (0..3)
                .map(|i| {
                    (0..3).fold(TimeFn::constant(0.0), |acc, k| {
                        fold(
                            Binary::Add,
                            acc,
                            fold(Binary::Mul, TimeFn::constant(r[i][k]), p[k].clone()),
                        )
                    })
                })
                .collect();
            Ok(Value::from_parts(rows, d))
        }
        (Value::Rotation { .. }, _, _) | (_, Value::Rotation { .. }, _) => Err(Diagnostic::error(
            Code::E0209,
            "a rotation can only multiply a vector or another rotation",
        )
        .at(span, "here")
        .hint("write `rotate(axis, angle) * (x, y, z)`")),
        _ => return None,
    })
}

type Operand<'a> = (&'a Value, Vec<TimeFn>, Dim);

fn add(
    op: BinOp,
    (a, pa, da): Operand,
    (b, pb, db): Operand,
    (ls, rs, span): (Span, Span, Span),
) -> Result<Value, Diagnostic> {
    let word = if op == BinOp::Add { "add" } else { "subtract" };
    same_dim(da, db, word, ls, rs)?;
    if pa.len() != pb.len() {
        return Err(Diagnostic::error(
            Code::E0209,
            format!("cannot {word} {} and {}", a.kind_name(), b.kind_name()),
        )
        .at(span, "here")
        .hint("add vectors to vectors and scalars to scalars"));
    }
    let o = if op == BinOp::Add {
        Binary::Add
    } else {
        Binary::Sub
    };
    let parts = pa.into_iter().zip(pb).map(|(x, y)| fold(o, x, y)).collect();
    Ok(Value::from_parts(parts, da))
}

fn divide(
    (pa, da): (Vec<TimeFn>, Dim),
    (b, pb, db): Operand,
    rs: Span,
) -> Result<Value, Diagnostic> {
    if pb.len() != 1 {
        return Err(
            Diagnostic::error(Code::E0209, "the divisor must be a scalar")
                .at(rs, format!("this is {}", b.kind_name()))
                .hint("divide by a scalar"),
        );
    }
    if pb[0].as_constant() == Some(0.0) {
        return Err(Diagnostic::error(Code::E0213, "division by zero")
            .at(rs, "this is zero")
            .hint("check the params this divisor uses"));
    }
    let parts = pa
        .into_iter()
        .map(|x| fold(Binary::Div, x, pb[0].clone()))
        .collect();
    Ok(Value::from_parts(parts, da.over(db)))
}

fn power(a: &Value, b: Value, ls: Span, rs: Span) -> Result<Value, Diagnostic> {
    let (x, d) = scalar_parts(a, ls, "`^`")?;
    let p = match b {
        Value::Scalar { value, dim } if dim.is_none() => value,
        _ => {
            return Err(Diagnostic::error(
                Code::E0202,
                "an exponent must be a dimensionless constant",
            )
            .at(rs, format!("this is {}", b.kind_name()))
            .hint("write a plain number such as `^2`"))
        }
    };
    if !d.is_none() && (p.fract() != 0.0 || p.abs() > 16.0) {
        return Err(Diagnostic::error(
            Code::E0202,
            "a dimensional quantity can only be raised to a small integer power",
        )
        .at(rs, "not an integer")
        .hint("use `sqrt` for square roots of dimensional quantities"));
    }
    let dim = if d.is_none() { d } else { d.powi(p as i32) };
    let f = match x.as_constant() {
        Some(c) if d.is_none() => TimeFn::constant(c.powf(p)),
        Some(c) => TimeFn::constant(c.powi(p as i32)),
        None => TimeFn::Pow {
            arg: Box::new(x),
            exponent: p,
        },
    };
    Ok(Value::from_parts(vec![f], dim))
}
