//! Lowering of elastic beams: elements between consecutive node groups, concentrated masses,
//! and the nodes' initial state.

use super::Lower;
use crate::model::{Beam, Section};
use crate::runtime::beams::{inertial_points, triad_between, Distributed, Gauss, SectionAt};
use crate::runtime::rotation::{M3, V3};
use crate::runtime::LoadKind;
use crate::runtime::{
    arr3, m3, BeamElement, Element, NodeRotation, Probe, ProbeQuantity, RigidBody, State,
};
use crate::runtime::{Between, End};

/// A section's properties for the element, in the section frame: its stiffness, `m`, `eta*`
/// and the inertia per length about the reference line (the section gives it about its centre
/// of mass).
fn properties(s: &Section) -> SectionAt {
    let m = s.mass_per_length;
    let eta = V3::new(0.0, s.mass_offset[0], s.mass_offset[1]);
    let rc = m3(&s.inertia);
    let rho = rc + (M3::identity() * eta.norm_squared() - eta * eta.transpose()) * m;
    SectionAt {
        stiffness: s.stiffness,
        mass: m,
        eta: eta.into(),
        rho: arr3(&rho),
    }
}

/// The section at arc length `s` of beam `b`: its own, or between its stations the linear
/// interpolation of theirs (stiffness, mass per length, offsets and inertias), held beyond
/// the first and the last.
pub fn section_at(b: &Beam, s: f64) -> SectionAt {
    let stations = &b.sections;
    let Some(i) = stations.windows(2).position(|w| s < w[1].0) else {
        return properties(stations.last().map_or(&b.section, |(_, x)| x));
    };
    let ((s0, a), (s1, c)) = (&stations[i], &stations[i + 1]);
    if s <= *s0 {
        return properties(a);
    }
    let f = (s - s0) / (s1 - s0);
    let mix = |x: f64, y: f64| x + f * (y - x);
    let section = Section {
        name: a.name.clone(),
        stiffness: std::array::from_fn(|r| {
            std::array::from_fn(|k| mix(a.stiffness[r][k], c.stiffness[r][k]))
        }),
        mass_per_length: mix(a.mass_per_length, c.mass_per_length),
        mass_offset: std::array::from_fn(|k| mix(a.mass_offset[k], c.mass_offset[k])),
        inertia: std::array::from_fn(|r| {
            std::array::from_fn(|k| mix(a.inertia[r][k], c.inertia[r][k]))
        }),
    };
    properties(&section)
}

pub fn beam(lw: &Lower, bi: usize, b: &Beam, elements: &mut Vec<Element>, initial: &mut State) {
    let model = lw.model;
    let starts = &model.dofs.node_start[bi];
    let ids = &lw.beam_nodes[bi];
    for (k, &s) in starts.iter().enumerate() {
        for i in 0..3 {
            initial.q[s + i] = b.initial_nodes[k][i];
            initial.v[s + i] = b.velocities[k][i];
        }
        initial.rot[ids[k]] = NodeRotation {
            w: b.angular_velocities[k],
            ..NodeRotation::REST
        };
    }
    let p = b.order;
    let le = b.length / b.elements as f64;
    let mut lumped = Vec::new();
    for e in 0..b.elements {
        let local: Vec<usize> = (e * (p - 1)..=e * (p - 1) + p - 1).collect();
        let dofs = local
            .iter()
            .flat_map(|&k| starts[k]..starts[k] + 6)
            .collect();
        let positions: Vec<[f64; 3]> = local.iter().map(|&k| b.nodes[k]).collect();
        let span = |xi: f64| le * (e as f64 + (xi + 1.0) / 2.0);
        let mut element = BeamElement::new(
            dofs,
            local.iter().map(|&k| ids[k]).collect(),
            &positions,
            local.iter().map(|&k| b.frames[k]).collect(),
            &|xi: f64| section_at(b, span(xi)),
            model.gravity,
        );
        // Distributed loads: their values at the inertial points, `span` replaced there.
        for d in model.distributed.iter().filter(|d| d.beam == bi) {
            let values = inertial_points(p)
                .iter()
                .map(|&xi| d.value.each_ref().map(|f| f.at_arc(span(xi))))
                .collect();
            element.loads.push(Distributed {
                kind: match d.kind {
                    crate::model::LoadKind::Force => LoadKind::Force,
                    crate::model::LoadKind::Torque => LoadKind::Torque,
                },
                follower: d.follower,
                values,
            });
        }
        // Concentrated masses between the nodes: the mass a point of weight 1 after the
        // inertial ones (its consistent mass `m N_k N_l`), its rotary inertia lumped on the
        // element's nodes in proportion to `|N_k|` (a consistent rotary inertia of one point
        // is rank 3 over all the nodes' rotations, which the start cannot tell from a node's).
        for &(s, mass, inertia) in &b.masses_between {
            let (at, xi) = locate(b, s);
            if at != e {
                continue;
            }
            let (n, _) = crate::runtime::beams::shape(p, xi);
            element.inertial.push(Gauss {
                wj: 1.0,
                n,
                dn: [0.0; 4],
                strain0: [0.0; 6],
                section: SectionAt {
                    stiffness: [[0.0; 6]; 6],
                    mass,
                    eta: [0.0; 3],
                    rho: [[0.0; 3]; 3],
                },
            });
            if inertia.iter().flatten().all(|&x| x == 0.0) {
                continue;
            }
            let total: f64 = n.iter().take(p).map(|x| x.abs()).sum();
            for (j, &k) in local.iter().enumerate() {
                let st = starts[k];
                let w = n[j].abs() / total;
                lumped.push(Element::RigidBody(RigidBody {
                    dofs: [st, st + 1, st + 2, st + 3, st + 4, st + 5],
                    node: ids[k],
                    mass: 0.0,
                    eta0: [0.0; 3],
                    inertia0: inertia.map(|row| row.map(|x| x * w)),
                    gravity: model.gravity,
                }));
            }
        }
        elements.push(Element::Beam(element));
    }
    elements.append(&mut lumped);
    // Concentrated masses: rigid bodies on the node, centred there.
    for &(node, mass, inertia) in &b.point_masses {
        let s = starts[node];
        elements.push(Element::RigidBody(RigidBody {
            dofs: [s, s + 1, s + 2, s + 3, s + 4, s + 5],
            node: ids[node],
            mass,
            eta0: [0.0; 3],
            inertia0: arr3(&m3(&inertia)),
            gravity: model.gravity,
        }));
    }
}

/// An output at arc length `s` between the nodes of beam `bi`: the element's shape functions
/// at that point weight its nodes' translations.
pub fn between_nodes(
    lw: &Lower,
    bi: usize,
    s: f64,
    quantity: ProbeQuantity,
    component: usize,
) -> Probe {
    let b = &lw.model.beams[bi];
    let (e, xi) = locate(b, s);
    let p = b.order;
    let (n, _) = crate::runtime::beams::shape(p, xi);
    let mut dofs = Vec::new();
    let mut weights = Vec::new();
    for (k, w) in n.iter().enumerate().take(p) {
        let st = lw.model.dofs.node_start[bi][e * (p - 1) + k];
        dofs.push([st, st + 1, st + 2]);
        weights.push(*w);
    }
    Probe::Interpolated {
        dofs,
        weights,
        quantity,
        component,
    }
}

/// The element of beam `b` holding arc length `s`, and the point's coordinate on [-1, 1].
pub fn locate(b: &Beam, s: f64) -> (usize, f64) {
    let le = b.length / b.elements as f64;
    let e = ((s / le).floor().max(0.0) as usize).min(b.elements - 1);
    (e, 2.0 * (s - e as f64 * le) / le - 1.0)
}

/// A marker at arc length `s` between the nodes of beam `bi`, at `position` with `axes`
/// (inertial, t = 0): its offset and axes are kept in the element's interpolated triad there.
pub fn end_between(lw: &Lower, bi: usize, s: f64, position: V3, axes: &M3) -> End {
    let b = &lw.model.beams[bi];
    let (e, xi) = locate(b, s);
    let p = b.order;
    let (n, _) = crate::runtime::beams::shape(p, xi);
    let local: Vec<usize> = (e * (p - 1)..e * (p - 1) + p).collect();
    let starts = &lw.model.dofs.node_start[bi];
    let frames: Vec<M3> = local.iter().map(|&k| m3(&b.frames[k])).collect();
    let (t0, _) = triad_between(&frames, &n);
    let mut x0 = V3::zeros();
    for (j, &k) in local.iter().enumerate() {
        x0 += V3::from(b.initial_nodes[k]) * n[j];
    }
    End::Between(Box::new(Between {
        dofs: local
            .iter()
            .flat_map(|&k| starts[k]..starts[k] + 6)
            .collect(),
        nodes: local.iter().map(|&k| lw.beam_nodes[bi][k]).collect(),
        triads: local.iter().map(|&k| b.frames[k]).collect(),
        n,
        offset: (t0.transpose() * (position - x0)).into(),
        axes: arr3(&(t0.transpose() * axes)),
    }))
}
