//! The rotor models against independent references (issue 7; PROBLEMS.md P5, P6; THEORY.md
//! §9.1): the ground-resonance windmill against its nonlinear equations of motion (integrated
//! in `reference/windmill.rs`); the spin-up's lag stability and its angular-momentum balance;
//! and the convergence of the elastic-blade windmill in mesh and time step.

use crate::common::{above, within};
use crate::common::{read, simulate, simulate_text_with, Trace};
use crate::reference::windmill::{windmill_reference, E, IB, MB, OMEGA_T, SB};
use mbd::settings::Request;
use std::f64::consts::PI;

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

fn max_abs(v: impl IntoIterator<Item = f64>) -> f64 {
    v.into_iter().map(f64::abs).fold(0.0, f64::max)
}

/// Largest `|a - b|` over the run relative to the largest `|b|` (the error measure of every
/// check here: "within p % of the channel's peak amplitude").
fn rel_error(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    max_abs(a.iter().zip(b).map(|(x, y)| x - y)) / max_abs(b.iter().copied())
}

fn channels(blades: usize) -> Vec<String> {
    std::iter::once("x_hub".to_string())
        .chain((1..=blades).map(|i| format!("zeta{i}")))
        .collect()
}

// ---------------------------------------------------------------------------------------------
// 1. The windmill against its nonlinear equations
// ---------------------------------------------------------------------------------------------

/// Runs `models/windmill.mbd` (as shipped: HHT alpha -0.1, 3 s, dt 0.5 ms unless `dt` is given)
/// with `blades` and `Omega_bar` set, and returns each channel's error against the reference
/// (rtol 1e-11, see `windmill_reference_is_converged`).
fn windmill_errors(blades: usize, omega_bar: f64, dt: Option<f64>) -> Vec<(String, f64)> {
    let sets = [format!("Omega_bar={omega_bar}"), format!("blades={blades}")];
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let tr = simulate(
        "models/windmill.mbd",
        &sets,
        Request {
            dt,
            ..Request::default()
        },
    );
    let t = tr.col("t");
    assert!(
        (t[t.len() - 1] - 3.0).abs() < 1e-9,
        "the run ends at {}",
        t[t.len() - 1]
    );
    let reference = windmill_reference(blades, omega_bar * OMEGA_T, &t, 1e-11);
    let errors: Vec<(String, f64)> = channels(blades)
        .into_iter()
        .enumerate()
        .map(|(c, name)| {
            let want: Vec<f64> = reference.iter().map(|y| y[c]).collect();
            let e = rel_error(&tr.col(&name), &want);
            (name, e)
        })
        .collect();
    let list: Vec<String> = errors
        .iter()
        .map(|(n, e)| format!("{n} {:.4} %", 100.0 * e))
        .collect();
    eprintln!(
        "windmill, {blades} blades, Omega_bar {omega_bar}, dt {dt:?}: max |error| / peak: {}",
        list.join(", ")
    );
    errors
}

/// Every channel within `bound` of its peak over the whole 3 s at the shipped dt (issue 7 asked
/// for 2 %), and converging: the largest error at dt = 1 ms over the largest at 0.5 ms gives an
/// observed order above 1.7 (HHT is second order; dt must divide 5 ms, see below).
fn assert_windmill(blades: usize, omega_bar: f64, bound: f64) {
    let errors = windmill_errors(blades, omega_bar, None);
    for (name, e) in &errors {
        within(
            &format!("{blades} blades, Omega_bar {omega_bar}: {name} / its peak"),
            *e,
            bound,
        );
    }
    let fine = errors.iter().map(|(_, e)| *e).fold(0.0, f64::max);
    let coarse = windmill_errors(blades, omega_bar, Some(1e-3))
        .iter()
        .map(|(_, e)| *e)
        .fold(0.0, f64::max);
    let p = (coarse / fine).log2();
    eprintln!("windmill, {blades} blades, Omega_bar {omega_bar}: observed order {p:.2} between dt 1 ms and 0.5 ms");
    above(
        &format!("{blades} blades, Omega_bar {omega_bar}: order ({coarse:.3e}, {fine:.3e})"),
        p,
        1.7,
    );
}

/// The reference is converged far below anything checked here: tightening its tolerance a
/// hundredfold (rtol 1e-9 to 1e-11; the output times also cap its step at 0.5 ms) moves no
/// channel by more than 1e-8 of its peak (measured 7e-14) at Omega_bar = 2, where the unstable
/// growth amplifies every error over the 3 s.
#[test]
fn windmill_reference_is_converged() {
    let t: Vec<f64> = (0..=6000).map(|k| k as f64 * 5e-4).collect();
    let omega = 2.0 * OMEGA_T;
    let coarse = windmill_reference(4, omega, &t, 1e-9);
    let fine = windmill_reference(4, omega, &t, 1e-11);
    for c in 0..5 {
        let a: Vec<f64> = coarse.iter().map(|y| y[c]).collect();
        let b: Vec<f64> = fine.iter().map(|y| y[c]).collect();
        let e = rel_error(&a, &b);
        eprintln!("windmill reference, channel {c}: rtol 1e-9 against 1e-11 {e:.3e} of the peak");
        within(&format!("channel {c}: {e:.3e}"), e, 3e-13); // measured 7.3e-14
    }
}

/// No error floor (issue 20, item 4): the windmill's error against its reference keeps falling
/// at HHT's second order as the step halves from 50 to 3.125 us (1 s of P5), to 2.7e-9 of the
/// peak. It used to stop falling at 25 us and grow as `1/h^2` below (the SE(3) increment's
/// `(1 - cos t) / t^2` lost `1e-16 / t^2` of itself to cancellation at a step's rotation
/// `t = Omega h`, and the drive's angle, 27.8 rad at 3 s, rounded each step's rotation of the
/// hub by its `ulp`); then, with those fixed, at 6.25 us (at about 1e-8 of the peak, growing as
/// `1/h`): the accelerations came from the step's increment less `h v`, whose rounding is the
/// same every step of a steady spin, and the rotations' re-orthonormalization turned them by
/// a rounding that changed sides at `pi`. Measured: orders 2.00, 2.00, 2.00 and 2.00 (the
/// largest error over the channels 6.9e-7, 1.7e-7, 4.3e-8, 1.1e-8 and 2.7e-9 of the peak);
/// at 1.5625 us, 1.1e-9 (the lag angles, 1e-13 rad).
#[test]
fn windmill_error_falls_at_second_order_down_to_fine_steps() {
    let errors: Vec<f64> = [5e-5, 2.5e-5, 1.25e-5, 6.25e-6, 3.125e-6]
        .iter()
        .map(|&dt| {
            let request = Request {
                dt: Some(dt),
                until: Some(1.0),
                every: Some((5e-4 / dt).round() as usize),
                ..Request::default()
            };
            let tr = simulate("models/windmill.mbd", &[], request);
            let reference = windmill_reference(4, OMEGA_T, &tr.col("t"), 1e-11);
            let worst = channels(4)
                .iter()
                .enumerate()
                .map(|(c, name)| {
                    let want: Vec<f64> = reference.iter().map(|y| y[c]).collect();
                    rel_error(&tr.col(name), &want)
                })
                .fold(0.0, f64::max);
            eprintln!("windmill to 1 s at dt {dt:e}: largest error {worst:.3e} of the peak");
            worst
        })
        .collect();
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        above(&format!("observed order {order:.2}"), order, 1.9);
    }
    within("error at 3.125 us", errors[4], 8e-9); // measured 2.7e-9
}

/// A steady spin stays steady (issue 20, item 4): the windmill without its pulse, whose exact
/// motion keeps the hub still and every lag angle zero, at 25 us steps for 1 s (40,000 steps).
/// Measured: 3.4e-14 rad at most on the lag angles, 6.0e-15 m on the hub (round-off).
/// Before the accelerations were carried (the increment less `h v` amplified by `1/(beta h^2)`)
/// the collective lag reached 1.3e-11 rad, growing as `1/h`; with them carried but the
/// rotations re-orthonormalized through the quaternion, 1.7e-13 rad.
#[test]
fn windmill_spinning_undisturbed_stays_steady() {
    let request = Request {
        dt: Some(2.5e-5),
        until: Some(1.0),
        every: Some(400),
        ..Request::default()
    };
    let tr = simulate("models/windmill.mbd", &["pulse_peak=0"], request);
    let largest = |name: &str| tr.col(name).iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let lag = (1..=4)
        .map(|i| largest(&format!("zeta{i}")))
        .fold(0.0, f64::max);
    eprintln!(
        "undisturbed spin: lag {lag:.3e} rad, hub {:.3e} m",
        largest("x_hub")
    );
    within("largest lag angle (rad)", lag, 1e-13); // measured 3.4e-14
    within("hub (m)", largest("x_hub"), 2e-14); // measured 6.0e-15
}

/// P5 as shipped, four blades, stable (Omega_bar = 1: all roots neutral). Measured: every
/// channel within 5.8e-5 of its peak.
#[test]
fn windmill_stable_rotor_follows_the_nonlinear_equations() {
    assert_windmill(4, 1.0, 1.5e-4);
}

/// P5 as shipped, four blades, unstable (Omega_bar = 2: the regressing lag mode grows as
/// exp(1.281 t), about 47-fold over the run). Measured: within 1.04e-4 of the peak. At dt = 1 ms
/// the error is 0.090 %: it converges at least at second order (measured 3.1; 3.2 and 3.3 on to
/// 0.25 and 0.125 ms: HHT's low-frequency dissipation is third order in dt, and its second-order
/// phase error is small at omega dt < 0.01), so the agreement is convergence to the reference
/// and not a coincidence of one step size. (dt must divide 5 ms: at 2 ms the pulse is sampled
/// off its peak, its impulse is 4 % short, and so is every channel.)
#[test]
fn windmill_unstable_rotor_follows_the_nonlinear_equations() {
    assert_windmill(4, 2.0, 3e-4); // measured 1.04e-4
}

/// Three and five blades at Omega_bar = 2, each against the equations with its own N (and
/// M = ma + N mb, kT = M omega_T^2, as the model builds them). Measured: within 1.1e-4 (3) and
/// 1.24e-4 (5) of the peak.
#[test]
fn windmill_with_three_and_five_blades_follows_the_nonlinear_equations() {
    assert_windmill(3, 2.0, 3e-4);
    assert_windmill(5, 2.0, 4e-4);
}

// ---------------------------------------------------------------------------------------------
// 2. Spin-up (P6)
// ---------------------------------------------------------------------------------------------

/// Outputs the momentum balance needs: hub azimuth, hub velocity and lag rates.
const SPINUP_OUTPUTS: &str = "
output psi = rotor.drive.angle
output v_hub = tower.tip.velocity.x
for i in 1..=4 {
    output zr[i] = rotor.lag[i - 1].rate
}
";

fn spinup(t0: f64, dt: Option<f64>) -> Result<Trace, (Trace, String)> {
    let text = read("models/windmill_spinup.mbd") + SPINUP_OUTPUTS;
    let set = format!("T0={t0}");
    simulate_text_with(
        "models/windmill_spinup.mbd",
        &text,
        &[&set],
        Request {
            dt,
            ..Request::default()
        },
    )
}

/// The spin-up's time histories, blades 0-based.
struct Spin {
    t: Vec<f64>,
    psi: Vec<f64>,
    omega: Vec<f64>,
    v_hub: Vec<f64>,
    zeta: [Vec<f64>; 4],
    rate: [Vec<f64>; 4],
}

impl Spin {
    fn new(tr: &Trace) -> Spin {
        Spin {
            t: tr.col("t"),
            psi: tr.col("psi"),
            omega: tr.col("Omega_hub"),
            v_hub: tr.col("v_hub"),
            zeta: std::array::from_fn(|i| tr.col(&format!("zeta{}", i + 1))),
            rate: std::array::from_fn(|i| tr.col(&format!("zr{}", i + 1))),
        }
    }

    fn azimuth(&self, k: usize, i: usize) -> f64 {
        self.psi[k] + 2.0 * PI * i as f64 / 4.0
    }

    /// Magnitude of the one-per-rev (cyclic) lag, `sqrt(zeta_1c^2 + zeta_1s^2)` (§9.1).
    fn cyclic(&self, k: usize) -> f64 {
        let (mut c, mut s) = (0.0, 0.0);
        for i in 0..4 {
            let a = self.azimuth(k, i);
            c += 0.5 * self.zeta[i][k] * a.cos();
            s += 0.5 * self.zeta[i][k] * a.sin();
        }
        c.hypot(s)
    }

    /// Largest cyclic lag and largest `|zeta1 - zeta3|` over `[from, to)`.
    fn window(&self, from: f64, to: f64) -> (f64, f64) {
        let ks = (0..self.t.len()).filter(|&k| self.t[k] >= from && self.t[k] < to);
        ks.fold((0.0, 0.0), |(c, d), k| {
            (
                f64::max(c, self.cyclic(k)),
                f64::max(d, (self.zeta[0][k] - self.zeta[2][k]).abs()),
            )
        })
    }

    /// The rotor's angular momentum about the moving hub centre A, about z (hub massless,
    /// J_hub = 0). For blade i, with `theta_i' = Omega + zeta_i'` and the point at `s` as in
    /// `windmill_rhs` (`(r - r_A) = e u(psi_i) + s u(theta_i)`, `u(a) x e_x = -sin a`,
    /// `u(a) x u'(b) = cos(b - a)`):
    /// `h_i = mb e^2 Omega + e Sb (Omega + theta_i') cos zeta_i + Ib theta_i'
    ///        - x' (mb e sin psi_i + Sb sin theta_i)`.
    fn momentum(&self, k: usize) -> f64 {
        let (om, v) = (self.omega[k], self.v_hub[k]);
        (0..4)
            .map(|i| {
                let (psi, zeta) = (self.azimuth(k, i), self.zeta[i][k]);
                let th_dot = om + self.rate[i][k];
                MB * E * E * om + E * SB * (om + th_dot) * zeta.cos() + IB * th_dot
                    - v * (MB * E * psi.sin() + SB * (psi + zeta).sin())
            })
            .sum()
    }

    /// The y component of the rotor's linear momentum,
    /// `p_y = sum_i [mb e Omega cos psi_i + Sb theta_i' cos theta_i]`.
    fn momentum_y(&self, k: usize) -> f64 {
        let om = self.omega[k];
        (0..4)
            .map(|i| {
                let (psi, zeta) = (self.azimuth(k, i), self.zeta[i][k]);
                MB * E * om * psi.cos() + SB * (om + self.rate[i][k]) * (psi + zeta).cos()
            })
            .sum()
    }

    /// Largest `|H_A(t) - H_A(0) - int T + int x' p_y|` over the run, by the trapezoid rule:
    /// about A, which moves with `v_A = x' e_x`, `dH_A/dt = T(t) - (v_A x m v_G)_z
    /// = T(t) - x' p_y` (the hub's joint forces act at A; only the drive torque has a moment).
    /// Returns it with the largest `|int x' p_y|` (the size of the correction).
    fn balance(&self, t0: f64) -> (f64, f64) {
        let torque = |t: f64| t0 * (t / 0.5).clamp(0.0, 1.0);
        let h0 = self.momentum(0);
        let (mut impulse, mut correction, mut worst, mut largest) = (0.0, 0.0, 0.0f64, 0.0f64);
        for k in 1..self.t.len() {
            let dt = self.t[k] - self.t[k - 1];
            impulse += 0.5 * dt * (torque(self.t[k]) + torque(self.t[k - 1]));
            correction += 0.5
                * dt
                * (self.v_hub[k] * self.momentum_y(k) + self.v_hub[k - 1] * self.momentum_y(k - 1));
            worst = worst.max((self.momentum(k) - h0 - impulse + correction).abs());
            largest = largest.max(correction.abs());
        }
        (worst, largest)
    }
}

fn spin(t0: f64, dt: Option<f64>) -> Spin {
    match spinup(t0, dt) {
        Ok(tr) => Spin::new(&tr),
        Err((tr, m)) => panic!(
            "the spin-up at T0 = {t0} N m, dt {dt:?} failed at t = {:?} s: {m}",
            tr.col("t").last()
        ),
    }
}

/// The lag windows: early, after the pulse's forced response (0.1 s) and before the rotor
/// reaches the band (Omega_bar = 1.1774 at 0.42 s for T0 = 2.5 kN m, 1.12 s for 0.5 kN m), and
/// late, the last half second. Returns (late / early) of the cyclic lag and of |zeta1 - zeta3|.
fn lag_growth(s: &Spin, t0: f64) -> (f64, f64) {
    let early = s.window(0.1, 0.4);
    let late = s.window(4.0, 4.5 + 1e-9);
    let growth = (late.0 / early.0, late.1 / early.1);
    let table: Vec<String> = (0..9)
        .map(|w| {
            let (a, b) = (w as f64 * 0.5, w as f64 * 0.5 + 0.5);
            format!("{:.2e}", s.window(a.max(0.1), b).0)
        })
        .collect();
    eprintln!(
        "spin-up T0 {t0} N m: cyclic lag, max per half second from 0.1 s: {}; late / early: cyclic {:.2}, zeta1 - zeta3 {:.2}",
        table.join(" "),
        growth.0,
        growth.1
    );
    growth
}

/// Checks the angular-momentum balance of `Spin::balance` and the mean rotor speed it implies;
/// returns (residual, largest correction). The balance's own error: the torque is linear in time
/// between samples (its kink at 0.5 s is a sample), so its trapezoid is exact; the trapezoid of
/// `x' p_y` (frequencies below 40 rad/s, h = 0.5 ms) is off by about (40 h)^2 / 12 = 3e-5 of
/// the correction, which is below 5e-3 N m s. What remains is the solver's: HHT does not
/// conserve angular momentum exactly, its error is second order in dt (see the T0 = 2.5 kN m
/// test), and Newton's tolerance adds far less. Bound: 2e-6 of the final momentum.
fn check_momentum(s: &Spin, t0: f64) -> (f64, f64) {
    let (residual, correction) = s.balance(t0);
    let last = s.t.len() - 1;
    let h_end = s.momentum(last);
    let impulse = t0 * (s.t[last] - 0.25);
    eprintln!(
        "spin-up T0 {t0} N m: H_A {:.4} -> {h_end:.4} N m s (torque impulse {impulse:.1}); \
         balance residual {residual:.3e} N m s ({:.2e} of H), largest |int x' p_y| {correction:.3e}",
        s.momentum(0),
        residual / h_end
    );
    within(
        &format!("T0 {t0}: angular-momentum balance off by {residual:.3e} N m s of {h_end:.3e}"),
        residual,
        2e-6 * h_end,
    );
    // The rotor speed follows the impulse over the polar inertia (mb e^2 + 2 e Sb + Ib per blade,
    // 266.4 kg m^2): the hub's rate swings with the collective lag (the hub is massless), so
    // compare means over the last half second. Within 1 %: the collective lag (a few hundredths
    // of a radian) changes the inertia by less than 1e-3, and the window holds several of its
    // cycles.
    let j = 4.0 * (MB * E * E + 2.0 * E * SB + IB);
    let ks: Vec<usize> = (0..s.t.len()).filter(|&k| s.t[k] >= 4.0).collect();
    let mean = |f: &dyn Fn(usize) -> f64| ks.iter().map(|&k| f(k)).sum::<f64>() / ks.len() as f64;
    let h0 = s.momentum(0);
    let measured = mean(&|k| s.omega[k]);
    let predicted = mean(&|k| (h0 + t0 * (s.t[k] - 0.25)) / j);
    eprintln!(
        "spin-up T0 {t0} N m: mean rotor speed over [4, 4.5] s {measured:.3} rad/s, \
         (H0 + impulse) / J {predicted:.3} rad/s"
    );
    within(
        &format!("T0 {t0}: rotor speed {measured:.3} rad/s, impulse predicts {predicted:.3}"),
        (measured / predicted - 1.0).abs(),
        0.002,
    ); // measured 5.1e-4
    (residual, correction)
}

/// P6, T0 = 2.5 kN m: the rotor crosses the unstable band (Omega_bar 1.18 to 2.32) between
/// about 0.42 s and 1.55 s. With frozen coefficients the regressing mode can grow by
/// exp(int max(Re s, 0) dt) = exp(1.25) = 3.5 on the way (Re s from the MBC equations of
/// THEORY.md §9.1 at the mean rotor speed (H0 + torque impulse) / J; the same estimate gives 48
/// for T0 = 0.5 kN m), then it is neutral again. So the late cyclic lag must stay below 3.5
/// times the early one (measured 1.68, zeta1 - zeta3 1.71; 2.6 at the largest, near 2 s) and
/// must not grow over the last second (measured ratio 0.89; bound 1.05). A running instability
/// leaves both far behind (T0 = 0.5 kN m: 27).
/// The hub being massless, the torque reaches the blades only through their hinges: the
/// collective lag reaches -0.48 rad at 0.5 s and oscillates (about 40 rad/s), and the hub's rate
/// swings by up to 0.5 omega_T with it; the cyclic lag and zeta1 - zeta3 do not see it.
/// The angular-momentum balance holds to 2e-6 of H (measured 9.6e-7); its residual is the
/// integrator's: halving dt divides it by 3.8 (second order).
#[test]
fn spinup_high_torque_crosses_the_band_without_instability() {
    let s = spin(2500.0, None);
    let (cyclic, differential) = lag_growth(&s, 2500.0);
    within(&format!("cyclic lag grew {cyclic:.2}-fold"), cyclic, 3.5);
    within(
        &format!("zeta1 - zeta3 grew {differential:.2}-fold"),
        differential,
        3.5,
    );
    let (prev, late) = (s.window(2.5, 3.5).0, s.window(3.5, 4.5 + 1e-9).0);
    eprintln!("spin-up T0 2500 N m: cyclic lag max [2.5, 3.5) {prev:.3e}, [3.5, 4.5] {late:.3e}");
    within(
        &format!("the cyclic lag still grows: {prev:.3e} then {late:.3e}"),
        late,
        1.05 * prev,
    );
    let (coarse, _) = check_momentum(&s, 2500.0);
    let half = spin(2500.0, Some(2.5e-4));
    let (fine, _) = check_momentum(&half, 2500.0);
    let p = (coarse / fine).log2();
    eprintln!("spin-up T0 2500 N m: balance residual {coarse:.3e} at 0.5 ms, {fine:.3e} at 0.25 ms: order {p:.2}");
    above(
        &format!("the balance residual does not converge: order {p:.2}"),
        p,
        1.7,
    );
}

/// P6, T0 = 0.5 kN m: the rotor enters the band at about 1.1 s and is still in it at 4.5 s
/// (Omega_bar about 1.86): the frozen-coefficient growth is exp(3.87) = 48. The cyclic lag must
/// grow more than tenfold (measured 27, zeta1 - zeta3 20). Newton converges throughout at the
/// shipped dt (the cyclic lag stays below 3e-3 rad). The angular-momentum balance holds to 2e-6
/// of H (measured 3.2e-8), and here the tower-motion correction `int x' p_y` (4.1e-3 N m s) is
/// 28 times the residual: the check sees it.
#[test]
fn spinup_low_torque_excites_the_instability() {
    let s = spin(500.0, None);
    let (cyclic, differential) = lag_growth(&s, 500.0);
    above(
        &format!("cyclic lag grew only {cyclic:.2}-fold"),
        cyclic,
        10.0,
    );
    above(
        &format!("zeta1 - zeta3 grew only {differential:.2}-fold"),
        differential,
        10.0,
    );
    let (residual, correction) = check_momentum(&s, 500.0);
    within(
        &format!("residual {residual:.3e} against a correction of {correction:.3e}"),
        residual,
        0.1 * correction,
    );
}

// ---------------------------------------------------------------------------------------------
// 3. The elastic-blade windmill converges in mesh and time step
// ---------------------------------------------------------------------------------------------

fn elastic(elements: usize, dt: f64) -> Trace {
    let set = format!("elements={elements}");
    simulate(
        "models/windmill_elastic.mbd",
        &[&set],
        Request {
            dt: Some(dt),
            until: Some(1.0),
            ..Request::default()
        },
    )
}

/// The channel `name` sampled every millisecond.
fn every_ms(tr: &Trace, name: &str) -> Vec<f64> {
    let t = tr.col("t");
    let v = tr.col(name);
    (0..t.len())
        .filter(|&k| {
            let ms = t[k] * 1e3;
            (ms - ms.round()).abs() < 1e-6
        })
        .map(|k| v[k])
        .collect()
}

/// Successive differences (max |difference| over the run / the finer run's peak) of `x_hub` and
/// `zeta1` along a sequence of runs.
fn successive(runs: &[Trace]) -> [[f64; 2]; 2] {
    let ch = ["x_hub", "zeta1"];
    std::array::from_fn(|c| {
        let v: Vec<Vec<f64>> = runs.iter().map(|tr| every_ms(tr, ch[c])).collect();
        [rel_error(&v[0], &v[1]), rel_error(&v[1], &v[2])]
    })
}

/// The elastic-blade windmill (Omega_bar 1.1, two quadratic elements per blade) over 1 s at
/// dt = 0.5, 0.25, 0.125 ms: second order. The differences between successive runs shrink with
/// an observed order within 0.3 of 2 (measured 1.91 for x_hub, 1.88 for zeta1). From 1 ms the
/// first difference is not yet asymptotic (orders 1.35 and 1.72). The lag channel's time-step
/// error is large: mostly collective (the same on every blade), it comes from the phase error
/// of the elastic blades' rigid rotation, O((Omega dt)^2), which loads the collective lag mode;
/// at the shipped 0.5 ms it is about a quarter of zeta1's (small, 1e-4 rad) peak.
#[test]
fn elastic_windmill_converges_in_dt() {
    let runs: Vec<Trace> = [5e-4, 2.5e-4, 1.25e-4]
        .iter()
        .map(|&dt| elastic(2, dt))
        .collect();
    let d = successive(&runs);
    for (c, name) in ["x_hub", "zeta1"].iter().enumerate() {
        let p = (d[c][0] / d[c][1]).log2();
        eprintln!(
            "elastic windmill {name}, dt 0.5 / 0.25 / 0.125 ms: differences {:.3e}, {:.3e} of the peak, order {p:.2}",
            d[c][0], d[c][1]
        );
        within(&format!("{name}: order {p:.2}"), (p - 2.0).abs(), 0.3);
    }
}

/// The same over 1 s at dt = 0.5 ms with 2, 4 and 8 quadratic elements per blade: the
/// differences between successive meshes shrink, by a factor of more than 3 (measured 4.9 for
/// x_hub, 6.4 for zeta1). With 16 elements zeta1's difference shrinks only by 2.3 more (1.1e-3
/// of its peak, the same at dt = 0.25 ms): not checked.
#[test]
fn elastic_windmill_converges_in_mesh() {
    let runs: Vec<Trace> = [2, 4, 8].iter().map(|&n| elastic(n, 5e-4)).collect();
    let d = successive(&runs);
    for (c, name) in ["x_hub", "zeta1"].iter().enumerate() {
        let ratio = d[c][0] / d[c][1];
        eprintln!(
            "elastic windmill {name}, 2 / 4 / 8 elements: differences {:.3e}, {:.3e} of the peak, ratio {ratio:.2}",
            d[c][0], d[c][1]
        );
        above(
            &format!("{name}: mesh differences shrink only {ratio:.2}-fold"),
            ratio,
            3.0,
        );
    }
}
