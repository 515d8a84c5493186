//! The model as a 3-D view draws it ([`Scene`]): bodies sized from their inertia, beams as
//! tubes through their nodes with their section axes, markers and joint axes by kind,
//! springs, load arrows, the ground. Sizes of symbols are fractions of the model's size.

use super::{nodes, Lower};
use crate::model::{Attach, Body, BodyKind, JointKind, LoadKind, Marker, Model, SpringKind};
use crate::runtime::rotation::{M3, V3};
use crate::runtime::scene::{Anchor, LoadVector, Look, Scene, Shape};
use crate::runtime::{m3, End};

const BODY: u32 = 0x4f7fbf;
const POINT_MASS: u32 = 0x3f6fa0;
const BEAM: u32 = 0xd08a2c;
const JOINT: u32 = 0xc0392b;
const SPRING: u32 = 0x27ae60;
const LOAD: u32 = 0x8e44ad;
const GROUND: u32 = 0x7f8c8d;

/// The model's scene at its initial configuration.
pub fn scene(model: &Model) -> Scene {
    let n = nodes(model);
    let lw = Lower {
        model,
        node_of: n.node_of,
        beam_nodes: n.beam_nodes,
    };
    let size = model_size(model);
    let mut s = Scene {
        anchors: Vec::new(),
        shapes: Vec::new(),
        loads: Vec::new(),
        size,
        up: up(model),
    };
    let symbol = 0.04 * size;
    let ground = add_anchor(&mut s, End::ground());
    s.shapes.push(Shape {
        name: "ground".to_string(),
        kind: "ground".to_string(),
        info: format!(
            "the inertial frame; gravity {}",
            vector(model.gravity, "m/s^2")
        ),
        anchor: ground,
        look: Look::Grid {
            size: 2.0 * size,
            normal: s.up,
        },
        color: GROUND,
    });
    s.shapes.push(Shape {
        name: "origin".to_string(),
        kind: "inertial axes".to_string(),
        info: "x red, y green, z blue".to_string(),
        anchor: ground,
        look: Look::Triad { size: 2.0 * symbol },
        color: GROUND,
    });
    for (bi, b) in model.bodies.iter().enumerate() {
        body(&lw, &mut s, bi, b, symbol);
    }
    for (bi, b) in model.beams.iter().enumerate() {
        beam(&lw, &mut s, bi, b, symbol);
    }
    for j in &model.joints {
        joint(&lw, &mut s, j, symbol);
    }
    for sp in &model.springs {
        let a = marker_anchor(&lw, &mut s, &sp.markers[0], None);
        let b = marker_anchor(&lw, &mut s, &sp.markers[1], None);
        let (kind, unit) = match sp.kind {
            SpringKind::Linear => ("spring", "N/m"),
            SpringKind::Torsional => ("torsional spring", "N*m/rad"),
        };
        s.shapes.push(Shape {
            name: sp.name.clone(),
            kind: kind.to_string(),
            info: format!(
                "stiffness {} {unit}, damping {}",
                num(sp.stiffness),
                num(sp.damping)
            ),
            anchor: a,
            look: Look::Link {
                to: b,
                radius: 0.3 * symbol,
                coils: 8,
            },
            color: SPRING,
        });
    }
    for l in &model.loads {
        let a = marker_anchor(&lw, &mut s, &l.marker, None);
        let (kind, unit) = match l.kind {
            LoadKind::Force => ("force", "N"),
            LoadKind::Torque => ("torque", "N*m"),
        };
        s.loads.push(LoadVector {
            value: l.value.clone(),
            follower: l.follower,
            torque: l.kind == LoadKind::Torque,
        });
        s.shapes.push(Shape {
            name: l.name.clone(),
            kind: kind.to_string(),
            info: format!(
                "in {}, {unit}{}",
                l.marker.text,
                if l.follower { ", follower" } else { "" }
            ),
            anchor: a,
            look: Look::Arrow {
                load: s.loads.len() - 1,
                scale: 0.3 * size,
            },
            color: LOAD,
        });
    }
    s
}

/// A beam: a tube through its nodes, each node's section axes.
fn beam(lw: &Lower, s: &mut Scene, bi: usize, b: &crate::model::Beam, symbol: f64) {
    let ids: Vec<usize> = (0..b.initial_nodes.len())
        .map(|k| {
            let m = Attach::BeamNode { beam: bi, node: k };
            let x = V3::from(b.initial_nodes[k]);
            add_anchor(s, lw.end_at(&m, x, &m3(&b.frames[k])))
        })
        .collect();
    let radius = (0.15 * symbol).max(0.01 * b.length);
    for (k, w) in ids.windows(2).enumerate() {
        s.shapes.push(Shape {
            name: b.name.clone(),
            kind: "beam".to_string(),
            info: format!(
                "{} elements of {} nodes, {} m, {} kg/m; segment {} of {}",
                b.elements,
                b.order,
                num(b.length),
                num(b.section.mass_per_length),
                k + 1,
                ids.len() - 1
            ),
            anchor: w[0],
            look: Look::Link {
                to: w[1],
                radius,
                coils: 0,
            },
            color: BEAM,
        });
    }
    for (k, &a) in ids.iter().enumerate() {
        s.shapes.push(Shape {
            name: format!("{}.node[{}]", b.name, k + 1),
            kind: "beam node".to_string(),
            info: "section axes: 1 red (along the beam), 2 green, 3 blue".to_string(),
            anchor: a,
            look: Look::Triad { size: symbol },
            color: BEAM,
        });
    }
}

fn add_anchor(s: &mut Scene, end: End) -> usize {
    s.anchors.push(Anchor { end });
    s.anchors.len() - 1
}

/// A marker's anchor, with its own axes or, given `axis`, axes whose first is `axis`.
fn marker_anchor(lw: &Lower, s: &mut Scene, m: &Marker, axis: Option<[f64; 3]>) -> usize {
    let axes = match axis {
        Some(a) => frame_along(V3::from(a)),
        None => m3(&m.world_axes),
    };
    add_anchor(s, lw.end(m, &axes))
}

fn body(lw: &Lower, s: &mut Scene, bi: usize, b: &Body, symbol: f64) {
    let x = V3::from(b.position);
    let anchor = add_anchor(
        s,
        lw.end_at(&Attach::Body { body: bi }, x, &m3(&b.orientation)),
    );
    let (look, kind) = match (b.kind, b.beam_axis) {
        (BodyKind::PointMass, _) => (
            Look::Sphere {
                radius: symbol,
                center: [0.0; 3],
            },
            "point mass",
        ),
        (BodyKind::Rigid, Some((length, _))) => (
            Look::Cylinder {
                radius: (0.15 * symbol).max(0.01 * length),
                length,
                center: [0.5 * length, 0.0, 0.0],
            },
            "rigid beam",
        ),
        (BodyKind::Rigid, None) => (
            Look::Box {
                half: inertia_box(b, symbol),
                center: b.center,
            },
            "rigid body",
        ),
    };
    let color = if b.kind == BodyKind::PointMass {
        POINT_MASS
    } else {
        BODY
    };
    let d = [b.inertia[0][0], b.inertia[1][1], b.inertia[2][2]];
    let info = match b.kind {
        BodyKind::PointMass => format!("{} kg", num(b.mass)),
        BodyKind::Rigid => format!(
            "{} kg, inertia about the centre of mass ({}, {}, {}) kg*m^2",
            num(b.mass),
            num(d[0]),
            num(d[1]),
            num(d[2])
        ),
    };
    s.shapes.push(Shape {
        name: b.name.clone(),
        kind: kind.to_string(),
        info,
        anchor,
        look,
        color,
    });
    if b.kind == BodyKind::Rigid {
        s.shapes.push(Shape {
            name: format!("{} axes", b.name),
            kind: "body axes".to_string(),
            info: "x red, y green, z blue".to_string(),
            anchor,
            look: Look::Triad { size: symbol },
            color,
        });
    }
}

/// The half-sizes of the uniform box with the body's mass and principal moments (the
/// diagonal of its inertia in its own axes); at least `symbol / 4` each, `symbol` for a body
/// without inertia.
fn inertia_box(b: &Body, symbol: f64) -> [f64; 3] {
    let i = [b.inertia[0][0], b.inertia[1][1], b.inertia[2][2]];
    if b.mass <= 0.0 || i.iter().all(|x| *x <= 0.0) {
        return [symbol; 3];
    }
    // I_x = m (b^2 + c^2) / 12 for full sizes a, b, c: a^2 = 6 (I_y + I_z - I_x) / m.
    let full = |k: usize| {
        let sq = 6.0 * (i[(k + 1) % 3] + i[(k + 2) % 3] - i[k]) / b.mass;
        sq.max(0.0).sqrt()
    };
    [0, 1, 2].map(|k| (0.5 * full(k)).max(0.25 * symbol))
}

fn joint(lw: &Lower, s: &mut Scene, j: &crate::model::Joint, symbol: f64) {
    let (axis, look, info) = match &j.kind {
        JointKind::Revolute { axis, .. } | JointKind::Cylindrical { axis } => (
            Some(*axis),
            Look::Cylinder {
                radius: 0.5 * symbol,
                length: 3.0 * symbol,
                center: [0.0; 3],
            },
            format!("axis {}", vector(*axis, "")),
        ),
        JointKind::Prismatic { axis, .. } => (
            Some(*axis),
            Look::Box {
                half: [2.0 * symbol, 0.4 * symbol, 0.4 * symbol],
                center: [0.0; 3],
            },
            format!("axis {}", vector(*axis, "")),
        ),
        JointKind::Universal { axis_a, axis_b } => (
            Some(*axis_a),
            Look::Cylinder {
                radius: 0.4 * symbol,
                length: 2.5 * symbol,
                center: [0.0; 3],
            },
            format!("axes {} and {}", vector(*axis_a, ""), vector(*axis_b, "")),
        ),
        JointKind::Spherical => (
            None,
            Look::Sphere {
                radius: 0.7 * symbol,
                center: [0.0; 3],
            },
            "free rotation about the point".to_string(),
        ),
        JointKind::Fixed => (
            None,
            Look::Box {
                half: [0.6 * symbol; 3],
                center: [0.0; 3],
            },
            "no relative motion".to_string(),
        ),
        JointKind::Distance { length } => {
            let a = marker_anchor(lw, s, &j.markers[0], None);
            let b = marker_anchor(lw, s, &j.markers[1], None);
            s.shapes.push(Shape {
                name: j.name.clone(),
                kind: "distance joint".to_string(),
                info: format!("length {} m", num(*length)),
                anchor: a,
                look: Look::Link {
                    to: b,
                    radius: 0.12 * symbol,
                    coils: 0,
                },
                color: JOINT,
            });
            return;
        }
    };
    let a = marker_anchor(lw, s, &j.markers[0], axis);
    s.shapes.push(Shape {
        name: j.name.clone(),
        kind: format!("{} joint", j.kind.name()),
        info: format!(
            "{info}; between {} and {}",
            j.markers[0].text, j.markers[1].text
        ),
        anchor: a,
        look,
        color: JOINT,
    });
}

/// Axes whose first is along `a`.
fn frame_along(a: V3) -> M3 {
    let x = a.try_normalize(1e-12).unwrap_or(V3::x());
    let helper = if x.x.abs() < 0.9 { V3::x() } else { V3::y() };
    let y = x.cross(&helper).normalize();
    let z = x.cross(&y);
    M3::from_columns(&[x, y, z])
}

/// The model's size: the diagonal of the box around its bodies, nodes and markers (1 m when
/// it has none or one point).
fn model_size(model: &Model) -> f64 {
    let mut pts: Vec<[f64; 3]> = model.bodies.iter().map(|b| b.position).collect();
    for b in &model.beams {
        pts.extend(b.initial_nodes.iter().copied());
    }
    for j in &model.joints {
        pts.extend(j.markers.iter().map(|m| m.position));
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &pts {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let d = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}

/// Up: against gravity, or z without it.
fn up(model: &Model) -> [f64; 3] {
    let g = V3::from(model.gravity);
    match (-g).try_normalize(1e-12) {
        Some(u) => u.into(),
        None => [0.0, 0.0, 1.0],
    }
}

fn num(x: f64) -> String {
    let v: f64 = format!("{x:.5e}").parse().unwrap_or(x);
    format!("{}", v + 0.0)
}

fn vector(v: [f64; 3], unit: &str) -> String {
    let u = if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    };
    format!("({}, {}, {}){u}", num(v[0]), num(v[1]), num(v[2]))
}
