//! Beams and their sections; `beam NAME rigid` lowers to one rigid body.

use super::{add, cross, dot, norm, scale, sub, Builder, Built, View};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::eval::units::{self, Dim, Quantity};
use crate::model::eval::{mat_mul, rotation, Value};
use crate::model::scope::env::Ref;
use crate::model::*;
use crate::syntax::ast::{Block, PropValue};

const BENDING: Quantity = Dim::new(1, 3, -2).quantity();

impl Builder<'_> {
    pub(super) fn section_decl(&mut self, v: &View) -> Option<Built> {
        if !self.shape(
            v,
            0,
            false,
            false,
            &[],
            "section NAME { EA = ..., EI2 = ..., mass_per_length = ... }",
        ) {
            return None;
        }
        let block = v.block.clone().unwrap_or_default();
        let s = self.section(v, &block, v.name.clone())?;
        self.sections.push(s);
        Some(Built::Section(self.sections.len() - 1))
    }

    fn section(&mut self, v: &View, block: &Block, name: String) -> Option<Section> {
        const DIAG: [(&str, Quantity); 6] = [
            ("EA", units::AXIAL_STIFFNESS),
            ("GA2", units::SHEAR_STIFFNESS),
            ("GA3", units::SHEAR_STIFFNESS),
            ("GJ", units::TORSIONAL_RIGIDITY),
            ("EI2", BENDING),
            ("EI3", BENDING),
        ];
        let p = self.props(
            v.scope,
            Some(block),
            &[
                "EA",
                "GA2",
                "GA3",
                "GJ",
                "EI2",
                "EI3",
                "stiffness",
                "mass_per_length",
                "mass_offset2",
                "mass_offset3",
                "i2",
                "i3",
                "polar",
            ],
            "a section",
        );
        let mut k = [[0.0; 6]; 6];
        let mut ok = true;
        if let Some(sp) = p.get("stiffness") {
            if let Some((name, _)) = DIAG.iter().find(|(n, _)| p.contains_key(n)) {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0224, "a section gives either `stiffness` (6x6) or the diagonal stiffnesses, not both")
                        .at(p.get(name).map(|q| q.name.span).unwrap_or(sp.name.span), "diagonal stiffness")
                        .at(sp.name.span, "full matrix")
                        .hint("keep one of them"),
                );
                return None;
            }
            k = self.matrix6(v, sp)?;
        } else {
            for (i, (key, dim)) in DIAG.iter().enumerate() {
                let example = if i < 3 { "8.53e7 N" } else { "1.28e4 N*m^2" };
                match self
                    .required(v.scope, &p, key, block.span, "a section", example)
                    .and_then(|e| self.scalar(v.scope, e, *dim, &format!("`{key}`")))
                {
                    Some(x) => k[i][i] = x,
                    None => ok = false,
                }
            }
        }
        let mass = self
            .required(
                v.scope,
                &p,
                "mass_per_length",
                block.span,
                "a section",
                "3.29 kg/m",
            )
            .and_then(|e| self.scalar(v.scope, e, Dim::new(1, -1, 0), "`mass_per_length`"));
        let get = |this: &mut Self, key: &str, dim: Dim| match this.expr(v.scope, p.get(key)) {
            Some(e) => this.scalar(v.scope, e, dim, &format!("`{key}`")),
            None => Some(0.0),
        };
        let o2 = get(self, "mass_offset2", Dim::LENGTH);
        let o3 = get(self, "mass_offset3", Dim::LENGTH);
        let i2 = get(self, "i2", Dim::new(1, 1, 0));
        let i3 = get(self, "i3", Dim::new(1, 1, 0));
        let polar = match self.expr(v.scope, p.get("polar")) {
            Some(e) => self.scalar(v.scope, e, Dim::new(1, 1, 0), "`polar`"),
            None => match (i2, i3) {
                (Some(a), Some(b)) => Some(a + b),
                _ => None,
            },
        };
        let (mass, o2, o3, i2, i3, polar) = (mass?, o2?, o3?, i2?, i3?, polar?);
        if !ok {
            return None;
        }
        if mass <= 0.0 {
            self.error(
                v.scope,
                Diagnostic::error(
                    Code::E0302,
                    format!("section `{name}` has a non-positive mass per length"),
                )
                .at(
                    p.get("mass_per_length")
                        .map(|q| q.span())
                        .unwrap_or(block.span),
                    format!("{mass} kg/m"),
                )
                .hint("a beam needs mass; a massless beam makes the iteration matrix singular"),
            );
            return None;
        }
        if i2 < 0.0 || i3 < 0.0 || polar < 0.0 {
            self.error(
                v.scope,
                Diagnostic::error(
                    Code::E0311,
                    format!("section `{name}` has a negative mass moment of inertia"),
                )
                .at(block.span, "in this section")
                .hint("i2, i3 and polar are non-negative (kg*m)"),
            );
            return None;
        }
        // The stiffness must be symmetric positive definite.
        let m = nalgebra::Matrix6::from_fn(|i, j| k[i][j]);
        let sym = (0..6).all(|i| {
            (0..6).all(|j| (k[i][j] - k[j][i]).abs() <= 1e-9 * (k[i][i].abs() + k[j][j].abs()))
        });
        if !sym || m.cholesky().is_none() {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0311, format!("the stiffness of section `{name}` is not symmetric positive definite"))
                    .at(block.span, "in this section")
                    .hint("every stiffness must be positive (a beam stiff in some direction still needs a finite value), and couplings must leave the matrix positive definite"),
            );
            return None;
        }
        Some(Section {
            name,
            stiffness: k,
            mass_per_length: mass,
            mass_offset: [o2, o3],
            inertia: [polar, i2, i3],
        })
    }

    /// `stiffness = ((k11, ..., k16), ..., (k61, ..., k66))` with per-block units.
    fn matrix6(&mut self, v: &View, p: &crate::syntax::ast::Prop) -> Option<[[f64; 6]; 6]> {
        use crate::syntax::ast::ExprKind;
        let bad = |this: &mut Self, span: Span| {
            this.error(
                v.scope,
                Diagnostic::error(Code::E0209, "`stiffness` must be a 6x6 matrix")
                    .at(span, "not six rows of six")
                    .hint("write `stiffness = ((EA, 0, 0, 0, 0, 0) N, ..., (0, 0, 0, 0, 0, EI3) N*m^2)`; rows and columns 1-3 in N, 4-6 in N*m, the lower-right block in N*m^2"),
            );
            None
        };
        let PropValue::Expr(e) = &p.value else {
            return bad(self, p.name.span);
        };
        let ExprKind::Vector {
            items: rows,
            unit: None,
        } = &e.kind
        else {
            return bad(self, e.span);
        };
        if rows.len() != 6 {
            return bad(self, e.span);
        }
        let mut k = [[0.0; 6]; 6];
        for (i, row) in rows.iter().enumerate() {
            let ExprKind::Vector { items, unit } = &row.kind else {
                return bad(self, row.span);
            };
            if items.len() != 6 {
                return bad(self, row.span);
            }
            for (j, item) in items.iter().enumerate() {
                let dim = Dim::new(1, 1 + (i >= 3) as i8 + (j >= 3) as i8, -2);
                // A row may carry one unit after its parenthesis: apply it to every entry.
                let val = self.value(v.scope, item)?;
                let (x, d) = match (val, unit) {
                    (Value::Scalar { value, dim: d }, Some(u)) => {
                        let wrapped = crate::syntax::ast::Expr {
                            kind: ExprKind::Quantity {
                                value: 1.0,
                                unit: Some(u.clone()),
                            },
                            span: u.span,
                        };
                        let f = self.value(v.scope, &wrapped)?;
                        (value * scalar_of(&f), d.times(f.dim()))
                    }
                    (Value::Scalar { value, dim: d }, None) => (value, d),
                    (other, _) => {
                        self.error(
                            v.scope,
                            Diagnostic::error(
                                Code::E0209,
                                format!(
                                    "a stiffness entry must be a constant scalar, found {}",
                                    other.kind_name()
                                ),
                            )
                            .at(item.span, "here")
                            .hint("write numbers with units"),
                        );
                        return None;
                    }
                };
                if x != 0.0 && d != dim {
                    self.error(
                        v.scope,
                        Diagnostic::error(Code::E0202, format!("stiffness entry ({}, {}) must be {}, found {}", i + 1, j + 1, dim.describe(), d.describe()))
                            .at(item.span, format!("this is {}", d.describe()))
                            .hint("rows and columns 1-3 are forces (N), 4-6 moments (N*m): the blocks are N, N*m and N*m^2"),
                    );
                    return None;
                }
                k[i][j] = x;
            }
        }
        Some(k)
    }

    pub(super) fn beam(&mut self, v: &View) -> Option<Built> {
        if !self.shape(
            v,
            0,
            false,
            false,
            &["rigid"],
            "beam NAME { from = ..., to = ..., section = S, elements = 4 }",
        ) {
            return None;
        }
        let of = format!("beam `{}`", v.name);
        let p = self.props(
            v.scope,
            v.block.as_ref(),
            &[
                "from",
                "to",
                "section",
                "elements",
                "order",
                "twist",
                "e2",
                "velocity",
                "angular_velocity",
                "spin_stretch",
            ],
            "a beam",
        );
        let get = |this: &mut Self, key: &str| {
            this.required(v.scope, &p, key, v.name_span, &of, "(0, 0, 0) m")
                .and_then(|e| this.vector(v.scope, e, Dim::LENGTH, &format!("`{key}`")))
        };
        let from = get(self, "from");
        let to = get(self, "to");
        let section = match p.get("section").map(|s| s.value.clone()) {
            Some(PropValue::Block(b)) => self.section(v, &b, format!("{}.section", v.name)),
            Some(PropValue::Expr(e)) => self.section_ref(v, &e),
            None => {
                self.missing(
                    v.scope,
                    v.name_span,
                    "section",
                    &of,
                    "NAME` or `section = { EA = ..., ... }",
                );
                None
            }
        };
        let elements = match self.expr(v.scope, p.get("elements")) {
            Some(e) => match self.integer(v.scope, e, "`elements`", 1) {
                Some(n) if n > 10_000 => {
                    self.error(
                        v.scope,
                        Diagnostic::error(Code::E0213, format!("beam `{}` has {n} elements", v.name))
                            .at(e.span, "more than 10000")
                            .hint("beams are limited to 10000 elements; a few dozen resolve a rotor blade's first modes"),
                    );
                    None
                }
                n => n,
            },
            None => Some(1),
        };
        let order = match self.expr(v.scope, p.get("order")) {
            Some(e) => {
                let o = self.integer(v.scope, e, "`order`", 2);
                match o {
                    Some(n @ 2..=4) => Some(n),
                    Some(n) => {
                        self.error(
                            v.scope,
                            Diagnostic::error(Code::E0213, format!("`order` = {n}: beam elements have 2, 3 or 4 nodes"))
                                .at(e.span, "not 2, 3 or 4")
                                .hint("`order` is the number of nodes per element: 2 (linear), 3 (quadratic, the default) or 4 (cubic)"),
                        );
                        None
                    }
                    None => None,
                }
            }
            None => Some(3),
        };
        let twist = match self.expr(v.scope, p.get("twist")) {
            Some(e) => {
                let x = self.scalar(v.scope, e, units::ANGLE, "`twist`");
                if x.is_some() {
                    self.angle_unit(v.scope, Some(e), x, "`twist`");
                }
                x
            }
            None => Some(0.0),
        };
        let e2 = match self.expr(v.scope, p.get("e2")) {
            Some(e) => self.direction(v.scope, e, "`e2`").map(Some),
            None => Some(None),
        };
        let (velocity, angular_velocity) = self.motion(v, &p);
        let spin = match self.expr(v.scope, p.get("spin_stretch")) {
            Some(e) => self
                .scalar(v.scope, e, Dim::new(0, 0, -1), "`spin_stretch`")
                .map(|w| Some((w, e.span))),
            None => Some(None),
        };
        let (from, to, section, elements, order, twist, e2, spin) =
            (from?, to?, section?, elements?, order?, twist?, e2?, spin?);
        let d = sub(to, from);
        let length = norm(d);
        if length == 0.0 {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0303, format!("beam `{}` has zero length", v.name))
                    .at(v.name_span, "`from` and `to` coincide")
                    .hint("place `to` away from `from`"),
            );
            return None;
        }
        let e1 = scale(d, 1.0 / length);
        let guess = e2.unwrap_or(if e1[2].abs() < 0.999 {
            cross([0.0, 0.0, 1.0], e1)
        } else {
            cross(e1, [1.0, 0.0, 0.0])
        });
        let g = sub(guess, scale(e1, dot(guess, e1)));
        if norm(g) < 1e-9 {
            self.error(
                v.scope,
                Diagnostic::error(
                    Code::E0303,
                    format!("`e2` of beam `{}` is parallel to the beam", v.name),
                )
                .at(
                    p.get("e2").map(|q| q.span()).unwrap_or(v.name_span),
                    "parallel to the beam axis",
                )
                .hint("`e2` sets the section's axis 2; give a direction across the beam"),
            );
            return None;
        }
        let e2 = scale(g, 1.0 / norm(g));
        let e3 = cross(e1, e2);
        let base = [
            [e1[0], e2[0], e3[0]],
            [e1[1], e2[1], e3[1]],
            [e1[2], e2[2], e3[2]],
        ];
        let frame = mat_mul(base, rotation([1.0, 0.0, 0.0], twist));
        if Self::has_flag(v, "rigid") {
            let nodes = elements * (order - 1) + 1;
            return self.rigid_beam(
                v,
                &section,
                from,
                length,
                nodes,
                frame,
                velocity,
                angular_velocity,
            );
        }
        let n = elements * (order - 1) + 1;
        let nodes: Vec<[f64; 3]> = (0..n)
            .map(|k| add(from, scale(d, k as f64 / (n - 1) as f64)))
            .collect();
        // The steady centrifugal stretch of a beam spinning about an axis through its start:
        // u(s) = sin(b s) / (b cos(b L)) - s, b^2 = m Omega^2 / EA.
        let mut initial_nodes = nodes.clone();
        if let Some((w, wspan)) = spin {
            let b = (section.mass_per_length * w * w / section.stiffness[0][0]).sqrt();
            if (b * length).cos() <= 1e-6 {
                self.error(
                    v.scope,
                    Diagnostic::error(
                        Code::E0213,
                        format!(
                            "beam `{}` spins at or above its first axial resonance",
                            v.name
                        ),
                    )
                    .at(wspan, "no steady stretched state")
                    .hint("check the spin rate, EA and the mass per length"),
                );
                return None;
            }
            for (k, x) in initial_nodes.iter_mut().enumerate() {
                let s = length * k as f64 / (n - 1) as f64;
                let u = if b > 0.0 {
                    (b * s).sin() / (b * (b * length).cos()) - s
                } else {
                    0.0
                };
                *x = add(*x, scale(e1, u));
            }
        }
        let velocities = initial_nodes
            .iter()
            .map(|x| add(velocity, cross(angular_velocity, sub(*x, from))))
            .collect();
        if let Some(b) = &v.block {
            for m in &b.markers {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0306, "name points on a beam by arc length")
                        .at(m.span, "not allowed on a beam")
                        .hint(format!("refer to `{0}.start`, `{0}.end`, `{0}.node[k]` or `{0}.at(s)` directly", v.name)),
                );
            }
        }
        self.beams.push(Beam {
            name: v.name.clone(),
            span: v.span,
            section,
            elements,
            order,
            angular_velocities: vec![angular_velocity; n],
            velocities,
            nodes,
            initial_nodes,
            frame,
            length,
            point_masses: Vec::new(),
        });
        self.beam_decl.push(v.decl);
        Some(Built::Beam(self.beams.len() - 1))
    }

    /// `beam NAME rigid`: one rigid body with the section's mass integrated along the beam.
    #[allow(clippy::too_many_arguments)]
    fn rigid_beam(
        &mut self,
        v: &View,
        s: &Section,
        from: [f64; 3],
        length: f64,
        nodes: usize,
        frame: Mat3,
        velocity: [f64; 3],
        angular_velocity: [f64; 3],
    ) -> Option<Built> {
        let m = s.mass_per_length * length;
        let center = [length / 2.0, s.mass_offset[0], s.mass_offset[1]];
        let bend = s.mass_per_length * length.powi(3) / 12.0;
        let inertia = [
            [s.inertia[0] * length, 0.0, 0.0],
            [0.0, s.inertia[1] * length + bend, 0.0],
            [0.0, 0.0, s.inertia[2] * length + bend],
        ];
        let mut markers = vec![
            ("start".to_string(), [0.0; 3], IDENTITY),
            ("end".to_string(), [length, 0.0, 0.0], IDENTITY),
            ("center".to_string(), center, IDENTITY),
        ];
        if let Some(b) = &v.block {
            for mk in &b.markers {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0306, "name points on a beam by arc length")
                        .at(mk.span, "not allowed on a beam")
                        .hint(format!(
                            "refer to `{0}.start`, `{0}.end` or `{0}.at(s)` directly",
                            v.name
                        )),
                );
            }
        }
        markers.dedup_by(|a, b| a.0 == b.0);
        self.push_body(
            v,
            Body {
                name: v.name.clone(),
                span: v.span,
                kind: BodyKind::Rigid,
                mass: m,
                center,
                inertia,
                position: from,
                orientation: frame,
                velocity,
                angular_velocity,
                markers,
                beam_axis: Some((length, nodes)),
            },
        )
    }

    fn section_ref(&mut self, v: &View, e: &crate::syntax::ast::Expr) -> Option<Section> {
        use crate::syntax::ast::ExprKind;
        let ExprKind::Path { path } = &e.kind else {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0222, "`section` names a section")
                    .at(e.span, "not a name")
                    .hint("write `section = NAME` or `section = { EA = ..., ... }`"),
            );
            return None;
        };
        let r = self
            .env
            .segs(v.scope, path)
            .and_then(|s| self.env.resolve(v.scope, &s, path.span));
        match r {
            Ok((Ref::Decl(d), rest)) if rest.is_empty() => match self.built[d] {
                Some(Built::Section(i)) => Some(self.sections[i].clone()),
                None if self.env.decls[d].item_kind() == Some("section") => None,
                _ => {
                    self.error(
                        v.scope,
                        Diagnostic::error(
                            Code::E0222,
                            format!("`{}` is not a section", self.env.decls[d].name),
                        )
                        .at(e.span, "not a section")
                        .hint("declare one with `section NAME { ... }`"),
                    );
                    None
                }
            },
            Ok(_) => {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0222, "`section` names a section")
                        .at(e.span, "not a section")
                        .hint("declare one with `section NAME { ... }`"),
                );
                None
            }
            Err(d) => {
                self.error(v.scope, d);
                None
            }
        }
    }
}

fn scalar_of(v: &Value) -> f64 {
    match v {
        Value::Scalar { value, .. } => *value,
        _ => 1.0,
    }
}
