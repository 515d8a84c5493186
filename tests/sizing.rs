//! The sizing lint (`mbd explain W0701`): a beam's lowest elastic frequency in its assembly
//! against Euler-Bernoulli's closed forms (clamped-free, and pinned-free on a hinge: the
//! mechanism's swing is not the beam's), its quasi-static deformation against the closed-form
//! cantilever's, less the best rigid motion; the verdict on `models/two_bar_beams.mbd` and on
//! its rigid version, which runs the same motion.

use crate::common::{read, simulate_text_with, within};
use mbd::lint::{Lint, Verdict};
use mbd::model::NoFiles;
use mbd::settings::Request;

fn lint_text(name: &str, text: &str, sets: &[&str]) -> Lint {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let c = match mbd::compile(name, text, &sets, Request::default()) {
        Ok(c) => c,
        Err(f) => panic!("{name} does not compile: {:?}", f.diagnostics),
    };
    mbd::lint(&c, name, text, &sets, Request::default(), &NoFiles)
}

/// A beam along x, `L` = 1 m, 1 kg/m, in-plane (xy) stiffness `EI3`, out of plane 100 times
/// stiffer, stiff in torsion, stretch and shear; its root `root`; a tip force `P t / 1 s`
/// along -z.
fn beam(root: &str, solve: &str) -> String {
    format!(
        "model b \"a beam\"
param P = 0 N
ground earth
section s {{
    EA = 1e9 N, GA2 = 1e9 N, GA3 = 1e9 N, GJ = 1e6 N*m^2, EI2 = 1e4 N*m^2, EI3 = 100 N*m^2
    mass_per_length = 1 kg/m
}}
beam b {{ from = (0, 0, 0) m, to = (1, 0, 0) m, section = s, elements = 10, order = 3 }}
joint root = {root}
force tip on b.end = (0, 0, -P * t / 1 s)
output z = b.end.position.z
solve {solve}
"
    )
}

#[test]
fn a_clamped_beams_frequency_and_deformation_are_the_cantilevers() {
    let lint = lint_text(
        "clamped.mbd",
        &beam("fixed(earth, b.start)", "static { steps = 1, until = 1 s }"),
        &["P=100"],
    );
    let b = &lint.beams[0];
    // Clamped-free, bending in plane (the softer): (1.8751)^2 sqrt(EI3 / (m L^4)) = 3.5160154 * 10.
    let w = b.omega.expect("a frequency");
    within(
        "clamped-free frequency, relative",
        (w / 35.160154 - 1.0).abs(),
        7e-6,
    ); // 2.2e-6
       // The deformation: w(x) = P x^2 (3 - x) / (6 EI2) at the 21 nodes, less the best line
       // (the rigid motion), and the slopes less its slope times L.
    let ei = 1e4;
    let xs: Vec<f64> = (0..21).map(|k| k as f64 / 20.0).collect();
    let p = 100.0;
    let defl: Vec<f64> = xs
        .iter()
        .map(|x| p * x * x * (3.0 - x) / (6.0 * ei))
        .collect();
    let slope: Vec<f64> = xs.iter().map(|x| p * x * (2.0 - x) / (2.0 * ei)).collect();
    let n = xs.len() as f64;
    let (mx, mw) = (xs.iter().sum::<f64>() / n, defl.iter().sum::<f64>() / n);
    let s = xs
        .iter()
        .zip(&defl)
        .map(|(x, w)| (x - mx) * (w - mw))
        .sum::<f64>()
        / xs.iter().map(|x| (x - mx) * (x - mx)).sum::<f64>();
    let off = xs
        .iter()
        .zip(&defl)
        .map(|(x, w)| (w - mw - s * (x - mx)).abs())
        .fold(0.0, f64::max);
    let turn = slope.iter().map(|d| (d - s).abs()).fold(0.0, f64::max);
    let expected = off.max(turn);
    // The mesh's error (10 parabolic elements) and the stretch's.
    within(
        "cantilever deformation, relative",
        (b.deflection / expected - 1.0).abs(),
        9e-5,
    ); // 2.9e-5
    assert_eq!(b.verdict, Verdict::Elastic, "{b:?}");
}

#[test]
fn a_hinged_beams_frequency_is_pinned_free_not_its_swing() {
    let lint = lint_text(
        "hinged.mbd",
        &beam(
            "revolute(earth, b.start) { axis = z }",
            "hht { dt = 1 ms, until = 1 s }",
        ),
        &[],
    );
    let b = &lint.beams[0];
    // Pinned-free, in plane: (3.926602)^2 sqrt(EI3 / (m L^4)) = 15.418206 * 10; the swing
    // about the hinge (zero frequency) is no mode of the beam's.
    let w = b.omega.expect("a frequency");
    within(
        "pinned-free frequency, relative",
        (w / 154.18206 - 1.0).abs(),
        1.5e-4,
    ); // 4.9e-5
}

#[test]
fn two_bar_beams_could_be_rigid_and_its_rigid_version_runs_the_same_motion() {
    // A rigid beam's points have no rotation output: the bars' crv columns go.
    let crv =
        ",\n       c1 = bar2.node[1].crv.c1, c2 = bar2.node[1].crv.c2, c3 = bar2.node[1].crv.c3";
    let text = read("models/two_bar_beams.mbd");
    assert!(text.contains(crv));
    let text = text.replace(crv, "");
    let lint = lint_text("models/two_bar_beams.mbd", &text, &[]);
    let verdicts: Vec<Verdict> = lint.beams.iter().map(|b| b.verdict).collect();
    assert_eq!(verdicts, [Verdict::CouldBeRigid, Verdict::CouldBeRigid]);
    let codes: Vec<&str> = lint.diagnostics.iter().map(|d| d.code.as_str()).collect();
    assert_eq!(codes, ["W0701", "W0701"]);
    let rigid = text
        .replace("beam bar1 {", "beam bar1 rigid {")
        .replace("beam bar2 {", "beam bar2 rigid {");
    let lint = lint_text("rigid.mbd", &rigid, &[]);
    let verdicts: Vec<Verdict> = lint.beams.iter().map(|b| b.verdict).collect();
    assert_eq!(verdicts, [Verdict::Rigid, Verdict::Rigid]);
    assert!(lint.diagnostics.is_empty(), "{:?}", lint.diagnostics);
    // The same motion, theta2_0 = 0 (smooth), 10 s: the two differ by the integrators' error
    // on different unknowns, of order h^2 (halving the step quarters it).
    let gap = |dt: f64| {
        let request = Request {
            dt: Some(dt),
            until: Some(10.0),
            ..Request::default()
        };
        let run = |t: &str| match simulate_text_with("m.mbd", t, &["theta2_0=0"], request.clone()) {
            Ok(trace) => trace,
            Err((_, why)) => panic!("the run failed: {why}"),
        };
        let (beams, bodies) = (run(&text), run(&rigid));
        ["theta1", "theta2"].map(|col| {
            let (a, b) = (beams.col(col), bodies.col(col));
            let scale = a.iter().map(|x| x.abs()).fold(0.0, f64::max);
            a.iter()
                .zip(&b)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
                / scale
        })
    };
    let (coarse, fine) = (gap(1e-3), gap(5e-4));
    within(
        "theta1: beams against rigid at 1 ms, relative",
        coarse[0],
        4e-5,
    ); // 1.2e-5
    within(
        "theta2: beams against rigid at 1 ms, relative",
        coarse[1],
        1.5e-5,
    ); // 4.5e-6
    for k in 0..2 {
        let order = (coarse[k] / fine[k]).log2();
        within(
            "the gap's order in the step, from 2",
            (order - 2.0).abs(),
            0.4,
        ); // 0.13, 0.18
    }
}
