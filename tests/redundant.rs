//! Redundant but consistent joints (W0303): the planar four-bar of four revolute joints
//! (three equations too many in 3-D) against its one-degree-of-freedom Lagrange equation,
//! integrated here by RK4; Bricard's overconstrained 6R linkage (IFToMM benchmark A04: five
//! unit rods of 1 kg, gravity along -y, 10 s), judged as the benchmark judges it, by its
//! energy; the joint forces' minimum-norm split on a door hung on two hinges of one axis.
//! A start at a singular position (E0608) is in `tests/diagnostics.rs`.

use crate::common::{simulate_text_with, within, Trace};
use mbd::settings::Request;

const G: f64 = 9.81;
/// Crank, coupler, rocker and ground lengths (m); the rods' masses (kg).
const LINKS: [f64; 4] = [0.2, 0.6, 0.45, 0.5];
const MASSES: [f64; 3] = [1.0, 2.0, 1.5];
const THETA0: f64 = std::f64::consts::FRAC_PI_3;

/// The four-bar's joints and rods' centres at crank angle `theta`: `A` (crank-coupler), `B`
/// (coupler-rocker) on the branch the model starts on.
fn joints(theta: f64) -> ([f64; 2], [f64; 2]) {
    let [a, b, c, d] = LINKS;
    let pa = [a * theta.cos(), a * theta.sin()];
    let (dx, dy) = (d - pa[0], -pa[1]);
    let l = dx.hypot(dy);
    let x = (b * b - c * c + l * l) / (2.0 * l);
    let h = (b * b - x * x).sqrt();
    let (ex, ey) = (dx / l, dy / l);
    (pa, [pa[0] + x * ex - h * ey, pa[1] + x * ey + h * ex])
}

/// The rods' centres (x, y) and angles at `theta`.
fn pose(theta: f64) -> [[f64; 3]; 3] {
    let d = LINKS[3];
    let (pa, pb) = joints(theta);
    [
        [pa[0] / 2.0, pa[1] / 2.0, theta],
        [
            (pa[0] + pb[0]) / 2.0,
            (pa[1] + pb[1]) / 2.0,
            (pb[1] - pa[1]).atan2(pb[0] - pa[0]),
        ],
        [(d + pb[0]) / 2.0, pb[1] / 2.0, pb[1].atan2(pb[0] - d)],
    ]
}

/// The generalized inertia `J(theta)` (kinetic energy `J theta'^2 / 2`) and the potential.
fn inertia_and_potential(theta: f64) -> (f64, f64) {
    let e = 1e-6;
    let (p, m) = (pose(theta + e), pose(theta - e));
    let lengths = [LINKS[0], LINKS[1], LINKS[2]];
    let mut j = 0.0;
    for k in 0..3 {
        let rate = |i: usize| (p[k][i] - m[k][i]) / (2.0 * e);
        let turn = rate(2);
        j += MASSES[k] * (rate(0).powi(2) + rate(1).powi(2))
            + MASSES[k] * lengths[k] * lengths[k] / 12.0 * turn * turn;
    }
    let centre = pose(theta);
    let v = (0..3).map(|k| MASSES[k] * G * centre[k][1]).sum();
    (j, v)
}

/// `theta'' = -(J'(theta) theta'^2 / 2 + V'(theta)) / J(theta)`.
fn acceleration(theta: f64, rate: f64) -> f64 {
    let e = 1e-4;
    let (jp, vp) = inertia_and_potential(theta + e);
    let (jm, vm) = inertia_and_potential(theta - e);
    let (j, _) = inertia_and_potential(theta);
    -(((jp - jm) / (2.0 * e)) * rate * rate / 2.0 + (vp - vm) / (2.0 * e)) / j
}

/// The crank angle from rest at `THETA0`, by RK4 at `h`, sampled every `every` steps.
fn reference(until: f64, h: f64, every: usize) -> Vec<f64> {
    let (mut x, mut v) = (THETA0, 0.0);
    let mut out = vec![x];
    let steps = (until / h).round() as usize;
    for k in 1..=steps {
        let k1 = (v, acceleration(x, v));
        let k2 = (
            v + h / 2.0 * k1.1,
            acceleration(x + h / 2.0 * k1.0, v + h / 2.0 * k1.1),
        );
        let k3 = (
            v + h / 2.0 * k2.1,
            acceleration(x + h / 2.0 * k2.0, v + h / 2.0 * k2.1),
        );
        let k4 = (v + h * k3.1, acceleration(x + h * k3.0, v + h * k3.1));
        x += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
        v += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        if k % every == 0 {
            out.push(x);
        }
    }
    out
}

fn four_bar() -> String {
    let (pa, pb) = joints(THETA0);
    let d = LINKS[3];
    format!(
        "model fourbar \"a planar four-bar of four revolute joints\"
gravity = (0, -{G}, 0) m/s^2
ground earth
rigid_rod crank {{ from = (0, 0, 0) m, to = ({:?}, {:?}, 0) m, mass = {} kg }}
rigid_rod coupler {{ from = ({:?}, {:?}, 0) m, to = ({:?}, {:?}, 0) m, mass = {} kg }}
rigid_rod rocker {{ from = ({d}, 0, 0) m, to = ({:?}, {:?}, 0) m, mass = {} kg }}
joint j1 = revolute(earth, crank.start) {{ axis = z }}
joint j2 = revolute(crank.end, coupler.start) {{ axis = z }}
joint j3 = revolute(coupler.end, rocker.end) {{ axis = z }}
joint j4 = revolute(earth @ ({d}, 0, 0) m, rocker.start) {{ axis = z }}
output theta = j1.angle
solve hht(alpha = -0.05) {{ dt = 1 ms, until = 2 s, every = 10 }}
",
        pa[0], pa[1], MASSES[0], pa[0], pa[1], pb[0], pb[1], MASSES[1], pb[0], pb[1], MASSES[2]
    )
}

fn run(text: &str, request: Request) -> Trace {
    match simulate_text_with("m.mbd", text, &[], request) {
        Ok(trace) => trace,
        Err((_, why)) => panic!("the run failed: {why}"),
    }
}

#[test]
fn a_four_bar_of_revolute_joints_follows_its_one_degree_of_freedom_equation() {
    let text = four_bar();
    let Ok(c) = mbd::compile("fourbar.mbd", &text, &[], Request::default()) else {
        panic!("the four-bar does not compile")
    };
    let codes: Vec<&str> = c.warnings.iter().map(|d| d.code.as_str()).collect();
    assert_eq!(codes, ["W0303"]);
    assert!(
        c.warnings[0].message.contains("3 equations too many"),
        "{}",
        c.warnings[0].message
    );
    let exact = reference(2.0, 1e-4, 100);
    let error = |dt: f64, every: usize| {
        let request = Request {
            dt: Some(dt),
            every: Some(every),
            ..Request::default()
        };
        let theta = run(&text, request).col("theta");
        assert_eq!(theta.len(), exact.len());
        let swing = exact.iter().map(|x| (x - THETA0).abs()).fold(0.0, f64::max);
        theta
            .iter()
            .zip(&exact)
            .map(|(t, x)| (t + THETA0 - x).abs())
            .fold(0.0, f64::max)
            / swing
    };
    let (coarse, fine) = (error(1e-3, 10), error(5e-4, 20));
    within(
        "four-bar crank angle at 1 ms, relative to its swing",
        coarse,
        3e-4,
    ); // 9.0e-5
    within(
        "order in dt, from 2",
        ((coarse / fine).log2() - 2.0).abs(),
        0.15,
    ); // 0.046
}

const BRICARD: &str = "model bricard \"Bricard's overconstrained 6R linkage (IFToMM A04)\"
gravity = (0, -9.81, 0) m/s^2
ground earth
rigid_rod r1 { from = (1, 0, 0) m, to = (1, 1, 0) m, mass = 1 kg }
rigid_rod r2 { from = (1, 1, 0) m, to = (1, 1, 1) m, mass = 1 kg }
rigid_rod r3 { from = (1, 1, 1) m, to = (0, 1, 1) m, mass = 1 kg }
rigid_rod r4 { from = (0, 1, 1) m, to = (0, 0, 1) m, mass = 1 kg }
rigid_rod r5 { from = (0, 0, 1) m, to = (0, 0, 0) m, mass = 1 kg }
joint j1 = revolute(earth @ (1, 0, 0) m, r1.start) { axis = z }
joint j2 = revolute(r1.end, r2.start) { axis = x }
joint j3 = revolute(r2.end, r3.start) { axis = y }
joint j4 = revolute(r3.end, r4.start) { axis = z }
joint j5 = revolute(r4.end, r5.start) { axis = x }
joint j6 = revolute(r5.end, earth) { axis = y }
output p3y = r2.end.position.y, total_energy, kinetic_energy
solve hht(alpha = 0) { dt = 1 ms, until = 10 s, every = 10 }
";

#[test]
fn bricards_linkage_moves_with_one_degree_of_freedom_and_keeps_its_energy() {
    let Ok(c) = mbd::compile("bricard.mbd", BRICARD, &[], Request::default()) else {
        panic!("Bricard's linkage does not compile")
    };
    let codes: Vec<&str> = c.warnings.iter().map(|d| d.code.as_str()).collect();
    assert_eq!(codes, ["W0303"]);
    assert!(
        c.warnings[0].message.contains("1 equation too many"),
        "{}",
        c.warnings[0].message
    );
    // Energy drift, relative to the largest kinetic energy, over the first 8.5 s and over
    // the benchmark's 10 s.
    let drift = |dt: f64, every: usize| {
        let request = Request {
            dt: Some(dt),
            every: Some(every),
            ..Request::default()
        };
        let trace = run(BRICARD, request);
        let (t, energy) = (trace.col("t"), trace.col("total_energy"));
        let (kinetic, y) = (trace.col("kinetic_energy"), trace.col("p3y"));
        // It moves: the point P3 = (1, 1, 1) falls by more than a metre and swings back.
        let low = y.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(low < -1.0, "P3 reaches y = {low}");
        let scale = kinetic.iter().copied().fold(0.0, f64::max);
        let off = |until: f64| {
            t.iter()
                .zip(&energy)
                .filter(|(t, _)| **t <= until)
                .map(|(_, e)| (e - energy[0]).abs())
                .fold(0.0, f64::max)
                / scale
        };
        (off(8.5), off(10.0))
    };
    let (coarse, fine) = (drift(2e-3, 5), drift(1e-3, 10));
    within("Bricard: energy drift over 8.5 s at 1 ms", fine.0, 2e-5); // 6.5e-6
    within(
        "Bricard: the drift's order in dt, from 2",
        ((coarse.0 / fine.0).log2() - 2.0).abs(),
        0.3,
    ); // 0.18
       // The passage near 9.6 s (P3 through y = 0 at the highest speed) costs more, and that
       // part does not shrink with the step (see the closing note of issue 23). It amplifies
       // round-off: over steps of 0.97 to 1.03 ms the 10-s drift spreads from 5e-5 to 1.6e-3
       // (to 1.8e-3 with the quaternion's re-orthonormalization; issue 20), and one step's
       // figure moves with any change in the last bits. The median over seven steps (0.97 to
       // 1.03 ms by 0.01: 5.3e-5 to 7.3e-4) moves far less.
    let mut tens: Vec<f64> = [0.97e-3, 0.98e-3, 0.99e-3, 1e-3, 1.01e-3, 1.02e-3, 1.03e-3]
        .iter()
        .map(|&dt| if dt == 1e-3 { fine.1 } else { drift(dt, 10).1 })
        .collect();
    tens.sort_by(f64::total_cmp);
    within(
        "Bricard: energy drift over 10 s, median over 0.97-1.03 ms",
        tens[3],
        1.2e-3,
    ); // 4.0e-4
}

#[test]
fn a_door_on_two_hinges_of_one_axis_shares_its_weight_by_the_minimum_norm_split() {
    // Gravity along the hinge axis: the weight is carried along the axis, by the two hinges
    // in any proportion; the minimum-norm split halves it (the dropped rows alone would put
    // it all on the first hinge).
    let text = "model door \"a door on two hinges of one axis\"
gravity = (0, 0, -9.81) m/s^2
ground earth
rigid_rod door { from = (0, 0, 0) m, to = (1, 0, 0) m, mass = 4 kg }
joint hinge_a = revolute(earth, door.start) { axis = z }
joint hinge_b = revolute(earth @ (0, 0, 0.2) m, door @ (-0.5, 0, 0.2) m) { axis = z }
output fa = hinge_a.force.z, fb = hinge_b.force.z
solve hht { dt = 1 ms, until = 0.01 s }
";
    let trace = run(text, Request::default());
    let (fa, fb) = (trace.col("fa"), trace.col("fb"));
    let weight = 4.0 * G;
    for (a, b) in fa.iter().zip(&fb) {
        within(
            "hinge a carries half the weight, relative",
            (a.abs() / (weight / 2.0) - 1.0).abs(),
            2e-15,
        ); // 4.4e-16
        within(
            "hinge b carries half the weight, relative",
            (b.abs() / (weight / 2.0) - 1.0).abs(),
            2e-15,
        ); // 4.4e-16
    }
}
