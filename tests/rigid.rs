//! The rigid multibody runtime against independent references (issue 4): a free asymmetric
//! rigid body against Euler's equations, the two-bar mechanism of P3 and P4 against its reduced
//! equations, the paper's Fig. 14 stability finding, and the two rotation treatments.
//! References are integrated here by the adaptive Dormand-Prince code of
//! `reference/dormand_prince.rs` (relative tolerance 1e-12 or tighter).

use crate::common::{above, within};
use crate::common::{read, simulate_text, Trace};
use crate::reference::{free_body, TwoBar, TwoBarState};
use mbd::settings::{Request, Rotations};
use mbd::solve::RunStats;
use std::f64::consts::PI;

pub(crate) type M = [[f64; 3]; 3];

fn mat_t_mul(a: &M, b: &M) -> M {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[k][i] * b[k][j]).sum();
        }
    }
    c
}

/// Geodesic angle between two rotation matrices.
pub(crate) fn angle_between(a: &M, b: &M) -> f64 {
    let r = mat_t_mul(a, b);
    ((r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0)
        .clamp(-1.0, 1.0)
        .acos()
}

pub(crate) fn overrides(dt: f64, until: f64) -> Request {
    Request {
        dt: Some(dt),
        until: Some(until),
        ..Request::default()
    }
}

pub(crate) fn order(e_coarse: f64, e_fine: f64) -> f64 {
    (e_coarse / e_fine).log2()
}

pub(crate) const FREE_BODY: &str = "model free_body
rigid b { mass = 2 kg, inertia = (1, 2, 3) kg*m^2, angular_velocity = (0.3, 1.0, 0.8) rad/s }
output b.rotation, b.angular_velocity, total_energy
solve hht(alpha = -0.1) { dt = 0.01 s, until = 10 s }
";

/// A torque-free body with principal moments (1, 2, 3) kg m^2 spinning mostly about its
/// intermediate axis (a tumbling motion). Measured: the orientation error at 10 s is second
/// order in dt; energy and angular momentum drift stay below the stated bounds.
#[test]
fn free_asymmetric_body_follows_eulers_equations() {
    let j = [1.0, 2.0, 3.0];
    let w0 = [0.3, 1.0, 0.8];
    let t_end = 10.0;
    let reference = free_body(j, w0, &[t_end]);
    let (r_ref, w_ref) = reference[0];
    let mut errors = Vec::new();
    for dt in [0.02, 0.01, 0.005] {
        let tr = simulate_text("free_body.mbd", FREE_BODY, overrides(dt, t_end))
            .unwrap_or_else(|(_, m)| panic!("{m}"));
        let last = tr.rows.len() - 1;
        let r: M = std::array::from_fn(|i| {
            std::array::from_fn(|k| tr.col(&format!("b.rotation.r{}{}", i + 1, k + 1))[last])
        });
        let e = angle_between(&r, &r_ref);
        // Body-frame angular velocity from the inertial one.
        let w: [f64; 3] = ["x", "y", "z"].map(|c| tr.col(&format!("b.angular_velocity.{c}"))[last]);
        let wb: [f64; 3] = std::array::from_fn(|i| (0..3).map(|k| r[k][i] * w[k]).sum());
        let ew = (0..3).map(|i| (wb[i] - w_ref[i]).abs()).fold(0.0, f64::max);
        // Energy and inertial angular momentum R J w* drift over the run.
        let energy = tr.col("total_energy");
        let e0 = energy[0];
        let de = energy
            .iter()
            .map(|x| (x - e0).abs() / e0)
            .fold(0.0, f64::max);
        let h = |k: usize| -> [f64; 3] {
            let r: M = std::array::from_fn(|i| {
                std::array::from_fn(|m| tr.col(&format!("b.rotation.r{}{}", i + 1, m + 1))[k])
            });
            let w: [f64; 3] =
                ["x", "y", "z"].map(|c| tr.col(&format!("b.angular_velocity.{c}"))[k]);
            let wb: [f64; 3] = std::array::from_fn(|i| (0..3).map(|m| r[m][i] * w[m]).sum());
            std::array::from_fn(|i| (0..3).map(|m| r[i][m] * j[m] * wb[m]).sum())
        };
        let (h0, h1) = (h(0), h(last));
        let dh = ((0..3).map(|i| (h1[i] - h0[i]).powi(2)).sum::<f64>()
            / (0..3).map(|i| h0[i].powi(2)).sum::<f64>())
        .sqrt();
        eprintln!("free body dt {dt}: rotation error {e:.3e} rad, omega* error {ew:.3e}, energy drift {de:.3e}, momentum drift {dh:.3e}");
        errors.push((e, de, dh));
    }
    for w in errors.windows(2) {
        let p = order(w[0].0, w[1].0);
        above(
            &format!("rotation error order {p:.2} (errors {errors:?})"),
            p,
            1.8,
        );
    }
    let (e, de, dh) = errors[2];
    // At dt = 0.005 s (omega h ~ 0.006): orientation within 1e-4 rad after 10 s; HHT's
    // dissipation and the discretization change energy and momentum by less than 2e-5
    // (measured 3.5e-6 and 7.5e-6).
    within(&format!("rotation error {e:.3e}"), e, 1e-4);
    assert!(
        de < 2e-5 && dh < 2e-5,
        "energy drift {de:.3e}, momentum drift {dh:.3e}"
    );
}

/// The model's bar-2 centre-of-mass channels against the reference at sample `k`.
pub(crate) fn com_error(tr: &Trace, k: usize, s: &TwoBarState) -> f64 {
    let x = ["xc2", "yc2", "zc2"].map(|c| tr.col(c)[k]);
    (0..3).map(|i| (x[i] - s.xc[i]).powi(2)).sum::<f64>().sqrt()
}

fn times(tr: &Trace) -> Vec<f64> {
    tr.col("t")
}

pub(crate) fn two_bar(dt: f64, until: f64, extra: Request) -> Result<Trace, (Trace, String)> {
    let text = read("models/two_bar.mbd");
    simulate_text(
        "models/two_bar.mbd",
        &text,
        Request {
            dt: Some(dt),
            until: Some(until),
            ..extra
        },
    )
}

/// P3 at the paper's dt = 0.05 s: bar 2's centre of mass within the stated bound of the
/// reduced equations up to 10 s, and second-order convergence over the full 50 s.
#[test]
fn two_bar_case_one_matches_the_reduced_equations() {
    let reference = TwoBar::paper_case1();
    let tr = two_bar(0.05, 10.0, Request::default()).unwrap_or_else(|(_, m)| panic!("{m}"));
    let t = times(&tr);
    let refs = reference.case1(PI / 2.0, &t);
    let worst = (0..t.len())
        .map(|k| com_error(&tr, k, &refs[k]))
        .fold(0.0, f64::max);
    let th2_err = (0..t.len())
        .map(|k| (tr.col("theta2")[k] - (refs[k].th2 - PI / 2.0)).abs())
        .fold(0.0, f64::max);
    eprintln!("two-bar dt 0.05, t <= 10 s: max centre-of-mass error {worst:.3e} m, theta2 {th2_err:.3e} rad");
    // Measured 2.7e-2 m (theta2 within 0.093 rad of 17.47 rad): the accuracy of a second-order
    // scheme with HHT's phase error at omega h up to 0.2 (the trapezoidal rule: 0.053 rad).
    within(
        &format!("centre-of-mass error {worst:.3e} m up to 10 s"),
        worst,
        3.5e-2,
    );
    // Convergence over 50 s: maximum centre-of-mass error over the run. Bar 2 turns 64 times,
    // so the phase error must be small for the error to be in the asymptotic range: from
    // dt = 2.5 ms (measured 0.50 m at 10 ms and 0.24 m at 5 ms, not yet asymptotic).
    let mut errs = Vec::new();
    for dt in [0.0025, 0.00125, 0.000625] {
        let tr = two_bar(dt, 50.0, Request::default()).unwrap_or_else(|(_, m)| panic!("{m}"));
        let t = times(&tr);
        let refs = reference.case1(PI / 2.0, &t);
        let e = (0..t.len())
            .map(|k| com_error(&tr, k, &refs[k]))
            .fold(0.0, f64::max);
        eprintln!("two-bar dt {dt}, 50 s: max centre-of-mass error {e:.3e} m");
        errs.push(e);
    }
    for w in errs.windows(2) {
        let p = order(w[0], w[1]);
        above(&format!("order {p:.2} (errors {errs:?})"), p, 1.8);
    }
}

/// The conformal rotation vector of bar 2 changes state many times (|c| <= 4, jumps of about 8
/// as the rotation passes pi) while the centre of mass moves smoothly through every change
/// (the paper's Fig. 10). Both rotation treatments report the principal state.
#[test]
fn changes_of_state_leave_the_motion_smooth() {
    for rotations in [Rotations::Incremental, Rotations::Conformal] {
        let tr = two_bar(
            0.01,
            50.0,
            Request {
                rotations: Some(rotations),
                ..Request::default()
            },
        )
        .unwrap_or_else(|(_, m)| panic!("{m}"));
        let c: Vec<[f64; 3]> = (0..tr.rows.len())
            .map(|k| ["c1", "c2", "c3"].map(|n| tr.col(n)[k]))
            .collect();
        let norm = |v: &[f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        assert!(c.iter().all(|v| norm(v) <= 4.0 + 1e-9));
        let jumps = c
            .windows(2)
            .filter(|w| norm(&[w[1][0] - w[0][0], w[1][1] - w[0][1], w[1][2] - w[0][2]]) > 4.0)
            .count();
        // The largest step-to-step move of the centre of mass against its speed: smooth.
        let (x, v) = (
            ["xc2", "yc2", "zc2"].map(|n| tr.col(n)),
            ["vxc2", "vyc2", "vzc2"].map(|n| tr.col(n)),
        );
        let mut ratio: f64 = 0.0;
        for k in 1..tr.rows.len() {
            let dx = (0..3)
                .map(|i| (x[i][k] - x[i][k - 1]).powi(2))
                .sum::<f64>()
                .sqrt();
            let speed = (0..3)
                .map(|i| v[i][k].powi(2).max(v[i][k - 1].powi(2)))
                .sum::<f64>()
                .sqrt();
            ratio = ratio.max(dx / (speed * 0.01 + 1e-12));
        }
        eprintln!(
            "{rotations:?}: {jumps} changes of state of c; largest |dx| / (|v| dt) = {ratio:.3}"
        );
        // Bar 2 turns about 64 times: at least one change of state per turn.
        assert!(jumps >= 60, "{jumps} changes of state");
        within(&format!("the centre of mass jumped: {ratio}"), ratio, 1.05);
    }
}

/// The paper's Fig. 14: at dt = 0.05 s, alpha = 0 grows unstable (here: fails) before 50 s,
/// alpha = -0.05 later, and alpha = -0.1 (in the paper) not at all. Growth is detected from bar
/// 2's centre-of-mass acceleration: the onset is the first time it exceeds twice the largest
/// acceleration of the exact solution, or the failure time.
///
/// At alpha = -0.1 the discrete motion is chaotic after the load reversal (18 s), and whether
/// its acceleration ever exceeds the threshold depends on the step's last digits and on
/// Newton's path: with the acceleration predictor alone it stayed under (92.6 against 92.8
/// m/s^2) at exactly 0.05 s but crossed it at 19.2, 19.7, 19.6, 21.0 and 19.6 s at 0.0498,
/// 0.0499, 0.04999, 0.0501 and 0.0502 s. What holds at every one of these steps is the order
/// and the delay: alpha = 0 at 11.4 to 11.7 s, -0.05 at 13.3 to 13.7 s, -0.1 after 18.3 s
/// or never, and every alpha = -0.1 run reaches 50 s.
#[test]
fn numerical_dissipation_delays_the_instability() {
    let reference = TwoBar::paper_case1();
    let fine: Vec<f64> = (0..=5000).map(|k| k as f64 * 0.01).collect();
    let amax = reference
        .case1(PI / 2.0, &fine)
        .iter()
        .map(|s| (s.ac[0].powi(2) + s.ac[1].powi(2) + s.ac[2].powi(2)).sqrt())
        .fold(0.0, f64::max);
    // The onset, and whether the run reached its end.
    let onset = |alpha: f64| -> (Option<f64>, bool) {
        let (tr, failed) = match two_bar(
            0.05,
            50.0,
            Request {
                alpha: Some(alpha),
                ..Request::default()
            },
        ) {
            Ok(tr) => (tr, None),
            Err((tr, _)) => {
                let t = tr.col("t");
                let end = t.last().copied().unwrap_or(0.0);
                (tr, Some(end))
            }
        };
        let t = tr.col("t");
        let a = ["axc2", "ayc2", "azc2"].map(|n| tr.col(n));
        let grown = (0..t.len())
            .find(|&k| (a[0][k].powi(2) + a[1][k].powi(2) + a[2][k].powi(2)).sqrt() > 2.0 * amax);
        (grown.map(|k| t[k]).or(failed), failed.is_none())
    };
    let ((o0, _), (o5, _), (o10, ended)) = (onset(0.0), onset(-0.05), onset(-0.1));
    eprintln!("largest exact acceleration {amax:.3} m/s^2; onset: alpha 0 {o0:?} s, -0.05 {o5:?} s, -0.1 {o10:?} s (paper: 22.15 s, 40.65 s, none)");
    let o0 = o0.expect("alpha = 0 stays bounded, unlike the paper's");
    let o5 = o5.expect("alpha = -0.05 stays bounded, unlike the paper's");
    // Measured: 11.4 s and 13.3 s (the paper: 22.15 s and 40.65 s).
    assert!(o5 < 50.0, "alpha -0.05 at {o5} s");
    above("delay of the onset by alpha = -0.05 [s]", o5 - o0, 0.5); // measured 1.9 s
                                                                    // Measured 18.4 s, 5.1 s after alpha = -0.05 (at the neighbouring steps 5.9 to 7.8 s).
    if let Some(o10) = o10 {
        above("delay of the onset by alpha = -0.1 [s]", o10 - o5, 2.5);
    }
    assert!(ended, "alpha = -0.1 runs its 50 s");
}

/// P4: the drive imposed on the mechanism at rest is an impulse; the consistent start gives
/// th2dot(0+) = (D2/D3) Omega sin th2(0) = 0.75 rad/s, after which th2 and the drive torque follow
/// the exact solution (th2'' = -Omega^2/2 sin 2 th2).
#[test]
fn two_bar_case_two_starts_impulsively_and_follows_the_exact_solution() {
    let text = read("models/two_bar_spin.mbd") + "output th2dot = j2.rate\n";
    let reference = TwoBar::paper_case2();
    let th2dot0 = reference.impulsive_th2dot(0.5, PI / 2.0);
    within("(th2dot0 - 0.75).abs()", (th2dot0 - 0.75).abs(), 1e-12);
    let mut errs = Vec::new();
    for dt in [0.05, 0.025, 0.0125] {
        let tr = simulate_text("two_bar_spin.mbd", &text, overrides(dt, 50.0))
            .unwrap_or_else(|(_, m)| panic!("{m}"));
        let start = tr.col("th2dot")[0];
        within(
            &format!("th2dot(0+) = {start}"),
            (start - 0.75).abs(),
            4e-16,
        ); // measured 1.1e-16
        let t = times(&tr);
        let refs = reference.case2(0.5, PI / 2.0, th2dot0, &t);
        let (th2, torque) = (tr.col("theta2"), tr.col("torque"));
        let e_th = (0..t.len())
            .map(|k| (th2[k] - (refs[k].th2 - PI / 2.0)).abs())
            .fold(0.0, f64::max);
        let tmax = refs.iter().map(|s| s.torque.abs()).fold(0.0, f64::max);
        let e_tq = (1..t.len())
            .map(|k| (torque[k] - refs[k].torque).abs())
            .fold(0.0, f64::max)
            / tmax;
        eprintln!("two-bar case II dt {dt}: max th2 error {e_th:.3e} rad, max torque error {e_tq:.3e} of {tmax:.3e} N m");
        errs.push((e_th, e_tq));
    }
    let p = order(errs[1].0, errs[2].0);
    above(&format!("th2 order {p:.2}: {errs:?}"), p, 1.8);
    // dt = 0.05 s (the paper's): th2 within 0.05 rad over 6.5 turns, torque within 5 %.
    assert!(errs[0].0 < 0.05 && errs[0].1 < 0.05, "{errs:?}");
}

/// The two rotation treatments on P3 up to 10 s: both converge to the reduced equations; the
/// incremental (SE(3)) one, the default, is the more accurate at every step size.
#[test]
fn rotation_treatments_compared_on_the_two_bar() {
    let reference = TwoBar::paper_case1();
    let mut table = Vec::new();
    for dt in [0.02, 0.01, 0.005] {
        let mut row = Vec::new();
        for rotations in [Rotations::Incremental, Rotations::Conformal] {
            let tr = two_bar(
                dt,
                10.0,
                Request {
                    rotations: Some(rotations),
                    ..Request::default()
                },
            )
            .unwrap_or_else(|(_, m)| panic!("{m}"));
            let t = times(&tr);
            let refs = reference.case1(PI / 2.0, &t);
            row.push(
                (0..t.len())
                    .map(|k| com_error(&tr, k, &refs[k]))
                    .fold(0.0, f64::max),
            );
        }
        eprintln!(
            "dt {dt}: centre-of-mass error incremental {:.3e} m, conformal {:.3e} m",
            row[0], row[1]
        );
        table.push(row);
    }
    for r in &table {
        assert!(r[0] <= r[1], "incremental less accurate: {table:?}");
    }
    for k in 0..2 {
        let p = order(table[1][k], table[2][k]);
        above(&format!("treatment {k}: order {p:.2} ({table:?})"), p, 1.5);
    }
    let _ = RunStats::default();
}
