//! Attachments between beam nodes (issue 23, item 4): a load, a spring and joints at a point
//! of an elastic beam that is not a node, interpolated with the element's shape functions.
//! Validated against the Euler-Bernoulli closed forms of the cantilever (a force at a = 0.75 m
//! of L = 2 m; a grounded spring there; a pin there, the propped cantilever; a clamp there
//! holding a free beam), each on meshes where the point falls between nodes and, as the
//! reference the issue names, on a mesh where the same point is a node.

use crate::common::{simulate_text_with, within};
use mbd::settings::Request;

const L: f64 = 2.0;
const A: f64 = 0.75;
const EI: f64 = 10.0;
const P: f64 = 1e-5;
const K: f64 = 50.0;

/// A beam along +x (length 2 m, EI 10 N*m^2 in the xy plane, shear and axial rigid), `n`
/// cubic elements, its tip pushed along +y by `p` in one load step; `attach` declares what
/// holds it, with `AT` standing for the attachment's marker. Returns the tip's y.
fn tip(attach: &str, n: usize, p: f64, at: &str) -> f64 {
    let attach = attach.replace("AT", at).replace("LOAD", &format!("{p} N"));
    let text = format!(
        r#"model between "A beam held or loaded between its nodes"
section s {{
    EA = 1e9 N, GA2 = 1e12 N, GA3 = 1e12 N
    GJ = 50 N*m^2, EI2 = 10 N*m^2, EI3 = 10 N*m^2
    mass_per_length = 1 kg/m
}}
ground earth
beam b {{ from = (0, 0, 0) m, to = (2, 0, 0) m, section = s, elements = {n}, order = 4 }}
{attach}
force push on b.end = (0, {p} N * t / 1 s, 0)
output y = b.end.position.y
solve static {{ steps = 1, until = 1 s }}
"#
    );
    let t = simulate_text_with("between.mbd", &text, &[], Request::default())
        .map_err(|(_, m)| m)
        .expect("the static run");
    *t.col("y").last().expect("row")
}

/// The part of the tip's deflection linear in the load.
fn linear(attach: &str, n: usize, at: &str) -> f64 {
    2.0 * tip(attach, n, P, at) - tip(attach, n, 2.0 * P, at) / 2.0
}

/// The tip deflections of the Euler-Bernoulli cantilever (clamped at 0, tip force P) with
/// the point a = 0.75 m loaded by a second force P, held by a grounded spring of stiffness K
/// (along y), pinned (a distance joint to a ground point 100 m away along -y holds y alone),
/// and, the root free, clamped there alone: the declarations (`AT` the marker, `LOAD` the
/// force) and the closed form. A unit force at x deflects the tip by `x^2 (3L - x) / 6EI`
/// and a unit force at a deflects a by `a^3 / 3EI`; the spring's and the pin's reactions
/// follow from the deflection at a.
/// Each with its bound on the relative error with 28 elements and the order it converges
/// at (none: exact at the nodes).
fn closed_forms() -> Vec<(&'static str, String, f64, f64, Option<f64>)> {
    let tip_of = |x: f64| x * x * (3.0 * L - x) / (6.0 * EI);
    let (tip_a, a_a) = (tip_of(A), A.powi(3) / (3.0 * EI));
    let free = P * L.powi(3) / (3.0 * EI);
    let spring = K * P * tip_a / (1.0 + K * a_a);
    let pin = P * tip_a / a_a;
    let root = "joint clamp = fixed(earth, b.start)";
    vec![
        (
            "force",
            format!("{root}\nforce extra on AT = (0, LOAD * t / 1 s, 0)"),
            free + P * tip_a,
            4e-11,
            None,
        ),
        (
            "spring",
            format!("{root}\nspring hold(earth @ (0.75, -1, 0) m, AT) {{ stiffness = {K} N/m }}"),
            free - spring * tip_a,
            2.4e-6,
            Some(3.0),
        ),
        (
            "pin",
            format!("{root}\njoint prop = distance(earth @ (0.75, -100, 0) m, AT)"),
            free - pin * tip_a,
            3e-5,
            Some(3.0),
        ),
        (
            "clamp",
            "joint hold = fixed(earth @ (0.75, 0, 0) m, AT)".to_string(),
            P * (L - A).powi(3) / (3.0 * EI),
            3.2e-2,
            Some(1.0),
        ),
    ]
}

/// Each attachment at a = 0.75 m: with 8 cubic elements the point is node 9 (the reference
/// mesh); with 4, 12, 20 and 28 it lies at the middle of an element (`b.at(0.75 m)`).
/// Measured, relative to the closed form (the load small, its response's linear part):
/// on the node, 1.3e-11 to 1.1e-10 (the Newton tolerance); between nodes, the force 1.3e-11
/// on every mesh (the cubic element's consistent load is exact at the nodes); the spring and
/// the pin at order 3.00
/// (a force there kinks the curvature inside the element), 7.9e-7 and 9.8e-6 with 28
/// elements; the clamp at order 1.00 (its moment makes the curvature jump inside the element),
/// 1.1e-2 with 28 elements: a joint that carries a moment converges fastest with a node there.
#[test]
fn attachments_between_nodes_match_the_same_point_made_a_node_and_the_closed_forms() {
    let meshes = [4.0f64, 12.0, 20.0, 28.0];
    for (what, attach, exact, bound, expected) in closed_forms() {
        let node = linear(&attach, 8, "b.node[9]");
        let errors: Vec<f64> = meshes
            .iter()
            .map(|&n| (linear(&attach, n as usize, "b.at(0.75 m)") - exact).abs() / exact.abs())
            .collect();
        let order = (errors[2] / errors[3]).ln() / (meshes[3] / meshes[2]).ln();
        within(
            &format!("{what} at a node: tip against the closed form"),
            (node - exact).abs() / exact.abs(),
            2e-10,
        );
        within(
            &format!("{what} between nodes, 28 elements: tip against the closed form"),
            errors[3],
            bound,
        );
        if let Some(p) = expected {
            assert!(
                (order - p).abs() < 0.3,
                "{what}: order {order} from 20 to 28 elements ({errors:?})"
            );
        } else {
            assert!(errors.iter().all(|&e| e < bound), "{what}: {errors:?}");
        }
    }
}

/// A stiff beam (1 m, 1 kg/m) hung by a revolute joint at a = 0.25 m, between the nodes of
/// its 3 cubic elements, released horizontal under gravity: it swings through the bottom
/// as the compound pendulum `I phi'' = -m g d cos(phi)`, `d = 0.25 m`,
/// `I = m L^2 / 12 + m d^2`, integrated here by RK4 (20,000 steps). The joint's rotation
/// rows at large rotation, through the element's interpolated triad. Measured, the angle
/// over 1 s (it swings to -3.06 rad) against the reference (HHT, dt 1 ms): 2.2e-5 rad at
/// most, 3.7 Newton iterations a step (3.8 with a node at the pivot).
#[test]
fn a_beam_hung_between_its_nodes_swings_as_the_compound_pendulum() {
    let text = r#"model hung "A stiff beam on a pivot between its nodes"
gravity = (0, -9.81, 0) m/s^2
section s {
    EA = 1e9 N, GA2 = 1e9 N, GA3 = 1e9 N
    GJ = 1e6 N*m^2, EI2 = 1e6 N*m^2, EI3 = 1e6 N*m^2
    mass_per_length = 1 kg/m
}
ground earth
beam b { from = (-0.25, 0, 0) m, to = (0.75, 0, 0) m, section = s, elements = 3, order = 4 }
joint pivot = revolute(earth, b.at(0.25 m)) { axis = z }
output phi = pivot.angle
solve hht { dt = 1 ms, until = 1 s }
"#;
    let t = simulate_text_with("hung.mbd", text, &[], Request::default())
        .map_err(|(_, m)| m)
        .expect("the run");
    let (m, d, g) = (1.0, 0.25, 9.81);
    let inertia = m / 12.0 + m * d * d;
    let rate = |s: [f64; 2]| [s[1], -m * g * d * s[0].cos() / inertia];
    let steps = 20_000;
    let h = 1.0 / steps as f64;
    let mut s = [0.0, 0.0];
    let mut reference = vec![0.0];
    for k in 1..=steps {
        let k1 = rate(s);
        let k2 = rate([s[0] + h / 2.0 * k1[0], s[1] + h / 2.0 * k1[1]]);
        let k3 = rate([s[0] + h / 2.0 * k2[0], s[1] + h / 2.0 * k2[1]]);
        let k4 = rate([s[0] + h * k3[0], s[1] + h * k3[1]]);
        for i in 0..2 {
            s[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        if k % 20 == 0 {
            reference.push(s[0]);
        }
    }
    let phi = t.col("phi");
    let error = phi
        .iter()
        .zip(&reference)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert_eq!(phi.len(), reference.len());
    within(
        "beam hung between its nodes: angle against the compound pendulum",
        error,
        6.5e-5,
    );
}

/// A concentrated mass between nodes (its mass consistent with the element's shape functions,
/// its rotary inertia lumped on the element's nodes): on a nearly massless cantilever under
/// gravity it weighs on the beam at its point, against the closed form of a force `m g` at
/// a = 0.75 m (exact at the nodes); on a free beam pushed along its axis it adds its mass,
/// `x = t^2 F / (2 (m_beam + m))`; and twisted about the beam's axis by a torque it adds its
/// polar inertia, `w = t T / (J_beam + J)`. Measured: the tip under gravity 1.5e-11 from the
/// closed form, the same with the mass on a node (8 elements) and between nodes (4); the push
/// 7.2e-7 (the axial stretch of a beam of EA 1e9 N), the twist 1.9e-9.
#[test]
fn a_concentrated_mass_between_nodes_weighs_and_accelerates_where_it_is() {
    let (m, g) = (2.0, 1e-5);
    let text = |extra: &str, n: usize, at: &str, mpl: f64| {
        format!(
            r#"model massive "A beam with a mass between its nodes"
gravity = (0, -{g}, 0) m/s^2
section s {{
    EA = 1e9 N, GA2 = 1e12 N, GA3 = 1e12 N
    GJ = 1e6 N*m^2, EI2 = 10 N*m^2, EI3 = 10 N*m^2
    mass_per_length = {mpl} kg/m, polar = 0.01 kg*m
}}
ground earth
beam b {{ from = (0, 0, 0) m, to = (2, 0, 0) m, section = s, elements = {n}, order = 4 }}
concentrated_mass bob on {at} {{ mass = {m} kg, inertia = (0.1, 0.2, 0.3) kg*m^2 }}
{extra}
output y = b.end.position.y, x = b.end.position.x, phi = b.end.angular_velocity.x
"#
        )
    };
    let run = |text: String| {
        simulate_text_with("massive.mbd", &text, &[], Request::default())
            .map_err(|(_, m)| m)
            .expect("the run")
    };
    let statics = "joint clamp = fixed(earth, b.start)\nsolve static { steps = 1, until = 1 s }";
    // The mass's weight at a, and the beam's own (1e-6 kg/m) along it.
    let exact = -(m * g * A * A * (3.0 * L - A) / (6.0 * EI) + 1e-6 * g * L.powi(4) / (8.0 * EI));
    let tip = |n: usize, at: &str| {
        let t = run(text(statics, n, at, 1e-6));
        (t.col("y").last().expect("row") - exact).abs() / exact.abs()
    };
    let (node, between) = (tip(8, "b.node[9]"), tip(4, "b.at(0.75 m)"));
    // Pushed along x by 1 N, twisted about x by 1 N*m, for 0.1 s from rest.
    let push = "force push on b.end = (1 N, 0, 0)\ntorque twist on b.end = (1 N*m, 0, 0)\n\
                solve hht { dt = 1 ms, until = 0.1 s }";
    let t = run(text(push, 4, "b.at(0.75 m)", 1.0));
    let (mass, polar) = (m + 2.0, 0.1 + 0.02);
    let moved = t.col("x").last().expect("row") - 2.0;
    let accel = (moved - 0.01 / (2.0 * mass)).abs() / (0.01 / (2.0 * mass));
    let spin = (t.col("phi").last().expect("row") - 0.1 / polar).abs() / (0.1 / polar);
    within(
        "concentrated mass on a node: weight against the closed form",
        node,
        5e-11,
    );
    within(
        "concentrated mass between nodes: weight against the closed form",
        between,
        5e-11,
    );
    within(
        "concentrated mass between nodes: pushed free beam",
        accel,
        2.2e-6,
    );
    within(
        "concentrated mass between nodes: twisted free beam",
        spin,
        6e-9,
    );
}
