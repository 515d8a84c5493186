//! Lowering: Model -> runtime System + provenance.
//!
//! Contract: assigns global indices from the model's DOF map, turns bodies and joints into
//! elements, outputs into probes, and records for every runtime entity the span it came from.
//! Raises no user errors: the model stage has caught them.

use crate::diagnostics::{Code, Diagnostic};
use crate::model::dofs::Unknown;
use crate::model::{
    Attach, BodyKind, BodyQuantity, JointKind, JointQuantity, Model, Probe as ModelProbe,
};
use crate::runtime::{Anchor, Channel, Element, Entity, Probe, State, System, UnknownKind};
use crate::source::Span;

/// Where each runtime entity was declared (index = entity index of the System).
#[derive(Clone, Debug, Default)]
pub struct Provenance {
    pub spans: Vec<Span>,
}

/// What this version's runtime cannot simulate yet, if anything (E0501, with a span).
fn unsupported(model: &Model) -> Option<Diagnostic> {
    let not_yet = |what: String, span: Span| {
        Some(
            Diagnostic::error(Code::E0501, format!("{what} cannot be simulated by this version of the runtime"))
                .at(span, "declared here")
                .hint("the model is valid (`mbd check` accepts it); this version simulates point masses, distance joints and gravity only"),
        )
    };
    if let Some(b) = model.bodies.iter().find(|b| b.kind == BodyKind::Rigid) {
        return not_yet(format!("rigid body `{}`", b.name), b.span);
    }
    if let Some(b) = model.beams.first() {
        return not_yet(format!("beam `{}`", b.name), b.span);
    }
    if let Some(j) = model
        .joints
        .iter()
        .find(|j| !matches!(j.kind, JointKind::Distance { .. }))
    {
        return not_yet(format!("{} joint `{}`", j.kind.name(), j.name), j.span);
    }
    if let Some(s) = model.springs.first() {
        return not_yet(format!("spring `{}`", s.name), s.span);
    }
    if let Some(l) = model.loads.first() {
        return not_yet(format!("load `{}`", l.name), l.span);
    }
    if let Some(o) = model.outputs.iter().find(|o| {
        !matches!(
            o.probe,
            ModelProbe::Body {
                quantity: BodyQuantity::Position
                    | BodyQuantity::Velocity
                    | BodyQuantity::Acceleration,
                ..
            } | ModelProbe::Joint { .. }
        )
    }) {
        return not_yet(format!("output `{}`", o.column), o.span);
    }
    None
}

pub fn lower(model: &Model) -> Result<(System, Provenance), Diagnostic> {
    if let Some(d) = unsupported(model) {
        return Err(d);
    }
    let dofs = &model.dofs;
    let n = dofs.len();
    let nb = model.bodies.len();
    let mut entities = Vec::new();
    let mut spans = Vec::new();
    for b in &model.bodies {
        entities.push(Entity {
            name: b.name.clone(),
            kind: "point_mass".to_string(),
        });
        spans.push(b.span);
    }
    for j in &model.joints {
        entities.push(Entity {
            name: j.name.clone(),
            kind: "distance joint".to_string(),
        });
        spans.push(j.span);
    }
    let mut unknowns = Vec::with_capacity(n);
    let mut owners = Vec::with_capacity(n);
    for u in &dofs.unknowns {
        match *u {
            Unknown::Translation { body, .. } => {
                unknowns.push(UnknownKind::Coordinate);
                owners.push(body);
            }
            Unknown::Multiplier { joint, .. } => {
                unknowns.push(UnknownKind::Multiplier);
                owners.push(nb + joint);
            }
            _ => {
                return Err(Diagnostic::error(
                    Code::E0501,
                    "internal: unknown kind not lowered",
                ))
            }
        }
    }
    let body_dofs = |b: usize| {
        let s = dofs.body_start[b];
        [s, s + 1, s + 2]
    };
    let mut elements = Vec::new();
    let mut initial = State::zeros(n);
    for (bi, b) in model.bodies.iter().enumerate() {
        let d = body_dofs(bi);
        elements.push(Element::PointMass {
            dofs: d,
            mass: b.mass,
            gravity: model.gravity,
        });
        for k in 0..3 {
            initial.q[d[k]] = b.position[k];
            initial.v[d[k]] = b.velocity[k];
        }
    }
    // Joint j is element nb + j.
    let mut length_scale: f64 = 0.0;
    for (ji, j) in model.joints.iter().enumerate() {
        let anchor = |m: &crate::model::Marker| match m.attach {
            Attach::Body { body } => Anchor::Node {
                dofs: body_dofs(body),
            },
            _ => Anchor::Fixed { point: m.offset },
        };
        if let JointKind::Distance { length } = j.kind {
            {
                length_scale = length_scale.max(length);
                elements.push(Element::Distance {
                    a: anchor(&j.markers[0]),
                    b: anchor(&j.markers[1]),
                    length,
                    multiplier: dofs.joint_start[ji],
                });
            }
        }
    }
    for b in &model.bodies {
        length_scale = length_scale.max(b.position.iter().fold(0.0, |m: f64, x| m.max(x.abs())));
    }
    let channels = model
        .outputs
        .iter()
        .map(|o| {
            let probe = match o.probe {
                ModelProbe::Body {
                    body,
                    quantity,
                    component,
                } => {
                    let index = body_dofs(body)[component];
                    match quantity {
                        BodyQuantity::Velocity => Probe::Velocity { index },
                        BodyQuantity::Acceleration => Probe::Acceleration { index },
                        _ => Probe::Position { index },
                    }
                }
                ModelProbe::Joint {
                    joint, quantity, ..
                } => match quantity {
                    JointQuantity::Force => Probe::ConstraintForce {
                        element: nb + joint,
                        row: 0,
                    },
                    _ => Probe::ConstraintViolation {
                        element: nb + joint,
                        row: 0,
                    },
                },
                _ => Probe::Position { index: 0 },
            };
            Channel {
                column: o.column.clone(),
                probe,
            }
        })
        .collect();
    let system = System {
        unknowns,
        owners,
        entities,
        elements,
        initial,
        channels,
        length_scale: if length_scale > 0.0 {
            length_scale
        } else {
            1.0
        },
    };
    Ok((system, Provenance { spans }))
}
