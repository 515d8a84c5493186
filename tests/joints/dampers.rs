//! Dampers against their closed forms: a prismatic joint's spring and damper (an under-damped
//! step response), the standalone `damper` on point masses, a revolute joint's `damper` and a
//! `torsional_damper` on a spinning rod, and the lag damper of `stdlib::rotor` on a turning
//! rotor against the reduced lag equation.

use super::{assert_order, column, max_abs, run};
use crate::common::{above, within, Trace};
use crate::reference::dopri;

/// Errors over the run of two channels against closed forms of t.
fn errors2(tr: &Trace, a: (&str, &dyn Fn(f64) -> f64), b: (&str, &dyn Fn(f64) -> f64)) -> [f64; 2] {
    let t = tr.col("t");
    let (ca, cb) = (tr.col(a.0), tr.col(b.0));
    [
        max_abs((0..t.len()).map(|k| ca[k] - (a.1)(t[k]))),
        max_abs((0..t.len()).map(|k| cb[k] - (b.1)(t[k]))),
    ]
}

/// A block on a prismatic joint with a spring and a damper (zeta = 0.1), loaded by a constant
/// force along it from t = 0: `x = x_s (1 - e^(-zeta w t) (cos w_d t + zeta w / w_d sin w_d t))`,
/// `x_s = F / k`, `w_d = w sqrt(1 - zeta^2)`; displacement and speed at second order.
#[test]
fn a_damped_slider_has_the_closed_form_step_response() {
    let (m, k, zeta, f): (f64, f64, f64, f64) = (2.0, 200.0, 0.1, 10.0);
    let w = (k / m).sqrt();
    let c = 2.0 * zeta * w * m;
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let xs = f / k;
    let text = format!(
        "model slider
ground earth
rigid block {{ mass = {m:?} kg, inertia = (0.01, 0.01, 0.01) kg*m^2, at = (0.5, 0, 0) m }}
joint rail = prismatic(earth, block) {{
    axis = x, spring = {k:?} N/m, damper = {c:?} N*s/m, force = {f:?} N
}}
output x = rail.displacement, v = rail.speed
solve hht {{ dt = 1 ms, until = 1 s }}
"
    );
    let x = |t: f64| {
        xs * (1.0 - (-zeta * w * t).exp() * ((wd * t).cos() + zeta * w / wd * (wd * t).sin()))
    };
    let v = |t: f64| xs * (-zeta * w * t).exp() * w * w / wd * (wd * t).sin();
    let mut errors = Vec::new();
    for dt in [4e-3, 2e-3, 1e-3] {
        let tr = run("slider.mbd", &text, dt, 3.0);
        let e = errors2(&tr, ("x", &x), ("v", &v));
        eprintln!(
            "damped slider dt {dt}: x {:.3e} m (of {xs}), v {:.3e} m/s",
            e[0], e[1]
        );
        errors.push(e);
    }
    within(
        "damped slider at dt = 1 ms: displacement [m]",
        errors[2][0],
        6e-6,
    ); // measured 1.9e-6
    within(
        "damped slider at dt = 1 ms: speed [m/s]",
        errors[2][1],
        6e-5,
    ); // measured 1.9e-5
    assert_order("damped slider displacement", &column(&errors, 0), 2.0);
    assert_order("damped slider speed", &column(&errors, 1), 2.0);
}

/// Standalone dampers on point masses moving along their lines: `lone` to a ground point, whose
/// speed decays as `e^(-c t / m)`, and a pair joined by one, whose relative speed decays at the
/// reduced mass, `e^(-c t / mu)`, while their common velocity stays.
#[test]
fn standalone_dampers_slow_point_masses_exponentially() {
    let (m, m2, m3, c) = (1.5, 1.0, 3.0, 3.0);
    let (v0, v2, v3) = (0.8, -0.2, 0.6);
    let text = format!(
        "model drag
ground earth
point_mass lone {{ mass = {m:?} kg, at = (1, 0, 0) m, velocity = ({v0:?}, 0, 0) m/s }}
damper anchor(earth, lone) {{ damping = {c:?} N*s/m }}
point_mass left {{ mass = {m2:?} kg, at = (0, 2, 0) m, velocity = ({v2:?}, 0, 0) m/s }}
point_mass right {{ mass = {m3:?} kg, at = (1, 2, 0) m, velocity = ({v3:?}, 0, 0) m/s }}
damper link(left, right) {{ damping = {c:?} N*s/m }}
output x = lone.position.x, v = lone.velocity.x, y = lone.position.y
output xl = left.position.x, xr = right.position.x, vl = left.velocity.x, vr = right.velocity.x
solve hht {{ dt = 1 ms, until = 1 s }}
"
    );
    let mu = m2 * m3 / (m2 + m3);
    let (vg, dv) = ((m2 * v2 + m3 * v3) / (m2 + m3), v3 - v2);
    let x = |t: f64| 1.0 + m * v0 / c * (1.0 - (-c * t / m).exp());
    let v = |t: f64| v0 * (-c * t / m).exp();
    let gap = |t: f64| 1.0 + mu * dv / c * (1.0 - (-c * t / mu).exp());
    let mut errors = Vec::new();
    for dt in [4e-3, 2e-3, 1e-3] {
        let tr = run("drag.mbd", &text, dt, 2.0);
        let [ex, ev] = errors2(&tr, ("x", &x), ("v", &v));
        let t = tr.col("t");
        let (xl, xr, vl, vr) = (tr.col("xl"), tr.col("xr"), tr.col("vl"), tr.col("vr"));
        let e_gap = max_abs((0..t.len()).map(|k| xr[k] - xl[k] - gap(t[k])));
        let e_mom = max_abs((0..t.len()).map(|k| (m2 * vl[k] + m3 * vr[k]) / (m2 + m3) - vg));
        let e_y = max_abs(tr.col("y"));
        eprintln!(
            "dampers dt {dt}: lone x {ex:.3e} m, v {ev:.3e} m/s, y {e_y:.3e}; pair gap {e_gap:.3e} m, momentum {e_mom:.3e} m/s"
        );
        errors.push([ex, ev, e_gap, e_mom, e_y]);
    }
    let [ex, ev, e_gap, e_mom, e_y] = errors[2];
    within("damper to ground at dt = 1 ms: position [m]", ex, 2.2e-7); // measured 7.5e-8
    within("damper to ground at dt = 1 ms: speed [m/s]", ev, 3.8e-7); // measured 1.3e-7
    within("damper to ground: no motion off its line [m]", e_y, 1e-15); // measured 0
    within("damper pair at dt = 1 ms: gap [m]", e_gap, 4.5e-7); // measured 1.5e-7
    within("damper pair: common velocity [m/s]", e_mom, 3.4e-11); // measured 1.1e-11
    assert_order("damper to ground position", &column(&errors, 0), 2.0);
    assert_order("damper pair gap", &column(&errors, 2), 2.0);
}

/// A rod spinning on a revolute joint with a rotational `damper`, and another braked by a
/// `torsional_damper` to ground: both rates decay as `e^(-c t / J)`, `J = m l^2 / 3`, and the
/// angles approach `J w0 / c`.
#[test]
fn rotational_dampers_slow_a_spinning_rod_exponentially() {
    let (m, l, c, w0) = (1.2, 1.0, 0.2, 2.0);
    let j = m * l * l / 3.0;
    let text = format!(
        "model brakes
ground earth
rigid_rod a {{ from = (0, 0, 0) m, to = ({l:?}, 0, 0) m, mass = {m:?} kg }}
joint pa = revolute(earth, a.start) {{ axis = z, damper = {c:?} N*m*s/rad }}
rigid_rod b {{ from = (0, 2, 0) m, to = ({l:?}, 2, 0) m, mass = {m:?} kg }}
joint pb = revolute(earth @ (0, 2, 0) m, b.start) {{ axis = z }}
torsional_damper brake(earth @ (0, 2, 0) m, b.start) {{ damping = {c:?} N*m*s/rad }}
initial spin of a = {w0:?} rad/s about z
initial spin of b = {w0:?} rad/s about z through (0, 2, 0) m
output qa = pa.angle, wa = pa.rate, qb = pb.angle, wb = pb.rate
solve hht {{ dt = 1 ms, until = 1 s }}
"
    );
    let q = |t: f64| j * w0 / c * (1.0 - (-c * t / j).exp());
    let w = |t: f64| w0 * (-c * t / j).exp();
    let mut errors = Vec::new();
    for dt in [4e-3, 2e-3, 1e-3] {
        let tr = run("brakes.mbd", &text, dt, 4.0);
        let [eqa, ewa] = errors2(&tr, ("qa", &q), ("wa", &w));
        let [eqb, ewb] = errors2(&tr, ("qb", &q), ("wb", &w));
        eprintln!(
            "rotational dampers dt {dt}: joint damper angle {eqa:.3e} rate {ewa:.3e}; torsional damper angle {eqb:.3e} rate {ewb:.3e}"
        );
        errors.push([eqa, ewa, eqb, ewb]);
    }
    let [eqa, ewa, eqb, ewb] = errors[2];
    within("revolute damper at dt = 1 ms: angle [rad]", eqa, 1.4e-7); // measured 4.7e-8
    within("revolute damper at dt = 1 ms: rate [rad/s]", ewa, 6e-8); // measured 2.0e-8
    within("torsional damper at dt = 1 ms: angle [rad]", eqb, 1.4e-7); // measured 4.7e-8
    within("torsional damper at dt = 1 ms: rate [rad/s]", ewb, 6e-8); // measured 2.0e-8
    assert_order("revolute damper angle", &column(&errors, 0), 2.0);
    assert_order("torsional damper angle", &column(&errors, 2), 2.0);
}

/// `stdlib::rotor` turning at a prescribed Omega, blade 0 kicked in lag: with the hub held at
/// constant speed the blades are independent, and a uniform rod of mass m and length l hinged
/// at e from the centre obeys `J z'' + c z' + k z + m Omega^2 e (l / 2) sin z = 0`,
/// `J = m l^2 / 3` (the centrifugal moment about the hinge; Coriolis forces act along the
/// blade). Its lag angle against that equation, at second order; blade 1 stays at zero lag.
#[test]
fn the_rotor_lag_damper_follows_the_reduced_lag_equation() {
    let (e, l, m, k, c, omega, kick) = (0.3, 2.7, 20.0, 14.0, 40.0, 9.26, 0.5);
    let j = m * l * l / 3.0;
    let text = format!(
        "model lag
use stdlib::rotor::lag_hinged_rotor
ground earth
rotor = lag_hinged_rotor(hub = earth, blades = 3, hinge_offset = {e:?} m, blade_length = {l:?} m,
                         blade_mass = {m:?} kg, lag_spring = {k:?} N*m/rad,
                         lag_damper = {c:?} N*m*s/rad, speed = {omega:?} rad/s)
initial spin of rotor = {omega:?} rad/s about z
initial spin of rotor.blade[0] = {kick:?} rad/s about z through ({e:?}, 0, 0) m
output z0 = rotor.lag[0].angle, z1 = rotor.lag[1].angle
solve hht {{ dt = 1 ms, until = 1 s }}
"
    );
    let f = move |_t: f64, y: &[f64; 2]| {
        let moment = -c * y[1] - k * y[0] - m * omega * omega * e * l / 2.0 * y[0].sin();
        [y[1], moment / j]
    };
    let mut errors = Vec::new();
    for dt in [4e-3, 2e-3, 1e-3] {
        let tr = run("lag.mbd", &text, dt, 5.0);
        let t = tr.col("t");
        let refs = dopri(f, 0.0, [0.0, kick], &t, 1e-12, 1e-14);
        let z0 = tr.col("z0");
        let err = max_abs((0..t.len()).map(|i| z0[i] - refs[i][0]));
        let peak = max_abs(refs.iter().map(|r| r[0]));
        let other = max_abs(tr.col("z1"));
        eprintln!(
            "rotor lag dt {dt}: blade 0 {err:.3e} rad (peak {peak:.3}), blade 1 {other:.3e} rad"
        );
        errors.push([err, other, peak]);
    }
    // The kick moved blade 0 (a peak lag of 0.112 rad), against which its error is measured:
    above(
        "rotor lag: peak lag of the kicked blade [rad]",
        errors[2][2],
        0.037,
    ); // measured 0.112
    within(
        "rotor lag damper at dt = 1 ms: blade 0 lag [rad]",
        errors[2][0],
        2.8e-6,
    ); // measured 9.3e-7
    within(
        "rotor lag damper: undisturbed blade 1 [rad]",
        errors[2][1],
        4e-12,
    ); // measured 1.3e-12
    assert_order("rotor lag angle", &column(&errors, 0), 2.0);
}
