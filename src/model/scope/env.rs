//! Scopes, bindings and their evaluation; paths are resolved in `resolve.rs`.
//!
//! A scope holds names: value bindings (params, lets, functions, component arguments, loop
//! variables), declarations, indexed families of them (`blade[0..4]`), component instances and
//! component definitions. Value bindings are evaluated lazily, in the scope that wrote them,
//! so declaration order never matters; cycles are reported (E0207), not overflowed.
//!
//! Scopes are lexical: a component instance's scope has the scope that *defined* the component
//! as its parent, while its arguments are evaluated in the caller's scope. A `for` body gets a
//! scope of its own for the loop variable and its lets, but declares its bodies in the
//! enclosing naming scope (its `home`), so `blade[i]` is visible after the loop.
//!
//! Contract: holds names and evaluates bindings lazily; must not build entities.

use super::types::ParamType;
use crate::diagnostics::{Code, Diagnostic, Iteration};
use crate::model::eval::units::Dim;
use crate::model::eval::Value;
use crate::runtime::timefn::TimeFn;
use crate::source::Span;
use crate::syntax::ast::{Component, Expr, Ident, Item, Path, PropValue};
use std::collections::{BTreeMap, HashMap};
use std::rc::Rc;

pub type ScopeId = usize;
pub type DeclId = usize;
pub type BindingId = usize;
/// The offset of a marker argument and the scope it is evaluated in.
pub type Offset = (Expr, ScopeId);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Member {
    Decl(DeclId),
    Instance(ScopeId),
}

#[derive(Clone, Debug)]
pub enum Named {
    Binding(BindingId),
    Decl(DeclId),
    /// Indexed declarations or instances, by index.
    Family(Rc<BTreeMap<i64, Member>>),
    Instance(ScopeId),
    /// A component definition and the scope it was defined in.
    Component(Rc<Component>, ScopeId),
}

pub struct Scope {
    pub parent: Option<ScopeId>,
    /// Prefix of the qualified names declared here: "" at top level, "rotor." in an instance.
    pub prefix: String,
    /// Where declarations made in this scope go (itself, or the enclosing one for a loop).
    pub home: ScopeId,
    pub names: HashMap<String, Named>,
    /// First span of each name declared here, for "first declared here".
    pub spans: HashMap<String, Span>,
    /// Names visible from outside an instance; `None` exports everything.
    pub exports: Option<HashMap<String, Option<Path>>>,
    /// For an instance scope: the component's name and where it was instantiated.
    pub instance: Option<(String, Span)>,
    /// For an instance scope: the scope of the code that instantiated it.
    pub caller: Option<ScopeId>,
    /// For the scope of one iteration of a `for` loop: which one.
    pub iteration: Option<Iteration>,
    /// For an instance scope: the instance could not be made (unknown component, too deep), so
    /// what names it stays silent; the cause has been reported.
    pub failed: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    Param,
    Let,
    Function,
    Arg,
    LoopVar,
}

#[derive(Clone, Debug)]
enum State {
    Pending,
    InProgress,
    Done(Value),
    Failed,
}

pub struct Binding {
    pub name: String,
    pub span: Span,
    pub kind: BindingKind,
    pub expr: Option<Expr>,
    /// The scope `expr` is evaluated in.
    pub scope: ScopeId,
    /// A `--set` override (top-level params only).
    pub set: Option<Expr>,
    pub ty: Option<(ParamType, Span)>,
    /// For a component argument: the component it belongs to (for messages).
    pub component: Option<String>,
    /// For a marker argument written with an offset (`base = earth @ (0, 0, 1) m`): the
    /// offset, evaluated in `scope` when the marker is resolved.
    pub offset: Option<Expr>,
    state: State,
    pub used: bool,
}

/// A declaration: an entity or joint item, instantiated in a scope.
pub struct Decl {
    pub item: Rc<Item>,
    /// The qualified name, e.g. `rotor.blade[2]`.
    pub name: String,
    /// The scope its expressions are evaluated in.
    pub scope: ScopeId,
    pub name_span: Span,
    pub used: bool,
}

impl Decl {
    /// The declaration's kind as written (`rigid`, `beam`, ...), or `joint`.
    pub fn item_kind(&self) -> Option<&str> {
        match &*self.item {
            Item::Entity { kind, .. } => Some(kind.name.as_str()),
            Item::Joint { .. } => Some("joint"),
            _ => None,
        }
    }
}

/// One segment of a path with its index and argument evaluated.
#[derive(Clone, Debug)]
pub struct Seg {
    pub name: Ident,
    pub index: Option<(i64, Span)>,
    pub arg: Option<(Value, Span)>,
    pub span: Span,
}

/// What a path resolves to, before its trailing segments.
#[derive(Clone, Debug)]
pub enum Ref {
    Binding(BindingId),
    Decl(DeclId),
    Instance(ScopeId),
    Component(Rc<Component>),
    /// `t`, `span`, `pi`, `x`, `y`, `z`.
    Builtin(Value),
    /// A whole indexed family, its members in index order (only from
    /// [`Env::resolve_family`]).
    Family(Vec<(i64, Member)>),
}

const BUILTINS: &[&str] = &["t", "span", "pi", "x", "y", "z", "true", "false"];

pub(super) fn builtin(name: &str) -> Option<Value> {
    let unit = |k: usize| {
        let mut v = [0.0; 3];
        v[k] = 1.0;
        Value::Vector {
            value: v,
            dim: Dim::NONE,
        }
    };
    Some(match name {
        "t" => Value::Signal {
            parts: vec![TimeFn::Time],
            dim: Dim::TIME,
        },
        "span" => Value::Signal {
            parts: vec![TimeFn::Arc],
            dim: Dim::LENGTH,
        },
        "pi" => Value::scalar(std::f64::consts::PI, Dim::NONE),
        "true" => Value::scalar(1.0, Dim::NONE),
        "false" => Value::scalar(0.0, Dim::NONE),
        "x" => unit(0),
        "y" => unit(1),
        "z" => unit(2),
        _ => return None,
    })
}

#[derive(Default)]
pub struct Env {
    pub scopes: Vec<Scope>,
    pub bindings: Vec<Binding>,
    pub decls: Vec<Decl>,
    /// Errors found while evaluating on demand.
    pub errors: Vec<Diagnostic>,
    /// Nesting of on-demand evaluations, to stop runaway self-reference.
    pub(super) depth: usize,
    /// Nesting of binding evaluations (a chain of definitions), at most [`MAX_NESTED`].
    pub(super) nested: usize,
    /// Set by [`Env::resolve_family`]: a family named without an index resolves to
    /// [`Ref::Family`] instead of asking for an index.
    pub(super) families: bool,
    /// Set by [`Env::resolve_marker`]: the offsets of the marker arguments resolution passes
    /// through, each with the scope it is evaluated in.
    pub(super) offsets: Option<Vec<Offset>>,
}

/// The deepest chain of definitions evaluated one inside another (each level's stack grows
/// on the heap as it needs).
pub const MAX_NESTED: usize = 10_000;

impl Env {
    pub fn new_scope(
        &mut self,
        parent: Option<ScopeId>,
        prefix: String,
        home: Option<ScopeId>,
    ) -> ScopeId {
        let id = self.scopes.len();
        self.scopes.push(Scope {
            parent,
            prefix,
            home: home.unwrap_or(id),
            names: HashMap::new(),
            spans: HashMap::new(),
            exports: None,
            instance: None,
            caller: None,
            iteration: None,
            failed: false,
        });
        id
    }

    /// Declares `name` (optionally indexed) in the home of `scope`. Reports duplicates.
    pub fn declare(
        &mut self,
        scope: ScopeId,
        name: &Ident,
        index: Option<i64>,
        what: Named,
    ) -> Result<(), Diagnostic> {
        let home = self.scopes[scope].home;
        let s = &mut self.scopes[home];
        let first = s.spans.get(&name.name).copied();
        let dup = |first: Option<Span>, label: String| {
            let mut d = Diagnostic::error(Code::E0203, format!("`{label}` is declared twice"))
                .at(name.span, "second declaration");
            if let Some(f) = first {
                d = d.at(f, "first declared here");
            }
            d.hint("every name in a scope must be distinct; inside a loop, index it: `blade[i]`")
        };
        match index {
            None => {
                if s.names.contains_key(&name.name) {
                    return Err(dup(first, name.name.clone()));
                }
                s.names.insert(name.name.clone(), what);
            }
            Some(i) => {
                let member = match what {
                    Named::Decl(d) => Member::Decl(d),
                    Named::Instance(sc) => Member::Instance(sc),
                    _ => {
                        return Err(Diagnostic::error(
                            Code::E0214,
                            "only declarations and instances can be indexed",
                        )
                        .at(name.span, "here")
                        .hint("remove the index"))
                    }
                };
                match s.names.get_mut(&name.name) {
                    Some(Named::Family(map)) => {
                        if map.contains_key(&i) {
                            return Err(dup(first, format!("{}[{i}]", name.name)));
                        }
                        Rc::make_mut(map).insert(i, member);
                    }
                    Some(_) => return Err(dup(first, name.name.clone())),
                    None => {
                        let mut map = BTreeMap::new();
                        map.insert(i, member);
                        s.names
                            .insert(name.name.clone(), Named::Family(Rc::new(map)));
                    }
                }
            }
        }
        s.spans.entry(name.name.clone()).or_insert(name.span);
        Ok(())
    }

    /// Declares a value binding in `scope` itself (a loop's lets stay in the loop body).
    pub fn declare_local(
        &mut self,
        scope: ScopeId,
        name: &Ident,
        id: BindingId,
    ) -> Result<(), Diagnostic> {
        let s = &mut self.scopes[scope];
        if let Some(first) = s
            .spans
            .get(&name.name)
            .copied()
            .or_else(|| s.names.contains_key(&name.name).then_some(name.span))
        {
            return Err(Diagnostic::error(
                Code::E0203,
                format!("`{}` is declared twice", name.name),
            )
            .at(name.span, "second declaration")
            .at(first, "first declared here")
            .hint("every name in a scope must be distinct"));
        }
        s.names.insert(name.name.clone(), Named::Binding(id));
        s.spans.insert(name.name.clone(), name.span);
        Ok(())
    }

    pub fn add_binding(&mut self, b: Binding) -> BindingId {
        self.bindings.push(b);
        self.bindings.len() - 1
    }

    #[allow(clippy::too_many_arguments)]
    pub fn binding(
        name: &Ident,
        span: Span,
        kind: BindingKind,
        expr: Option<Expr>,
        scope: ScopeId,
        ty: Option<(ParamType, Span)>,
        value: Option<Value>,
    ) -> Binding {
        Binding {
            name: name.name.clone(),
            span,
            kind,
            expr,
            scope,
            set: None,
            ty,
            component: None,
            offset: None,
            state: match value {
                Some(v) => State::Done(v),
                None => State::Pending,
            },
            used: false,
        }
    }

    /// Looks a plain name up through the scope chain.
    pub fn lookup(&self, scope: ScopeId, name: &str) -> Option<Named> {
        let mut s = Some(scope);
        while let Some(id) = s {
            if let Some(n) = self.scopes[id].names.get(name) {
                return Some(n.clone());
            }
            s = self.scopes[id].parent;
        }
        None
    }

    /// Every name visible from `scope`, for "did you mean".
    pub fn visible(&self, scope: ScopeId) -> Vec<String> {
        let mut out: Vec<String> = BUILTINS.iter().map(|s| s.to_string()).collect();
        let mut s = Some(scope);
        while let Some(id) = s {
            out.extend(self.scopes[id].names.keys().cloned());
            s = self.scopes[id].parent;
        }
        out
    }

    /// The qualified name of a declaration made in `scope`.
    pub fn qualified(&self, scope: ScopeId, name: &str, index: Option<i64>) -> String {
        let prefix = &self.scopes[self.scopes[scope].home].prefix;
        match index {
            Some(i) => format!("{prefix}{name}[{i}]"),
            None => format!("{prefix}{name}"),
        }
    }

    /// "in this instance of component X" notes for a diagnostic raised in `scope`, and the loop
    /// iterations it was raised in (labels once repeats are merged).
    pub fn trace(&self, scope: ScopeId, mut d: Diagnostic) -> Diagnostic {
        let mut s = Some(scope);
        let mut n = 0;
        while let Some(id) = s {
            if let Some(it) = &self.scopes[id].iteration {
                d.iterations.push(it.clone());
            }
            if let Some((comp, span)) = &self.scopes[id].instance {
                if n < 4 && !d.labels.iter().any(|l| l.span == *span) {
                    d = d.at(*span, format!("in this instance of component `{comp}`"));
                }
                n += 1;
                s = self.scopes[id].caller;
            } else {
                s = self.scopes[id].parent;
            }
        }
        d
    }

    /// The value of a binding, evaluated on first use.
    pub fn value_of(&mut self, id: BindingId, use_span: Span) -> Result<Value, Diagnostic> {
        self.bindings[id].used = true;
        match self.bindings[id].state.clone() {
            State::Done(v) => return Ok(v),
            State::Failed => return Err(secondary(use_span)),
            State::InProgress => {
                let b = &self.bindings[id];
                self.errors.push(
                    Diagnostic::error(
                        Code::E0207,
                        format!("`{}` is defined in terms of itself", b.name),
                    )
                    .at(b.span, "this definition depends on itself")
                    .hint(
                        "break the cycle: give one of these names a value that does not refer back",
                    ),
                );
                self.bindings[id].state = State::Failed;
                return Err(secondary(use_span));
            }
            State::Pending => {}
        }
        if let Some((ty, _)) = &self.bindings[id].ty {
            if ty.is_reference() {
                let b = &self.bindings[id];
                return Err(Diagnostic::error(Code::E0222, format!("`{}` is a {}, not a value", b.name, ty.name()))
                    .at(use_span, "used as a value here")
                    .hint("markers and bodies go in joint and load declarations; use their properties (`body.mass`) in expressions"));
            }
        }
        let Some(expr) = self.bindings[id].expr.clone() else {
            self.bindings[id].state = State::Failed;
            return Err(secondary(use_span));
        };
        self.bindings[id].state = State::InProgress;
        let scope = self.bindings[id].scope;
        // A definition that uses another evaluates it first: a chain of them declared in
        // reverse is as deep as it is long. The stack grows on the heap as it needs, up to
        // MAX_NESTED definitions.
        self.nested += 1;
        let value = if self.nested > MAX_NESTED {
            Err(Diagnostic::error(
                Code::E0207,
                format!("definitions nest more than {MAX_NESTED} deep"),
            )
            .at(self.bindings[id].span, "the innermost")
            .hint("a value uses one that uses another, and so on: shorten the chain, e.g. with a `for` loop or by writing values directly"))
        } else {
            stacker::maybe_grow(256 * 1024, 8 * 1024 * 1024, || self.eval_in(scope, &expr))
        };
        self.nested -= 1;
        let result = value.and_then(|v| self.check_binding(id, v, &expr));
        match result {
            Ok(v) => {
                self.bindings[id].state = State::Done(v.clone());
                Ok(v)
            }
            Err(e) => {
                if !is_secondary(&e) {
                    let e = self.trace(scope, e);
                    self.errors.push(e);
                }
                self.bindings[id].state = State::Failed;
                Err(secondary(use_span))
            }
        }
    }

    /// Applies `--set` and the declared type to a freshly evaluated binding.
    fn check_binding(&mut self, id: BindingId, v: Value, expr: &Expr) -> Result<Value, Diagnostic> {
        let b = &self.bindings[id];
        if b.kind == BindingKind::Param {
            if let Value::Signal { .. } = v {
                return Err(Diagnostic::error(
                    Code::E0401,
                    format!("param `{}` varies in time", b.name),
                )
                .at(expr.span, "depends on `t`")
                .hint(format!(
                    "params are constants; declare it as `function {} = ...`",
                    b.name
                )));
            }
            if let Some(set) = b.set.clone() {
                let name = b.name.clone();
                let scope = b.scope;
                let given = self.eval_in(scope, &set)?;
                return match given {
                    // A bare number given with --set is read in SI units of the declared dimension.
                    g if g.dim().is_none() && !v.dim().is_none() => Ok(g.with_dim(v.dim())),
                    g if g.dim() == v.dim() && std::mem::discriminant(&g) == std::mem::discriminant(&v) => Ok(g),
                    g => Err(Diagnostic::error(Code::E0202, format!("`--set {name}` has the wrong dimension"))
                        .at(set.span, format!("this is {}", g.dim().describe()))
                        .hint(format!("`{name}` is {}; give a plain number in SI units or a value with matching units", v.dim().describe()))),
                };
            }
        }
        if let Some((ty, tspan)) = b.ty {
            if let Err(found) = ty.accepts(&v) {
                let comp = b.component.clone().unwrap_or_default();
                let name = b.name.clone();
                let mut d = Diagnostic::error(
                    Code::E0215,
                    format!("argument `{name}` of `{comp}` must be {}", ty.describe()),
                )
                .at(expr.span, format!("this is {found}"));
                if let Some((span, how)) = self.definition(b.scope, expr) {
                    d = d.at(span, format!("{how} as {found}"));
                }
                return Err(d
                    .at(tspan, format!("declared here as `{name}: {}`", ty.name()))
                    .hint(ty.example()));
            }
            if let (ParamType::Scalar(q), Value::Scalar { value, .. }) = (ty, &v) {
                if q == crate::model::eval::units::ANGLE {
                    let what = format!(
                        "argument `{}` of `{}`",
                        b.name,
                        b.component.clone().unwrap_or_default()
                    );
                    let scope = b.scope;
                    if let Some(d) = self.bare_angle(scope, expr, Some(*value), &what) {
                        let d = self.trace(scope, d);
                        self.errors.push(d);
                    }
                }
            }
            if let ParamType::Direction = ty {
                if let Value::Vector { value, .. } = v {
                    let n =
                        (value[0] * value[0] + value[1] * value[1] + value[2] * value[2]).sqrt();
                    return Ok(Value::Vector {
                        value: value.map(|x| x / n),
                        dim: Dim::NONE,
                    });
                }
            }
        }
        Ok(v)
    }

    /// The expression of property `prop` of a declaration, if written.
    pub fn decl_prop(&self, d: DeclId, prop: &str) -> Option<Expr> {
        match &*self.decls[d].item {
            Item::Entity { block, value, .. } => {
                if prop == "value" {
                    if let Some(v) = value {
                        return Some(v.clone());
                    }
                }
                block
                    .as_ref()?
                    .props
                    .iter()
                    .find(|p| p.name.name == prop)
                    .and_then(|p| match &p.value {
                        PropValue::Expr(e) => Some(e.clone()),
                        PropValue::Block(_) => None,
                    })
            }
            Item::Joint { block, .. } => {
                block
                    .props
                    .iter()
                    .find(|p| p.name.name == prop)
                    .and_then(|p| match &p.value {
                        PropValue::Expr(e) => Some(e.clone()),
                        PropValue::Block(_) => None,
                    })
            }
            _ => None,
        }
    }
}

/// Raised where a failure has been reported already.
const SECONDARY: &str = "(reported already)";

pub fn secondary(span: Span) -> Diagnostic {
    Diagnostic::error(Code::E0201, SECONDARY).at(span, "")
}

pub fn is_secondary(d: &Diagnostic) -> bool {
    d.message == SECONDARY
}
