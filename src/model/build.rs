//! Building the model from the AST: names, properties, units, topology.

use super::eval::{eval, Value};
use super::params::{is_secondary, ParamTable};
use super::units::Dim;
use super::*;
use crate::diagnostics::{did_you_mean, Code, Diagnostic, Sink};
use crate::syntax::ast::{self, Expr, ExprKind, Item, Prop};
use std::collections::HashMap;

#[derive(Clone, Copy, PartialEq, Eq)]
enum Entity {
    Ground(usize),
    Body(usize),
    Joint(usize),
}

struct Builder<'a> {
    sink: &'a mut Sink,
    params: ParamTable,
    entities: HashMap<String, (Entity, Span)>,
}

/// Builds and checks the model. Every error found is pushed to `sink`; `None` if any.
pub fn build(file: &ast::File, overrides: &Overrides, sink: &mut Sink) -> Option<Model> {
    let mut b = Builder {
        sink,
        params: ParamTable::new(),
        entities: HashMap::new(),
    };
    if file.items.is_empty() {
        b.sink.push(
            Diagnostic::error(Code::E0102, "the model file is empty")
                .at(file.span, "nothing declared here")
                .hint("start with `model NAME \"title\"`, then declare a ground, bodies, joints, outputs and a `solve` block (see models/pendulum.mbd)"),
        );
        return None;
    }

    // Pass 1: declare every name, so that order does not matter.
    let mut header: Option<(String, Option<String>)> = None;
    let mut grounds = Vec::new();
    let mut body_items = Vec::new();
    let mut joint_items = Vec::new();
    let mut gravity_item: Option<&Expr> = None;
    let mut solve_item: Option<&Item> = None;
    let mut output_items = Vec::new();
    for item in &file.items {
        match item {
            Item::Model { name, title, span } => {
                if header.is_some() {
                    b.sink.push(
                        Diagnostic::error(Code::E0103, "a second `model` header")
                            .at(*span, "repeated here")
                            .hint("one file describes one model; remove this header"),
                    );
                } else {
                    header = Some((name.name.clone(), title.clone()));
                }
            }
            Item::Param { name, value, span } => {
                if b.taken(&name.name, name.span)
                    || !b.params.declare(&name.name, *span, value.clone())
                {
                    let first = b.first_span(&name.name);
                    b.duplicate(name, first);
                }
            }
            Item::Gravity { value, span } => {
                if gravity_item.is_some() {
                    b.sink.push(
                        Diagnostic::error(Code::E0203, "gravity is declared twice")
                            .at(*span, "second declaration")
                            .hint("declare `gravity` once"),
                    );
                }
                gravity_item = Some(value);
            }
            Item::Ground { name, span } => {
                if b.declare(name, Entity::Ground(grounds.len())) {
                    grounds.push(Ground {
                        name: name.name.clone(),
                        span: *span,
                    });
                }
            }
            Item::PointMass { name, props, span } => {
                if b.declare(name, Entity::Body(body_items.len())) {
                    body_items.push((name, props, *span));
                }
            }
            Item::Joint {
                name,
                kind,
                markers,
                props,
                span,
            } => {
                if b.declare(name, Entity::Joint(joint_items.len())) {
                    joint_items.push((name, kind, markers, props, *span));
                }
            }
            Item::Output { items, .. } => output_items.extend(items.iter()),
            Item::Solve { span, .. } => {
                if solve_item.is_some() {
                    b.sink.push(Diagnostic::error(Code::E0203, "a second `solve` block").at(*span, "repeated here").hint("one model has one `solve` block; override it from the command line with --dt, --until, --alpha"));
                } else {
                    solve_item = Some(item);
                }
            }
        }
    }
    if header.is_none() {
        b.sink.push(
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

    // --set overrides name params only.
    for (name, expr) in &overrides.sets {
        if !b.params.set_override(&name.name, expr.clone()) {
            let names = b.params.names();
            let hint = match did_you_mean(&name.name, names.iter().map(|s| s.as_str())) {
                Some(s) => format!("did you mean `{s}`? Only params can be set"),
                None if names.is_empty() => "this model declares no params".to_string(),
                None => format!("the model's params are: {}", names.join(", ")),
            };
            b.sink.push(
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

    let params = b.params.evaluate_all();
    let gravity = gravity_item
        .and_then(|g| b.vector(g, Dim::ACCELERATION, "gravity"))
        .unwrap_or([0.0; 3]);

    let bodies: Vec<Option<Body>> = body_items
        .iter()
        .map(|(n, p, s)| b.point_mass(n, p, *s))
        .collect();
    let joints: Vec<Option<Joint>> = joint_items
        .iter()
        .map(|(n, k, m, p, s)| b.joint(n, k, m, p, *s, &body_items))
        .collect();
    let outputs = b.outputs(&output_items);
    let solve = b.solve(solve_item, overrides, file.span);

    if body_items.is_empty() {
        b.sink.push(
            Diagnostic::error(Code::E0304, "the model has no bodies")
                .at(file.items[0].span(), "in this model")
                .hint("declare a body, e.g. `point_mass bob { mass = 1 kg, at = (0, -1, 0) m }`"),
        );
    }
    for e in std::mem::take(&mut b.params.errors) {
        b.sink.push(e);
    }
    for (name, span) in b.params.unused() {
        b.sink.push(
            Diagnostic::error(Code::W0201, format!("param `{name}` is never used"))
                .at(span, "declared here")
                .hint("remove it, or use it in a property or an output"),
        );
    }
    if b.sink.has_errors() {
        return None;
    }
    let bodies: Vec<Body> = bodies.into_iter().collect::<Option<_>>()?;
    let mut joints: Vec<Joint> = joints.into_iter().collect::<Option<_>>()?;
    for j in &mut joints {
        let JointKind::Distance { length } = &mut j.kind;
        let d = norm(sub(
            initial_position(&j.markers[1], &bodies),
            initial_position(&j.markers[0], &bodies),
        ));
        if length.is_nan() {
            if d < 1e-12 {
                b.sink.push(Diagnostic::error(Code::E0303, format!("distance joint `{}` starts with coincident markers", j.name)).at(j.span, "zero initial distance, no `length` given").hint("give `length = ...`, or place the bodies apart: a zero-length link has no direction"));
                return None;
            }
            *length = d;
        }
    }
    let (name, title) = header?;
    let dofs = DofMap::new(&bodies, &joints);
    Some(Model {
        name,
        title,
        params,
        gravity,
        grounds,
        bodies,
        joints,
        outputs,
        solve: solve?,
        dofs,
    })
}

impl Builder<'_> {
    fn taken(&self, name: &str, _span: Span) -> bool {
        self.entities.contains_key(name)
    }

    fn first_span(&self, name: &str) -> Option<Span> {
        self.entities
            .get(name)
            .map(|e| e.1)
            .or_else(|| self.params.span_of(name))
    }

    fn duplicate(&mut self, name: &ast::Ident, first: Option<Span>) {
        let mut d = Diagnostic::error(Code::E0203, format!("`{}` is declared twice", name.name))
            .at(name.span, "second declaration");
        if let Some(f) = first {
            d = d.at(f, "first declared here");
        }
        self.sink
            .push(d.hint("every param, ground, body and joint needs its own name"));
    }

    fn declare(&mut self, name: &ast::Ident, e: Entity) -> bool {
        if self.entities.contains_key(&name.name) || self.params.span_of(&name.name).is_some() {
            let first = self.first_span(&name.name);
            self.duplicate(name, first);
            return false;
        }
        self.entities.insert(name.name.clone(), (e, name.span));
        true
    }

    fn report(&mut self, d: Diagnostic) {
        if !is_secondary(&d) {
            self.sink.push(d);
        }
    }

    fn value(&mut self, e: &Expr) -> Option<Value> {
        match eval(e, &mut self.params) {
            Ok(v) => Some(v),
            Err(d) => {
                self.report(d);
                None
            }
        }
    }

    /// Evaluates `e` and checks its shape (vector or scalar) and dimension.
    fn typed(&mut self, e: &Expr, dim: Dim, what: &str, vector: bool) -> Option<Value> {
        let v = self.value(e)?;
        let is_vector = matches!(v, Value::Vector { .. });
        let error = if is_vector != vector {
            let (want, found) = if vector {
                ("a vector `(x, y, z)`", "scalar")
            } else {
                ("a scalar", "vector")
            };
            Diagnostic::error(
                Code::E0209,
                format!("{what} must be {want}, found a {found}"),
            )
            .at(e.span, format!("this is a {found}"))
        } else if v.dim() != dim {
            Diagnostic::error(
                Code::E0202,
                format!(
                    "{what} must be a {}, found a {}",
                    dim.describe(),
                    v.dim().describe()
                ),
            )
            .at(e.span, format!("this is a {}", v.dim().describe()))
        } else {
            return Some(v);
        };
        let hint = if vector && !is_vector {
            format!("write `(x, y, z)`; {}", unit_hint(dim))
        } else {
            unit_hint(dim)
        };
        self.sink.push(error.hint(hint));
        None
    }

    fn scalar(&mut self, e: &Expr, dim: Dim, what: &str) -> Option<f64> {
        match self.typed(e, dim, what, false)? {
            Value::Scalar { value, .. } => Some(value),
            Value::Vector { .. } => None,
        }
    }

    fn vector(&mut self, e: &Expr, dim: Dim, what: &str) -> Option<[f64; 3]> {
        match self.typed(e, dim, what, true)? {
            Value::Vector { value, .. } => Some(value),
            Value::Scalar { .. } => None,
        }
    }

    fn integer(&mut self, e: &Expr, what: &str, min: usize) -> Option<usize> {
        let x = self.scalar(e, Dim::NONE, what)?;
        if x.fract() != 0.0 || x < min as f64 || x > 1e12 {
            self.sink.push(
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

    /// Splits a property list by name, reporting unknown and repeated properties.
    fn props<'p>(
        &mut self,
        props: &'p [Prop],
        known: &[&'static str],
        of: &str,
    ) -> HashMap<&'static str, &'p Prop> {
        let mut out: HashMap<&'static str, &'p Prop> = HashMap::new();
        for p in props {
            match known.iter().find(|k| **k == p.name.name) {
                Some(&k) => {
                    if let Some(first) = out.get(k) {
                        self.sink.push(
                            Diagnostic::error(Code::E0203, format!("property `{k}` is set twice"))
                                .at(p.name.span, "second value")
                                .at(first.name.span, "first value")
                                .hint("set each property once"),
                        );
                    } else {
                        out.insert(k, p);
                    }
                }
                None => {
                    let hint = match did_you_mean(&p.name.name, known.iter().copied()) {
                        Some(s) => format!("did you mean `{s}`? {of} takes: {}", known.join(", ")),
                        None => format!("{of} takes: {}", known.join(", ")),
                    };
                    self.sink.push(
                        Diagnostic::error(
                            Code::E0205,
                            format!("{of} has no property `{}`", p.name.name),
                        )
                        .at(p.name.span, "unknown property")
                        .hint(hint),
                    );
                }
            }
        }
        out
    }

    fn missing(&mut self, at: Span, prop: &str, of: &str, example: &str) {
        self.sink.push(
            Diagnostic::error(Code::E0206, format!("{of} needs `{prop}`"))
                .at(at, format!("`{prop}` missing"))
                .hint(format!("add `{prop} = {example}`")),
        );
    }

    fn point_mass(&mut self, name: &ast::Ident, props: &[Prop], span: Span) -> Option<Body> {
        let of = format!("point_mass `{}`", name.name);
        let p = self.props(props, &["mass", "at", "velocity"], "a point_mass");
        let mass = match p.get("mass") {
            Some(m) => {
                let v = self.scalar(&m.value, Dim::MASS, "`mass`");
                if let Some(x) = v {
                    if x <= 0.0 {
                        self.sink.push(Diagnostic::error(Code::E0302, format!("the mass of `{}` is not positive", name.name)).at(m.value.span, format!("{x} kg")).hint("a body needs a positive mass; a massless point makes the iteration matrix singular"));
                        return None;
                    }
                }
                v
            }
            None => {
                self.missing(name.span, "mass", &of, "1 kg");
                None
            }
        };
        let position = match p.get("at") {
            Some(a) => self.vector(&a.value, Dim::LENGTH, "`at`"),
            None => {
                self.missing(name.span, "at", &of, "(0, 0, 0) m");
                None
            }
        };
        let velocity = match p.get("velocity") {
            Some(v) => self.vector(&v.value, Dim::VELOCITY, "`velocity`"),
            None => Some([0.0; 3]),
        };
        Some(Body {
            name: name.name.clone(),
            span,
            mass: mass?,
            position: position?,
            velocity: velocity?,
        })
    }

    fn marker(
        &mut self,
        m: &ast::MarkerRef,
        bodies: &[(&ast::Ident, &Vec<Prop>, Span)],
    ) -> Option<Marker> {
        let head = &m.path.segments[0];
        let target = self.entities.get(&head.name).map(|e| e.0);
        let attach = match target {
            Some(Entity::Ground(g)) if m.path.segments.len() == 1 => Attach::Ground(g),
            Some(Entity::Body(b)) if m.path.segments.len() == 1 => Attach::Body(b),
            Some(Entity::Ground(_)) | Some(Entity::Body(_)) => {
                self.sink.push(
                    Diagnostic::error(Code::E0201, format!("`{}` names no marker", m.path.text()))
                        .at(m.path.span, "unknown marker")
                        .hint(format!(
                            "attach to the body itself: `{}` or `{} @ (x, y, z)`",
                            head.name, head.name
                        )),
                );
                return None;
            }
            Some(Entity::Joint(_)) => {
                self.sink.push(
                    Diagnostic::error(
                        Code::E0201,
                        format!("`{}` is a joint, not a body", head.name),
                    )
                    .at(head.span, "a joint")
                    .hint("a joint connects markers on bodies or on a ground"),
                );
                return None;
            }
            None => {
                let names: Vec<String> = self
                    .entities
                    .iter()
                    .filter(|(_, e)| !matches!(e.0, Entity::Joint(_)))
                    .map(|(n, _)| n.clone())
                    .collect();
                let hint = match did_you_mean(&head.name, names.iter().map(|s| s.as_str())) {
                    Some(s) => format!("did you mean `{s}`?"),
                    None => {
                        "declare it with `ground NAME` or `point_mass NAME { ... }`".to_string()
                    }
                };
                self.sink.push(
                    Diagnostic::error(Code::E0201, format!("unknown body `{}`", head.name))
                        .at(head.span, "not declared")
                        .hint(hint),
                );
                return None;
            }
        };
        let offset = match &m.offset {
            Some(e) => {
                if let Attach::Body(b) = attach {
                    self.sink.push(Diagnostic::error(Code::E0306, format!("a marker on point mass `{}` cannot have an offset", bodies[b].0.name)).at(e.span, "offset given here").hint("a point mass has no orientation: its only marker is the point itself; remove `@ ...`"));
                    return None;
                }
                self.vector(e, Dim::LENGTH, "a marker offset")?
            }
            None => [0.0; 3],
        };
        Some(Marker {
            attach,
            offset,
            span: m.span,
        })
    }

    fn joint(
        &mut self,
        name: &ast::Ident,
        kind: &ast::Ident,
        markers: &[ast::MarkerRef],
        props: &[Prop],
        span: Span,
        bodies: &[(&ast::Ident, &Vec<Prop>, Span)],
    ) -> Option<Joint> {
        const KINDS: &[&str] = &["distance"];
        if kind.name != "distance" {
            let hint = match did_you_mean(&kind.name, KINDS.iter().copied()) {
                Some(s) => format!("did you mean `{s}`? Joint kinds: {}", KINDS.join(", ")),
                None => format!(
                    "joint kinds available in this version: {}",
                    KINDS.join(", ")
                ),
            };
            self.sink.push(
                Diagnostic::error(Code::E0211, format!("unknown joint kind `{}`", kind.name))
                    .at(kind.span, "not a joint kind")
                    .hint(hint),
            );
            return None;
        }
        if markers.len() != 2 {
            self.sink.push(
                Diagnostic::error(
                    Code::E0209,
                    format!(
                        "a distance joint connects 2 markers, found {}",
                        markers.len()
                    ),
                )
                .at(kind.span, "here")
                .hint("write `distance(a, b)`"),
            );
            return None;
        }
        let ms: Vec<Option<Marker>> = markers.iter().map(|m| self.marker(m, bodies)).collect();
        let p = self.props(props, &["length"], "a distance joint");
        let length = match p.get("length") {
            Some(l) => Some((
                self.scalar(&l.value, Dim::LENGTH, "`length`")?,
                l.value.span,
            )),
            None => None,
        };
        let [Some(a), Some(b)] = [ms[0].clone(), ms[1].clone()] else {
            return None;
        };
        match (a.attach, b.attach) {
            (Attach::Ground(_), Attach::Ground(_)) => {
                self.sink.push(
                    Diagnostic::error(
                        Code::E0305,
                        format!("joint `{}` connects two grounds", name.name),
                    )
                    .at(span, "both markers fixed")
                    .hint("attach at least one marker to a body"),
                );
                return None;
            }
            (Attach::Body(x), Attach::Body(y)) if x == y => {
                self.sink.push(
                    Diagnostic::error(
                        Code::E0301,
                        format!(
                            "joint `{}` connects `{}` to itself",
                            name.name, bodies[x].0.name
                        ),
                    )
                    .at(a.span, "this marker")
                    .at(b.span, "and this one are on the same body")
                    .hint("connect the body to another body or to ground"),
                );
                return None;
            }
            _ => {}
        }
        let length = match length {
            Some((l, s)) if l <= 0.0 => {
                self.sink.push(Diagnostic::error(Code::E0303, format!("distance joint `{}` has a non-positive length", name.name)).at(s, "must be positive").hint("a distance joint keeps two points a positive distance apart; use a spherical joint to make them coincide"));
                return None;
            }
            Some((l, _)) => l,
            // Without `length`, the joint keeps the initial distance; checked in the lowering.
            None => f64::NAN,
        };
        Some(Joint {
            name: name.name.clone(),
            span,
            kind: JointKind::Distance { length },
            markers: [a, b],
        })
    }

    fn outputs(&mut self, items: &[&ast::OutputItem]) -> Vec<OutputChannel> {
        let mut out: Vec<OutputChannel> = Vec::new();
        let mut columns: HashMap<String, Span> = HashMap::new();
        columns.insert("t".to_string(), Span::default());
        for item in items {
            let Some(probes) = self.probes(&item.path) else {
                continue;
            };
            let base = item
                .name
                .as_ref()
                .map(|n| n.name.clone())
                .unwrap_or_else(|| item.path.text());
            let n = probes.len();
            for (suffix, probe) in probes {
                let column = if n == 1 {
                    base.clone()
                } else {
                    format!("{base}.{suffix}")
                };
                if let Some(first) = columns.get(&column) {
                    let mut d = Diagnostic::error(
                        Code::E0203,
                        format!("output column `{column}` is declared twice"),
                    )
                    .at(item.span, "second column of that name");
                    if first.end > 0 {
                        d = d.at(*first, "first declared here");
                    }
                    self.sink
                        .push(d.hint("name the output: `output NAME = PATH`"));
                    continue;
                }
                columns.insert(column.clone(), item.span);
                out.push(OutputChannel {
                    column,
                    probe,
                    span: item.span,
                });
            }
        }
        out
    }

    /// The probes a path names, with column suffixes for vectors.
    fn probes(&mut self, path: &ast::Path) -> Option<Vec<(&'static str, Probe)>> {
        let segs = &path.segments;
        let head = &segs[0];
        const AXES: [&str; 3] = ["x", "y", "z"];
        let entity = self.entities.get(&head.name).map(|e| e.0);
        let bad = |this: &mut Self, at: &ast::Ident, what: &str, known: &[&str]| {
            let hint = match did_you_mean(&at.name, known.iter().copied()) {
                Some(s) => format!("did you mean `{s}`? {what} provides: {}", known.join(", ")),
                None => format!("{what} provides: {}", known.join(", ")),
            };
            this.sink.push(
                Diagnostic::error(
                    Code::E0212,
                    format!("`{}` is not an output quantity of {what}", at.name),
                )
                .at(at.span, "unknown quantity")
                .hint(hint),
            );
            None
        };
        match entity {
            Some(Entity::Body(b)) => {
                const Q: &[&str] = &["position", "velocity", "acceleration"];
                let Some(q) = segs.get(1) else {
                    return bad(self, head, "a point_mass", Q).or(None);
                };
                let quantity = match q.name.as_str() {
                    "position" => BodyQuantity::Position,
                    "velocity" => BodyQuantity::Velocity,
                    "acceleration" => BodyQuantity::Acceleration,
                    _ => return bad(self, q, "a point_mass", Q),
                };
                match segs.get(2) {
                    None => Some(
                        AXES.iter()
                            .enumerate()
                            .map(|(i, a)| {
                                (
                                    *a,
                                    Probe::Body {
                                        body: b,
                                        quantity,
                                        component: i,
                                    },
                                )
                            })
                            .collect(),
                    ),
                    Some(c) if segs.len() == 3 => match AXES.iter().position(|a| *a == c.name) {
                        Some(i) => Some(vec![(
                            "",
                            Probe::Body {
                                body: b,
                                quantity,
                                component: i,
                            },
                        )]),
                        None => bad(self, c, "a vector", &AXES),
                    },
                    Some(_) => bad(self, &segs[3], "a vector component", &[]),
                }
            }
            Some(Entity::Joint(j)) => {
                const Q: &[&str] = &["force", "violation"];
                let quantity = match segs.get(1).map(|s| s.name.as_str()) {
                    Some("force") if segs.len() == 2 => JointQuantity::Force,
                    Some("violation") if segs.len() == 2 => JointQuantity::Violation,
                    Some(_) if segs.len() > 2 => {
                        return bad(self, &segs[2], "a scalar joint quantity", &[])
                    }
                    Some(_) => return bad(self, &segs[1], "a distance joint", Q),
                    None => return bad(self, head, "a distance joint", Q),
                };
                Some(vec![("", Probe::Joint { joint: j, quantity })])
            }
            Some(Entity::Ground(_)) => {
                self.sink.push(
                    Diagnostic::error(
                        Code::E0212,
                        format!("ground `{}` has no output quantities", head.name),
                    )
                    .at(path.span, "a ground does not move")
                    .hint("output a body's position, velocity or acceleration, or a joint's force"),
                );
                None
            }
            None => {
                let names: Vec<String> = self.entities.keys().cloned().collect();
                let hint = match did_you_mean(&head.name, names.iter().map(|s| s.as_str())) {
                    Some(s) => format!("did you mean `{s}`?"),
                    None => "outputs name a body or a joint, e.g. `bob.position.x` or `link.force`"
                        .to_string(),
                };
                self.sink.push(
                    Diagnostic::error(
                        Code::E0201,
                        format!("unknown name `{}` in output", head.name),
                    )
                    .at(head.span, "not declared")
                    .hint(hint),
                );
                None
            }
        }
    }

    fn solve(&mut self, item: Option<&Item>, o: &Overrides, file_span: Span) -> Option<SolveSpec> {
        let (method, props, span) = match item {
            Some(Item::Solve {
                method,
                args,
                props,
                span,
            }) => (
                Some(method),
                args.iter()
                    .chain(props.iter())
                    .cloned()
                    .collect::<Vec<Prop>>(),
                *span,
            ),
            _ => (
                None,
                Vec::new(),
                Span {
                    end: file_span.start,
                    ..file_span
                },
            ),
        };
        let mut integrator = Integrator::Hht;
        if let Some(m) = method {
            integrator = match m.name.as_str() {
                "hht" => Integrator::Hht,
                "fet" => Integrator::Fet,
                other => {
                    let hint = match did_you_mean(other, ["hht", "fet"]) {
                        Some(s) => format!("did you mean `{s}`? Solvers: hht, fet"),
                        None => "solvers: hht (HHT-alpha), fet (time finite elements)".to_string(),
                    };
                    self.sink.push(
                        Diagnostic::error(Code::E0211, format!("unknown solver `{other}`"))
                            .at(m.span, "not a solver")
                            .hint(hint),
                    );
                    return None;
                }
            };
        }
        let p = self.props(
            &props,
            &[
                "alpha",
                "dt",
                "steps",
                "until",
                "every",
                "start",
                "tolerance",
                "max_iterations",
            ],
            "a solve block",
        );
        let mut alpha = match p.get("alpha") {
            Some(a) => self.scalar(&a.value, Dim::NONE, "`alpha`")?,
            None => -0.1,
        };
        if let Some(a) = p.get("alpha") {
            if !(-1.0 / 3.0 - 1e-12..=0.0).contains(&alpha) {
                self.sink.push(Diagnostic::error(Code::E0213, format!("HHT alpha = {alpha} is outside [-1/3, 0]")).at(a.value.span, "out of range").hint("alpha = -0.1 is the usual choice; 0 adds no numerical dissipation, -1/3 the most"));
                return None;
            }
        }
        let mut dt = match p.get("dt") {
            Some(d) => Some((self.scalar(&d.value, Dim::TIME, "`dt`")?, d.value.span)),
            None => None,
        };
        let mut steps = match p.get("steps") {
            Some(s) => Some(self.integer(&s.value, "`steps`", 1)?),
            None => None,
        };
        let mut until = match p.get("until") {
            Some(u) => Some((self.scalar(&u.value, Dim::TIME, "`until`")?, u.value.span)),
            None => None,
        };
        let mut every = match p.get("every") {
            Some(e) => self.integer(&e.value, "`every`", 1)?,
            None => 1,
        };
        let mut start = match p.get("start") {
            Some(s) => match &s.value.kind {
                ExprKind::Path { path } if path.text() == "consistent" => Start::Consistent,
                ExprKind::Path { path } if path.text() == "zero_acceleration" => {
                    Start::ZeroAcceleration
                }
                _ => {
                    self.sink.push(Diagnostic::error(Code::E0211, "unknown start").at(s.value.span, "not a start option").hint("`start = consistent` (default) or `start = zero_acceleration` (the paper's start)"));
                    return None;
                }
            },
            None => Start::Consistent,
        };
        let tolerance = match p.get("tolerance") {
            Some(t) => self.scalar(&t.value, Dim::NONE, "`tolerance`")?,
            None => 1e-10,
        };
        let max_iterations = match p.get("max_iterations") {
            Some(m) => self.integer(&m.value, "`max_iterations`", 1)?,
            None => 25,
        };
        for (name, value, s) in [("dt", dt, p.get("dt")), ("until", until, p.get("until"))] {
            if let (Some((v, vs)), Some(_)) = (value, s) {
                if v <= 0.0 {
                    self.sink.push(
                        Diagnostic::error(Code::E0213, format!("`{name}` must be positive"))
                            .at(vs, "not positive")
                            .hint("times are positive durations, e.g. `dt = 0.005 s`"),
                    );
                    return None;
                }
            }
        }
        if !(tolerance > 0.0 && tolerance < 1e-2) {
            self.sink.push(
                Diagnostic::error(Code::E0213, "`tolerance` must lie in (0, 0.01)")
                    .at(
                        p.get("tolerance").map(|t| t.value.span).unwrap_or(span),
                        "out of range",
                    )
                    .hint("the default 1e-10 is right for most models"),
            );
            return None;
        }
        // Command-line flags override the block.
        integrator = o.integrator.unwrap_or(integrator);
        alpha = o.alpha.unwrap_or(alpha);
        if let Some(d) = o.dt {
            dt = Some((d, span));
            steps = None;
        }
        if let Some(n) = o.steps {
            steps = Some(n);
            dt = None;
        }
        if let Some(u) = o.until {
            until = Some((u, span));
        }
        every = o.every.unwrap_or(every);
        start = o.start.unwrap_or(start);
        let Some((until, _)) = until else {
            self.missing(span, "until", "the solve block", "1 s");
            return None;
        };
        let (dt, steps) = match (dt, steps) {
            (_, Some(n)) => (until / n as f64, n),
            (Some((d, _)), None) => {
                // The last step is shortened by at most round-off: dt is rounded to fit `until`.
                let n = (until / d - 1e-9).ceil().max(1.0) as usize;
                (until / n as f64, n)
            }
            (None, None) => {
                self.missing(span, "dt", "the solve block", "0.005 s");
                return None;
            }
        };
        Some(SolveSpec {
            integrator,
            alpha,
            dt,
            steps,
            until,
            every,
            start,
            tolerance,
            max_iterations,
            span,
        })
    }
}

fn unit_hint(dim: Dim) -> String {
    let example = match (dim.mass, dim.length, dim.time) {
        (1, 0, 0) => "`1.0 kg`",
        (0, 1, 0) => "`0.5 m` or `(0, -0.5, 0) m`",
        (0, 0, 1) => "`0.005 s`",
        (0, 1, -1) => "`1.5 m/s` or `(1.5, 0, 0) m/s`",
        (0, 1, -2) => "`(0, -9.81, 0) m/s^2`",
        (0, 0, 0) => "a plain number",
        _ => "a value with units",
    };
    format!("expected a {}, e.g. {example}", dim.describe())
}

/// Where a marker is in the initial configuration.
pub fn initial_position(m: &Marker, bodies: &[Body]) -> [f64; 3] {
    match m.attach {
        Attach::Ground(_) => m.offset,
        Attach::Body(b) => bodies[b].position,
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}
