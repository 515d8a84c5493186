//! Elaboration: walks the items of a file, imports `use`d modules, instantiates components and
//! unrolls `for` loops, so that every declaration ends up with a qualified name and the scope
//! its expressions are evaluated in.
//!
//! Within one scope, names are declared first (params, lets, functions, components, imports)
//! and structure second (declarations, loops, instances), so order never matters.
//!
//! Contract: declares names and scopes and collects what the build needs (outputs, initial
//! motions, solutions, the `solve` block); must not build entities, nor evaluate more than
//! indices, loop bounds and conditions.

use super::env::{Binding, BindingKind, Decl, Env, Named, ScopeId};
use super::types::ParamType;
use crate::diagnostics::{did_you_mean, Code, Diagnostic, Iteration};
use crate::model::{LoadRequest, Loader};
use crate::source::{SourceMap, Span};
use crate::syntax::ast::{Component, Expr, Ident, Item, Name, OutputItem, UseTarget};
use std::collections::{HashMap, HashSet};
use std::rc::Rc;

mod imports;
mod instances;

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
                self.declaration(item, name, scope);
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
            Item::For { span, .. } => {
                if at == Where::Module {
                    return self.misplaced(scope, *span, "for", at);
                }
                self.unroll(item, scope, file);
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
                self.condition(cond, then, otherwise, scope, file);
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

    /// A declaration (an entity or a joint) gets its qualified name in `scope`.
    fn declaration(&mut self, item: &Item, name: &Name, scope: ScopeId) {
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

    /// `for VAR in FROM..TO { ... }`: the body elaborated once per value, each in a scope of
    /// its own that declares into the enclosing naming scope.
    fn unroll(&mut self, item: &Item, scope: ScopeId, file: &str) {
        let Item::For {
            var,
            from,
            to,
            inclusive,
            items,
            span,
        } = item
        else {
            return;
        };
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
            let v =
                crate::model::eval::Value::scalar(i as f64, crate::model::eval::units::Dim::NONE);
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

    /// `if COND { ... } else { ... }`: the branch taken is elaborated, the other's names are
    /// only mentioned.
    fn condition(
        &mut self,
        cond: &Expr,
        then: &[Item],
        otherwise: &[Item],
        scope: ScopeId,
        file: &str,
    ) {
        let c = match self.env.eval_in(scope, cond) {
            // Any constant scalar, `if height { ... }` too: true when it is not zero.
            Ok(crate::model::eval::Value::Scalar { value, .. }) => value != 0.0,
            Ok(v) => {
                return self.error(
                    scope,
                    Diagnostic::error(Code::E0209, format!("a condition must be a constant number, found {}", v.kind_name()))
                        .at(cond.span, "not a condition")
                        .hint("write `if elastic { ... }` with a `bool` parameter, or any constant number or quantity (true when not 0)"),
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
}

/// Every binding nobody used, for W0201/W0202.
pub fn unused_bindings(env: &Env) -> Vec<&Binding> {
    env.bindings
        .iter()
        .filter(|b| !b.used && b.kind != BindingKind::LoopVar)
        .collect()
}
