//! The pivot-free LU of a small system as one dense block: the same elimination order and
//! pivot test as the supernodal factors, without their index lists, which cost more than the
//! arithmetic they save below [`DENSE_MAX`] unknowns.

use super::{TinyPivot, TINY};
use crate::runtime::Pattern;

/// Systems of at most this many unknowns are factored densely. Measured (CPU of whole runs,
/// dense against supernodal): the pendulum (4 unknowns) 0.79x, the two-bar (26) 0.95x, chains
/// of 3, 4 and 5 links (39, 52 and 65) 0.91x, 0.93x and 1.00x, the windmill (77) 1.05x.
pub const DENSE_MAX: usize = 60;

/// `L` below the diagonal and `U` on and above it, column-major in the elimination order.
pub(super) struct Dense {
    n: usize,
    lu: Vec<f64>,
    /// Where each stored entry of the matrix goes in `lu`.
    dest: Vec<usize>,
    /// Each pivot's reciprocal.
    recip: Vec<f64>,
}

impl Dense {
    /// For `pattern`, whose unknown `old` is eliminated `new_of[old]`-th.
    pub(super) fn new(pattern: &Pattern, new_of: &[usize]) -> Dense {
        let n = pattern.n;
        let mut dest = Vec::with_capacity(pattern.row_idx.len());
        for j in 0..n {
            for &i in &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]] {
                dest.push(new_of[i] + n * new_of[j]);
            }
        }
        Dense {
            n,
            lu: vec![0.0; n * n],
            dest,
            recip: vec![0.0; n],
        }
    }

    /// Factors `values`; `scale[k]` is the largest entry of new column `k`, `perm[new] = old`.
    pub(super) fn factor(
        &mut self,
        values: &[f64],
        scale: &[f64],
        perm: &[usize],
    ) -> Result<(), TinyPivot> {
        let n = self.n;
        let a = &mut self.lu;
        a.fill(0.0);
        for (&d, &v) in self.dest.iter().zip(values) {
            a[d] = v;
        }
        for k in 0..n {
            let p = a[k + k * n];
            if !p.is_finite() || p.abs() <= TINY * scale[k] {
                return Err(TinyPivot(perm[k]));
            }
            let inv = 1.0 / p;
            self.recip[k] = inv;
            let (done, rest) = a.split_at_mut((k + 1) * n);
            let lk = &mut done[k * n + k + 1..];
            for v in lk.iter_mut() {
                *v *= inv;
            }
            for col in rest.chunks_exact_mut(n) {
                let u = col[k];
                if u != 0.0 {
                    for (d, l) in col[k + 1..].iter_mut().zip(lk.iter()) {
                        *d -= l * u;
                    }
                }
            }
        }
        Ok(())
    }

    /// `y <- U^-1 L^-1 y`, in the elimination order.
    pub(super) fn substitute(&self, y: &mut [f64]) {
        let (n, a) = (self.n, &self.lu);
        for k in 0..n {
            let yk = y[k];
            if yk != 0.0 {
                for (yi, l) in y[k + 1..].iter_mut().zip(&a[k * n + k + 1..(k + 1) * n]) {
                    *yi -= l * yk;
                }
            }
        }
        for k in (0..n).rev() {
            y[k] *= self.recip[k];
            let yk = y[k];
            for (yi, u) in y[..k].iter_mut().zip(&a[k * n..k * n + k]) {
                *yi -= u * yk;
            }
        }
    }
}
