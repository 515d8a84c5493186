//! Evaluation in a scope: [`Cx`] answers the evaluator's questions about names (a binding's
//! value, a declaration's property, a user function, an angle without a unit) from one scope;
//! indices are whole numbers; a wrong value points back to where it was defined.
//! Contract: connects `Env` and the evaluator; must not build entities.

use super::env::{BindingKind, Env, Named, Ref, ScopeId, Seg};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::eval::{eval, Names, Value};
use crate::source::Span;
use crate::syntax::ast::{Expr, ExprKind, Ident, Path};

impl Env {
    pub fn eval_in(&mut self, scope: ScopeId, expr: &Expr) -> Result<Value, Diagnostic> {
        let mut cx = Cx { env: self, scope };
        eval(expr, &mut cx)
    }

    /// Evaluates an index or a count: a whole number.
    pub fn integer_in(
        &mut self,
        scope: ScopeId,
        expr: &Expr,
        what: &str,
    ) -> Result<i64, Diagnostic> {
        match self.eval_in(scope, expr)? {
            Value::Scalar { value, dim } if dim.is_none() && value.fract() == 0.0 && value.abs() < 1e9 => Ok(value as i64),
            v => Err(Diagnostic::error(Code::E0214, format!("{what} must be a whole number"))
                .at(expr.span, match &v { Value::Scalar { value, dim } if dim.is_none() => format!("this is {value}"), Value::Scalar { dim, .. } => format!("this is {}", dim.describe()), v => format!("this is {}", v.kind_name()) })
                .hint("indices and loop bounds are dimensionless integers, e.g. `blade[i]` with `for i in 0..N`")),
        }
    }

    /// Where the value of `e` was defined, when `e` names a param, a let or a function (the
    /// declaration) or a component argument (the value given to the instance, or what that
    /// names in turn): a second place to look when the value is wrong where it is used.
    pub fn definition(&self, scope: ScopeId, e: &Expr) -> Option<(Span, &'static str)> {
        self.definition_at(scope, e, 0)
    }

    fn definition_at(
        &self,
        scope: ScopeId,
        e: &Expr,
        depth: usize,
    ) -> Option<(Span, &'static str)> {
        let ExprKind::Path { path } = &e.kind else {
            return None;
        };
        let Some(Named::Binding(id)) = self.lookup(scope, &path.single()?.name) else {
            return None;
        };
        let b = &self.bindings[id];
        match b.kind {
            BindingKind::Param | BindingKind::Let | BindingKind::Function => {
                Some((b.span, "defined here"))
            }
            BindingKind::Arg => {
                let given = b.expr.as_ref()?;
                let further = if depth < 8 {
                    self.definition_at(b.scope, given, depth + 1)
                } else {
                    None
                };
                further.or(Some((given.span, "given here")))
            }
            BindingKind::LoopVar => None,
        }
    }
}

/// Evaluation context: an environment seen from one scope.
pub struct Cx<'a> {
    pub env: &'a mut Env,
    pub scope: ScopeId,
}

fn component(v: Value, seg: &Seg) -> Result<Value, Diagnostic> {
    let k = match seg.name.name.as_str() {
        "x" => 0,
        "y" => 1,
        "z" => 2,
        other => {
            return Err(
                Diagnostic::error(Code::E0201, format!("a value has no `{other}`"))
                    .at(seg.span, "not a component")
                    .hint("take a vector component with `.x`, `.y` or `.z`"),
            )
        }
    };
    match v {
        Value::Vector { value, dim } => Ok(Value::scalar(value[k], dim)),
        Value::Signal { mut parts, dim } if parts.len() == 3 => Ok(Value::Signal {
            parts: vec![parts.swap_remove(k)],
            dim,
        }),
        other => Err(Diagnostic::error(
            Code::E0209,
            format!(
                "`.{}` needs a vector, found {}",
                seg.name.name,
                other.kind_name()
            ),
        )
        .at(seg.span, "not a vector")
        .hint("components `.x`, `.y`, `.z` apply to vectors")),
    }
}

impl Names for Cx<'_> {
    fn path(&mut self, path: &Path) -> Result<Value, Diagnostic> {
        let segs = self.env.segs(self.scope, path)?;
        let (r, rest) = self.env.resolve(self.scope, &segs, path.span)?;
        let (mut v, rest) = match r {
            Ref::Builtin(v) => (v, rest),
            Ref::Binding(b) => (self.env.value_of(b, path.span)?, rest),
            Ref::Decl(d) => {
                let Some(prop) = rest.first() else {
                    let name = self.env.decls[d].name.clone();
                    return Err(Diagnostic::error(
                        Code::E0222,
                        format!("`{name}` is a declaration, not a value"),
                    )
                    .at(path.span, "used as a value")
                    .hint(format!("use one of its properties, e.g. `{name}.mass`")));
                };
                let Some(expr) = self.env.decl_prop(d, &prop.name.name) else {
                    let name = self.env.decls[d].name.clone();
                    return Err(Diagnostic::error(
                        Code::E0201,
                        format!("`{name}` does not set `{}`", prop.name.name),
                    )
                    .at(prop.span, "no such property written")
                    .hint("expressions may use the properties a declaration writes in its block"));
                };
                let scope = self.env.decls[d].scope;
                self.env.depth += 1;
                let v = if self.env.depth > 64 {
                    Err(Diagnostic::error(
                        Code::E0207,
                        "this property is defined in terms of itself",
                    )
                    .at(path.span, "here")
                    .hint("break the cycle"))
                } else {
                    self.env.eval_in(scope, &expr)
                };
                self.env.depth -= 1;
                (v?, rest[1..].to_vec())
            }
            Ref::Instance(s) => {
                let comp = self.env.scopes[s]
                    .instance
                    .clone()
                    .map(|i| i.0)
                    .unwrap_or_default();
                return Err(Diagnostic::error(
                    Code::E0222,
                    format!("an instance of `{comp}` is not a value"),
                )
                .at(path.span, "used as a value")
                .hint("use one of its exported names"));
            }
            Ref::Family(_) => {
                return Err(Diagnostic::error(
                    Code::E0214,
                    "an indexed family is not a value; say which member",
                )
                .at(path.span, "used as a value")
                .hint("write `NAME[i]`"));
            }
            Ref::Component(c) => {
                return Err(Diagnostic::error(
                    Code::E0222,
                    format!("`{}` is a component, not a value", c.name.name),
                )
                .at(path.span, "used as a value")
                .hint(format!("instantiate it: `NAME = {}(...)`", c.name.name)));
            }
        };
        for seg in &rest {
            v = component(v, seg)?;
        }
        Ok(v)
    }

    fn angle(&mut self, e: &Expr, value: f64, what: &str) {
        if let Some(d) = self.env.bare_angle(self.scope, e, Some(value), what) {
            let d = self.env.trace(self.scope, d);
            self.env.errors.push(d);
        }
    }

    fn function(&mut self, name: &Ident) -> Result<Option<Value>, Diagnostic> {
        match self.env.lookup(self.scope, &name.name) {
            Some(Named::Binding(b)) if self.env.bindings[b].kind == BindingKind::Function => {
                Ok(Some(self.env.value_of(b, name.span)?))
            }
            _ => Ok(None),
        }
    }
}
