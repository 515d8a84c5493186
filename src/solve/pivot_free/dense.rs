//! The pivot-free LU of a small system as one dense block: the same elimination order and
//! pivot test as the supernodal factors, without their index lists, which cost more than the
//! arithmetic they save below [`DENSE_MAX`] unknowns.

use super::{TinyPivot, TINY};
use crate::runtime::Pattern;
use std::ops::Range;

/// Systems of at most this many unknowns are factored densely. Measured (CPU of whole runs,
/// dense against supernodal): the pendulum (4 unknowns) 0.79x, the two-bar (26) 0.95x, chains
/// of 3, 4 and 5 links (39, 52 and 65) 0.91x, 0.93x and 1.00x, the windmill (77) 1.05x; since
/// the elimination keeps to the factors' reach, the windmill 0.968x (11 paired runs), and
/// since it keeps to its runs, 0.958x more (21 paired runs).
pub const DENSE_MAX: usize = 80;

/// Rows (or columns) of a pivot's reach this close (zeros between them) are updated as one
/// run: a run's loop costs about as much as a few multiply-adds.
const GAP: usize = 4;

/// `L` below the diagonal and `U` on and above it, column-major in the elimination order.
pub(super) struct Dense {
    n: usize,
    lu: Vec<f64>,
    /// Where each stored entry of the matrix goes in `lu`.
    dest: Vec<usize>,
    /// Per pivot `k`: the columns of `U`'s row `k` right of it that the factors' pattern
    /// (with its fill) can make nonzero, as the runs `cols[col_runs[k]..col_runs[k + 1]]`,
    /// and the rows of `L`'s column `k` below the diagonal that it can make nonzero, as the
    /// runs `rows[runs[k]..runs[k + 1]]` (runs closer than [`GAP`] merged). The elimination
    /// updates only their product: on the two-bar (26 unknowns, 494 entries, no fill) 2,704
    /// multiply-adds instead of 3,796 (one run each); on the windmill (77 unknowns), whose
    /// blades' rows and columns meet only the hub's, 11,976 in two runs each instead of
    /// 24,171 over one range of rows (and 64,908 over both ranges).
    cols: Vec<Range<usize>>,
    col_runs: Vec<usize>,
    rows: Vec<Range<usize>>,
    runs: Vec<usize>,
    /// Per pivot `k`: the rows of `U`'s column `k` above the diagonal that can be nonzero
    /// (for the backward substitution), once the pattern is filled.
    above: Vec<Range<usize>>,
    /// Each pivot's reciprocal.
    recip: Vec<f64>,
    /// The stored entries of each column of the matrix, `dest[col_ptr[j]..col_ptr[j + 1]]`,
    /// and that column's place in the elimination order.
    col_ptr: Vec<usize>,
    new_col: Vec<usize>,
    /// The places of `lu` that the factorization or the substitution reads and no stored
    /// entry sets: zeroed before each factorization, the rest of `lu` left as it is (on
    /// the two-bar 78 of 676, on the windmill 80 of 5,929).
    zero: Vec<usize>,
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
        // The places the stored entries set.
        let set = nz.clone();
        // Indices in runs, those closer than GAP merged, appended to `out`.
        fn push_runs(out: &mut Vec<Range<usize>>, hit: &[usize]) {
            let start = out.len();
            for &i in hit {
                let open = out.len() > start;
                match out.last_mut() {
                    Some(run) if open && i <= run.end + GAP => run.end = i + 1,
                    _ => out.push(i..i + 1),
                }
            }
        }
        let (mut cols, mut col_runs, mut rows, mut runs) =
            (Vec::new(), vec![0], Vec::new(), vec![0]);
        for k in 0..n {
            let hit: Vec<usize> = (k + 1..n).filter(|&i| nz[i + k * n]).collect();
            let across: Vec<usize> = (k + 1..n).filter(|&j| nz[k + j * n]).collect();
            for &j in &across {
                for &i in &hit {
                    nz[i + j * n] = true;
                }
            }
            push_runs(&mut rows, &hit);
            runs.push(rows.len());
            push_runs(&mut cols, &across);
            col_runs.push(cols.len());
        }
        let above: Vec<Range<usize>> = (0..n)
            .map(|k| {
                let first = (0..k).find(|&i| nz[i + k * n]).unwrap_or(k);
                let end = (0..k)
                    .rev()
                    .find(|&i| nz[i + k * n])
                    .map_or(first, |i| i + 1);
                first..end
            })
            .collect();
        let zero = Self::read(n, &above, (&rows, &runs), (&cols, &col_runs))
            .into_iter()
            .enumerate()
            .filter(|&(at, read)| read && !set[at])
            .map(|(at, _)| at)
            .collect();
        Dense {
            n,
            lu: vec![0.0; n * n],
            dest,
            cols,
            col_runs,
            rows,
            runs,
            above,
            recip: vec![0.0; n],
            col_ptr: pattern.col_ptr.clone(),
            new_col: new_of.to_vec(),
            zero,
        }
    }

    /// Which places of `lu` the factorization and the substitution read: each pivot, its
    /// column's runs, its row's entries in its column runs and their products, and `U`'s
    /// columns above the diagonal.
    fn read(
        n: usize,
        above: &[Range<usize>],
        (rows, runs): (&[Range<usize>], &[usize]),
        (cols, col_runs): (&[Range<usize>], &[usize]),
    ) -> Vec<bool> {
        let mut read = vec![false; n * n];
        for k in 0..n {
            read[k + k * n] = true;
            for i in above[k].clone() {
                read[i + k * n] = true;
            }
            for c in &cols[col_runs[k]..col_runs[k + 1]] {
                for j in c.clone() {
                    read[k + j * n] = true;
                }
            }
            for run in &rows[runs[k]..runs[k + 1]] {
                for i in run.clone() {
                    read[i + k * n] = true;
                    for c in &cols[col_runs[k]..col_runs[k + 1]] {
                        for j in c.clone() {
                            read[i + j * n] = true;
                        }
                    }
                }
            }
        }
        read
    }

    /// Factors `values`, with `scale[k]` set to the largest entry of new column `k`;
    /// `perm[new] = old`.
    pub(super) fn factor(
        &mut self,
        values: &[f64],
        scale: &mut [f64],
        perm: &[usize],
    ) -> Result<(), TinyPivot> {
        let n = self.n;
        let a = &mut self.lu;
        for &z in &self.zero {
            a[z] = 0.0;
        }
        for (j, &c) in self.new_col.iter().enumerate() {
            let (lo, hi) = (self.col_ptr[j], self.col_ptr[j + 1]);
            let mut m = 0.0;
            for (&d, &v) in self.dest[lo..hi].iter().zip(&values[lo..hi]) {
                a[d] = v;
                // Not f64::max: a NaN here shows as a NaN pivot, and this compiles to maxsd.
                let x = v.abs();
                if x > m {
                    m = x;
                }
            }
            scale[c] = m;
        }
        for k in 0..n {
            let p = a[k + k * n];
            if !p.is_finite() || p.abs() <= TINY * scale[k] {
                return Err(TinyPivot(perm[k]));
            }
            let inv = 1.0 / p;
            self.recip[k] = inv;
            let runs = &self.rows[self.runs[k]..self.runs[k + 1]];
            let cols = &self.cols[self.col_runs[k]..self.col_runs[k + 1]];
            let (done, rest) = a.split_at_mut((k + 1) * n);
            let lk = &mut done[k * n..(k + 1) * n];
            for run in runs {
                for v in &mut lk[run.clone()] {
                    *v *= inv;
                }
            }
            // Run by run, so that a column's update is one tight loop as without runs.
            for run in runs {
                let lk = &lk[run.clone()];
                for c in cols {
                    let at = (c.start - k - 1) * n..(c.end - k - 1) * n;
                    for col in rest[at].chunks_exact_mut(n) {
                        let u = col[k];
                        if u != 0.0 {
                            for (d, l) in col[run.clone()].iter_mut().zip(lk) {
                                *d -= l * u;
                            }
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Fills the factors' storage with NaN: a factorization after it reads none of it but
    /// what it zeroes or sets ([`Dense::zero`]).
    #[cfg(test)]
    pub(super) fn poison(&mut self) {
        self.lu.fill(f64::NAN);
    }

    /// The most runs of rows and of columns any pivot's elimination updates.
    #[cfg(test)]
    pub(super) fn most_runs(&self) -> (usize, usize) {
        let most = |ptr: &[usize]| ptr.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0);
        (most(&self.runs), most(&self.col_runs))
    }

    /// `y <- U^-1 L^-1 y`, in the elimination order.
    pub(super) fn substitute(&self, y: &mut [f64]) {
        let (n, a) = (self.n, &self.lu);
        for k in 0..n {
            let yk = y[k];
            if yk != 0.0 {
                let l = &a[k * n..(k + 1) * n];
                for run in &self.rows[self.runs[k]..self.runs[k + 1]] {
                    for (yi, l) in y[run.clone()].iter_mut().zip(&l[run.clone()]) {
                        *yi -= l * yk;
                    }
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
