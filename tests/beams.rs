//! Validation of the geometrically exact beams (issue 5): statics against closed forms and a
//! shooting solution of the elastica, modes against Euler-Bernoulli and the published rotating
//! cantilever, and dynamics: the rotating beam (P1), the two-bar mechanism with beams (P3, P4).

use crate::common::{above, within};
use crate::common::{read, simulate, Trace};
use crate::reference::dopri;
use mbd::settings::Request;
use std::f64::consts::PI;

fn last(t: &Trace, c: &str) -> f64 {
    *t.col(c).last().expect("rows")
}

fn peak(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

#[test]
fn cantilever_rolls_into_the_exact_arcs_and_a_full_circle() {
    // M = 2 pi EI / L in 10 load steps: at load fraction f the beam is an arc of curvature
    // kappa = 2 pi f / L, tip at (sin(kappa L), 1 - cos(kappa L)) / kappa.
    let (l, ei): (f64, f64) = (1.0, 100.0);
    let m = 2.0 * PI * ei / l;
    let t = simulate(
        "models/cantilever.mbd",
        &[&format!("M={m}")],
        Request::default(),
    );
    let (ts, xs, ys, zs) = (t.col("t"), t.col("x"), t.col("y"), t.col("z"));
    let mut worst = 0.0f64;
    for k in 1..ts.len() {
        let kappa = 2.0 * PI * ts[k] / l;
        let (xe, ye) = ((kappa * l).sin() / kappa, (1.0 - (kappa * l).cos()) / kappa);
        worst = worst.max(((xs[k] - xe).powi(2) + (ys[k] - ye).powi(2) + zs[k].powi(2)).sqrt());
    }
    // 10 quadratic elements: measured 3.6e-6 m (the arc is interpolated by parabolas).
    within(&format!("largest tip error {worst:e} m"), worst, 2e-5 * l);
    let closed = (last(&t, "x").powi(2) + last(&t, "y").powi(2)).sqrt();
    within(
        &format!("the circle does not close: tip {closed:e} m from the root"),
        closed,
        1e-5 * l,
    );
}

#[test]
fn small_tip_force_gives_the_linear_deflection() {
    let (l, ei, p): (f64, f64, f64) = (1.0, 100.0, 1e-3);
    let t = simulate(
        "models/cantilever.mbd",
        &[&format!("P={p}")],
        Request::default(),
    );
    // Timoshenko: bending P L^3 / (3 EI) plus shear P L / GA (GA = 1e7 N, 3e-5 of the total).
    let exact = -p * l.powi(3) / (3.0 * ei) - p * l / 1e7;
    let rel = (last(&t, "z") - exact).abs() / exact.abs();
    within(
        &format!("tip deflection {} vs {exact}: {rel:e}", last(&t, "z")),
        rel,
        4e-11,
    ); // measured 1.1e-11
}

/// The elastica of a cantilever under a tip force of fixed direction, by shooting:
/// `theta'' = -(P/EI) cos(theta)`, `theta(0) = 0`, `theta'(L) = 0`; returns the tip
/// `(x, -z)` (horizontal position, deflection).
fn elastica(alpha: f64) -> (f64, f64) {
    // Unit length and EI; alpha = P L^2 / EI. State (theta, theta', x, y) in s.
    let tip = |k0: f64| {
        dopri(
            |_, y: &[f64; 4]| [y[1], -alpha * y[0].cos(), y[0].cos(), y[0].sin()],
            0.0,
            [0.0, k0, 0.0, 0.0],
            &[1.0],
            1e-12,
            1e-14,
        )[0]
    };
    // theta'(0) = alpha cos-weighted moment: bisect on the end condition theta'(1) = 0.
    let (mut a, mut b) = (0.0, alpha);
    for _ in 0..100 {
        let c = 0.5 * (a + b);
        if tip(c)[1] > 0.0 {
            b = c;
        } else {
            a = c;
        }
    }
    let y = tip(0.5 * (a + b));
    (y[2], y[3])
}

#[test]
fn large_tip_force_matches_the_elastica() {
    let (l, ei): (f64, f64) = (1.0, 100.0);
    for alpha in [1.0, 3.0, 10.0] {
        let (xe, de) = elastica(alpha);
        let p = alpha * ei / (l * l);
        let t = simulate(
            "models/cantilever.mbd",
            &[&format!("P={p}")],
            Request::default(),
        );
        let (x, d) = (last(&t, "x"), -last(&t, "z"));
        let err = ((x - xe).powi(2) + (d - de).powi(2)).sqrt();
        // The elastica is inextensible; the beam stretches by up to P/EA (1e-4 at alpha = 10,
        // EA = 1e7 N). Measured at alpha = 10: 8.8e-5 m.
        let bound = 2e-5 * l + 1.5 * p / 1e7 * l;
        assert!(
            err < bound,
            "alpha {alpha}: tip ({x}, {d}) vs elastica ({xe}, {de})"
        );
    }
    let (x1, d1) = elastica(1.0);
    assert!((1.0 - x1 - 0.05643).abs() < 1e-5 && (d1 - 0.30172).abs() < 2e-5);
}

fn modes_of(name: &str, text: &str, sets: &[String]) -> Vec<f64> {
    let c = match mbd::compile(name, text, sets, Request::default()) {
        Ok(c) => c,
        Err(f) => panic!("{name}: {:?}", f.diagnostics),
    };
    match mbd::modes(&c, false) {
        Ok(m) => m.modes.iter().map(|x| x.omega()).collect(),
        Err(d) => panic!("{name}: {}", d.message),
    }
}

#[test]
fn cantilever_bending_frequencies_match_euler_bernoulli() {
    // EI2 = EI3: the bending modes come in pairs; torsion has no inertia and the axial mode is
    // far above. Euler-Bernoulli: omega_n = (beta_n L)^2 sqrt(EI / (m L^4)).
    let w = modes_of("cantilever", &read("models/cantilever.mbd"), &[]);
    // Bounds per mode, about 3 times the measured 2.1e-5, 6.2e-5 and 3.9e-4 (shear flexibility
    // and the mesh: 10 quadratic elements).
    let cases = [
        (1.875_104_068_7, 6e-5),
        (4.694_091_133, 2e-4),
        (7.854_757_438, 1.2e-3),
    ];
    for (n, (bl, bound)) in cases.iter().enumerate() {
        let exact = bl * bl * (100.0f64 / 1.0).sqrt();
        for pair in [w[2 * n], w[2 * n + 1]] {
            let rel = (pair - exact).abs() / exact;
            within(&format!("mode {}: {pair} vs {exact}", n + 1), rel, *bound);
        }
    }
}

const ROTATING: &str = "model rotating_cantilever \"A cantilever on a hub driven at Omega\"
param Omega = 10 rad/s
section s { EA = 1e8 N, GA2 = 1e8 N, GA3 = 1e8 N, GJ = 100 N*m^2, EI2 = 100 N*m^2,
            EI3 = 400 N*m^2, mass_per_length = 1 kg/m }
ground earth
rigid hub { mass = 1 kg, inertia = (1, 1, 1) kg*m^2, angular_velocity = Omega * z }
joint drive = revolute(earth, hub) { axis = z, rate = Omega }
beam b { from = (0, 0, 0) m, to = (1, 0, 0) m, section = s, elements = 10, spin_stretch = Omega }
initial spin of b = Omega about z through (0, 0, 0) m
joint root = fixed(hub, b.start)
solve hht { dt = 1 ms, until = 1 s }
";

#[test]
fn rotating_cantilever_flap_frequency_rises_with_spin_as_published() {
    // sqrt(m L^4 / EI) = 0.1 s: Omega = 10 rad/s is Omega-bar = 1. Published first flap
    // frequencies of a uniform rotating cantilever without hub offset (Wright et al. 1982;
    // Hodges & Rutkowski 1981): 3.5160 (at rest), 3.6817, 4.1373, 5.5850 for Omega-bar = 0,
    // 1, 2, 4. The flap mode is the lowest (EI3 = 4 EI2).
    let mut previous = 0.0;
    for (wbar, exact) in [(0.0, 3.5160), (1.0, 3.6817), (2.0, 4.1373), (4.0, 5.5850)] {
        let w = modes_of("rotating", ROTATING, &[format!("Omega={}", 10.0 * wbar)]);
        let flap = w[0] * 0.1;
        within(
            &format!("Omega-bar {wbar}: {flap} vs {exact}"),
            (flap - exact).abs(),
            5e-5 * exact,
        ); // measured 1.5e-5 * exact
        assert!(flap > previous);
        previous = flap;
    }
}

#[test]
fn rotating_beam_phase_error_falls_at_second_order() {
    // P1: (phi(pi/Omega) - pi)/pi for the paper's step counts.
    let mut errors = Vec::new();
    for n in [12usize, 18, 36, 180, 360, 720] {
        let t = simulate(
            "models/rotating_beam.mbd",
            &[],
            Request {
                steps: Some(n),
                ..Request::default()
            },
        );
        errors.push((n, (last(&t, "phi") - PI) / PI));
    }
    // Measured: -8.7e-3, -3.9e-3, -9.7e-4, -3.8e-5, -9.6e-6, -2.4e-6.
    for w in errors.windows(2) {
        within(&format!("{errors:?}"), w[1].1.abs(), w[0].1.abs());
    }
    let order =
        |a: (usize, f64), b: (usize, f64)| (a.1 / b.1).abs().ln() / (b.0 as f64 / a.0 as f64).ln();
    for (a, b) in [(2, 4), (3, 4), (4, 5)] {
        let p = order(errors[a], errors[b]);
        assert!(
            (1.9..2.1).contains(&p),
            "order {p} between {} and {} steps",
            errors[a].0,
            errors[b].0
        );
    }
    within("errors[5].1.abs()", errors[5].1.abs(), 5e-6);
}

#[test]
fn two_bar_beams_agree_with_the_rigid_two_bar() {
    // Near-rigid bars (EI 1.28e7 N*m^2 under loads of 0.1 N: deflections ~1e-10 m); the same
    // step (10 ms): the difference is the integration of two discretizations of the same
    // inertia. Measured over 10 s: theta2 6.3e-3 rad, centre of mass 1.3e-3 m.
    let o = || Request {
        dt: Some(0.01),
        until: Some(10.0),
        ..Request::default()
    };
    let beams = simulate("models/two_bar_beams.mbd", &[], o());
    let rigid = simulate("models/two_bar.mbd", &[], o());
    let diff = |c: &str| {
        beams
            .col(c)
            .iter()
            .zip(rigid.col(c))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    within(
        &format!("theta2 {}", diff("theta2")),
        diff("theta2"),
        1.5e-2,
    );
    for c in ["xc2", "yc2", "zc2"] {
        within(&format!("{c} {}", diff(c)), diff(c), 3e-3);
    }
}

#[test]
fn two_bar_beams_runs_the_papers_case_at_its_step() {
    // The shipped model as P3 specifies it: 50 s at dt = 0.05 s (bar 2 reaches ~11 rad/s: a
    // stiff element turning 0.55 rad per step; Newton needs the half-radian limit on its
    // corrections and halves about one step in eight). Up to 10 s
    // theta2 stays within 0.2 rad of the rigid model at the same step (measured 0.137 rad;
    // each is about 0.1 rad from the exact solution at this step, rigid: 0.093 rad in
    // tests/rigid.rs); after the load reversal the two discrete solutions separate, as any two
    // discretizations of this motion do at this step.
    let beams = simulate("models/two_bar_beams.mbd", &[], Request::default());
    let t = beams.col("t");
    assert!(
        (t[t.len() - 1] - 50.0).abs() < 1e-9,
        "ended at {}",
        t[t.len() - 1]
    );
    let rigid = simulate("models/two_bar.mbd", &[], Request::default());
    let (a, b) = (beams.col("theta2"), rigid.col("theta2"));
    let worst = (0..=200).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max);
    eprintln!("two_bar_beams dt 0.05: theta2 within {worst:.3e} rad of the rigid model to 10 s");
    within(&format!("theta2 {worst}"), worst, 0.2);
}

#[test]
fn elastic_two_bar_root_torque_exceeds_the_rigid_one_and_converges() {
    // P4 with elastic bars, over the first 5 s: the peak drive torque against the rigid
    // model's, at two steps and two meshes. Measured: ratio 2.55 (1 ms), 2.54 (0.5 ms), 2.51
    // (2 elements per bar); elastic deviation of bar 2's centre of mass 5.7e-4 m.
    let run = |model: &str, dt: f64, sets: &[&str]| {
        simulate(
            model,
            sets,
            Request {
                dt: Some(dt),
                until: Some(5.0),
                ..Request::default()
            },
        )
    };
    let rigid = run("models/two_bar_spin.mbd", 1e-3, &[]);
    let r0 = peak(&rigid.col("torque")[1..]);
    let a = run("models/two_bar_spin_elastic.mbd", 1e-3, &[]);
    let b = run("models/two_bar_spin_elastic.mbd", 5e-4, &[]);
    let c = run("models/two_bar_spin_elastic.mbd", 1e-3, &["elements=2"]);
    let (pa, pb, pc) = (
        peak(&a.col("torque")),
        peak(&b.col("torque")),
        peak(&c.col("torque")),
    );
    above(&format!("peak torque ratio {}", pa / r0), pa / r0, 2.0);
    within(&format!("dt: {pa} vs {pb}"), (pa - pb).abs(), 0.004 * pb); // measured 1.1e-3 * pb
    within(&format!("mesh: {pa} vs {pc}"), (pa - pc).abs(), 0.03 * pc);
    // Elastic motion in the yz path of bar 2's centre of mass, small against the bar.
    let dev = a
        .col("yc2")
        .iter()
        .zip(a.col("zc2"))
        .zip(rigid.col("yc2").iter().zip(rigid.col("zc2")))
        .map(|((y, z), (yr, zr))| ((y - yr).powi(2) + (z - zr).powi(2)).sqrt())
        .fold(0.0, f64::max);
    assert!(dev > 1e-5 && dev < 1e-2, "elastic deviation {dev}");
}

#[test]
fn linear_elements_converge_at_second_order_in_the_mesh() {
    // First bending frequency of the cantilever with 2-node elements: error ~ h^2.
    let text = read("models/cantilever.mbd");
    let exact = 1.875_104_068_7f64.powi(2) * 10.0;
    let err = |n: usize| {
        let w = modes_of(
            "cantilever",
            &text,
            &[format!("elements={n}"), "order=2".into()],
        );
        (w[0] - exact).abs() / exact
    };
    let (e1, e2, e3) = (err(4), err(8), err(16));
    let (p1, p2) = ((e1 / e2).log2(), (e2 / e3).log2());
    assert!(
        (1.8..2.3).contains(&p1) && (1.8..2.3).contains(&p2),
        "orders {p1} {p2} ({e1:e} {e2:e} {e3:e})"
    );
}
