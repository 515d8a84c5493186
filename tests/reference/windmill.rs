//! The ground-resonance windmill of P5 (THEORY.md §9.1): its nonlinear equations of motion,
//! integrated by `dopri_breaks`. Checked against the model by `tests/rotor.rs`; its parameters
//! are those of `models/windmill.mbd`.
//!
//! Contract: plain `f64` arithmetic only (see `mod.rs`): no `mbd`, no other crate.

use super::dopri_breaks;
use std::f64::consts::PI;

/// Blade mass, length and hinge offset, tower-top mass, tower frequency, lag spring (P5).
pub const MB: f64 = 20.0;
const LB: f64 = 2.7;
pub const E: f64 = 0.3;
const MA: f64 = 100.0;
pub const OMEGA_T: f64 = 9.26;
const K_ZETA: f64 = 14.0;
/// Static moment and inertia of a blade (uniform rod) about its hinge: 27 kg m, 48.6 kg m^2.
pub const SB: f64 = MB * LB / 2.0;
pub const IB: f64 = MB * LB * LB / 3.0;
/// Kinks of the pulse.
const PULSE_BREAKS: [f64; 2] = [0.005, 0.01];

/// The 20 N triangular pulse: 0 N at 0, 20 N at 5 ms, 0 N from 10 ms.
fn pulse(t: f64) -> f64 {
    if t <= 0.0 || t >= 0.01 {
        0.0
    } else if t <= 0.005 {
        20.0 * t / 0.005
    } else {
        20.0 * (0.01 - t) / 0.005
    }
}

/// The planar windmill, re-derived from its Lagrangian (it agrees with THEORY.md §9.1 term by
/// term, and so with the model's conventions).
///
/// Conventions, those of the model: the rotor turns counter-clockwise about +z at the
/// prescribed rate `Omega`, blade `i` (0-based here, `zeta{i+1}` in the model) at azimuth
/// `psi_i = Omega t + 2 pi i / N` (blade 0 along +x at t = 0), the lag angle `zeta_i` positive
/// for a lead, so the blade points along `u(theta_i)`, `theta_i = psi_i + zeta_i`,
/// `u(a) = (cos a, sin a)`. The hub centre is at `(x, 0)`.
///
/// A point at distance `s` along blade `i` sits at `(x, 0) + e u(psi_i) + s u(theta_i)` and moves
/// with `v = x' e_x + e Omega u'(psi_i) + s theta_i' u'(theta_i)` (`u' = (-sin, cos)`,
/// `theta_i' = Omega + zeta_i'`). Integrating `|v|^2` over the uniform rod (`mb`, `Sb = mb L/2`,
/// `Ib = mb L^2/3`; `u(a).u'(b) = sin(b - a)`, `u'(a).u'(b) = cos(b - a)`):
///
/// `T_i = mb x'^2/2 + mb e^2 Omega^2/2 + Ib theta_i'^2/2 - mb e Omega x' sin psi_i
///        - Sb x' theta_i' sin theta_i + e Sb Omega theta_i' cos zeta_i`,
///
/// plus `ma x'^2/2` for the tower top, `V = kT x^2/2 + sum k_zeta zeta_i^2/2`, and the pulse's
/// generalized force `F` on `x`. Lagrange's equation for `zeta_i` (`Omega` constant):
/// `d/dt(Ib theta' - Sb x' sin theta + e Sb Omega cos zeta) + Sb x' theta' cos theta
///  + e Sb Omega theta' sin zeta + k_zeta zeta = 0`, which is
///
/// `Ib zeta_i'' + k_zeta zeta_i + e Sb Omega^2 sin zeta_i - Sb x'' sin theta_i = 0`;
///
/// and for `x` (`M = ma + N mb`; `sum_i cos psi_i = 0` for N >= 2 removes the hinge term):
///
/// `M x'' + kT x - Sb sum_i [zeta_i'' sin theta_i + theta_i'^2 cos theta_i] = F`,
///
/// exactly the equations of THEORY.md §9.1, with `kT = M omega_T^2`. The mass matrix is an
/// arrowhead (`M` and `Ib` on the diagonal, `-Sb sin theta_i` coupling `x` to `zeta_i`), solved
/// exactly at every evaluation by eliminating the `zeta_i''`:
/// `x'' = (r_x + (Sb/Ib) sum s_i r_i) / (M - (Sb^2/Ib) sum s_i^2)`, `zeta_i'' = (r_i + Sb s_i x'')/Ib`,
/// with `s_i = sin theta_i` and the right-hand sides `r_x`, `r_i` of the two equations. The
/// pivot is at least `M - N Sb^2/Ib = 180 - 60 > 0` kg.
///
/// State `y = [x, zeta_0 .. zeta_{N-1}, x', zeta_0' .. zeta_{N-1}']`, `D = 2 + 2N`.
fn windmill_rhs<const D: usize>(omega: f64, t: f64, y: &[f64; D]) -> [f64; D] {
    let n = (D - 2) / 2;
    let m = MA + n as f64 * MB;
    let kt = m * OMEGA_T * OMEGA_T;
    let mut s = [0.0; D];
    let mut r = [0.0; D];
    let mut rx = pulse(t) - kt * y[0];
    let (mut num, mut den) = (0.0, m);
    for i in 0..n {
        let (zeta, rate) = (y[1 + i], y[2 + n + i]);
        let theta = omega * t + 2.0 * PI * i as f64 / n as f64 + zeta;
        s[i] = theta.sin();
        r[i] = -K_ZETA * zeta - E * SB * omega * omega * zeta.sin();
        rx += SB * (omega + rate).powi(2) * theta.cos();
        num += SB / IB * s[i] * r[i];
        den -= SB * SB / IB * s[i] * s[i];
    }
    let xdd = (rx + num) / den;
    let mut dy = [0.0; D];
    dy[0] = y[1 + n];
    dy[1 + n] = xdd;
    for i in 0..n {
        dy[1 + i] = y[2 + n + i];
        dy[2 + n + i] = (r[i] + SB * s[i] * xdd) / IB;
    }
    dy
}

/// The windmill from rest (`x = zeta_i = 0`, rates 0, the rotor at `Omega`) at `times`,
/// integrated by the adaptive Dormand-Prince code, stepping onto the pulse's kinks. Rows:
/// `[x, zeta_0 .. zeta_{N-1}]`.
pub fn windmill_reference(blades: usize, omega: f64, times: &[f64], rtol: f64) -> Vec<Vec<f64>> {
    fn run<const D: usize>(omega: f64, times: &[f64], rtol: f64) -> Vec<Vec<f64>> {
        // Displacements are of order 1e-5 m and 1e-4 rad: atol 1e-15 leaves rtol in charge.
        dopri_breaks(
            |t, y: &[f64; D]| windmill_rhs(omega, t, y),
            0.0,
            [0.0; D],
            times,
            &PULSE_BREAKS,
            rtol,
            1e-15,
        )
        .into_iter()
        .map(|y| y[..D / 2].to_vec())
        .collect()
    }
    match blades {
        3 => run::<8>(omega, times, rtol),
        4 => run::<10>(omega, times, rtol),
        5 => run::<12>(omega, times, rtol),
        n => panic!("no reference for {n} blades"),
    }
}
