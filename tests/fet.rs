//! Time finite elements (issue 6, THEORY §8) against independent references: the trapezoidal
//! rule in closed form on a linear oscillator, the pendulum's RK4 reference, Euler's equations
//! for a free body (adaptive Dormand-Prince), the rotating beam's exact rigid rotation, the
//! two-bar's reduced equations; and where the scheme fails, as THEORY §8.2 says it does.

use crate::common::{above, within};
use crate::common::{read, simulate, simulate_text};
use crate::pendulum::{final_error, sawtooth, Reference};
use crate::reference::{free_body, TwoBar};
use crate::rigid::{angle_between, com_error, order, overrides, two_bar, FREE_BODY, M};
use mbd::settings::{Method, Request};
use std::f64::consts::PI;

fn fet() -> Request {
    Request {
        method: Some(Method::Fet),
        ..Request::default()
    }
}

/// Least-squares slope of log(error) against log(dt).
fn slope(dts: &[f64], errs: &[f64]) -> f64 {
    let n = dts.len() as f64;
    let xs: Vec<f64> = dts.iter().map(|d| d.ln()).collect();
    let ys: Vec<f64> = errs.iter().map(|e| e.ln()).collect();
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    xs.iter()
        .zip(&ys)
        .map(|(x, y)| (x - mx) * (y - my))
        .sum::<f64>()
        / xs.iter().map(|x| (x - mx).powi(2)).sum::<f64>()
}

/// A rigid body on a prismatic joint with a linear spring: `x'' = -(k/m) x`, with the five
/// other motions held by the joint's multipliers.
const OSCILLATOR: &str = "model oscillator
param k = 400 N/m
ground earth
rigid b { mass = 1 kg, inertia = (1, 1, 1) kg*m^2, velocity = (1, 0, 0) m/s }
joint slide = prismatic(earth, b) { axis = x, spring = k }
output x = slide.displacement, v = b.velocity.x, e = total_energy
solve hht(alpha = -0.1) { dt = 0.01 s, until = 100 s }
";

/// On a linear problem FET is the trapezoidal rule: every step equals the closed-form
/// trapezoidal recursion, and over 10,000 steps at omega h = 0.2 the energy (a quadratic
/// invariant of the trapezoidal rule) is kept to round-off, where HHT alpha = -0.1 loses 27 %.
#[test]
fn fet_is_the_trapezoidal_rule_on_a_linear_oscillator_and_keeps_its_amplitude() {
    let tr =
        simulate_text("oscillator.mbd", OSCILLATOR, fet()).unwrap_or_else(|(_, m)| panic!("{m}"));
    let (x, v, e) = (tr.col("x"), tr.col("v"), tr.col("e"));
    assert_eq!(x.len(), 10_001);
    // Trapezoidal rule: (I - h/2 J) y_{n+1} = (I + h/2 J) y_n, J = [0 1; -w2 0].
    let (w2, h) = (400.0f64, 0.01f64);
    let q = (h / 2.0).powi(2) * w2;
    let (mut xt, mut vt) = (0.0f64, 1.0f64);
    let mut worst = 0.0f64;
    for k in 1..x.len() {
        let (xr, vr) = (xt + h / 2.0 * vt, vt - h / 2.0 * w2 * xt);
        // Solve [1, -h/2; h/2 w2, 1] y = (xr, vr).
        xt = (xr + h / 2.0 * vr) / (1.0 + q);
        vt = (vr - h / 2.0 * w2 * xr) / (1.0 + q);
        worst = worst.max((x[k] - xt).abs() * 20.0).max((v[k] - vt).abs());
    }
    let drift = e
        .iter()
        .map(|ek| (ek - 0.5).abs() / 0.5)
        .fold(0.0, f64::max);
    let hht = simulate_text("oscillator.mbd", OSCILLATOR, Request::default())
        .unwrap_or_else(|(_, m)| panic!("{m}"));
    let hht_loss = 1.0 - hht.col("e").last().copied().unwrap_or(0.0) / 0.5;
    eprintln!("oscillator, 10,000 steps at omega h = 0.2: FET from the trapezoidal rule {worst:.3e} (of the amplitude), energy drift {drift:.3e}; HHT -0.1 energy loss {hht_loss:.3}");
    // Round-off of 10,000 steps: measured 2e-13.
    within(
        &format!("FET departs from the trapezoidal rule by {worst:.3e}"),
        worst,
        4e-13,
    ); // measured 1.1e-13
    within(
        &format!("FET changes the energy by {drift:.3e}"),
        drift,
        1.5e-13,
    ); // measured 3.9e-14
    above(
        &format!("HHT -0.1 should dissipate, lost {hht_loss}"),
        hht_loss,
        0.2,
    );
}

/// The pendulum's position at 1 s converges at second order (errors against the RK4
/// reference of `pendulum.rs`).
#[test]
fn fet_is_second_order_on_the_pendulum() {
    let dts = [0.01, 0.005, 0.0025, 0.00125];
    let errs: Vec<f64> = dts
        .iter()
        .map(|&dt| {
            let tr = simulate(
                "models/pendulum.mbd",
                &[],
                Request {
                    dt: Some(dt),
                    ..fet()
                },
            );
            final_error(&tr, &Reference::new(1.5, dt, (1.0 / dt).round() as usize))
        })
        .collect();
    let p = slope(&dts, &errs);
    eprintln!("pendulum FET errors at 1 s: {errs:?}; observed order {p:.3}");
    assert!((1.9..=2.1).contains(&p), "observed order {p}");
    // The paper's accuracy at its step (0.02 % after 200 steps).
    within(&format!("error at dt = 0.005: {}", errs[1]), errs[1], 2e-4);
}

/// A torque-free asymmetric body: the orientation at 10 s converges at second order against
/// Euler's equations, the inertial angular momentum is kept to the Newton tolerance
/// (`g_{n+1} = g_n` for a single body), and the energy error stays small without drift.
#[test]
fn fet_is_second_order_on_a_free_body_and_keeps_its_angular_momentum() {
    let j = [1.0, 2.0, 3.0];
    let t_end = 10.0;
    let (r_ref, _) = free_body(j, [0.3, 1.0, 0.8], &[t_end])[0];
    let mut errs = Vec::new();
    let dts = [0.02, 0.01, 0.005];
    for dt in dts {
        let tr = simulate_text(
            "free_body.mbd",
            FREE_BODY,
            Request {
                method: Some(Method::Fet),
                ..overrides(dt, t_end)
            },
        )
        .unwrap_or_else(|(_, m)| panic!("{m}"));
        let rot = |k: usize| -> M {
            std::array::from_fn(|i| {
                std::array::from_fn(|m| tr.col(&format!("b.rotation.r{}{}", i + 1, m + 1))[k])
            })
        };
        let last = tr.rows.len() - 1;
        let e = angle_between(&rot(last), &r_ref);
        // Inertial angular momentum R J R^T w.
        let h = |k: usize| -> [f64; 3] {
            let r = rot(k);
            let w: [f64; 3] =
                ["x", "y", "z"].map(|c| tr.col(&format!("b.angular_velocity.{c}"))[k]);
            let wb: [f64; 3] = std::array::from_fn(|i| (0..3).map(|m| r[m][i] * w[m]).sum());
            std::array::from_fn(|i| (0..3).map(|m| r[i][m] * j[m] * wb[m]).sum())
        };
        let h0 = h(0);
        let norm = (h0.iter().map(|x| x * x).sum::<f64>()).sqrt();
        let dh = (0..=last)
            .map(|k| {
                let hk = h(k);
                ((0..3).map(|i| (hk[i] - h0[i]).powi(2)).sum::<f64>()).sqrt() / norm
            })
            .fold(0.0, f64::max);
        let energy = tr.col("total_energy");
        let de = energy
            .iter()
            .map(|x| (x - energy[0]).abs() / energy[0])
            .fold(0.0, f64::max);
        eprintln!("free body FET dt {dt}: rotation error {e:.3e} rad, angular momentum drift {dh:.3e}, energy error {de:.3e}");
        within(&format!("angular momentum drifts by {dh:.3e}"), dh, 5e-11); // measured 1.3e-11
                                                                            // Bounded, O(h^2): measured 1.2e-4 at dt = 0.02 (omega h ~ 0.025).
        within(&format!("energy error {de:.3e}"), de, 6e-5); // measured 1.7e-5
        errs.push(e);
    }
    for w in errs.windows(2) {
        let p = order(w[0], w[1]);
        assert!((1.9..=2.1).contains(&p), "order {p:.3} (errors {errs:?})");
    }
}

/// P1: the rotating beam's rigid rotation after half a turn converges at second order.
#[test]
fn fet_is_second_order_on_the_rotating_beam() {
    let steps = [90usize, 180, 360, 720];
    let errs: Vec<f64> = steps
        .iter()
        .map(|&n| {
            let tr = simulate(
                "models/rotating_beam.mbd",
                &[],
                Request {
                    steps: Some(n),
                    ..fet()
                },
            );
            let phi = tr.col("phi");
            ((phi[phi.len() - 1] - PI) / PI).abs()
        })
        .collect();
    let pairwise: Vec<f64> = errs.windows(2).map(|w| order(w[0], w[1])).collect();
    eprintln!("rotating beam FET errors {errs:?}, pairwise orders {pairwise:.3?}");
    for p in pairwise {
        assert!((1.9..=2.1).contains(&p), "order {p:.3} (errors {errs:?})");
    }
    // 360 steps: measured 2.6e-5 (HHT -0.1: 9.6e-6).
    within(&format!("error at 360 steps {}", errs[2]), errs[2], 5e-5);
}

/// P3, the rigid two-bar, at the paper's step: bar 2's centre of mass follows the reduced
/// equations up to 10 s as closely as HHT does, and converges at second order.
#[test]
fn fet_follows_the_two_bar_reduced_equations() {
    let reference = TwoBar::paper_case1();
    let error = |dt: f64| -> f64 {
        let tr = two_bar(dt, 10.0, fet()).unwrap_or_else(|(_, m)| panic!("{m}"));
        let t = tr.col("t");
        let refs = reference.case1(PI / 2.0, &t);
        (0..t.len())
            .map(|k| com_error(&tr, k, &refs[k]))
            .fold(0.0, f64::max)
    };
    let errs: Vec<f64> = [0.05, 0.025, 0.0125].map(error).to_vec();
    eprintln!("two-bar FET, t <= 10 s: max centre-of-mass errors {errs:?} m");
    within("FET centre-of-mass error at dt 0.05 s [m]", errs[0], 3e-2); // measured 9.8e-3
                                                                        // The README's claim: 2.8 times more accurate than HHT -0.1 at the paper's step.
    let hht = {
        let tr = two_bar(0.05, 10.0, Request::default()).unwrap_or_else(|(_, m)| panic!("{m}"));
        let t = tr.col("t");
        let refs = reference.case1(PI / 2.0, &t);
        (0..t.len())
            .map(|k| com_error(&tr, k, &refs[k]))
            .fold(0.0, f64::max)
    };
    eprintln!(
        "two-bar HHT -0.1 at dt 0.05 s: {hht:.3e} m, {:.2} times FET's",
        hht / errs[0]
    );
    above("HHT error / FET error at dt 0.05 s", hht / errs[0], 2.5); // measured 2.77
    for w in errs.windows(2) {
        let p = order(w[0], w[1]);
        assert!((1.8..=2.3).contains(&p), "order {p:.3} (errors {errs:?})");
    }
}

/// THEORY §8.2: without numerical dissipation an inconsistency is never damped. A kink in a
/// prescribed motion (the two-bar's drive speed jumps from 0.5 to 0.6 rad/s within one step at
/// 10 s) leaves a step-to-step oscillation in the drive torque that FET keeps undiminished to the
/// end of the run, while HHT alpha = -0.1 damps it by orders of magnitude.
#[test]
fn fet_keeps_the_oscillation_a_kinked_drive_excites_and_hht_damps_it() {
    let text = read("models/two_bar_spin.mbd")
        .replace(
            "rate = Omega }",
            "rate = piecewise { 0 s: 0.5 rad/s, 10 s: 0.5 rad/s, 10.05 s: 0.6 rad/s } }",
        )
        .replace("until = 50 s", "until = 20 s");
    assert!(text.contains("10.05 s"), "the drive was not replaced");
    let torque = |o: Request| -> Vec<f64> {
        simulate_text("kink.mbd", &text, o)
            .unwrap_or_else(|(_, m)| panic!("{m}"))
            .col("torque")
    };
    let (f, h) = (torque(fet()), torque(Request::default()));
    let (f_kink, f_late) = (sawtooth(&f, 206..240), sawtooth(&f, 360..398));
    let (h_kink, h_late) = (sawtooth(&h, 206..240), sawtooth(&h, 360..398));
    eprintln!("drive-torque sawtooth after the kink / at the end: FET {f_kink:.3e} / {f_late:.3e} N m, HHT -0.1 {h_kink:.3e} / {h_late:.3e} N m");
    above(&format!("the kink must excite FET: {f_kink}"), f_kink, 5e-3); // measured 1.4e-2
    above(
        &format!("FET has no dissipation: {f_kink} -> {f_late}"),
        f_late,
        0.7 * f_kink,
    );
    within(
        &format!("HHT -0.1 damps it: {h_kink} -> {h_late}"),
        h_late,
        8e-6 * h_kink,
    ); // measured 2.4e-6 * h_kink
}

/// THEORY §8.2: the midpoint rule is not stable for stiff beams in large motion (Simo & Tarnow
/// 1992). The two-bar made of near-rigid beams (P3's `two_bar_beams`) runs through 50 s with HHT,
/// but under FET the energy of its stiff modes grows until Newton fails; the diagnostic says so
/// and points to HHT, and the rows before the failure are kept.
#[test]
fn fet_on_stiff_beams_in_large_motion_fails_with_a_hint() {
    let text = read("models/two_bar_beams.mbd");
    let Err((tr, message)) = simulate_text("models/two_bar_beams.mbd", &text, fet()) else {
        panic!("FET is expected to fail on the near-rigid beams (THEORY §8.2)");
    };
    let t = tr.col("t");
    let reached = t.last().copied().unwrap_or(0.0);
    eprintln!("two_bar_beams under FET fails at {reached} s: {message}");
    // Measured: 6.1 s (step 123 of 1,000), the README's figure.
    above(&format!("fails at {reached} s"), reached, 5.5);
    within(&format!("fails at {reached} s"), reached, 6.7);
    assert!(message.contains("time element"), "{message}");
}
