//! The iteration matrix's LU without pivoting, on supernodes analysed once (THEORY §6).
//!
//! Supernode `s` (width `w`, `m` rows below) keeps a dense `(w + m) x w` panel of `L` (its
//! diagonal block holds `L` below the diagonal and `U` on and above it) and a dense `m x w`
//! panel of `U^T`. The symbolic phase maps each entry of the matrix to its place in the panels
//! and lists, for each supernode, the later supernodes it updates and where each of its rows
//! lands in them. A numeric factorization is then arithmetic on those lists: no search, no
//! allocation, no pivoting. A pivot at or below [`TINY`] of its column's largest entry is
//! reported with its (original) unknown, never pivoted around.
//!
//! Contract: reads a pattern, its elimination and values; must not know elements or the
//! integrator.

mod dense;
mod substitute;

use dense::{Dense, DENSE_MAX};

use super::ordering::{Elimination, Rule};
use crate::runtime::Pattern;

/// A pivot this small relative to its column's largest entry (or not finite) stops the
/// factorization.
pub const TINY: f64 = 1e-12;

/// Factorizations between two whose solves measure what the refinement changes
/// ([`PivotFree::solve`]).
const CHECK_EVERY: usize = 16;

/// A refinement that moves the solution by more than this fraction of its largest entry is
/// done at every solve until one moves it less: the factorization has lost more than six of
/// the sixteen digits to the growth of its factors ([`PivotFree::solve`]).
const REFINE_ABOVE: f64 = 1e-10;

/// The update of a later supernode by one supernode's panels: rows `start..` of the source's
/// rows below (those past the target's first column), of which the first `nj` are the
/// target's own columns; `pos[p..p + ni]` places each in the target's rows.
struct Update {
    target: usize,
    start: usize,
    ni: usize,
    nj: usize,
    pos: usize,
}

pub struct PivotFree {
    /// `perm[new] = old`.
    perm: Vec<usize>,
    first: Vec<usize>,
    rows: Vec<usize>,
    rows_ptr: Vec<usize>,
    /// Offsets of each supernode's `L` panel and `U^T` panel in `x`.
    l_at: Vec<usize>,
    u_at: Vec<usize>,
    x: Vec<f64>,
    /// Where each stored entry of the matrix goes in `x`, and its new column.
    dest: Vec<usize>,
    /// The places in `x` no entry goes to (the fill), zeroed before each factorization.
    fill: Vec<usize>,
    new_of: Vec<usize>,
    /// The largest entry of each new column (and row), for the pivot test.
    scale: Vec<f64>,
    /// Each pivot's reciprocal: the backward substitution multiplies by it (a division is
    /// on the substitution's chain of dependent updates: it took a fifth of the substitution's
    /// time on the 1,000-link chain).
    recip: Vec<f64>,
    updates: Vec<Update>,
    updates_ptr: Vec<usize>,
    pos: Vec<usize>,
    tmp: Vec<f64>,
    y: Vec<f64>,
    /// A supernode's rows below, gathered (as long as the longest).
    gather: Vec<f64>,
    /// The factored matrix (for the refinement's residual, when the factorization's solves
    /// refine), the right-hand side and the residual.
    a: Vec<f64>,
    b: Vec<f64>,
    r: Vec<f64>,
    /// [`PivotFree::substitute_many`]'s workspace: the right-hand sides and the gathered rows.
    many: (Vec<f64>, Vec<f64>),
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Factorizations so far, whether the last one's solves refine (it keeps the matrix in
    /// `a` then), and whether the last measured refinement mattered.
    factorizations: usize,
    checked: bool,
    refining: bool,
    /// The whole system as one dense block, for small systems ([`DENSE_MAX`]).
    dense: Option<Dense>,
}

/// The new column whose pivot was tiny, as its original unknown.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TinyPivot(pub usize);

impl PivotFree {
    pub fn new(pattern: &Pattern, late: &[bool], rule: Rule) -> PivotFree {
        let e = Elimination::of(pattern, late, rule);
        let n = pattern.n;
        let ns = e.supernodes();
        let mut sn = vec![0usize; n];
        for s in 0..ns {
            sn[e.first[s]..e.first[s + 1]].fill(s);
        }
        let mut inv = vec![0usize; n];
        for (k, &o) in e.perm.iter().enumerate() {
            inv[o] = k;
        }
        let (mut l_at, mut u_at, mut size) = (Vec::with_capacity(ns), Vec::with_capacity(ns), 0);
        for s in 0..ns {
            let (w, m) = (
                e.first[s + 1] - e.first[s],
                e.rows_ptr[s + 1] - e.rows_ptr[s],
            );
            l_at.push(size);
            size += (w + m) * w;
            u_at.push(size);
            size += m * w;
        }
        let below = |s: usize| &e.rows[e.rows_ptr[s]..e.rows_ptr[s + 1]];
        // The local row of new row `i` in supernode `s` (its own columns, then its rows below).
        let local = |s: usize, i: usize| -> usize {
            if i < e.first[s + 1] {
                i - e.first[s]
            } else {
                let w = e.first[s + 1] - e.first[s];
                w + below(s)
                    .binary_search(&i)
                    .expect("the fill holds every entry")
            }
        };
        let mut dest = Vec::with_capacity(pattern.row_idx.len());
        for j in 0..n {
            for &i in &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]] {
                let (ni, nj) = (inv[i], inv[j]);
                let d = if ni >= nj || sn[ni] == sn[nj] {
                    // L, or the diagonal block.
                    let s = sn[nj];
                    let ld = e.first[s + 1] - e.first[s] + below(s).len();
                    l_at[s] + local(s, ni) + (nj - e.first[s]) * ld
                } else {
                    // U above the diagonal block: row ni's supernode, column nj below it.
                    let s = sn[ni];
                    let w = e.first[s + 1] - e.first[s];
                    u_at[s] + (local(s, nj) - w) + (ni - e.first[s]) * below(s).len()
                };
                dest.push(d);
            }
        }
        let mut covered = vec![false; size];
        dest.iter().for_each(|&d| covered[d] = true);
        let fill = (0..size).filter(|&d| !covered[d]).collect();
        let (mut updates, mut updates_ptr, mut pos) = (Vec::new(), vec![0], Vec::new());
        let mut tmp_len = 0;
        for t in 0..ns {
            let r = below(t);
            let mut a = 0;
            while a < r.len() {
                let target = sn[r[a]];
                let mut b = a;
                while b < r.len() && sn[r[b]] == target {
                    b += 1;
                }
                let (ni, nj) = (r.len() - a, b - a);
                let p = pos.len();
                pos.extend(r[a..].iter().map(|&i| local(target, i)));
                tmp_len = tmp_len.max(ni * nj);
                updates.push(Update {
                    target,
                    start: a,
                    ni,
                    nj,
                    pos: p,
                });
                a = b;
            }
            updates_ptr.push(updates.len());
        }
        let dense = (n <= DENSE_MAX).then(|| Dense::new(pattern, &inv));
        PivotFree {
            perm: e.perm.clone(),
            first: e.first.clone(),
            rows: e.rows.clone(),
            rows_ptr: e.rows_ptr.clone(),
            l_at,
            u_at,
            x: vec![0.0; size],
            dest,
            fill,
            new_of: inv,
            scale: vec![0.0; n],
            recip: vec![0.0; n],
            updates,
            updates_ptr,
            pos,
            tmp: vec![0.0; tmp_len],
            many: (Vec::new(), Vec::new()),
            y: vec![0.0; n],
            gather: vec![
                0.0;
                (0..ns)
                    .map(|s| e.rows_ptr[s + 1] - e.rows_ptr[s])
                    .max()
                    .unwrap_or(0)
            ],
            a: vec![0.0; pattern.row_idx.len()],
            b: vec![0.0; n],
            r: vec![0.0; n],
            col_ptr: pattern.col_ptr.clone(),
            row_idx: pattern.row_idx.clone(),
            factorizations: 0,
            checked: false,
            refining: true,
            dense,
        }
    }

    /// As [`PivotFree::new`], supernodal at every size (the tests compare both paths).
    #[cfg(test)]
    fn supernodal(pattern: &Pattern, late: &[bool], rule: Rule) -> PivotFree {
        let mut lu = PivotFree::new(pattern, late, rule);
        lu.dense = None;
        lu
    }

    /// Factors the matrix with the analysed pattern and `values`.
    pub fn factor(&mut self, values: &[f64]) -> Result<(), TinyPivot> {
        self.checked = self.refining || self.factorizations.is_multiple_of(CHECK_EVERY);
        self.factorizations = self.factorizations.wrapping_add(1);
        if self.checked {
            self.a.copy_from_slice(values);
        }
        if let Some(dense) = &mut self.dense {
            return dense.factor(values, &mut self.scale, &self.perm);
        }
        for &d in &self.fill {
            self.x[d] = 0.0;
        }
        self.scale.fill(0.0);
        for (j, &c) in self.new_of.iter().enumerate() {
            let (lo, hi) = (self.col_ptr[j], self.col_ptr[j + 1]);
            let m = &mut self.scale[c];
            for (&d, &v) in self.dest[lo..hi].iter().zip(&values[lo..hi]) {
                self.x[d] = v;
                // Not f64::max: a NaN here shows as a NaN pivot, and this compiles to maxsd.
                let a = v.abs();
                if a > *m {
                    *m = a;
                }
            }
        }
        for t in 0..self.first.len() - 1 {
            self.factor_panel(t)?;
            for u in self.updates_ptr[t]..self.updates_ptr[t + 1] {
                self.update(t, u);
            }
        }
        Ok(())
    }

    /// Factors supernode `t`'s diagonal block in place and solves its panels against it.
    fn factor_panel(&mut self, t: usize) -> Result<(), TinyPivot> {
        let f = self.first[t];
        let w = self.first[t + 1] - f;
        let m = self.rows_ptr[t + 1] - self.rows_ptr[t];
        let ld = w + m;
        let (l, ut) = self.x[self.l_at[t]..].split_at_mut(ld * w);
        let ut = &mut ut[..m * w];
        for k in 0..w {
            let p = l[k + k * ld];
            if !p.is_finite() || p.abs() <= TINY * self.scale[f + k] {
                return Err(TinyPivot(self.perm[f + k]));
            }
            let inv = 1.0 / p;
            self.recip[f + k] = inv;
            // Column k of L below the pivot, own rows and rows below alike.
            for v in &mut l[k + 1 + k * ld..(k + 1) * ld] {
                *v *= inv;
            }
            // The rest of the diagonal block and of L's panel.
            for j in k + 1..w {
                let u = l[k + j * ld];
                if u != 0.0 {
                    let (src, dst) = l.split_at_mut(j * ld);
                    let src = &src[k * ld + k + 1..(k + 1) * ld];
                    for (d, s) in dst[k + 1..ld].iter_mut().zip(src) {
                        *d -= s * u;
                    }
                }
            }
            // U's panel: row k is final; eliminate it from the rows after k.
            let (done, rest) = ut.split_at_mut((k + 1) * m);
            let uk = &done[k * m..];
            for j in k + 1..w {
                let lj = l[j + k * ld];
                if lj != 0.0 {
                    for (d, s) in rest[(j - k - 1) * m..(j - k) * m].iter_mut().zip(uk) {
                        *d -= lj * s;
                    }
                }
            }
        }
        Ok(())
    }

    /// Subtracts supernode `t`'s contribution from a later supernode.
    fn update(&mut self, t: usize, u: usize) {
        let Update {
            target,
            start,
            ni,
            nj,
            pos,
        } = self.updates[u];
        let w = self.first[t + 1] - self.first[t];
        let m = self.rows_ptr[t + 1] - self.rows_ptr[t];
        let ld = w + m;
        let (lt, ut) = (self.l_at[t], self.u_at[t]);
        let pos = &self.pos[pos..pos + ni];
        let ws = self.first[target + 1] - self.first[target];
        let ms = self.rows_ptr[target + 1] - self.rows_ptr[target];
        let lds = ws + ms;
        let (ls, us) = (self.l_at[target], self.u_at[target]);
        // L (and the diagonal block) of the target: rows I, columns J.
        let tmp = &mut self.tmp[..ni * nj];
        tmp.fill(0.0);
        for k in 0..w {
            let lcol = &self.x[lt + k * ld + w + start..lt + k * ld + w + start + ni];
            for b in 0..nj {
                let ukj = self.x[ut + k * m + start + b];
                if ukj != 0.0 {
                    for (d, s) in tmp[b * ni..(b + 1) * ni].iter_mut().zip(lcol) {
                        *d += s * ukj;
                    }
                }
            }
        }
        for b in 0..nj {
            let c = ls + pos[b] * lds;
            for a in 0..ni {
                self.x[c + pos[a]] -= tmp[b * ni + a];
            }
        }
        // U^T of the target: rows I past J, columns J.
        let nu = ni - nj;
        if nu == 0 {
            return;
        }
        let tmp = &mut self.tmp[..nu * nj];
        tmp.fill(0.0);
        for k in 0..w {
            let ucol = &self.x[ut + k * m + start + nj..ut + k * m + start + ni];
            for b in 0..nj {
                let ljk = self.x[lt + k * ld + w + start + b];
                if ljk != 0.0 {
                    for (d, s) in tmp[b * nu..(b + 1) * nu].iter_mut().zip(ucol) {
                        *d += s * ljk;
                    }
                }
            }
        }
        for b in 0..nj {
            let c = us + pos[b] * ms;
            for a in 0..nu {
                self.x[c + pos[nj + a] - ws] -= tmp[b * nu + a];
            }
        }
    }

    /// Solves `A x = rhs` in place with the last factorization, refined once with the residual
    /// `r = rhs - A x` (`x += A^-1 r`) when refining has mattered: the solves with the first
    /// factorization and every [`CHECK_EVERY`]-th refine and measure the refinement's change
    /// (only those factorizations keep a copy of the matrix), and every one refines while the
    /// last solve measured moved the solution by more than [`REFINE_ABOVE`] of its largest
    /// entry. Without pivoting the factors' entries are not bounded by one, and a growing
    /// factor would lose digits to round-off: the refinement takes them back. The models
    /// measured lose none: the refinement moves the correction by 1e-16 to 5e-13 of its
    /// largest entry (median 1.1e-13 on the 1,000-link chain, 4.3e-14 on the paper's beam
    /// windmill, 1.4e-15 on the two-bar, 4.6e-16 on the windmill; positions by at most 3e-18 m;
    /// the spherical top of `tests/joints/spherical.rs` ends 1.35e-13 rad from its azimuth
    /// refined, 1.39e-13 not), where it and the matrix's copy cost 15 % of the chain's run and
    /// 6 % of the two-bar's and the windmill's.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        if !self.checked {
            self.substitute(rhs);
            return;
        }
        self.b.copy_from_slice(rhs);
        self.substitute(rhs);
        let mut r = std::mem::take(&mut self.r);
        r.copy_from_slice(&self.b);
        for (j, &xj) in rhs.iter().enumerate() {
            if xj != 0.0 {
                let (lo, hi) = (self.col_ptr[j], self.col_ptr[j + 1]);
                for (&i, &a) in self.row_idx[lo..hi].iter().zip(&self.a[lo..hi]) {
                    r[i] -= a * xj;
                }
            }
        }
        self.substitute(&mut r);
        let (mut moved, mut largest) = (0.0f64, 0.0f64);
        for (x, d) in rhs.iter_mut().zip(&r) {
            *x += d;
            moved = moved.max(d.abs());
            largest = largest.max(x.abs());
        }
        // (`f64::max` passes over NaNs: a solution holding one fails `SparseLu`'s check.)
        self.refining = moved > REFINE_ABOVE * largest;
        self.r = r;
    }

    /// Supernodes, their widths, and the multiply-adds of one factorization.
    pub fn describe(&self) -> String {
        let ns = self.first.len() - 1;
        let mut widths = std::collections::BTreeMap::new();
        let mut flops = 0usize;
        for t in 0..ns {
            let w = self.first[t + 1] - self.first[t];
            let m = self.rows_ptr[t + 1] - self.rows_ptr[t];
            *widths.entry(w).or_insert(0) += 1;
            flops += w * w * w / 3 + w * w * m * 2 + w * m * m * 2;
        }
        if self.dense.is_some() {
            return format!("{} unknowns, dense", self.perm.len());
        }
        format!(
            "{} unknowns, {ns} supernodes (width: count {widths:?}), {} values stored, {flops} multiply-adds",
            self.perm.len(),
            self.x.len()
        )
    }
}

#[cfg(test)]
mod tests;
