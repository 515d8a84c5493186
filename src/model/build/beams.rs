//! Beams: their nodes along `from`-`to`, the section frame (`e2`, `twist`), the steady spin
//! stretch and initial motion; `beam NAME rigid` becomes one rigid body. Contract: builds
//! `Beam`s (sections come from `sections.rs`); must not know beam elements or the runtime.

use super::{add, cross, dot, norm, scale, sub, Builder, Built, View};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::eval::units::{self, Dim};
use crate::model::eval::{mat_mul, rotation};
use crate::model::*;
use crate::syntax::ast::{Prop, PropValue};
use std::collections::HashMap;

type Props = HashMap<&'static str, Prop>;

/// A beam's properties, evaluated.
struct Layout {
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
            &["rigid"],
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
            ],
            "a beam",
        );
        let b = self.beam_layout(v, &p)?;
        let d = sub(b.to, b.from);
        let length = norm(d);
        let (e1, base) = self.section_frame(v, &p, d, &b)?;
        let n = b.elements * (b.order - 1) + 1;
        let rigid = Self::has_flag(v, "rigid");
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
        let frames: Vec<Mat3> = (0..n)
            .map(|k| {
                let s = length * k as f64 / (n - 1) as f64;
                mat_mul(base, rotation([1.0, 0.0, 0.0], twist_at(&b.twist.0, s)))
            })
            .collect();
        if Self::has_flag(v, "rigid") {
            return self.rigid_beam(v, &b, length, n, frames[0]);
        }
        let nodes: Vec<[f64; 3]> = (0..n)
            .map(|k| add(b.from, scale(d, k as f64 / (n - 1) as f64)))
            .collect();
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
        let from = get(self, "from");
        let to = get(self, "to");
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

    /// `twist`: an angle, or stations `((s, angle), ...)` with `s` the arc length from `from`.
    fn twist(&mut self, scope: usize, e: &crate::syntax::ast::Expr) -> Option<Vec<(f64, f64)>> {
        use crate::syntax::ast::ExprKind;
        let rows = match &e.kind {
            ExprKind::Vector { items, unit: None }
                if items
                    .iter()
                    .all(|r| matches!(&r.kind, ExprKind::Vector { .. })) =>
            {
                items
            }
            _ => {
                let x = self.scalar(scope, e, units::ANGLE, "`twist`");
                if x.is_some() {
                    self.angle_unit(scope, Some(e), x, "`twist`");
                }
                return x.map(|a| vec![(0.0, a)]);
            }
        };
        let mut out = Vec::with_capacity(rows.len());
        for row in rows {
            let ExprKind::Vector { items, unit: None } = &row.kind else {
                continue;
            };
            if items.len() != 2 {
                self.error(
                    scope,
                    Diagnostic::error(Code::E0209, "a twist station is an arc length and an angle")
                        .at(row.span, format!("{} entries", items.len()))
                        .hint("write `twist = ((0 m, 0 deg), (2.5 m, -8 deg))`: each station `(s, angle)`, s from the beam's `from`, each entry with its unit"),
                );
                return None;
            }
            let s = self.scalar(
                scope,
                &items[0],
                Dim::LENGTH,
                "a twist station's arc length",
            );
            let a = self.scalar(scope, &items[1], units::ANGLE, "a twist station's angle");
            if a.is_some() {
                self.angle_unit(scope, Some(&items[1]), a, "a twist station's angle");
            }
            out.push((s?, a?));
        }
        Some(out)
    }

    /// `section = ((s, NAME), ...)`: sections at stations, each a declared section.
    fn section_stations(
        &mut self,
        v: &View,
        e: &crate::syntax::ast::Expr,
    ) -> Option<Vec<(f64, Section)>> {
        let mut out = Vec::new();
        for items in stations(e)? {
            if items.len() != 2 {
                self.error(
                    v.scope,
                    Diagnostic::error(Code::E0209, "a section station is an arc length and a section")
                        .at(e.span, format!("a station with {} entries", items.len()))
                        .hint("write `section = ((0 m, root), (2.5 m, tip))`: each station `(s, NAME)`, s from the beam's `from`, NAME a declared section"),
                );
                return None;
            }
            let s = self.scalar(
                v.scope,
                &items[0],
                Dim::LENGTH,
                "a section station's arc length",
            );
            let section = self.section_ref(v, &items[1]);
            out.push((s?, section?));
        }
        Some(out)
    }

    /// Stations (of the twist or the section, `what`) within the beam (`0 <= s <= length`), in
    /// increasing arc length; `refuse` says why the beam takes none.
    fn check_stations(
        &mut self,
        v: &View,
        what: &str,
        (at, span): (&[f64], Span),
        length: f64,
        refuse: Option<&str>,
    ) -> Option<()> {
        let inside = at
            .iter()
            .all(|&s| (-1e-12 * length..=length * (1.0 + 1e-12)).contains(&s));
        let increasing = at.windows(2).all(|w| w[1] > w[0]);
        let problem = if at.is_empty() {
            Some("no station")
        } else if !inside {
            Some("a station outside the beam")
        } else if !increasing {
            Some("stations not in increasing arc length")
        } else {
            refuse
        };
        let Some(problem) = problem else {
            return Some(());
        };
        self.error(
            v.scope,
            Diagnostic::error(Code::E0213, format!("the {what} of beam `{}` has {problem}", v.name))
                .at(span, problem)
                .hint(format!("give stations `(s, {what})` with s increasing from 0 to the beam's length ({length} m); a `rigid` beam takes one {what}, and `spin_stretch` one section")),
        );
        None
    }

    /// The beam's axis 1 and its section frame at t = 0 before the twist (axis 2 from `e2` or
    /// a default across the beam).
    fn section_frame(
        &mut self,
        v: &View,
        p: &Props,
        d: [f64; 3],
        b: &Layout,
    ) -> Option<([f64; 3], Mat3)> {
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
        Some((e1, base))
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

/// The twist at arc length `s`: linear between the stations, held beyond the ends.
pub(super) fn twist_at(stations: &[(f64, f64)], s: f64) -> f64 {
    match stations {
        [] => 0.0,
        [(s0, a0), ..] if s <= *s0 => *a0,
        [.., (sl, al)] if s >= *sl => *al,
        _ => stations.windows(2).find(|w| s <= w[1].0).map_or(0.0, |w| {
            let f = (s - w[0].0) / (w[1].0 - w[0].0);
            w[0].1 + f * (w[1].1 - w[0].1)
        }),
    }
}

/// The rows of a table of stations, `((a, b), (c, d), ...)`: a vector of vectors (no unit
/// after the outer parenthesis, none after the rows); `None` if `e` is not one.
fn stations(e: &crate::syntax::ast::Expr) -> Option<Vec<Vec<crate::syntax::ast::Expr>>> {
    use crate::syntax::ast::ExprKind;
    let ExprKind::Vector { items, unit: None } = &e.kind else {
        return None;
    };
    items
        .iter()
        .map(|r| match &r.kind {
            ExprKind::Vector { items, unit: None } => Some(items.clone()),
            _ => None,
        })
        .collect()
}
