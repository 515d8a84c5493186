//! The built-in functions, one table row each: its name, the arguments it takes (what each
//! must be: a ratio, a scalar, a constant vector or axis, a time, a constant of a fixed
//! dimension), the dimension of its result, its domain and how it is computed. `call` checks
//! any call against its row; user functions (`f(t - 1 s)`) are composed here too.
//! Contract: evaluates the arguments through the evaluator; must not know names beyond
//! [`Names`].

use super::arith::{fold, unary};
use super::units::Dim;
use super::value::rotation;
use super::{dimensionless_fn, eval_inner, same_dim, scalar, scalar_parts, Names, Value};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::runtime::timefn::{Binary, Outside, TimeFn, Unary};
use crate::source::Span;
use crate::syntax::ast::{Expr, Ident};

/// What an argument of a built-in must be.
#[derive(Clone, Copy)]
enum Param {
    /// A dimensionless scalar, constant or a function of time (`sin(x)`).
    Ratio,
    /// A scalar of any dimension, constant or a function of time, named `.0` in messages
    /// (empty: the function's name).
    Scalar(&'static str),
    /// A constant vector of any dimension.
    Vector,
    /// A constant vector of non-zero length (`rotate`'s axis), made a unit vector.
    Axis,
    /// A constant time.
    Time,
    /// A constant scalar of dimension `dim`; an `angle` warns when it has no unit (W0203).
    Fixed {
        what: &'static str,
        dim: Dim,
        message: &'static str,
        hint: &'static str,
        angle: bool,
    },
    /// Any value.
    Any,
}

/// The dimension of a built-in's result.
#[derive(Clone, Copy)]
enum Returns {
    /// Dimensionless.
    Ratio,
    /// The first argument's.
    First,
    /// The square root of the first argument's, which must be a perfect square.
    Root,
    /// The product of the first two arguments'.
    Product,
    /// The first two arguments must have one dimension, which the result has.
    Common,
    /// The first two arguments must have one dimension; the result is dimensionless.
    CommonRatio,
}

/// A checked argument.
enum Arg {
    Fn(TimeFn),
    Vector([f64; 3]),
    Number(f64),
    Value(Value),
}

impl Arg {
    fn f(&self) -> TimeFn {
        match self {
            Arg::Fn(f) => f.clone(),
            _ => unreachable!("the table gives a function of time"),
        }
    }

    fn vector(&self) -> [f64; 3] {
        match self {
            Arg::Vector(v) => *v,
            _ => unreachable!("the table gives a vector"),
        }
    }

    fn number(&self) -> f64 {
        match self {
            Arg::Number(x) => *x,
            _ => unreachable!("the table gives a number"),
        }
    }
}

type Apply = fn(&[Arg], Dim, &[Expr]) -> Result<Value, Diagnostic>;

/// A built-in function: its arguments (those from `required` on may be left out), the usage
/// shown in hints, its result's dimension, the domain of its first argument when constant,
/// and its value.
struct Builtin {
    name: &'static str,
    params: &'static [Param],
    required: usize,
    usage: &'static str,
    returns: Returns,
    domain: Option<fn(f64) -> bool>,
    apply: Apply,
}

const F_X: &str = "f(x)";
const RATIO: &[Param] = &[Param::Ratio];
/// Two scalars of one dimension, named by the function in messages.
const TWO_SCALARS: &[Param] = &[Param::Scalar(""), Param::Scalar("")];
const TWO_VECTORS: &[Param] = &[Param::Vector, Param::Vector];

/// A row taking all its `params`, with no domain restriction.
const fn builtin(
    name: &'static str,
    params: &'static [Param],
    usage: &'static str,
    returns: Returns,
    apply: Apply,
) -> Builtin {
    Builtin {
        name,
        params,
        required: params.len(),
        usage,
        returns,
        domain: None,
        apply,
    }
}

impl Builtin {
    /// Only the first `required` arguments must be given.
    const fn optional_from(mut self, required: usize) -> Builtin {
        self.required = required;
        self
    }

    /// A constant first argument must satisfy `ok`.
    const fn domain(mut self, ok: fn(f64) -> bool) -> Builtin {
        self.domain = Some(ok);
        self
    }
}

fn sig(f: TimeFn, dim: Dim) -> Value {
    Value::from_parts(vec![f], dim)
}

fn unary_of(op: Unary, a: &[Arg], dim: Dim) -> Result<Value, Diagnostic> {
    Ok(sig(unary(op, a[0].f()), dim))
}

fn binary_of(op: Binary, a: &[Arg], dim: Dim) -> Result<Value, Diagnostic> {
    Ok(sig(fold(op, a[0].f(), a[1].f()), dim))
}

/// The built-ins, in the order hints list them.
const BUILTINS: &[Builtin] = &[
    builtin("sin", RATIO, F_X, Returns::Ratio, |a, d, _| unary_of(Unary::Sin, a, d)),
    builtin("cos", RATIO, F_X, Returns::Ratio, |a, d, _| unary_of(Unary::Cos, a, d)),
    builtin("tan", RATIO, F_X, Returns::Ratio, |a, d, _| unary_of(Unary::Tan, a, d)),
    builtin("asin", RATIO, F_X, Returns::Ratio, |a, d, _| unary_of(Unary::Asin, a, d))
        .domain(|c| (-1.0..=1.0).contains(&c)),
    builtin("acos", RATIO, F_X, Returns::Ratio, |a, d, _| unary_of(Unary::Acos, a, d))
        .domain(|c| (-1.0..=1.0).contains(&c)),
    builtin("atan", RATIO, F_X, Returns::Ratio, |a, d, _| unary_of(Unary::Atan, a, d)),
    builtin("atan2", TWO_SCALARS, "atan2(y, x)", Returns::CommonRatio, |a, d, _| {
        binary_of(Binary::Atan2, a, d)
    }),
    builtin("sqrt", &[Param::Scalar("`sqrt`")], F_X, Returns::Root, |a, d, _| {
        unary_of(Unary::Sqrt, a, d)
    })
    .domain(|c| c >= 0.0),
    builtin("abs", &[Param::Scalar("`abs`")], F_X, Returns::First, |a, d, _| {
        unary_of(Unary::Abs, a, d)
    }),
    builtin("exp", RATIO, F_X, Returns::Ratio, |a, d, _| unary_of(Unary::Exp, a, d)),
    builtin("ln", RATIO, F_X, Returns::Ratio, |a, d, _| unary_of(Unary::Ln, a, d))
        .domain(|c| c > 0.0),
    builtin("min", TWO_SCALARS, "min(a, b)", Returns::Common, |a, d, _| {
        binary_of(Binary::Min, a, d)
    }),
    builtin("max", TWO_SCALARS, "max(a, b)", Returns::Common, |a, d, _| {
        binary_of(Binary::Max, a, d)
    }),
    builtin("norm", &[Param::Vector], "norm((x, y, z))", Returns::First, |a, d, _| {
        let v = a[0].vector();
        Ok(Value::scalar((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt(), d))
    }),
    builtin("dot", TWO_VECTORS, "dot(a, b)", Returns::Product, |a, d, _| {
        let (u, v) = (a[0].vector(), a[1].vector());
        Ok(Value::scalar(u[0] * v[0] + u[1] * v[1] + u[2] * v[2], d))
    }),
    builtin("cross", TWO_VECTORS, "cross(a, b)", Returns::Product, |a, d, _| {
        let (u, v) = (a[0].vector(), a[1].vector());
        Ok(Value::Vector {
            value: [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ],
            dim: d,
        })
    }),
    builtin(
        "rotate",
        &[
            Param::Axis,
            Param::Fixed {
                what: "the angle of `rotate`",
                dim: Dim::NONE,
                message: "the angle of `rotate` must be dimensionless",
                hint: "write an angle such as `30 deg` or `0.5 rad`",
                angle: true,
            },
        ],
        "rotate(axis, angle), e.g. rotate(z, 30 deg)",
        Returns::Ratio,
        |a, _, _| {
            Ok(Value::Rotation {
                matrix: rotation(a[0].vector(), a[1].number()),
            })
        },
    ),
    builtin(
        "ramp",
        &[Param::Time, Param::Time],
        "ramp(start, end), e.g. ramp(0 s, 0.5 s)",
        Returns::Ratio,
        ramp,
    ),
    builtin("step", &[Param::Time], "step(time), e.g. step(1 s)", Returns::Ratio, |a, d, _| {
        let t0 = a[0].number();
        Ok(sig(hold(vec![(t0, 0.0), (t0, 1.0)]), d))
    }),
    builtin(
        "sine",
        &[
            Param::Scalar("the amplitude of `sine`"),
            Param::Fixed {
                what: "the angular frequency of `sine`",
                dim: Dim::new(0, 0, -1),
                message: "the angular frequency of `sine` must be a frequency",
                hint: "write `sine(amplitude, omega)` with omega in rad/s, e.g. `sine(20 N, 9.26 rad/s)`; for a frequency f in Hz write `2 * pi * f`",
                angle: false,
            },
            Param::Fixed {
                what: "the phase of `sine`",
                dim: Dim::NONE,
                message: "the phase of `sine` must be an angle",
                hint: "write the phase in rad or deg",
                angle: true,
            },
        ],
        "sine(amplitude, omega, phase), e.g. sine(20 N, 10 rad/s)",
        Returns::First,
        sine,
    )
    .optional_from(2),
    builtin("constant", &[Param::Any], "constant(value)", Returns::Ratio, |a, _, _| {
        match &a[0] {
            Arg::Value(v) => Ok(v.clone()),
            _ => unreachable!("the table gives a value"),
        }
    }),
];

/// The names of the built-in functions, in the order hints list them.
fn builtin_names() -> impl Iterator<Item = &'static str> {
    BUILTINS.iter().map(|b| b.name)
}

fn hold(knots: Vec<(f64, f64)>) -> TimeFn {
    TimeFn::Piecewise {
        knots,
        outside: Outside::Hold,
        arg: Box::new(TimeFn::Time),
    }
}

fn ramp(a: &[Arg], d: Dim, args: &[Expr]) -> Result<Value, Diagnostic> {
    let (t0, t1) = (a[0].number(), a[1].number());
    if t1 <= t0 {
        return Err(Diagnostic::error(Code::E0402, "`ramp` must rise over a positive time")
            .at(args[1].span, "not after the start")
            .hint("write `ramp(start, end)` with end > start; it is 0 before start and 1 after end"));
    }
    Ok(sig(hold(vec![(t0, 0.0), (t1, 1.0)]), d))
}

fn sine(a: &[Arg], d: Dim, _: &[Expr]) -> Result<Value, Diagnostic> {
    let phase = a.get(2).map(Arg::number).unwrap_or(0.0);
    let arg = TimeFn::binary(
        Binary::Add,
        TimeFn::binary(Binary::Mul, TimeFn::constant(a[1].number()), TimeFn::Time),
        TimeFn::constant(phase),
    );
    let s = TimeFn::Unary {
        op: Unary::Sin,
        arg: Box::new(arg),
    };
    Ok(sig(TimeFn::binary(Binary::Mul, a[0].f(), s), d))
}

/// `name(args)`: a user function or a built-in.
pub(super) fn call(
    function: &Ident,
    args: &[Expr],
    span: Span,
    names: &mut dyn Names,
) -> Result<Value, Diagnostic> {
    if let Some(f) = names.function(function)? {
        return user(&function.name, &f, args, span, names);
    }
    let name = function.name.as_str();
    let Some(b) = BUILTINS.iter().find(|b| b.name == name) else {
        let d = Diagnostic::error(Code::E0210, format!("unknown function `{name}`"))
            .at(function.span, "not a function");
        return Err(match did_you_mean(name, builtin_names()) {
            Some(s) => d.hint(format!("did you mean `{s}`?")),
            None => d.hint(format!(
                "functions: {}; declare your own with `function NAME = expression of t`",
                builtin_names().collect::<Vec<_>>().join(" ")
            )),
        });
    };
    let (lo, hi) = (b.required, b.params.len());
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
        .hint(format!("write `{}`", b.usage)));
    }
    let vals: Vec<Value> = args
        .iter()
        .map(|a| eval_inner(a, names))
        .collect::<Result<_, _>>()?;
    let mut checked = Vec::with_capacity(vals.len());
    let mut dims = Vec::with_capacity(vals.len());
    for (k, v) in vals.into_iter().enumerate() {
        let (arg, dim) = b.check(b.params[k], v, &args[k], names)?;
        checked.push(arg);
        dims.push(dim);
    }
    let dim = b.result_dim(&dims, args)?;
    if let (Some(ok), Some(Arg::Fn(x))) = (b.domain, checked.first()) {
        if x.as_constant().is_some_and(|c| !ok(c)) {
            return Err(Diagnostic::error(
                Code::E0213,
                format!("`{name}` is undefined for this argument"),
            )
            .at(span, "outside the function's domain")
            .hint("check the params this argument uses"));
        }
    }
    (b.apply)(&checked, dim, args)
}

/// A user function `f(x)`: f with t replaced by x.
fn user(
    name: &str,
    f: &Value,
    args: &[Expr],
    span: Span,
    names: &mut dyn Names,
) -> Result<Value, Diagnostic> {
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
    Ok(Value::from_parts(
        parts.iter().map(|p| p.compose(&inner)).collect(),
        dim,
    ))
}

impl Builtin {
    /// Checks one argument against what the table says it must be.
    fn check(
        &self,
        param: Param,
        v: Value,
        e: &Expr,
        names: &mut dyn Names,
    ) -> Result<(Arg, Dim), Diagnostic> {
        let name = self.name;
        match param {
            Param::Ratio => {
                let x = dimensionless_fn(&v, e.span, &format!("`{name}`"))?;
                Ok((Arg::Fn(x), Dim::NONE))
            }
            Param::Scalar(what) => {
                let what = if what.is_empty() { name } else { what };
                let (x, d) = scalar_parts(&v, e.span, what)?;
                Ok((Arg::Fn(x), d))
            }
            Param::Vector | Param::Axis => {
                let (n, d) = self.vector(&v, e)?;
                if matches!(param, Param::Vector) {
                    return Ok((Arg::Vector(n), d));
                }
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                if len == 0.0 {
                    return Err(Diagnostic::error(Code::E0303, "`rotate` about a zero axis")
                        .at(e.span, "this axis has zero length")
                        .hint("give a non-zero axis, e.g. `rotate(z, 30 deg)`"));
                }
                Ok((Arg::Vector(n.map(|x| x / len)), d))
            }
            Param::Time => {
                let (x, d) = scalar(&v, e.span, &format!("the argument of `{name}`"))?;
                if d != Dim::TIME {
                    return Err(
                        Diagnostic::error(Code::E0202, format!("`{name}` takes times"))
                            .at(e.span, format!("this is {}", d.describe()))
                            .hint(format!("write `{}`", self.usage)),
                    );
                }
                Ok((Arg::Number(x), d))
            }
            Param::Fixed {
                what,
                dim,
                message,
                hint,
                angle,
            } => {
                let (x, d) = scalar(&v, e.span, what)?;
                if d != dim {
                    return Err(Diagnostic::error(Code::E0202, message)
                        .at(e.span, format!("this is {}", d.describe()))
                        .hint(hint));
                }
                if angle {
                    names.angle(e, x, what);
                }
                Ok((Arg::Number(x), d))
            }
            Param::Any => {
                let d = v.dim();
                Ok((Arg::Value(v), d))
            }
        }
    }

    fn vector(&self, v: &Value, e: &Expr) -> Result<([f64; 3], Dim), Diagnostic> {
        match v {
            Value::Vector { value, dim } => Ok((*value, *dim)),
            v => Err(Diagnostic::error(
                Code::E0209,
                format!(
                    "`{}` needs constant vectors, found {}",
                    self.name,
                    v.kind_name()
                ),
            )
            .at(e.span, format!("this is {}", v.kind_name()))
            .hint(format!("write `{}`", self.usage))),
        }
    }

    /// The result's dimension from the arguments' (`dims`), as the table says.
    fn result_dim(&self, dims: &[Dim], args: &[Expr]) -> Result<Dim, Diagnostic> {
        match self.returns {
            Returns::Ratio => Ok(Dim::NONE),
            Returns::First => Ok(dims[0]),
            Returns::Product => Ok(dims[0].times(dims[1])),
            Returns::Root => dims[0].sqrt().ok_or_else(|| {
                Diagnostic::error(
                    Code::E0202,
                    format!("cannot take the square root of {}", dims[0].describe()),
                )
                .at(args[0].span, "odd powers of its units")
                .hint("the argument's dimension must be a perfect square, such as m^2 or m^2/s^2")
            }),
            Returns::Common | Returns::CommonRatio => {
                same_dim(
                    dims[0],
                    dims[1],
                    &format!("compare in `{}`", self.name),
                    args[0].span,
                    args[1].span,
                )?;
                Ok(match self.returns {
                    Returns::Common => dims[0],
                    _ => Dim::NONE,
                })
            }
        }
    }
}
