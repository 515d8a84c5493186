//! Sparse LU through faer: the only module that imports faer.
//!
//! Invariant: the symbolic factorization and the workspace are computed once per pattern;
//! each Newton iteration refactors numerically into the same storage.

use super::ordering::Rule;
use super::pivot_free::{PivotFree, TinyPivot};
use crate::runtime::Pattern;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::factor::PartialPivLuParams;
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Spec};

#[derive(Debug, Clone, PartialEq)]
pub enum LinearError {
    /// The matrix could not be factored (structurally or numerically singular).
    Singular,
    /// The pivot-free factorization met a tiny pivot at this unknown, and the pivoting one
    /// could not factor the matrix either.
    TinyPivot(usize),
    /// The solution has non-finite entries (numerically singular matrix).
    NonFinite,
    /// faer reported an allocation failure.
    OutOfMemory,
}

/// faer's LU with partial pivoting, its symbolic factorization and workspace made once.
struct Pivoting {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    mem: MemBuffer,
}

/// A sparse LU whose symbolic work is done once per pattern.
///
/// The iteration matrix's (`SparseLu::pivot_free`) factors without pivoting in the order of
/// `ordering.rs`, each joint's multipliers after one side; should a pivot be tiny, in the
/// strict order (after both sides) from then on; should a pivot still be tiny (a model the
/// ordering does not cover), the matrix is factored with faer's partial pivoting from then on, and only if that fails too is it
/// singular, at the unknown of the tiny pivot. Other matrices (the constrained mass matrix,
/// which may hold massless rotations) use faer's from the start.
pub struct SparseLu {
    pattern: Pattern,
    /// The multipliers, and the rule the pivot-free order follows.
    late: Vec<bool>,
    rule: Rule,
    fast: Option<PivotFree>,
    pivoting: Option<Pivoting>,
    tiny: Option<usize>,
    factored: bool,
}

/// The average nonzeros per column from which the supernodal factorization is used.
pub const SUPERNODAL_DENSITY: usize = 12;

/// faer's COLAMD order either way. Patterns of coupled 6x6 and 3x3 blocks (at least
/// [`SUPERNODAL_DENSITY`] nonzeros a column: every model with rigid frames or beams) take the
/// supernodal factorization, whose pattern is found once here; faer's own choice was the
/// simplicial one, which searches the pattern again in every factorization and measured 1.26
/// to 1.63 times slower on the shipped models. Sparser patterns (point masses on distance
/// joints, chains) stay simplicial, where the two measured equal or the supernodal slower.
/// The rule depends on the pattern only, so a run's results do not depend on timing.
fn symbolic_params(pattern: &Pattern) -> LuSymbolicParams<'static> {
    let mut params = LuSymbolicParams::default();
    if pattern.row_idx.len() >= SUPERNODAL_DENSITY * pattern.n {
        params.supernodal_flop_ratio_threshold = SupernodalThreshold::FORCE_SUPERNODAL;
    }
    params
}

impl Pivoting {
    fn new(pattern: &Pattern) -> Result<Pivoting, LinearError> {
        let n = pattern.n;
        let sym =
            SymbolicSparseColMatRef::new_checked(n, n, &pattern.col_ptr, None, &pattern.row_idx);
        let symbolic = factorize_symbolic_lu(sym, symbolic_params(pattern))
            .map_err(|_| LinearError::OutOfMemory)?;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_lu_scratch::<f64>(
                Par::Seq,
                Spec::<PartialPivLuParams, f64>::default(),
            ),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]);
        let mem = MemBuffer::try_new(req).map_err(|_| LinearError::OutOfMemory)?;
        Ok(Pivoting {
            n,
            col_ptr: pattern.col_ptr.clone(),
            row_idx: pattern.row_idx.clone(),
            symbolic,
            numeric: NumericLu::new(),
            mem,
        })
    }

    fn factor(&mut self, values: &[f64]) -> Result<(), LinearError> {
        let sym = SymbolicSparseColMatRef::new_checked(
            self.n,
            self.n,
            &self.col_ptr,
            None,
            &self.row_idx,
        );
        let mat = SparseColMatRef::new(sym, values);
        let stack = MemStack::new(&mut self.mem);
        self.symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                mat,
                Par::Seq,
                stack,
                Spec::<PartialPivLuParams, f64>::default(),
            )
            .map_err(|_| LinearError::Singular)?;
        Ok(())
    }

    fn solve(&mut self, rhs: &mut [f64]) {
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        let stack = MemStack::new(&mut self.mem);
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, self.n, 1),
            Par::Seq,
            stack,
        );
    }
}

impl SparseLu {
    /// faer's LU with partial pivoting.
    pub fn new(pattern: &Pattern) -> Result<SparseLu, LinearError> {
        Ok(SparseLu {
            pattern: pattern.clone(),
            late: Vec::new(),
            rule: Rule::Strict,
            fast: None,
            pivoting: Some(Pivoting::new(pattern)?),
            tiny: None,
            factored: false,
        })
    }

    /// The pivot-free LU of an iteration matrix whose multipliers are flagged in `late`.
    pub fn pivot_free(pattern: &Pattern, late: &[bool]) -> SparseLu {
        SparseLu {
            pattern: pattern.clone(),
            late: late.to_vec(),
            rule: Rule::OneSide,
            fast: Some(PivotFree::new(pattern, late, Rule::OneSide)),
            pivoting: None,
            tiny: None,
            factored: false,
        }
    }

    /// The pivot-free factorization's size and work, for benchmarks.
    pub fn describe(&self) -> Option<String> {
        self.fast.as_ref().map(PivotFree::describe)
    }

    /// The order the pivot-free factorization follows (the strict one after a tiny pivot).
    pub fn rule(&self) -> Rule {
        self.rule
    }

    /// The unknown of the first tiny pivot met, after which faer's pivoting LU is used.
    pub fn tiny_pivot(&self) -> Option<usize> {
        self.tiny
    }

    /// Numeric factorization of the matrix with this pattern and `values`.
    pub fn factor(&mut self, values: &[f64]) -> Result<(), LinearError> {
        self.factored = false;
        while self.tiny.is_none() {
            let Some(fast) = &mut self.fast else { break };
            match fast.factor(values) {
                Ok(()) => {
                    self.factored = true;
                    return Ok(());
                }
                // A joint whose rows are not independent on the side its multipliers
                // followed: the strict order, made once, from then on.
                Err(TinyPivot(_)) if self.rule == Rule::OneSide => {
                    self.rule = Rule::Strict;
                    *fast = PivotFree::new(&self.pattern, &self.late, Rule::Strict);
                }
                Err(TinyPivot(i)) => self.tiny = Some(i),
            }
        }
        if self.pivoting.is_none() {
            self.pivoting = Some(Pivoting::new(&self.pattern)?);
        }
        let pivoting = self.pivoting.as_mut().expect("made above");
        pivoting.factor(values).map_err(|e| match self.tiny {
            Some(i) => LinearError::TinyPivot(i),
            None => e,
        })?;
        self.factored = true;
        Ok(())
    }

    /// Solves `A x = rhs` in place with the last factorization.
    pub fn solve(&mut self, rhs: &mut [f64]) -> Result<(), LinearError> {
        self.solve_with(rhs, true)
    }

    /// As [`SparseLu::solve`], without the pivot-free factorization's refinement: for an
    /// iteration that refines the solution itself (Newton with a kept matrix).
    pub fn solve_unrefined(&mut self, rhs: &mut [f64]) -> Result<(), LinearError> {
        self.solve_with(rhs, false)
    }

    /// As [`SparseLu::solve_unrefined`] for `count` right-hand sides at once (column-major).
    pub fn solve_many_unrefined(
        &mut self,
        rhs: &mut [f64],
        count: usize,
    ) -> Result<(), LinearError> {
        let n = self.pattern.n;
        match &mut self.fast {
            Some(fast) if self.factored && self.tiny.is_none() => {
                fast.substitute_many(rhs, count);
                if all_finite(rhs) {
                    Ok(())
                } else {
                    Err(LinearError::NonFinite)
                }
            }
            _ => rhs
                .chunks_mut(n.max(1))
                .take(count)
                .try_for_each(|col| self.solve_with(col, false)),
        }
    }

    fn solve_with(&mut self, rhs: &mut [f64], refine: bool) -> Result<(), LinearError> {
        if !self.factored {
            return Err(LinearError::Singular);
        }
        match (&mut self.fast, &mut self.pivoting) {
            (Some(fast), _) if self.tiny.is_none() && refine => fast.solve(rhs),
            (Some(fast), _) if self.tiny.is_none() => fast.substitute(rhs),
            (_, Some(p)) => p.solve(rhs),
            _ => return Err(LinearError::Singular),
        }
        if all_finite(rhs) {
            Ok(())
        } else {
            Err(self
                .tiny
                .map_or(LinearError::NonFinite, LinearError::TinyPivot))
        }
    }
}

/// Whether every entry is finite: `x * 0` is zero for those and NaN for the others, summed
/// without a branch per entry.
fn all_finite(x: &[f64]) -> bool {
    x.iter().fold(0.0, |s, v| s + v * 0.0) == 0.0
}

/// An orthonormal basis of the null space of the `rows x cols` row-major matrix `b`, as the
/// columns of a column-major `cols x r` array (singular values below `1e-10` of the largest
/// count as zero).
pub fn null_space(b: &[f64], rows: usize, cols: usize) -> Option<(Vec<f64>, usize)> {
    if rows == 0 {
        let mut id = vec![0.0; cols * cols];
        for i in 0..cols {
            id[i * cols + i] = 1.0;
        }
        return Some((id, cols));
    }
    let m = faer::Mat::<f64>::from_fn(rows, cols, |i, j| b[i * cols + j]);
    let svd = m.svd().ok()?;
    let s = svd.S().column_vector();
    let smax = (0..s.nrows()).map(|i| s[i].abs()).fold(0.0, f64::max);
    let rank = (0..s.nrows())
        .filter(|&i| s[i].abs() > 1e-10 * smax)
        .count();
    let v = svd.V();
    let r = cols - rank;
    let mut out = vec![0.0; cols * r];
    for j in 0..r {
        for i in 0..cols {
            out[j * cols + i] = v[(i, rank + j)];
        }
    }
    Some((out, r))
}

/// The thin singular value decomposition of the `rows x cols` row-major matrix `a`: the
/// singular values in decreasing order and the matching right singular vectors, as the columns
/// of a column-major `cols x k` array (`k = min(rows, cols)`).
pub fn svd_right(a: &[f64], rows: usize, cols: usize) -> Option<(Vec<f64>, Vec<f64>)> {
    let m = faer::Mat::<f64>::from_fn(rows, cols, |i, j| a[i * cols + j]);
    let svd = m.thin_svd().ok()?;
    let s = svd.S().column_vector();
    let v = svd.V();
    let k = s.nrows();
    let mut order: Vec<usize> = (0..k).collect();
    order.sort_by(|&x, &y| s[y].abs().total_cmp(&s[x].abs()));
    let values = order.iter().map(|&i| s[i].abs()).collect();
    let mut vecs = vec![0.0; cols * k];
    for (j, &o) in order.iter().enumerate() {
        for i in 0..cols {
            vecs[j * cols + i] = v[(i, o)];
        }
    }
    Some((values, vecs))
}

/// The minimum-norm least-squares solution of `a x = b` (`a`: `rows x cols`, `b`:
/// `rows x nrhs`, both row-major; result `cols x nrhs` row-major), singular values below
/// `cutoff` of the largest dropped.
pub fn least_squares(
    a: &[f64],
    rows: usize,
    cols: usize,
    b: &[f64],
    nrhs: usize,
    cutoff: f64,
) -> Option<Vec<f64>> {
    let m = faer::Mat::<f64>::from_fn(rows, cols, |i, j| a[i * cols + j]);
    let svd = m.thin_svd().ok()?;
    let (u, s, v) = (svd.U(), svd.S().column_vector(), svd.V());
    let k = s.nrows();
    let smax = (0..k).map(|i| s[i].abs()).fold(0.0, f64::max);
    let mut x = vec![0.0; cols * nrhs];
    for i in 0..k {
        if s[i].abs() <= cutoff * smax || s[i].is_nan() {
            continue;
        }
        for r in 0..nrhs {
            let ub: f64 = (0..rows).map(|p| u[(p, i)] * b[p * nrhs + r]).sum::<f64>() / s[i];
            for j in 0..cols {
                x[j * nrhs + r] += v[(j, i)] * ub;
            }
        }
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Generalized eigenvalues `alpha / beta` and right eigenvectors of `A z = s B z` for real
/// column-major `n x n` matrices (QZ): `(alpha, beta, vector)` with complex numbers as
/// `(re, im)`.
///
/// Calls faer's `gevd_real` with its own workspace: the one `Mat::generalized_eigen` sizes
/// omits the `n x 2` block of the eigenvector back-substitution, which is the largest need
/// for `n <= 2` (faer 0.24 panics there, "buffer is not large enough").
#[allow(clippy::type_complexity)]
pub fn generalized_eigen(
    a: &[f64],
    b: &[f64],
    n: usize,
) -> Option<Vec<((f64, f64), (f64, f64), Vec<(f64, f64)>)>> {
    use faer::linalg::evd::ComputeEigenvectors;
    if n == 0 {
        return Some(Vec::new());
    }
    let mut am = faer::Mat::<f64>::from_fn(n, n, |i, j| a[j * n + i]);
    let mut bm = faer::Mat::<f64>::from_fn(n, n, |i, j| b[j * n + i]);
    let mut u = faer::Mat::<f64>::zeros(n, n);
    let (mut re, mut im, mut beta) = (
        faer::diag::Diag::<f64>::zeros(n),
        faer::diag::Diag::<f64>::zeros(n),
        faer::diag::Diag::<f64>::zeros(n),
    );
    let req = StackReq::all_of(&[
        faer::linalg::gevd::gevd_scratch::<f64>(
            n,
            ComputeEigenvectors::No,
            ComputeEigenvectors::Yes,
            Par::Seq,
            Default::default(),
        ),
        faer::linalg::temp_mat_scratch::<f64>(n, 2),
        faer::linalg::temp_mat_scratch::<f64>(n, 2),
    ]);
    let mut mem = MemBuffer::try_new(req).ok()?;
    faer::linalg::gevd::gevd_real(
        am.as_mut(),
        bm.as_mut(),
        re.as_mut(),
        im.as_mut(),
        beta.as_mut(),
        None,
        Some(u.as_mut()),
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .ok()?;
    let (re, im, beta) = (re.column_vector(), im.column_vector(), beta.column_vector());
    let pairs = conjugate_pairs(n, |j| (re[j], im[j]), |i, j| u[(i, j)]);
    let out = pairs
        .into_iter()
        .map(|(j, value, v)| (value, (beta[j], 0.0), v))
        .collect();
    Some(out)
}

/// The eigenvalues `(re, im)` of the `n x n` column-major matrix `a` and their right
/// eigenvectors (complex pairs as conjugates), by the real Schur form (faer's `evd_real`:
/// a standard problem, where the QZ of [`generalized_eigen`] against the identity took
/// seconds on a 146 x 146 monodromy with many zero eigenvalues).
#[allow(clippy::type_complexity)]
pub fn eigen(a: &[f64], n: usize) -> Option<Vec<((f64, f64), Vec<(f64, f64)>)>> {
    use faer::linalg::evd::ComputeEigenvectors;
    if n == 0 {
        return Some(Vec::new());
    }
    let am = faer::Mat::<f64>::from_fn(n, n, |i, j| a[j * n + i]);
    let mut u = faer::Mat::<f64>::zeros(n, n);
    let (mut re, mut im) = (
        faer::diag::Diag::<f64>::zeros(n),
        faer::diag::Diag::<f64>::zeros(n),
    );
    let req = faer::linalg::evd::evd_scratch::<f64>(
        n,
        ComputeEigenvectors::No,
        ComputeEigenvectors::Yes,
        Par::Seq,
        Default::default(),
    );
    let mut mem = MemBuffer::try_new(req).ok()?;
    faer::linalg::evd::evd_real(
        am.as_ref(),
        re.as_mut(),
        im.as_mut(),
        None,
        Some(u.as_mut()),
        Par::Seq,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .ok()?;
    let (re, im) = (re.column_vector(), im.column_vector());
    let pairs = conjugate_pairs(n, |j| (re[j], im[j]), |i, j| u[(i, j)]);
    let out = pairs.into_iter().map(|(_, value, v)| (value, v)).collect();
    Some(out)
}

/// Real eigendecompositions' output as complex pairs: eigenvalue `j` (`value(j)`, a pair
/// occupying two columns of `u`: the real and the imaginary part of the first) with its
/// column index, value and eigenvector; conjugates follow each other.
#[allow(clippy::type_complexity)]
fn conjugate_pairs(
    n: usize,
    value: impl Fn(usize) -> (f64, f64),
    u: impl Fn(usize, usize) -> f64,
) -> Vec<(usize, (f64, f64), Vec<(f64, f64)>)> {
    let mut out = Vec::with_capacity(n);
    let mut j = 0;
    while j < n {
        let (re, im) = value(j);
        if im == 0.0 || j + 1 == n {
            out.push((j, (re, 0.0), (0..n).map(|i| (u(i, j), 0.0)).collect()));
            j += 1;
        } else {
            let v: Vec<(f64, f64)> = (0..n).map(|i| (u(i, j), u(i, j + 1))).collect();
            let conjugate = v.iter().map(|&(x, y)| (x, -y)).collect();
            out.push((j, (re, im), v));
            out.push((j, (re, -im), conjugate));
            j += 2;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_small_unsymmetric_system_with_a_zero_diagonal() {
        // [[4, 1, 1], [1, 3, 0], [1, 0, 0]] x = [6, 4, 1] -> x = (1, 1, 1)
        let pattern = Pattern {
            n: 3,
            col_ptr: vec![0, 3, 5, 6],
            row_idx: vec![0, 1, 2, 0, 1, 0],
        };
        let values = [4.0, 1.0, 1.0, 1.0, 3.0, 1.0];
        let mut lu = SparseLu::new(&pattern).expect("symbolic");
        lu.factor(&values).expect("numeric");
        let mut rhs = [6.0, 4.0, 1.0];
        lu.solve(&mut rhs).expect("solve");
        for x in rhs {
            assert!((x - 1.0).abs() < 1e-14);
        }
        // Refactor with new values into the same storage.
        let values2 = [8.0, 2.0, 2.0, 2.0, 6.0, 2.0];
        lu.factor(&values2).expect("numeric");
        let mut rhs = [12.0, 8.0, 2.0];
        lu.solve(&mut rhs).expect("solve");
        assert!(rhs.iter().all(|x| (x - 1.0).abs() < 1e-14));
    }

    #[test]
    fn a_tiny_pivot_hands_the_matrix_to_the_pivoting_lu() {
        // [[0, 1], [1, 0]] x = [2, 3]: no multiplier flagged, so the pivot-free order meets
        // the zero first; faer's pivoting solves it, and keeps doing so.
        let pattern = Pattern {
            n: 2,
            col_ptr: vec![0, 2, 4],
            row_idx: vec![0, 1, 0, 1],
        };
        let mut lu = SparseLu::pivot_free(&pattern, &[false, false]);
        for _ in 0..2 {
            lu.factor(&[0.0, 1.0, 1.0, 0.0])
                .expect("pivoting factors it");
            let mut x = [2.0, 3.0];
            lu.solve(&mut x).expect("solve");
            assert_eq!(x, [3.0, 2.0]);
            assert_eq!(lu.tiny_pivot(), Some(0));
        }
        // A singular matrix names the unknown of the tiny pivot (faer factors it; the solution
        // is not finite).
        let factored = lu.factor(&[0.0, 0.0, 0.0, 0.0]);
        let mut x = [2.0, 3.0];
        let solved = factored.and_then(|()| lu.solve(&mut x));
        assert_eq!(solved, Err(LinearError::TinyPivot(0)));
    }

    #[test]
    fn generalized_eigenvalues_of_one_and_two_unknowns() {
        // A single oscillator as a first-order pencil: [0 1; -k 0] z = s [1 0; 0 m] z with
        // k = 4, m = 1: s = +-2i. And the 1x1 pencil 3 z = s 2 z.
        let a = [0.0, -4.0, 1.0, 0.0];
        let b = [1.0, 0.0, 0.0, 1.0];
        let ev = generalized_eigen(&a, &b, 2).expect("qz");
        let mut s: Vec<(f64, f64)> = ev
            .iter()
            .map(|((ar, ai), (br, _), _)| (ar / br, ai / br))
            .collect();
        s.sort_by(|p, q| p.1.total_cmp(&q.1));
        assert!(
            (s[0].0).abs() < 1e-14 && (s[0].1 + 2.0).abs() < 1e-14,
            "{s:?}"
        );
        assert!(
            (s[1].0).abs() < 1e-14 && (s[1].1 - 2.0).abs() < 1e-14,
            "{s:?}"
        );
        // The eigenvector satisfies A z = s B z.
        for ((ar, ai), (br, _), z) in &ev {
            let (sr, si) = (ar / br, ai / br);
            for i in 0..2 {
                let (mut lr, mut li, mut rr, mut ri) = (0.0, 0.0, 0.0, 0.0);
                for j in 0..2 {
                    lr += a[j * 2 + i] * z[j].0;
                    li += a[j * 2 + i] * z[j].1;
                    let (bz_r, bz_i) = (b[j * 2 + i] * z[j].0, b[j * 2 + i] * z[j].1);
                    rr += sr * bz_r - si * bz_i;
                    ri += sr * bz_i + si * bz_r;
                }
                assert!((lr - rr).abs() < 1e-12 && (li - ri).abs() < 1e-12);
            }
        }
        let one = generalized_eigen(&[3.0], &[2.0], 1).expect("qz");
        assert_eq!(one.len(), 1);
        assert!((one[0].0 .0 / one[0].1 .0 - 1.5).abs() < 1e-15);
    }
}
