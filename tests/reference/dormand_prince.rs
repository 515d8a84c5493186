//! Adaptive Dormand–Prince 5(4) integrator of the reference solutions.
//!
//! Contract: plain `f64` arithmetic only (see `mod.rs`): no `mbd`, no other crate.

/// Largest number of attempted steps `dopri_breaks` takes before it gives up.
pub const MAX_STEPS: usize = 10_000_000;

/// Integrates `y' = f(t, y)` from `(t0, y0)` and returns `y` at each of `times` (non-decreasing,
/// all `>= t0`; a time equal to `t0` returns `y0`). Each requested time is hit exactly by
/// shortening the step onto it: no dense-output interpolation.
pub fn dopri<const N: usize>(
    f: impl FnMut(f64, &[f64; N]) -> [f64; N],
    t0: f64,
    y0: [f64; N],
    times: &[f64],
    rtol: f64,
    atol: f64,
) -> Vec<[f64; N]> {
    dopri_breaks(f, t0, y0, times, &[], rtol, atol)
}

/// `dopri` that also steps exactly onto each of `breaks` (times where `f` has a kink or jump;
/// those outside `(t0, last time)` are ignored) and restarts there with a fresh `f(t, y)`, so no
/// step straddles a break. The step-size control is the standard one (Hairer, Nørsett & Wanner,
/// *Solving ODEs I*, §II.4): RMS error norm scaled by `atol + rtol max(|y|, |y_new|)`, new step
/// `h * clamp(0.9 err^(-1/5), 0.2, 5)`, no growth right after a rejection.
///
/// Panics after `MAX_STEPS` attempted steps, on a step size that underflows, or on a
/// non-finite state: this is test code and a panic is the honest answer.
pub fn dopri_breaks<const N: usize>(
    mut f: impl FnMut(f64, &[f64; N]) -> [f64; N],
    t0: f64,
    y0: [f64; N],
    times: &[f64],
    breaks: &[f64],
    rtol: f64,
    atol: f64,
) -> Vec<[f64; N]> {
    assert!(
        rtol > 0.0 && atol > 0.0,
        "dopri: need rtol > 0 and atol > 0 (the error scale of a zero component is atol)"
    );
    assert!(t0.is_finite(), "dopri: t0 = {t0}");
    assert!(
        times.iter().all(|t| t.is_finite() && *t >= t0) && times.windows(2).all(|w| w[0] <= w[1]),
        "dopri: requested times must be finite, >= t0 = {t0} and non-decreasing"
    );
    let Some(&t_end) = times.last() else {
        return Vec::new();
    };
    let mut stops: Vec<f64> = times
        .iter()
        .copied()
        .chain(breaks.iter().copied().filter(|&b| b > t0 && b < t_end))
        .collect();
    stops.sort_by(f64::total_cmp);
    stops.dedup();

    let mut run = Run {
        t: t0,
        y: y0,
        h: 0.0,
        steps: 0,
        rtol,
        atol,
    };
    let mut out = Vec::with_capacity(times.len());
    let mut next = 0;
    for stop in stops {
        if stop > run.t {
            run.segment(&mut f, stop);
        }
        while next < times.len() && times[next] == stop {
            out.push(run.y);
            next += 1;
        }
    }
    out
}

/// The integrator's state between segments.
struct Run<const N: usize> {
    t: f64,
    y: [f64; N],
    /// Proposed size of the next step (0 before the first step).
    h: f64,
    steps: usize,
    rtol: f64,
    atol: f64,
}

// Dormand–Prince 5(4) tableau (Hairer, Nørsett & Wanner, Table II.5.2).
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// Fifth-order weights minus fourth-order weights: the local error estimate.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

impl<const N: usize> Run<N> {
    /// RMS norm of `v` scaled by `atol + rtol max(|a|, |b|)`.
    fn norm(&self, v: &[f64; N], a: &[f64; N], b: &[f64; N]) -> f64 {
        let sum: f64 = (0..N)
            .map(|i| {
                let sc = self.atol + self.rtol * a[i].abs().max(b[i].abs());
                (v[i] / sc).powi(2)
            })
            .sum();
        (sum / N.max(1) as f64).sqrt()
    }

    /// Starting step (Hairer, Nørsett & Wanner, §II.4 "starting step size").
    fn initial_step(&self, f: &mut impl FnMut(f64, &[f64; N]) -> [f64; N], f0: &[f64; N]) -> f64 {
        let d0 = self.norm(&self.y, &self.y, &self.y);
        let d1 = self.norm(f0, &self.y, &self.y);
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        let y1: [f64; N] = std::array::from_fn(|i| self.y[i] + h0 * f0[i]);
        let f1 = f(self.t + h0, &y1);
        let df: [f64; N] = std::array::from_fn(|i| f1[i] - f0[i]);
        let d2 = self.norm(&df, &self.y, &self.y) / h0;
        let dm = d1.max(d2);
        let h1 = if dm <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / dm).powf(0.2)
        };
        (100.0 * h0).min(h1)
    }

    /// Integrates from `self.t` exactly onto `target`.
    fn segment(&mut self, f: &mut impl FnMut(f64, &[f64; N]) -> [f64; N], target: f64) {
        let mut k = [[0.0; N]; 7];
        k[0] = f(self.t, &self.y);
        if self.h <= 0.0 {
            self.h = self.initial_step(f, &k[0]);
        }
        let mut rejected = false;
        while self.t < target {
            self.steps += 1;
            assert!(
                self.steps <= MAX_STEPS,
                "dopri: more than {MAX_STEPS} steps at t = {} (target {target}); \
                 tolerances too tight or the problem is stiff",
                self.t
            );
            let remaining = target - self.t;
            let last = self.h >= remaining;
            let h = if last { remaining } else { self.h };
            assert!(
                last || h > 1e-14 * self.t.abs().max(1.0),
                "dopri: step size underflow (h = {h}) at t = {}",
                self.t
            );
            for s in 1..7 {
                let ys: [f64; N] = std::array::from_fn(|i| {
                    self.y[i] + h * (0..s).map(|j| A[s][j] * k[j][i]).sum::<f64>()
                });
                k[s] = f(self.t + C[s] * h, &ys);
            }
            // The seventh stage is evaluated at the fifth-order solution (FSAL).
            let y_new: [f64; N] = std::array::from_fn(|i| {
                self.y[i] + h * (0..6).map(|j| A[6][j] * k[j][i]).sum::<f64>()
            });
            let e: [f64; N] =
                std::array::from_fn(|i| h * (0..7).map(|j| E[j] * k[j][i]).sum::<f64>());
            let err = self.norm(&e, &self.y, &y_new);
            if err <= 1.0 {
                assert!(
                    y_new.iter().all(|v| v.is_finite()),
                    "dopri: non-finite state at t = {}",
                    self.t
                );
                let mut fac = (0.9 * err.powf(-0.2)).clamp(0.2, 5.0);
                if rejected {
                    fac = fac.min(1.0);
                }
                if !last || h == self.h {
                    self.h = h * fac;
                } else {
                    // A step shortened onto the target says nothing against the proposal.
                    self.h = self.h.max(h * fac);
                }
                self.t = if last { target } else { self.t + h };
                self.y = y_new;
                k[0] = k[6];
                rejected = false;
            } else {
                let fac = if err.is_finite() {
                    (0.9 * err.powf(-0.2)).clamp(0.2, 1.0)
                } else {
                    0.2
                };
                self.h = h * fac;
                rejected = true;
            }
        }
    }
}
