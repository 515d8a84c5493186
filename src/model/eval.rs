//! Evaluation of constant expressions with dimension checking.

use super::units::{self, Dim};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::source::Span;
use crate::syntax::ast::{BinOp, Expr, ExprKind, UnitExpr, UnitOp};
use serde::Serialize;

/// A constant value: a scalar or a 3-vector, with its dimension. Always SI.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Value {
    Scalar { value: f64, dim: Dim },
    Vector { value: [f64; 3], dim: Dim },
}

impl Value {
    pub fn dim(&self) -> Dim {
        match self {
            Value::Scalar { dim, .. } | Value::Vector { dim, .. } => *dim,
        }
    }

    pub fn with_dim(self, dim: Dim) -> Value {
        match self {
            Value::Scalar { value, .. } => Value::Scalar { value, dim },
            Value::Vector { value, .. } => Value::Vector { value, dim },
        }
    }

    fn kind_name(&self) -> &'static str {
        match self {
            Value::Scalar { .. } => "a scalar",
            Value::Vector { .. } => "a vector",
        }
    }
}

/// Resolves a name used in an expression (params, constants).
pub trait Names {
    /// `Ok(None)` means the name is unknown.
    fn lookup(&mut self, name: &str, span: Span) -> Result<Option<Value>, Diagnostic>;
    /// Candidates for "did you mean".
    fn candidates(&self) -> Vec<String>;
}

pub fn eval(expr: &Expr, names: &mut dyn Names) -> Result<Value, Diagnostic> {
    let v = eval_inner(expr, names)?;
    let finite = match v {
        Value::Scalar { value, .. } => value.is_finite(),
        Value::Vector { value, .. } => value.iter().all(|x| x.is_finite()),
    };
    if !finite {
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

fn scalar(v: Value, span: Span, what: &str) -> Result<(f64, Dim), Diagnostic> {
    match v {
        Value::Scalar { value, dim } => Ok((value, dim)),
        Value::Vector { .. } => Err(Diagnostic::error(
            Code::E0209,
            format!("{what} needs a scalar, found a vector"),
        )
        .at(span, "this is a vector")
        .hint("take one component, or use a scalar expression")),
    }
}

fn dimensionless(v: Value, span: Span, what: &str) -> Result<f64, Diagnostic> {
    let (x, d) = scalar(v, span, what)?;
    if !d.is_none() {
        return Err(Diagnostic::error(
            Code::E0202,
            format!("{what} needs a dimensionless argument"),
        )
        .at(span, format!("this is a {}", d.describe()))
        .hint(
            "angles are plain numbers (radians); divide by a reference quantity to make a ratio",
        ));
    }
    Ok(x)
}

fn same_dim(a: Dim, b: Dim, op: &str, lspan: Span, rspan: Span) -> Result<(), Diagnostic> {
    if a != b {
        return Err(Diagnostic::error(
            Code::E0202,
            format!("cannot {op} a {} and a {}", a.describe(), b.describe()),
        )
        .at(rspan, format!("this is a {}", b.describe()))
        .at(lspan, format!("this is a {}", a.describe()))
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
            let mut out = [0.0; 3];
            let mut dim = None;
            for (k, item) in items.iter().enumerate() {
                let v = eval_inner(item, names)?;
                let (x, d) = scalar(v, item.span, "a vector component")?;
                // A bare `0` fits any dimension: `(0, -L, 0)` is a length.
                if is_bare_zero(item) {
                    continue;
                }
                match dim {
                    None => dim = Some((d, item.span)),
                    Some((d0, s0)) => same_dim(d0, d, "mix in one vector", s0, item.span)?,
                }
                out[k] = x;
            }
            let mut dim = dim.map(|d| d.0).unwrap_or(Dim::NONE);
            if let Some(u) = unit {
                let (f, d) = eval_unit(u)?;
                out.iter_mut().for_each(|x| *x *= f);
                dim = dim.times(d);
            }
            Ok(Value::Vector { value: out, dim })
        }
        ExprKind::Path { path } => {
            let text = path.text();
            if path.segments.len() == 1 {
                if let Some(v) = names.lookup(&text, path.span)? {
                    return Ok(v);
                }
            }
            let candidates = names.candidates();
            let mut d = Diagnostic::error(Code::E0201, format!("unknown name `{text}`"))
                .at(path.span, "not defined");
            d = match did_you_mean(&text, candidates.iter().map(|s| s.as_str())) {
                Some(s) => d.hint(format!("did you mean `{s}`?")),
                None if path.segments.len() > 1 => d.hint("expressions may use params and `pi`; properties of other declarations are not available here"),
                None => d.hint("declare it with `param NAME = value`"),
            };
            Err(d)
        }
        ExprKind::Neg { operand } => Ok(match eval_inner(operand, names)? {
            Value::Scalar { value, dim } => Value::Scalar { value: -value, dim },
            Value::Vector { value, dim } => Value::Vector {
                value: value.map(|x| -x),
                dim,
            },
        }),
        ExprKind::Binary { op, lhs, rhs } => {
            let a = eval_inner(lhs, names)?;
            let b = eval_inner(rhs, names)?;
            binary(*op, a, b, lhs.span, rhs.span, expr.span)
        }
        ExprKind::Call { function, args } => {
            call(&function.name, function.span, args, expr.span, names)
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

fn binary(
    op: BinOp,
    a: Value,
    b: Value,
    ls: Span,
    rs: Span,
    span: Span,
) -> Result<Value, Diagnostic> {
    use Value::*;
    match op {
        BinOp::Add | BinOp::Sub => {
            same_dim(
                a.dim(),
                b.dim(),
                if op == BinOp::Add { "add" } else { "subtract" },
                ls,
                rs,
            )?;
            let s = if op == BinOp::Add { 1.0 } else { -1.0 };
            match (a, b) {
                (Scalar { value: x, dim }, Scalar { value: y, .. }) => Ok(Scalar {
                    value: x + s * y,
                    dim,
                }),
                (Vector { value: x, dim }, Vector { value: y, .. }) => Ok(Vector {
                    value: [x[0] + s * y[0], x[1] + s * y[1], x[2] + s * y[2]],
                    dim,
                }),
                _ => Err(Diagnostic::error(
                    Code::E0209,
                    format!(
                        "cannot combine {} and {} with `+` or `-`",
                        a.kind_name(),
                        b.kind_name()
                    ),
                )
                .at(span, "here")
                .hint("add vectors to vectors and scalars to scalars")),
            }
        }
        BinOp::Mul => match (a, b) {
            (Scalar { value: x, dim: d }, Scalar { value: y, dim: e }) => Ok(Scalar {
                value: x * y,
                dim: d.times(e),
            }),
            (Scalar { value: x, dim: d }, Vector { value: y, dim: e })
            | (Vector { value: y, dim: e }, Scalar { value: x, dim: d }) => Ok(Vector {
                value: y.map(|c| c * x),
                dim: d.times(e),
            }),
            _ => Err(
                Diagnostic::error(Code::E0209, "cannot multiply two vectors with `*`")
                    .at(span, "here")
                    .hint("scale a vector by a scalar"),
            ),
        },
        BinOp::Div => {
            let (y, e) = scalar(b, rs, "the divisor")?;
            if y == 0.0 {
                return Err(Diagnostic::error(Code::E0213, "division by zero")
                    .at(rs, "this is zero")
                    .hint("check the params this divisor uses"));
            }
            Ok(match a {
                Scalar { value: x, dim } => Scalar {
                    value: x / y,
                    dim: dim.over(e),
                },
                Vector { value: x, dim } => Vector {
                    value: x.map(|c| c / y),
                    dim: dim.over(e),
                },
            })
        }
        BinOp::Pow => {
            let (x, d) = scalar(a, ls, "`^`")?;
            let p = dimensionless(b, rs, "an exponent")?;
            if d.is_none() {
                return Ok(Scalar {
                    value: x.powf(p),
                    dim: d,
                });
            }
            if p.fract() != 0.0 || p.abs() > 16.0 {
                return Err(Diagnostic::error(
                    Code::E0202,
                    "a dimensional quantity can only be raised to a small integer power",
                )
                .at(rs, "not an integer")
                .hint("use `sqrt` for square roots of dimensional quantities"));
            }
            Ok(Scalar {
                value: x.powi(p as i32),
                dim: d.powi(p as i32),
            })
        }
    }
}

fn call(
    name: &str,
    fspan: Span,
    args: &[Expr],
    span: Span,
    names: &mut dyn Names,
) -> Result<Value, Diagnostic> {
    const FUNCTIONS: &[(&str, usize)] = &[
        ("sin", 1),
        ("cos", 1),
        ("tan", 1),
        ("asin", 1),
        ("acos", 1),
        ("atan", 1),
        ("atan2", 2),
        ("sqrt", 1),
        ("abs", 1),
        ("exp", 1),
        ("ln", 1),
        ("min", 2),
        ("max", 2),
    ];
    let Some(&(_, arity)) = FUNCTIONS.iter().find(|(n, _)| *n == name) else {
        let d = Diagnostic::error(Code::E0210, format!("unknown function `{name}`"))
            .at(fspan, "not a function");
        return Err(
            match did_you_mean(name, FUNCTIONS.iter().map(|(n, _)| *n)) {
                Some(s) => d.hint(format!("did you mean `{s}`?")),
                None => {
                    d.hint("functions: sin cos tan asin acos atan atan2 sqrt abs exp ln min max")
                }
            },
        );
    };
    if args.len() != arity {
        return Err(Diagnostic::error(
            Code::E0210,
            format!("`{name}` takes {arity} argument(s), found {}", args.len()),
        )
        .at(span, "here")
        .hint(format!("write `{name}({})`", vec!["x"; arity].join(", "))));
    }
    let vals: Vec<Value> = args
        .iter()
        .map(|a| eval_inner(a, names))
        .collect::<Result<_, _>>()?;
    let domain = |ok: bool, x: f64| -> Result<f64, Diagnostic> {
        if ok {
            Ok(x)
        } else {
            Err(Diagnostic::error(
                Code::E0213,
                format!("`{name}` is undefined for this argument"),
            )
            .at(span, "outside the function's domain")
            .hint("check the params this argument uses"))
        }
    };
    let s = |v: f64| Value::Scalar {
        value: v,
        dim: Dim::NONE,
    };
    match name {
        "sqrt" => {
            let (x, d) = scalar(vals[0], args[0].span, "`sqrt`")?;
            let Some(dim) = d.sqrt() else {
                return Err(Diagnostic::error(
                    Code::E0202,
                    format!("cannot take the square root of a {}", d.describe()),
                )
                .at(args[0].span, "odd powers of its units")
                .hint(
                    "the argument's dimension must be a perfect square, such as m^2 or m^2/s^2",
                ));
            };
            Ok(Value::Scalar {
                value: domain(x >= 0.0, x)?.sqrt(),
                dim,
            })
        }
        "abs" => {
            let (x, d) = scalar(vals[0], args[0].span, "`abs`")?;
            Ok(Value::Scalar {
                value: x.abs(),
                dim: d,
            })
        }
        "min" | "max" | "atan2" => {
            let (x, d) = scalar(vals[0], args[0].span, name)?;
            let (y, e) = scalar(vals[1], args[1].span, name)?;
            same_dim(
                d,
                e,
                &format!("compare in `{name}`"),
                args[0].span,
                args[1].span,
            )?;
            Ok(match name {
                "min" => Value::Scalar {
                    value: x.min(y),
                    dim: d,
                },
                "max" => Value::Scalar {
                    value: x.max(y),
                    dim: d,
                },
                _ => s(x.atan2(y)),
            })
        }
        _ => {
            let x = dimensionless(vals[0], args[0].span, &format!("`{name}`"))?;
            Ok(s(match name {
                "sin" => x.sin(),
                "cos" => x.cos(),
                "tan" => x.tan(),
                "asin" => domain((-1.0..=1.0).contains(&x), x)?.asin(),
                "acos" => domain((-1.0..=1.0).contains(&x), x)?.acos(),
                "atan" => x.atan(),
                "exp" => x.exp(),
                _ => domain(x > 0.0, x)?.ln(),
            }))
        }
    }
}
