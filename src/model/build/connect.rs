//! Connections: the marker pair of a joint or spring, springs and dampers, and loads.
//! Contract: builds `Spring`s and `Load`s from their declarations, markers resolved through
//! `marker`; must not know unknowns, rows or the runtime.

use super::{norm, sub, Builder, Built, View};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::eval::units::{self, Dim, Quantity};
use crate::model::*;
use crate::syntax::ast::MarkerRef;

impl Builder<'_> {
    /// W0203 if the angle `e` of `what` is a bare number (`value`: its constant value, `None`
    /// for a function of time).
    pub(super) fn angle_unit(
        &mut self,
        scope: usize,
        e: Option<&crate::syntax::ast::Expr>,
        value: Option<f64>,
        what: &str,
    ) {
        if let Some(d) = e.and_then(|e| self.env.bare_angle(scope, e, value, what)) {
            self.error(scope, d);
        }
    }

    /// Resolves the two markers of a connection and rejects one that connects nothing.
    pub(super) fn pair(
        &mut self,
        scope: usize,
        what: &str,
        name: &str,
        markers: &[MarkerRef],
        span: Span,
    ) -> Option<[Marker; 2]> {
        if markers.len() != 2 {
            self.error(
                scope,
                Diagnostic::error(
                    Code::E0224,
                    format!(
                        "{what} `{name}` connects 2 markers, found {}",
                        markers.len()
                    ),
                )
                .at(markers.first().map(|m| m.span).unwrap_or(span), "here")
                .hint(format!("write `({}, {})`", "a", "b")),
            );
            return None;
        }
        let a = self.marker(scope, &markers[0]);
        let b = self.marker(scope, &markers[1]);
        let (a, b) = (a?, b?);
        let same = match (a.attach, b.attach) {
            (Attach::Ground { .. }, Attach::Ground { .. }) => {
                self.error(
                    scope,
                    Diagnostic::error(
                        Code::E0305,
                        format!("{what} `{name}` connects the ground to the ground"),
                    )
                    .at(markers[0].span, "fixed")
                    .at(markers[1].span, "fixed too")
                    .hint("connect at least one body"),
                );
                return None;
            }
            (Attach::Body { body: x }, Attach::Body { body: y }) => x == y,
            (Attach::BeamNode { beam: x, node: i }, Attach::BeamNode { beam: y, node: j }) => {
                x == y && i == j
            }
            _ => false,
        };
        if same {
            self.error(
                scope,
                Diagnostic::error(
                    Code::E0301,
                    format!("{what} `{name}` connects `{}` to itself", a.text),
                )
                .at(markers[0].span, "this marker")
                .at(markers[1].span, "and this one are on the same body")
                .hint("connect the body to another body or to ground"),
            );
            return None;
        }
        Some([a, b])
    }

    pub(super) fn spring(&mut self, v: &View) -> Option<Built> {
        let k = v.kind.name.as_str();
        let torsional = k.starts_with("torsional");
        let damper_only = k.ends_with("damper");
        let example = format!(
            "{k} NAME(a, b) {{ {} }}",
            if damper_only {
                "damping = ..."
            } else {
                "stiffness = ..."
            }
        );
        if !self.shape(v, 2, false, false, &[], &example) {
            return None;
        }
        let known: &[&'static str] = match (torsional, damper_only) {
            (false, false) => &["stiffness", "damping", "length"],
            (true, false) => &["stiffness", "damping"],
            (_, true) => &["damping"],
        };
        let p = self.props(v.scope, v.block.as_ref(), known, &format!("a {k}"));
        let pair = self.pair(v.scope, k, &v.name, &v.markers, v.span);
        let (kdim, cdim): (Quantity, Quantity) = if torsional {
            (units::TORSIONAL_STIFFNESS, Dim::new(1, 2, -1).into())
        } else {
            (Dim::new(1, 0, -2).into(), Dim::new(1, 0, -1).into())
        };
        let get = |this: &mut Self, key: &str, dim: Quantity, required: bool| match this
            .expr(v.scope, p.get(key))
        {
            Some(e) => this.scalar(v.scope, e, dim, &format!("`{key}`")),
            None => {
                if required && !p.contains_key(key) {
                    this.missing(
                        v.scope,
                        v.name_span,
                        key,
                        &format!("{k} `{}`", v.name),
                        if key == "damping" {
                            "10 N*s/m"
                        } else {
                            "1000 N/m"
                        },
                    );
                    return None;
                }
                Some(0.0)
            }
        };
        let stiffness = get(self, "stiffness", kdim, !damper_only);
        let damping = get(self, "damping", cdim, damper_only);
        let pair = pair?;
        let (stiffness, damping) = (stiffness?, damping?);
        if stiffness < 0.0 || damping < 0.0 {
            self.error(
                v.scope,
                Diagnostic::error(
                    Code::E0213,
                    format!("{k} `{}` has a negative coefficient", v.name),
                )
                .at(v.name_span, "here")
                .hint("stiffness and damping are non-negative"),
            );
            return None;
        }
        let d0 = norm(sub(pair[1].position, pair[0].position));
        let length = match self.expr(v.scope, p.get("length")) {
            Some(e) => self.scalar(v.scope, e, Dim::LENGTH, "`length`")?,
            None => d0,
        };
        if !torsional && d0 < 1e-12 && length == 0.0 {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0303, format!("{k} `{}` starts with coincident markers", v.name))
                    .at(v.span, "zero length: the force has no direction")
                    .hint("place the markers apart; to tie two points together elastically use a joint with a spring, or a `torsional_spring`"),
            );
            return None;
        }
        self.springs.push(Spring {
            name: v.name.clone(),
            span: v.span,
            kind: if torsional {
                SpringKind::Torsional
            } else {
                SpringKind::Linear
            },
            stiffness,
            damping,
            length,
            markers: pair,
        });
        Some(Built::Spring(self.springs.len() - 1))
    }

    pub(super) fn load(&mut self, v: &View) -> Option<Built> {
        let k = v.kind.name.as_str();
        let example = format!(
            "{k} NAME on MARKER = (x, y, z) {}",
            if k == "force" { "N" } else { "N*m" }
        );
        if !self.shape(v, 0, true, true, &["follower"], &example) {
            return None;
        }
        if let Some(b) = &v.block {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0224, format!("a {k} takes no block"))
                    .at(b.span, "here")
                    .hint(format!("write `{example}`")),
            );
        }
        let (on, value) = (v.on.clone()?, v.value.clone()?);
        let marker = self.marker(v.scope, &on);
        let dim = if k == "force" {
            Dim::FORCE.into()
        } else {
            units::TORQUE
        };
        let parts = self.signal(v.scope, &value, dim, &format!("{k} `{}`", v.name), true);
        let (marker, parts) = (marker?, parts?);
        if let Attach::Ground { .. } = marker.attach {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0306, format!("{k} `{}` acts on the ground", v.name))
                    .at(on.span, "the ground does not move")
                    .hint("apply it to a body; a reaction on the ground needs no declaration"),
            );
            return None;
        }
        let [a, b, c]: [TimeFn; 3] = parts.try_into().ok()?;
        self.loads.push(Load {
            name: v.name.clone(),
            span: v.span,
            kind: if k == "force" {
                LoadKind::Force
            } else {
                LoadKind::Torque
            },
            marker,
            value: [a, b, c],
            follower: Self::has_flag(v, "follower"),
        });
        Some(Built::Load(self.loads.len() - 1))
    }
}
