//! The pivot-free LU of a small system as one dense block: the same elimination order and
//! pivot test as the supernodal factors, without their index lists, which cost more than the
//! arithmetic they save below [`DENSE_MAX`] unknowns.

use super::{TinyPivot, TINY};
use crate::runtime::Pattern;
use std::ops::Range;

/// Systems of at most this many unknowns are factored densely. Measured (CPU of whole runs,
/// dense against supernodal): the pendulum (4 unknowns) 0.79x, the two-bar (26) 0.95x, chains
/// of 3, 4 and 5 links (39, 52 and 65) 0.91x, 0.93x and 1.00x, the windmill (77) 1.05x; since
/// the elimination keeps to the factors' reach, the windmill 0.968x (11 paired runs).
pub const DENSE_MAX: usize = 80;

/// `L` below the diagonal and `U` on and above it, column-major in the elimination order.
pub(super) struct Dense {
    n: usize,
    lu: Vec<f64>,
    /// Where each stored entry of the matrix goes in `lu`.
    dest: Vec<usize>,
    /// Per pivot `k`: the rows of `L`'s column `k` below the diagonal and the columns of
    /// `U`'s row `k` right of it that the factors' pattern (with its fill) can make nonzero,
    /// as ranges. The elimination updates only their product: on the two-bar (26 unknowns,
    /// 494 entries, no fill) 2,704 multiply-adds instead of 3,796.
    reach: Vec<(Range<usize>, Range<usize>)>,
    /// Per pivot `k`: the rows of `U`'s column `k` above the diagonal that can be nonzero
    /// (for the backward substitution), once the pattern is filled.
    above: Vec<Range<usize>>,
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
        // The factors' pattern: the matrix's, and the fill of each elimination.
        let mut nz = vec![false; n * n];
        for &d in &dest {
            nz[d] = true;
        }
        let mut reach = Vec::with_capacity(n);
        for k in 0..n {
            let span = |hit: &dyn Fn(usize) -> bool| {
                let first = (k + 1..n).find(|&i| hit(i)).unwrap_or(n);
                let end = (k + 1..n).rev().find(|&i| hit(i)).map_or(first, |i| i + 1);
                first..end
            };
            let rows = span(&|i| nz[i + k * n]);
            let cols = span(&|j| nz[k + j * n]);
            for j in cols.clone() {
                if nz[k + j * n] {
                    for i in rows.clone() {
                        if nz[i + k * n] {
                            nz[i + j * n] = true;
                        }
                    }
                }
            }
            reach.push((rows, cols));
        }
        let above = (0..n)
            .map(|k| {
                let first = (0..k).find(|&i| nz[i + k * n]).unwrap_or(k);
                let end = (0..k)
                    .rev()
                    .find(|&i| nz[i + k * n])
                    .map_or(first, |i| i + 1);
                first..end
            })
            .collect();
        Dense {
            n,
            lu: vec![0.0; n * n],
            dest,
            reach,
            above,
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
            let (rows, cols) = self.reach[k].clone();
            let (done, rest) = a.split_at_mut((k + 1) * n);
            let lk = &mut done[k * n + rows.start..k * n + rows.end];
            for v in lk.iter_mut() {
                *v *= inv;
            }
            let first = (cols.start - k - 1) * n;
            let last = (cols.end - k - 1) * n;
            for col in rest[first..last].chunks_exact_mut(n) {
                let u = col[k];
                if u != 0.0 {
                    for (d, l) in col[rows.clone()].iter_mut().zip(lk.iter()) {
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
                let rows = self.reach[k].0.clone();
                let l = &a[k * n + rows.start..k * n + rows.end];
                for (yi, l) in y[rows].iter_mut().zip(l) {
                    *yi -= l * yk;
                }
            }
        }
        for k in (0..n).rev() {
            y[k] *= self.recip[k];
            let yk = y[k];
            let rows = self.above[k].clone();
            let u = &a[k * n + rows.start..k * n + rows.end];
            for (yi, u) in y[rows].iter_mut().zip(u) {
                *yi -= u * yk;
            }
        }
    }
}
