//! A wheel on a cylindrical joint along z: it slides and spins, with its centre of mass off the
//! axis by `E` and its principal axes tilted by `TILT` about x from the joint axis.
//!
//! Turning at the constant rate `w` about z while sliding, the wheel's rotation is
//! `R(t) = Rz(w t) R0` and the joint's force and moment on it (about its reference point, on
//! the axis) follow from Newton-Euler about the centre of mass `r_c = Rz(w t) (E, 0, 0)`:
//!
//! ```text
//! F = -m w^2 r_c                  (no axial component: the joint is free along z)
//! M = w^2 z x (J_c(t) z) + m (z'' - g_z) r_c x z,   J_c(t) = R(t) diag(I) R(t)^T
//! ```
//!
//! where `z''` is the axial acceleration and `g_z` gravity along the axis (the axial loads act
//! on the axis, gravity at the centre of mass).

use super::{assert_order, cross, dist, rotation, rotation_angle, run, vector};
use crate::common::{within, Trace};

const MASS: f64 = 2.0;
const E: f64 = 0.05;
const I: [f64; 3] = [0.02, 0.03, 0.04];
const TILT: f64 = 0.1;
const SPIN: f64 = 5.0;
const V0: f64 = 0.3;

type M3 = [[f64; 3]; 3];

fn mul(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn apply(a: &M3, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

fn rot_z(a: f64) -> M3 {
    let (s, c) = a.sin_cos();
    [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]
}

fn rot_x(a: f64) -> M3 {
    let (s, c) = a.sin_cos();
    [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
}

/// The wheel; `extra` adds gravity or an axial spring.
fn wheel(extra: &str) -> String {
    format!(
        "model axle
ground earth
rigid wheel {{
    mass = {MASS:?} kg, inertia = ({:?}, {:?}, {:?}) kg*m^2, center = ({E:?}, 0, 0) m
    orientation = rotate(x, {TILT:?} rad)
    velocity = (0, 0, {V0:?}) m/s, angular_velocity = (0, 0, {SPIN:?}) rad/s
}}
joint axle = cylindrical(earth @ (0, 0, -1) m, wheel) {{ axis = z }}
{extra}
output p = wheel.position, wheel.rotation, f = axle.force, mo = axle.moment
solve hht {{ dt = 5 ms, until = 1 s }}
",
        I[0], I[1], I[2]
    )
}

/// Largest errors over the run of (position, rotation, force, moment) against the screw motion
/// with axial position `z(t)` and acceleration `zdd(t)`, gravity `g_z` along the axis.
fn screw_errors(
    tr: &Trace,
    z: impl Fn(f64) -> f64,
    zdd: impl Fn(f64) -> f64,
    g_z: f64,
) -> [f64; 4] {
    let t = tr.col("t");
    let r0 = rot_x(TILT);
    let mut worst = [0.0f64; 4];
    for (k, &tk) in t.iter().enumerate() {
        let rz = rot_z(SPIN * tk);
        let r = mul(&rz, &r0);
        let rc = apply(&rz, [E, 0.0, 0.0]);
        // J_c z = R diag(I) R^T z.
        let jz = apply(&r, std::array::from_fn(|i| I[i] * r[2][i]));
        let gyro = cross([0.0, 0.0, SPIN * SPIN], jz);
        let lever = cross(rc, [0.0, 0.0, 1.0]).map(|x| MASS * (zdd(tk) - g_z) * x);
        let moment = std::array::from_fn(|i| gyro[i] + lever[i]);
        let force = rc.map(|x| -MASS * SPIN * SPIN * x);
        let errors = [
            dist(vector(tr, "p", k), [0.0, 0.0, z(tk)]),
            rotation_angle(&rotation(tr, "wheel", k), &r),
            dist(vector(tr, "f", k), force),
            dist(vector(tr, "mo", k), moment),
        ];
        for (w, e) in worst.iter_mut().zip(errors) {
            *w = w.max(e);
        }
    }
    worst
}

/// The scale of the reactions: the centripetal force and the gyroscopic moment.
fn scales() -> (f64, f64) {
    let gyro = SPIN * SPIN * (I[2] - I[1]) * TILT.sin() * TILT.cos();
    (MASS * SPIN * SPIN * E, gyro.abs())
}

/// With no axial load the wheel slides at its initial speed and spins at its initial rate: a
/// screw motion of constant twist, which the SE(3) update of a rigid body integrates exactly;
/// the reactions are the centripetal force and the gyroscopic moment of the tilted wheel. The
/// force is exact to what the Newton tolerances admit: at dt = 5 ms its error grows from 1e-14 N
/// (most steps converge in one iteration) until they stop it near 1e-5 N of 2.5 N (1e-7 N with
/// `tolerance = 1e-12`; it stays below 1e-11 N at dt = 2.5 ms).
#[test]
fn a_free_cylindrical_joint_slides_and_spins_exactly() {
    let tr = run("axle.mbd", &wheel(""), 5e-3, 2.0);
    let [ep, er, ef, em] = screw_errors(&tr, |t| V0 * t, |_| 0.0, 0.0);
    let (f, m) = scales();
    eprintln!(
        "free cylindrical: position {ep:.3e} m, rotation {er:.3e} rad, force {ef:.3e} N (of {f:.3}), moment {em:.3e} N m (of {m:.4})"
    );
    within(
        "free cylindrical: position against x0 + v t [m]",
        ep,
        1.6e-12,
    ); // measured 5.5e-13
    within(
        "free cylindrical: rotation against Rz(w t) R0 [rad]",
        er,
        4e-10,
    ); // measured 1.3e-10
    within("free cylindrical: force against -m w^2 r_c [N]", ef, 1.9e-5); // measured 6.3e-6
    within(
        "free cylindrical: moment against w x J_c w [N m]",
        em,
        2.2e-8,
    ); // measured 7.4e-9
}

/// Gravity along the axis: the wheel falls at g while it spins (a constant acceleration, which
/// Newmark's formulas integrate exactly), and the joint carries none of the weight.
#[test]
fn a_cylindrical_joint_under_gravity_along_its_axis_falls_at_g() {
    let g = 9.81;
    let tr = run(
        "axle.mbd",
        &wheel("gravity = (0, 0, -9.81) m/s^2"),
        5e-3,
        1.0,
    );
    let [ep, er, ef, em] = screw_errors(&tr, |t| V0 * t - 0.5 * g * t * t, |_| -g, -g);
    eprintln!(
        "falling cylindrical: position {ep:.3e} m, rotation {er:.3e} rad, force {ef:.3e} N, moment {em:.3e} N m"
    );
    within(
        "falling cylindrical: position against v t - g t^2 / 2 [m]",
        ep,
        6e-13,
    ); // measured 2.1e-13
    within(
        "falling cylindrical: rotation against Rz(w t) R0 [rad]",
        er,
        5e-13,
    ); // measured 1.6e-13
    within(
        "falling cylindrical: force against -m w^2 r_c [N]",
        ef,
        1.2e-10,
    ); // measured 4.0e-11
    within("falling cylindrical: moment [N m]", em, 1.3e-13); // measured 4.2e-14
}

/// An axial spring (a `spring` from a ground point on the axis to the wheel's reference point):
/// the slide is harmonic, `z = (v0 / w_n) sin(w_n t)`, `w_n^2 = k / m`, converging at second
/// order; the spin is untouched by it.
#[test]
fn an_axial_spring_on_a_cylindrical_joint_gives_a_harmonic_slide() {
    let k = 200.0;
    let wn = (k / MASS).sqrt();
    let spring = format!("spring coil(earth @ (0, 0, -1) m, wheel) {{ stiffness = {k:?} N/m }}");
    let text = wheel(&spring);
    let mut errors = Vec::new();
    for dt in [4e-3, 2e-3, 1e-3] {
        let tr = run("axle.mbd", &text, dt, 2.0);
        let z = |t: f64| V0 / wn * (wn * t).sin();
        let zdd = |t: f64| -V0 * wn * (wn * t).sin();
        let e = screw_errors(&tr, z, zdd, 0.0);
        eprintln!(
            "sprung cylindrical dt {dt}: position {:.3e} m, rotation {:.3e} rad, force {:.3e} N, moment {:.3e} N m",
            e[0], e[1], e[2], e[3]
        );
        errors.push(e);
    }
    let [ep, er, ef, em] = errors[2];
    within("sprung cylindrical at dt = 1 ms: slide [m]", ep, 1.8e-5); // measured 5.9e-6
    within(
        "sprung cylindrical at dt = 1 ms: rotation [rad]",
        er,
        1.2e-11,
    ); // measured 3.9e-12
    within("sprung cylindrical at dt = 1 ms: force [N]", ef, 3.2e-11); // measured 1.1e-11
    within("sprung cylindrical at dt = 1 ms: moment [N m]", em, 1.8e-4); // measured 5.9e-5
    let slide: Vec<f64> = errors.iter().map(|e| e[0]).collect();
    assert_order("sprung cylindrical slide", &slide, 2.0);
}
