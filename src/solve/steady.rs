//! Steady motions for modal analysis: whether the initial state is one (an equilibrium, or a
//! rigid rotation in a model symmetric about its axis), and Newton's method onto the nearest
//! one for a state that moves rigidly but does not yet balance.
//!
//! A rigid motion: every rotating node turns at one `w`, every point moves at
//! `w x (x - c) + v0`. It is steady when every acceleration is the centripetal `w x v`, no node
//! accelerates its turn and every joint rate is constant; about it the linearized equations are
//! constant in the turning frame only if the model is symmetric about the axis, which
//! [`periodic_change`] measures by linearizing again after a turn of one radian.

use super::integrator::{Integrator, Linearization};
use super::linear::{least_squares, null_space};
use super::modes::{rotating_frame, Unsteady};
use super::RuntimeFailure;
use crate::runtime::rotation::{exp, orthonormalize, V3};
use crate::runtime::{State, System};
use nalgebra::DMatrix;

/// Relative tolerances of the steadiness tests (the consistent start is exact to about
/// 1e-12 of these scales).
const SPIN_TOL: f64 = 1e-9;
const MOTION_TOL: f64 = 1e-7;
/// Largest relative change of the linearized equations over a turn of one radian for them to
/// count as constant.
pub(super) const PERIODIC_TOL: f64 = 1e-7;
/// Newton iterations to the steady motion.
const RELAX_ITERATIONS: usize = 30;

/// A rigid motion: spin `w` about the axis through `center`, plus a uniform velocity `v0`
/// along it (all zero at rest).
#[derive(Clone, Copy, Debug)]
pub(super) struct Motion {
    pub(super) spin: V3,
    pub(super) center: V3,
    pub(super) v0: V3,
}

/// Where each translation triplet (node or point mass) and each revolute angle is among the
/// unknowns: `(translations, angles)`, as first unknowns.
pub(super) fn coordinates(sys: &System) -> (Vec<usize>, Vec<usize>) {
    (sys.translation_triplets(), sys.angle_unknowns())
}

fn triplet(v: &[f64], i: usize) -> V3 {
    V3::new(v[i], v[i + 1], v[i + 2])
}

/// The common angular velocity of the rotating nodes (`None`: none turns), or the two that
/// differ.
pub(super) fn uniform_spin(sys: &System, st: &State) -> Result<Option<V3>, Unsteady> {
    let w: Vec<V3> = st.rot.iter().map(|r| r.omega()).collect();
    let scale = w.iter().fold(0.0f64, |m, x| m.max(x.norm()));
    if scale == 0.0 {
        return Ok(None);
    }
    let entity = |k: usize| sys.owners[sys.rotations[k]];
    for k in 1..w.len() {
        if (w[k] - w[0]).norm() > SPIN_TOL * scale {
            return Err(Unsteady::Spins {
                a: entity(0),
                wa: w[0].into(),
                b: entity(k),
                wb: w[k].into(),
            });
        }
    }
    Ok(Some(w[0]))
}

/// The rigid motion the velocities make (every rotating node at one angular velocity, every
/// point at `w x (x - c) + v0`), or why they make none.
pub(super) fn rigid_motion(sys: &System, st: &State) -> Result<Motion, Unsteady> {
    let spin = uniform_spin(sys, st)?;
    let w = spin.unwrap_or_else(V3::zeros);
    let (tr, _) = coordinates(sys);
    let ell = sys.length_scale.max(f64::MIN_POSITIVE);
    // v_i = w x (x_i - c) + v0 for one c and one v0 along w: b_i = w x x_i - v_i is then the
    // same for every point.
    let b: Vec<V3> = tr
        .iter()
        .map(|&i| w.cross(&triplet(&st.q, i)) - triplet(&st.v, i))
        .collect();
    let vscale = tr
        .iter()
        .map(|&i| triplet(&st.v, i).norm())
        .fold(w.norm() * ell, f64::max);
    let b0 = b.first().copied().unwrap_or_else(V3::zeros);
    for (k, bk) in b.iter().enumerate() {
        let dev = (bk - b0).norm();
        if dev > MOTION_TOL * vscale.max(f64::MIN_POSITIVE) {
            return Err(Unsteady::Velocities {
                entity: sys.owners[tr[k]],
                deviation: dev,
            });
        }
    }
    if w.norm() == 0.0 {
        return Ok(Motion {
            spin: w,
            center: V3::zeros(),
            v0: -b0,
        });
    }
    let center = b0.cross(&w) / w.norm_squared();
    Ok(Motion {
        spin: w,
        center,
        v0: -w * (b0.dot(&w) / w.norm_squared()),
    })
}

/// How far the (consistent) accelerations are from the steady motion's (the centripetal
/// `w x v_i`, no angular acceleration, constant joint rates): the largest deviation, its
/// entity, whether it is angular (rad/s^2), and the size of the accelerations for scale.
fn deviation(sys: &System, st: &State, w: V3) -> (f64, Option<usize>, bool, f64) {
    let (tr, angles) = coordinates(sys);
    let ell = sys.length_scale.max(f64::MIN_POSITIVE);
    let mut worst = (0.0, None, false);
    let vmax = tr
        .iter()
        .map(|&i| triplet(&st.v, i).norm())
        .fold(0.0, f64::max);
    let mut scale = w.norm() * vmax;
    for &i in &tr {
        let a = triplet(&st.a, i);
        scale = scale.max(a.norm());
        let dev = (a - w.cross(&triplet(&st.v, i))).norm();
        if dev > worst.0 {
            worst = (dev, Some(sys.owners[i]), false);
        }
    }
    for (k, r) in st.rot.iter().enumerate() {
        let dev = r.omega_dot().norm() * ell;
        scale = scale.max(dev);
        if dev > worst.0 {
            worst = (dev, Some(sys.owners[sys.rotations[k]]), true);
        }
    }
    for &a in &angles {
        let dev = st.a[a].abs() * ell;
        scale = scale.max(dev);
        if dev > worst.0 {
            worst = (dev, Some(sys.owners[a]), true);
        }
    }
    let dev = if worst.2 { worst.0 / ell } else { worst.0 };
    (dev, worst.1, worst.2, scale)
}

/// Newton iterations of the balance in the rotating frame, `K_r dq = -M (a_steady - a)` on the
/// constraint-free subspace (the equations of the steady motion: velocities and accelerations
/// follow the positions as the rigid motion has them, so their tangent is the rotating frame's
/// `K_r`), from `st` to the steady motion, restarting the integrator at each iterate. Leaves
/// the integrator at the steady state; gives the largest translation it moved, or why there is
/// none nearby.
pub(super) fn relax(
    sys: &System,
    it: &mut Integrator,
    st: &State,
    motion: &Motion,
    tolerance: f64,
) -> Result<Result<f64, Unsteady>, RuntimeFailure> {
    let tr = sys.translation_triplets();
    let w = motion.spin;
    let ell = sys.length_scale.max(f64::MIN_POSITIVE);
    let first = deviation(sys, st, w);
    let moved = |now: &State| {
        let far = tr
            .iter()
            .map(|&i| (triplet(&now.q, i) - triplet(&st.q, i)).norm())
            .fold(0.0, f64::max);
        // Below a billionth of the model's size it did not move.
        if far > 1e-9 * ell {
            far
        } else {
            0.0
        }
    };
    for _ in 0..RELAX_ITERATIONS {
        let now = it.state().clone();
        if deviation(sys, &now, w).0 == 0.0 {
            return Ok(Ok(moved(&now)));
        }
        let lin = it.linearize();
        let nf = lin.unknowns.len();
        let mut pos = vec![usize::MAX; sys.len()];
        for (j, &i) in lin.unknowns.iter().enumerate() {
            pos[i] = j;
        }
        let d = imbalance(sys, &now, w, &pos, nf);
        let (m, _, k) = rotating_frame(sys, &lin, (w.norm() > 0.0).then_some(w));
        let Some((basis, r)) = null_space(&lin.b, lin.rows, nf) else {
            break;
        };
        let n = DMatrix::<f64>::from_column_slice(nf, r, &basis);
        let d = nalgebra::DVector::from_vec(d);
        // The steady accelerations must satisfy the joints: a deviation across them (a
        // pendulum swinging through the bottom cannot move steadily) is no imbalance that
        // moving cancels.
        let across = &d - &n * (n.transpose() * &d);
        let scale = deviation(sys, &now, w).3.max(f64::MIN_POSITIVE);
        if across.iter().fold(0.0f64, |a, x| a.max(x.abs())) > 1e-3 * scale {
            break;
        }
        let kr = n.transpose() * &k * &n;
        let rhs = -(n.transpose() * (&m * &d));
        let Some(y) = least_squares(kr.transpose().as_slice(), r, r, rhs.as_slice(), 1, 1e-12)
        else {
            break;
        };
        let y = nalgebra::DVector::from_vec(y);
        // Moving can cancel the imbalance only if it is not in the null space of `K_r` (a free
        // body under a constant force accelerates wherever it is).
        let resolvable = (&kr * &y - &rhs).norm() <= 0.5 * rhs.norm();
        let dq = &n * y;
        let big = dq.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        // Below the Newton tolerance the imbalance left is round-off (a stiff beam's stretch
        // carries about 1e-7 of its accelerations as noise).
        if resolvable && big <= tolerance * ell {
            return Ok(Ok(moved(&now)));
        }
        // The step, at most a tenth of the model's length (or a tenth of a radian).
        let cut = if big > 0.1 * ell {
            0.1 * ell / big
        } else {
            1.0
        };
        let dq: Vec<f64> = dq.iter().map(|x| x * cut).collect();
        let next = moved_by(sys, &now, motion, &pos, &dq);
        it.restart(&next)?;
    }
    it.restart(st)?;
    Ok(Err(Unsteady::Accelerates {
        entity: first.1.unwrap_or(0),
        deviation: first.0,
        angular: first.2,
    }))
}

/// How much the linearized equations change when the steady rotation has turned by one radian:
/// the largest change of `M`, `G`, `K` on the constraint-free subspace (and of that subspace),
/// in the rotating frame, relative to each matrix's largest entry. Zero (to round-off) for a
/// system symmetric about the spin axis.
pub(super) fn periodic_change(
    sys: &System,
    it: &mut Integrator,
    st: &State,
    lin0: &Linearization,
    motion: &Motion,
) -> Result<f64, RuntimeFailure> {
    let (spin, center, v0) = (motion.spin, motion.center, motion.v0);
    let (tr, angles) = coordinates(sys);
    let dt = 1.0 / spin.norm();
    let q = exp(&(spin * dt));
    let mut s1 = st.clone();
    s1.t = st.t + dt;
    for &i in &tr {
        let x = center + q * (triplet(&st.q, i) - center) + v0 * dt;
        let (v, a) = (q * triplet(&st.v, i), q * triplet(&st.a, i));
        for c in 0..3 {
            s1.q[i + c] = x[c];
            s1.v[i + c] = v[c];
            s1.a[i + c] = a[c];
        }
    }
    for r in s1.rot.iter_mut() {
        let m = q * r.matrix();
        r.set_matrix(&m);
        r.w = (q * r.omega()).into();
        r.dw = (q * r.omega_dot()).into();
    }
    for &a in &angles {
        s1.q[a] += st.v[a] * dt;
    }
    it.restart(&s1)?;
    let lin1 = it.linearize();
    it.restart(st)?;
    // The rotation on the unknowns: Q on every translation and rotation triplet.
    let nf = lin0.unknowns.len();
    let mut pos = vec![usize::MAX; sys.len()];
    for (j, &i) in lin0.unknowns.iter().enumerate() {
        pos[i] = j;
    }
    let mut t = DMatrix::<f64>::identity(nf, nf);
    for &first in tr.iter().chain(&sys.rotations) {
        let j = pos[first];
        if j == usize::MAX {
            continue;
        }
        for a in 0..3 {
            for b in 0..3 {
                t[(j + a, j + b)] = q[(a, b)];
            }
        }
    }
    let Some((basis, r)) = null_space(&lin0.b, lin0.rows, nf) else {
        return Ok(f64::INFINITY);
    };
    let n0 = DMatrix::<f64>::from_column_slice(nf, r, &basis);
    let tn = &t * &n0;
    let dense = |a: &[f64], rows: usize| DMatrix::<f64>::from_row_slice(rows, nf, a);
    let max = |a: &DMatrix<f64>| a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let reduce = |x0: &[f64], x1: &[f64]| {
        (
            n0.transpose() * dense(x0, nf) * &n0,
            tn.transpose() * dense(x1, nf) * &tn,
        )
    };
    let (m, g, k) = (
        reduce(&lin0.m, &lin1.m),
        reduce(&lin0.g, &lin1.g),
        reduce(&lin0.k, &lin1.k),
    );
    // Each change against the size of its matrix's part in the eigenproblem: `G` against
    // `M Omega` and `sqrt(M K)`, `K` against `M Omega^2`, so a matrix that is zero (no damping)
    // does not turn round-off into a change.
    let w = spin.norm();
    let sm = max(&m.0).max(max(&m.1));
    let sk = max(&k.0).max(max(&k.1)).max(sm * w * w);
    let sg = max(&g.0).max(max(&g.1)).max(sm * w).max((sm * sk).sqrt());
    let mut change = 0.0f64;
    for ((r0, r1), scale) in [(m, sm), (g, sg), (k, sk)] {
        if scale > 0.0 {
            change = change.max(max(&(r1 - r0)) / scale);
        }
    }
    // The constraint-free subspace turns with the model.
    if lin1.rows > 0 {
        let b1 = dense(&lin1.b, lin1.rows);
        let bs = max(&b1);
        if bs > 0.0 {
            change = change.max(max(&(b1 * &tn)) / bs);
        }
    }
    Ok(change)
}

/// `a_steady - a` over the free unknowns (`pos`: each unknown's place among them, or
/// `usize::MAX`): what the steady motion's accelerations lack.
fn imbalance(sys: &System, now: &State, w: V3, pos: &[usize], nf: usize) -> Vec<f64> {
    let (tr, angles) = coordinates(sys);
    let mut d = vec![0.0; nf];
    for &i in &tr {
        let dv = w.cross(&triplet(&now.v, i)) - triplet(&now.a, i);
        for c in 0..3 {
            if pos[i + c] != usize::MAX {
                d[pos[i + c]] = dv[c];
            }
        }
    }
    for (k, &r) in sys.rotations.iter().enumerate() {
        for c in 0..3 {
            if pos[r + c] != usize::MAX {
                d[pos[r + c]] = -now.rot[k].dw[c];
            }
        }
    }
    for &a in &angles {
        if pos[a] != usize::MAX {
            d[pos[a]] = -now.a[a];
        }
    }
    d
}

/// `now` moved by `dq` over the free unknowns (rotations turned by their entries), with the
/// velocities of the rigid motion at the new positions.
fn moved_by(sys: &System, now: &State, motion: &Motion, pos: &[usize], dq: &[f64]) -> State {
    let (tr, angles) = coordinates(sys);
    let at = |i: usize| {
        if pos[i] == usize::MAX {
            0.0
        } else {
            dq[pos[i]]
        }
    };
    let mut next = now.clone();
    for &i in &tr {
        let x = triplet(&now.q, i) + V3::new(at(i), at(i + 1), at(i + 2));
        let v = motion.spin.cross(&(x - motion.center)) + motion.v0;
        for c in 0..3 {
            next.q[i + c] = x[c];
            next.v[i + c] = v[c];
        }
    }
    for (k, &r) in sys.rotations.iter().enumerate() {
        let turn = exp(&V3::new(at(r), at(r + 1), at(r + 2)));
        let m = orthonormalize(&(turn * now.rot[k].matrix()));
        next.rot[k].set_matrix(&m);
    }
    for &a in &angles {
        next.q[a] += at(a);
    }
    next
}
