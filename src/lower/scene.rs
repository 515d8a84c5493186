//! The model as a 3-D view draws it ([`Scene`]): bodies sized from their inertia, beams as
//! tubes through their nodes with their section axes, markers and joint axes by kind,
//! springs, load arrows, the ground. Sizes of symbols are fractions of the model's size.

use super::{nodes, Lower};
use crate::model::{
    Attach, Body, BodyKind, Geometry, GeometryShape, JointKind, LoadKind, Marker, Model, SpringKind,
};
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
const GEOMETRY: u32 = 0x9aa3ad;

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
    for g in &model.geometry {
        geometry(&lw, &mut s, g);
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

/// A shape declared for the view: a cylinder between two markers, a box or a sphere on one.
fn geometry(lw: &Lower, s: &mut Scene, g: &Geometry) {
    let a = marker_anchor(lw, s, &g.markers[0], None);
    let (look, info) = match g.shape {
        GeometryShape::Cylinder { radius } => {
            let b = marker_anchor(lw, s, &g.markers[1], None);
            let info = format!(
                "radius {} m, from {} to {}",
                num(radius),
                g.markers[0].text,
                g.markers[1].text
            );
            (
                Look::Link {
                    to: b,
                    radius,
                    coils: 0,
                },
                info,
            )
        }
        GeometryShape::Box { size } => (
            Look::Box {
                half: size.map(|x| 0.5 * x),
                center: [0.0; 3],
            },
            format!("size {} on {}", vector(size, "m"), g.markers[0].text),
        ),
        GeometryShape::Sphere { radius } => (
            Look::Sphere {
                radius,
                center: [0.0; 3],
            },
            format!("radius {} m on {}", num(radius), g.markers[0].text),
        ),
    };
    let color = g.color.map_or(GEOMETRY, |c| {
        let b = c.map(|x| (x * 255.0).round() as u32);
        (b[0] << 16) | (b[1] << 8) | b[2]
    });
    s.shapes.push(Shape {
        name: g.name.clone(),
        kind: "shape (drawn only)".to_string(),
        info,
        anchor: a,
        look,
        color,
    });
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
    let at = Attach::Body { body: bi };
    let axes = m3(&b.orientation);
    let anchor = add_anchor(s, lw.end_at(&at, x, &axes));
    // The inertia box along the principal axes: its own anchor when they are not the body's.
    let (moments, principal) = principal(&m3(&b.inertia));
    let (box_anchor, box_center) = if principal == M3::identity() {
        (anchor, b.center)
    } else {
        let c = principal.transpose() * V3::from(b.center);
        (
            add_anchor(s, lw.end_at(&at, x, &(axes * principal))),
            c.into(),
        )
    };
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
                half: inertia_box(b.mass, moments, symbol),
                center: box_center,
            },
            "rigid body",
        ),
    };
    let shape_anchor = if matches!(look, Look::Box { .. }) {
        box_anchor
    } else {
        anchor
    };
    let color = if b.kind == BodyKind::PointMass {
        POINT_MASS
    } else {
        BODY
    };
    let d = [b.inertia[0][0], b.inertia[1][1], b.inertia[2][2]];
    let i = &b.inertia;
    let products = if i[0][1] != 0.0 || i[0][2] != 0.0 || i[1][2] != 0.0 {
        format!(
            ", products ({}, {}, {}), principal moments ({}, {}, {})",
            num(i[0][1]),
            num(i[0][2]),
            num(i[1][2]),
            num(moments[0]),
            num(moments[1]),
            num(moments[2])
        )
    } else {
        String::new()
    };
    let info = match b.kind {
        BodyKind::PointMass => format!("{} kg", num(b.mass)),
        BodyKind::Rigid => format!(
            "{} kg, inertia about the centre of mass ({}, {}, {}){products} kg*m^2",
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
        anchor: shape_anchor,
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

/// The principal moments of an inertia matrix and its principal axes as the columns of a
/// proper rotation (the identity when the matrix is diagonal, so the box keeps the body's
/// axes and order).
fn principal(i: &M3) -> ([f64; 3], M3) {
    if i[(0, 1)] == 0.0 && i[(0, 2)] == 0.0 && i[(1, 2)] == 0.0 {
        return ([i[(0, 0)], i[(1, 1)], i[(2, 2)]], M3::identity());
    }
    let e = nalgebra::SymmetricEigen::new(*i);
    let mut p = e.eigenvectors;
    if p.determinant() < 0.0 {
        p.set_column(2, &(-p.column(2)));
    }
    (e.eigenvalues.into(), p)
}

/// The half-sizes of the uniform box with the body's mass and principal moments; at least
/// `symbol / 4` each, `symbol` for a body without inertia.
fn inertia_box(mass: f64, i: [f64; 3], symbol: f64) -> [f64; 3] {
    if mass <= 0.0 || i.iter().all(|x| *x <= 0.0) {
        return [symbol; 3];
    }
    // I_x = m (b^2 + c^2) / 12 for full sizes a, b, c: a^2 = 6 (I_y + I_z - I_x) / m.
    let full = |k: usize| {
        let sq = 6.0 * (i[(k + 1) % 3] + i[(k + 2) % 3] - i[k]) / mass;
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
    for g in &model.geometry {
        pts.extend(g.markers.iter().map(|m| m.position));
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
