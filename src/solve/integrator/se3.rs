//! The incremental rotation treatment, coupled with the translation: each rotating node is a
//! frame `H = (x, R)` in SE(3), updated by body-frame increments `H <- H exp(d)`, and the
//! Newmark relations act on body-frame twists `(R^T x-dot, R^T omega)` (Bruls, Cardona &
//! Arnold 2012). A rigid motion with a constant body twist (a steady spin about any fixed
//! axis, wherever the node is) is then integrated exactly.
//!
//! The elements stay in inertial components with spatial virtual rotations: the body-frame
//! correction `(du*, dtheta*)` moves the node by `dx = R du*` and `dtheta = R dtheta*` to first
//! order, so the iteration matrix is `T^T J T` and the residual `T^T r` with `T = diag(R, R)`.
//!
//! Nodes that are not frames (`System::is_frame`, beam nodes) keep only the rotational half:
//! `R <- R exp(dtheta*)` with Newmark on `R^T omega`, their translations being coordinates.

use crate::runtime::precise::coupling_coefficients;
use crate::runtime::rotation::{exp, left_jacobian, left_jacobian_inverse, tilde, M3, V3};
use crate::runtime::{State, System};

fn x_of(st: &State, t: usize) -> V3 {
    V3::new(st.q[t], st.q[t + 1], st.q[t + 2])
}

fn split(a: &[f64; 6]) -> (V3, V3) {
    (V3::new(a[0], a[1], a[2]), V3::new(a[3], a[4], a[5]))
}

fn join(u: &V3, w: &V3) -> [f64; 6] {
    [u[0], u[1], u[2], w[0], w[1], w[2]]
}

/// Body-frame twists from the inertial velocities and accelerations in the flat slots.
pub fn to_frames(sys: &System, st: &mut State) {
    for (k, (&t, &r)) in sys.translations.iter().zip(&sys.rotations).enumerate() {
        let rt = st.rot[k].matrix().transpose();
        let g = |x: &[f64], i: usize| V3::new(x[i], x[i + 1], x[i + 2]);
        let (mut v, w) = (rt * g(&st.v, t), rt * g(&st.v, r));
        let (mut a, dw) = (rt * g(&st.a, t), rt * g(&st.a, r));
        if !sys.is_frame(k) {
            // Translations are integrated as coordinates.
            (v, a) = (V3::zeros(), V3::zeros());
        }
        let f = &mut st.frames[k];
        f.v = join(&v, &w);
        f.dv = join(&(a - w.cross(&v)), &dw);
        f.alg = f.dv;
    }
}

/// Inertial velocities and accelerations (flat slots and node kinematics) of node `k` from its
/// body-frame twist.
pub fn to_physical(sys: &System, st: &mut State, k: usize) {
    let (t, r) = (sys.translations[k], sys.rotations[k]);
    let rm = st.rot[k].matrix();
    let (v, w) = split(&st.frames[k].v);
    let (dv, dw) = split(&st.frames[k].dv);
    let (xd, om) = (rm * v, rm * w);
    let (xdd, omd) = (rm * (dv + w.cross(&v)), rm * dw);
    let frame = sys.is_frame(k);
    for i in 0..3 {
        if frame {
            st.v[t + i] = xd[i];
            st.a[t + i] = xdd[i];
        }
        st.v[r + i] = om[i];
        st.a[r + i] = omd[i];
    }
    st.rot[k].w = om.into();
    st.rot[k].dw = omd.into();
}

/// `H <- H_from exp(d)` for node `k`, written into `to`.
pub fn displace(sys: &System, from: &State, to: &mut State, k: usize, d: &[f64; 6]) {
    let t = sys.translations[k];
    let (u, th) = split(d);
    let r0: M3 = from.rot[k].matrix();
    if sys.is_frame(k) {
        let x = x_of(from, t) + r0 * (left_jacobian(&th) * u);
        for i in 0..3 {
            to.q[t + i] = x[i];
        }
    }
    to.rot[k].set_matrix(&(r0 * exp(&th)));
}

/// The rotation vector of `exp(a) exp(b)`, through unit quaternions: every quantity stays as
/// small as the rotations, so the result is accurate relative to them (`log(exp(a) exp(b))`
/// through matrices would carry an absolute round-off of `1e-16` rad).
fn compose_rotations(a: &V3, b: &V3) -> V3 {
    let half = |v: &V3| {
        let t = v.norm();
        let (s, c) = (0.5 * t).sin_cos();
        let k = if t > 1e-6 { s / t } else { 0.5 - t * t / 48.0 };
        (c, v * k)
    };
    let ((wa, va), (wb, vb)) = (half(a), half(b));
    let (mut w, mut v) = (wa * wb - va.dot(&vb), vb * wa + va * wb + va.cross(&vb));
    if w < 0.0 {
        (w, v) = (-w, -v);
    }
    let sn = v.norm();
    if sn == 0.0 {
        return V3::zeros();
    }
    v * (2.0 * sn.atan2(w) / sn)
}

/// The body-frame increment `log(exp(d0) exp(d))` of node `k` after a correction `d` of the
/// step's increment `d0`, composed from the increments alone: the step's increment then
/// never comes from differences of the coordinates (metres from the origin, rotations of many
/// turns), whose round-off `1/(beta h^2)` would amplify into the accelerations. Nodes that are
/// not frames compose their rotation only.
pub fn compose(sys: &System, k: usize, d0: &[f64; 6], d: &[f64; 6]) -> [f64; 6] {
    if !sys.is_frame(k) {
        let th = compose_rotations(&split(d0).1, &split(d).1);
        return join(&V3::zeros(), &th);
    }
    compose_frames(d0, d)
}

/// The turn (rad) of a correction above which [`increment`] composes exactly.
const EXACT: f64 = 1e-3;

/// How node `k`'s body-frame increment `d0` moves with a correction `d`: `J^-1 d`, the
/// first-order part of `log(exp(d0) exp(d)) - d0` (SE(3)'s inverse right Jacobian at `d0`;
/// nodes that are not frames, the rotation's alone). The step's increment adds it, and its
/// algorithmic acceleration adds it over `beta h^2`: the acceleration then never comes from
/// the increment less its predictable part, `h v`, whose round-off (`ulp(h v)`, the same
/// every step of a steady spin) became a steady load of `ulp(h v) / (beta h^2)`. (On the
/// windmill spinning without the pulse, the collective lag then grew to 1.3e-10 rad at
/// 6.25e-6 s; it is the reason the windmill's error stopped falling below 1e-5 s.) A
/// correction moves the frame by `exp(d)` to first order as before, so Newton's matrix is
/// unchanged. A correction that turns a node by more than [`EXACT`] (Newton far from the
/// step's solution, where the retraction steers its path) composes exactly, as before: with
/// the first-order update alone the stiff-beam two-bar at the paper's step failed at 12.15 s.
/// `jinv`: `right_jacobian_inverse(d0)` when the caller has it (the matrix just made at
/// this `d0`, [`Jinv`]).
pub fn increment(
    sys: &System,
    k: usize,
    d0: &[f64; 6],
    d: &[f64; 6],
    jinv: Option<&(M3, M3)>,
) -> [f64; 6] {
    let (du, dth) = split(d);
    if dth.norm() > EXACT {
        let exact = compose(sys, k, d0, d);
        return std::array::from_fn(|j| exact[j] - d0[j]);
    }
    if !sys.is_frame(k) {
        let a = jinv.map_or_else(|| left_jacobian_inverse(&-split(d0).1), |j| j.0);
        return join(&V3::zeros(), &(a * dth));
    }
    let (a, b) = jinv.copied().unwrap_or_else(|| right_jacobian_inverse(d0));
    join(&(a * du + b * dth), &(a * dth))
}

/// `right_jacobian_inverse(d0)` kept with its `d0`: the matrix's rate columns
/// ([`rate_maps`]) and the correction that follows ([`increment`]) take it at the same
/// increment, so it is made once an iteration, not twice.
#[derive(Clone, Copy)]
pub struct Jinv {
    d0: [f64; 6],
    j: (M3, M3),
}

impl Jinv {
    pub fn new(d0: &[f64; 6]) -> Jinv {
        Jinv {
            d0: *d0,
            j: right_jacobian_inverse(d0),
        }
    }

    /// The kept maps if they were made at `d0` (bit for bit).
    pub fn at(&self, d0: &[f64; 6]) -> Option<&(M3, M3)> {
        (self.d0.map(f64::to_bits) == d0.map(f64::to_bits)).then_some(&self.j)
    }
}

/// `log(exp(d0) exp(d))` in SE(3), twists as `(u, theta)`.
fn compose_frames(d0: &[f64; 6], d: &[f64; 6]) -> [f64; 6] {
    let ((u0, t0), (u, t)) = (split(d0), split(d));
    let th = compose_rotations(&t0, &t);
    let p = left_jacobian(&t0) * u0 + exp(&t0) * (left_jacobian(&t) * u);
    join(&(left_jacobian_inverse(&th) * p), &th)
}

/// The translation-rotation block `Q(u, theta)` of SE(3)'s left Jacobian
/// `[[J_l(theta), Q], [0, J_l(theta)]]` (Barfoot, *State Estimation for Robotics*, 2017,
/// eq. 7.86), its coefficients by series below 1 rad ([`coupling_coefficients`]).
fn coupling(u: &V3, th: &V3) -> M3 {
    let t = th.norm();
    let (ut, tt) = (tilde(u), tilde(th));
    let (a, b, c) = coupling_coefficients(t);
    let (tu, ttu) = (tt * ut, tt * tt * ut);
    let tut = tu * tt;
    ut * 0.5
        + (tu + ut * tt + tut) * a
        + (ttu + ut * tt * tt - tut * 3.0) * b
        + (tut * tt + tt * tut) * c
}

/// `d log(exp(d0) exp(d)) / d d` at `d = 0`, SE(3)'s inverse right Jacobian at `d0`, as its
/// diagonal block `J_r^-1(theta)` and its translation-rotation block.
pub fn right_jacobian_inverse(d0: &[f64; 6]) -> (M3, M3) {
    let (u, th) = split(d0);
    let ja = left_jacobian_inverse(&-th);
    (ja, -ja * coupling(&-u, &-th) * ja)
}

/// How node `k`'s inertial rates move with a body-frame correction `d`, beyond `velocity` and
/// `mass` times the position columns `R`: 6x6 maps `(E_v, E_a)`, row-major over (translation,
/// rotation), acting on the inertial position columns (so that `M E_a + C E_v` times `T = R`
/// is what the Newmark relations on body-frame twists add to `(mass M + velocity C) T`).
/// With `J = [[A, B], [0, A]]` the increment's inverse right Jacobian, `^` the rotation by
/// `R` (`A^ = R A R^T`):
/// `E_v = c_v [[A^ - I, B^], [0, A^ - I]] - [[0, x-dot~], [0, w~]]`,
/// `E_a = c_a [[A^ - I, B^], [0, A^ - I]] + c_v [[w~ A^, w~ B^ - x-dot~ A^], [0, 0]]
/// - [[0, x-ddot~], [0, w-dot~]]`. Nodes that are not frames keep the rotation blocks alone.
pub fn rate_maps(
    sys: &System,
    st: &State,
    k: usize,
    jinv: &Jinv,
    cv: f64,
    ca: f64,
) -> ([f64; 36], [f64; 36]) {
    let (t, r) = (sys.translations[k], sys.rotations[k]);
    let g = |x: &[f64], i: usize| V3::new(x[i], x[i + 1], x[i + 2]);
    let rm = st.rot[k].matrix();
    let (w, dw) = (g(&st.v, r), g(&st.a, r));
    let (ja, jb) = jinv.j;
    let a = rm * ja * rm.transpose() - M3::identity();
    let mut ev = [0.0; 36];
    let mut ea = [0.0; 36];
    let put = |m: &mut [f64; 36], r0: usize, c0: usize, b: &M3| {
        for i in 0..3 {
            for j in 0..3 {
                m[(r0 + i) * 6 + c0 + j] += b[(i, j)];
            }
        }
    };
    put(&mut ev, 3, 3, &(a * cv - tilde(&w)));
    put(&mut ea, 3, 3, &(a * ca - tilde(&dw)));
    if sys.is_frame(k) {
        let (xd, xdd) = (g(&st.v, t), g(&st.a, t));
        let b = rm * jb * rm.transpose();
        let ah = a + M3::identity();
        put(&mut ev, 0, 0, &(a * cv));
        put(&mut ev, 0, 3, &(b * cv - tilde(&xd)));
        put(&mut ea, 0, 0, &(a * ca + tilde(&w) * ah * cv));
        put(
            &mut ea,
            0,
            3,
            &(b * ca + (tilde(&w) * b - tilde(&xd) * ah) * cv - tilde(&xdd)),
        );
    }
    (ev, ea)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The inverse right Jacobian is the derivative of the composition (central differences,
    /// agreement 1e-8 relative; measured 3e-10), at large and at small rotations.
    #[test]
    fn right_jacobian_inverse_is_the_derivative_of_composition() {
        for d0 in [
            [0.3, -0.7, 1.1, 0.9, -0.4, 1.3],
            [0.3, -0.7, 1.1, 2e-3, -1e-3, 4e-3],
            [-1.2, 0.5, 0.2, 1e-7, 3e-8, -2e-7],
        ] {
            let (ja, jb) = right_jacobian_inverse(&d0);
            let e = 1e-6;
            for j in 0..6 {
                let mut dp = [0.0; 6];
                dp[j] = e;
                let (p, m) = (
                    compose_frames(&d0, &dp),
                    compose_frames(&d0, &dp.map(|x| -x)),
                );
                for i in 0..6 {
                    let fd = (p[i] - m[i]) / (2.0 * e);
                    let exact = match (i < 3, j < 3) {
                        (true, true) => ja[(i, j)],
                        (true, false) => jb[(i, j - 3)],
                        (false, true) => 0.0,
                        (false, false) => ja[(i - 3, j - 3)],
                    };
                    assert!(
                        (fd - exact).abs() < 1e-8,
                        "{d0:?} ({i}, {j}): {fd} vs {exact}"
                    );
                }
            }
        }
    }
}
