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
    /// How many slots hold consecutive steps of size `h`.
    count: usize,
    h: Option<f64>,
    n: usize,
}

impl History {
    pub(super) fn new(n: usize, nodes: usize) -> History {
        History {
            past: vec![vec![0.0; n + 6 * nodes]; ORDERS],
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
        let c = &COEF[p - 1];
        let mut x = c[0] * now;
        for j in 0..p {
            x += c[j + 1] * self.past[j][i];
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
            let mut past = History::new(1, 1);
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
        let mut past = History::new(1, 1);
        let st = State::zeros(1, 1);
        past.push(&st, h, false);
        past.push(&st, h, true);
        assert_eq!((past.orders(h), past.orders(h / 2.0)), (2, 0));
        past.push(&st, h / 2.0, true);
        assert_eq!((past.orders(h), past.orders(h / 2.0)), (0, 1));
        past.clear();
        assert_eq!(past.orders(h / 2.0), 0);
    }
}
