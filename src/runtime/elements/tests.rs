//! Every element's analytic tangent against central differences of its residual, at random
//! states, with random integrator coefficients (THEORY §3.6: the finite-difference oracle).
//!
//! A perturbation `eps` of unknown `j` moves the state the way a Newton correction does
//! through the integrator's relations: positions by `eps * position` (rotations by
//! `R <- exp(eps * position * e_j~) R`), velocities by `eps * velocity`, accelerations by
//! `eps * mass`; multipliers by `eps`. The residual is the integrator's:
//! `F^I + force_weight * F` at coordinates and `s * C` at multipliers.

use super::*;
use crate::runtime::forces::LoadKind;
use crate::runtime::joints::{End, Row};
use crate::runtime::rotation::{exp, V3};
use crate::runtime::timefn::{Binary, TimeFn, Unary};
use crate::runtime::BeamElement;
use crate::runtime::{NodeRotation, SpringKind};

/// A small deterministic generator.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }

    fn v3(&mut self) -> [f64; 3] {
        [self.next(), self.next(), self.next()]
    }

    fn rotation(&mut self, size: f64) -> [[f64; 3]; 3] {
        crate::runtime::arr3(&exp(&(V3::from(self.v3()) * size)))
    }
}

/// Layout of the test system: node A (unknowns 0..6, rotating node 0), node B (6..12,
/// node 1), a joint angle (12), multipliers from 13.
const N: usize = 40;
const ROT_A: [usize; 3] = [3, 4, 5];
const ROT_B: [usize; 3] = [9, 10, 11];

fn random_state(rng: &mut Lcg) -> State {
    let mut st = State::zeros(N, 2);
    // Rows 1 and 4 of the joint in slot 0 dropped as redundant (W0303).
    st.dropped = vec![0b10010];
    st.t = 0.3 + rng.next().abs();
    for i in 0..N {
        st.q[i] = rng.next();
        st.v[i] = rng.next();
        st.a[i] = rng.next();
        st.lambda[i] = rng.next();
    }
    for k in 0..2 {
        st.rot[k] = NodeRotation {
            r: rng.rotation(2.0),
            w: rng.v3(),
            dw: rng.v3(),
        };
    }
    st
}

fn node_end(rng: &mut Lcg, which: usize) -> End {
    let s = 6 * which;
    End::Node {
        dofs: [s, s + 1, s + 2, s + 3, s + 4, s + 5],
        node: which,
        offset: rng.v3(),
        axes: rng.rotation(3.0),
    }
}

/// Every fourth case: end B between the nodes of a two-node beam element over nodes A and B
/// (their triads at t = 0 close to each other, as the state's rotations are made too), end A
/// on the ground.
fn ends(rng: &mut Lcg, case: usize) -> (End, End) {
    let b = if case % 4 == 3 {
        let common = crate::runtime::m3(&rng.rotation(3.0));
        let triads = (0..2)
            .map(|_| crate::runtime::arr3(&(crate::runtime::m3(&rng.rotation(0.2)) * common)))
            .collect();
        End::Between(Box::new(super::super::joints::Between {
            dofs: (0..12).collect(),
            nodes: vec![0, 1],
            triads,
            n: [0.35, 0.65, 0.0, 0.0],
            offset: rng.v3(),
            axes: rng.rotation(3.0),
        }))
    } else {
        node_end(rng, 1)
    };
    let a = match case % 4 {
        0 => node_end(rng, 0),
        1 => End::Point {
            dofs: [0, 1, 2],
            axes: rng.rotation(3.0),
        },
        _ => End::Ground {
            point: rng.v3(),
            axes: rng.rotation(3.0),
        },
    };
    (a, b)
}

/// `sin(2 t) + t^2`: a drive with non-trivial derivatives.
fn drive() -> TimeFn {
    TimeFn::binary(
        Binary::Add,
        TimeFn::Unary {
            op: Unary::Sin,
            arg: Box::new(TimeFn::binary(
                Binary::Mul,
                TimeFn::constant(2.0),
                TimeFn::Time,
            )),
        },
        TimeFn::binary(Binary::Mul, TimeFn::Time, TimeFn::Time),
    )
}

fn all_rows() -> Vec<Row> {
    vec![
        Row::Point { k: 0 },
        Row::Point { k: 1 },
        Row::Point { k: 2 },
        Row::Dot { i: 1, j: 2 },
        Row::Dot { i: 2, j: 0 },
        Row::Dot { i: 0, j: 1 },
        Row::Along { i: 0, offset: 0.1 },
        Row::Along { i: 2, offset: -0.2 },
        Row::Angle,
        Row::Distance { length: 0.7 },
        Row::AngleDrive { f: drive() },
        Row::AngleRate { f: drive() },
        Row::SlideDrive {
            offset: 0.3,
            f: drive(),
        },
        Row::SlideRate { f: drive() },
        Row::Phi,
    ]
}

/// The test elements for one random case.
fn elements(rng: &mut Lcg, case: usize) -> Vec<Element> {
    let (a, b) = ends(rng, case);
    let mut out = vec![
        Element::RigidBody(RigidBody {
            dofs: [6, 7, 8, 9, 10, 11],
            node: 1,
            mass: 1.0 + rng.next().abs(),
            // Every fifth case: the node at the centre of mass (the tangent's terms of the
            // first moment of mass are then not formed).
            eta0: {
                let eta = rng.v3();
                if case % 5 == 4 {
                    [0.0; 3]
                } else {
                    eta
                }
            },
            inertia0: {
                let r = crate::runtime::m3(&rng.rotation(3.0));
                let d = crate::runtime::rotation::M3::from_diagonal(&V3::new(
                    1.0 + rng.next().abs(),
                    1.0 + rng.next().abs(),
                    1.5 + rng.next().abs(),
                ));
                crate::runtime::arr3(&(r * d * r.transpose()))
            },
            gravity: rng.v3(),
        }),
        Element::Joint(Joint {
            a: a.clone(),
            b: b.clone(),
            angle: Some(12),
            first: 13,
            rows: all_rows(),
            slide_offset: Some(0.3),
            slot: None,
        }),
        // The same with rows 1 and 4 dropped as redundant (W0303): held at lambda = 0.
        Element::Joint(Joint {
            a: a.clone(),
            b: b.clone(),
            angle: Some(12),
            first: 13,
            rows: all_rows(),
            slide_offset: Some(0.3),
            slot: Some(0),
        }),
        Element::Spring(Spring {
            kind: SpringKind::Torsional,
            a: a.clone(),
            b: b.clone(),
            angle: None,
            row: Row::Phi,
            stiffness: 2.0,
            damping: 0.5,
            rest: 0.0,
            load: None,
        }),
    ];
    for row in [
        Row::Distance { length: 0.4 },
        Row::Along { i: 2, offset: 0.1 },
        Row::Point { k: 1 },
        Row::Phi,
    ] {
        out.push(Element::Spring(Spring {
            kind: SpringKind::Row,
            a: a.clone(),
            b: b.clone(),
            angle: Some(12),
            row,
            stiffness: 3.0,
            damping: 0.7,
            rest: 0.2,
            load: Some(drive()),
        }));
    }
    for (kind, follower) in [
        (LoadKind::Force, false),
        (LoadKind::Force, true),
        (LoadKind::Torque, false),
        (LoadKind::Torque, true),
    ] {
        out.push(Element::Load(Load {
            kind,
            end: b.clone(),
            value: [drive(), TimeFn::constant(0.5), TimeFn::Time],
            follower,
        }));
    }
    out
}

fn perturb(st: &State, j: usize, eps: f64, c: TangentCoeffs) -> State {
    let mut s = st.clone();
    if j >= 13 {
        s.lambda[j] += eps;
        return s;
    }
    for (node, rot) in [(0usize, ROT_A), (1, ROT_B)] {
        if let Some(axis) = rot.iter().position(|&r| r == j) {
            let mut e = V3::zeros();
            e[axis] = eps * c.position;
            let r = exp(&e) * s.rot[node].matrix();
            s.rot[node].set_matrix(&r);
            s.rot[node].w[axis] += eps * c.velocity;
            s.rot[node].dw[axis] += eps * c.mass;
            return s;
        }
    }
    s.q[j] += eps * c.position;
    s.v[j] += eps * c.velocity;
    s.a[j] += eps * c.mass;
    s
}

/// Random integrator coefficients and penalty.
fn coefficients(rng: &mut Lcg) -> (TangentCoeffs, Augment) {
    let c = TangentCoeffs {
        mass: 1.0 + 5.0 * rng.next().abs(),
        velocity: 0.5 + 2.0 * rng.next().abs(),
        // Newton's unknowns are the positions: the constraint rows are `s B` for a unit
        // position weight (TangentCoeffs).
        position: 1.0,
        force_weight: 0.8 + 0.2 * rng.next().abs(),
    };
    let aug = Augment {
        s: 1.0 + 3.0 * rng.next().abs(),
        p: 1.0 + 3.0 * rng.next().abs(),
        rate_scale: 1.0 / c.velocity,
    };
    (c, aug)
}

#[test]
fn tangents_match_central_differences() {
    let mut rng = Lcg(7);
    let rate_rows: Vec<bool> = all_rows().iter().map(Row::is_rate).collect();
    for case in 0..60 {
        let (c, aug) = coefficients(&mut rng);
        let mut st = random_state(&mut rng);
        if case % 4 == 3 {
            // The element's two nodes turned alike, up to 0.3 rad.
            let r = crate::runtime::m3(&rng.rotation(0.3)) * st.rot[0].matrix();
            st.rot[1].set_matrix(&r);
        }
        for (ei, el) in elements(&mut rng, case).iter().enumerate() {
            let idx = el.indices();
            let nl = idx.len();
            let mut k = vec![0.0; nl * nl];
            el.tangent(&st, aug, c, &mut k);
            let full = |s: &State| {
                let mut r = Residual::new(N);
                el.residual(s, aug, &mut r);
                (0..N)
                    .map(|i| {
                        if i >= 13 {
                            aug.s * r.constraint[i]
                        } else {
                            r.inertia[i] + c.force_weight * r.force[i]
                        }
                    })
                    .collect::<Vec<f64>>()
            };
            let h = 1e-6;
            for (lj, &j) in idx.iter().enumerate() {
                let (rp, rm) = (full(&perturb(&st, j, h, c)), full(&perturb(&st, j, -h, c)));
                for (li, &i) in idx.iter().enumerate() {
                    let fd = (rp[i] - rm[i]) / (2.0 * h);
                    let an = k[li * nl + lj];
                    // Central differences at h = 1e-6: error ~1e-10 relative; 1e-6 leaves room
                    // for round-off in the residual (entries are O(10)).
                    assert!(
                        (fd - an).abs() < 1e-6 * (1.0 + fd.abs()),
                        "case {case}, element {ei} ({:?}), row {i}{}, column {j}: analytic {an}, finite differences {fd}",
                        std::mem::discriminant(el),
                        if i >= 13 && rate_rows.get(i - 13).copied().unwrap_or(false) { " (rate row)" } else { "" },
                    );
                }
            }
        }
    }
}

/// `Element::residual_and_tangent` writes exactly what `residual` and `tangent` write apart,
/// and `Element::rate_jacobians` what `tangent` writes with a unit mass or velocity
/// coefficient alone: every element, dropped and rate rows, ends between beam nodes.
#[test]
fn one_pass_residual_and_tangent_and_rate_jacobians_equal_the_parts() {
    let mut rng = Lcg(11);
    for case in 0..16 {
        let (c, aug) = coefficients(&mut rng);
        let st = random_state(&mut rng);
        for el in elements(&mut rng, case) {
            let nl2 = el.indices().len().pow(2);
            let (mut r1, mut r2) = (Residual::new(N), Residual::new(N));
            let (mut k1, mut k2) = (vec![0.0; nl2], vec![f64::NAN; nl2]);
            el.residual(&st, aug, &mut r1);
            el.tangent(&st, aug, c, &mut k1);
            el.residual_and_tangent(&st, aug, c, &mut r2, &mut k2);
            assert_eq!(
                (&r1.inertia, &r1.force, &r1.constraint),
                (&r2.inertia, &r2.force, &r2.constraint)
            );
            assert_eq!(k1, k2, "case {case}: {:?}", std::mem::discriminant(&el));
            let unit = |mass: f64, velocity: f64| TangentCoeffs {
                mass,
                velocity,
                position: 0.0,
                force_weight: c.force_weight,
            };
            let (mut m1, mut c1) = (vec![0.0; nl2], vec![0.0; nl2]);
            el.tangent(&st, aug, unit(1.0, 0.0), &mut m1);
            el.tangent(&st, aug, unit(0.0, 1.0), &mut c1);
            let (mut m2, mut c2) = (vec![f64::NAN; nl2], vec![f64::NAN; nl2]);
            el.rate_jacobians(&st, aug, c.force_weight, &mut m2, &mut c2);
            assert_eq!(
                (m1, c1),
                (m2, c2),
                "case {case}: {:?}",
                std::mem::discriminant(&el)
            );
        }
    }
}

/// A beam element of `nn` nodes at random deformed, moving states: nodes at unknowns
/// `6k..6k+6`, rotating node `k`; reference line curved and twisted, with a full coupled
/// section, mass offsets and gravity.
fn beam_case(rng: &mut Lcg, nn: usize) -> (BeamElement, State) {
    let mut positions = Vec::new();
    let mut triads = Vec::new();
    for k in 0..nn {
        let s = k as f64 / (nn - 1) as f64;
        // An arc with a twist: the reference strains are not zero.
        positions.push([s, 0.3 * s * s, 0.1 * s]);
        let base = exp(&V3::new(0.4 * s, 0.0, 0.6 * s));
        triads.push(crate::runtime::arr3(&base));
    }
    let mut stiffness = [[0.0; 6]; 6];
    for i in 0..6 {
        for j in 0..6 {
            stiffness[i][j] = 0.3 * rng.next();
        }
    }
    // Symmetric, positive definite: A A^T + diagonal.
    let a = stiffness;
    for i in 0..6 {
        for j in 0..6 {
            stiffness[i][j] = (0..6).map(|k| a[i][k] * a[j][k]).sum::<f64>()
                + if i == j { 2.0 + i as f64 } else { 0.0 };
        }
    }
    let rho = {
        let r = crate::runtime::m3(&rng.rotation(1.0));
        let d = crate::runtime::rotation::M3::from_diagonal(&V3::new(0.5, 0.2, 0.3));
        crate::runtime::arr3(&(r * d * r.transpose()))
    };
    let dofs: Vec<usize> = (0..6 * nn).collect();
    // A section varying along the element (a tapered beam), so that the tangent is checked
    // with different properties at every quadrature point.
    let eta = [0.0, 0.1 * rng.next(), 0.1 * rng.next()];
    let section = |xi: f64| crate::runtime::beams::SectionAt {
        stiffness: stiffness.map(|row| row.map(|k| k * (1.0 + 0.3 * xi))),
        mass: 1.3 * (1.0 - 0.2 * xi),
        eta: eta.map(|e| e * (1.0 + 0.5 * xi)),
        rho: rho.map(|row| row.map(|r| r * (1.0 + 0.4 * xi))),
    };
    let mut beam = BeamElement::new(
        dofs,
        (0..nn).collect(),
        &positions,
        triads,
        &section,
        rng.v3(),
    );
    // Distributed loads: fixed and follower forces and torques, different at every point.
    let points = beam.inertial.len();
    for (kind, follower) in [
        (LoadKind::Force, false),
        (LoadKind::Force, true),
        (LoadKind::Torque, true),
        (LoadKind::Torque, false),
    ] {
        let values = (0..points)
            .map(|_| rng.v3().map(TimeFn::constant))
            .collect();
        beam.loads.push(crate::runtime::beams::Distributed {
            kind,
            follower,
            values,
        });
    }
    let mut st = State::zeros(6 * nn, nn);
    for k in 0..nn {
        for i in 0..3 {
            st.q[6 * k + i] = positions[k][i] + 0.1 * rng.next();
            st.v[6 * k + i] = rng.next();
            st.a[6 * k + i] = rng.next();
        }
        // A large common rotation plus moderate relative ones.
        let common = exp(&V3::new(1.0, 2.0, -0.5));
        st.rot[k] = NodeRotation {
            r: crate::runtime::arr3(&(crate::runtime::m3(&rng.rotation(0.3)) * common)),
            w: rng.v3(),
            dw: rng.v3(),
        };
    }
    (beam, st)
}

#[test]
fn beam_tangents_match_central_differences() {
    let mut rng = Lcg(11);
    for case in 0..30 {
        let nn = 2 + case % 3;
        let (beam, st) = beam_case(&mut rng, nn);
        let c = TangentCoeffs {
            mass: 1.0 + 5.0 * rng.next().abs(),
            velocity: 0.5 + 2.0 * rng.next().abs(),
            position: 1.0,
            force_weight: 0.8 + 0.2 * rng.next().abs(),
        };
        let n = 6 * nn;
        let el = Element::Beam(beam);
        let mut k = vec![0.0; n * n];
        let aug = Augment {
            s: 1.0,
            p: 1.0,
            rate_scale: 1.0,
        };
        el.tangent(&st, aug, c, &mut k);
        let full = |s: &State| {
            let mut r = Residual::new(n);
            el.residual(s, aug, &mut r);
            (0..n)
                .map(|i| r.inertia[i] + c.force_weight * r.force[i])
                .collect::<Vec<f64>>()
        };
        let perturb = |j: usize, eps: f64| {
            let mut s = st.clone();
            let (node, i) = (j / 6, j % 6);
            if i >= 3 {
                let mut e = V3::zeros();
                e[i - 3] = eps * c.position;
                let r = exp(&e) * s.rot[node].matrix();
                s.rot[node].set_matrix(&r);
                s.rot[node].w[i - 3] += eps * c.velocity;
                s.rot[node].dw[i - 3] += eps * c.mass;
            } else {
                s.q[j] += eps * c.position;
                s.v[j] += eps * c.velocity;
                s.a[j] += eps * c.mass;
            }
            s
        };
        let h = 1e-6;
        let mut worst: f64 = 0.0;
        for j in 0..n {
            let (rp, rm) = (full(&perturb(j, h)), full(&perturb(j, -h)));
            for i in 0..n {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                let an = k[i * n + j];
                worst = worst.max((fd - an).abs() / (1.0 + fd.abs()));
                assert!(
                    (fd - an).abs() < 1e-6 * (1.0 + fd.abs()),
                    "case {case} ({nn} nodes), row {i}, column {j}: analytic {an}, finite differences {fd}"
                );
            }
        }
        assert!(worst < 1e-6);
    }
}

/// The centre-of-mass probe weighs each element as its inertia does: at random states the
/// first moment of mass times gravity is the gravity potential, its velocity moment is the
/// translational momentum, and its acceleration moment the translational inertial force.
#[test]
fn mass_moments_agree_with_momentum_inertia_and_gravity() {
    let mut rng = Lcg(23);
    let mut cases: Vec<(Element, State)> = Vec::new();
    for case in 0..6 {
        let st = random_state(&mut rng);
        let body = elements(&mut rng, case).swap_remove(0);
        cases.push((body, st.clone()));
        cases.push((
            Element::PointMass(PointMass {
                dofs: [0, 1, 2],
                mass: 1.0 + rng.next().abs(),
                gravity: rng.v3(),
            }),
            st,
        ));
        let (beam, st) = beam_case(&mut rng, 2 + case % 3);
        cases.push((Element::Beam(beam), st));
    }
    for (i, (el, st)) in cases.iter().enumerate() {
        let m = el.mass_moments(st).expect("an element with mass");
        let n = st.q.len();
        let translations: Vec<usize> = el
            .indices()
            .chunks(if matches!(el, Element::PointMass(_)) {
                3
            } else {
                6
            })
            .flat_map(|c| c[..3].to_vec())
            .collect();
        let sum = |v: &[f64]| -> V3 {
            let mut s = V3::zeros();
            for (k, &d) in translations.iter().enumerate() {
                s[k % 3] += v[d];
            }
            s
        };
        let (mut p, mut g) = (vec![0.0; n], vec![0.0; n]);
        el.momentum(st, &mut p, &mut g);
        let mut r = Residual::new(n);
        let aug = Augment {
            s: 1.0,
            p: 1.0,
            rate_scale: 1.0,
        };
        el.residual(st, aug, &mut r);
        let gravity = V3::new(0.3, -1.1, 0.7);
        let potential = |g: V3| {
            let mut e = el.clone();
            match &mut e {
                Element::PointMass(x) => x.gravity = g.into(),
                Element::RigidBody(x) => x.gravity = g.into(),
                Element::Beam(x) => x.gravity = g.into(),
                _ => unreachable!(),
            }
            e.energy(st).potential
        };
        let close = |a: V3, b: V3| (a - b).norm() < 1e-12 * (1.0 + b.norm());
        assert!(close(m.velocity, sum(&p)), "case {i}: velocity moment");
        assert!(close(m.acceleration, sum(&r.inertia)), "case {i}: inertia");
        let work = potential(V3::zeros()) - potential(gravity);
        assert!(
            (work - gravity.dot(&m.position)).abs() < 1e-12 * (1.0 + work.abs()),
            "case {i}: position moment"
        );
        assert!(m.mass > 0.0);
    }
}
