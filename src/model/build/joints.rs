//! Joints: the kind is parsed once into [`Kind`], which knows its properties and its free
//! motion; small functions check the axes, where the markers meet, the drives and the length.
//! Contract: builds one `Joint` from its declaration with markers resolved by `pair`; must
//! not know unknowns, rows or the runtime.

use super::{dot, norm, scale, sub, Builder, Built};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::model::eval::units::{self, Dim, Quantity};
use crate::model::*;
use crate::syntax::ast::{Expr, Item, MarkerRef, Prop, PropValue};
use std::collections::HashMap;

/// A joint kind as written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Revolute,
    Prismatic,
    Cylindrical,
    Universal,
    Spherical,
    Fixed,
    Distance,
}

impl Kind {
    /// Every kind, in the order "did you mean" lists them.
    const ALL: [Kind; 7] = [
        Kind::Revolute,
        Kind::Spherical,
        Kind::Fixed,
        Kind::Prismatic,
        Kind::Universal,
        Kind::Cylindrical,
        Kind::Distance,
    ];

    fn name(self) -> &'static str {
        match self {
            Kind::Revolute => "revolute",
            Kind::Prismatic => "prismatic",
            Kind::Cylindrical => "cylindrical",
            Kind::Universal => "universal",
            Kind::Spherical => "spherical",
            Kind::Fixed => "fixed",
            Kind::Distance => "distance",
        }
    }

    fn parse(name: &str) -> Option<Kind> {
        Kind::ALL.into_iter().find(|k| k.name() == name)
    }

    /// The properties its block may set.
    fn props(self) -> &'static [&'static str] {
        match self {
            Kind::Revolute => REVOLUTE.props,
            Kind::Prismatic => PRISMATIC.props,
            Kind::Cylindrical => &["axis"],
            Kind::Universal => &["axis1", "axis2"],
            Kind::Spherical | Kind::Fixed => &[],
            Kind::Distance => &["length"],
        }
    }
}

/// The one free motion of a revolute (an angle) or prismatic (a displacement) joint: the
/// names and quantities of its properties.
struct Motion {
    revolute: bool,
    props: &'static [&'static str],
    spring: Quantity,
    damper: Quantity,
    motion: Quantity,
    load: Quantity,
    /// The prescribed position, the prescribed rate and the applied load.
    position_key: &'static str,
    rate_key: &'static str,
    load_key: &'static str,
}

const REVOLUTE: Motion = Motion {
    revolute: true,
    props: &[
        "axis",
        "spring",
        "damper",
        "rest_angle",
        "angle",
        "rate",
        "torque",
    ],
    spring: units::TORSIONAL_STIFFNESS,
    damper: Dim::new(1, 2, -1).quantity(),
    motion: units::ANGLE,
    load: units::TORQUE,
    position_key: "angle",
    rate_key: "rate",
    load_key: "torque",
};

const PRISMATIC: Motion = Motion {
    revolute: false,
    props: &["axis", "spring", "damper", "displacement", "speed", "force"],
    spring: Dim::new(1, 0, -2).quantity(),
    damper: Dim::new(1, 0, -1).quantity(),
    motion: Dim::LENGTH.quantity(),
    load: Dim::FORCE.quantity(),
    position_key: "displacement",
    rate_key: "speed",
    load_key: "force",
};

/// One joint declaration being built.
struct Decl<'a> {
    scope: usize,
    name: &'a str,
    kind: Kind,
    kind_span: Span,
    span: Span,
    markers: &'a [MarkerRef],
    props: HashMap<&'static str, Prop>,
    pair: &'a [Marker; 2],
}

/// A property's expression, if it is one (not a block).
fn prop_expr(p: &Prop) -> Option<&Expr> {
    match &p.value {
        PropValue::Expr(e) => Some(e),
        PropValue::Block(_) => None,
    }
}

impl Decl<'_> {
    fn prop_span(&self, key: &str) -> Span {
        self.props.get(key).map(|q| q.span()).unwrap_or(self.span)
    }
}

impl Builder<'_> {
    pub(super) fn joint(&mut self, d: usize) {
        let decl = &self.env.decls[d];
        let (scope, qname) = (decl.scope, decl.name.clone());
        let Item::Joint {
            kind,
            markers,
            block,
            span,
            ..
        } = &*decl.item.clone()
        else {
            return;
        };
        let Some(k) = Kind::parse(&kind.name) else {
            let names: Vec<&str> = Kind::ALL.iter().map(|k| k.name()).collect();
            let hint = match did_you_mean(&kind.name, names.iter().copied()) {
                Some(s) => format!("did you mean `{s}`? Joints: {}", names.join(", ")),
                None => format!("joints: {}", names.join(", ")),
            };
            self.error(
                scope,
                Diagnostic::error(Code::E0211, format!("unknown joint kind `{}`", kind.name))
                    .at(kind.span, "not a joint kind")
                    .hint(hint),
            );
            return;
        };
        let of = format!("a {} joint", kind.name);
        let props = self.props(scope, Some(block), k.props(), &of);
        let Some(pair) = self.pair(scope, "joint", &qname, markers, *span) else {
            return;
        };
        let j = Decl {
            scope,
            name: &qname,
            kind: k,
            kind_span: kind.span,
            span: *span,
            markers,
            props,
            pair: &pair,
        };
        let Some(kind) = self.joint_kind(&j) else {
            return;
        };
        self.joints.push(Joint {
            name: qname,
            span: *span,
            kind,
            markers: pair,
        });
        self.built[d] = Some(Built::Joint(self.joints.len() - 1));
    }

    fn joint_kind(&mut self, j: &Decl) -> Option<JointKind> {
        match j.kind {
            Kind::Revolute => self.sliding(j, &REVOLUTE),
            Kind::Prismatic => self.sliding(j, &PRISMATIC),
            Kind::Cylindrical => {
                let n = self.joint_axis(j, "axis")?;
                self.coincide(j, Some(n))
                    .then_some(JointKind::Cylindrical { axis: n })
            }
            Kind::Universal => self.universal(j),
            Kind::Spherical => self.coincide(j, None).then_some(JointKind::Spherical),
            Kind::Fixed => self.coincide(j, None).then_some(JointKind::Fixed),
            Kind::Distance => self.distance(j),
        }
    }

    fn joint_axis(&mut self, j: &Decl, key: &str) -> Option<[f64; 3]> {
        let of = format!("joint `{}`", j.name);
        self.required(j.scope, &j.props, key, j.kind_span, &of, "z")
            .and_then(|e| self.direction(j.scope, e, &format!("`{key}`")))
    }

    /// Whether the markers coincide at the start (or lie on the axis `along`); E0310 if not.
    fn coincide(&mut self, j: &Decl, along: Option<[f64; 3]>) -> bool {
        let [a, b] = j.pair;
        let gap = sub(b.position, a.position);
        let size = 1.0f64.max(norm(a.position)).max(norm(b.position));
        let off = match along {
            Some(n) => sub(gap, scale(n, dot(gap, n))),
            None => gap,
        };
        if norm(off) > 1e-8 * size {
            let what = if along.is_some() {
                "off its axis by"
            } else {
                "apart by"
            };
            let at = |p: [f64; 3]| format!("at ({:.4}, {:.4}, {:.4})", p[0], p[1], p[2]);
            self.error(
                j.scope,
                Diagnostic::error(Code::E0310, format!("the markers of joint `{}` are {what} {:.6} m at the start", j.name, norm(off)))
                    .at(j.markers[0].span, at(a.position))
                    .at(j.markers[1].span, at(b.position))
                    .hint("place the bodies so the joint's points coincide (or lie on its axis), or move a marker with `body @ (x, y, z)`"),
            );
            return false;
        }
        true
    }

    /// An optional constant property, 0 when not written.
    fn joint_scalar(&mut self, j: &Decl, key: &str, dim: Quantity) -> Option<f64> {
        match self.expr(j.scope, j.props.get(key)) {
            Some(e) => self.scalar(j.scope, e, dim, &format!("`{key}`")),
            None => Some(0.0),
        }
    }

    /// An optional function of time; `Some(None)` when not written.
    fn joint_signal(&mut self, j: &Decl, key: &str, dim: Quantity) -> Option<Option<TimeFn>> {
        match self.expr(j.scope, j.props.get(key)) {
            Some(e) => self
                .signal(j.scope, e, dim, &format!("`{key}`"), false)
                .map(|mut v| Some(v.remove(0))),
            None => Some(None),
        }
    }

    /// A revolute or prismatic joint: its axis, spring, damper and drive.
    fn sliding(&mut self, j: &Decl, m: &Motion) -> Option<JointKind> {
        let n = self.joint_axis(j, "axis")?;
        if !self.coincide(j, if m.revolute { None } else { Some(n) }) {
            return None;
        }
        let spring = self.joint_scalar(j, "spring", m.spring);
        let damper = self.joint_scalar(j, "damper", m.damper);
        let rest = if m.revolute {
            self.joint_scalar(j, "rest_angle", units::ANGLE)
        } else {
            Some(0.0)
        };
        let position = self.joint_signal(j, m.position_key, m.motion);
        let rate_dim = m.motion.dim.over(Dim::TIME).into();
        let rate = self.joint_signal(j, m.rate_key, rate_dim);
        let load = self.joint_signal(j, m.load_key, m.load);
        let (spring, damper, rest, position, rate, load) =
            (spring?, damper?, rest?, position?, rate?, load?);
        if m.revolute {
            let rest_expr = j.props.get("rest_angle").and_then(prop_expr);
            self.angle_unit(j.scope, rest_expr, Some(rest), "`rest_angle`");
            let f = position.as_ref().map(|f| f.as_constant());
            let angle_expr = j.props.get("angle").and_then(prop_expr);
            self.angle_unit(j.scope, angle_expr, f.flatten(), "the prescribed `angle`");
        }
        let driven = [position.is_some(), rate.is_some(), load.is_some()];
        if !self.driven_once(j, m, driven) || !self.starts_at_zero(j, m, position.as_ref()) {
            return None;
        }
        let drive = match (position, rate) {
            (Some(f), _) => Drive::Position { f },
            (_, Some(f)) => Drive::Rate { f },
            _ => Drive::Free,
        };
        Some(if m.revolute {
            JointKind::Revolute {
                axis: n,
                spring,
                damper,
                rest_angle: rest,
                drive,
                torque: load,
            }
        } else {
            JointKind::Prismatic {
                axis: n,
                spring,
                damper,
                drive,
                force: load,
            }
        })
    }

    /// A joint is prescribed (position or rate) or loaded, not several (E0404).
    fn driven_once(&mut self, j: &Decl, m: &Motion, driven: [bool; 3]) -> bool {
        let keys = [m.position_key, m.rate_key, m.load_key];
        let drives: Vec<&str> = keys
            .iter()
            .zip(driven)
            .filter(|x| x.1)
            .map(|x| *x.0)
            .collect();
        if drives.len() <= 1 {
            return true;
        }
        let mut d = Diagnostic::error(
            Code::E0404,
            format!(
                "joint `{}` is driven twice: {}",
                j.name,
                drives.join(" and ")
            ),
        );
        for k in &drives {
            if let Some(q) = j.props.get(k) {
                d = d.at(q.span(), "drive");
            }
        }
        let [pos_key, rate_key, load_key] = keys;
        self.error(
            j.scope,
            d.hint(format!("prescribe the motion (`{pos_key}` or `{rate_key}`) or apply a load (`{load_key}`), not several: a prescribed joint takes whatever load it needs")),
        );
        false
    }

    /// A prescribed position is measured from the start, so it is zero at t = 0 (E0404).
    fn starts_at_zero(&mut self, j: &Decl, m: &Motion, position: Option<&TimeFn>) -> bool {
        let Some(f) = position else {
            return true;
        };
        let f0 = f.eval(0.0);
        if f0.abs() <= 1e-12 {
            return true;
        }
        let pos_key = m.position_key;
        self.error(
            j.scope,
            Diagnostic::error(Code::E0404, format!("the prescribed {pos_key} of `{}` is {f0} at t = 0", j.name))
                .at(j.prop_span(pos_key), "not zero at the start")
                .hint(format!("joint {pos_key}s are measured from the initial configuration; subtract the initial value, or place the bodies at it")),
        );
        false
    }

    fn universal(&mut self, j: &Decl) -> Option<JointKind> {
        let a = self.joint_axis(j, "axis1");
        let b = self.joint_axis(j, "axis2");
        let (a, b) = (a?, b?);
        if dot(a, b).abs() > 1e-9 {
            self.error(
                j.scope,
                Diagnostic::error(Code::E0303, format!("the axes of universal joint `{}` are not perpendicular", j.name))
                    .at(j.prop_span("axis2"), format!("angle {:.3} deg between the axes", dot(a, b).clamp(-1.0, 1.0).acos().to_degrees()))
                    .hint("a universal joint's cross has perpendicular arms; parallel axes would leave it a revolute joint with a redundant constraint"),
            );
            return None;
        }
        if !self.coincide(j, None) {
            return None;
        }
        Some(JointKind::Universal {
            axis_a: a,
            axis_b: b,
        })
    }

    fn distance(&mut self, j: &Decl) -> Option<JointKind> {
        let d0 = norm(sub(j.pair[1].position, j.pair[0].position));
        let length = match self.expr(j.scope, j.props.get("length")) {
            Some(e) => {
                let l = self.scalar(j.scope, e, Dim::LENGTH, "`length`")?;
                if l <= 0.0 {
                    self.error(
                        j.scope,
                        Diagnostic::error(Code::E0303, format!("distance joint `{}` has a non-positive length", j.name))
                            .at(e.span, "must be positive")
                            .hint("a distance joint keeps two points a positive distance apart; use a spherical joint to make them coincide"),
                    );
                    return None;
                }
                l
            }
            None => {
                if d0 < 1e-12 {
                    self.error(
                        j.scope,
                        Diagnostic::error(Code::E0303, format!("distance joint `{}` starts with coincident markers", j.name))
                            .at(j.span, "zero initial distance, no `length` given")
                            .hint("give `length = ...`, or place the bodies apart: a zero-length link has no direction"),
                    );
                    return None;
                }
                d0
            }
        };
        Some(JointKind::Distance { length })
    }
}
