//! Floquet's monodromy from the step's own tangent (one run of the period, the directions
//! carried by the converged steps' iteration matrices) against the monodromy of perturbed runs
//! (central differences of 4 n_f runs): the same discrete map, so the same matrix to the
//! truncation and Newton error of the differences, and the same exponents.

use crate::common::{read, within};
use mbd::settings::Request;
use mbd::solve::floquet::{floquet_by, Floquet, Monodromy};

fn both(path: &str, sets: &[&str], period: Option<f64>) -> (Floquet, Floquet) {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let c = mbd::compile(path, &read(path), &sets, Request::default())
        .map_err(|f| format!("{:?}", f.diagnostics))
        .unwrap();
    let sys = &c
        .lowered
        .as_ref()
        .map_err(|d| d.message.clone())
        .unwrap()
        .system;
    let period = period.unwrap_or_else(|| mbd::study::sweep::rotor_period(&c).unwrap());
    let by = |how| {
        floquet_by(sys, &c.settings, period, how, &|| {})
            .map_err(|f| format!("{}: {:?}", f.which(), f.failure))
            .unwrap()
    };
    (by(Monodromy::Tangent), by(Monodromy::Runs))
}

/// The largest entry of `a - b` over the largest of `b`.
fn matrix_difference(a: &Floquet, b: &Floquet) -> f64 {
    let scale = b.monodromy.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a
        .monodromy
        .iter()
        .zip(&b.monodromy)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    diff / scale
}

/// The largest distance between the exponents, in the runs' order (largest multiplier
/// first), over the largest exponent's modulus.
fn exponent_difference(a: &Floquet, b: &Floquet) -> f64 {
    let norm = |re: f64, im: f64| (re * re + im * im).sqrt();
    let scale = b
        .exponents
        .iter()
        .fold(0.0f64, |m, s| m.max(norm(s.re, s.im)));
    a.exponents
        .iter()
        .zip(&b.exponents)
        .fold(0.0f64, |m, (x, y)| m.max(norm(x.re - y.re, x.im - y.im)))
        / scale
}

/// The rigid windmill (SE(3) frames, the revolute joints' angles, the tower's slider),
/// stable and in the ground-resonance band. Measured: monodromies 3.4e-8 and 1.7e-8 apart
/// (relative to the largest entry), exponents 3.0e-8 and 1.6e-8.
#[test]
fn the_tangent_monodromy_of_the_windmill_is_that_of_perturbed_runs() {
    for (omega_bar, m_bound, s_bound) in [("1.0", 1.1e-7, 9e-8), ("1.5", 6e-8, 5e-8)] {
        let (t, r) = both(
            "models/windmill.mbd",
            &[&format!("Omega_bar={omega_bar}")],
            None,
        );
        assert_eq!(t.how, Monodromy::Tangent);
        assert_eq!(r.how, Monodromy::Runs);
        assert_eq!(t.free, 5);
        within(
            &format!("windmill at {omega_bar}: monodromy, tangent vs runs"),
            matrix_difference(&t, &r),
            m_bound,
        );
        within(
            &format!("windmill at {omega_bar}: exponents, tangent vs runs"),
            exponent_difference(&t, &r),
            s_bound,
        );
        // One run of the period against 4 n_f + 1.
        assert!(t.newton_iterations * 10 < r.newton_iterations);
    }
}

/// Beam nodes (rotations apart from their translations, rotary inertia) on a spinning beam,
/// over a part of a revolution: the map of any interval is the same for both. Measured
/// 5.6e-6; 3.7e-5 while the residual was differenced along positions too (at 1e-6 of their
/// scale: digits lost to the centrifugal tension, 1.4e5 N), 1.2e-2 while the beam nodes' rate
/// columns were left out of the matrix, 2.7e-2 while the step of the differences was sized by
/// the stiff modes' accelerations.
#[test]
fn the_tangent_monodromy_of_a_spinning_beam_is_that_of_perturbed_runs() {
    let (t, r) = both("models/rotating_beam.mbd", &["elements=2"], Some(0.02));
    within(
        "rotating beam: monodromy, tangent vs runs",
        matrix_difference(&t, &r),
        1.7e-5,
    );
}
