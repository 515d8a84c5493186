//! Lowering of joints, springs and loads to constraint rows and force elements.
//!
//! Every joint gets one triad at t = 0, shared by both ends (so the ends' axes coincide at
//! the start): the third axis is the joint axis (revolute, prismatic, cylindrical); a
//! universal joint's first two axes are its two axes; other joints use the first marker's
//! axes.

use super::Lower;
use crate::model::{
    Drive, Joint as ModelJoint, JointKind, Load as ModelLoad, LoadKind as ModelLoadKind,
    Spring as ModelSpring, SpringKind as ModelSpringKind,
};
use crate::runtime::rotation::{M3, V3};
use crate::runtime::timefn::TimeFn;
use crate::runtime::{m3, End, Joint, Load, LoadKind, Row, Spring, SpringKind};

/// A lowered joint and the force elements acting along its free motion.
pub struct Lowered {
    pub joint: Joint,
    pub forces: Vec<Spring>,
}

/// A right-handed triad whose third axis is `n`.
fn triad_about(n: [f64; 3]) -> M3 {
    let n = V3::from(n).normalize();
    let t = if n[0].abs() < 0.9 { V3::x() } else { V3::y() };
    let a = n.cross(&t).normalize();
    M3::from_columns(&[a, n.cross(&a), n])
}

const POINT: [Row; 3] = [
    Row::Point { k: 0 },
    Row::Point { k: 1 },
    Row::Point { k: 2 },
];

/// Rows that keep the axes' relative orientation: all three, or only those locking rotations
/// about the first two axes (`a_2 . b_0`, `a_2 . b_1`).
fn orientation_rows(all: bool) -> Vec<Row> {
    if all {
        vec![
            Row::Dot { i: 1, j: 2 },
            Row::Dot { i: 2, j: 0 },
            Row::Dot { i: 0, j: 1 },
        ]
    } else {
        vec![Row::Dot { i: 2, j: 0 }, Row::Dot { i: 2, j: 1 }]
    }
}

fn no_ends() -> (End, End) {
    let g = End::Ground {
        point: [0.0; 3],
        axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };
    (g.clone(), g)
}

pub fn joint(lw: &Lower, ji: usize, j: &ModelJoint) -> Lowered {
    let dofs = &lw.model.dofs;
    let triad = match &j.kind {
        JointKind::Revolute { axis, .. }
        | JointKind::Prismatic { axis, .. }
        | JointKind::Cylindrical { axis } => triad_about(*axis),
        JointKind::Universal { axis_a, axis_b } => {
            let (a, b) = (V3::from(*axis_a).normalize(), V3::from(*axis_b).normalize());
            M3::from_columns(&[a, b, a.cross(&b)])
        }
        _ => m3(&j.markers[0].world_axes),
    };
    let a = lw.end(&j.markers[0], &triad);
    let b = lw.end(&j.markers[1], &triad);
    let (xa, xb) = (
        V3::from(j.markers[0].position),
        V3::from(j.markers[1].position),
    );
    let slide0 = triad.column(2).dot(&(xb - xa));
    let mut forces = Vec::new();
    let mut slide_offset = None;
    let rows: Vec<Row> = match &j.kind {
        JointKind::Spherical => POINT.to_vec(),
        JointKind::Fixed => [POINT.to_vec(), orientation_rows(true)].concat(),
        JointKind::Universal { .. } => [POINT.to_vec(), vec![Row::Dot { i: 0, j: 1 }]].concat(),
        JointKind::Cylindrical { .. } => [
            orientation_rows(false),
            vec![
                Row::Along { i: 0, offset: 0.0 },
                Row::Along { i: 1, offset: 0.0 },
            ],
        ]
        .concat(),
        JointKind::Distance { length } => vec![Row::Distance { length: *length }],
        JointKind::Revolute {
            spring,
            damper,
            rest_angle,
            drive,
            torque,
            ..
        } => {
            let mut rows = [POINT.to_vec(), orientation_rows(false), vec![Row::Angle]].concat();
            match drive {
                Drive::Free => {}
                Drive::Position { f } => rows.push(Row::AngleDrive { f: f.clone() }),
                Drive::Rate { f } => rows.push(Row::AngleRate { f: f.clone() }),
            }
            if *spring != 0.0 || *damper != 0.0 || torque.is_some() {
                let (ga, gb) = no_ends();
                forces.push(Spring {
                    kind: SpringKind::Row,
                    a: ga,
                    b: gb,
                    angle: dofs.joint_extra[ji],
                    row: Row::Phi,
                    stiffness: *spring,
                    damping: *damper,
                    rest: *rest_angle,
                    load: torque.clone(),
                });
            }
            rows
        }
        JointKind::Prismatic {
            spring,
            damper,
            drive,
            force,
            ..
        } => {
            slide_offset = Some(slide0);
            let mut rows = [
                orientation_rows(true),
                vec![
                    Row::Along { i: 0, offset: 0.0 },
                    Row::Along { i: 1, offset: 0.0 },
                ],
            ]
            .concat();
            match drive {
                Drive::Free => {}
                Drive::Position { f } => rows.push(Row::SlideDrive {
                    offset: slide0,
                    f: f.clone(),
                }),
                Drive::Rate { f } => rows.push(Row::SlideRate { f: f.clone() }),
            }
            if *spring != 0.0 || *damper != 0.0 || force.is_some() {
                forces.push(Spring {
                    kind: SpringKind::Row,
                    a: a.clone(),
                    b: b.clone(),
                    angle: None,
                    row: Row::Along {
                        i: 2,
                        offset: slide0,
                    },
                    stiffness: *spring,
                    damping: *damper,
                    rest: 0.0,
                    load: force.clone(),
                });
            }
            rows
        }
    };
    Lowered {
        joint: Joint {
            a,
            b,
            angle: dofs.joint_extra[ji],
            first: dofs.joint_start[ji],
            rows,
            slide_offset,
            slot: None,
        },
        forces,
    }
}

/// A spring or damper: along the line between its markers, or (zero free length) on the
/// vector between them, or on the relative rotation of their axes.
pub fn spring(lw: &Lower, s: &ModelSpring) -> Vec<Spring> {
    let ea = m3(&s.markers[0].world_axes);
    let eb = m3(&s.markers[1].world_axes);
    let a = lw.end(&s.markers[0], &ea);
    let b = lw.end(&s.markers[1], &eb);
    let make = |kind, row| Spring {
        kind,
        a: a.clone(),
        b: b.clone(),
        angle: None,
        row,
        stiffness: s.stiffness,
        damping: s.damping,
        rest: 0.0,
        load: None,
    };
    match s.kind {
        ModelSpringKind::Torsional => vec![make(SpringKind::Torsional, Row::Phi)],
        ModelSpringKind::Linear if s.length > 0.0 => {
            vec![make(SpringKind::Row, Row::Distance { length: s.length })]
        }
        ModelSpringKind::Linear => POINT
            .iter()
            .map(|r| make(SpringKind::Row, r.clone()))
            .collect(),
    }
}

pub fn load(lw: &Lower, l: &ModelLoad) -> Load {
    let axes = m3(&l.marker.world_axes);
    Load {
        kind: match l.kind {
            ModelLoadKind::Force => LoadKind::Force,
            ModelLoadKind::Torque => LoadKind::Torque,
        },
        end: lw.end(&l.marker, &axes),
        value: l.value.clone() as [TimeFn; 3],
        follower: l.follower,
    }
}
