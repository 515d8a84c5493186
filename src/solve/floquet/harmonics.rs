//! Floquet frequencies resolved (THEORY §9.2 step 4): a multiplier fixes its exponent's
//! frequency only modulo `Omega = 2 pi / T`; the mode's time history over the period,
//! `y(t) = Z(t) Z_0^-1 v` (`v` its eigenvector, `Z(t)` the carried directions' measure),
//! is `exp(s t) p(t)` with `p` periodic, and the frequency is the principal exponent's plus
//! the dominant harmonic `l Omega` of `p`: the harmonic that carries most of the mode's motion.

use nalgebra::{Complex, DMatrix};

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
    // The measure's components (the directions' count, `z0`'s, may be fewer).
    let n = history.first().map_or(z0.nrows(), |(_, z)| z.nrows());
    let (r, harmonics) = (z0.nrows(), (2 * top + 1) as usize);
    // Every mode's start at once: `W = Z_0^-1 V`, real and imaginary parts.
    let part = |pick: fn(&(f64, f64)) -> f64| {
        DMatrix::from_fn(r, modes.len(), |i, m| modes[m].1.get(i).map_or(0.0, pick))
    };
    let (wr, wi) = (lu.solve(&part(|x| x.0))?, lu.solve(&part(|x| x.1))?);
    // c_l = sum_k exp(-s t_k) y(t_k) exp(-i l Omega t_k), per mode, harmonic and component.
    let mut c = vec![Complex::new(0.0, 0.0); modes.len() * harmonics * n];
    for (t, z) in history {
        let (yr, yi) = (z * &wr, z * &wi);
        for (m, ((re, im), _)) in modes.iter().enumerate() {
            let back = Complex::new(-re * t, -im * t).exp();
            let cm = &mut c[m * harmonics * n..(m + 1) * harmonics * n];
            for (l, cl) in (-top..=top).zip(cm.chunks_mut(n)) {
                let turn = back * Complex::new(0.0, -(l as f64) * omega * t).exp();
                for (ci, (a, b)) in cl
                    .iter_mut()
                    .zip(yr.column(m).iter().zip(yi.column(m).iter()))
                {
                    *ci += turn * Complex::new(*a, *b);
                }
            }
        }
    }
    let mut out = Vec::with_capacity(modes.len());
    for (m, ((_, im), _)) in modes.iter().enumerate() {
        let cm = &c[m * harmonics * n..(m + 1) * harmonics * n];
        let energy: Vec<f64> = cm
            .chunks(n)
            .map(|cl| cl.iter().map(|x| x.norm_sqr()).sum())
            .collect();
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
