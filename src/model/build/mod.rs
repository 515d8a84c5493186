//! Building the model: elaborate the files, then evaluate every declaration into bodies,
//! beams, joints, springs and loads, then check the topology and number the unknowns.
//! Every error found is reported; the model is returned only if there are none.

mod beams;
mod bodies;
mod center_of_mass;
mod connect;
mod exact;
mod output_calls;
mod outputs;

pub use exact::channel_dim;

use crate::diagnostics::{did_you_mean, merge_repeats, Code, Diagnostic, Sink};
use crate::model::eval::units::{Dim, Quantity};
use crate::model::eval::Value;
use crate::model::scope::elaborate::{unused_bindings, Elaborator};
use crate::model::scope::env::{is_secondary, BindingKind, Env, Named, ScopeId};
use crate::model::*;
use crate::source::SourceMap;
use crate::syntax::ast::{self, Block, Expr, Item, MarkerRef, Prop, PropValue};
use std::collections::HashMap;

/// What a declaration became.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Built {
    Ground(usize),
    Body(usize),
    Beam(usize),
    Section(usize),
    Joint(usize),
    Spring(usize),
    Load(usize),
    Mass,
}

/// The parts of an entity declaration.
pub(super) struct View {
    pub decl: usize,
    pub kind: ast::Ident,
    pub name: String,
    pub name_span: Span,
    pub flags: Vec<ast::Ident>,
    pub markers: Vec<MarkerRef>,
    pub on: Option<MarkerRef>,
    pub value: Option<Expr>,
    pub block: Option<Block>,
    pub span: Span,
    pub scope: ScopeId,
}

pub(super) struct Builder<'s> {
    pub env: Env,
    pub sink: &'s mut Sink,
    pub grounds: Vec<Ground>,
    pub bodies: Vec<Body>,
    pub beams: Vec<Beam>,
    pub sections: Vec<Section>,
    pub joints: Vec<Joint>,
    pub springs: Vec<Spring>,
    pub loads: Vec<Load>,
    pub built: Vec<Option<Built>>,
    /// Declaration spans of bodies and beams (for topology messages).
    pub body_decl: Vec<usize>,
    pub beam_decl: Vec<usize>,
}

/// The kinds of entity declarations, for "did you mean".
pub(super) const KINDS: &[&str] = &[
    "ground",
    "point_mass",
    "rigid",
    "rigid_rod",
    "beam",
    "section",
    "spring",
    "damper",
    "torsional_spring",
    "torsional_damper",
    "force",
    "torque",
    "concentrated_mass",
];

/// Builds and checks the model. Every error found is pushed to `sink`, each mistake once (a
/// loop's repeats merged, see [`merge_repeats`]); `None` if any.
pub fn build(
    file: &ast::File,
    file_name: &str,
    overrides: &Overrides,
    sources: &mut SourceMap,
    loader: &dyn Loader,
    sink: &mut Sink,
) -> Option<Model> {
    let model = build_model(file, file_name, overrides, sources, loader, sink);
    sink.diagnostics = merge_repeats(std::mem::take(&mut sink.diagnostics));
    model
}

fn build_model(
    file: &ast::File,
    file_name: &str,
    overrides: &Overrides,
    sources: &mut SourceMap,
    loader: &dyn Loader,
    sink: &mut Sink,
) -> Option<Model> {
    if file.items.is_empty() {
        sink.push(
            Diagnostic::error(Code::E0102, "the model file is empty")
                .at(file.span, "nothing declared here")
                .hint("start with `model NAME \"title\"`, then declare a ground, bodies, joints, outputs and a `solve` block (see models/pendulum.mbd)"),
        );
        return None;
    }
    let mut el = Elaborator::new(sources, loader);
    el.sets = overrides.sets.clone();
    let top = el.main(&file.items, file_name);
    let (env, out, errors) = el.finish();
    for e in errors {
        sink.push(e);
    }
    if out.header.is_none() {
        sink.push(
            Diagnostic::error(Code::E0103, "the file has no `model` header")
                .at(
                    Span {
                        end: file.span.start,
                        ..file.span
                    },
                    "expected `model NAME \"title\"` here",
                )
                .hint("begin the file with `model NAME \"what it is\"`"),
        );
    }
    let mut b = Builder {
        built: vec![None; env.decls.len()],
        env,
        sink,
        grounds: Vec::new(),
        bodies: Vec::new(),
        beams: Vec::new(),
        sections: Vec::new(),
        joints: Vec::new(),
        springs: Vec::new(),
        loads: Vec::new(),
        body_decl: Vec::new(),
        beam_decl: Vec::new(),
    };

    // Params, in the order written.
    let mut params = Vec::new();
    let mut ids: Vec<usize> = (0..b.env.bindings.len())
        .filter(|&i| b.env.bindings[i].kind == BindingKind::Param && b.env.bindings[i].scope == top)
        .collect();
    ids.sort_by_key(|&i| b.env.bindings[i].span.start);
    for id in ids {
        let used = b.env.bindings[id].used;
        let span = b.env.bindings[id].span;
        if let Ok(v) = b.env.value_of(id, span) {
            params.push((b.env.bindings[id].name.clone(), v));
        }
        b.env.bindings[id].used = used;
    }
    let gravity = match &out.gravity {
        Some((g, _)) => b
            .vector(top, g, Dim::ACCELERATION, "gravity")
            .unwrap_or([0.0; 3]),
        None => [0.0; 3],
    };

    // Declarations: sections, then bodies and beams, then what attaches to them.
    let views: Vec<Option<View>> = (0..b.env.decls.len()).map(|d| b.view(d)).collect();
    let order = |v: &View| match v.kind.name.as_str() {
        "section" => 0,
        "ground" | "point_mass" | "rigid" | "rigid_rod" | "beam" => 1,
        "concentrated_mass" => 2,
        _ => 3,
    };
    for pass in 0..4 {
        for v in views.iter().flatten() {
            if order(v) == pass {
                b.entity(v);
            }
        }
    }
    // Joints come after everything they can attach to.
    for d in 0..b.env.decls.len() {
        if let Item::Joint { .. } = &*b.env.decls[d].item {
            b.joint(d);
        }
    }
    for (item, scope) in &out.initials {
        b.initial(item, *scope);
    }
    let outputs = b.outputs(&out.outputs);
    let exact = b.exacts(&out.exacts, &outputs);
    // A missing solve block is reported at the header (or where it belongs).
    let header = match &out.header {
        Some((_, _, span)) => *span,
        None => Span {
            end: file.span.start,
            ..file.span
        },
    };
    let solve = b.solve(out.solve.as_ref(), overrides, top, file.span, header);

    for e in std::mem::take(&mut b.env.errors) {
        b.sink.push(e);
    }
    if b.bodies.is_empty() && b.beams.is_empty() && b.sink.diagnostics.iter().all(|d| !d.is_error())
    {
        b.sink.push(
            Diagnostic::error(Code::E0304, "the model has no bodies")
                .at(file.items[0].span(), "in this model")
                .hint("declare a body, e.g. `point_mass bob { mass = 1 kg, at = (0, -1, 0) m }`"),
        );
    }
    for e in std::mem::take(&mut b.env.errors) {
        b.sink.push(e);
    }
    b.excuse_failed(&file.items, file.span.source);
    b.unused(file.span.source, &out);
    if b.sink.has_errors() {
        return None;
    }
    let (name, title) = out.header.map(|h| (h.0.name, h.1))?;
    let mut model = Model {
        name,
        title,
        params,
        gravity,
        grounds: b.grounds,
        bodies: b.bodies,
        beams: b.beams,
        joints: b.joints,
        springs: b.springs,
        loads: b.loads,
        outputs,
        exact,
        solve: solve?,
        dofs: DofMap::default(),
    };
    topology::check(&model, b.sink);
    if b.sink.has_errors() {
        return None;
    }
    model.dofs = DofMap::new(&model);
    Some(model)
}

/// Checks a library file (components only): its imports, names and parameter types. Returns
/// each component's signature, `name(param: type, ...)`.
pub fn check_library(
    file: &ast::File,
    file_name: &str,
    sources: &mut SourceMap,
    loader: &dyn Loader,
    sink: &mut Sink,
) -> Vec<String> {
    let mut el = Elaborator::new(sources, loader);
    let scope = el.library(&file.items, file_name);
    for e in std::mem::take(&mut el.errors) {
        sink.push(e);
    }
    let mut out: Vec<(u32, String)> = el.env.scopes[scope]
        .names
        .values()
        .filter_map(|n| match n {
            Named::Component(c, _) if c.span.source == file.span.source => {
                let params: Vec<String> = c
                    .params
                    .iter()
                    .map(|p| format!("{}: {}", p.name.name, p.ty.name))
                    .collect();
                Some((
                    c.span.start,
                    format!("{}({})", c.name.name, params.join(", ")),
                ))
            }
            _ => None,
        })
        .collect();
    out.sort();
    out.into_iter().map(|x| x.1).collect()
}

impl Builder<'_> {
    fn view(&self, d: usize) -> Option<View> {
        let decl = &self.env.decls[d];
        match &*decl.item {
            Item::Entity {
                kind,
                flags,
                markers,
                on,
                value,
                block,
                span,
                ..
            } => Some(View {
                decl: d,
                kind: kind.clone(),
                name: decl.name.clone(),
                name_span: decl.name_span,
                flags: flags.clone(),
                markers: markers.clone(),
                on: on.clone(),
                value: value.clone(),
                block: block.clone(),
                span: *span,
                scope: decl.scope,
            }),
            _ => None,
        }
    }

    /// Reports an error raised while building something declared in `scope`.
    pub fn error(&mut self, scope: ScopeId, d: Diagnostic) {
        if !is_secondary(&d) {
            let d = self.env.trace(scope, d);
            self.sink.push(d);
        }
    }

    fn entity(&mut self, v: &View) {
        let built = match v.kind.name.as_str() {
            "ground" => self.ground(v),
            "point_mass" => self.point_mass(v),
            "rigid" => self.rigid(v),
            "rigid_rod" => self.rigid_rod(v),
            "beam" => self.beam(v),
            "section" => self.section_decl(v),
            "spring" | "damper" | "torsional_spring" | "torsional_damper" => self.spring(v),
            "force" | "torque" => self.load(v),
            "concentrated_mass" => self.concentrated_mass(v),
            other => {
                let hint = match did_you_mean(other, KINDS.iter().copied()) {
                    Some(s) => format!("did you mean `{s}`? Declarations: {}", KINDS.join(", ")),
                    None => format!(
                        "declarations: {}; joints are written `joint NAME = KIND(a, b)`",
                        KINDS.join(", ")
                    ),
                };
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0211, format!("unknown declaration kind `{other}`"))
                        .at(v.kind.span, "not a kind of declaration")
                        .hint(hint),
                );
                None
            }
        };
        self.built[v.decl] = built;
    }

    /// Whether a body or beam named `name`, or declared inside the instance named `name`
    /// (`rotor`), failed to build. What needs those bodies stays silent then: their own errors
    /// have been reported, and "declares no bodies" would be a second error for one mistake.
    pub fn failed_within(&self, name: &str) -> bool {
        self.env.decls.iter().enumerate().any(|(d, decl)| {
            self.built[d].is_none()
                && decl
                    .item_kind()
                    .is_some_and(|k| matches!(k, "point_mass" | "rigid" | "rigid_rod" | "beam"))
                && (decl.name == name || decl.name.starts_with(&format!("{name}.")))
        })
    }

    /// Checks the parts a declaration has against those its kind takes.
    pub fn shape(
        &mut self,
        v: &View,
        markers: usize,
        on: bool,
        value: bool,
        flags: &[&str],
        example: &str,
    ) -> bool {
        let mut ok = true;
        let kind = v.kind.name.clone();
        let mut bad = |this: &mut Self, span: Span, what: String| {
            ok = false;
            this.error(
                v.scope,
                Diagnostic::error(Code::E0224, format!("`{kind}` {what}"))
                    .at(span, "here")
                    .hint(format!("write it as `{example}`")),
            );
        };
        if v.markers.len() != markers {
            let span = v.markers.first().map(|m| m.span).unwrap_or(v.name_span);
            let what = match markers {
                0 => "does not connect markers".to_string(),
                n => format!("connects {n} markers, found {}", v.markers.len()),
            };
            bad(self, span, what);
        }
        match (&v.on, on) {
            (Some(m), false) => bad(self, m.span, "takes no `on` marker".to_string()),
            (None, true) => bad(self, v.name_span, "needs `on MARKER`".to_string()),
            _ => {}
        }
        match (&v.value, value) {
            (Some(e), false) => bad(self, e.span, "takes no `= value`".to_string()),
            (None, true) => bad(self, v.name_span, "needs `= value`".to_string()),
            _ => {}
        }
        for f in &v.flags {
            if !flags.contains(&f.name.as_str()) {
                bad(self, f.span, format!("takes no flag `{}`", f.name));
            }
        }
        ok
    }

    pub fn has_flag(v: &View, flag: &str) -> bool {
        v.flags.iter().any(|f| f.name == flag)
    }

    /// Splits a block by property name, reporting unknown and repeated properties.
    pub fn props(
        &mut self,
        scope: ScopeId,
        block: Option<&Block>,
        known: &[&'static str],
        of: &str,
    ) -> HashMap<&'static str, Prop> {
        let mut out: HashMap<&'static str, Prop> = HashMap::new();
        let Some(block) = block else {
            return out;
        };
        for p in &block.props {
            match known.iter().find(|k| **k == p.name.name) {
                Some(&k) => {
                    if let Some(first) = out.get(k) {
                        let d =
                            Diagnostic::error(Code::E0203, format!("property `{k}` is set twice"))
                                .at(p.name.span, "second value")
                                .at(first.name.span, "first value")
                                .hint("set each property once");
                        self.error(scope, d);
                    } else {
                        out.insert(k, p.clone());
                    }
                }
                None => {
                    let hint = match did_you_mean(&p.name.name, known.iter().copied()) {
                        Some(s) => format!("did you mean `{s}`? {of} takes: {}", known.join(", ")),
                        None => format!("{of} takes: {}", known.join(", ")),
                    };
                    let d = Diagnostic::error(
                        Code::E0205,
                        format!("{of} has no property `{}`", p.name.name),
                    )
                    .at(p.name.span, "unknown property")
                    .hint(hint);
                    self.error(scope, d);
                }
            }
        }
        out
    }

    /// A property's expression; a `{ ... }` block where a value belongs is an error.
    pub fn expr<'p>(&mut self, scope: ScopeId, p: Option<&'p Prop>) -> Option<&'p Expr> {
        let p = p?;
        match &p.value {
            PropValue::Expr(e) => Some(e),
            PropValue::Block(b) => {
                self.error(
                    scope,
                    Diagnostic::error(
                        Code::E0209,
                        format!("`{}` takes a value, not a block", p.name.name),
                    )
                    .at(b.span, "a block")
                    .hint(format!("write `{} = value`", p.name.name)),
                );
                None
            }
        }
    }

    /// A required property's expression; reports it missing (E0206) when it is not written.
    pub fn required<'p>(
        &mut self,
        scope: ScopeId,
        p: &'p HashMap<&'static str, Prop>,
        key: &str,
        at: Span,
        of: &str,
        example: &str,
    ) -> Option<&'p Expr> {
        match p.get(key) {
            Some(prop) => self.expr(scope, Some(prop)),
            None => {
                self.missing(scope, at, key, of, example);
                None
            }
        }
    }

    pub fn missing(&mut self, scope: ScopeId, at: Span, prop: &str, of: &str, example: &str) {
        self.error(
            scope,
            Diagnostic::error(Code::E0206, format!("{of} needs `{prop}`"))
                .at(at, format!("`{prop}` missing"))
                .hint(format!("add `{prop} = {example}`")),
        );
    }

    pub fn value(&mut self, scope: ScopeId, e: &Expr) -> Option<Value> {
        match self.env.eval_in(scope, e) {
            Ok(v) => Some(v),
            Err(d) => {
                self.error(scope, d);
                None
            }
        }
    }

    /// Evaluates `e` as a constant of the given shape and dimension.
    fn typed(
        &mut self,
        scope: ScopeId,
        e: &Expr,
        want: Quantity,
        what: &str,
        vector: bool,
    ) -> Option<Value> {
        let v = self.value(scope, e)?;
        let error = match (&v, vector) {
            (Value::Signal { .. }, _) => Diagnostic::error(
                Code::E0401,
                format!("{what} must be a constant, found a function of time"),
            )
            .at(e.span, "this varies in time"),
            (Value::Scalar { .. }, true)
            | (Value::Vector { .. }, false)
            | (Value::Rotation { .. }, _) => {
                let shape = if vector {
                    "a vector `(x, y, z)`"
                } else {
                    "a scalar"
                };
                Diagnostic::error(
                    Code::E0209,
                    format!("{what} must be {shape}, found {}", v.kind_name()),
                )
                .at(e.span, format!("this is {}", v.kind_name()))
            }
            _ if v.dim() != want.dim => self.mismatch(scope, e, want, v.dim(), what),
            _ => return Some(v),
        };
        let hint = if let Value::Signal { .. } = v {
            "only loads, prescribed motions and functions may depend on `t`".to_string()
        } else if vector && !matches!(v, Value::Vector { .. }) {
            format!("write `(x, y, z)`; {}", unit_hint(want, vector))
        } else {
            unit_hint(want, vector)
        };
        self.error(scope, error.hint(hint));
        None
    }

    /// E0202 for `e`, found of dimension `found` where `want` is needed: at the use, and at
    /// the definition of the param or let it names.
    fn mismatch(
        &self,
        scope: ScopeId,
        e: &Expr,
        want: Quantity,
        found: Dim,
        what: &str,
    ) -> Diagnostic {
        let found = found.describe();
        let d = Diagnostic::error(
            Code::E0202,
            format!("{what} must be {}, found {found}", want.describe()),
        )
        .at(e.span, format!("this is {found}"));
        match self.env.definition(scope, e) {
            Some((span, how)) => d.at(span, format!("{how} as {found}")),
            None => d,
        }
    }

    pub fn scalar(
        &mut self,
        scope: ScopeId,
        e: &Expr,
        want: impl Into<Quantity>,
        what: &str,
    ) -> Option<f64> {
        match self.typed(scope, e, want.into(), what, false)? {
            Value::Scalar { value, .. } => Some(value),
            _ => None,
        }
    }

    pub fn vector(
        &mut self,
        scope: ScopeId,
        e: &Expr,
        want: impl Into<Quantity>,
        what: &str,
    ) -> Option<[f64; 3]> {
        match self.typed(scope, e, want.into(), what, true)? {
            Value::Vector { value, .. } => Some(value),
            _ => None,
        }
    }

    /// A non-zero direction, normalised. Any dimension is accepted (`(1, 0, 0)`, `(0, 0, 1) m`).
    pub fn direction(&mut self, scope: ScopeId, e: &Expr, what: &str) -> Option<[f64; 3]> {
        let v = self.value(scope, e)?;
        let Value::Vector { value, .. } = v else {
            self.error(
                scope,
                Diagnostic::error(
                    Code::E0209,
                    format!(
                        "{what} must be a constant direction, found {}",
                        v.kind_name()
                    ),
                )
                .at(e.span, format!("this is {}", v.kind_name()))
                .hint("write an axis such as `z` or `(0, 0, 1)`"),
            );
            return None;
        };
        let n = norm(value);
        if n == 0.0 {
            self.error(
                scope,
                Diagnostic::error(Code::E0303, format!("{what} is a zero vector"))
                    .at(e.span, "has no direction")
                    .hint("give a non-zero axis such as `z` or `(0, 0, 1)`"),
            );
            return None;
        }
        Some(value.map(|x| x / n))
    }

    /// A time function (a constant is a constant function) with the given dimension.
    pub fn signal(
        &mut self,
        scope: ScopeId,
        e: &Expr,
        want: impl Into<Quantity>,
        what: &str,
        vector: bool,
    ) -> Option<Vec<TimeFn>> {
        let want = want.into();
        let v = self.value(scope, e)?;
        let parts = v.parts();
        let count = if vector { 3 } else { 1 };
        match parts {
            Some((p, d)) if p.len() == count && d == want.dim => Some(p),
            Some((p, d)) if p.len() == count => {
                let error = self.mismatch(scope, e, want, d, what);
                self.error(scope, error.hint(unit_hint(want, vector)));
                None
            }
            _ => {
                let shape = if vector {
                    "a vector (x, y, z)"
                } else {
                    "a scalar"
                };
                self.error(
                    scope,
                    Diagnostic::error(
                        Code::E0209,
                        format!("{what} must be {shape}, found {}", v.kind_name()),
                    )
                    .at(e.span, format!("this is {}", v.kind_name()))
                    .hint(unit_hint(want, vector)),
                );
                None
            }
        }
    }

    pub fn rotation(&mut self, scope: ScopeId, e: &Expr, what: &str) -> Option<Mat3> {
        match self.value(scope, e)? {
            Value::Rotation { matrix } => Some(matrix),
            v => {
                self.error(
                    scope,
                    Diagnostic::error(Code::E0209, format!("{what} must be a rotation, found {}", v.kind_name()))
                        .at(e.span, format!("this is {}", v.kind_name()))
                        .hint("write `rotate(axis, angle)`, e.g. `rotate(z, 90 deg)`, or a product of rotations"),
                );
                None
            }
        }
    }

    pub fn integer(&mut self, scope: ScopeId, e: &Expr, what: &str, min: usize) -> Option<usize> {
        let x = self.scalar(scope, e, Dim::NONE, what)?;
        if x.fract() != 0.0 || x < min as f64 || x > 1e9 {
            self.error(
                scope,
                Diagnostic::error(
                    Code::E0213,
                    format!("{what} must be a whole number of at least {min}"),
                )
                .at(e.span, "not allowed here")
                .hint(format!("write an integer such as {}", min.max(1))),
            );
            return None;
        }
        Some(x as usize)
    }

    /// Marks as used every name written in a declaration of the model file that failed (the
    /// innermost item holding a label of an error): a param whose only user failed was not
    /// forgotten, and "never used" would be a second report of one mistake.
    fn excuse_failed(&mut self, items: &[Item], main: crate::source::SourceId) {
        let spans: Vec<Span> = self
            .sink
            .diagnostics
            .iter()
            .filter(|d| d.is_error())
            .flat_map(|d| d.labels.iter().map(|l| l.span))
            .filter(|s| s.source == main)
            .collect();
        if spans.is_empty() {
            return;
        }
        let mut names = std::collections::HashSet::new();
        failed_names(items, &spans, &mut names);
        for b in &mut self.env.bindings {
            if b.span.source == main && names.contains(&b.name) {
                b.used = true;
            }
        }
    }

    /// Warnings for what the model file declares and never uses.
    fn unused(
        &mut self,
        main: crate::source::SourceId,
        out: &crate::model::scope::elaborate::Elaborated,
    ) {
        let mut warnings = Vec::new();
        for b in unused_bindings(&self.env) {
            if b.span.source != main {
                continue;
            }
            let (code, what, hint) = match b.kind {
                BindingKind::Param => (
                    Code::W0201,
                    "param",
                    "remove it, or use it in a property or an output",
                ),
                BindingKind::Let => (Code::W0202, "let", "remove it, or use it"),
                BindingKind::Function => (
                    Code::W0202,
                    "function",
                    "remove it, or use it in a load or a prescribed motion",
                ),
                _ => continue,
            };
            warnings.push(
                Diagnostic::error(code, format!("{what} `{}` is never used", b.name))
                    .at(b.span, "declared here")
                    .hint(hint),
            );
        }
        for (d, decl) in self.env.decls.iter().enumerate() {
            if decl.used || decl.name_span.source != main {
                continue;
            }
            if let Some(Built::Section(_)) = self.built[d] {
                warnings.push(
                    Diagnostic::error(
                        Code::W0202,
                        format!("section `{}` is never used", decl.name),
                    )
                    .at(decl.name_span, "declared here")
                    .hint("remove it, or give it to a beam: `section = NAME`"),
                );
            }
        }
        for (name, span) in &out.local_components {
            let defined = self.env.scopes.iter().any(|s| {
                s.names.get(name).map(|n| matches!(n, Named::Component(c, _) if c.name.span == *span && out.instantiated.contains(&c.span))).unwrap_or(false)
            });
            if !defined {
                warnings.push(
                    Diagnostic::error(
                        Code::W0202,
                        format!("component `{name}` is never instantiated"),
                    )
                    .at(*span, "declared here")
                    .hint(format!(
                        "remove it, or instantiate it: `NAME = {name}(...)`"
                    )),
                );
            }
        }
        warnings.sort_by_key(|d| d.labels.first().map(|l| l.span.start));
        for w in warnings {
            self.sink.push(w);
        }
    }
}

/// Collects the names written in the innermost items that contain one of `spans`; whether
/// any item did.
fn failed_names(
    items: &[Item],
    spans: &[Span],
    names: &mut std::collections::HashSet<String>,
) -> bool {
    let mut any = false;
    for item in items {
        let outer = item.span();
        if !spans
            .iter()
            .any(|s| outer.start <= s.start && s.end <= outer.end)
        {
            continue;
        }
        any = true;
        let inside = match item {
            Item::For { items, .. } => failed_names(items, spans, names),
            Item::If {
                then, otherwise, ..
            } => failed_names(then, spans, names) | failed_names(otherwise, spans, names),
            Item::Component(c) => failed_names(&c.items, spans, names),
            _ => false,
        };
        if !inside {
            names.extend(written_names(item));
        }
    }
    any
}

/// Every name an item writes (declared or used), read from its syntax tree.
pub(super) fn written_names(item: &Item) -> Vec<String> {
    let Ok(text) = serde_json::to_string(item) else {
        return Vec::new();
    };
    text.split("\"name\":\"")
        .skip(1)
        .filter_map(|part| part.split('"').next())
        .map(str::to_string)
        .collect()
}

/// "expected a length [m], e.g. `0.5 m`" (a vector of it: "`(0, 0, 0.5) m`").
pub(super) fn unit_hint(want: Quantity, vector: bool) -> String {
    let example = match (vector, want.dim.is_none()) {
        (false, _) => want.example(),
        (true, true) => "`(1, 0, 0)`".to_string(),
        (true, false) => {
            let e = want.example();
            // `0.5 m` -> `(0, 0, 0.5) m`
            let inner = e.trim_matches('`');
            match inner.split_once(' ') {
                Some((x, unit)) => format!("`(0, 0, {x}) {unit}`"),
                None => format!("`(0, 0, {inner})`"),
            }
        }
    };
    format!("expected {}, e.g. {example}", want.describe())
}

pub(super) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(super) fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub(super) fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    a.map(|x| x * s)
}

pub(super) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(super) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
