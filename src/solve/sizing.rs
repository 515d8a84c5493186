//! The numbers of the sizing lint: for each elastic part (a beam's nodes), its lowest elastic
//! frequency in its assembly and its quasi-static deformation under the scene's loads.
//!
//! The model is linearized at rest at its initial configuration (velocities zero, gravity and
//! the multipliers it needs consistent), reduced to the null space of the constraint gradient
//! (`x = N y`), and the motions without mass are condensed statically, which leaves the
//! symmetric eigenproblem `K* a = w^2 a` of the mass-normalized coordinates. A part's
//! frequency is the lowest `w` among the modes in which its elements store at least
//! [`SHARE`] of the mode's strain energy: how far its stiffness moves a mode (Rayleigh:
//! `dw^2 / w^2 = share * dk / k`). Symmetric parts (a rotor's blades) share their modes, so
//! no part owns a mode alone.
//!
//! Its deformation is the static response in those same modes, `q_i = x_i^T g / w_i^2`, to
//! the load of each sampled time, less the part's best rigid motion: the largest remaining
//! displacement of a node, or rotation times the part's length. In a dynamic run the load is
//! `g = M a(t)`, the consistent accelerations of the initial configuration started at time `t`
//! (its velocities projected onto the drives' rates then): they carry every mode's forcing
//! (gravity, the loads, the drives, the motion's centripetal accelerations; `q_i'' = x_i^T M a`
//! while the structure is undeformed); in statics it is the loads `f(t)` themselves.
//!
//! Contract: reads the system, never changes it; dense, so limited to [`MAX_FREE`] free
//! motions. Knows no concrete element.

use super::integrator::{Integrator, Linearization};
use super::linear::null_space;
use super::RuntimeFailure;
use crate::runtime::rotation::V3;
use crate::runtime::{Augment, Frame, Residual, State, System, TangentCoeffs, UnknownKind};
use crate::settings::Settings;
use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// A mode belongs to a part when the part stores this share of its strain energy.
pub const SHARE: f64 = 0.1;

/// Models with more free motions (unknowns less constraints) are not sized.
pub const MAX_FREE: usize = 1500;
/// Nor models with more unknowns other than multipliers (the dense matrices' size).
pub const MAX_UNKNOWNS: usize = 2000;

/// One part to size: the first unknown of each of its nodes (a translation triplet, then a
/// rotation triplet), and its length.
#[derive(Clone, Debug)]
pub struct Part {
    pub nodes: Vec<usize>,
    pub length: f64,
}

/// What the lint measured on one part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartSize {
    /// The lowest frequency of a mode the part stores [`SHARE`] of (rad/s); `None` if no
    /// mode has that share (a part held rigid by its joints).
    pub omega: Option<f64>,
    /// The largest quasi-static elastic displacement under the sampled loads (m).
    pub deflection: f64,
}

/// Why the model was not sized.
#[derive(Clone, Debug, PartialEq)]
pub enum NotSized {
    /// More unknowns than [`MAX_UNKNOWNS`] or free motions than [`MAX_FREE`].
    TooLarge { unknowns: usize },
    /// The linear algebra failed (a singular reduction, a failed start).
    Failed(String),
}

impl From<RuntimeFailure> for NotSized {
    fn from(f: RuntimeFailure) -> NotSized {
        NotSized::Failed(f.detail)
    }
}

/// What the lint measured on the model.
#[derive(Clone, Debug, PartialEq)]
pub struct Sizing {
    pub parts: Vec<PartSize>,
    /// The highest frequency of a mode that no part owns (rad/s): the scene's own motion
    /// (a pendulum's swing, a lag mode on its spring), zero if there is none.
    pub unowned: f64,
}

/// Sizes every part of `sys`, the loads sampled at `times`.
pub fn size_parts(
    sys: &System,
    set: &Settings,
    parts: &[Part],
    times: &[f64],
) -> Result<Sizing, NotSized> {
    let mults = sys.unknowns.iter().filter(|k| k.is_multiplier()).count();
    let nf = sys.len() - mults;
    if nf > MAX_UNKNOWNS || nf.saturating_sub(mults) > MAX_FREE {
        return Err(NotSized::TooLarge { unknowns: nf });
    }
    let statics = set.method == crate::settings::Method::Static;
    let mut it = Integrator::new(sys, set)?;
    // Dynamics: the consistent accelerations at each sampled time (the loads then, the drives'
    // rates projected onto); statics: the loads themselves.
    let mut accelerations = Vec::new();
    if !statics {
        for &t in times {
            let mut start = sys.initial.clone();
            start.t = t;
            if it.restart(&start).is_err() {
                continue;
            }
            let st = it.state();
            let mut a: Vec<f64> = (0..sys.len())
                .map(|i| match sys.unknowns[i] {
                    UnknownKind::Rotation { node, axis } => st.rot[node].dw[axis],
                    _ => st.a[i],
                })
                .collect();
            for p in parts {
                centripetal(sys, st, p, &mut a);
            }
            accelerations.push(a);
        }
    }
    let mut rest = sys.initial.clone();
    rest.v
        .iter_mut()
        .chain(rest.a.iter_mut())
        .for_each(|x| *x = 0.0);
    for r in &mut rest.rot {
        (r.w, r.dw) = ([0.0; 3], [0.0; 3]);
    }
    rest.frames.iter_mut().for_each(|f| *f = Frame::default());
    it.restart(&rest)?;
    let lin = it.linearize();
    if !lin
        .m
        .iter()
        .chain(&lin.k)
        .chain(&lin.b)
        .all(|x| x.is_finite())
    {
        return Err(NotSized::Failed(
            "the linearization at rest is not finite".into(),
        ));
    }
    let modes = Modes::of(&lin)?;
    let st = it.state().clone();
    let free = |v: &[f64]| DVector::<f64>::from_iterator(nf, lin.unknowns.iter().map(|&i| v[i]));
    let loads: Vec<DVector<f64>> = if statics {
        load_vectors(sys, times).iter().map(|f| free(f)).collect()
    } else {
        let m = DMatrix::<f64>::from_row_slice(nf, nf, &lin.m);
        accelerations.iter().map(|a| &m * free(a)).collect()
    };
    let mut owned = vec![false; modes.w2.len()];
    let sized = parts
        .iter()
        .map(|p| size_part(sys, &st, &lin, &modes, p, &loads, &mut owned))
        .collect();
    let unowned = (0..modes.w2.len())
        .filter(|&j| !owned[j] && modes.w2[j] > 0.0)
        .map(|j| modes.w2[j].sqrt())
        .fold(0.0, f64::max);
    Ok(Sizing {
        parts: sized,
        unowned,
    })
}

/// Adds to `a` the centripetal accelerations of the part's nodes turning with the part's mean
/// angular velocity `w` about its centre, `w x (w x (x_k - c))`: the load that bends a
/// spinning part, which the consistent start does not show (an undeformed part's nodes start
/// along their velocities; the internal forces that curve their paths come with deformation).
fn centripetal(sys: &System, st: &State, part: &Part, a: &mut [f64]) {
    let turning: Vec<V3> = part
        .nodes
        .iter()
        .filter_map(|&s| match sys.unknowns.get(s + 3) {
            Some(UnknownKind::Rotation { node, .. }) => Some(V3::from(st.rot[*node].w)),
            _ => None,
        })
        .collect();
    if turning.is_empty() {
        return;
    }
    let w = turning.iter().sum::<V3>() / turning.len() as f64;
    let at = |s: usize| V3::new(st.q[s], st.q[s + 1], st.q[s + 2]);
    let c = part.nodes.iter().map(|&s| at(s)).sum::<V3>() / part.nodes.len() as f64;
    for &s in &part.nodes {
        let ac = w.cross(&w.cross(&(at(s) - c)));
        for i in 0..3 {
            a[s + i] += ac[i];
        }
    }
}

/// The load vectors over all unknowns: minus the force residual at each time, at the initial
/// positions, at rest, with zero multipliers (statics).
fn load_vectors(sys: &System, times: &[f64]) -> Vec<Vec<f64>> {
    let mut st: State = sys.initial.clone();
    st.v.iter_mut()
        .chain(st.a.iter_mut())
        .for_each(|x| *x = 0.0);
    st.lambda.iter_mut().for_each(|x| *x = 0.0);
    for r in &mut st.rot {
        (r.w, r.dw) = ([0.0; 3], [0.0; 3]);
    }
    st.frames.iter_mut().for_each(|f| *f = Frame::default());
    let aug = Augment {
        s: 1.0,
        p: 0.0,
        rate_scale: 1.0,
    };
    let mut r = Residual::new(sys.len());
    times
        .iter()
        .map(|&t| {
            st.t = t;
            r.clear();
            for e in &sys.elements {
                e.residual(&st, aug, &mut r);
            }
            r.force.iter().map(|f| -f).collect()
        })
        .collect()
}

/// The reduced, mass-normalized modes: `x_i = N y_i` over the linearization's unknowns.
struct Modes {
    /// Squared frequencies, increasing (elastic and rigid alike).
    w2: Vec<f64>,
    /// Columns: each mode over the free unknowns (`nf x count`).
    shapes: DMatrix<f64>,
}

impl Modes {
    fn of(lin: &Linearization) -> Result<Modes, NotSized> {
        let nf = lin.unknowns.len();
        let failed = |what: &str| NotSized::Failed(format!("the sizing analysis: {what}"));
        let (basis, r) = null_space(&lin.b, lin.rows, nf).ok_or_else(|| failed("no null space"))?;
        let n = DMatrix::<f64>::from_column_slice(nf, r, &basis);
        let sym = |a: &[f64]| {
            let a = DMatrix::<f64>::from_row_slice(nf, nf, a);
            let a = &n.transpose() * (&a + a.transpose()) * &n * 0.5;
            (&a + a.transpose()) * 0.5
        };
        let (m, k) = (sym(&lin.m), sym(&lin.k));
        // Mass-carrying directions P (scaled so that P^T M P = I) and massless ones Q.
        let em = eigen(m);
        let dmax = em.eigenvalues.amax();
        let (heavy, light): (Vec<usize>, Vec<usize>) =
            (0..r).partition(|&i| em.eigenvalues[i] > 1e-12 * dmax);
        let p = DMatrix::<f64>::from_fn(r, heavy.len(), |i, j| {
            em.eigenvectors[(i, heavy[j])] / em.eigenvalues[heavy[j]].sqrt()
        });
        let q = DMatrix::<f64>::from_fn(r, light.len(), |i, j| em.eigenvectors[(i, light[j])]);
        // Static condensation of the massless directions: c = -S a, S = pinv(Q^T K Q) Q^T K P;
        // a massless direction without stiffness (a rod's spin about its own axis) drops out.
        let y = if light.is_empty() {
            p
        } else {
            let kqq = eigen(q.transpose() * &k * &q);
            let kmax = kqq.eigenvalues.amax();
            let inv = DMatrix::<f64>::from_diagonal(&kqq.eigenvalues.map(|l| {
                if l.abs() > 1e-12 * kmax {
                    1.0 / l
                } else {
                    0.0
                }
            }));
            let pinv = &kqq.eigenvectors * inv * kqq.eigenvectors.transpose();
            let s = pinv * q.transpose() * &k * &p;
            &p - &q * &s
        };
        let ks = y.transpose() * &k * &y;
        let e = eigen((&ks + ks.transpose()) * 0.5);
        let mut order: Vec<usize> = (0..e.eigenvalues.len()).collect();
        order.sort_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
        let w2 = order.iter().map(|&i| e.eigenvalues[i]).collect();
        let a = DMatrix::<f64>::from_fn(e.eigenvalues.len(), order.len(), |i, j| {
            e.eigenvectors[(i, order[j])]
        });
        Ok(Modes {
            w2,
            shapes: n * y * a,
        })
    }
}

/// The symmetric eigendecomposition, empty for an empty matrix (nalgebra refuses those).
fn eigen(a: DMatrix<f64>) -> SymmetricEigen<f64, nalgebra::Dyn> {
    if a.is_empty() {
        SymmetricEigen {
            eigenvectors: a.clone(),
            eigenvalues: DVector::zeros(0),
        }
    } else {
        SymmetricEigen::new(a)
    }
}

fn size_part(
    sys: &System,
    st: &State,
    lin: &Linearization,
    modes: &Modes,
    part: &Part,
    loads: &[DVector<f64>],
    owners: &mut [bool],
) -> PartSize {
    let mut local = vec![usize::MAX; sys.len()];
    let mut col = vec![usize::MAX; sys.len()];
    for (j, &i) in lin.unknowns.iter().enumerate() {
        col[i] = j;
    }
    let unknowns: Vec<usize> = part.nodes.iter().flat_map(|&s| s..s + 6).collect();
    for (l, &g) in unknowns.iter().enumerate() {
        local[g] = l;
    }
    let kp = part_stiffness(sys, st, &local, unknowns.len());
    let cols: Vec<Option<usize>> = unknowns
        .iter()
        .map(|&g| (col[g] != usize::MAX).then_some(col[g]))
        .collect();
    let on_part = |j: usize| {
        DVector::<f64>::from_iterator(
            unknowns.len(),
            cols.iter().map(|c| c.map_or(0.0, |c| modes.shapes[(c, j)])),
        )
    };
    // A rigid motion of the part stores round-off (1e-16 of its stiffness); an elastic one
    // more than 1e-12 of it (the softest bending of a beam 1e12 times stiffer in stretch
    // would not count).
    let scale = kp.amax();
    let owned: Vec<usize> = (0..modes.w2.len())
        .filter(|&j| {
            let w2 = modes.w2[j];
            let x = on_part(j);
            let stored = x.dot(&(&kp * &x));
            w2 > 0.0 && stored >= SHARE * w2 && stored > 1e-12 * scale * x.norm_squared()
        })
        .collect();
    owned.iter().for_each(|&j| owners[j] = true);
    let omega = owned.first().map(|&j| modes.w2[j].sqrt());
    let mut deflection: f64 = 0.0;
    for f in loads {
        let mut u = DVector::<f64>::zeros(unknowns.len());
        for &j in &owned {
            let amp = modes.shapes.column(j).dot(f) / modes.w2[j];
            u += on_part(j) * amp;
        }
        deflection = deflection.max(elastic_part(sys, st, part, &u));
    }
    PartSize { omega, deflection }
}

/// The part's elements' stiffness over its unknowns (`local`: global -> local index): the
/// elements all of whose unknowns are the part's.
fn part_stiffness(sys: &System, st: &State, local: &[usize], n: usize) -> DMatrix<f64> {
    let aug = Augment {
        s: 1.0,
        p: 0.0,
        rate_scale: 1.0,
    };
    let coeffs = TangentCoeffs {
        mass: 0.0,
        velocity: 0.0,
        position: 1.0,
        force_weight: 1.0,
    };
    let mut k = DMatrix::<f64>::zeros(n, n);
    let mut block = Vec::new();
    for e in &sys.elements {
        let idx = e.indices();
        let Some(at) = idx
            .iter()
            .map(|&g| (local[g] != usize::MAX).then_some(local[g]))
            .collect::<Option<Vec<usize>>>()
        else {
            continue;
        };
        let nl = idx.len();
        block.clear();
        block.resize(nl * nl, 0.0);
        e.tangent(st, aug, coeffs, &mut block);
        for (i, &li) in at.iter().enumerate() {
            for (j, &lj) in at.iter().enumerate() {
                k[(li, lj)] += 0.5 * (block[i * nl + j] + block[j * nl + i]);
            }
        }
    }
    k
}

/// The largest displacement of `u` (the part's unknowns, node by node: translation, virtual
/// rotation) that its best rigid motion leaves, rotations counted times the part's length.
fn elastic_part(sys: &System, st: &State, part: &Part, u: &DVector<f64>) -> f64 {
    let nn = part.nodes.len();
    let at = |k: usize| {
        V3::new(
            st.q[part.nodes[k]],
            st.q[part.nodes[k] + 1],
            st.q[part.nodes[k] + 2],
        )
    };
    let centre = (0..nn).map(at).sum::<V3>() / nn as f64;
    // u_k = a + theta x r_k = a - r_k~ theta: least squares over the translations.
    let mut a = DMatrix::<f64>::zeros(3 * nn, 6);
    let mut b = DVector::<f64>::zeros(3 * nn);
    for k in 0..nn {
        let r = at(k) - centre;
        let rt = crate::runtime::rotation::tilde(&r);
        for i in 0..3 {
            a[(3 * k + i, i)] = 1.0;
            for j in 0..3 {
                a[(3 * k + i, 3 + j)] = -rt[(i, j)];
            }
            b[3 * k + i] = u[6 * k + i];
        }
    }
    let fit = a
        .clone()
        .svd(true, true)
        .solve(&b, 1e-12)
        .unwrap_or_else(|_| DVector::zeros(6));
    let moved = &a * &fit - &b;
    let theta = V3::new(fit[3], fit[4], fit[5]);
    let mut worst: f64 = 0.0;
    for k in 0..nn {
        let t = V3::new(moved[3 * k], moved[3 * k + 1], moved[3 * k + 2]).norm();
        let phi = V3::new(u[6 * k + 3], u[6 * k + 4], u[6 * k + 5]) - theta;
        let rotates = matches!(
            sys.unknowns[part.nodes[k] + 3],
            UnknownKind::Rotation { .. }
        );
        let turn = if rotates {
            phi.norm() * part.length
        } else {
            0.0
        };
        worst = worst.max(t).max(turn);
    }
    worst
}
