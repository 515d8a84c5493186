//! The algorithmic accelerations of the last steps of one size, which the extrapolating
//! predictors ([`super::step::Predictor::Extrapolated`]) continue by a polynomial.

use crate::runtime::State;

/// The highest order of extrapolation: the polynomial through the algorithmic accelerations
/// of the step's start and of the `ORDERS` steps before it. On the two-bar (theta2_0 = 0,
/// 1 ms, 50 s) the first correction after the predictor, whose size decides whether a step
/// ends after it, fell from up to 1.4e-6 (acceleration unchanged) to 1.2e-9 (order 3), and
/// the Newton iterations from 97,284 to 92,415 (order 1), 77,389 (2), 62,713 (3) and
/// 51,447 (4); 51,448 with the predictor chosen as `Integrator::best_predictor` chooses it.
pub(super) const ORDERS: usize = 4;

/// The highest order of the extrapolations that continue the scheme's ringing too: each
/// takes two more past steps than the polynomial alone.
pub(super) const RINGS: usize = ORDERS - 1;

/// `COEF[p - 1]`: the weights of `alg_n, alg_{n-1}, ..., alg_{n-p}` in the extrapolation of
/// order `p` to `alg_{n+1}` (the binomial coefficients of the `(p + 1)`-th difference).
const COEF: [[f64; ORDERS + 1]; ORDERS] = [
    [2.0, -1.0, 0.0, 0.0, 0.0],
    [3.0, -3.0, 1.0, 0.0, 0.0],
    [4.0, -6.0, 4.0, -1.0, 0.0],
    [5.0, -10.0, 10.0, -5.0, 1.0],
];

/// The algorithmic accelerations of the steps before the current one, newest first: each
/// slot holds the unknowns' then the nodes' body-frame six (incremental rotations).
pub(super) struct History {
    past: Vec<Vec<f64>>,
    /// `ring[d - 1]`: the weights of `alg_n, alg_{n-1}, ..., alg_{n-d-1}` in the
    /// extrapolation of order `d` that also continues the scheme's ringing
    /// ([`History::ringing`]).
    ring: [[f64; ORDERS + 1]; RINGS],
    /// How many slots hold consecutive steps of size `h`.
    count: usize,
    h: Option<f64>,
    n: usize,
}

impl History {
    /// `ringing`: the scheme's ringing polynomial `z^2 + b1 z + b0` as `(b1, b0)`
    /// ([`super::newmark::Scheme::ringing`]).
    pub(super) fn new(n: usize, nodes: usize, ringing: (f64, f64)) -> History {
        // (E - 1)^d (E^2 + b1 E + b0), ascending powers of E.
        let mut ring = [[0.0; ORDERS + 1]; RINGS];
        for (i, weights) in ring.iter_mut().enumerate() {
            let d = i + 1;
            let mut q = [0.0; ORDERS + 2];
            (q[0], q[1], q[2]) = (ringing.1, ringing.0, 1.0);
            // Times (E - 1), d times: from degree 2 to d + 2.
            for deg in 2..d + 2 {
                for k in (0..=deg + 1).rev() {
                    q[k] = if k > 0 { q[k - 1] } else { 0.0 } - q[k];
                }
            }
            // x_{n+1} = -(q_0 x_{n-d-1} + ... + q_{d+1} x_n): alg_{n-j} weighs -q_{d+1-j}.
            for (j, w) in weights.iter_mut().enumerate().take(d + 2) {
                *w = -q[d + 1 - j];
            }
        }
        History {
            past: vec![vec![0.0; n + 6 * nodes]; ORDERS],
            ring,
            count: 0,
            h: None,
            n,
        }
    }

    /// Forgets the steps taken (a restart, a halving).
    pub(super) fn clear(&mut self) {
        self.count = 0;
        self.h = None;
    }

    /// Records `start`, the state at the start of a converged step of size `h`; `continued`:
    /// the step before it had size `h` too.
    pub(super) fn push(&mut self, start: &State, h: f64, continued: bool) {
        self.past.rotate_right(1);
        let slot = &mut self.past[0];
        slot[..self.n].copy_from_slice(&start.alg);
        for (dst, f) in slot[self.n..].chunks_exact_mut(6).zip(&start.frames) {
            dst.copy_from_slice(&f.alg);
        }
        let continued = continued && self.h == Some(h);
        self.count = if continued {
            (self.count + 1).min(ORDERS)
        } else {
            1
        };
        self.h = Some(h);
    }

    /// The highest order available to a step of size `h`.
    pub(super) fn orders(&self, h: f64) -> usize {
        if self.h == Some(h) {
            self.count
        } else {
            0
        }
    }

    /// The extrapolation of order `p` (at most [`History::orders`]) of slot `i` (an unknown,
    /// or `n + 6 k + j` for component `j` of node `k`'s frame), whose value now is `now`.
    #[inline]
    pub(super) fn extrapolate(&self, p: usize, i: usize, now: f64) -> f64 {
        Self::extrapolate_from(p, now, &self.slot(i))
    }

    /// Slot `i`'s past values, newest first (those beyond [`History::orders`] stale).
    #[inline]
    pub(super) fn slot(&self, i: usize) -> [f64; ORDERS] {
        std::array::from_fn(|j| self.past[j][i])
    }

    /// [`History::extrapolate`] from a slot's past values.
    #[inline]
    pub(super) fn extrapolate_from(p: usize, now: f64, past: &[f64; ORDERS]) -> f64 {
        let c = &COEF[p - 1];
        let mut x = c[0] * now;
        for j in 0..p {
            x += c[j + 1] * past[j];
        }
        x
    }

    /// The extrapolation of order `d` (at most [`History::orders`] less one) of slot `i`
    /// that continues the scheme's ringing as well as a polynomial of degree `d - 1`.
    #[inline]
    pub(super) fn ringing(&self, d: usize, i: usize, now: f64) -> f64 {
        self.ringing_from(d, now, &self.slot(i))
    }

    /// [`History::ringing`] from a slot's past values.
    #[inline]
    pub(super) fn ringing_from(&self, d: usize, now: f64, past: &[f64; ORDERS]) -> f64 {
        let c = &self.ring[d - 1];
        let mut x = c[0] * now;
        for j in 0..=d {
            x += c[j + 1] * past[j];
        }
        x
    }

    /// The slot of component `j` of node `k`'s frame.
    #[inline]
    pub(super) fn frame_slot(&self, k: usize, j: usize) -> usize {
        self.n + 6 * k + j
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The extrapolation of order `p` continues a polynomial of degree `p` exactly, in the
    /// unknowns' and the frames' slots, and one of a higher degree with the error of its next
    /// difference; the orders available count the consecutive steps of one size.
    #[test]
    fn extrapolates_polynomials_of_its_order_exactly() {
        let h = 1e-3;
        let poly = |d: i32, t: f64| (0..=d).map(|j| (0.3 + j as f64) * t.powi(j)).sum::<f64>();
        for d in 1..=ORDERS as i32 + 1 {
            let mut past = History::new(1, 1, (0.0, 0.0));
            let mut st = State::zeros(1, 1);
            for k in 0..ORDERS {
                st.alg[0] = poly(d, k as f64 * h);
                st.frames[0].alg[4] = -poly(d, k as f64 * h);
                past.push(&st, h, k > 0);
            }
            assert_eq!(past.orders(h), ORDERS);
            let (now, next) = (poly(d, ORDERS as f64 * h), poly(d, (ORDERS + 1) as f64 * h));
            for p in 1..=ORDERS {
                let miss = (past.extrapolate(p, 0, now) - next).abs();
                let frame = past.extrapolate(p, past.frame_slot(0, 4), -now) + next;
                if p as i32 >= d {
                    // Measured at most 5.0e-16.
                    let off = miss.max(frame.abs());
                    assert!(off < 1.5e-15, "degree {d}, order {p}: {off:e}");
                } else {
                    // The polynomial's next difference, (p + 1)! c_{p+1} h^{p+1} with
                    // c_j = j + 0.3, and terms h times smaller from higher degrees: measured
                    // within 1.7 % of it.
                    let factorial: f64 = (1..=p + 1).map(|j| j as f64).product();
                    let expected = factorial * (p as f64 + 1.3) * h.powi(p as i32 + 1);
                    let off = (miss / expected - 1.0).abs();
                    assert!(
                        off < 0.05,
                        "degree {d}, order {p}: {miss:e} against {expected:e}"
                    );
                }
            }
        }
        let mut past = History::new(1, 1, (0.0, 0.0));
        let st = State::zeros(1, 1);
        past.push(&st, h, false);
        past.push(&st, h, true);
        assert_eq!((past.orders(h), past.orders(h / 2.0)), (2, 0));
        past.push(&st, h / 2.0, true);
        assert_eq!((past.orders(h), past.orders(h / 2.0)), (0, 1));
        past.clear();
        assert_eq!(past.orders(h / 2.0), 0);
    }

    /// The extrapolation of order `d` that continues the ringing continues exactly a
    /// polynomial of degree `d - 1` plus `(c0 + c1 n) z^n`, where `z` is the double root of the
    /// ringing polynomial (generalized-alpha's `-rho_inf`), and `alg_n` ringing at a simple
    /// root too, where the polynomial's roots are distinct.
    #[test]
    fn ringing_extrapolations_continue_the_ringing_exactly() {
        let h = 1e-3;
        // (z + 0.9)^2 and (z + 0.9)(z + 0.5).
        for (ringing, roots) in [
            ((1.8, 0.81), (-0.9f64, -0.9f64)),
            ((1.4, 0.45), (-0.9, -0.5)),
        ] {
            let double = roots.0 == roots.1;
            let seq = |d: usize, n: usize| {
                let t = n as f64 * h;
                let poly: f64 = (0..d).map(|j| (0.7 + j as f64) * t.powi(j as i32)).sum();
                let ring = if double {
                    (0.3 - 0.02 * n as f64) * roots.0.powi(n as i32)
                } else {
                    0.3 * roots.0.powi(n as i32) - 0.2 * roots.1.powi(n as i32)
                };
                poly + ring
            };
            for d in 1..=RINGS {
                let mut past = History::new(1, 1, ringing);
                let mut st = State::zeros(1, 1);
                for n in 0..ORDERS {
                    st.alg[0] = seq(d, n);
                    st.frames[0].alg[2] = 2.0 * seq(d, n);
                    past.push(&st, h, n > 0);
                }
                let (now, next) = (seq(d, ORDERS), seq(d, ORDERS + 1));
                let miss = (past.ringing(d, 0, now) - next).abs();
                let frame = (past.ringing(d, past.frame_slot(0, 2), 2.0 * now) - 2.0 * next).abs();
                // Measured at most 4.4e-16.
                assert!(
                    miss.max(frame) < 1.2e-15,
                    "{roots:?}, order {d}: {miss:e}, {frame:e}"
                );
            }
        }
    }

    /// Generalized-alpha and HHT ring at `-rho_inf`, a double root.
    #[test]
    fn the_schemes_ring_at_minus_rho_inf_twice() {
        use crate::settings::{Method, Settings};
        let cases = [
            (Method::GeneralizedAlpha, 0.9, 0.0, 0.9),
            (Method::GeneralizedAlpha, 0.5, 0.0, 0.5),
            (Method::Hht, 0.0, -0.1, 0.9 / 1.1),
            (Method::Hht, 0.0, -0.3, 0.7 / 1.3),
        ];
        for (method, rho_inf, alpha, rho) in cases {
            let set = Settings {
                method,
                rho_inf,
                alpha,
                ..Settings::default()
            };
            let (b1, b0) = super::super::newmark::Scheme::of(&set).ringing();
            // Measured at most 1.3e-15.
            let off = (b1 - 2.0 * rho).abs().max((b0 - rho * rho).abs());
            assert!(off < 4e-15, "{method:?} {rho_inf} {alpha}: {b1} {b0}");
        }
    }
}
