//! Bodies, beams, sections and markers.

use super::{add, dot, norm, scale, sub, Builder, Built, View};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::model::eval::units::Dim;
use crate::model::eval::{mat_mul, mat_vec, transpose, Value};
use crate::model::scope::env::{Ref, Seg};
use crate::model::*;
use crate::syntax::ast::{Block, MarkerRef};

const INERTIA: Dim = Dim::new(1, 2, 0);

impl Builder<'_> {
    pub(super) fn ground(&mut self, v: &View) -> Option<Built> {
        if !self.shape(v, 0, false, false, &[], "ground NAME") {
            return None;
        }
        if let Some(b) = &v.block {
            if !b.props.is_empty() || !b.markers.is_empty() {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0205, "a ground takes no properties")
                        .at(b.span, "here")
                        .hint("a ground is the inertial frame; place points on it with `NAME @ (x, y, z)`"),
                );
            }
        }
        self.grounds.push(Ground {
            name: v.name.clone(),
            span: v.span,
        });
        Some(Built::Ground(self.grounds.len() - 1))
    }

    pub(super) fn push_body(&mut self, v: &View, body: Body) -> Option<Built> {
        self.bodies.push(body);
        self.body_decl.push(v.decl);
        Some(Built::Body(self.bodies.len() - 1))
    }

    /// Initial velocity and angular velocity properties.
    pub(super) fn motion(
        &mut self,
        v: &View,
        p: &std::collections::HashMap<&'static str, crate::syntax::ast::Prop>,
    ) -> ([f64; 3], [f64; 3]) {
        let vel = self
            .expr(v.scope, p.get("velocity"))
            .and_then(|e| self.vector(v.scope, e, Dim::VELOCITY, "`velocity`"));
        let w = self
            .expr(v.scope, p.get("angular_velocity"))
            .and_then(|e| self.vector(v.scope, e, Dim::new(0, 0, -1), "`angular_velocity`"));
        (vel.unwrap_or([0.0; 3]), w.unwrap_or([0.0; 3]))
    }

    pub(super) fn positive_mass(
        &mut self,
        v: &View,
        e: &crate::syntax::ast::Expr,
        allow_zero: bool,
    ) -> Option<f64> {
        let m = self.scalar(v.scope, e, Dim::MASS, "`mass`")?;
        if m < 0.0 || (m == 0.0 && !allow_zero) {
            let hint = if allow_zero {
                "a mass cannot be negative; a massless rigid body (mass = 0) must be held by its joints"
            } else {
                "a point mass needs a positive mass; a massless point makes the iteration matrix singular"
            };
            self.error(
                v.scope,
                Diagnostic::error(
                    Code::E0302,
                    format!("the mass of `{}` is not positive", v.name),
                )
                .at(e.span, format!("{m} kg"))
                .hint(hint),
            );
            return None;
        }
        Some(m)
    }

    pub(super) fn point_mass(&mut self, v: &View) -> Option<Built> {
        if !self.shape(
            v,
            0,
            false,
            false,
            &[],
            "point_mass NAME { mass = 1 kg, at = (0, -1, 0) m }",
        ) {
            return None;
        }
        let of = format!("point_mass `{}`", v.name);
        let p = self.props(
            v.scope,
            v.block.as_ref(),
            &["mass", "at", "velocity"],
            "a point_mass",
        );
        self.no_markers(v, "a point_mass");
        let mass = self
            .required(v.scope, &p, "mass", v.name_span, &of, "1 kg")
            .and_then(|e| self.positive_mass(v, e, false));
        let position = self
            .required(v.scope, &p, "at", v.name_span, &of, "(0, 0, 0) m")
            .and_then(|e| self.vector(v.scope, e, Dim::LENGTH, "`at`"));
        let (velocity, _) = self.motion(v, &p);
        self.push_body(
            v,
            Body {
                name: v.name.clone(),
                span: v.span,
                kind: BodyKind::PointMass,
                mass: mass?,
                center: [0.0; 3],
                inertia: [[0.0; 3]; 3],
                position: position?,
                orientation: IDENTITY,
                velocity,
                angular_velocity: [0.0; 3],
                markers: Vec::new(),
                beam_axis: None,
            },
        )
    }

    fn no_markers(&mut self, v: &View, what: &str) {
        if let Some(m) = v.block.as_ref().and_then(|b| b.markers.first()) {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0306, format!("{what} has no markers"))
                    .at(m.span, "not allowed here")
                    .hint("a point mass has no orientation; attach joints to it directly"),
            );
        }
    }

    /// `marker NAME = (x, y, z) m { axes = rotate(...) }` items of a body block.
    fn body_markers(&mut self, v: &View, block: Option<&Block>) -> Vec<(String, [f64; 3], Mat3)> {
        let mut out: Vec<(String, [f64; 3], Mat3)> = Vec::new();
        let Some(block) = block else {
            return out;
        };
        for m in &block.markers {
            if m.name.index.is_some() {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0214, "markers are not indexed")
                        .at(m.name.span, "here")
                        .hint("give each marker its own name"),
                );
                continue;
            }
            let name = m.name.ident.name.clone();
            if out.iter().any(|o| o.0 == name)
                || ["center", "start", "end"].contains(&name.as_str())
                    && out.iter().any(|o| o.0 == name)
            {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0203, format!("marker `{name}` is declared twice"))
                        .at(m.name.span, "second declaration")
                        .hint("give each marker its own name"),
                );
                continue;
            }
            let p = self.props(v.scope, m.block.as_ref(), &["at", "axes"], "a marker");
            let at_expr = match (&m.at, self.expr(v.scope, p.get("at"))) {
                (Some(e), None) => Some(e.clone()),
                (None, Some(e)) => Some(e.clone()),
                (Some(e), Some(_)) => {
                    self.error(
                        v.scope,
                        Diagnostic::error(Code::E0203, format!("marker `{name}` is placed twice"))
                            .at(e.span, "here and in its block")
                            .hint("write `marker NAME = (x, y, z) m` or `marker NAME { at = ... }`, not both"),
                    );
                    None
                }
                (None, None) => {
                    self.missing(
                        v.scope,
                        m.name.span,
                        "at",
                        &format!("marker `{name}`"),
                        "(0, 0, 0) m",
                    );
                    None
                }
            };
            let Some(at) =
                at_expr.and_then(|e| self.vector(v.scope, &e, Dim::LENGTH, "a marker position"))
            else {
                continue;
            };
            let axes = match self.expr(v.scope, p.get("axes")) {
                Some(e) => self.rotation(v.scope, e, "`axes`").unwrap_or(IDENTITY),
                None => IDENTITY,
            };
            out.push((name, at, axes));
        }
        out
    }

    pub(super) fn rigid(&mut self, v: &View) -> Option<Built> {
        if !self.shape(
            v,
            0,
            false,
            false,
            &[],
            "rigid NAME { mass = 2 kg, inertia = (0.1, 0.1, 0.2) kg*m^2 }",
        ) {
            return None;
        }
        let of = format!("rigid body `{}`", v.name);
        let p = self.props(
            v.scope,
            v.block.as_ref(),
            &[
                "mass",
                "center",
                "inertia",
                "products",
                "at",
                "orientation",
                "velocity",
                "angular_velocity",
            ],
            "a rigid body",
        );
        let mass = self
            .required(v.scope, &p, "mass", v.name_span, &of, "2 kg")
            .and_then(|e| self.positive_mass(v, e, true));
        let center = match self.expr(v.scope, p.get("center")) {
            Some(e) => self.vector(v.scope, e, Dim::LENGTH, "`center`"),
            None => Some([0.0; 3]),
        };
        let principal = match self.expr(v.scope, p.get("inertia")) {
            Some(e) => self.vector(
                v.scope,
                e,
                INERTIA,
                "`inertia` (principal moments about the centre of mass)",
            ),
            None => Some([0.0; 3]),
        };
        let products = match self.expr(v.scope, p.get("products")) {
            Some(e) => self.vector(v.scope, e, INERTIA, "`products` (Ixy, Ixz, Iyz)"),
            None => Some([0.0; 3]),
        };
        let position = match self.expr(v.scope, p.get("at")) {
            Some(e) => self.vector(v.scope, e, Dim::LENGTH, "`at`"),
            None => Some([0.0; 3]),
        };
        let orientation = match self.expr(v.scope, p.get("orientation")) {
            Some(e) => self.rotation(v.scope, e, "`orientation`"),
            None => Some(IDENTITY),
        };
        let (velocity, angular_velocity) = self.motion(v, &p);
        let mut markers = self.body_markers(v, v.block.as_ref());
        let (i, q) = (principal?, products?);
        let inertia = [[i[0], q[0], q[1]], [q[0], i[1], q[2]], [q[1], q[2], i[2]]];
        let span = p.get("inertia").map(|p| p.span()).unwrap_or(v.name_span);
        self.check_inertia(v, &inertia, span)?;
        let center = center?;
        if !markers.iter().any(|m| m.0 == "center") {
            markers.push(("center".to_string(), center, IDENTITY));
        }
        self.push_body(
            v,
            Body {
                name: v.name.clone(),
                span: v.span,
                kind: BodyKind::Rigid,
                mass: mass?,
                center,
                inertia,
                position: position?,
                orientation: orientation?,
                velocity,
                angular_velocity,
                markers,
                beam_axis: None,
            },
        )
    }

    /// An inertia tensor must be positive semi-definite and satisfy the triangle inequality of
    /// its principal moments (a physical mass distribution).
    pub(super) fn check_inertia(&mut self, v: &View, inertia: &Mat3, span: Span) -> Option<()> {
        let m = nalgebra::Matrix3::from_fn(|i, j| inertia[i][j]);
        let e = m.symmetric_eigenvalues();
        let scale = e.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let tol = 1e-9 * scale;
        let mut l: Vec<f64> = e.iter().copied().collect();
        l.sort_by(|a, b| a.total_cmp(b));
        let problem = if l[0] < -tol {
            Some(format!(
                "a principal moment is negative ({:.4e} kg*m^2)",
                l[0]
            ))
        } else if l[0] + l[1] < l[2] - tol {
            Some(format!(
                "principal moments {:.4e}, {:.4e}, {:.4e} kg*m^2 break the triangle inequality",
                l[0], l[1], l[2]
            ))
        } else {
            None
        };
        if let Some(msg) = problem {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0311, format!("the inertia of `{}` is not physical: {msg}", v.name))
                    .at(span, "here")
                    .hint("principal moments must be non-negative and each at most the sum of the other two (a slender rod has 0, I, I)"),
            );
            return None;
        }
        Some(())
    }

    pub(super) fn rigid_rod(&mut self, v: &View) -> Option<Built> {
        if !self.shape(
            v,
            0,
            false,
            false,
            &[],
            "rigid_rod NAME { from = (0, 0, 0) m, to = (1, 0, 0) m, mass = 1.6 kg }",
        ) {
            return None;
        }
        let of = format!("rigid_rod `{}`", v.name);
        let p = self.props(
            v.scope,
            v.block.as_ref(),
            &["from", "to", "mass", "velocity", "angular_velocity"],
            "a rigid_rod",
        );
        let get = |this: &mut Self, key: &str| {
            this.required(v.scope, &p, key, v.name_span, &of, "(0, 0, 0) m")
                .and_then(|e| this.vector(v.scope, e, Dim::LENGTH, &format!("`{key}`")))
        };
        let from = get(self, "from");
        let to = get(self, "to");
        let mass = self
            .required(v.scope, &p, "mass", v.name_span, &of, "1 kg")
            .and_then(|e| self.positive_mass(v, e, false));
        let (velocity, angular_velocity) = self.motion(v, &p);
        let (from, to, mass) = (from?, to?, mass?);
        let d = sub(to, from);
        let len = norm(d);
        if len == 0.0 {
            self.error(
                v.scope,
                Diagnostic::error(
                    Code::E0303,
                    format!("rigid_rod `{}` has zero length", v.name),
                )
                .at(v.name_span, "`from` and `to` coincide")
                .hint("place `to` away from `from`"),
            );
            return None;
        }
        let e = scale(d, 1.0 / len);
        let center = scale(add(from, to), 0.5);
        let k = mass * len * len / 12.0;
        let mut inertia = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                inertia[i][j] = k * (if i == j { 1.0 } else { 0.0 } - e[i] * e[j]);
            }
        }
        let mut markers = vec![
            ("start".to_string(), scale(e, -len / 2.0), IDENTITY),
            ("end".to_string(), scale(e, len / 2.0), IDENTITY),
            ("center".to_string(), [0.0; 3], IDENTITY),
        ];
        for m in self.body_markers(v, v.block.as_ref()) {
            if markers.iter().any(|x| x.0 == m.0) {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0203, format!("marker `{}` is built in", m.0))
                        .at(v.name_span, "in this rod")
                        .hint("a rigid_rod has `start`, `end` and `center`; choose another name"),
                );
                continue;
            }
            markers.push(m);
        }
        self.push_body(
            v,
            Body {
                name: v.name.clone(),
                span: v.span,
                kind: BodyKind::Rigid,
                mass,
                center: [0.0; 3],
                inertia,
                position: center,
                orientation: IDENTITY,
                velocity,
                angular_velocity,
                markers,
                beam_axis: None,
            },
        )
    }

    pub(super) fn concentrated_mass(&mut self, v: &View) -> Option<Built> {
        if !self.shape(
            v,
            0,
            true,
            false,
            &[],
            "concentrated_mass NAME on MARKER { mass = 2 kg }",
        ) {
            return None;
        }
        let p = self.props(
            v.scope,
            v.block.as_ref(),
            &["mass", "inertia"],
            "a concentrated_mass",
        );
        let on = v.on.clone()?;
        let mass = self
            .required(
                v.scope,
                &p,
                "mass",
                v.name_span,
                &format!("concentrated_mass `{}`", v.name),
                "2 kg",
            )
            .and_then(|e| self.positive_mass(v, e, false));
        let inertia = match self.expr(v.scope, p.get("inertia")) {
            Some(e) => self.vector(
                v.scope,
                e,
                INERTIA,
                "`inertia` (principal, in the marker's axes)",
            ),
            None => Some([0.0; 3]),
        };
        let marker = self.marker(v.scope, &on)?;
        let (mass, inertia) = (mass?, inertia?);
        let local = [
            [inertia[0], 0.0, 0.0],
            [0.0, inertia[1], 0.0],
            [0.0, 0.0, inertia[2]],
        ];
        self.check_inertia(v, &local, v.name_span)?;
        match marker.attach {
            Attach::Body { body } => {
                let b = &mut self.bodies[body];
                if b.kind == BodyKind::PointMass {
                    if inertia != [0.0; 3] {
                        self.error(
                            v.scope,
                            Diagnostic::error(
                                Code::E0306,
                                "a point mass cannot carry rotary inertia",
                            )
                            .at(on.span, "on a point mass")
                            .hint("remove `inertia`, or make the body `rigid`"),
                        );
                        return None;
                    }
                    b.mass += mass;
                    return Some(Built::Mass);
                }
                // Combine about the new centre of mass (parallel axis), in the body frame.
                let r = marker.offset;
                let total = b.mass + mass;
                let c = scale(add(scale(b.center, b.mass), scale(r, mass)), 1.0 / total);
                let rotated = mat_mul(mat_mul(marker.axes, local), transpose(marker.axes));
                let shift = |m: f64, d: [f64; 3]| {
                    let mut s = [[0.0; 3]; 3];
                    for i in 0..3 {
                        for j in 0..3 {
                            s[i][j] = m * (if i == j { dot(d, d) } else { 0.0 } - d[i] * d[j]);
                        }
                    }
                    s
                };
                let (s1, s2) = (shift(b.mass, sub(b.center, c)), shift(mass, sub(r, c)));
                for i in 0..3 {
                    for j in 0..3 {
                        b.inertia[i][j] += s1[i][j] + s2[i][j] + rotated[i][j];
                    }
                }
                b.mass = total;
                b.center = c;
                for m in b.markers.iter_mut().filter(|m| m.0 == "center") {
                    m.1 = c;
                }
                Some(Built::Mass)
            }
            Attach::BeamNode { beam, node } => {
                let world = mat_mul(
                    mat_mul(marker.world_axes, local),
                    transpose(marker.world_axes),
                );
                self.beams[beam].point_masses.push((node, mass, world));
                Some(Built::Mass)
            }
            _ => {
                self.error(
                    v.scope,
                    Diagnostic::error(
                        Code::E0306,
                        "a concentrated mass goes on a body or a beam node",
                    )
                    .at(on.span, "not on a body or a node")
                    .hint(
                        "attach it to a body marker or to `beam.node[k]`, `beam.start`, `beam.end`",
                    ),
                );
                None
            }
        }
    }

    /// Resolves a marker reference: `earth`, `earth @ (x, y, z)`, `bar.end`, `rotor.hub`,
    /// `mast.node[2]`, `mast.at(1.2 m)`.
    pub(super) fn marker(&mut self, scope: usize, m: &MarkerRef) -> Option<Marker> {
        let segs = match self.env.segs(scope, &m.path) {
            Ok(s) => s,
            Err(d) => {
                self.error(scope, d);
                return None;
            }
        };
        let (r, rest, passed) = match self.env.resolve_marker(scope, &segs, m.path.span) {
            Ok(x) => x,
            Err(d) => {
                self.error(scope, d);
                return None;
            }
        };
        // Its own offset and those of the marker arguments it names, all in one frame (the
        // body's, the beam section's or the inertial one), so they add.
        let mut offset: Option<([f64; 3], Span)> = None;
        let written = m.offset.iter().map(|e| (e.clone(), scope));
        for (e, s) in written.chain(passed) {
            let o = self.vector(s, &e, Dim::LENGTH, "a marker offset")?;
            offset = Some(match offset {
                Some((sum, first)) => (add(sum, o), first),
                None => (o, e.span),
            });
        }
        let not_marker = |this: &mut Self, what: String| {
            this.error(
                scope,
                Diagnostic::error(Code::E0222, format!("{what} is not a marker"))
                    .at(m.path.span, "a marker is needed here")
                    .hint("name a ground, a body or one of its markers (`bar.end`), or a point on a beam (`mast.node[2]`)"),
            );
            None
        };
        let d = match r {
            Ref::Decl(d) => d,
            Ref::Instance(s) => {
                let comp = self.env.scopes[s]
                    .instance
                    .clone()
                    .map(|i| i.0)
                    .unwrap_or_default();
                return not_marker(self, format!("an instance of `{comp}`"));
            }
            Ref::Component(c) => return not_marker(self, format!("component `{}`", c.name.name)),
            Ref::Binding(b) => return not_marker(self, format!("`{}`", self.env.bindings[b].name)),
            Ref::Builtin(_) | Ref::Family(_) => {
                return not_marker(self, format!("`{}`", m.path.text()))
            }
        };
        let text = self.env.decls[d].name.clone();
        let built = self.built[d];
        let marker = match built {
            Some(Built::Ground(g)) => {
                if let Some(s) = rest.first() {
                    return self.no_such_marker(scope, s, &text, &[]);
                }
                let o = offset.map(|o| o.0).unwrap_or([0.0; 3]);
                Marker {
                    attach: Attach::Ground { ground: g },
                    offset: o,
                    axes: IDENTITY,
                    position: o,
                    world_axes: IDENTITY,
                    text: text.clone(),
                    span: m.span,
                }
            }
            Some(Built::Body(b)) => {
                let body = self.bodies[b].clone();
                let along =
                    |s: &Seg| -> Option<Result<f64, Diagnostic>> { axis_point(&body, s, &text) };
                let (local, axes) = match rest.as_slice() {
                    [] => ([0.0; 3], IDENTITY),
                    [s] if along(s).is_some() => match along(s) {
                        Some(Ok(x)) => ([x, 0.0, 0.0], IDENTITY),
                        Some(Err(d)) => {
                            self.error(scope, d);
                            return None;
                        }
                        None => return None,
                    },
                    [s] if s.index.is_none() && s.arg.is_none() => {
                        match body.markers.iter().find(|x| x.0 == s.name.name) {
                            Some(x) => (x.1, x.2),
                            None => {
                                let names: Vec<String> =
                                    body.markers.iter().map(|x| x.0.clone()).collect();
                                return self.no_such_marker(scope, s, &text, &names);
                            }
                        }
                    }
                    [s, ..] => {
                        let names: Vec<String> = body.markers.iter().map(|x| x.0.clone()).collect();
                        return self.no_such_marker(scope, s, &text, &names);
                    }
                };
                if body.kind == BodyKind::PointMass {
                    if let Some((_, s)) = offset {
                        self.error(
                            scope,
                            Diagnostic::error(Code::E0306, format!("`{text}` is a point mass: a marker on it cannot be offset"))
                                .at(s, "offset on a point mass")
                                .hint("a point mass has no orientation to carry an offset; attach to the point itself, or make the body `rigid`"),
                        );
                        return None;
                    }
                }
                let local = add(local, offset.map(|o| o.0).unwrap_or([0.0; 3]));
                Marker {
                    attach: Attach::Body { body: b },
                    offset: local,
                    axes,
                    position: add(body.position, mat_vec(body.orientation, local)),
                    world_axes: mat_mul(body.orientation, axes),
                    text: format!(
                        "{text}{}",
                        rest.first()
                            .map(|s| format!(".{}", s.name.name))
                            .unwrap_or_default()
                    ),
                    span: m.span,
                }
            }
            Some(Built::Beam(bi)) => {
                let beam = self.beams[bi].clone();
                let n = beam.nodes.len();
                let point = match rest.as_slice() {
                    [s] => beam_point(&beam, bi, s, &text),
                    _ => None,
                };
                let (attach, s) = match point {
                    Some(Ok(x)) => x,
                    Some(Err(d)) => {
                        self.error(scope, d);
                        return None;
                    }
                    None => {
                        let span = rest.first().map(|s| s.span).unwrap_or(m.path.span);
                        return self.beam_point_error(scope, span, &text, n);
                    }
                };
                let o = offset.map(|o| o.0).unwrap_or([0.0; 3]);
                // Where the point is at t = 0: on the initial (possibly stretched) nodes.
                let h = beam.length / (n - 1) as f64;
                let k = ((s / h).floor() as usize).min(n - 2);
                let w = (s - k as f64 * h) / h;
                let at = add(
                    scale(beam.initial_nodes[k], 1.0 - w),
                    scale(beam.initial_nodes[k + 1], w),
                );
                Marker {
                    attach,
                    offset: o,
                    axes: IDENTITY,
                    position: add(at, mat_vec(beam.frame, o)),
                    world_axes: beam.frame,
                    text: format!(
                        "{text}.{}",
                        rest.first()
                            .map(|s| s.name.name.clone())
                            .unwrap_or_default()
                    ),
                    span: m.span,
                }
            }
            None if !matches!(
                &*self.env.decls[d].item,
                crate::syntax::ast::Item::Joint { .. }
            ) =>
            {
                // Its own declaration failed and was reported.
                return None;
            }
            _ => return not_marker(self, format!("`{text}`")),
        };
        Some(marker)
    }

    fn no_such_marker(
        &mut self,
        scope: usize,
        s: &Seg,
        of: &str,
        names: &[String],
    ) -> Option<Marker> {
        let d = Diagnostic::error(
            Code::E0201,
            format!("`{of}` has no marker `{}`", s.name.name),
        )
        .at(s.span, "no such marker");
        let hint = match did_you_mean(&s.name.name, names.iter().map(|n| n.as_str())) {
            Some(m) => format!("did you mean `{m}`? Markers: {}", names.join(", ")),
            None if names.is_empty() => {
                format!("`{of}` has no named markers; use `{of}` itself, or `{of} @ (x, y, z)`")
            }
            None => format!("markers of `{of}`: {}", names.join(", ")),
        };
        self.error(scope, d.hint(hint));
        None
    }

    fn beam_point_error(&mut self, scope: usize, span: Span, of: &str, n: usize) -> Option<Marker> {
        self.error(
            scope,
            Diagnostic::error(Code::E0306, format!("say which point of beam `{of}`"))
                .at(span, "not a point of the beam")
                .hint(format!("write `{of}.start`, `{of}.end`, `{of}.node[k]` (k in 0..={}) or `{of}.at(s)` with s an arc length", n - 1)),
        );
        None
    }
}

/// `at(s)` or `node[k]` on a rigid beam: the arc length along its axis, if `s` names one.
pub(super) fn axis_point(body: &Body, s: &Seg, of: &str) -> Option<Result<f64, Diagnostic>> {
    let (length, n) = body.beam_axis?;
    match (s.name.name.as_str(), s.index, &s.arg) {
        ("node", Some((k, ks)), None) => Some(if k >= 0 && (k as usize) < n {
            Ok(length * k as f64 / (n - 1) as f64)
        } else {
            Err(Diagnostic::error(
                Code::E0214,
                format!(
                    "node {k} is out of range: beam `{of}` has nodes 0..={}",
                    n - 1
                ),
            )
            .at(ks, "no such node")
            .hint("a rigid beam keeps the node numbering its elements and order give"))
        }),
        ("at", None, Some((Value::Scalar { value, dim }, vs))) => Some(
            if *dim == Dim::LENGTH && (0.0..=length * (1.0 + 1e-12)).contains(value) {
                Ok(*value)
            } else {
                Err(Diagnostic::error(
                    Code::E0214,
                    format!("`at(s)` on beam `{of}` needs an arc length in [0, {length} m]"),
                )
                .at(*vs, "outside the beam")
                .hint("s is the distance from the beam's start, in metres"))
            },
        ),
        _ => None,
    }
}

/// The point of beam `bi` a path segment names (`start`, `end`, `node[k]`, `at(s)`), with its arc
/// length; `None` if the segment names no point of a beam.
pub(super) fn beam_point(
    beam: &Beam,
    bi: usize,
    s: &Seg,
    of: &str,
) -> Option<Result<(Attach, f64), Diagnostic>> {
    let n = beam.nodes.len();
    let node = |k: usize| Attach::BeamNode { beam: bi, node: k };
    Some(Ok(match (s.name.name.as_str(), s.index, &s.arg) {
        ("start", None, None) => (node(0), 0.0),
        ("end", None, None) => (node(n - 1), beam.length),
        ("node", Some((k, ks)), None) => {
            if k < 0 || k as usize >= n {
                return Some(Err(Diagnostic::error(
                    Code::E0214,
                    format!(
                        "node {k} is out of range: beam `{of}` has nodes 0..={}",
                        n - 1
                    ),
                )
                .at(ks, "no such node")
                .hint(format!(
                    "{} elements of {} nodes give {n} nodes",
                    beam.elements, beam.order
                ))));
            }
            (node(k as usize), beam.length * k as f64 / (n - 1) as f64)
        }
        ("at", None, Some((Value::Scalar { value, dim }, vs))) => {
            if *dim != Dim::LENGTH || !(0.0..=beam.length * (1.0 + 1e-12)).contains(value) {
                return Some(Err(Diagnostic::error(
                    Code::E0214,
                    format!(
                        "`at(s)` on beam `{of}` needs an arc length in [0, {} m]",
                        beam.length
                    ),
                )
                .at(*vs, "outside the beam")
                .hint("s is the distance from the beam's start, in metres")));
            }
            let k = value / beam.length * (n - 1) as f64;
            if (k - k.round()).abs() < 1e-9 {
                (node(k.round() as usize), *value)
            } else {
                (
                    Attach::BeamPoint {
                        beam: bi,
                        s: *value,
                    },
                    *value,
                )
            }
        }
        _ => return None,
    }))
}
