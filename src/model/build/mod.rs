//! Building the model: elaborate the files, then evaluate every declaration into bodies,
//! beams, joints, springs and loads, then check the topology and number the unknowns.
//! Every error found is reported; the model is returned only if there are none.
//!
//! Contract: turns the elaborated scopes into a `Model` of SI values, reporting every error once;
//! must not know integrators, the runtime or faer, nor read files (a `Loader` supplies module texts).

mod beams;
mod bodies;
mod center_of_mass;
mod connect;
mod curve;
mod distributed;
mod exact;
mod geometry;
mod initial;
mod joints;
mod markers;
mod output_calls;
mod outputs;
mod probes;
mod sections;
mod solve;
mod stations;
mod unused;
mod values;

pub use exact::channel_dim;
pub(super) use unused::written_names;
use values::unit_hint;

use crate::diagnostics::{did_you_mean, merge_repeats, Code, Diagnostic, Sink};
use crate::model::eval::units::Dim;
use crate::model::eval::Value;
use crate::model::scope::elaborate::{Elaborated, Elaborator};
use crate::model::scope::env::{is_secondary, BindingKind, Env, Named, ScopeId};
use crate::model::*;
use crate::source::SourceMap;
use crate::syntax::ast::{self, Block, Expr, Item, MarkerRef};

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
    Distributed(usize),
    Mass,
    Geometry,
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
    pub distributed: Vec<DistributedLoad>,
    pub geometry: Vec<Geometry>,
    /// Set while a distributed load's value is built: the only place `span` may appear.
    pub span_allowed: bool,
    /// `beam NAME rigid` builds the elastic beam ([`Overrides::elastic`]).
    pub elastic: bool,
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
    "distributed_force",
    "distributed_torque",
    "concentrated_mass",
    "cylinder",
    "box",
    "sphere",
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
    // Where the header is, or belongs.
    let header = match &out.header {
        Some((_, _, span)) => *span,
        None => {
            // The first line with text: the header belongs before it.
            let text = sources.text(file.span.source);
            let from = file.span.start as usize;
            let rest = text.get(from..).unwrap_or("");
            let start = from + (rest.len() - rest.trim_start().len());
            let line = text[start..].lines().next().unwrap_or("").trim_end();
            let at = Span::new(file.span.source, start, start + line.len());
            let insert_at = Span {
                end: at.start,
                ..at
            };
            sink.push(
                Diagnostic::error(Code::E0103, "the file has no `model` header")
                    .at(at, "expected `model NAME \"title\"` before this")
                    .hint("begin the file with `model NAME \"what it is\"`"),
            );
            insert_at
        }
    };
    let mut b = Builder::new(env, sink);
    b.elastic = overrides.elastic;
    let params = b.params(top);
    let gravity = match &out.gravity {
        Some((g, _)) => b
            .vector(top, g, Dim::ACCELERATION, "gravity")
            .unwrap_or([0.0; 3]),
        None => [0.0; 3],
    };
    b.declarations(&out);
    let outputs = b.outputs(&out.outputs);
    let exact = b.exacts(&out.exacts, &outputs);
    // A missing solve block is reported at the header (or where it belongs).
    let solve = b.solve(out.solve.as_ref(), &overrides.solve, top, header);
    b.finish(file, &out);
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
        distributed: b.distributed,
        geometry: b.geometry,
        outputs,
        exact,
        solve: solve?,
        dofs: DofMap::default(),
        redundant: Vec::new(),
        surplus: 0,
    };
    (model.redundant, model.surplus) = topology::check(&model, b.sink);
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

impl<'s> Builder<'s> {
    fn new(env: Env, sink: &'s mut Sink) -> Builder<'s> {
        Builder {
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
            distributed: Vec::new(),
            geometry: Vec::new(),
            span_allowed: false,
            elastic: false,
            body_decl: Vec::new(),
            beam_decl: Vec::new(),
        }
    }

    /// The top-level params' values, in the order written (evaluating them marks nothing
    /// used).
    fn params(&mut self, top: ScopeId) -> Vec<(String, Value)> {
        let env = &mut self.env;
        let mut params = Vec::new();
        let mut ids: Vec<usize> = (0..env.bindings.len())
            .filter(|&i| env.bindings[i].kind == BindingKind::Param && env.bindings[i].scope == top)
            .collect();
        ids.sort_by_key(|&i| env.bindings[i].span.start);
        for id in ids {
            let used = env.bindings[id].used;
            let span = env.bindings[id].span;
            if let Ok(v) = env.value_of(id, span) {
                params.push((env.bindings[id].name.clone(), v));
            }
            env.bindings[id].used = used;
        }
        params
    }

    /// Builds the declarations: sections, then bodies and beams, then what attaches to them;
    /// joints after everything they can attach to; then the initial motions.
    fn declarations(&mut self, out: &Elaborated) {
        let views: Vec<Option<View>> = (0..self.env.decls.len()).map(|d| self.view(d)).collect();
        let order = |v: &View| match v.kind.name.as_str() {
            "section" => 0,
            "ground" | "point_mass" | "rigid" | "rigid_rod" | "beam" => 1,
            "concentrated_mass" => 2,
            _ => 3,
        };
        for pass in 0..4 {
            for v in views.iter().flatten() {
                if order(v) == pass {
                    self.entity(v);
                }
            }
        }
        for d in 0..self.env.decls.len() {
            if let Item::Joint { .. } = &*self.env.decls[d].item {
                self.joint(d);
            }
        }
        for (item, scope) in &out.initials {
            self.initial(item, *scope);
        }
    }

    /// The errors evaluation left in the scopes, a model with no bodies (E0304), and the
    /// warnings for what is never used.
    fn finish(&mut self, file: &ast::File, out: &Elaborated) {
        for e in std::mem::take(&mut self.env.errors) {
            self.sink.push(e);
        }
        if self.bodies.is_empty()
            && self.beams.is_empty()
            && self.sink.diagnostics.iter().all(|d| !d.is_error())
        {
            self.sink.push(
                Diagnostic::error(Code::E0304, "the model has no bodies")
                    .at(file.items[0].span(), "in this model")
                    .hint(
                        "declare a body, e.g. `point_mass bob { mass = 1 kg, at = (0, -1, 0) m }`",
                    ),
            );
        }
        for e in std::mem::take(&mut self.env.errors) {
            self.sink.push(e);
        }
        self.excuse_failed(&file.items, file.span.source);
        self.unused(file.span.source, out);
    }

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
            "distributed_force" | "distributed_torque" => self.distributed_load(v),
            "concentrated_mass" => self.concentrated_mass(v),
            "cylinder" | "box" | "sphere" => self.geometry(v),
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
