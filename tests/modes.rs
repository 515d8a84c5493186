//! `mbd modes` against closed forms: hinged rods and rigid bodies on a spinning hub (flap and
//! lag, central and offset hinges, with and without springs), a physical pendulum, a spinning
//! cantilever against Southwell's formula with the coefficient integrated here from the
//! Euler-Bernoulli mode, the steady coning of a blade under gravity, and the refusals (E0605)
//! of models that have no steady motion. Regression tests of issue 16: a rod's missing axial
//! inertia biased the start's multipliers, and with them every spinning rod's frequencies.

use crate::cli::{code, mbd, stderr, temp};
use crate::common::within;
use mbd::diagnostics::Code;
use mbd::settings::Request;
use mbd::solve::modes::{Frame, Modes};

fn modes_of(name: &str, text: &str, frozen: bool) -> Result<Modes, mbd::diagnostics::Diagnostic> {
    let c = match mbd::compile(name, text, &[], Request::default()) {
        Ok(c) => c,
        Err(f) => panic!("{name}: {:?}", f.diagnostics),
    };
    mbd::modes(&c, frozen)
}

fn omegas(name: &str, text: &str) -> Vec<f64> {
    match modes_of(name, text, false) {
        Ok(m) => m.modes.iter().map(|x| x.omega()).collect(),
        Err(d) => panic!("{name}: {}", d.message),
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Body {
    Rod,
    Rigid,
}

#[derive(Clone, Copy, PartialEq)]
enum Hinge {
    Flap,
    Lag,
}

const M: f64 = 8.0;
const L: f64 = 2.0;

/// `blades` uniform blades (mass M, length L) hinged at `e` from the centre of a massless hub
/// driven at `omega` about z, each by a revolute (flap: about the tangential axis; lag: about
/// z) with a torsional spring `k`.
fn rotor(body: Body, hinge: Hinge, blades: usize, e: f64, k: f64, omega: f64) -> String {
    let blade = match body {
        Body::Rod => {
            "rigid_rod b[i] { from = e * radial, to = (e + L) * radial, mass = m }".to_string()
        }
        Body::Rigid => "rigid b[i] {
        mass = m, at = (e + L / 2) * radial, orientation = rotate(z, psi)
        inertia = (0, 1, 1) * m * L^2 / 12
        marker start = (-L / 2, 0, 0)
    }"
        .to_string(),
    };
    let axis = match hinge {
        Hinge::Flap => "rotate(z, psi) * y",
        Hinge::Lag => "z",
    };
    format!(
        "model rotor \"Hinged blades on a driven hub\"
param Omega = {omega} rad/s
param m = {M} kg
param L = {L} m
param e = {e} m
ground earth
rigid hub {{ mass = 0 kg }}
joint drive = revolute(earth, hub) {{ axis = z, rate = Omega }}
initial spin of hub = Omega about z
for i in 0..{blades} {{
    let psi = i * 360 deg / {blades}
    let radial = rotate(z, psi) * x
    {blade}
    joint h[i] = revolute(hub @ (e * radial), b[i].start) {{ axis = {axis}, spring = {k} N*m/rad }}
    initial spin of b[i] = Omega about z
}}
solve hht {{ dt = 1 ms, until = 1 s }}
"
    )
}

/// About the hinge: `I = m L^2 / 3`, `S = m L / 2`. Flap: `w^2 = Omega^2 (1 + e S / I) + K / I`;
/// lag: `w^2 = (e S Omega^2 + K) / I` (centrifugal stiffening from the offset only).
fn closed_form(hinge: Hinge, e: f64, k: f64, omega: f64) -> f64 {
    let (i, s) = (M * L * L / 3.0, M * L / 2.0);
    match hinge {
        Hinge::Flap => (omega * omega * (1.0 + e * s / i) + k / i).sqrt(),
        Hinge::Lag => ((e * s * omega * omega + k) / i).sqrt(),
    }
}

#[test]
fn hinged_rods_and_rigid_blades_match_the_closed_forms_at_every_speed() {
    let mut worst = 0.0f64;
    for hinge in [Hinge::Flap, Hinge::Lag] {
        for (e, k) in [(0.0, 100.0), (0.3, 100.0), (0.3, 0.0), (0.0, 0.0)] {
            for omega in [0.0, 10.0, 20.0, 40.0] {
                let exact = closed_form(hinge, e, k, omega);
                for body in [Body::Rod, Body::Rigid] {
                    let w = omegas("rotor", &rotor(body, hinge, 2, e, k, omega));
                    if exact == 0.0 {
                        // A free hinge without stiffening: a double zero eigenvalue per blade,
                        // split by round-off to about its square root (measured 2.1e-5 rad/s).
                        assert!(w.iter().all(|x| *x < 1e-4), "{w:?}");
                        continue;
                    }
                    // Two blades: a pair of equal modes (one degree of freedom each).
                    assert_eq!(w.len(), 2, "{w:?}");
                    for wi in w {
                        let err = (wi - exact).abs() / exact.max(1.0);
                        worst = worst.max(err);
                        within(
                            &format!("e {e}, k {k}, Omega {omega}: {wi} vs {exact} rad/s"),
                            err,
                            1e-10,
                        ); // measured 3.4e-11 (the README's 1e-10)
                    }
                }
            }
        }
    }
    // Measured: 3.4e-11 (round-off of the start and the QZ).
    within(&format!("{worst:e}"), worst, 1e-10);
}

#[test]
fn the_issue_s_two_cases_give_the_textbook_frequencies() {
    // One rod on a central flap hinge at 20 rad/s: sqrt(Omega^2 + K / I) = 20.233 (25.187
    // before the fix); two rods on lag hinges offset 0.3 m: 9.969 (19.796 before).
    let flap = omegas("flap", &rotor(Body::Rod, Hinge::Flap, 1, 0.0, 100.0, 20.0));
    assert_eq!(flap.len(), 1);
    within(
        &format!("{flap:?}"),
        (flap[0] - 20.233_017_570_300_9).abs(),
        8e-14,
    ); // measured 2.1e-14
    let lag = omegas("lag", &rotor(Body::Rod, Hinge::Lag, 2, 0.3, 100.0, 20.0));
    assert!(
        lag.iter().all(|w| (w - 9.968_701_018_7).abs() < 1e-8),
        "{lag:?}"
    );
}

#[test]
fn rods_and_equivalent_rigid_bodies_have_the_same_modes() {
    for hinge in [Hinge::Flap, Hinge::Lag] {
        for blades in [1, 3] {
            let a = omegas("rod", &rotor(Body::Rod, hinge, blades, 0.25, 60.0, 15.0));
            let b = omegas(
                "rigid",
                &rotor(Body::Rigid, hinge, blades, 0.25, 60.0, 15.0),
            );
            assert_eq!(a.len(), b.len());
            for (x, y) in a.iter().zip(&b) {
                // Measured: up to 7.9e-12.
                within(&format!("{a:?} vs {b:?}"), (x - y).abs(), 2.5e-11 * x);
            }
        }
    }
}

#[test]
fn a_one_degree_of_freedom_pendulum_has_its_frequency_and_no_panic() {
    // A rod hanging from a hinge under gravity: w^2 = (m g L/2) / (m L^2/3) = 3 g / (2 L).
    let text = "model pendulum \"A hanging rod\"
gravity = (0, -9.81, 0) m/s^2
ground earth
rigid_rod bar { from = (0, 0, 0) m, to = (0, -1.5, 0) m, mass = 2 kg }
joint pin = revolute(earth, bar.start) { axis = z }
solve hht { dt = 1 ms, until = 1 s }
";
    let m = modes_of("pendulum", text, false).expect("modes");
    assert_eq!(m.frame, Frame::Inertial);
    assert_eq!((m.modes.len(), m.dofs), (1, 1));
    let exact = (3.0 * 9.81 / (2.0 * 1.5f64)).sqrt();
    // Measured: 1.9e-11.
    within(
        "(m.modes[0].omega() - exact).abs()",
        (m.modes[0].omega() - exact).abs(),
        6e-11 * exact,
    );
    // Welded to the ground: no degree of freedom, no mode, no failure.
    let welded = text.replace(
        "revolute(earth, bar.start) { axis = z }",
        "fixed(earth, bar.start)",
    );
    let m = modes_of("welded", &welded, false).expect("modes");
    assert!(m.modes.is_empty() && m.dofs == 0);
}

/// The first mode of a uniform cantilever, `phi(x) = cosh - cos - s (sinh - sin)` of `b x`.
fn cantilever_mode(x: f64, l: f64) -> (f64, f64) {
    let b = 1.875_104_068_711_961 / l;
    let s = ((b * l).cosh() + (b * l).cos()) / ((b * l).sinh() + (b * l).sin());
    let y = b * x;
    let phi = y.cosh() - y.cos() - s * (y.sinh() - y.sin());
    let dphi = b * (y.sinh() + y.sin() - s * (y.cosh() - y.cos()));
    (phi, dphi)
}

#[test]
fn spinning_cantilever_flap_and_lag_follow_southwell() {
    // Southwell: w^2 = w0^2 + K Omega^2 (flap), w0^2 + (K - 1) Omega^2 (lag), with
    // K = int T phi'^2 / (Omega^2 int m phi^2), T = m Omega^2 (L^2 - x^2) / 2 the centrifugal
    // tension, phi the non-rotating mode: integrated here (Simpson, 2000 panels).
    let l = 1.0;
    let n = 2000;
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0..=n {
        let x = l * k as f64 / n as f64;
        let w = if k == 0 || k == n {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let (phi, dphi) = cantilever_mode(x, l);
        num += w * 0.5 * (l * l - x * x) * dphi * dphi;
        den += w * phi * phi;
    }
    let southwell = num / den;
    within(&format!("{southwell}"), (southwell - 1.1933).abs(), 1e-4);
    let model = |omega: f64| {
        format!(
            "model spinning \"A cantilever on a hub driven at Omega\"
param Omega = {omega} rad/s
section s {{ EA = 1e8 N, GA2 = 1e8 N, GA3 = 1e8 N, GJ = 100 N*m^2, EI2 = 100 N*m^2,
            EI3 = 400 N*m^2, mass_per_length = 1 kg/m }}
ground earth
rigid hub {{ mass = 1 kg, inertia = (1, 1, 1) kg*m^2, angular_velocity = Omega * z }}
joint drive = revolute(earth, hub) {{ axis = z, rate = Omega }}
beam b {{ from = (0, 0, 0) m, to = (1, 0, 0) m, section = s, elements = 10, spin_stretch = Omega }}
initial spin of b = Omega about z through (0, 0, 0) m
joint root = fixed(hub, b.start)
solve hht {{ dt = 1 ms, until = 1 s }}
"
        )
    };
    // The non-rotating frequencies of the same mesh: flap (EI2) first, lag (EI3 = 4 EI2) after
    // the second flap mode.
    let w0 = omegas("still", &model(0.0));
    let (flap0, lag0) = (w0[0], w0[1]);
    within(&format!("{w0:?}"), (lag0 / flap0 - 2.0).abs(), 5e-5); // measured 1.4e-5
    let mut errors = Vec::new();
    for omega in [5.0, 10.0] {
        let w = omegas("spinning", &model(omega));
        let flap = (flap0 * flap0 + southwell * omega * omega).sqrt();
        let lag = (lag0 * lag0 + (southwell - 1.0) * omega * omega).sqrt();
        let (ef, el) = ((w[0] - flap).abs() / flap, (w[1] - lag).abs() / lag);
        errors.push((ef, el));
        // Southwell's formula is exact to O(Omega^4). Measured at Omega-bar 0.5 and 1: flap
        // 3.1e-6 and 4.4e-5, lag 5.0e-7 and 4.2e-6.
        let (bf, bl) = if omega < 7.0 {
            (1e-5, 1.5e-6)
        } else {
            (1.3e-4, 1.3e-5)
        };
        assert!(
            ef < bf && el < bl,
            "Omega {omega}: {:?} vs {flap}, {lag} ({ef:e}, {el:e})",
            &w[..2]
        );
    }
    // The flap error grows as Omega^4 (measured order 3.84).
    let order = (errors[1].0 / errors[0].0).log2();
    assert!((3.5..4.5).contains(&order), "order {order}");
}

#[test]
fn a_blade_coned_by_gravity_is_analysed_about_its_steady_coning_angle() {
    // A rod on a central flap hinge with a spring, gravity along the spin axis: the steady
    // coning angle b0 solves I Omega^2 sin b cos b + K b + S g cos b = 0 and the flap
    // frequency is w^2 = (I Omega^2 cos 2 b0 + K - S g sin b0) / I. The model starts flat;
    // `mbd modes` finds the coned state first.
    let (k, omega, g) = (100.0, 6.0, 9.81);
    let (i, s) = (M * L * L / 3.0, M * L / 2.0);
    let f = |b: f64| i * omega * omega * b.sin() * b.cos() + k * b + s * g * b.cos();
    let (mut lo, mut hi) = (-1.0, 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(lo) * f(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let b0 = 0.5 * (lo + hi);
    let exact = ((i * omega * omega * (2.0 * b0).cos() + k - s * g * b0.sin()) / i).sqrt();
    let text = rotor(Body::Rod, Hinge::Flap, 1, 0.0, k, omega).replace(
        "ground earth",
        "ground earth\ngravity = (0, 0, -9.81) m/s^2",
    );
    let m = modes_of("coning", &text, false).expect("modes");
    assert!(matches!(m.frame, Frame::Rotating { .. }));
    // Measured: 1.9e-12.
    within(
        &format!("{} vs {exact}", m.modes[0].omega()),
        (m.modes[0].omega() - exact).abs(),
        6e-12 * exact,
    );
    // The rod's centre moved from the flat start by L/2 (1 - cos b0) in and L/2 sin b0 down.
    let tip = 0.5 * L * ((1.0 - b0.cos()).powi(2) + b0.sin().powi(2)).sqrt();
    // Measured: 2e-16 m.
    within(
        &format!("moved {} vs {tip}", m.moved),
        (m.moved - tip).abs(),
        4e-15 * tip,
    ); // measured 1.2e-15 * tip
}

/// A teetering rotor (two rods welded to a yoke on a teeter hinge) on a hub driven at Omega,
/// on an elastic mast or on the ground.
pub fn teetering(elastic_mast: bool) -> String {
    let (mount, mast) = if elastic_mast {
        (
            "mast.end",
            "section mast_s { EA = 1e9 N, GA2 = 1e8 N, GA3 = 1e8 N, GJ = 1e5 N*m^2,
                  EI2 = 2e5 N*m^2, EI3 = 2e5 N*m^2, mass_per_length = 20 kg/m }
beam mast { from = (0, 0, -2) m, to = (0, 0, 0) m, section = mast_s, elements = 2 }
joint base = fixed(earth @ (0, 0, -2) m, mast.start)",
        )
    } else {
        ("earth", "")
    };
    format!(
        "model teeter \"A teetering rotor\"
param Omega = 31.4 rad/s
param m = 8 kg
param L = 2 m
param e = 0.2 m
ground earth
{mast}
rigid hub {{ mass = 5 kg, inertia = (0.1, 0.1, 0.2) kg*m^2 }}
joint drive = revolute({mount}, hub) {{ axis = z, rate = Omega }}
rigid yoke {{ mass = 0 kg }}
joint teeter = revolute(hub, yoke) {{ axis = y, spring = 50 N*m/rad }}
for i in 0..2 {{
    let radial = rotate(z, i * 180 deg) * x
    rigid_rod blade[i] {{ from = e * radial, to = (e + L) * radial, mass = m }}
    joint root[i] = fixed(yoke @ (e * radial), blade[i].start)
    initial spin of blade[i] = Omega about z
}}
initial spin of hub = Omega about z
initial spin of yoke = Omega about z
output root0 = root[0].force.in(yoke), drive = drive.force, beta = teeter.angle
solve hht {{ dt = 1 ms, until = 0.2 s }}
"
    )
}

#[test]
fn models_without_a_steady_motion_are_refused_with_e0605_or_frozen_on_request() {
    // A rotor on a non-rotating flexible mast: periodic (the issue: a frozen teeter mode at
    // 252.5 rad/s against 31.4 in the run).
    let err = modes_of("teeter", &teetering(true), false)
        .err()
        .expect("refused");
    assert_eq!(err.code, Code::E0605);
    assert!(err.message.contains("does not turn"), "{}", err.message);
    assert!(err.hint.as_deref().unwrap_or("").contains("mbd stability"));
    assert!(!err.labels.is_empty());
    let frozen = modes_of("teeter", &teetering(true), true).expect("frozen");
    assert!(matches!(frozen.frame, Frame::Frozen { .. }));
    // On the ground the same rotor is steady: its teeter mode in the rotating frame,
    // sqrt(Omega^2 + K / I_teeter) (two rods: I = 2 m ((e + L)^3 - e^3) / (3 L)).
    let m = modes_of("teeter", &teetering(false), false).expect("modes");
    let it = 2.0 * 8.0 * (2.2f64.powi(3) - 0.2f64.powi(3)) / (3.0 * 2.0);
    let exact = (31.4f64 * 31.4 + 50.0 / it).sqrt();
    // Measured: 8e-14.
    within(
        &format!("{} vs {exact}", m.modes[0].omega()),
        (m.modes[0].omega() - exact).abs(),
        3e-13 * exact,
    );
    // The windmill (a rotor on a slider tower) and a pendulum swinging through the bottom.
    let windmill = crate::common::read("models/windmill.mbd");
    assert_eq!(
        modes_of("windmill", &windmill, false).err().map(|d| d.code),
        Some(Code::E0605)
    );
    let pendulum = crate::common::read("models/pendulum.mbd");
    let d = modes_of("pendulum", &pendulum, false)
        .err()
        .expect("refused");
    assert!(
        d.code == Code::E0605 && d.message.contains("accelerates"),
        "{}",
        d.message
    );
    // Spinning with gravity across the spin axis: the equations turn with the blade.
    let across = rotor(Body::Rod, Hinge::Flap, 2, 0.0, 100.0, 20.0).replace(
        "ground earth",
        "ground earth\ngravity = (0, -9.81, 0) m/s^2",
    );
    let d = modes_of("across", &across, false).err().expect("refused");
    assert!(d.code == Code::E0605, "{}", d.message);
}

#[test]
fn the_modes_command_says_why_it_gives_fewer_modes_or_refuses() {
    let rotor_file = temp(
        "flap.mbd",
        &rotor(Body::Rod, Hinge::Flap, 1, 0.0, 100.0, 20.0),
    );
    let o = mbd(&[
        "modes",
        rotor_file.to_str().unwrap_or_default(),
        "--count",
        "6",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let table = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(table
        .starts_with("mode,frequency_hz,omega_rad_s,damping_ratio,real_per_s,imag_rad_s,frame\n"));
    assert!(table.contains(",rotating\n"), "{table}");
    assert!(
        stderr(&o).contains("6 modes were asked for; the model has 1"),
        "{}",
        stderr(&o)
    );
    let mast = temp("teeter.mbd", &teetering(true));
    let o = mbd(&["modes", mast.to_str().unwrap_or_default()]);
    assert_eq!(code(&o), 3);
    assert!(stderr(&o).contains("E0605"), "{}", stderr(&o));
    let o = mbd(&[
        "modes",
        mast.to_str().unwrap_or_default(),
        "--frozen",
        "--count",
        "2",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let table = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        table.lines().skip(1).all(|l| l.ends_with(",frozen")),
        "{table}"
    );
    assert!(stderr(&o).contains("FROZEN-TIME"), "{}", stderr(&o));
}

#[test]
fn a_fan_plot_follows_the_flap_mode_against_the_rotor_speed() {
    let file = temp(
        "fan.mbd",
        &rotor(Body::Rod, Hinge::Flap, 1, 0.3, 100.0, 20.0),
    );
    let (csv, svg) = (temp("fan.csv", ""), temp("fan.svg", ""));
    // Units in the range: 0 to 300 rpm in steps of 100 rpm.
    let o = mbd(&[
        "modes",
        file.to_str().unwrap_or_default(),
        "--sweep",
        "Omega=0rpm:300rpm:100rpm",
        "-o",
        csv.to_str().unwrap_or_default(),
        "--chart",
        svg.to_str().unwrap_or_default(),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    // Off a terminal, a line per finished value.
    assert_eq!(stderr(&o).matches("Omega = ").count(), 4, "{}", stderr(&o));
    let text = std::fs::read_to_string(&csv).expect("csv");
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("Omega,mode,frequency_hz,omega_rad_s,damping_ratio,real_per_s,imag_rad_s,frame,rotor_speed_rad_s")
    );
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    assert_eq!(rows.len(), 4);
    for (k, r) in rows.iter().enumerate() {
        let omega = k as f64 * 100.0 * std::f64::consts::TAU / 60.0;
        let num = |i: usize| r[i].parse::<f64>().unwrap_or(f64::NAN);
        within(
            "(num(0) - omega).abs()",
            (num(0) - omega).abs(),
            6e-16 * omega.max(1.0),
        ); // measured 1.7e-16 * omega.max(1.0)
        assert_eq!(r[1], "1");
        let exact = closed_form(Hinge::Flap, 0.3, 100.0, omega);
        within(
            &format!("{r:?} vs {exact}"),
            (num(3) - exact).abs(),
            4e-11 * exact,
        ); // measured 1.1e-11 * exact
        within(
            "(num(8) - omega).abs()",
            (num(8) - omega).abs(),
            6e-16 * omega.max(1.0),
        ); // measured 1.7e-16 * omega.max(1.0)
    }
    let chart = std::fs::read_to_string(&svg).expect("svg");
    crate::charts::check(&chart, Some("fan"));
    assert!(
        chart.contains("1/rev") && chart.contains("mode 1") && chart.contains("Re s [1/s]"),
        "per-rev lines, the mode and the real parts' panel"
    );
    // A unit that is not an angular velocity is refused before any run.
    let o = mbd(&[
        "modes",
        file.to_str().unwrap_or_default(),
        "--sweep",
        "Omega=0m:3m:1m",
        "-o",
        csv.to_str().unwrap_or_default(),
    ]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
}
