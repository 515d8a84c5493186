//! A universal (Cardan) joint between two shafts whose axes meet at the origin at an angle beta.
//!
//! The input shaft turns about x on a revolute joint to ground (angle th1); the output shaft
//! about `b = (cos beta, sin beta, 0)` (angle th2). The cross's arm in the input is `z` at the
//! start, its arm in the output `(-sin beta, cos beta, 0)`: they stay square, which with
//! `a1 = (0, -sin th1, cos th1)`, `a2 = cos th2 (-sin beta, cos beta, 0) + sin th2 z` is
//! `cos th1 sin th2 = cos beta sin th1 cos th2`, so
//!
//! ```text
//! tan th2 = cos beta tan th1,   th2' = r(th1) th1',   r = cos beta / (1 - sin^2 beta sin^2 th1)
//! ```
//!
//! (the textbook `tan th2 = tan th1 / cos beta` with the roles of the arms exchanged).
//!
//! Both shafts on revolute joints to ground at the origin would hold the cross's centre three
//! times over (E0307). So the output's revolute is to a housing, a rigid body whose centre the
//! joints hold and whose rotations three distance links to ground lock: the housing stays put
//! and the model has no redundant constraint. Its revolute angle is the output angle.

use super::{assert_order, column, max_abs, run, unwrap};
use crate::common::within;
use crate::reference::dopri;
use std::f64::consts::{PI, TAU};

const BETA: f64 = 30.0 * PI / 180.0;
/// Polar inertias of the input and output shafts about their axes.
const J1: f64 = 0.01;
const J2: f64 = 0.02;

/// The Cardan joint's model: the input started at `w0` (the output at `r(0) w0`), driven at
/// that rate if `driven`.
fn cardan(w0: f64, driven: bool) -> String {
    let drive = if driven {
        format!(", rate = {w0:?} rad/s")
    } else {
        String::new()
    };
    let b = format!("({:?}, {:?}, 0)", BETA.cos(), BETA.sin());
    let w2 = w0 * BETA.cos();
    format!(
        "model cardan
ground earth
rigid inshaft {{ mass = 1 kg, inertia = ({J1:?}, 0.02, 0.02) kg*m^2, angular_velocity = ({w0:?}, 0, 0) rad/s }}
rigid outshaft {{
    mass = 1 kg, inertia = ({J2:?}, 0.03, 0.03) kg*m^2, orientation = rotate(z, {BETA:?} rad)
    angular_velocity = {w2:?} rad/s * {b}
}}
rigid housing {{ mass = 1 kg, inertia = (0.01, 0.01, 0.01) kg*m^2 }}
joint j1 = revolute(earth, inshaft) {{ axis = x{drive} }}
joint j2 = revolute(housing, outshaft) {{ axis = {b} }}
joint cross = universal(inshaft, outshaft) {{ axis1 = z, axis2 = ({:?}, {:?}, 0) }}
joint l1 = distance(earth @ (1, 1, 0) m, housing @ (1, 0, 0) m)
joint l2 = distance(earth @ (0, 1, 1) m, housing @ (0, 1, 0) m)
joint l3 = distance(earth @ (1, 0, 1) m, housing @ (0, 0, 1) m)
output th1 = j1.angle, w1 = j1.rate, th2 = j2.angle, w2 = j2.rate, m1 = j1.moment, h = housing.crv
solve hht {{ dt = 1 ms, until = 1 s }}
",
        -BETA.sin(),
        BETA.cos()
    )
}

/// The output angle for an input angle, continuous with it.
fn output_angle(th1: f64) -> f64 {
    let th2 = (BETA.cos() * th1.sin()).atan2(th1.cos());
    th1 + (th2 - th1 + PI).rem_euclid(TAU) - PI
}

/// The velocity ratio `r = th2' / th1'` and its derivative `dr/dth1`.
fn ratio(th1: f64) -> (f64, f64) {
    let s2 = BETA.sin().powi(2);
    let den = 1.0 - s2 * th1.sin().powi(2);
    (
        BETA.cos() / den,
        BETA.cos() * s2 * (2.0 * th1).sin() / (den * den),
    )
}

fn housing_motion(tr: &crate::common::Trace) -> f64 {
    (0..tr.rows.len())
        .map(|k| max_abs(["c1", "c2", "c3"].map(|c| tr.col(&format!("h.{c}"))[k])))
        .fold(0.0, f64::max)
}

/// Driven at a constant rate W for three turns, the output turns at the closed-form angle (the
/// position constraints hold it to the Newton tolerance), at the closed-form rate (its velocity
/// is the integrator's: second order), and the drive supplies the torque that accelerates the
/// output: by the power balance `tau W = d/dt (J2 th2'^2 / 2)`, `tau = J2 r r' W^2`. The torque
/// is a multiplier: it carries the O(h) start-up error of index-3 HHT (Arnold & Bruls 2007),
/// damped out within the first half second, and is second order after it.
#[test]
fn a_driven_cardan_joint_turns_the_output_at_the_closed_form_ratio() {
    let w = 2.0;
    let text = cardan(w, true);
    let mut errors = Vec::new();
    for dt in [4e-3, 2e-3, 1e-3] {
        let tr = run("cardan.mbd", &text, dt, 3.0 * TAU / w);
        let t = tr.col("t");
        let (th1, th2, w2) = (tr.col("th1"), unwrap(&tr.col("th2")), tr.col("w2"));
        let m1 = tr.col("m1.x");
        let e_th1 = max_abs((0..t.len()).map(|k| th1[k] - w * t[k]));
        let e_th2 = max_abs((0..t.len()).map(|k| th2[k] - output_angle(th1[k])));
        let e_w2 = max_abs((0..t.len()).map(|k| w2[k] - ratio(th1[k]).0 * w));
        let tau = |range: std::ops::Range<f64>| {
            max_abs((0..t.len()).filter(|&k| range.contains(&t[k])).map(|k| {
                let (r, dr) = ratio(th1[k]);
                m1[k] - J2 * r * dr * w * w
            }))
        };
        let (start, after) = (tau(0.0..0.1), tau(0.5..3.0));
        let still = housing_motion(&tr);
        eprintln!(
            "driven cardan dt {dt}: th1 {e_th1:.3e}, th2 {e_th2:.3e} rad, th2' {e_w2:.3e} rad/s, \
             drive torque {start:.3e} in 0.1 s, {after:.3e} N m after 0.5 s (peak {:.3e}), \
             housing {still:.3e} rad",
            max_abs(m1.iter().copied())
        );
        errors.push([e_th1, e_th2, e_w2, start, after, still]);
    }
    let [e_th1, e_th2, e_w2, start, after, still] = errors[2];
    within("driven cardan: input angle against W t [rad]", e_th1, 9e-12); // measured 3.0e-12
    within(
        "driven cardan: output angle against the closed form [rad]",
        e_th2,
        2e-14,
    ); // measured 7.1e-15
    within(
        "driven cardan at dt = 1 ms: output rate [rad/s]",
        e_w2,
        1.8e-6,
    ); // measured 5.9e-7
       // Of a peak torque of 2.4e-2 N m:
    within(
        "driven cardan at dt = 1 ms: drive torque at the start [N m]",
        start,
        1.4e-4,
    ); // measured 4.8e-5
    within(
        "driven cardan at dt = 1 ms: drive torque after 0.5 s [N m]",
        after,
        3.7e-7,
    ); // measured 1.2e-7
    within("driven cardan: housing rotation [rad]", still, 1e-12); // measured 0
    assert_order("driven cardan output rate", &column(&errors, 2), 2.0);
    assert_order(
        "driven cardan drive torque at the start",
        &column(&errors, 3),
        1.0,
    );
    assert_order(
        "driven cardan drive torque after 0.5 s",
        &column(&errors, 4),
        2.0,
    );
}

/// Left to coast from `w0`, the pair has one degree of freedom th1 with the kinetic energy
/// `(J1 + J2 r^2) th1'^2 / 2`: `(J1 + J2 r^2) th1'' + J2 r r' th1'^2 = 0`. Input angle and rate
/// and the output angle against it, second order as dt halves.
#[test]
fn a_coasting_cardan_joint_follows_its_reduced_equation() {
    let w0 = 3.0;
    let until = 4.0;
    let text = cardan(w0, false);
    let f = |_t: f64, y: &[f64; 2]| {
        let (r, dr) = ratio(y[0]);
        [y[1], -J2 * r * dr * y[1] * y[1] / (J1 + J2 * r * r)]
    };
    let mut errors = Vec::new();
    for dt in [4e-3, 2e-3, 1e-3] {
        let tr = run("cardan.mbd", &text, dt, until);
        let t = tr.col("t");
        let refs = dopri(f, 0.0, [0.0, w0], &t, 1e-12, 1e-14);
        let (th1, w1, th2) = (tr.col("th1"), tr.col("w1"), unwrap(&tr.col("th2")));
        let e_th1 = max_abs((0..t.len()).map(|k| th1[k] - refs[k][0]));
        let e_w1 = max_abs((0..t.len()).map(|k| w1[k] - refs[k][1]));
        let e_th2 = max_abs((0..t.len()).map(|k| th2[k] - output_angle(refs[k][0])));
        eprintln!(
            "coasting cardan dt {dt}: th1 {e_th1:.3e} rad, th1' {e_w1:.3e} rad/s, th2 {e_th2:.3e} rad, housing {:.3e}",
            housing_motion(&tr)
        );
        errors.push([e_th1, e_w1, e_th2]);
    }
    let [e_th1, e_w1, e_th2] = errors[2];
    within(
        "coasting cardan at dt = 1 ms: input angle [rad]",
        e_th1,
        7e-7,
    ); // measured 2.2e-7
    within(
        "coasting cardan at dt = 1 ms: input rate [rad/s]",
        e_w1,
        4e-6,
    ); // measured 1.4e-6
    within(
        "coasting cardan at dt = 1 ms: output angle [rad]",
        e_th2,
        7.5e-7,
    ); // measured 2.5e-7
    assert_order("coasting cardan input angle", &column(&errors, 0), 2.0);
    assert_order("coasting cardan input rate", &column(&errors, 1), 2.0);
}
