//! Evaluation of expressions with dimension checking.
//!
//! A value is a constant (scalar, 3-vector, rotation) or a signal: a scalar or vector whose
//! components are functions of time ([`TimeFn`]). Arithmetic on constants folds to constants,
//! so a signal appears only where `t` or a time function does; declarations that need a
//! constant reject signals (E0401).

use super::units::{self, Dim};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::runtime::timefn::{Binary, Outside, TimeFn, Unary};
use crate::source::Span;
use crate::syntax::ast::{BinOp, Expr, ExprKind, Ident, Path, UnitExpr, UnitOp};
use serde::Serialize;

/// A value, always in SI.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Value {
    Scalar {
        value: f64,
        dim: Dim,
    },
    Vector {
        value: [f64; 3],
        dim: Dim,
    },
    /// A rotation matrix, from `rotate(axis, angle)`.
    Rotation {
        matrix: [[f64; 3]; 3],
    },
    /// A scalar (one part) or vector (three parts) that varies in time.
    Signal {
        parts: Vec<TimeFn>,
        dim: Dim,
    },
}

impl Value {
    pub fn scalar(value: f64, dim: Dim) -> Value {
        Value::Scalar { value, dim }
    }

    pub fn dim(&self) -> Dim {
        match self {
            Value::Scalar { dim, .. } | Value::Vector { dim, .. } | Value::Signal { dim, .. } => {
                *dim
            }
            Value::Rotation { .. } => Dim::NONE,
        }
    }

    pub fn with_dim(self, dim: Dim) -> Value {
        match self {
            Value::Scalar { value, .. } => Value::Scalar { value, dim },
            Value::Vector { value, .. } => Value::Vector { value, dim },
            Value::Signal { parts, .. } => Value::Signal { parts, dim },
            r => r,
        }
    }

    pub fn kind_name(&self) -> &'static str {
        match self {
            Value::Scalar { .. } => "a scalar",
            Value::Vector { .. } => "a vector",
            Value::Rotation { .. } => "a rotation",
            Value::Signal { parts, .. } if parts.len() == 1 => "a function of time",
            Value::Signal { .. } => "a vector function of time",
        }
    }

    /// Components as time functions, with the dimension (`None` for a rotation).
    pub fn parts(&self) -> Option<(Vec<TimeFn>, Dim)> {
        match self {
            Value::Scalar { value, dim } => Some((vec![TimeFn::constant(*value)], *dim)),
            Value::Vector { value, dim } => {
                Some((value.iter().map(|x| TimeFn::constant(*x)).collect(), *dim))
            }
            Value::Signal { parts, dim } => Some((parts.clone(), *dim)),
            Value::Rotation { .. } => None,
        }
    }

    /// Builds a value from parts, folding constants.
    pub fn from_parts(parts: Vec<TimeFn>, dim: Dim) -> Value {
        let consts: Option<Vec<f64>> = parts.iter().map(|p| p.as_constant()).collect();
        match (consts, parts.len()) {
            (Some(c), 1) => Value::Scalar { value: c[0], dim },
            (Some(c), 3) => Value::Vector {
                value: [c[0], c[1], c[2]],
                dim,
            },
            _ => Value::Signal { parts, dim },
        }
    }

    fn is_finite(&self) -> bool {
        match self {
            Value::Scalar { value, .. } => value.is_finite(),
            Value::Vector { value, .. } => value.iter().all(|x| x.is_finite()),
            Value::Rotation { matrix } => matrix.iter().flatten().all(|x| x.is_finite()),
            Value::Signal { .. } => true,
        }
    }
}

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

/// Folds constant operands; builds a tree otherwise.
fn fold(op: Binary, a: TimeFn, b: TimeFn) -> TimeFn {
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

fn unary(op: Unary, a: TimeFn) -> TimeFn {
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
        ExprKind::Call { function, args } => call(function, args, expr.span, names),
        ExprKind::Piecewise { mode, knots } => piecewise(mode.as_ref(), knots, expr.span, names),
    }
}

fn is_bare_zero(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::Quantity { value, unit: None } => *value == 0.0,
        ExprKind::Neg { operand } => is_bare_zero(operand),
        _ => false,
    }
}

pub fn transpose(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = m[j][i];
        }
    }
    t
}

pub fn mat_mul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

pub fn mat_vec(a: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

/// The rotation by `angle` about the unit vector `n` (Rodrigues).
pub fn rotation(n: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let (s, c) = angle.sin_cos();
    let k = [[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]];
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let id = if i == j { 1.0 } else { 0.0 };
            r[i][j] = id * c + s * k[i][j] + (1.0 - c) * n[i] * n[j];
        }
    }
    r
}

fn binary(
    op: BinOp,
    a: Value,
    b: Value,
    ls: Span,
    rs: Span,
    span: Span,
) -> Result<Value, Diagnostic> {
    // Rotations compose and act on vectors.
    match (&a, &b, op) {
        (Value::Rotation { matrix: r }, Value::Rotation { matrix: q }, BinOp::Mul) => {
            return Ok(Value::Rotation {
                matrix: mat_mul(*r, *q),
            })
        }
        (Value::Rotation { matrix: r }, v, BinOp::Mul) => {
            let (p, d) = v.parts().unwrap_or_default();
            if p.len() != 3 {
                return Err(
                    Diagnostic::error(Code::E0209, "a rotation multiplies a vector")
                        .at(rs, format!("this is {}", v.kind_name()))
                        .hint("write `rotate(axis, angle) * (x, y, z)`"),
                );
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
            return Ok(Value::from_parts(rows, d));
        }
        (Value::Rotation { .. }, _, _) | (_, Value::Rotation { .. }, _) => {
            return Err(Diagnostic::error(
                Code::E0209,
                "a rotation can only multiply a vector or another rotation",
            )
            .at(span, "here")
            .hint("write `rotate(axis, angle) * (x, y, z)`"))
        }
        _ => {}
    }
    let (pa, da) = a.parts().unwrap_or_default();
    let (pb, db) = b.parts().unwrap_or_default();
    match op {
        BinOp::Add | BinOp::Sub => {
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
        BinOp::Div => {
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
        BinOp::Pow => {
            let (x, d) = scalar_parts(&a, ls, "`^`")?;
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
    }
}

/// The built-in functions: name, arity (min, max), description for hints.
pub const FUNCTIONS: &[(&str, usize, usize)] = &[
    ("sin", 1, 1),
    ("cos", 1, 1),
    ("tan", 1, 1),
    ("asin", 1, 1),
    ("acos", 1, 1),
    ("atan", 1, 1),
    ("atan2", 2, 2),
    ("sqrt", 1, 1),
    ("abs", 1, 1),
    ("exp", 1, 1),
    ("ln", 1, 1),
    ("min", 2, 2),
    ("max", 2, 2),
    ("norm", 1, 1),
    ("dot", 2, 2),
    ("cross", 2, 2),
    ("rotate", 2, 2),
    ("ramp", 2, 2),
    ("step", 1, 1),
    ("sine", 2, 3),
    ("constant", 1, 1),
];

fn call(
    function: &Ident,
    args: &[Expr],
    span: Span,
    names: &mut dyn Names,
) -> Result<Value, Diagnostic> {
    let name = function.name.as_str();
    // A user function `f(x)`: f with t replaced by x.
    if let Some(f) = names.function(function)? {
        if args.len() != 1 {
            return Err(Diagnostic::error(
                Code::E0210,
                format!(
                    "function `{name}` takes one argument (the time), found {}",
                    args.len()
                ),
            )
            .at(span, "here")
            .hint(format!(
                "write `{name}(t - 1 s)`, or just `{name}` for its value at the current time"
            )));
        }
        let x = eval_inner(&args[0], names)?;
        let (inner, d) = scalar_parts(&x, args[0].span, "a function's argument")?;
        if d != Dim::TIME {
            return Err(Diagnostic::error(
                Code::E0202,
                format!("`{name}` is a function of time; its argument must be a time"),
            )
            .at(args[0].span, format!("this is {}", d.describe()))
            .hint(format!("write `{name}(t - 2 s)` or `{name}(2 * t)`")));
        }
        let (parts, dim) = f.parts().unwrap_or_default();
        return Ok(Value::from_parts(
            parts.iter().map(|p| p.compose(&inner)).collect(),
            dim,
        ));
    }
    let Some(&(_, lo, hi)) = FUNCTIONS.iter().find(|(n, _, _)| *n == name) else {
        let d = Diagnostic::error(Code::E0210, format!("unknown function `{name}`"))
            .at(function.span, "not a function");
        return Err(
            match did_you_mean(name, FUNCTIONS.iter().map(|(n, _, _)| *n)) {
                Some(s) => d.hint(format!("did you mean `{s}`?")),
                None => d.hint(format!(
                    "functions: {}; declare your own with `function NAME = expression of t`",
                    FUNCTIONS.iter().map(|f| f.0).collect::<Vec<_>>().join(" ")
                )),
            },
        );
    };
    if args.len() < lo || args.len() > hi {
        let count = if lo == hi {
            format!("{lo}")
        } else {
            format!("{lo} to {hi}")
        };
        return Err(Diagnostic::error(
            Code::E0210,
            format!("`{name}` takes {count} argument(s), found {}", args.len()),
        )
        .at(span, "here")
        .hint(format!("write `{}`", usage(name))));
    }
    let vals: Vec<Value> = args
        .iter()
        .map(|a| eval_inner(a, names))
        .collect::<Result<_, _>>()?;
    let domain = |ok: bool| -> Result<(), Diagnostic> {
        if ok {
            Ok(())
        } else {
            Err(Diagnostic::error(
                Code::E0213,
                format!("`{name}` is undefined for this argument"),
            )
            .at(span, "outside the function's domain")
            .hint("check the params this argument uses"))
        }
    };
    let vector = |k: usize, this: &str| -> Result<([f64; 3], Dim), Diagnostic> {
        match &vals[k] {
            Value::Vector { value, dim } => Ok((*value, *dim)),
            v => Err(Diagnostic::error(
                Code::E0209,
                format!("`{this}` needs constant vectors, found {}", v.kind_name()),
            )
            .at(args[k].span, format!("this is {}", v.kind_name()))
            .hint(format!("write `{}`", usage(this)))),
        }
    };
    let time = |k: usize| -> Result<f64, Diagnostic> {
        let (x, d) = scalar(&vals[k], args[k].span, &format!("the argument of `{name}`"))?;
        if d != Dim::TIME {
            return Err(
                Diagnostic::error(Code::E0202, format!("`{name}` takes times"))
                    .at(args[k].span, format!("this is {}", d.describe()))
                    .hint(format!("write `{}`", usage(name))),
            );
        }
        Ok(x)
    };
    let signal = |f: TimeFn, dim: Dim| Value::from_parts(vec![f], dim);
    match name {
        "sqrt" => {
            let (x, d) = scalar_parts(&vals[0], args[0].span, "`sqrt`")?;
            let Some(dim) = d.sqrt() else {
                return Err(Diagnostic::error(
                    Code::E0202,
                    format!("cannot take the square root of {}", d.describe()),
                )
                .at(args[0].span, "odd powers of its units")
                .hint(
                    "the argument's dimension must be a perfect square, such as m^2 or m^2/s^2",
                ));
            };
            if let Some(c) = x.as_constant() {
                domain(c >= 0.0)?;
            }
            Ok(signal(unary(Unary::Sqrt, x), dim))
        }
        "abs" => {
            let (x, d) = scalar_parts(&vals[0], args[0].span, "`abs`")?;
            Ok(signal(unary(Unary::Abs, x), d))
        }
        "min" | "max" | "atan2" => {
            let (x, d) = scalar_parts(&vals[0], args[0].span, name)?;
            let (y, e) = scalar_parts(&vals[1], args[1].span, name)?;
            same_dim(
                d,
                e,
                &format!("compare in `{name}`"),
                args[0].span,
                args[1].span,
            )?;
            Ok(match name {
                "min" => signal(fold(Binary::Min, x, y), d),
                "max" => signal(fold(Binary::Max, x, y), d),
                _ => signal(fold(Binary::Atan2, x, y), Dim::NONE),
            })
        }
        "norm" => {
            let (v, d) = vector(0, "norm")?;
            Ok(Value::scalar(
                (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt(),
                d,
            ))
        }
        "dot" => {
            let ((a, d), (b, e)) = (vector(0, "dot")?, vector(1, "dot")?);
            Ok(Value::scalar(
                a[0] * b[0] + a[1] * b[1] + a[2] * b[2],
                d.times(e),
            ))
        }
        "cross" => {
            let ((a, d), (b, e)) = (vector(0, "cross")?, vector(1, "cross")?);
            Ok(Value::Vector {
                value: [
                    a[1] * b[2] - a[2] * b[1],
                    a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0],
                ],
                dim: d.times(e),
            })
        }
        "rotate" => {
            let (n, _) = vector(0, "rotate")?;
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len == 0.0 {
                return Err(Diagnostic::error(Code::E0303, "`rotate` about a zero axis")
                    .at(args[0].span, "this axis has zero length")
                    .hint("give a non-zero axis, e.g. `rotate(z, 30 deg)`"));
            }
            let (angle, d) = scalar(&vals[1], args[1].span, "the angle of `rotate`")?;
            if !d.is_none() {
                return Err(Diagnostic::error(
                    Code::E0202,
                    "the angle of `rotate` must be dimensionless",
                )
                .at(args[1].span, format!("this is {}", d.describe()))
                .hint("write an angle such as `30 deg` or `0.5 rad`"));
            }
            names.angle(&args[1], angle, "the angle of `rotate`");
            Ok(Value::Rotation {
                matrix: rotation(n.map(|x| x / len), angle),
            })
        }
        "ramp" => {
            let (t0, t1) = (time(0)?, time(1)?);
            if t1 <= t0 {
                return Err(Diagnostic::error(Code::E0402, "`ramp` must rise over a positive time")
                    .at(args[1].span, "not after the start")
                    .hint("write `ramp(start, end)` with end > start; it is 0 before start and 1 after end"));
            }
            Ok(signal(
                TimeFn::Piecewise {
                    knots: vec![(t0, 0.0), (t1, 1.0)],
                    outside: Outside::Hold,
                    arg: Box::new(TimeFn::Time),
                },
                Dim::NONE,
            ))
        }
        "step" => {
            let t0 = time(0)?;
            Ok(signal(
                TimeFn::Piecewise {
                    knots: vec![(t0, 0.0), (t0, 1.0)],
                    outside: Outside::Hold,
                    arg: Box::new(TimeFn::Time),
                },
                Dim::NONE,
            ))
        }
        "sine" => {
            let (a, d) = scalar_parts(&vals[0], args[0].span, "the amplitude of `sine`")?;
            let (w, e) = scalar(&vals[1], args[1].span, "the angular frequency of `sine`")?;
            if e != Dim::new(0, 0, -1) {
                return Err(Diagnostic::error(Code::E0202, "the angular frequency of `sine` must be a frequency")
                    .at(args[1].span, format!("this is {}", e.describe()))
                    .hint("write `sine(amplitude, omega)` with omega in rad/s, e.g. `sine(20 N, 9.26 rad/s)`; for a frequency f in Hz write `2 * pi * f`"));
            }
            let phase = match vals.get(2) {
                Some(p) => {
                    let (x, d) = scalar(p, args[2].span, "the phase of `sine`")?;
                    if !d.is_none() {
                        return Err(Diagnostic::error(
                            Code::E0202,
                            "the phase of `sine` must be an angle",
                        )
                        .at(args[2].span, format!("this is {}", d.describe()))
                        .hint("write the phase in rad or deg"));
                    }
                    names.angle(&args[2], x, "the phase of `sine`");
                    x
                }
                None => 0.0,
            };
            let arg = TimeFn::binary(
                Binary::Add,
                TimeFn::binary(Binary::Mul, TimeFn::constant(w), TimeFn::Time),
                TimeFn::constant(phase),
            );
            let s = TimeFn::Unary {
                op: Unary::Sin,
                arg: Box::new(arg),
            };
            Ok(signal(TimeFn::binary(Binary::Mul, a, s), d))
        }
        "constant" => Ok(vals[0].clone()),
        _ => {
            let x = dimensionless_fn(&vals[0], args[0].span, &format!("`{name}`"))?;
            let op = match name {
                "sin" => Unary::Sin,
                "cos" => Unary::Cos,
                "tan" => Unary::Tan,
                "asin" => Unary::Asin,
                "acos" => Unary::Acos,
                "atan" => Unary::Atan,
                "exp" => Unary::Exp,
                _ => Unary::Ln,
            };
            if let Some(c) = x.as_constant() {
                match op {
                    Unary::Asin | Unary::Acos => domain((-1.0..=1.0).contains(&c))?,
                    Unary::Ln => domain(c > 0.0)?,
                    _ => {}
                }
            }
            Ok(signal(unary(op, x), Dim::NONE))
        }
    }
}

fn usage(name: &str) -> &'static str {
    match name {
        "atan2" => "atan2(y, x)",
        "min" => "min(a, b)",
        "max" => "max(a, b)",
        "norm" => "norm((x, y, z))",
        "dot" => "dot(a, b)",
        "cross" => "cross(a, b)",
        "rotate" => "rotate(axis, angle), e.g. rotate(z, 30 deg)",
        "ramp" => "ramp(start, end), e.g. ramp(0 s, 0.5 s)",
        "step" => "step(time), e.g. step(1 s)",
        "sine" => "sine(amplitude, omega, phase), e.g. sine(20 N, 10 rad/s)",
        "constant" => "constant(value)",
        _ => "f(x)",
    }
}

fn piecewise(
    mode: Option<&Ident>,
    knots: &[(Expr, Expr)],
    span: Span,
    names: &mut dyn Names,
) -> Result<Value, Diagnostic> {
    let outside = match mode.map(|m| m.name.as_str()) {
        None | Some("hold") => Outside::Hold,
        Some("extrapolate") => Outside::Extrapolate,
        Some("periodic") => Outside::Periodic,
        Some(other) => {
            let m = mode.map(|m| m.span).unwrap_or(span);
            let hint = match did_you_mean(other, ["hold", "extrapolate", "periodic"]) {
                Some(s) => format!("did you mean `{s}`?"),
                None => "write `piecewise { ... }` (constant outside), `piecewise extrapolate { ... }` or `piecewise periodic { ... }`".to_string(),
            };
            return Err(Diagnostic::error(
                Code::E0403,
                format!("unknown piecewise mode `{other}`"),
            )
            .at(m, "not a mode")
            .hint(hint));
        }
    };
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(knots.len());
    let mut dim: Option<(Dim, Span)> = None;
    let mut last: Option<(f64, Span)> = None;
    for (te, ve) in knots {
        let (t, td) = scalar(&eval_inner(te, names)?, te.span, "a knot time")?;
        if td != Dim::TIME {
            return Err(Diagnostic::error(Code::E0202, "a knot time must be a time")
                .at(te.span, format!("this is {}", td.describe()))
                .hint("write knots as `time: value`, e.g. `5 ms: 20 N`"));
        }
        let (v, vd) = scalar(&eval_inner(ve, names)?, ve.span, "a knot value")?;
        if !is_bare_zero(ve) {
            match dim {
                None => dim = Some((vd, ve.span)),
                Some((d0, s0)) => same_dim(d0, vd, "mix in one piecewise function", s0, ve.span)?,
            }
        }
        if let Some((tp, sp)) = last {
            let twice = out.len() >= 2 && out[out.len() - 2].0 == t && tp == t;
            if t < tp || twice {
                return Err(
                    Diagnostic::error(Code::E0402, "piecewise knots out of order")
                        .at(
                            te.span,
                            if twice {
                                "a third knot at the same time"
                            } else {
                                "earlier than the knot before"
                            },
                        )
                        .at(sp, "previous knot")
                        .hint(
                            "list knots in increasing time; two knots at the same time make a jump",
                        ),
                );
            }
        }
        last = Some((t, te.span));
        out.push((t, v));
    }
    if outside == Outside::Periodic && out.len() >= 2 && out[out.len() - 1].0 <= out[0].0 {
        return Err(Diagnostic::error(
            Code::E0402,
            "a periodic piecewise function needs a positive period",
        )
        .at(span, "first and last knots at the same time")
        .hint("the period is the last knot's time minus the first's"));
    }
    Ok(Value::from_parts(
        vec![TimeFn::Piecewise {
            knots: out,
            outside,
            arg: Box::new(TimeFn::Time),
        }],
        dim.map(|d| d.0).unwrap_or(Dim::NONE),
    ))
}
