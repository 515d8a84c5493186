//! Linearized modal analysis about the initial state (`mbd modes`).
//!
//! The element matrices at the consistent initial state give `M x'' + G x' + K x = 0` with
//! `B x = 0` (THEORY §3.6, §6). Modes exist only about a steady motion: an equilibrium, or a
//! rigid rotation at `Omega` about a fixed axis that the equations do not notice (a relative
//! equilibrium of a system symmetric about the axis). [`steadiness`] decides which, or why
//! neither; a model that is neither (a rotor on a non-rotating flexible structure, two rotors,
//! gravity across the spin axis) has periodic or time-varying equations, and the analysis
//! refuses it unless frozen-time eigenvalues are asked for.
//!
//! About a rigid rotation, perturbations are written in the frame turning with it,
//! `dx = Q xi`, `dtheta = Q psi`, `Q = exp(Omega~ t)`, which with
//! `d omega = d theta-dot - omega~ d theta` gives constant coefficients:
//! `G_r = G + 2 M_x Omega~ + M_theta Omega~` and `K_r = K + G_x Omega~ + M_x Omega~^2`
//! (`_x` the translation columns, `_theta` the rotation columns). The equations are reduced
//! to the null space of `B` and the quadratic eigenproblem is solved as a generalized one,
//! `[0 I; -K -G] z = s [I 0; 0 M] z` (QZ), so massless unknowns give infinite eigenvalues,
//! which are dropped.

use super::integrator::{Integrator, Linearization};
use super::linear::{generalized_eigen, least_squares, null_space};
use super::{RuntimeFailure, Settings};
use crate::runtime::rotation::{exp, orthonormalize, tilde, V3};
use crate::runtime::{Element, State, System};
use nalgebra::DMatrix;

/// A complex number `re + i im`.
#[allow(non_camel_case_types)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct c64 {
    pub re: f64,
    pub im: f64,
}

impl c64 {
    pub fn new(re: f64, im: f64) -> c64 {
        c64 { re, im }
    }
}

/// One mode: the eigenvalue `s` (1/s) and the shape over the system's unknowns (multipliers
/// zero), scaled so that its largest entry is 1.
#[derive(Clone, Debug)]
pub struct Mode {
    pub s: c64,
    pub shape: Vec<c64>,
}

impl Mode {
    /// Undamped natural frequency `|s|` in rad/s.
    pub fn omega(&self) -> f64 {
        (self.s.re * self.s.re + self.s.im * self.s.im).sqrt()
    }

    /// Damped frequency in Hz.
    pub fn frequency_hz(&self) -> f64 {
        self.s.im.abs() / (2.0 * std::f64::consts::PI)
    }

    pub fn damping_ratio(&self) -> f64 {
        let w = self.omega();
        if w > 0.0 {
            -self.s.re / w
        } else {
            0.0
        }
    }
}

/// Why the initial state is not a steady motion.
#[derive(Clone, Debug, PartialEq)]
pub enum Unsteady {
    /// Two rotating nodes (of entities `a` and `b`) turn at different rates: a rotor on a
    /// non-rotating structure, or two rotors.
    Spins {
        a: usize,
        wa: [f64; 3],
        b: usize,
        wb: [f64; 3],
    },
    /// The velocities are not a rigid rotation (entity, deviation in m/s).
    Velocities { entity: usize, deviation: f64 },
    /// The state accelerates: not an equilibrium or steady rotation (entity, deviation in
    /// m/s^2 or rad/s^2).
    Accelerates {
        entity: usize,
        deviation: f64,
        angular: bool,
    },
    /// The model turns rigidly at `spin`, but its linearized equations change as it turns
    /// (largest relative change over a turn of one radian): they are periodic.
    Periodic { spin: [f64; 3], change: f64 },
}

/// The frame the modes are referred to.
#[derive(Clone, Debug, PartialEq)]
pub enum Frame {
    /// About an equilibrium.
    Inertial,
    /// About a steady rotation, in the frame turning at `spin` (rad/s).
    Rotating { spin: [f64; 3] },
    /// Frozen-time eigenvalues at t = 0 of a motion that is not steady (asked for): not the
    /// system's modes. Referred to the frame turning at `spin` when every node turns alike.
    Frozen {
        spin: Option<[f64; 3]>,
        why: Unsteady,
    },
}

impl Frame {
    pub fn spin(&self) -> Option<[f64; 3]> {
        match self {
            Frame::Inertial => None,
            Frame::Rotating { spin } => Some(*spin),
            Frame::Frozen { spin, .. } => *spin,
        }
    }

    /// The CSV label: `inertial`, `rotating` or `frozen`.
    pub fn label(&self) -> &'static str {
        match self {
            Frame::Inertial => "inertial",
            Frame::Rotating { .. } => "rotating",
            Frame::Frozen { .. } => "frozen",
        }
    }
}

/// What the analysis found.
pub struct Modes {
    /// By increasing natural frequency; one of each complex-conjugate pair (`Im s >= 0`).
    pub modes: Vec<Mode>,
    pub frame: Frame,
    /// Degrees of freedom: unknowns less independent constraints.
    pub dofs: usize,
    /// Of those, the motions without inertia (infinite eigenvalues, no mode).
    pub massless: usize,
    /// The fastest spin of any rotating node at the start (rad/s).
    pub rotor_speed: f64,
    /// How far the steady motion is from the initial state: the largest translation (m).
    pub moved: f64,
}

/// Why the analysis gave no modes.
#[derive(Clone, Debug, PartialEq)]
pub enum ModesFailure {
    Runtime(RuntimeFailure),
    Unsteady(Unsteady),
}

impl From<RuntimeFailure> for ModesFailure {
    fn from(f: RuntimeFailure) -> ModesFailure {
        ModesFailure::Runtime(f)
    }
}

/// Relative tolerances of the steadiness tests (the consistent start is exact to about
/// 1e-12 of these scales).
const SPIN_TOL: f64 = 1e-9;
const MOTION_TOL: f64 = 1e-7;
/// Largest relative change of the linearized equations over a turn of one radian for them to
/// count as constant.
const PERIODIC_TOL: f64 = 1e-7;
/// Newton iterations to the steady motion.
const RELAX_ITERATIONS: usize = 30;

/// The modes about the steady motion of the initial state. With `frozen`, a state that is not
/// a steady motion gives the frozen-time eigenvalues (marked as such) instead of
/// [`ModesFailure::Unsteady`].
///
/// A state that moves rigidly but does not yet balance (a beam's stretch from a formula, a blade
/// not yet at its steady lag or coning angle, a structure before its static deflection) is
/// first brought to the nearest steady motion by Newton's method on the rotating-frame
/// equations ([`relax`]); [`Modes::moved`] says how far.
pub fn modes(sys: &System, set: &Settings, frozen: bool) -> Result<Modes, ModesFailure> {
    let mut it = Integrator::new(sys, set)?;
    it.initialize()?;
    let st = it.state().clone();
    let found = match rigid_motion(sys, &st) {
        Err(why) => Err(why),
        Ok(motion) => {
            let periodic = if motion.spin.norm() > 0.0 {
                let lin = it.linearize();
                periodic_change(sys, &mut it, &st, &lin, &motion)?
            } else {
                0.0
            };
            if periodic > PERIODIC_TOL {
                Err(Unsteady::Periodic {
                    spin: motion.spin.into(),
                    change: periodic,
                })
            } else {
                relax(sys, &mut it, &st, &motion, set.increment_tolerance)?
                    .map(|moved| (motion, moved))
            }
        }
    };
    let (frame, moved) = match found {
        Ok((motion, moved)) if motion.spin.norm() > 0.0 => (
            Frame::Rotating {
                spin: motion.spin.into(),
            },
            moved,
        ),
        Ok((_, moved)) => (Frame::Inertial, moved),
        Err(why) if frozen => {
            // Frozen at the initial state itself.
            it.restart(&st)?;
            let spin = uniform_spin(sys, &st).ok().flatten().map(Into::into);
            (Frame::Frozen { spin, why }, 0.0)
        }
        Err(why) => return Err(ModesFailure::Unsteady(why)),
    };
    let state = it.state().clone();
    let lin = it.linearize();
    let (m, g, k) = rotating_frame(sys, &lin, frame.spin().map(V3::from));
    let mut out = eigen(sys, &lin, m, g, k, frame)?;
    out.rotor_speed = state
        .rot
        .iter()
        .map(|r| r.omega().norm())
        .fold(0.0, f64::max);
    out.moved = moved;
    Ok(out)
}

/// A rigid motion: spin `w` about the axis through `center`, plus a uniform velocity `v0`
/// along it (all zero at rest).
#[derive(Clone, Copy, Debug)]
struct Motion {
    spin: V3,
    center: V3,
    v0: V3,
}

/// Where each translation triplet (node or point mass) and each revolute angle is among the
/// unknowns: `(translations, angles)`, as first unknowns.
fn coordinates(sys: &System) -> (Vec<usize>, Vec<usize>) {
    let mut tr = sys.translations.clone();
    let mut angles = Vec::new();
    for e in &sys.elements {
        match e {
            Element::PointMass(p) => tr.push(p.dofs[0]),
            Element::Joint(j) => angles.extend(j.angle),
            _ => {}
        }
    }
    (tr, angles)
}

fn triplet(v: &[f64], i: usize) -> V3 {
    V3::new(v[i], v[i + 1], v[i + 2])
}

/// The common angular velocity of the rotating nodes (`None`: none turns), or the two that
/// differ.
fn uniform_spin(sys: &System, st: &State) -> Result<Option<V3>, Unsteady> {
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
fn rigid_motion(sys: &System, st: &State) -> Result<Motion, Unsteady> {
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
fn relax(
    sys: &System,
    it: &mut Integrator,
    st: &State,
    motion: &Motion,
    tolerance: f64,
) -> Result<Result<f64, Unsteady>, RuntimeFailure> {
    let (tr, angles) = coordinates(sys);
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
        // d = a_steady - a over the free unknowns.
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
        let at = |i: usize| {
            if pos[i] == usize::MAX {
                0.0
            } else {
                dq[pos[i]] * cut
            }
        };
        let mut next = now.clone();
        for &i in &tr {
            let x = triplet(&now.q, i) + V3::new(at(i), at(i + 1), at(i + 2));
            let v = w.cross(&(x - motion.center)) + motion.v0;
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
fn periodic_change(
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

/// `M`, `G`, `K` over the free unknowns, in the frame turning at `spin` when given.
fn rotating_frame(
    sys: &System,
    lin: &Linearization,
    spin: Option<V3>,
) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let nf = lin.unknowns.len();
    let dense = |a: &[f64]| DMatrix::<f64>::from_row_slice(nf, nf, a);
    let (m, mut g, mut k) = (dense(&lin.m), dense(&lin.g), dense(&lin.k));
    let Some(w) = spin else { return (m, g, k) };
    // Omega~ on the translation and rotation triplets of each rotating node and point mass.
    let wt = tilde(&w);
    let mut om = DMatrix::<f64>::zeros(nf, nf);
    let mut is_rot = vec![false; nf];
    let mut pos = vec![usize::MAX; sys.len()];
    for (j, &i) in lin.unknowns.iter().enumerate() {
        pos[i] = j;
    }
    let (tr, _) = coordinates(sys);
    let triplets = tr
        .iter()
        .map(|&t| (t, false))
        .chain(sys.rotations.iter().map(|&r| (r, true)));
    for (first, rot) in triplets {
        let j = pos[first];
        if j == usize::MAX {
            continue;
        }
        for a in 0..3 {
            is_rot[j + a] = rot;
            for b in 0..3 {
                om[(j + a, j + b)] = wt[(a, b)];
            }
        }
    }
    let split = |a: &DMatrix<f64>, rot: bool| {
        DMatrix::<f64>::from_fn(
            nf,
            nf,
            |i, j| if is_rot[j] == rot { a[(i, j)] } else { 0.0 },
        )
    };
    let (mx, mt, gx) = (split(&m, false), split(&m, true), split(&g, false));
    g = &g + &mx * &om * 2.0 + &mt * &om;
    k = &k + &gx * &om + &mx * &om * &om;
    (m, g, k)
}

/// The eigenvalues and shapes of `M x'' + G x' + K x = 0` on the null space of `B`.
fn eigen(
    sys: &System,
    lin: &Linearization,
    m: DMatrix<f64>,
    g: DMatrix<f64>,
    k: DMatrix<f64>,
    frame: Frame,
) -> Result<Modes, RuntimeFailure> {
    let nf = lin.unknowns.len();
    let (basis, r) = null_space(&lin.b, lin.rows, nf)
        .ok_or_else(|| failure("the constraint gradient could not be decomposed"))?;
    let basis = DMatrix::<f64>::from_column_slice(nf, r, &basis);
    let red = |a: &DMatrix<f64>| basis.transpose() * a * &basis;
    let (m, g, k) = (red(&m), red(&g), red(&k));
    let n2 = 2 * r;
    let a = DMatrix::<f64>::from_fn(n2, n2, |i, j| match (i < r, j < r) {
        (true, true) => 0.0,
        (true, false) => f64::from(u8::from(j - r == i)),
        (false, true) => -k[(i - r, j)],
        (false, false) => -g[(i - r, j - r)],
    });
    let bm = DMatrix::<f64>::from_fn(n2, n2, |i, j| match (i < r, j < r) {
        (true, true) => f64::from(u8::from(i == j)),
        (false, false) => m[(i - r, j - r)],
        _ => 0.0,
    });
    let ev = generalized_eigen(a.as_slice(), bm.as_slice(), n2)
        .ok_or_else(|| failure("the eigenvalue problem did not converge"))?;
    let bnorm = (0..n2).map(|i| bm[(i, i)].abs()).fold(0.0, f64::max);
    let mut out = Vec::new();
    let mut infinite = 0;
    for ((xr, xi), (yr, yi), z) in ev {
        let den = yr * yr + yi * yi;
        if den.sqrt() <= 1e-12 * bnorm.max(1.0) {
            infinite += 1;
            continue;
        }
        let s = c64::new((xr * yr + xi * yi) / den, (xi * yr - xr * yi) / den);
        if !(s.re.is_finite() && s.im.is_finite()) {
            infinite += 1;
            continue;
        }
        if s.im < 0.0 {
            continue;
        }
        // Shape over the unknowns: the basis times the displacement half of z.
        let mut shape = vec![c64::new(0.0, 0.0); sys.len()];
        for (row, &i) in lin.unknowns.iter().enumerate() {
            let (mut re, mut im) = (0.0, 0.0);
            for (c, zc) in z.iter().take(r).enumerate() {
                re += basis[(row, c)] * zc.0;
                im += basis[(row, c)] * zc.1;
            }
            shape[i] = c64::new(re, im);
        }
        // Scale so that the largest entry is real and 1.
        let lead = shape
            .iter()
            .copied()
            .max_by(|p, q| p.re.hypot(p.im).total_cmp(&q.re.hypot(q.im)))
            .unwrap_or(c64::new(1.0, 0.0));
        let l2 = lead.re * lead.re + lead.im * lead.im;
        if l2 > 0.0 {
            for z in shape.iter_mut() {
                *z = c64::new(
                    (z.re * lead.re + z.im * lead.im) / l2,
                    (z.im * lead.re - z.re * lead.im) / l2,
                );
            }
        }
        out.push(Mode { s, shape });
    }
    out.sort_by(|p, q| p.omega().total_cmp(&q.omega()));
    Ok(Modes {
        modes: out,
        frame,
        dofs: r,
        massless: infinite / 2,
        rotor_speed: 0.0,
        moved: 0.0,
    })
}

fn failure(detail: &str) -> RuntimeFailure {
    RuntimeFailure {
        kind: super::FailureKind::Singular,
        t: 0.0,
        step: 0,
        entity: None,
        detail: detail.to_string(),
    }
}
