//! The triangular solves with the supernodal factors: one right-hand side, or several at once
//! (Floquet's tangent solves a step's directions together).

use super::PivotFree;

impl PivotFree {
    /// `rhs <- U^-1 L^-1 rhs`, in the original numbering.
    pub fn substitute(&mut self, rhs: &mut [f64]) {
        let (y, g) = (&mut self.y, &mut self.gather);
        for (k, &o) in self.perm.iter().enumerate() {
            y[k] = rhs[o];
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
                y[f + k] /= l[k + k * ld];
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
    /// each supernode's entries are read once for all of them. The workspace grows on the
    /// first call of a size and is kept.
    pub fn substitute_many(&mut self, rhs: &mut [f64], count: usize) {
        let n = self.perm.len();
        if count == 0 {
            return;
        }
        if self.many.0.len() < n * count {
            self.many.0.resize(n * count, 0.0);
        }
        if self.many.1.len() < self.gather.len() * count {
            self.many.1.resize(self.gather.len() * count, 0.0);
        }
        let (y, g) = (&mut self.many.0, &mut self.many.1);
        // Row-major: unknown k's right-hand sides side by side.
        for (k, &o) in self.perm.iter().enumerate() {
            for c in 0..count {
                y[k * count + c] = rhs[c * n + o];
            }
        }
        let ns = self.first.len() - 1;
        for t in 0..ns {
            let f = self.first[t];
            let w = self.first[t + 1] - f;
            let rows = &self.rows[self.rows_ptr[t]..self.rows_ptr[t + 1]];
            let (m, ld) = (rows.len(), w + rows.len());
            let l = &self.x[self.l_at[t]..self.l_at[t] + ld * w];
            let g = &mut g[..m * count];
            g.fill(0.0);
            for k in 0..w {
                let c = &l[k * ld..(k + 1) * ld];
                let (head, tail) = y.split_at_mut((f + k + 1) * count);
                let yk = &head[(f + k) * count..];
                for i in k + 1..w {
                    let yi = &mut tail[(i - k - 1) * count..(i - k) * count];
                    for (a, b) in yi.iter_mut().zip(yk) {
                        *a -= c[i] * b;
                    }
                }
                for (gi, ci) in g.chunks_mut(count).zip(&c[w..]) {
                    for (a, b) in gi.iter_mut().zip(yk) {
                        *a += ci * b;
                    }
                }
            }
            for (&i, gi) in rows.iter().zip(g.chunks(count)) {
                for (a, b) in y[i * count..(i + 1) * count].iter_mut().zip(gi) {
                    *a -= b;
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
            let g = &mut g[..m * count];
            for (gi, &i) in g.chunks_mut(count).zip(rows) {
                gi.copy_from_slice(&y[i * count..(i + 1) * count]);
            }
            for j in 0..w {
                let yj = &mut y[(f + j) * count..(f + j + 1) * count];
                for (u, gi) in ut[j * m..(j + 1) * m].iter().zip(g.chunks(count)) {
                    for (a, b) in yj.iter_mut().zip(gi) {
                        *a -= u * b;
                    }
                }
            }
            for k in (0..w).rev() {
                let d = l[k + k * ld];
                let (head, tail) = y.split_at_mut((f + k) * count);
                let yk = &mut tail[..count];
                yk.iter_mut().for_each(|a| *a /= d);
                for i in 0..k {
                    let yi = &mut head[(f + i) * count..(f + i + 1) * count];
                    for (a, b) in yi.iter_mut().zip(yk.iter()) {
                        *a -= l[i + k * ld] * b;
                    }
                }
            }
        }
        for (k, &o) in self.perm.iter().enumerate() {
            for c in 0..count {
                rhs[c * n + o] = y[k * count + c];
            }
        }
    }
}
