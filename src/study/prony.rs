//! Damping from a transient: the matrix pencil method (THEORY §9.3), several signals sharing
//! their poles.
//!
//! Signals are scaled by the largest magnitude of their group (signals of one physical
//! dimension); their Hankel matrices (`K - L` rows of
//! `L + 1` samples, pencil parameter `L = K / 3`) are stacked and decomposed (SVD). The model
//! order `M` is the number of singular values above `rank_tolerance` of the largest (at most
//! `max_order`), cut at the last drop by more than `gap` between neighbours (the noise floor
//! of the integration, when the signals show one); with `V'` the `M` leading right singular vectors, `V1` and `V2` it without its
//! last and first row, the poles `z` are the eigenvalues of `V1^+ V2`, and
//! `s = ln z / dt`. Each pole's amplitude in each signal comes from a least-squares fit of the
//! signal by the poles' real modes (`Re z^k`, `Im z^k`); a pole is kept if its largest
//! contribution over the window, relative to the signal's peak, reaches `amplitude_tolerance`
//! in some signal. Conjugate pairs are reported once, with `Im s >= 0`.

use crate::solve::linear::{generalized_eigen, least_squares, svd_right};
use crate::solve::modes::c64;
use nalgebra::DMatrix;
use std::fmt;

/// Settings of the fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PencilSpec {
    /// Largest model order (number of poles, conjugates counted).
    pub max_order: usize,
    /// Singular values below this fraction of the largest are noise.
    pub rank_tolerance: f64,
    /// A drop by more than this factor between neighbouring singular values marks the noise
    /// floor: the order stops there.
    pub gap: f64,
    /// Poles contributing less than this fraction of every signal's peak are dropped.
    pub amplitude_tolerance: f64,
    /// Signals whose peak is below this fraction of their group's largest peak are not
    /// excited (numerical noise), and are skipped.
    pub unexcited: f64,
}

impl Default for PencilSpec {
    fn default() -> PencilSpec {
        PencilSpec {
            max_order: 40,
            rank_tolerance: 1e-7,
            gap: 100.0,
            amplitude_tolerance: 1e-2,
            unexcited: 1e-6,
        }
    }
}

/// One pole of the fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pole {
    /// `s = ln z / dt` (1/s), `Im s >= 0`.
    pub s: c64,
    /// Largest contribution over the window relative to the peak of the signal where it is
    /// largest.
    pub amplitude: f64,
}

/// Why the matrix pencil found no poles. `Display` is the message.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PencilError {
    /// Fewer than 12 samples of a signal that is not zero throughout.
    TooFewSamples {
        samples: usize,
    },
    SvdFailed,
    /// Every singular value is zero (or NaN).
    NoEnergy,
    PencilFailed,
    EigenvaluesFailed,
    AmplitudeFitFailed,
}

impl fmt::Display for PencilError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            PencilError::TooFewSamples { samples } => write!(
                f,
                "a transient fit needs at least 12 samples of a signal that is not zero throughout, got {samples}"
            ),
            PencilError::SvdFailed => write!(f, "the singular value decomposition failed"),
            PencilError::NoEnergy => write!(f, "the signals carry no energy"),
            PencilError::PencilFailed => write!(f, "the pencil could not be formed"),
            PencilError::EigenvaluesFailed => write!(f, "the pencil's eigenvalues failed"),
            PencilError::AmplitudeFitFailed => write!(f, "the amplitude fit failed"),
        }
    }
}

impl std::error::Error for PencilError {}

/// The minimum-norm least-squares solution of `a x = b` (SVD, singular values below 1e-12 of
/// the largest dropped).
fn solve_ls(a: &DMatrix<f64>, b: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let (rows, cols, nrhs) = (a.nrows(), a.ncols(), b.ncols());
    let ar: Vec<f64> = (0..rows * cols).map(|p| a[(p / cols, p % cols)]).collect();
    let br: Vec<f64> = (0..rows * nrhs).map(|p| b[(p / nrhs, p % nrhs)]).collect();
    let x = least_squares(&ar, rows, cols, &br, nrhs, 1e-12)?;
    Some(DMatrix::from_row_slice(cols, nrhs, &x))
}

/// The pencil's eigenvalues `z` at order `m`, from the right singular vectors `vs` (columns
/// of length `width`, leading first): `V1 A = V2` in least squares.
fn pencil_poles(vs: &[f64], width: usize, m: usize) -> Result<Vec<c64>, PencilError> {
    let l = width - 1;
    let v = DMatrix::<f64>::from_fn(width, m, |i, j| vs[j * width + i]);
    let v1 = v.rows(0, l).into_owned();
    let v2 = v.rows(1, l).into_owned();
    let a = solve_ls(&v1, &v2).ok_or(PencilError::PencilFailed)?;
    let col: Vec<f64> = (0..m * m).map(|p| a[(p % m, p / m)]).collect();
    let identity: Vec<f64> = (0..m * m)
        .map(|p| if p % (m + 1) == 0 { 1.0 } else { 0.0 })
        .collect();
    let eig = generalized_eigen(&col, &identity, m).ok_or(PencilError::EigenvaluesFailed)?;
    Ok(eig
        .iter()
        .map(|((ar, ai), (br, bi), _)| {
            let d = br * br + bi * bi;
            c64::new((ar * br + ai * bi) / d, (ai * br - ar * bi) / d)
        })
        .filter(|z| z.re.is_finite() && z.im.is_finite() && (z.re != 0.0 || z.im != 0.0))
        .collect())
}

/// The poles of uniformly sampled signals (step `dt`), largest amplitude first. Signals of the
/// same group (the same physical dimension) share one scale, the group's largest peak, so a
/// weakly excited signal weighs little; without groups each signal is its own.
pub fn matrix_pencil(
    signals: &[Vec<f64>],
    groups: Option<&[usize]>,
    dt: f64,
    spec: &PencilSpec,
) -> Result<Vec<Pole>, PencilError> {
    let scaled = scaled_signals(signals, groups, spec);
    let k = scaled.iter().map(Vec::len).min().unwrap_or(0);
    if k < 12 {
        return Err(PencilError::TooFewSamples { samples: k });
    }
    let hankel = Hankel::decompose(&scaled, k)?;
    let m = hankel.model_order(spec);
    if m == 0 {
        return Ok(Vec::new());
    }
    let poles = distinct_poles(&hankel.stable_poles(m)?, k);
    let amplitude = amplitudes(&poles, &scaled, k)?;
    let mut out: Vec<Pole> = poles
        .iter()
        .zip(&amplitude)
        .filter(|(_, a)| **a >= spec.amplitude_tolerance)
        .map(|(z, a)| {
            let r = (z.re * z.re + z.im * z.im).sqrt();
            Pole {
                s: c64::new(r.ln() / dt, z.im.atan2(z.re) / dt),
                amplitude: *a,
            }
        })
        .collect();
    out.sort_by(|a, b| b.amplitude.total_cmp(&a.amplitude));
    Ok(out)
}

/// The excited signals, each divided by its group's scale (the largest peak of its finite
/// signals); signals that are not finite, or not excited, are dropped.
fn scaled_signals(
    signals: &[Vec<f64>],
    groups: Option<&[usize]>,
    spec: &PencilSpec,
) -> Vec<Vec<f64>> {
    let peak_of = |y: &Vec<f64>| y.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let group = |i: usize| groups.map_or(i, |g| g[i]);
    let finite = |y: &Vec<f64>| y.iter().all(|x| x.is_finite());
    // Each group's scale: the largest peak of its signals.
    let scale = |i: usize| {
        (0..signals.len())
            .filter(|&j| group(j) == group(i) && finite(&signals[j]))
            .map(|j| peak_of(&signals[j]))
            .fold(0.0f64, f64::max)
    };
    (0..signals.len())
        .filter_map(|i| {
            let (y, s) = (&signals[i], scale(i));
            (finite(y) && peak_of(y) > spec.unexcited * s && s > 0.0)
                .then(|| y.iter().map(|x| x / s).collect())
        })
        .collect()
}

/// The stacked Hankel matrices of the signals (`K - L` rows of `L + 1` samples each,
/// `L = K / 3`), decomposed: singular values, largest first, and right singular vectors.
struct Hankel {
    /// The pencil parameter `L`.
    l: usize,
    sv: Vec<f64>,
    vs: Vec<f64>,
}

impl Hankel {
    fn decompose(scaled: &[Vec<f64>], k: usize) -> Result<Hankel, PencilError> {
        let l = k / 3;
        let rows = k - l;
        let width = l + 1;
        let mut y = vec![0.0; rows * scaled.len() * width];
        for (s, sig) in scaled.iter().enumerate() {
            for i in 0..rows {
                for j in 0..width {
                    y[(s * rows + i) * width + j] = sig[i + j];
                }
            }
        }
        let (sv, vs) = svd_right(&y, rows * scaled.len(), width).ok_or(PencilError::SvdFailed)?;
        let smax = sv.first().copied().unwrap_or(0.0);
        if smax.is_nan() || smax <= 0.0 {
            return Err(PencilError::NoEnergy);
        }
        Ok(Hankel { l, sv, vs })
    }

    /// The model order: singular values above the tolerance, cut at the last gap of more
    /// than `gap` between neighbours (the noise floor of the integration) if there is one.
    fn model_order(&self, spec: &PencilSpec) -> usize {
        let sv = &self.sv;
        let smax = sv[0];
        let above = sv
            .iter()
            .take_while(|&&x| x > spec.rank_tolerance * smax)
            .count()
            .min(spec.max_order)
            .min(self.l);
        (1..above.min(sv.len() - 1) + 1)
            .rev()
            .find(|&k| sv[k] * spec.gap < sv[k - 1])
            .unwrap_or(above)
    }

    /// Stabilization: a pole of the data stays put when the order grows by 2, 4 and 6; poles
    /// fitted to the noise move. Keeps the poles of order `m` found again at the larger
    /// orders (within 1e-3 of |ln z|, i.e. of |s| dt), when the data allow them.
    fn stable_poles(&self, m: usize) -> Result<Vec<c64>, PencilError> {
        let (l, width) = (self.l, self.l + 1);
        let zs = pencil_poles(&self.vs, width, m)?;
        let extra: Vec<Vec<c64>> = [m + 2, m + 4, m + 6]
            .iter()
            .filter(|&&o| o <= l && o <= self.sv.len())
            .map(|&o| pencil_poles(&self.vs, width, o))
            .collect::<Result<_, _>>()?;
        let log_of = |z: &c64| c64::new((z.re * z.re + z.im * z.im).sqrt().ln(), z.im.atan2(z.re));
        Ok(zs
            .into_iter()
            .filter(|z| {
                let a = log_of(z);
                extra.iter().all(|set| {
                    set.iter().any(|w| {
                        let b = log_of(w);
                        (a.re - b.re).abs() + (a.im - b.im).abs()
                            <= 1e-3 * (a.re * a.re + a.im * a.im).sqrt().max(1e-3)
                    })
                })
            })
            .collect())
    }
}

/// The poles the data resolve, `Im z >= 0`, each once: poles that vanish within a sample, or
/// grow by more than 1e12 over the `k` samples, are noise in the pencil's rank.
fn distinct_poles(zs: &[c64], k: usize) -> Vec<c64> {
    let tiny = 1e-9;
    let mut poles: Vec<c64> = Vec::new();
    let span = (k - 1) as f64;
    for z in zs {
        let r = (z.re * z.re + z.im * z.im).sqrt();
        if z.im < -tiny * r || r < 1e-3 || span * r.ln() > 12.0 * std::f64::consts::LN_10 {
            continue;
        }
        let z = if z.im.abs() <= tiny * r {
            c64::new(z.re, 0.0)
        } else {
            *z
        };
        if !poles
            .iter()
            .any(|p| (p.re - z.re).abs() + (p.im - z.im).abs() <= 1e-9 * r)
        {
            poles.push(z);
        }
    }
    poles
}

/// Each pole's largest contribution over the window relative to the peak of the signal where
/// it is largest: a least-squares fit of the signals by the poles' real modes.
fn amplitudes(poles: &[c64], scaled: &[Vec<f64>], k: usize) -> Result<Vec<f64>, PencilError> {
    // Real modes of each pole over the samples: z^k = r^k (cos k th + i sin k th).
    let mut columns: Vec<(usize, Vec<f64>)> = Vec::new();
    for (p, z) in poles.iter().enumerate() {
        let (r, th) = ((z.re * z.re + z.im * z.im).sqrt(), z.im.atan2(z.re));
        let pow = |i: usize| r.powi(i as i32);
        columns.push((p, (0..k).map(|i| pow(i) * (th * i as f64).cos()).collect()));
        if z.im != 0.0 {
            columns.push((p, (0..k).map(|i| pow(i) * (th * i as f64).sin()).collect()));
        }
    }
    let basis = DMatrix::<f64>::from_fn(k, columns.len(), |i, j| columns[j].1[i]);
    let b = DMatrix::<f64>::from_fn(k, scaled.len(), |i, s| scaled[s][i]);
    let coefficients = solve_ls(&basis, &b).ok_or(PencilError::AmplitudeFitFailed)?;
    let mut amplitude = vec![0.0f64; poles.len()];
    for s in 0..scaled.len() {
        let c = coefficients.column(s);
        let mut per = vec![0.0f64; poles.len()];
        for (j, (p, _)) in columns.iter().enumerate() {
            per[*p] += c[j] * c[j];
        }
        for (p, z) in poles.iter().enumerate() {
            let r = (z.re * z.re + z.im * z.im).sqrt();
            let reach = per[p].sqrt() * r.powi(k as i32 - 1).max(1.0);
            amplitude[p] = amplitude[p].max(reach);
        }
    }
    Ok(amplitude)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two damped modes and a growing one in two signals, with different amplitudes.
    #[test]
    fn recovers_the_poles_of_a_sum_of_damped_sinusoids() {
        let dt = 0.01;
        let modes = [(-0.3, 5.0), (0.8, 12.0), (-1.5, 0.0)];
        let signal = |amps: [f64; 3]| -> Vec<f64> {
            (0..400)
                .map(|i| {
                    let t = i as f64 * dt;
                    modes
                        .iter()
                        .zip(amps)
                        .map(|((re, im), a)| a * (re * t).exp() * (im * t + 0.3).cos())
                        .sum()
                })
                .collect()
        };
        let poles = matrix_pencil(
            &[signal([1.0, 1e-2, 0.5]), signal([0.0, 2.0, 0.1])],
            None,
            dt,
            &PencilSpec::default(),
        )
        .expect("fit");
        assert_eq!(poles.len(), 3, "{poles:?}");
        for (re, im) in modes {
            let p = poles
                .iter()
                .find(|p| (p.s.im - im).abs() < 1e-6)
                .unwrap_or_else(|| panic!("no pole at {im} rad/s: {poles:?}"));
            assert!((p.s.re - re).abs() < 1e-7, "{p:?} vs {re}");
        }
    }

    #[test]
    fn too_short_or_empty_signals_are_errors() {
        assert!(matrix_pencil(&[vec![1.0; 5]], None, 0.1, &PencilSpec::default()).is_err());
        assert!(matrix_pencil(&[vec![0.0; 100]], None, 0.1, &PencilSpec::default()).is_err());
    }
}
