//! Lowering: Model -> runtime System + provenance.
//!
//! Contract: assigns global indices from the model's DOF map, turns bodies, joints, springs
//! and loads into elements and outputs into probes, and records for every runtime entity the
//! span it came from. Raises no user errors: the model stage has caught them.

mod beams;
mod joints;
mod redundant;
mod scene;

pub use scene::scene;

use crate::model::dofs::Unknown;
use crate::model::{
    Attach, Body, BodyKind, BodyQuantity, EnergyKind as ModelEnergy, JointQuantity, Marker, Model,
    Probe as ModelProbe,
};
use crate::runtime::rotation::{M3, V3};
use crate::runtime::{
    arr3, m3, Channel, Element, End, EnergyKind, Entity, NodeRotation, PointMass, Probe,
    ProbeQuantity, RigidBody, State, System, UnknownKind,
};
use crate::source::Span;

/// Where each runtime entity was declared (index = entity index of the System).
#[derive(Clone, Debug, Default)]
pub struct Provenance {
    pub spans: Vec<Span>,
}

/// The lowering context: the model and the index maps.
pub(crate) struct Lower<'m> {
    pub model: &'m Model,
    /// Rotating node of each body (rigid bodies only).
    pub node_of: Vec<Option<usize>>,
    /// Rotating node of each beam node.
    pub beam_nodes: Vec<Vec<usize>>,
}

impl Lower<'_> {
    /// The unknowns of a body: 3 (point mass) or 6 (rigid: translation then rotation).
    pub fn body_dofs(&self, b: usize) -> Vec<usize> {
        let s = self.model.dofs.body_start[b];
        let n = if self.node_of[b].is_some() { 6 } else { 3 };
        (s..s + n).collect()
    }

    /// A marker as a runtime end, with its axes `axes` (inertial, at t = 0).
    pub fn end(&self, m: &Marker, axes: &M3) -> End {
        self.end_at(&m.attach, V3::from(m.position), axes)
    }

    /// The end of a point fixed on an attachment, at `position` (inertial, at t = 0).
    pub fn end_at(&self, attach: &Attach, position: V3, axes: &M3) -> End {
        let axes = arr3(axes);
        match *attach {
            Attach::Body { body } => {
                let b = &self.model.bodies[body];
                let d = self.body_dofs(body);
                match self.node_of[body] {
                    Some(node) => End::Node {
                        dofs: [d[0], d[1], d[2], d[3], d[4], d[5]],
                        node,
                        offset: (position - V3::from(b.position)).into(),
                        axes,
                    },
                    None => End::Point {
                        dofs: [d[0], d[1], d[2]],
                        axes,
                    },
                }
            }
            Attach::BeamNode { beam, node } => {
                let s = self.model.dofs.node_start[beam][node];
                let x0 = V3::from(self.model.beams[beam].initial_nodes[node]);
                End::Node {
                    dofs: [s, s + 1, s + 2, s + 3, s + 4, s + 5],
                    node: self.beam_nodes[beam][node],
                    offset: (position - x0).into(),
                    axes,
                }
            }
            Attach::BeamPoint { beam, s } => {
                beams::end_between(self, beam, s, position, &m3(&axes))
            }
            Attach::Ground { .. } => End::Ground {
                point: position.into(),
                axes,
            },
        }
    }
}

/// The rotating nodes: each rigid body's, then each beam node's, with the unknowns of their
/// rotation and translation.
struct Nodes {
    node_of: Vec<Option<usize>>,
    beam_nodes: Vec<Vec<usize>>,
    rotations: Vec<usize>,
    translations: Vec<usize>,
    /// How many are rigid bodies' (the first ones).
    rigid: usize,
}

fn nodes(model: &Model) -> Nodes {
    let dofs = &model.dofs;
    let mut node_of = Vec::new();
    let mut rotations = Vec::new();
    let mut translations = Vec::new();
    for (bi, b) in model.bodies.iter().enumerate() {
        if b.kind == BodyKind::Rigid {
            node_of.push(Some(rotations.len()));
            rotations.push(dofs.body_start[bi] + 3);
            translations.push(dofs.body_start[bi]);
        } else {
            node_of.push(None);
        }
    }
    let rigid = rotations.len();
    let mut beam_nodes = Vec::new();
    for (bi, b) in model.beams.iter().enumerate() {
        let mut ids = Vec::new();
        for k in 0..b.nodes.len() {
            ids.push(rotations.len());
            rotations.push(dofs.node_start[bi][k] + 3);
            translations.push(dofs.node_start[bi][k]);
        }
        beam_nodes.push(ids);
    }
    Nodes {
        node_of,
        beam_nodes,
        rotations,
        translations,
        rigid,
    }
}

/// The runtime entities (bodies, beams, joints, springs, loads, in that order) and where
/// each was declared.
fn entities(model: &Model) -> (Vec<Entity>, Vec<Span>) {
    let mut entities = Vec::new();
    let mut spans = Vec::new();
    let mut add = |name: &str, kind: String, span: Span| {
        entities.push(Entity {
            name: name.to_string(),
            kind,
        });
        spans.push(span);
    };
    for b in &model.bodies {
        let kind = match b.kind {
            BodyKind::PointMass => "point mass",
            BodyKind::Rigid => "rigid body",
        };
        add(&b.name, kind.to_string(), b.span);
    }
    for b in &model.beams {
        add(&b.name, "beam".to_string(), b.span);
    }
    for j in &model.joints {
        add(&j.name, format!("{} joint", j.kind.name()), j.span);
    }
    for s in &model.springs {
        add(&s.name, "spring".to_string(), s.span);
    }
    for l in &model.loads {
        add(&l.name, "load".to_string(), l.span);
    }
    (entities, spans)
}

pub fn lower(model: &Model) -> (System, Provenance) {
    let n = model.dofs.len();
    let nodes = nodes(model);
    let rotations_len = nodes.rotations.len();
    let lw = Lower {
        model,
        node_of: nodes.node_of,
        beam_nodes: nodes.beam_nodes,
    };
    let (entities, spans) = entities(model);
    let mut elements = Vec::new();
    let mut initial = State::zeros(n, rotations_len);
    lw.bodies(&mut elements, &mut initial);
    // Bodies are elements 0..nb; each beam lowers to a run of elements (with its masses).
    let mut beam_elements = Vec::new();
    for (bi, b) in model.beams.iter().enumerate() {
        let first = elements.len();
        beams::beam(&lw, bi, b, &mut elements, &mut initial);
        beam_elements.push(first..elements.len());
    }
    // Joints: element index of each, and whether each multiplier is a rate row.
    let mut joint_element = Vec::new();
    let mut rate_rows = vec![false; n];
    for (ji, j) in model.joints.iter().enumerate() {
        let lowered = joints::joint(&lw, ji, j);
        for (r, row) in lowered.joint.rows.iter().enumerate() {
            rate_rows[lowered.joint.first + r] = row.is_rate();
        }
        joint_element.push(elements.len());
        elements.push(Element::Joint(lowered.joint));
        elements.extend(lowered.forces.into_iter().map(Element::Spring));
    }
    for s in &model.springs {
        elements.extend(joints::spring(&lw, s).into_iter().map(Element::Spring));
    }
    for l in &model.loads {
        elements.push(Element::Load(joints::load(&lw, l)));
    }
    let (unknowns, owners) = lw.unknowns(&rate_rows);
    let surplus: Vec<usize> = model.redundant.iter().map(|&j| joint_element[j]).collect();
    if !surplus.is_empty() {
        redundant::drop_surplus(
            &mut elements,
            &surplus,
            &unknowns,
            &mut initial,
            length_scale(model),
            model.surplus,
        );
    }
    let channels = model
        .outputs
        .iter()
        .map(|o| Channel {
            column: o.column.clone(),
            probe: probe(&lw, &o.probe, &joint_element, &beam_elements),
        })
        .collect();
    let system = System {
        unknowns,
        owners,
        rotations: nodes.rotations,
        coupled: (0..rotations_len).map(|k| k < nodes.rigid).collect(),
        translations: nodes.translations,
        entities,
        elements,
        initial,
        channels,
        length_scale: length_scale(model),
        redundant: surplus,
    };
    (system, Provenance { spans })
}

impl Lower<'_> {
    /// Each body's element and its initial state.
    fn bodies(&self, elements: &mut Vec<Element>, initial: &mut State) {
        let model = self.model;
        for (bi, b) in model.bodies.iter().enumerate() {
            let d = self.body_dofs(bi);
            for k in 0..3 {
                initial.q[d[k]] = b.position[k];
                initial.v[d[k]] = b.velocity[k];
            }
            match self.node_of[bi] {
                Some(node) => {
                    elements.push(Element::RigidBody(rigid(b, &d, node, model.gravity)));
                    initial.rot[node] = NodeRotation {
                        w: b.angular_velocity,
                        ..NodeRotation::REST
                    };
                }
                None => elements.push(Element::PointMass(PointMass {
                    dofs: [d[0], d[1], d[2]],
                    mass: b.mass,
                    gravity: model.gravity,
                })),
            }
        }
    }

    /// The kind of each unknown and the entity it belongs to (`rate_rows`: which
    /// multipliers are of rate rows).
    fn unknowns(&self, rate_rows: &[bool]) -> (Vec<UnknownKind>, Vec<usize>) {
        let model = self.model;
        let n = model.dofs.len();
        let nb = model.bodies.len();
        let njoint0 = nb + model.beams.len();
        let mut unknowns = Vec::with_capacity(n);
        let mut owners = Vec::with_capacity(n);
        for (i, u) in model.dofs.unknowns.iter().enumerate() {
            let (kind, owner) = match *u {
                Unknown::Translation { body, .. } => (UnknownKind::Coordinate, body),
                Unknown::Rotation { body, axis } => match self.node_of[body] {
                    Some(node) => (UnknownKind::Rotation { node, axis }, body),
                    None => (UnknownKind::Coordinate, body),
                },
                Unknown::JointAngle { joint } => (UnknownKind::Coordinate, njoint0 + joint),
                Unknown::Multiplier { joint, .. } => (
                    if rate_rows[i] {
                        UnknownKind::RateMultiplier
                    } else {
                        UnknownKind::Multiplier
                    },
                    njoint0 + joint,
                ),
                Unknown::NodeTranslation { beam, .. } => (UnknownKind::Coordinate, nb + beam),
                Unknown::NodeRotation { beam, node, axis } => (
                    UnknownKind::Rotation {
                        node: self.beam_nodes[beam][node],
                        axis,
                    },
                    nb + beam,
                ),
            };
            unknowns.push(kind);
            owners.push(owner);
        }
        (unknowns, owners)
    }
}

/// The rigid body element: centre of mass and inertia about the reference point, in
/// inertial components at t = 0 (THEORY §4).
fn rigid(b: &Body, d: &[usize], node: usize, gravity: [f64; 3]) -> RigidBody {
    let o = m3(&b.orientation);
    let eta = o * V3::from(b.center);
    let jc = o * m3(&b.inertia) * o.transpose();
    let jref = jc + (M3::identity() * eta.norm_squared() - eta * eta.transpose()) * b.mass;
    RigidBody {
        dofs: [d[0], d[1], d[2], d[3], d[4], d[5]],
        node,
        mass: b.mass,
        eta0: eta.into(),
        inertia0: arr3(&jref),
        gravity,
    }
}

fn probe(
    lw: &Lower,
    p: &ModelProbe,
    joint_element: &[usize],
    beam_elements: &[std::ops::Range<usize>],
) -> Probe {
    let quantity = |q: BodyQuantity| match q {
        BodyQuantity::Position => ProbeQuantity::Position,
        BodyQuantity::Velocity => ProbeQuantity::Velocity,
        BodyQuantity::Acceleration => ProbeQuantity::Acceleration,
        BodyQuantity::AngularVelocity => ProbeQuantity::AngularVelocity,
        BodyQuantity::AngularAcceleration => ProbeQuantity::AngularAcceleration,
        BodyQuantity::Rotation => ProbeQuantity::Rotation,
        BodyQuantity::Crv => ProbeQuantity::Crv,
    };
    match *p {
        ModelProbe::Multiblade {
            ref blades,
            azimuth,
            coordinate,
        } => Probe::Multiblade {
            blades: blades.iter().map(|&j| joint_element[j]).collect(),
            azimuth: joint_element[azimuth],
            coordinate,
        },
        ModelProbe::CenterOfMass {
            ref bodies,
            ref beams,
            quantity: q,
            component,
        } => Probe::CenterOfMass {
            // Bodies were lowered first, one element each: body `b` is element `b`.
            elements: bodies
                .iter()
                .copied()
                .chain(beams.iter().flat_map(|&b| beam_elements[b].clone()))
                .collect(),
            quantity: quantity(q),
            component,
        },
        ModelProbe::Body {
            body,
            quantity: q,
            component,
        } => {
            let b = &lw.model.bodies[body];
            Probe::Point {
                end: lw.end_at(
                    &Attach::Body { body },
                    V3::from(b.position),
                    &m3(&b.orientation),
                ),
                quantity: quantity(q),
                component,
            }
        }
        ModelProbe::Point {
            attach: Attach::BeamPoint { beam, s },
            quantity: q,
            component,
            ..
        } => beams::between_nodes(lw, beam, s, quantity(q), component),
        ModelProbe::Point {
            attach,
            offset,
            quantity: q,
            component,
        } => {
            let (position, axes) = match attach {
                Attach::Body { body } => {
                    let b = &lw.model.bodies[body];
                    let o = m3(&b.orientation);
                    (V3::from(b.position) + o * V3::from(offset), o)
                }
                Attach::BeamNode { beam, node } => {
                    let b = &lw.model.beams[beam];
                    let o = m3(&b.frames[node]);
                    (V3::from(b.initial_nodes[node]) + o * V3::from(offset), o)
                }
                _ => (V3::from(offset), M3::identity()),
            };
            Probe::Point {
                end: lw.end_at(&attach, position, &axes),
                quantity: quantity(q),
                component,
            }
        }
        ModelProbe::Joint {
            joint,
            quantity: q,
            component,
            ref axes,
        } => {
            let element = joint_element[joint];
            let axes = axes.as_ref().map(|m| lw.end(m, &m3(&m.world_axes)));
            match q {
                JointQuantity::Force => Probe::JointForce {
                    element,
                    component,
                    axes,
                },
                JointQuantity::Moment => Probe::JointMoment {
                    element,
                    component: component.unwrap_or(0),
                    axes,
                },
                JointQuantity::Angle => Probe::JointAngle { element },
                JointQuantity::Rate => Probe::JointRate { element },
                JointQuantity::Violation => Probe::Violation { element },
            }
        }
        ModelProbe::Energy { kind } => Probe::Energy {
            kind: match kind {
                ModelEnergy::Kinetic => EnergyKind::Kinetic,
                ModelEnergy::Potential => EnergyKind::Potential,
                ModelEnergy::Total => EnergyKind::Total,
            },
        },
    }
}

/// A length typical of the model: the largest distance of a body or marker from the origin
/// or of a joint's markers from each other, at least 1 mm.
fn length_scale(model: &Model) -> f64 {
    let norm = |x: [f64; 3]| V3::from(x).norm();
    let mut l: f64 = 1e-3;
    for b in &model.bodies {
        l = l.max(norm(b.position));
        for (_, offset, _) in &b.markers {
            l = l.max(norm(*offset));
        }
    }
    for j in &model.joints {
        for m in &j.markers {
            l = l.max(norm(m.position));
        }
    }
    l
}
