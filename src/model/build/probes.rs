//! The quantities each family of entity outputs: a body (its reference point, its markers and
//! points along a rigid beam), a beam point or node, a joint; a vector is split into its
//! components. Contract: turns the segments after an entity's name into probes with column
//! suffixes; must not resolve paths (`outputs.rs` does).

use super::Builder;
use crate::model::scope::env::{ScopeId, Seg};
use crate::model::*;
use crate::syntax::ast::Path;

pub(super) const AXES: [&str; 3] = ["x", "y", "z"];
const CRV: [&str; 3] = ["c1", "c2", "c3"];
const DCM: [&str; 9] = [
    "r11", "r12", "r13", "r21", "r22", "r23", "r31", "r32", "r33",
];

/// The quantities a point provides.
const POINT_Q: &[&str] = &["position", "velocity", "acceleration"];
const RIGID_Q: &[&str] = &[
    "position",
    "velocity",
    "acceleration",
    "angular_velocity",
    "angular_acceleration",
    "rotation",
    "crv",
];
/// The points of a beam.
const BEAM_POINTS: &[&str] = &["start", "end", "node[k]", "at(s)"];

type Probes = Option<Vec<(String, Probe)>>;

/// The component names of a body quantity.
fn component_names(quantity: BodyQuantity) -> &'static [&'static str] {
    match quantity {
        BodyQuantity::Rotation => &DCM,
        BodyQuantity::Crv => &CRV,
        _ => &AXES,
    }
}

/// A quantity of a turning frame (a rigid body, a beam node), beyond those of a point.
fn rotation_quantity(name: &str) -> Option<BodyQuantity> {
    match name {
        "angular_velocity" => Some(BodyQuantity::AngularVelocity),
        "angular_acceleration" => Some(BodyQuantity::AngularAcceleration),
        "rotation" => Some(BodyQuantity::Rotation),
        "crv" => Some(BodyQuantity::Crv),
        _ => None,
    }
}

/// A joint's quantities, and whether one is a scalar (a single column).
fn joint_quantities(kind: &JointKind) -> &'static [&'static str] {
    match kind {
        JointKind::Distance { .. } => &["force", "violation"],
        JointKind::Revolute { .. } => &["angle", "rate", "force", "moment", "violation"],
        JointKind::Prismatic { .. } => &["displacement", "speed", "force", "moment", "violation"],
        _ => &["force", "moment", "violation"],
    }
}

impl Builder<'_> {
    /// Splits a vector quantity into components, or selects one.
    pub(super) fn components(
        &mut self,
        scope: ScopeId,
        rest: &[Seg],
        names: &'static [&'static str],
        make: impl Fn(usize) -> Probe,
    ) -> Option<Vec<(String, Probe)>> {
        match rest {
            [] => Some(
                names
                    .iter()
                    .enumerate()
                    .map(|(i, n)| (format!(".{n}"), make(i)))
                    .collect(),
            ),
            [c] => match names.iter().position(|a| *a == c.name.name) {
                Some(i) => Some(vec![(String::new(), make(i))]),
                None => self.bad_quantity(scope, c, "this quantity", names),
            },
            [_, extra, ..] => self.bad_quantity(scope, extra, "a component", &[]),
        }
    }

    fn point_quantity(
        &mut self,
        scope: ScopeId,
        rest: &[Seg],
        span: Span,
        what: &str,
        make: impl Fn(BodyQuantity, usize) -> Probe,
    ) -> Option<Vec<(String, Probe)>> {
        let Some(q) = rest.first() else {
            return self.missing_quantity(scope, span, what, POINT_Q);
        };
        let quantity = match q.name.name.as_str() {
            "position" => BodyQuantity::Position,
            "velocity" => BodyQuantity::Velocity,
            "acceleration" => BodyQuantity::Acceleration,
            _ => return self.bad_quantity(scope, q, what, POINT_Q),
        };
        self.components(scope, &rest[1..], &AXES, |i| make(quantity, i))
    }

    pub(super) fn body_probes(
        &mut self,
        scope: ScopeId,
        path: &Path,
        b: usize,
        name: &str,
        rest: &[Seg],
    ) -> Probes {
        let body = self.bodies[b].clone();
        if let Some(probes) = self.body_point(scope, path, b, &body, name, rest) {
            return probes;
        }
        let known = if body.kind == BodyKind::Rigid {
            RIGID_Q
        } else {
            POINT_Q
        };
        let what = format!("body `{name}`");
        let Some(q) = rest.first() else {
            return self.missing_quantity(scope, path.span, &what, known);
        };
        let quantity = match (q.name.name.as_str(), body.kind) {
            ("position", _) => BodyQuantity::Position,
            ("velocity", _) => BodyQuantity::Velocity,
            ("acceleration", _) => BodyQuantity::Acceleration,
            (other, BodyKind::Rigid) if rotation_quantity(other).is_some() => {
                rotation_quantity(other)?
            }
            _ => {
                let mut all: Vec<&str> = known.to_vec();
                let markers: Vec<String> = body.markers.iter().map(|m| m.0.clone()).collect();
                all.extend(markers.iter().map(|s| s.as_str()));
                return self.bad_quantity(scope, q, &what, &all);
            }
        };
        let names = component_names(quantity);
        self.components(scope, &rest[1..], names, |component| Probe::Body {
            body: b,
            quantity,
            component,
        })
    }

    /// A point of a body other than its reference point: along a rigid beam
    /// (`blade.at(1 m).position`) or a named marker (`bar.end.position`). `None` if `rest`
    /// names neither.
    fn body_point(
        &mut self,
        scope: ScopeId,
        path: &Path,
        b: usize,
        body: &Body,
        name: &str,
        rest: &[Seg],
    ) -> Option<Probes> {
        let first = rest.first()?;
        let (offset, what) = if let Some(r) = super::markers::axis_point(body, first, name) {
            match r {
                Ok(x) => ([x, 0.0, 0.0], format!("a point of beam `{name}`")),
                Err(d) => {
                    self.error(scope, d);
                    return Some(None);
                }
            }
        } else {
            let m = body.markers.iter().find(|x| x.0 == first.name.name)?;
            (m.1, format!("marker `{name}.{}`", m.0))
        };
        Some(self.point_quantity(
            scope,
            &rest[1..],
            path.span,
            &what,
            |quantity, component| Probe::Point {
                attach: Attach::Body { body: b },
                offset,
                quantity,
                component,
            },
        ))
    }

    pub(super) fn beam_probes(
        &mut self,
        scope: ScopeId,
        path: &Path,
        bi: usize,
        name: &str,
        rest: &[Seg],
    ) -> Probes {
        let beam = self.beams[bi].clone();
        let what = format!("beam `{name}`");
        let Some(p) = rest.first() else {
            return self.missing_quantity(scope, path.span, &what, BEAM_POINTS);
        };
        let attach = match super::markers::beam_point(&beam, bi, p, name) {
            Some(Ok((attach, _))) => attach,
            Some(Err(d)) => {
                self.error(scope, d);
                return None;
            }
            None => return self.bad_quantity(scope, p, &what, BEAM_POINTS),
        };
        let point = |quantity, component| Probe::Point {
            attach,
            offset: [0.0; 3],
            quantity,
            component,
        };
        // A node rotates: its rotation, crv and angular velocity are outputs too.
        if let (Attach::BeamNode { .. }, Some(q)) = (attach, rest.get(1)) {
            if let Some(quantity) = rotation_quantity(&q.name.name) {
                let names = component_names(quantity);
                return self.components(scope, &rest[2..], names, |c| point(quantity, c));
            }
        }
        let what = format!("a point of beam `{name}`");
        self.point_quantity(scope, &rest[1..], path.span, &what, point)
    }

    pub(super) fn joint_probes(
        &mut self,
        scope: ScopeId,
        path: &Path,
        j: usize,
        name: &str,
        rest: &[Seg],
    ) -> Probes {
        let kind = self.joints[j].kind.clone();
        let what = format!("{} joint `{name}`", kind.name());
        let known = joint_quantities(&kind);
        let Some(q) = rest.first() else {
            return self.missing_quantity(scope, path.span, &what, known);
        };
        if !known.contains(&q.name.name.as_str()) {
            return self.bad_quantity(scope, q, &what, known);
        }
        let quantity = match q.name.name.as_str() {
            "angle" | "displacement" => JointQuantity::Angle,
            "rate" | "speed" => JointQuantity::Rate,
            "force" => JointQuantity::Force,
            "moment" => JointQuantity::Moment,
            _ => JointQuantity::Violation,
        };
        let scalar = matches!(
            quantity,
            JointQuantity::Angle | JointQuantity::Rate | JointQuantity::Violation
        ) || matches!(kind, JointKind::Distance { .. });
        let probe = |component| Probe::Joint {
            joint: j,
            quantity,
            component,
            axes: None,
        };
        if scalar {
            if let Some(extra) = rest.get(1) {
                return self.bad_quantity(scope, extra, "a scalar joint quantity", &[]);
            }
            return Some(vec![(String::new(), probe(None))]);
        }
        self.components(scope, &rest[1..], &AXES, |c| probe(Some(c)))
    }
}
