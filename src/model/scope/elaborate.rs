//! Elaboration: walks the items of a file, imports `use`d modules, instantiates components and
//! unrolls `for` loops, so that every declaration ends up with a qualified name and the scope
//! its expressions are evaluated in.
//!
//! Within one scope, names are declared first (params, lets, functions, components, imports)
//! and structure second (declarations, loops, instances), so order never matters.

use super::env::{Binding, BindingKind, Decl, Env, Named, ScopeId};
use super::types::ParamType;
use crate::diagnostics::{did_you_mean, Code, Diagnostic, Iteration};
use crate::model::{LoadRequest, Loader};
use crate::source::{SourceMap, Span};
use crate::syntax::ast::{Component, Ident, Item, OutputItem, UseTarget};
use std::collections::{HashMap, HashSet};
use std::rc::Rc;

/// Nesting limit of component instances (a component that instantiates itself hits it).
const MAX_DEPTH: usize = 24;
/// Largest loop.
const MAX_LOOP: i64 = 100_000;

#[derive(Clone, Copy, PartialEq, Eq)]
enum Where {
    /// The model file's top level.
    Main,
    /// A library module's top level: components, imports, lets, functions only.
    Module,
    /// Inside a component body or a loop.
    Nested,
}

#[derive(Default)]
pub struct Elaborated {
    pub header: Option<(Ident, Option<String>, Span)>,
    pub gravity: Option<(crate::syntax::ast::Expr, Span)>,
    pub solve: Option<Item>,
    pub outputs: Vec<(OutputItem, ScopeId)>,
    pub initials: Vec<(Item, ScopeId)>,
    /// `exact CHANNEL = f(t)` declarations (top level of the model file only).
    pub exacts: Vec<(Item, ScopeId)>,
    /// Components defined in the model file, with whether they were instantiated.
    pub local_components: Vec<(String, Span)>,
    pub instantiated: HashSet<Span>,
}

pub struct Elaborator<'a> {
    pub env: Env,
    pub errors: Vec<Diagnostic>,
    pub out: Elaborated,
    sources: &'a mut SourceMap,
    loader: &'a dyn Loader,
    /// Loaded modules by key, with their scope.
    modules: HashMap<String, ScopeId>,
    /// Modules being loaded (to catch import cycles).
    loading: Vec<String>,
    depth: usize,
    /// The file name of each source id (for relative `use`).
    file_names: Vec<String>,
    /// `--set NAME=VALUE` overrides of top-level params, applied before any structure is built
    /// (so they steer loops and conditions too).
    pub sets: Vec<(Ident, crate::syntax::ast::Expr)>,
}

impl<'a> Elaborator<'a> {
    pub fn new(sources: &'a mut SourceMap, loader: &'a dyn Loader) -> Elaborator<'a> {
        Elaborator {
            env: Env::default(),
            errors: Vec::new(),
            out: Elaborated::default(),
            sources,
            loader,
            modules: HashMap::new(),
            loading: Vec::new(),
            depth: 0,
            file_names: Vec::new(),
            sets: Vec::new(),
        }
    }

    /// What elaboration produced: the environment, the model-level items, and the errors.
    pub fn finish(self) -> (Env, Elaborated, Vec<Diagnostic>) {
        (self.env, self.out, self.errors)
    }

    fn error(&mut self, scope: ScopeId, d: Diagnostic) {
        if !super::env::is_secondary(&d) {
            let d = self.env.trace(scope, d);
            self.errors.push(d);
        }
    }

    /// Elaborates the model file's items in a fresh top-level scope.
    pub fn main(&mut self, items: &[Item], file: &str) -> ScopeId {
        let top = self.env.new_scope(None, String::new(), None);
        self.file_names.push(file.to_string());
        self.items(items, top, Where::Main, file);
        top
    }

    /// Elaborates a library file as `use` would; returns its scope.
    pub fn library(&mut self, items: &[Item], file: &str) -> ScopeId {
        let scope = self.env.new_scope(None, String::new(), None);
        self.items(items, scope, Where::Module, file);
        scope
    }

    fn items(&mut self, items: &[Item], scope: ScopeId, at: Where, file: &str) {
        // Names first.
        for item in items {
            self.declare_names(item, scope, at, file);
        }
        if at == Where::Main {
            self.apply_sets(scope);
        }
        // Then structure.
        for item in items {
            self.structure(item, scope, at, file);
        }
    }

    fn apply_sets(&mut self, top: ScopeId) {
        for (name, expr) in std::mem::take(&mut self.sets) {
            match self.env.scopes[top].names.get(&name.name) {
                Some(Named::Binding(id)) if self.env.bindings[*id].kind == BindingKind::Param => {
                    self.env.bindings[*id].set = Some(expr);
                }
                _ => {
                    let mut names: Vec<(u32, String)> = self.env.scopes[top]
                        .names
                        .iter()
                        .filter_map(|(k, n)| match n {
                            Named::Binding(id)
                                if self.env.bindings[*id].kind == BindingKind::Param =>
                            {
                                Some((self.env.bindings[*id].span.start, k.clone()))
                            }
                            _ => None,
                        })
                        .collect();
                    names.sort();
                    let names: Vec<String> = names.into_iter().map(|x| x.1).collect();
                    let hint = match did_you_mean(&name.name, names.iter().map(|s| s.as_str())) {
                        Some(s) => format!("did you mean `{s}`? Only params can be set"),
                        None if names.is_empty() => "this model declares no params".to_string(),
                        None => format!("the model's params are: {}", names.join(", ")),
                    };
                    self.errors.push(
                        Diagnostic::error(
                            Code::E0208,
                            format!(
                                "`--set {}`: the model has no param `{}`",
                                name.name, name.name
                            ),
                        )
                        .at(name.span, "unknown param")
                        .hint(hint),
                    );
                }
            }
        }
    }

    /// Marks the names an untaken `if` branch mentions as used, so a param used only there is
    /// not reported unused.
    fn mention(&mut self, items: &[Item], scope: ScopeId) {
        for name in items.iter().flat_map(crate::model::build::written_names) {
            if let Some(Named::Binding(id)) = self.env.lookup(scope, &name) {
                self.env.bindings[id].used = true;
            }
        }
    }

    fn misplaced(&mut self, scope: ScopeId, span: Span, what: &str, at: Where) {
        let place = match at {
            Where::Module => "a library file",
            _ => "a component or a loop",
        };
        let hint = match (what, at) {
            ("param", Where::Nested) => {
                "inside components use `let`, or make it a component parameter".to_string()
            }
            (_, Where::Module) => {
                "a library file declares components (and the lets, functions and `use`s they need)"
                    .to_string()
            }
            _ => format!("declare `{what}` at the top level of the model file"),
        };
        self.error(
            scope,
            Diagnostic::error(Code::E0220, format!("`{what}` cannot appear in {place}"))
                .at(span, "not allowed here")
                .hint(hint),
        );
    }

    fn declare_names(&mut self, item: &Item, scope: ScopeId, at: Where, file: &str) {
        match item {
            Item::Param { name, value, span } => {
                if at != Where::Main {
                    return self.misplaced(scope, *span, "param", at);
                }
                self.bind(scope, name, *span, BindingKind::Param, value);
            }
            Item::Let { name, value, span } => {
                self.bind(scope, name, *span, BindingKind::Let, value)
            }
            Item::Function { name, value, span } => {
                self.bind(scope, name, *span, BindingKind::Function, value)
            }
            Item::Component(c) => {
                if at == Where::Nested {
                    return self.misplaced(scope, c.span, "component", at);
                }
                if self.reserved(scope, &c.name) {
                    return;
                }
                self.check_component(c, scope);
                if let Err(d) =
                    self.env
                        .declare(scope, &c.name, None, Named::Component(c.clone(), scope))
                {
                    self.error(scope, d);
                }
                if at == Where::Main {
                    self.out
                        .local_components
                        .push((c.name.name.clone(), c.name.span));
                }
            }
            Item::Use { target, span } => {
                if at == Where::Nested {
                    return self.misplaced(scope, *span, "use", at);
                }
                self.import(target, *span, scope, file);
            }
            Item::Model { name, title, span } => {
                if at != Where::Main {
                    return self.misplaced(scope, *span, "model", at);
                }
                if self.out.header.is_some() {
                    self.error(
                        scope,
                        Diagnostic::error(Code::E0103, "a second `model` header")
                            .at(*span, "repeated here")
                            .hint("one file describes one model; remove this header"),
                    );
                } else {
                    self.out.header = Some((name.clone(), title.clone(), *span));
                }
            }
            Item::Gravity { value, span } => {
                if at != Where::Main {
                    return self.misplaced(scope, *span, "gravity", at);
                }
                if self.out.gravity.is_some() {
                    self.error(
                        scope,
                        Diagnostic::error(Code::E0203, "gravity is declared twice")
                            .at(*span, "second declaration")
                            .hint("declare `gravity` once"),
                    );
                } else {
                    self.out.gravity = Some((value.clone(), *span));
                }
            }
            Item::Solve { span, .. } => {
                if at != Where::Main {
                    return self.misplaced(scope, *span, "solve", at);
                }
                if self.out.solve.is_some() {
                    self.error(scope, Diagnostic::error(Code::E0203, "a second `solve` block").at(*span, "repeated here").hint("one model has one `solve` block; override it from the command line with --dt, --until, --alpha"));
                } else {
                    self.out.solve = Some(item.clone());
                }
            }
            _ => {}
        }
    }

    /// `t` is the time everywhere: no declaration, parameter or loop variable may take it.
    fn reserved(&mut self, scope: ScopeId, name: &Ident) -> bool {
        if name.name != "t" {
            return false;
        }
        self.error(
            scope,
            Diagnostic::error(Code::E0203, "`t` is the time and cannot be redeclared")
                .at(name.span, "reserved name")
                .hint("choose another name"),
        );
        true
    }

    fn bind(
        &mut self,
        scope: ScopeId,
        name: &Ident,
        span: Span,
        kind: BindingKind,
        value: &crate::syntax::ast::Expr,
    ) {
        if self.reserved(scope, name) {
            return;
        }
        let b = Env::binding(name, span, kind, Some(value.clone()), scope, None, None);
        let id = self.env.add_binding(b);
        if let Err(d) = self.env.declare_local(scope, name, id) {
            self.error(scope, d);
        }
    }

    /// Checks a component's parameter list once, where it is defined.
    fn check_component(&mut self, c: &Component, scope: ScopeId) {
        let mut seen: HashMap<&str, Span> = HashMap::new();
        for p in &c.params {
            self.reserved(scope, &p.name);
            if let Some(first) = seen.insert(&p.name.name, p.name.span) {
                self.error(
                    scope,
                    Diagnostic::error(
                        Code::E0203,
                        format!("parameter `{}` is declared twice", p.name.name),
                    )
                    .at(p.name.span, "second declaration")
                    .at(first, "first declared here")
                    .hint("give every parameter its own name"),
                );
            }
            if ParamType::parse(&p.ty.name).is_none() {
                let names = super::types::TYPES.iter().map(|t| t.0);
                let d = Diagnostic::error(
                    Code::E0215,
                    format!("unknown parameter type `{}`", p.ty.name),
                )
                .at(p.ty.span, "not a type");
                let list = super::types::TYPES
                    .iter()
                    .map(|t| t.0)
                    .collect::<Vec<_>>()
                    .join(", ");
                self.error(
                    scope,
                    match did_you_mean(&p.ty.name, names) {
                        Some(s) => d.hint(format!("did you mean `{s}`? Types: {list}")),
                        None => d.hint(format!("types: {list}")),
                    },
                );
            }
        }
    }

    fn structure(&mut self, item: &Item, scope: ScopeId, at: Where, file: &str) {
        match item {
            Item::Entity { name, span, .. } | Item::Joint { name, span, .. } => {
                if at == Where::Module {
                    return self.misplaced(scope, *span, "a declaration", at);
                }
                if self.reserved(scope, &name.ident) {
                    return;
                }
                let index = match &name.index {
                    Some(e) => match self.env.integer_in(scope, e, "an index") {
                        Ok(i) => Some(i),
                        Err(d) => return self.error(scope, d),
                    },
                    None => None,
                };
                let qualified = self.env.qualified(scope, &name.ident.name, index);
                let id = self.env.decls.len();
                self.env.decls.push(Decl {
                    item: Rc::new(item.clone()),
                    name: qualified,
                    scope,
                    name_span: name.span,
                    used: false,
                });
                if let Err(d) = self.env.declare(scope, &name.ident, index, Named::Decl(id)) {
                    self.error(scope, d);
                }
            }
            Item::Instance {
                name,
                component,
                args,
                span,
            } => {
                if at == Where::Module {
                    return self.misplaced(scope, *span, "an instance", at);
                }
                if self.reserved(scope, &name.ident) {
                    return;
                }
                self.instantiate(name, component, args, *span, scope, file);
            }
            Item::For {
                var,
                from,
                to,
                inclusive,
                items,
                span,
            } => {
                if at == Where::Module {
                    return self.misplaced(scope, *span, "for", at);
                }
                if self.reserved(scope, var) {
                    return;
                }
                let bounds = self
                    .env
                    .integer_in(scope, from, "a loop bound")
                    .and_then(|a| {
                        self.env
                            .integer_in(scope, to, "a loop bound")
                            .map(|b| (a, b))
                    });
                let (a, b) = match bounds {
                    Ok(x) => x,
                    Err(d) => return self.error(scope, d),
                };
                let end = if *inclusive { b + 1 } else { b };
                if end - a > MAX_LOOP {
                    return self.error(
                        scope,
                        Diagnostic::error(Code::E0223, format!("this loop runs {} times", end - a))
                            .at(*span, "too many iterations")
                            .hint(format!(
                                "loops are limited to {MAX_LOOP} iterations; check the bounds"
                            )),
                    );
                }
                let header = Span {
                    end: to.span.end,
                    ..*span
                };
                for i in a..end {
                    let home = self.env.scopes[scope].home;
                    let prefix = self.env.scopes[home].prefix.clone();
                    let inner = self.env.new_scope(Some(scope), prefix, Some(home));
                    self.env.scopes[inner].iteration = Some(Iteration {
                        header,
                        var: var.name.clone(),
                        value: i,
                        count: end - a,
                    });
                    let v = crate::model::eval::Value::scalar(
                        i as f64,
                        crate::model::eval::units::Dim::NONE,
                    );
                    let mut b = Env::binding(
                        var,
                        var.span,
                        BindingKind::LoopVar,
                        None,
                        inner,
                        None,
                        Some(v),
                    );
                    b.used = true;
                    let id = self.env.add_binding(b);
                    self.env.scopes[inner]
                        .names
                        .insert(var.name.clone(), Named::Binding(id));
                    self.items(items, inner, Where::Nested, file);
                }
            }
            Item::If {
                cond,
                then,
                otherwise,
                span,
            } => {
                if at == Where::Module {
                    return self.misplaced(scope, *span, "if", at);
                }
                let c = match self.env.eval_in(scope, cond) {
                    Ok(crate::model::eval::Value::Scalar { value, dim }) if dim.is_none() => value != 0.0,
                    Ok(v) => {
                        return self.error(
                            scope,
                            Diagnostic::error(Code::E0209, format!("a condition must be a constant number, found {}", v.kind_name()))
                                .at(cond.span, "not a condition")
                                .hint("write `if elastic { ... }` with a `bool` parameter, or any dimensionless number (true when not 0)"),
                        )
                    }
                    Err(d) => return self.error(scope, d),
                };
                let home = self.env.scopes[scope].home;
                let prefix = self.env.scopes[home].prefix.clone();
                let inner = self.env.new_scope(Some(scope), prefix, Some(home));
                self.mention(if c { otherwise } else { then }, scope);
                self.items(if c { then } else { otherwise }, inner, Where::Nested, file);
            }
            Item::Export { items, span } => {
                if at == Where::Main {
                    return self.error(
                        scope,
                        Diagnostic::error(Code::E0220, "`export` belongs in a component")
                            .at(*span, "not in a component")
                            .hint("every name of the model file is visible already"),
                    );
                }
                let home = self.env.scopes[scope].home;
                let exports = self.env.scopes[home]
                    .exports
                    .get_or_insert_with(HashMap::new);
                for e in items {
                    exports.insert(e.name.name.clone(), e.target.clone());
                }
            }
            Item::Output { items, span } => {
                if at == Where::Module {
                    return self.misplaced(scope, *span, "output", at);
                }
                for o in items {
                    self.out.outputs.push((o.clone(), scope));
                }
            }
            Item::Initial { span, .. } => {
                if at == Where::Module {
                    return self.misplaced(scope, *span, "initial", at);
                }
                self.out.initials.push((item.clone(), scope));
            }
            Item::Exact { span, .. } => {
                if at != Where::Main {
                    return self.misplaced(scope, *span, "exact", at);
                }
                self.out.exacts.push((item.clone(), scope));
            }
            _ => {}
        }
    }

    fn instantiate(
        &mut self,
        name: &crate::syntax::ast::Name,
        component: &Ident,
        args: &[crate::syntax::ast::Arg],
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
            Some(_) => {
                self.failed_instance(name, index, scope);
                return self.error(
                    scope,
                    Diagnostic::error(Code::E0222, format!("`{}` is not a component", component.name))
                        .at(component.span, "not a component")
                        .hint("instantiate a component declared with `component NAME(...) { ... }` or imported with `use`"),
                );
            }
            None => {
                self.failed_instance(name, index, scope);
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
                return self.error(scope, d.hint(hint));
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
        // Arguments.
        let mut given: HashMap<&str, &crate::syntax::ast::Arg> = HashMap::new();
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
        for p in &def.params {
            let Some(ty) = ParamType::parse(&p.ty.name) else {
                continue;
            };
            let (expr, offset, eval_scope) = match (given.get(p.name.name.as_str()), &p.default) {
                (Some(a), _) => (a.value.clone(), a.offset.clone(), scope),
                (None, Some(d)) => (d.clone(), None, inst),
                (None, None) => {
                    self.error(
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
                    continue;
                }
            };
            if ty.is_reference() && !matches!(expr.kind, crate::syntax::ast::ExprKind::Path { .. })
            {
                self.error(
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
                continue;
            }
            if let (Some(o), false) = (&offset, ty == ParamType::Marker) {
                self.error(
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
                continue;
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
        self.depth += 1;
        self.items(&def.items, inst, Where::Nested, file);
        self.depth -= 1;
        // Exports must name something the component declares.
        if let Some(exports) = self.env.scopes[inst].exports.clone() {
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
    }

    /// Declares an instance that could not be made, so that the names through it stay silent
    /// instead of each reporting it unknown.
    fn failed_instance(
        &mut self,
        name: &crate::syntax::ast::Name,
        index: Option<i64>,
        scope: ScopeId,
    ) {
        let prefix = format!("{}.", self.env.qualified(scope, &name.ident.name, index));
        let inst = self.env.new_scope(None, prefix, None);
        self.env.scopes[inst].failed = true;
        // A clash with another name is secondary to the failure reported.
        let _ = self
            .env
            .declare(scope, &name.ident, index, Named::Instance(inst));
    }

    fn import(&mut self, target: &UseTarget, span: Span, scope: ScopeId, file: &str) {
        let (module, item): (Vec<String>, Option<Ident>) = match target {
            UseTarget::File(path) => {
                let Some(ms) = self.load(
                    &format!("\"{path}\""),
                    LoadRequest::File { path, from: file },
                    span,
                    scope,
                ) else {
                    return;
                };
                return self.import_all(ms, scope, span);
            }
            UseTarget::Module(segs) => (segs.iter().map(|s| s.name.clone()).collect(), None),
        };
        // `use a::b::c`: module a::b::c entire, or item c of module a::b.
        let whole = module.join("::");
        if let Some(ms) = self.try_load(&module, span, scope, file) {
            return self.import_all(ms, scope, span);
        }
        let _ = item;
        if module.len() >= 2 {
            let (m, last) = module.split_at(module.len() - 1);
            if let Some(ms) = self.try_load(m, span, scope, file) {
                let name = &last[0];
                let Some(named) = self.env.scopes[ms].names.get(name).cloned() else {
                    let names: Vec<String> = self.env.scopes[ms].names.keys().cloned().collect();
                    let d = Diagnostic::error(
                        Code::E0216,
                        format!("module `{}` has no `{name}`", m.join("::")),
                    )
                    .at(span, "not found");
                    let hint = match did_you_mean(name, names.iter().map(|s| s.as_str())) {
                        Some(s) => format!("did you mean `{s}`?"),
                        None => format!("it declares: {}", names.join(", ")),
                    };
                    return self.error(scope, d.hint(hint));
                };
                let ident = Ident {
                    name: name.clone(),
                    span,
                };
                if let Err(d) = self.env.declare(scope, &ident, None, named) {
                    self.error(scope, d);
                }
                return;
            }
        }
        if !self.errors.iter().any(|e| e.code == Code::E0217) {
            let stdlib: Vec<&str> = crate::stdlib::MODULES.iter().map(|m| m.0).collect();
            self.error(
                scope,
                Diagnostic::error(Code::E0216, format!("cannot find module `{whole}`"))
                    .at(span, "not found")
                    .hint(format!(
                        "the standard library has: {}; your own modules are searched next to the model file and in the directories of MBD_PATH",
                        stdlib.iter().map(|m| format!("stdlib::{m}")).collect::<Vec<_>>().join(", ")
                    )),
            );
        }
    }

    fn import_all(&mut self, ms: ScopeId, scope: ScopeId, span: Span) {
        let mut names: Vec<(String, Named)> = self.env.scopes[ms]
            .names
            .iter()
            .filter(|(_, n)| matches!(n, Named::Component(..)))
            .map(|(k, n)| (k.clone(), n.clone()))
            .collect();
        names.sort_by(|a, b| a.0.cmp(&b.0));
        for (name, named) in names {
            let ident = Ident { name, span };
            if let Err(d) = self.env.declare(scope, &ident, None, named) {
                self.error(scope, d);
            }
        }
    }

    fn try_load(
        &mut self,
        module: &[String],
        span: Span,
        scope: ScopeId,
        file: &str,
    ) -> Option<ScopeId> {
        let key = module.join("::");
        if module.first().map(|s| s.as_str()) == Some("stdlib") {
            let name = module[1..].join("::");
            let text = crate::stdlib::MODULES.iter().find(|m| m.0 == name)?.1;
            return self.load_text(
                &key,
                &format!("stdlib/{name}.mbd"),
                text.to_string(),
                span,
                scope,
            );
        }
        self.load(
            &key,
            LoadRequest::Module {
                path: module,
                from: file,
            },
            span,
            scope,
        )
    }

    fn load(&mut self, key: &str, req: LoadRequest, span: Span, scope: ScopeId) -> Option<ScopeId> {
        if let Some(&s) = self.modules.get(key) {
            return Some(s);
        }
        if self.loading.iter().any(|k| k == key) {
            return self.cycle(key, span, scope);
        }
        match self.loader.load(&req) {
            Ok((name, text)) => self.load_text(key, &name, text, span, scope),
            Err(None) => None,
            Err(Some(msg)) => {
                self.error(
                    scope,
                    Diagnostic::error(Code::E0216, format!("cannot read `{key}`: {msg}"))
                        .at(span, "imported here")
                        .hint("check the path; relative paths start at the importing file's directory"),
                );
                None
            }
        }
    }

    fn cycle(&mut self, key: &str, span: Span, scope: ScopeId) -> Option<ScopeId> {
        let chain = self.loading.join(" -> ");
        self.error(
            scope,
            Diagnostic::error(Code::E0217, format!("import cycle: {chain} -> {key}"))
                .at(span, "imports a module that is still being loaded")
                .hint("move what both modules need into a third module that imports neither"),
        );
        None
    }

    fn load_text(
        &mut self,
        key: &str,
        name: &str,
        text: String,
        span: Span,
        scope: ScopeId,
    ) -> Option<ScopeId> {
        if let Some(&s) = self.modules.get(key) {
            return Some(s);
        }
        if self.loading.iter().any(|k| k == key) {
            return self.cycle(key, span, scope);
        }
        let id = self.sources.add(name, text.clone());
        let file = match crate::syntax::parse_file(&text, id) {
            Ok(f) => f,
            Err(d) => {
                self.errors.push(d);
                return None;
            }
        };
        self.loading.push(key.to_string());
        let ms = self.env.new_scope(None, String::new(), None);
        self.items(&file.items, ms, Where::Module, name);
        self.loading.pop();
        self.modules.insert(key.to_string(), ms);
        Some(ms)
    }
}

/// Every binding nobody used, for W0201/W0202.
pub fn unused_bindings(env: &Env) -> Vec<&Binding> {
    env.bindings
        .iter()
        .filter(|b| !b.used && b.kind != BindingKind::LoopVar)
        .collect()
}
