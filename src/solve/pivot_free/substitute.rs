//! The triangular solves with the supernodal factors: one right-hand side, or several at once
//! (Floquet's tangent solves a step's directions together).

use super::PivotFree;

/// The most right-hand sides updated together by [`PivotFree::substitute_many`]. A pass over
/// small supernodes is bound by the latency of its chain of dependent updates, not by its
/// arithmetic, so a pass with more lanes costs little more than one with fewer: on the
/// windmill's Floquet point (10 directions), one pass of 10 right-hand sides instead of passes
/// of 4, 4 and 2 took 4.7 % off the whole point (criterion, 66.5 ms to 63.4 ms).
const LANES: usize = 12;

impl PivotFree {
    /// `rhs <- U^-1 L^-1 rhs`, in the original numbering.
    pub fn substitute(&mut self, rhs: &mut [f64]) {
        let (y, g) = (&mut self.y, &mut self.gather);
        for (k, &o) in self.perm.iter().enumerate() {
            y[k] = rhs[o];
        }
        if let Some(dense) = &self.dense {
            dense.substitute(y);
            for (k, &o) in self.perm.iter().enumerate() {
                rhs[o] = y[k];
            }
            return;
        }
        let ns = self.first.len() - 1;
        // Forward: each supernode's own unknowns, then its rows below through one dense
        // product and one scatter.
        for t in 0..ns {
            let f = self.first[t];
            let w = self.first[t + 1] - f;
            let rows = &self.rows[self.rows_ptr[t]..self.rows_ptr[t + 1]];
            let (m, ld) = (rows.len(), w + rows.len());
            let l = &self.x[self.l_at[t]..self.l_at[t] + ld * w];
            let g = &mut g[..m];
            g.fill(0.0);
            for k in 0..w {
                let yk = y[f + k];
                if yk != 0.0 {
                    let c = &l[k * ld..(k + 1) * ld];
                    for i in k + 1..w {
                        y[f + i] -= c[i] * yk;
                    }
                    for (gi, ci) in g.iter_mut().zip(&c[w..]) {
                        *gi += ci * yk;
                    }
                }
            }
            for (&i, gi) in rows.iter().zip(g.iter()) {
                y[i] -= gi;
            }
        }
        // Backward: the rows below gathered once, then the diagonal block.
        for t in (0..ns).rev() {
            let f = self.first[t];
            let w = self.first[t + 1] - f;
            let rows = &self.rows[self.rows_ptr[t]..self.rows_ptr[t + 1]];
            let (m, ld) = (rows.len(), w + rows.len());
            let l = &self.x[self.l_at[t]..self.l_at[t] + ld * w];
            let ut = &self.x[self.u_at[t]..self.u_at[t] + m * w];
            let g = &mut g[..m];
            for (gi, &i) in g.iter_mut().zip(rows) {
                *gi = y[i];
            }
            for j in 0..w {
                let s: f64 = ut[j * m..(j + 1) * m]
                    .iter()
                    .zip(g.iter())
                    .map(|(u, v)| u * v)
                    .sum();
                y[f + j] -= s;
            }
            for k in (0..w).rev() {
                y[f + k] *= self.recip[f + k];
                let yk = y[f + k];
                for i in 0..k {
                    y[f + i] -= l[i + k * ld] * yk;
                }
            }
        }
        for (k, &o) in self.perm.iter().enumerate() {
            rhs[o] = y[k];
        }
    }

    /// `rhs <- U^-1 L^-1 rhs` for `count` right-hand sides at once (column-major `n x count`):
    /// each supernode's entries are read once for every [`LANES`] of them, which are updated
    /// together as fixed-size rows (unrolled and vectorised). The workspace grows on the first
    /// call and is kept.
    pub fn substitute_many(&mut self, rhs: &mut [f64], count: usize) {
        let n = self.perm.len();
        if self.dense.is_some() {
            for col in rhs.chunks_exact_mut(n.max(1)).take(count) {
                self.substitute(col);
            }
            return;
        }
        // Passes of equal width, as few as [`LANES`] allows.
        let passes = count.div_ceil(LANES);
        let mut done = 0;
        for p in 0..passes {
            let lanes = (count - done).div_ceil(passes - p);
            let cols = &mut rhs[done * n..(done + lanes) * n];
            match lanes {
                12 => self.substitute_lanes::<12>(cols),
                11 => self.substitute_lanes::<11>(cols),
                10 => self.substitute_lanes::<10>(cols),
                9 => self.substitute_lanes::<9>(cols),
                8 => self.substitute_lanes::<8>(cols),
                7 => self.substitute_lanes::<7>(cols),
                6 => self.substitute_lanes::<6>(cols),
                5 => self.substitute_lanes::<5>(cols),
                4 => self.substitute_lanes::<4>(cols),
                3 => self.substitute_lanes::<3>(cols),
                2 => self.substitute_lanes::<2>(cols),
                _ => self.substitute_lanes::<1>(cols),
            }
            done += lanes;
        }
    }

    /// [`PivotFree::substitute_many`] for `B` right-hand sides (column-major `n x B`).
    fn substitute_lanes<const B: usize>(&mut self, rhs: &mut [f64]) {
        let n = self.perm.len();
        if self.many.0.len() < n * B {
            self.many.0.resize(n * B, 0.0);
        }
        if self.many.1.len() < self.gather.len() * B {
            self.many.1.resize(self.gather.len() * B, 0.0);
        }
        // Row-major: unknown k's right-hand sides side by side.
        let (y, _) = self.many.0[..n * B].as_chunks_mut::<B>();
        let (g, _) = self.many.1.as_chunks_mut::<B>();
        for (k, &o) in self.perm.iter().enumerate() {
            for (c, yk) in y[k].iter_mut().enumerate() {
                *yk = rhs[c * n + o];
            }
        }
        let ns = self.first.len() - 1;
        for t in 0..ns {
            let f = self.first[t];
            let w = self.first[t + 1] - f;
            let rows = &self.rows[self.rows_ptr[t]..self.rows_ptr[t + 1]];
            let (m, ld) = (rows.len(), w + rows.len());
            let l = &self.x[self.l_at[t]..self.l_at[t] + ld * w];
            let g = &mut g[..m];
            g.fill([0.0; B]);
            for k in 0..w {
                let c = &l[k * ld..(k + 1) * ld];
                let yk = y[f + k];
                for (yi, &ci) in y[f + k + 1..f + w].iter_mut().zip(&c[k + 1..w]) {
                    for j in 0..B {
                        yi[j] -= ci * yk[j];
                    }
                }
                for (gi, &ci) in g.iter_mut().zip(&c[w..]) {
                    for j in 0..B {
                        gi[j] += ci * yk[j];
                    }
                }
            }
            for (&i, gi) in rows.iter().zip(g.iter()) {
                for j in 0..B {
                    y[i][j] -= gi[j];
                }
            }
        }
        for t in (0..ns).rev() {
            let f = self.first[t];
            let w = self.first[t + 1] - f;
            let rows = &self.rows[self.rows_ptr[t]..self.rows_ptr[t + 1]];
            let (m, ld) = (rows.len(), w + rows.len());
            let l = &self.x[self.l_at[t]..self.l_at[t] + ld * w];
            let ut = &self.x[self.u_at[t]..self.u_at[t] + m * w];
            let g = &mut g[..m];
            for (gi, &i) in g.iter_mut().zip(rows) {
                *gi = y[i];
            }
            for j in 0..w {
                let yj = &mut y[f + j];
                for (&u, gi) in ut[j * m..(j + 1) * m].iter().zip(g.iter()) {
                    for c in 0..B {
                        yj[c] -= u * gi[c];
                    }
                }
            }
            for k in (0..w).rev() {
                let d = self.recip[f + k];
                for c in 0..B {
                    y[f + k][c] *= d;
                }
                let yk = y[f + k];
                for (yi, &lik) in y[f..f + k].iter_mut().zip(&l[k * ld..k * ld + k]) {
                    for c in 0..B {
                        yi[c] -= lik * yk[c];
                    }
                }
            }
        }
        for (k, &o) in self.perm.iter().enumerate() {
            for (c, yk) in y[k].iter().enumerate() {
                rhs[c * n + o] = *yk;
            }
        }
    }
}
