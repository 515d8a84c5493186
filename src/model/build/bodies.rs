//! Bodies: grounds, point masses, rigid bodies (with their markers and inertia checked), rigid
//! rods and concentrated masses on beams. Contract: builds `Ground`s and `Body`s and adds
//! point masses to beams; must not resolve marker references (`markers.rs` does).

use super::{add, dot, norm, scale, sub, Builder, Built, View};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::eval::units::Dim;
use crate::model::eval::{mat_mul, transpose};
use crate::model::*;
use crate::syntax::ast::Block;

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
            Attach::BeamNode { beam, .. } | Attach::BeamPoint { beam, .. } => {
                let world = mat_mul(
                    mat_mul(marker.world_axes, local),
                    transpose(marker.world_axes),
                );
                let b = &mut self.beams[beam];
                match marker.attach {
                    Attach::BeamNode { node, .. } => b.point_masses.push((node, mass, world)),
                    Attach::BeamPoint { s, .. } => b.masses_between.push((s, mass, world)),
                    _ => {}
                }
                Some(Built::Mass)
            }
            _ => {
                self.error(
                    v.scope,
                    Diagnostic::error(
                        Code::E0306,
                        "a concentrated mass goes on a body or a beam",
                    )
                    .at(on.span, "not on a body or a beam")
                    .hint(
                        "attach it to a body marker or to a point of a beam (`beam.node[k]`, `beam.at(s)`)",
                    ),
                );
                None
            }
        }
    }
}
