//! Beams: their nodes along `from`-`to`, the section frame (`e2`, `twist`), the steady spin
//! stretch and initial motion; `beam NAME rigid` becomes one rigid body. Contract: builds
//! `Beam`s (sections come from `sections.rs`); must not know beam elements or the runtime.

use super::curve::Curve;
use super::stations::{stations, twist_at};
use super::{add, cross, dot, norm, scale, sub, Builder, Built, View};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::eval::units::Dim;
use crate::model::eval::{mat_mul, rotation};
use crate::model::*;
use crate::syntax::ast::{Prop, PropValue};
use std::collections::HashMap;

type Props = HashMap<&'static str, Prop>;

/// How to write a curved beam's points.
const EXAMPLE: &str = "write `points = ((0, 0, 0) m, (1, 0, 0) m, (1.5, 0.5, 0) m)`";

/// A beam's properties, evaluated.
struct Layout {
    /// The points a curved beam runs through, and where they are written.
    points: Option<(Vec<[f64; 3]>, Span)>,
    from: [f64; 3],
    to: [f64; 3],
    section: Section,
    /// Stations `(arc length, section)` of a varying section (empty: `section` everywhere),
    /// and where they are written.
    sections: (Vec<(f64, Section)>, Span),
    elements: usize,
    order: usize,
    /// Stations `(arc length, twist)`, linear between, held beyond the ends (one station for a
    /// constant twist), and where they are written.
    twist: (Vec<(f64, f64)>, Span),
    e2: Option<[f64; 3]>,
    velocity: [f64; 3],
    angular_velocity: [f64; 3],
    /// `spin_stretch`: the spin rate and where it is written.
    spin: Option<(f64, Span)>,
}

impl Builder<'_> {
    pub(super) fn beam(&mut self, v: &View) -> Option<Built> {
        if !self.shape(
            v,
            0,
            false,
            false,
            &["rigid", "polyline"],
            "beam NAME { from = ..., to = ..., section = S, elements = 4 }",
        ) {
            return None;
        }
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
                "points",
            ],
            "a beam",
        );
        let b = self.beam_layout(v, &p)?;
        let d = sub(b.to, b.from);
        let n = b.elements * (b.order - 1) + 1;
        let rigid = Self::has_flag(v, "rigid") && !self.elastic;
        // Each node's position and axis 1: along the curve through `points`, or the straight
        // line from `from` to `to`.
        let (length, along) = match &b.points {
            Some((points, span)) => {
                let curve = self.curve(v, points, *span, rigid || b.spin.is_some())?;
                let length = curve.length();
                let along: Vec<_> = (0..n)
                    .map(|k| curve.at(length * k as f64 / (n - 1) as f64))
                    .collect();
                (length, along)
            }
            None => {
                let e1 = self.axis(v, d)?;
                let along = (0..n)
                    .map(|k| (add(b.from, scale(d, k as f64 / (n - 1) as f64)), e1))
                    .collect();
                (norm(d), along)
            }
        };
        let e1 = along[0].1;
        let varies = b.twist.0.iter().any(|&(_, a)| a != b.twist.0[0].1);
        let at: Vec<f64> = b.twist.0.iter().map(|&(s, _)| s).collect();
        let refuse = (rigid && varies).then_some("a varying twist on a rigid beam");
        self.check_stations(v, "twist", (&at, b.twist.1), length, refuse)?;
        if !b.sections.0.is_empty() {
            let at: Vec<f64> = b.sections.0.iter().map(|&(s, _)| s).collect();
            let refuse = if rigid {
                Some("a varying section on a rigid beam")
            } else {
                b.spin.map(|_| "a varying section with `spin_stretch`")
            };
            self.check_stations(v, "section", (&at, b.sections.1), length, refuse)?;
        }
        let mut frames: Vec<Mat3> = Vec::with_capacity(n);
        for &(_, e1) in &along {
            let base = match frames.first() {
                // A straight beam's axis is the same at every node.
                Some(&f) if b.points.is_none() => f,
                _ => self.section_frame(v, &p, e1, &b)?,
            };
            frames.push(base);
        }
        for (k, f) in frames.iter_mut().enumerate() {
            let s = length * k as f64 / (n - 1) as f64;
            *f = mat_mul(*f, rotation([1.0, 0.0, 0.0], twist_at(&b.twist.0, s)));
        }
        if rigid {
            return self.rigid_beam(v, &b, length, n, frames[0]);
        }
        let nodes: Vec<[f64; 3]> = along.iter().map(|&(x, _)| x).collect();
        let initial_nodes = self.spin_stretch(v, &b, &nodes, e1, length)?;
        let velocities = initial_nodes
            .iter()
            .map(|x| add(b.velocity, cross(b.angular_velocity, sub(*x, b.from))))
            .collect();
        if let Some(block) = &v.block {
            for m in &block.markers {
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
            section: b.section,
            sections: b.sections.0,
            elements: b.elements,
            order: b.order,
            angular_velocities: vec![b.angular_velocity; n],
            velocities,
            nodes,
            initial_nodes,
            frames,
            length,
            point_masses: Vec::new(),
            masses_between: Vec::new(),
        });
        self.beam_decl.push(v.decl);
        Some(Built::Beam(self.beams.len() - 1))
    }

    /// Every property of a beam, each reported when wrong; `None` if one is.
    fn beam_layout(&mut self, v: &View, p: &Props) -> Option<Layout> {
        let of = format!("beam `{}`", v.name);
        let get = |this: &mut Self, key: &str| {
            this.required(v.scope, p, key, v.name_span, &of, "(0, 0, 0) m")
                .and_then(|e| this.vector(v.scope, e, Dim::LENGTH, &format!("`{key}`")))
        };
        let points = match self.expr(v.scope, p.get("points")) {
            Some(e) => self.points(v.scope, e).map(|x| Some((x, e.span))),
            None => Some(None),
        };
        let (from, to) = match &points {
            Some(Some((x, span))) => {
                if let Some(q) = p.get("from").or(p.get("to")) {
                    self.error(
                        v.scope,
                        Diagnostic::error(Code::E0224, format!("beam `{}` gives both `points` and `from`/`to`", v.name))
                            .at(q.name.span, "here")
                            .at(*span, "and here")
                            .hint("a curved beam runs through `points`, from the first to the last; a straight one from `from` to `to`"),
                    );
                }
                (x.first().copied(), x.last().copied())
            }
            _ => (get(self, "from"), get(self, "to")),
        };
        let mut sections = (Vec::new(), v.name_span);
        let section = match p.get("section").map(|s| s.value.clone()) {
            Some(PropValue::Block(b)) => self.section(v, &b, format!("{}.section", v.name)),
            Some(PropValue::Expr(e)) if stations(&e).is_some() => {
                sections = (self.section_stations(v, &e)?, e.span);
                sections.0.first().map(|(_, x)| x.clone())
            }
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
        let (elements, order) = self.discretization(v, p);
        let twist = match self.expr(v.scope, p.get("twist")) {
            Some(e) => self.twist(v.scope, e).map(|t| (t, e.span)),
            None => Some((vec![(0.0, 0.0)], v.name_span)),
        };
        let e2 = match self.expr(v.scope, p.get("e2")) {
            Some(e) => self.direction(v.scope, e, "`e2`").map(Some),
            None => Some(None),
        };
        let (velocity, angular_velocity) = self.motion(v, p);
        let spin = match self.expr(v.scope, p.get("spin_stretch")) {
            Some(e) => self
                .scalar(v.scope, e, Dim::new(0, 0, -1), "`spin_stretch`")
                .map(|w| Some((w, e.span))),
            None => Some(None),
        };
        Some(Layout {
            points: points?,
            from: from?,
            to: to?,
            section: section?,
            sections,
            elements: elements?,
            order: order?,
            twist: twist?,
            e2: e2?,
            velocity,
            angular_velocity,
            spin: spin?,
        })
    }

    /// `elements` (1 to 10,000, default 1) and `order` (2, 3 or 4 nodes, default 3).
    fn discretization(&mut self, v: &View, p: &Props) -> (Option<usize>, Option<usize>) {
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
        (elements, order)
    }

    /// `points = (P1, P2, ...)`: lengths, each point a vector.
    fn points(&mut self, scope: usize, e: &crate::syntax::ast::Expr) -> Option<Vec<[f64; 3]>> {
        use crate::syntax::ast::ExprKind;
        let ExprKind::Vector { items, unit: None } = &e.kind else {
            self.error(
                scope,
                Diagnostic::error(Code::E0209, "`points` is a list of points")
                    .at(e.span, "not a list of points")
                    .hint("write `points = ((0, 0, 0) m, (1, 0, 0) m, (1.5, 0.5, 0) m)`"),
            );
            return None;
        };
        let points: Vec<Option<[f64; 3]>> = items
            .iter()
            .map(|x| self.vector(scope, x, Dim::LENGTH, "a point of `points`"))
            .collect();
        points.into_iter().collect()
    }

    /// The beam's axis 1 and its section frame at t = 0 before the twist (axis 2 from `e2` or
    /// a default across the beam).
    fn section_frame(&mut self, v: &View, p: &Props, e1: [f64; 3], b: &Layout) -> Option<Mat3> {
        let guess = b.e2.unwrap_or(if e1[2].abs() < 0.999 {
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
        Some(base)
    }

    /// A straight beam's axis 1, from `from` to `to` (`d`).
    fn axis(&mut self, v: &View, d: [f64; 3]) -> Option<[f64; 3]> {
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
        Some(scale(d, 1.0 / length))
    }

    /// The reference line through `points` (a polyline with the `polyline` flag, else the
    /// smooth curve through them); `straight_only`: the beam is `rigid` or starts with
    /// `spin_stretch`, which need a straight beam.
    fn curve(
        &mut self,
        v: &View,
        points: &[[f64; 3]],
        span: Span,
        straight_only: bool,
    ) -> Option<Curve> {
        let problem = if straight_only {
            Some((
                Code::E0213,
                "is `rigid` or starts with `spin_stretch`, which need a straight beam",
                "give `from` and `to` for a straight beam, or drop `rigid` and `spin_stretch`"
                    .to_string(),
            ))
        } else if points.len() < 2 {
            Some((Code::E0209, "needs two points or more", EXAMPLE.to_string()))
        } else {
            None
        };
        let curve = match problem {
            Some(_) => None,
            None => Curve::new(points, Self::has_flag(v, "polyline")),
        };
        if curve.is_none() {
            let (code, what, hint) = problem.unwrap_or((
                Code::E0303,
                "cannot follow points that coincide",
                format!("consecutive points must be apart; {EXAMPLE}"),
            ));
            self.error(
                v.scope,
                Diagnostic::error(code, format!("curved beam `{}` {what}", v.name))
                    .at(span, "the reference line's points")
                    .hint(hint),
            );
        }
        curve
    }

    /// The nodes at t = 0: with `spin_stretch`, the steady centrifugal stretch of a beam
    /// spinning about an axis through its start, u(s) = sin(b s) / (b cos(b L)) - s,
    /// b^2 = m Omega^2 / EA.
    fn spin_stretch(
        &mut self,
        v: &View,
        b: &Layout,
        nodes: &[[f64; 3]],
        e1: [f64; 3],
        length: f64,
    ) -> Option<Vec<[f64; 3]>> {
        let mut initial_nodes = nodes.to_vec();
        let Some((w, wspan)) = b.spin else {
            return Some(initial_nodes);
        };
        let n = nodes.len();
        let section = &b.section;
        let beta = (section.mass_per_length * w * w / section.stiffness[0][0]).sqrt();
        if (beta * length).cos() <= 1e-6 {
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
            let u = if beta > 0.0 {
                (beta * s).sin() / (beta * (beta * length).cos()) - s
            } else {
                0.0
            };
            *x = add(*x, scale(e1, u));
        }
        Some(initial_nodes)
    }

    /// `beam NAME rigid`: one rigid body with the section's mass integrated along the beam.
    fn rigid_beam(
        &mut self,
        v: &View,
        b: &Layout,
        length: f64,
        nodes: usize,
        frame: Mat3,
    ) -> Option<Built> {
        let s = &b.section;
        let m = s.mass_per_length * length;
        let center = [length / 2.0, s.mass_offset[0], s.mass_offset[1]];
        let bend = s.mass_per_length * length.powi(3) / 12.0;
        let mut inertia = s.inertia.map(|row| row.map(|x| x * length));
        inertia[1][1] += bend;
        inertia[2][2] += bend;
        let mut markers = vec![
            ("start".to_string(), [0.0; 3], IDENTITY),
            ("end".to_string(), [length, 0.0, 0.0], IDENTITY),
            ("center".to_string(), center, IDENTITY),
        ];
        if let Some(block) = &v.block {
            for mk in &block.markers {
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
                position: b.from,
                orientation: frame,
                velocity: b.velocity,
                angular_velocity: b.angular_velocity,
                markers,
                beam_axis: Some((length, nodes)),
            },
        )
    }
}
