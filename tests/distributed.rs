//! Distributed loads along beams (issue 23, item 3): forces and torques per length, fixed in
//! the inertial frame or following the section, functions of the time and of the span.
//! Validated against the Euler-Bernoulli and Timoshenko closed forms of the loaded
//! cantilever (uniform and triangular loads, small loads: the part linear in the load), and
//! at large deflection against the planar Reissner beam integrated here (a shooting method on
//! RK4, 4,000 steps) for a fixed and a follower load, and the exact elastica of a cantilever
//! under a uniform torque per length.

use crate::common::{simulate_text_with, within};
use mbd::settings::Request;

/// A cantilever along +x (length 1 m) clamped at the root, `elements` cubic elements, bending
/// in the xy plane (EI3, GA2); `load` is the load's declaration, ramped by `t` over `steps`
/// load steps. Returns the tip's (x, y) and the midspan's y.
fn cantilever(load: &str, elements: usize, ga: f64, steps: usize) -> (f64, f64, f64) {
    let text = format!(
        r#"model loaded "A cantilever under a distributed load"
section s {{
    EA = 1e6 N, GA2 = {ga} N, GA3 = {ga} N
    GJ = 50 N*m^2, EI2 = 10 N*m^2, EI3 = 10 N*m^2
    mass_per_length = 1 kg/m
}}
ground earth
beam b {{ from = (0, 0, 0) m, to = (1, 0, 0) m, section = s, elements = {elements}, order = 4 }}
joint clamp = fixed(earth, b.start)
{load}
output x = b.end.position.x, y = b.end.position.y, mid = b.node[{mid}].position.y
solve static {{ steps = {steps}, until = 1 s }}
"#,
        mid = elements * 3 / 2
    );
    let t = simulate_text_with("loaded.mbd", &text, &[], Request::default())
        .map_err(|(_, m)| m)
        .expect("the static run");
    let last = |c: &str| *t.col(c).last().expect("row");
    (last("x"), last("y"), last("mid"))
}

/// The part of the tip's and the midspan's deflection linear in the load `q` (N/m), the load
/// written by `load(q)`: `2 d(q) - d(2 q) / 2` cancels the part of second order.
fn linear(load: &dyn Fn(f64) -> String, q: f64, elements: usize, ga: f64) -> (f64, f64) {
    let (_, y1, m1) = cantilever(&load(q), elements, ga, 1);
    let (_, y2, m2) = cantilever(&load(2.0 * q), elements, ga, 1);
    (2.0 * y1 - y2 / 2.0, 2.0 * m1 - m2 / 2.0)
}

/// A load case: its name, its declaration for a load `q`, the tip's and the midspan's closed
/// forms.
type Case<'a> = (&'a str, &'a dyn Fn(f64) -> String, f64, f64);

/// Uniform and triangular loads on the Euler-Bernoulli (GA = 1e12 N) and the Timoshenko
/// (GA = 2,000 N: shear adds a fifth to the tip's deflection) cantilever, against the closed
/// forms (L = 1 m, EI = 10 N*m^2): uniform `q`, tip `q L^4 / (8 EI) + q L^2 / (2 GA)`, midspan
/// `17 q L^4 / (384 EI) + 3 q L^2 / (8 GA)`; triangular `q s / L`, tip
/// `11 q L^4 / (120 EI) + q L^2 / (3 GA)`, midspan `121 q L^4 / (3840 EI) + 11 q L^2 / (48 GA)`.
/// The cubic element with its consistent nodal loads is exact at the nodes for these
/// polynomial loads: measured, relative, 2.5e-12 (tip) and 2.1e-12 (midspan) for every mesh
/// from 2 to 8 elements, the round-off of the load steps' Newton solution.
#[test]
fn a_loaded_cantilever_deflects_as_the_closed_forms_say() {
    let (ei, l, q) = (10.0, 1.0f64, 1e-4);
    let uniform = |q: f64| format!("distributed_force w on b = (0, {q} N/m * t / 1 s, 0)");
    let triangle =
        |q: f64| format!("distributed_force w on b = (0, {q} N/m * span / 1 m * t / 1 s, 0)");
    for (ga, model) in [(1e12, "Euler-Bernoulli"), (2000.0, "Timoshenko")] {
        let cases: [Case; 2] = [
            (
                "uniform",
                &uniform,
                q * l.powi(4) / (8.0 * ei) + q * l * l / (2.0 * ga),
                17.0 * q * l.powi(4) / (384.0 * ei) + 3.0 * q * l * l / (8.0 * ga),
            ),
            (
                "triangular",
                &triangle,
                11.0 * q * l.powi(4) / (120.0 * ei) + q * l * l / (3.0 * ga),
                121.0 * q * l.powi(4) / (3840.0 * ei) + 11.0 * q * l * l / (48.0 * ga),
            ),
        ];
        for (what, load, tip, mid) in cases {
            for n in [2, 8] {
                let (y, m) = linear(load, q, n, ga);
                let error = ((y - tip).abs() / tip).max((m - mid).abs() / mid);
                within(
                    &format!("{model} cantilever, {what} load, {n} elements"),
                    error,
                    1e-11,
                );
            }
        }
    }
}

/// A load that no polynomial reproduces, `q cos(pi s / 2 L)`, converges at the element's
/// order: the tip's deflection against `int M(x) (L - x) / EI dx + int V / GA dx` (Simpson's
/// rule, 2,000 intervals), `V = q (2L / pi)(1 - sin(pi x / 2L))`, `M = int_x^L V`. Measured,
/// relative, Timoshenko (GA = 2,000 N), 1, 2, 4 cubic elements: 3.1e-6, 1.0e-8, 3.9e-11,
/// order 8.1 (the nodal superconvergence of the cubic element).
#[test]
fn a_cosine_load_converges_at_the_elements_order() {
    let (ei, ga, l, q) = (10.0, 2000.0, 1.0f64, 1e-4);
    let k = std::f64::consts::PI / (2.0 * l);
    let shear = |x: f64| q / k * (1.0 - (k * x).sin());
    let moment = |x: f64| q / k * ((l - x) - (k * x).cos() / k);
    let intervals = 2000;
    let h = l / intervals as f64;
    let simpson = |f: &dyn Fn(f64) -> f64| {
        (0..=intervals)
            .map(|i| {
                let w = match i {
                    0 => 1.0,
                    i if i == intervals => 1.0,
                    i if i % 2 == 1 => 4.0,
                    _ => 2.0,
                };
                w * f(i as f64 * h)
            })
            .sum::<f64>()
            * h
            / 3.0
    };
    let tip = simpson(&|x| moment(x) * (l - x) / ei) + simpson(&|x| shear(x) / ga);
    let load = |q: f64| {
        format!("distributed_force w on b = (0, {q} N/m * cos(pi * span / 2 m) * t / 1 s, 0)")
    };
    let errors: Vec<f64> = [1, 2, 4]
        .iter()
        .map(|&n| (linear(&load, q, n, ga).0 - tip).abs() / tip)
        .collect();
    within(
        "cosine load, 4 cubic elements: tip against the closed form",
        errors[2],
        1.2e-10,
    );
    let order = (errors[1] / errors[2]).log2();
    assert!(
        (7.0..9.0).contains(&order),
        "order {order} from 2 to 4 elements ({errors:?})"
    );
}

/// The planar Reissner beam (extensible, shear-deformable) clamped at s = 0, free at L,
/// under a force per length `q` along the section's axis 2 (`follower`) or along +y, and a
/// torque per length `c` about z: `n' = -f`, `m' = -(x' x n) - c`, `theta' = m / EI`,
/// `x' = (1 + N / EA) e1 + (V / GA) e2`. Integrated by RK4 from the free end (n = 0, m = 0,
/// theta = theta_L) to the root, theta_L shot until theta(0) = 0. Returns the tip's (x, y).
fn reissner(q: f64, c: f64, follower: bool, (ea, ga, ei): (f64, f64, f64)) -> (f64, f64) {
    let l = 1.0;
    let steps = 4000;
    // State: n_x, n_y, m, theta, x, y.
    let rate = |s: &[f64; 6]| -> [f64; 6] {
        let (ct, st) = (s[3].cos(), s[3].sin());
        let f = if follower {
            [-q * st, q * ct]
        } else {
            [0.0, q]
        };
        let (nn, vv) = (s[0] * ct + s[1] * st, -s[0] * st + s[1] * ct);
        let (eps, gam) = (nn / ea, vv / ga);
        let dx = [(1.0 + eps) * ct - gam * st, (1.0 + eps) * st + gam * ct];
        [
            -f[0],
            -f[1],
            -(dx[0] * s[1] - dx[1] * s[0]) - c,
            s[2] / ei,
            dx[0],
            dx[1],
        ]
    };
    let root = |theta_l: f64| -> [f64; 6] {
        let mut s = [0.0, 0.0, 0.0, theta_l, 0.0, 0.0];
        let h = -l / steps as f64;
        for _ in 0..steps {
            let k1 = rate(&s);
            let at = |k: &[f64; 6], a: f64| std::array::from_fn::<f64, 6, _>(|i| s[i] + a * k[i]);
            let k2 = rate(&at(&k1, h / 2.0));
            let k3 = rate(&at(&k2, h / 2.0));
            let k4 = rate(&at(&k3, h));
            for i in 0..6 {
                s[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        s
    };
    // Secant iterations on theta(0)(theta_L) = 0.
    let (mut a, mut b) = (0.0, 0.1);
    let (mut fa, mut fb) = (root(a)[3], root(b)[3]);
    for _ in 0..60 {
        if (fb - fa).abs() < 1e-300 || fb.abs() < 1e-15 {
            break;
        }
        let next = b - fb * (b - a) / (fb - fa);
        (a, fa) = (b, fb);
        b = next;
        fb = root(b)[3];
    }
    let s = root(b);
    assert!(
        s[3].abs() < 1e-12,
        "shooting did not converge: theta(0) = {}",
        s[3]
    );
    // Positions were integrated from the tip at the origin: the tip relative to the root.
    (-s[4], -s[5])
}

/// Large deflection: a uniform force per length fixed along +y, the same following the
/// section, and a uniform torque per length about z (planar: the same fixed or following),
/// turning the tip by 0.4 to 0.5 rad, in 10 load steps with 4 and 8 cubic elements, against
/// the planar Reissner beam. Measured (tip position error / L) with 4 and 8 elements: fixed
/// force 3.0e-7, 4.6e-9; follower force 1.5e-7, 2.2e-9; torque (fixed or follower) 8.6e-9,
/// 1.3e-10: order 6.0 (the follower force's tip lands 0.024 m from the fixed one's).
#[test]
fn a_cantilever_bends_far_under_fixed_and_follower_loads_as_the_reissner_beam_says() {
    let props = (1e6, 2000.0, 10.0);
    let cases = [
        (
            "fixed force",
            "distributed_force w on b = (0, 30 N/m * t / 1 s, 0)",
            30.0,
            0.0,
            false,
            1.4e-8,
        ),
        (
            "follower force",
            "distributed_force w on b = (0, 30 N/m * t / 1 s, 0) follower",
            30.0,
            0.0,
            true,
            7e-9,
        ),
        (
            "torque",
            "distributed_torque c on b = (0, 0, 12 N*m/m * t / 1 s)",
            0.0,
            12.0,
            false,
            4e-10,
        ),
        (
            "follower torque",
            "distributed_torque c on b = (0, 0, 12 N*m/m * t / 1 s) follower",
            0.0,
            12.0,
            true,
            4e-10,
        ),
    ];
    for (what, load, q, c, follower, bound) in cases {
        let (xr, yr) = reissner(q, c, follower, props);
        let error = |n: usize| {
            let (x, y, _) = cantilever(load, n, props.1, 10);
            ((x - xr).powi(2) + (y - yr).powi(2)).sqrt()
        };
        let (e4, e8) = (error(4), error(8));
        within(
            &format!("{what} along a cantilever, 8 elements: tip against Reissner"),
            e8,
            bound,
        );
        let order = (e4 / e8).log2();
        assert!(
            (5.5..6.5).contains(&order),
            "{what}: order {order} from 4 to 8 elements"
        );
    }
}
