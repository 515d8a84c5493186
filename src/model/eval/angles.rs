//! Angles written without a unit (W0203).
//!
//! Angles are dimensionless, so `rest_angle = 3` is accepted as 3 rad though its writer probably
//! meant degrees. The rule: an angle-valued property or argument (a revolute joint's
//! `rest_angle` and prescribed `angle`, a beam's `twist`, the angle of `rotate(axis, angle)`,
//! the phase of `sine`, a component argument of type `angle`) warns when its value is not zero
//! and its expression names no angle anywhere: no `rad`, `deg` or `rev` in a unit (`rad/s`
//! counts), no `pi`, no inverse trigonometric function, also through the params, lets,
//! functions and arguments it names.
//!
//! Contract: reads expressions and the bindings they name; must not evaluate them (the caller
//! gives the value).

use super::units;
use crate::diagnostics::{Code, Diagnostic};
use crate::model::scope::env::{BindingKind, Env, Named, ScopeId};
use crate::model::scope::types::ParamType;
use crate::syntax::ast::{Expr, ExprKind, UnitExpr};

/// Units that make a number an angle.
const ANGLE_UNITS: &[&str] = &["rad", "deg", "rev"];
/// Functions whose value is an angle in radians.
const ANGLE_FUNCTIONS: &[&str] = &["asin", "acos", "atan", "atan2"];

impl Env {
    /// Whether `e` (read in `scope`) says it is an angle: a unit `rad`, `deg` or `rev`, `pi`, an
    /// inverse trigonometric function, or a name whose definition does.
    pub fn names_an_angle(&self, scope: ScopeId, e: &Expr) -> bool {
        self.angle_in(scope, e, 0)
    }

    fn angle_in(&self, scope: ScopeId, e: &Expr, depth: usize) -> bool {
        if depth > 16 {
            return true;
        }
        let unit = |u: &Option<UnitExpr>| {
            u.as_ref().is_some_and(|u| {
                u.factors
                    .iter()
                    .any(|f| ANGLE_UNITS.contains(&f.name.name.as_str()))
            })
        };
        let any = |items: &mut dyn Iterator<Item = &Expr>| {
            let mut found = false;
            for x in items {
                found = found || self.angle_in(scope, x, depth + 1);
            }
            found
        };
        match &e.kind {
            ExprKind::Quantity { unit: u, .. } => unit(u),
            ExprKind::Vector { items, unit: u } => unit(u) || any(&mut items.iter()),
            ExprKind::Neg { operand } => self.angle_in(scope, operand, depth + 1),
            ExprKind::Binary { lhs, rhs, .. } => {
                self.angle_in(scope, lhs, depth + 1) || self.angle_in(scope, rhs, depth + 1)
            }
            ExprKind::Piecewise { knots, .. } => any(&mut knots.iter().map(|k| &k.1)),
            ExprKind::Call { function, args } => {
                ANGLE_FUNCTIONS.contains(&function.name.as_str())
                    || self.binding_names_angle(scope, &function.name, depth)
                    || any(&mut args.iter())
            }
            ExprKind::Path { path } => match path.single() {
                Some(name) if name.name == "pi" => true,
                Some(name) => self.binding_names_angle(scope, &name.name, depth),
                // A property of a declaration (`hinge.rest_angle`) or a member: not followed,
                // given the benefit of the doubt.
                None => true,
            },
        }
    }

    fn binding_names_angle(&self, scope: ScopeId, name: &str, depth: usize) -> bool {
        let Some(Named::Binding(id)) = self.lookup(scope, name) else {
            return false;
        };
        let b = &self.bindings[id];
        match b.kind {
            BindingKind::LoopVar => false,
            // An `angle` argument is checked where it is given.
            BindingKind::Arg if matches!(b.ty, Some((ParamType::Scalar(q), _)) if q == units::ANGLE) => {
                true
            }
            // A param is judged by its declaration: `--set` values are SI by contract, so
            // `--set tilt=0.1` of `param tilt = 5 deg` is radians, and no mistake.
            _ => b
                .expr
                .as_ref()
                .is_some_and(|x| self.angle_in(b.scope, x, depth + 1)),
        }
    }

    /// W0203 for the angle `e` of `what` (read in `scope`), if it is a bare number other than
    /// zero; `value` is its constant value, `None` for a function of time.
    pub fn bare_angle(
        &self,
        scope: ScopeId,
        e: &Expr,
        value: Option<f64>,
        what: &str,
    ) -> Option<Diagnostic> {
        if value == Some(0.0) || self.names_an_angle(scope, e) {
            return None;
        }
        let read = match value {
            Some(x) => format!(
                ": {} is read as {} rad ({} deg)",
                short(x),
                short(x),
                short(x.to_degrees())
            ),
            None => ", so it is read in radians".to_string(),
        };
        let hint = match &e.kind {
            ExprKind::Quantity {
                value: x,
                unit: None,
            } => format!(
                "write `{} deg` for degrees, or `{} rad` to say it is radians",
                short(*x),
                short(*x)
            ),
            _ => "give the angle a unit: multiply by `1 deg` for degrees, or by `1 rad` to say it is radians".to_string(),
        };
        Some(
            Diagnostic::warning(Code::W0203, format!("{what} has no angle unit{read}"))
                .at(e.span, "no `rad`, `deg` or `rev`")
                .hint(hint),
        )
    }
}

/// A number as a person writes it: as written when short (`3`, `0.25`), else to four
/// significant digits (`171.9`).
fn short(x: f64) -> String {
    let plain = format!("{x}");
    if plain.len() <= 8 || !x.is_finite() || x == 0.0 {
        return plain;
    }
    let decimals = (3 - x.abs().log10().floor() as i32).clamp(0, 12) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::short;

    #[test]
    fn numbers_are_shown_short() {
        assert_eq!(short(3.0), "3");
        assert_eq!(short(0.25), "0.25");
        assert_eq!(short(3f64.to_degrees()), "171.9");
        assert_eq!(short(0.0523598775598), "0.05236");
        assert_eq!(short(1e20), "100000000000000000000");
    }
}
