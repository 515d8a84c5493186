//! Floquet frequencies resolved (THEORY §9.2 step 4): a multiplier fixes its exponent's
//! frequency only modulo `Omega = 2 pi / T`; the mode's time history over the period,
//! `y(t) = Z(t) Z_0^-1 v` (`v` its eigenvector, `Z(t)` the carried directions' measure),
//! is `exp(s t) p(t)` with `p` periodic, and the frequency is the principal exponent's plus
//! the dominant harmonic `l Omega` of `p`: the harmonic that carries most of the mode's motion.

use nalgebra::{Complex, DMatrix, DVector};

/// A mode: its exponent `(Re s, Im s)` on the principal branch and its eigenvector (complex
/// entries as `(re, im)`).
pub type Mode = ((f64, f64), Vec<(f64, f64)>);

/// Harmonics looked at: `|l| <= MAX_HARMONIC` (a rotor's modes sit within a few per rev of
/// their principal branch).
pub const MAX_HARMONIC: i32 = 8;

/// Samples of the period: `Z(t_k)` at evenly spaced steps.
pub const SAMPLES: usize = 48;

/// The frequency (rad/s) of each mode `(s, v)` (`s` on the principal branch, `v` the
/// eigenvector of the monodromy), from `history` (`t_k`, `Z(t_k)`) over one period `period`.
pub fn resolve(
    history: &[(f64, DMatrix<f64>)],
    z0: &DMatrix<f64>,
    modes: &[Mode],
    period: f64,
) -> Option<Vec<f64>> {
    let lu = z0.clone().lu();
    let omega = 2.0 * std::f64::consts::PI / period;
    let top = MAX_HARMONIC.min(history.len() as i32 / 2 - 1).max(0);
    let mut out = Vec::with_capacity(modes.len());
    for ((re, im), v) in modes {
        let vr = DVector::from_iterator(v.len(), v.iter().map(|x| x.0));
        let vi = DVector::from_iterator(v.len(), v.iter().map(|x| x.1));
        let (wr, wi) = (lu.solve(&vr)?, lu.solve(&vi)?);
        // c_l = sum_k exp(-s t_k) y(t_k) exp(-i l Omega t_k), per component.
        let mut energy = vec![0.0f64; (2 * top + 1) as usize];
        let mut c = vec![Complex::new(0.0, 0.0); v.len() * energy.len()];
        for (t, z) in history {
            let (yr, yi) = (z * &wr, z * &wi);
            let back = Complex::new(-re * t, -im * t).exp();
            for (l, cl) in (-top..=top).zip(c.chunks_mut(v.len())) {
                let turn = back * Complex::new(0.0, -(l as f64) * omega * t).exp();
                for (ci, (a, b)) in cl.iter_mut().zip(yr.iter().zip(yi.iter())) {
                    *ci += turn * Complex::new(*a, *b);
                }
            }
        }
        for (e, cl) in energy.iter_mut().zip(c.chunks(v.len())) {
            *e = cl.iter().map(|x| x.norm_sqr()).sum();
        }
        // The dominant harmonic; the one nearest the principal branch among equals.
        let mut best = top as usize;
        for (k, e) in energy.iter().enumerate() {
            let closer = (k as i32 - top).abs() < (best as i32 - top).abs();
            if *e > energy[best] * (1.0 + 1e-9) || (*e >= energy[best] * (1.0 - 1e-9) && closer) {
                best = k;
            }
        }
        out.push(im + (best as i32 - top) as f64 * omega);
    }
    Some(out)
}
