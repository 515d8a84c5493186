//! Component instances: `NAME = component(args)` gets a scope of its own (its parent the
//! scope that defined the component), its arguments checked against the parameters and
//! bound lazily in the caller's scope, its body elaborated, its exports checked.
//! Contract: declares names and scopes; must not evaluate anything but indices.

use super::*;
use crate::syntax::ast::{Arg, CompParam, ExprKind};

impl Elaborator<'_> {
    pub(super) fn instantiate(
        &mut self,
        name: &Name,
        component: &Ident,
        args: &[Arg],
        span: Span,
        scope: ScopeId,
        file: &str,
    ) {
        let index = match &name.index {
            Some(e) => match self.env.integer_in(scope, e, "an index") {
                Ok(i) => Some(i),
                Err(d) => return self.error(scope, d),
            },
            None => None,
        };
        let (def, def_scope) = match self.env.lookup(scope, &component.name) {
            Some(Named::Component(c, s)) => (c, s),
            other => {
                self.failed_instance(name, index, scope);
                return self.not_a_component(component, scope, other.is_some());
            }
        };
        if self.depth >= MAX_DEPTH {
            return self.error(
                scope,
                Diagnostic::error(Code::E0218, format!("components nest more than {MAX_DEPTH} deep"))
                    .at(span, "instantiated here")
                    .hint(format!("component `{}` probably instantiates itself, directly or through another component", def.name.name)),
            );
        }
        self.out.instantiated.insert(def.span);
        let prefix = format!("{}.", self.env.qualified(scope, &name.ident.name, index));
        let inst = self.env.new_scope(Some(def_scope), prefix, None);
        self.env.scopes[inst].instance = Some((def.name.name.clone(), span));
        self.env.scopes[inst].caller = Some(scope);
        if let Err(d) = self
            .env
            .declare(scope, &name.ident, index, Named::Instance(inst))
        {
            self.error(scope, d);
        }
        let given = self.arguments(&def, args, scope);
        for p in &def.params {
            self.bind_param(
                &def,
                p,
                given.get(p.name.name.as_str()).copied(),
                component,
                (scope, inst),
            );
        }
        self.depth += 1;
        self.items(&def.items, inst, Where::Nested, file);
        self.depth -= 1;
        self.check_exports(&def, inst);
    }

    /// `component` names something else (`declared`), or nothing.
    fn not_a_component(&mut self, component: &Ident, scope: ScopeId, declared: bool) {
        if declared {
            return self.error(
                scope,
                Diagnostic::error(Code::E0222, format!("`{}` is not a component", component.name))
                    .at(component.span, "not a component")
                    .hint("instantiate a component declared with `component NAME(...) { ... }` or imported with `use`"),
            );
        }
        let candidates = self.env.visible(scope);
        let d = Diagnostic::error(
            Code::E0201,
            format!("unknown component `{}`", component.name),
        )
        .at(component.span, "not declared");
        let hint = match did_you_mean(&component.name, candidates.iter().map(|s| s.as_str())) {
            Some(s) => format!("did you mean `{s}`?"),
            None => "declare it with `component`, or import it, e.g. `use stdlib::rotor::lag_hinged_rotor`".to_string(),
        };
        self.error(scope, d.hint(hint));
    }

    /// The arguments by name, each given once and naming a parameter.
    fn arguments<'x>(
        &mut self,
        def: &Component,
        args: &'x [Arg],
        scope: ScopeId,
    ) -> HashMap<&'x str, &'x Arg> {
        let mut given: HashMap<&str, &Arg> = HashMap::new();
        for a in args {
            if let Some(first) = given.insert(&a.name.name, a) {
                self.error(
                    scope,
                    Diagnostic::error(
                        Code::E0203,
                        format!("argument `{}` is given twice", a.name.name),
                    )
                    .at(a.name.span, "second value")
                    .at(first.name.span, "first value")
                    .hint("give each argument once"),
                );
            }
            if !def.params.iter().any(|p| p.name.name == a.name.name) {
                let names: Vec<&str> = def.params.iter().map(|p| p.name.name.as_str()).collect();
                let d = Diagnostic::error(
                    Code::E0215,
                    format!(
                        "component `{}` has no parameter `{}`",
                        def.name.name, a.name.name
                    ),
                )
                .at(a.name.span, "unknown argument");
                let hint = match did_you_mean(&a.name.name, names.iter().copied()) {
                    Some(s) => format!("did you mean `{s}`? Parameters: {}", names.join(", ")),
                    None => format!("parameters: {}", names.join(", ")),
                };
                self.error(scope, d.hint(hint));
            }
        }
        given
    }

    /// Binds parameter `p` in the instance's scope to its argument (evaluated in the caller's
    /// scope) or its default (in the instance's).
    fn bind_param(
        &mut self,
        def: &Component,
        p: &CompParam,
        arg: Option<&Arg>,
        component: &Ident,
        (scope, inst): (ScopeId, ScopeId),
    ) {
        let Some(ty) = ParamType::parse(&p.ty.name) else {
            return;
        };
        let (expr, offset, eval_scope) = match (arg, &p.default) {
            (Some(a), _) => (a.value.clone(), a.offset.clone(), scope),
            (None, Some(d)) => (d.clone(), None, inst),
            (None, None) => {
                return self.error(
                    scope,
                    Diagnostic::error(
                        Code::E0215,
                        format!("`{}` needs argument `{}`", def.name.name, p.name.name),
                    )
                    .at(component.span, "missing argument")
                    .at(p.span, "parameter declared here")
                    .hint(format!(
                        "add `{} = ...`: {}",
                        p.name.name,
                        ty.describe()
                    )),
                );
            }
        };
        if ty.is_reference() && !matches!(expr.kind, ExprKind::Path { .. }) {
            return self.error(
                scope,
                Diagnostic::error(
                    Code::E0215,
                    format!(
                        "argument `{}` of `{}` must name a {}",
                        p.name.name,
                        def.name.name,
                        ty.name()
                    ),
                )
                .at(expr.span, "not a name")
                .hint(ty.example()),
            );
        }
        if let (Some(o), false) = (&offset, ty == ParamType::Marker) {
            return self.error(
                scope,
                Diagnostic::error(
                    Code::E0215,
                    format!(
                        "argument `{}` of `{}` is a {}: it takes no offset",
                        p.name.name,
                        def.name.name,
                        ty.name()
                    ),
                )
                .at(o.span, "an offset")
                .at(p.ty.span, "declared here")
                .hint(format!(
                    "only `marker` arguments take `@ (x, y, z)`; {}",
                    ty.example()
                )),
            );
        }
        let mut b = Env::binding(
            &p.name,
            p.span,
            BindingKind::Arg,
            Some(expr),
            eval_scope,
            Some((ty, p.ty.span)),
            None,
        );
        b.component = Some(def.name.name.clone());
        b.offset = offset;
        // Arguments are part of a component's interface: never reported unused.
        b.used = true;
        let id = self.env.add_binding(b);
        self.env.scopes[inst]
            .names
            .insert(p.name.name.clone(), Named::Binding(id));
    }

    /// Exports must name something the component declares.
    fn check_exports(&mut self, def: &Component, inst: ScopeId) {
        let Some(exports) = self.env.scopes[inst].exports.clone() else {
            return;
        };
        for (n, alias) in exports {
            if alias.is_none() && !self.env.scopes[inst].names.contains_key(&n) {
                let span = def.items.iter().find_map(|i| match i {
                    Item::Export { items, .. } => {
                        items.iter().find(|e| e.name.name == n).map(|e| e.name.span)
                    }
                    _ => None,
                });
                let mut d = Diagnostic::error(
                    Code::E0201,
                    format!(
                        "component `{}` exports `{n}`, which it does not declare",
                        def.name.name
                    ),
                );
                if let Some(s) = span {
                    d = d.at(s, "exported here");
                }
                self.error(
                    inst,
                    d.hint("declare it in the component, or write `export NAME = path`"),
                );
            }
        }
    }

    /// Declares an instance that could not be made, so that the names through it stay silent
    /// instead of each reporting it unknown.
    fn failed_instance(&mut self, name: &Name, index: Option<i64>, scope: ScopeId) {
        let prefix = format!("{}.", self.env.qualified(scope, &name.ident.name, index));
        let inst = self.env.new_scope(None, prefix, None);
        self.env.scopes[inst].failed = true;
        // A clash with another name is secondary to the failure reported.
        let _ = self
            .env
            .declare(scope, &name.ident, index, Named::Instance(inst));
    }
}
