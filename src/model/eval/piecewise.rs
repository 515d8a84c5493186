//! `piecewise { time: value, ... }`: knots in increasing time, one dimension for the values.
//! Contract: evaluates the knots through the evaluator; must not know names.

use super::units::Dim;
use super::{eval_inner, is_bare_zero, same_dim, scalar, Names, Value};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::runtime::timefn::{Outside, TimeFn};
use crate::source::Span;
use crate::syntax::ast::{Expr, Ident};

pub(super) fn piecewise(
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
