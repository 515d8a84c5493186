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

use crate::runtime::rotation::{exp, left_jacobian, left_jacobian_inverse, M3, V3};
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
    let ((u0, t0), (u, t)) = (split(d0), split(d));
    let th = compose_rotations(&t0, &t);
    if !sys.is_frame(k) {
        return join(&V3::zeros(), &th);
    }
    let p = left_jacobian(&t0) * u0 + exp(&t0) * (left_jacobian(&t) * u);
    join(&(left_jacobian_inverse(&th) * p), &th)
}
