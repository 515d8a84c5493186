//! The conformal (paper's) rotation treatment: rotation unknowns hold the total conformal
//! rotation vector `c` and its rates; the elements' forces conjugate to virtual rotations
//! `delta theta = H(c) delta c` are mapped to generalized forces `H^T F`, and the iteration
//! matrix to `T^T J T` with `T = diag(H)` (THEORY §2.3, §2.5, §7.1).

use crate::runtime::rotation::{self, M3, V3};
use crate::runtime::{Pattern, State, System};

/// `c`, `c-dot`, `c-ddot` of node `k` from the rotation slots of `q`, `v`, `a`.
fn slots(st: &State, f: usize) -> (V3, V3, V3) {
    let g = |x: &[f64]| V3::new(x[f], x[f + 1], x[f + 2]);
    (g(&st.q), g(&st.v), g(&st.a))
}

fn put(x: &mut [f64], f: usize, v: &V3) {
    x[f..f + 3].copy_from_slice(v.as_slice());
}

/// Fills the nodes' rotation, angular velocity and acceleration from `c` and its rates.
pub fn sync(sys: &System, st: &mut State) {
    for (k, &f) in sys.rotations.iter().enumerate() {
        let (c, cd, cdd) = slots(st, f);
        let h = rotation::tangent(&c);
        let n = &mut st.rot[k];
        n.set_matrix(&rotation::rotation(&c));
        n.w = (h * cd).into();
        n.dw = (h * cdd + rotation::tangent_rate(&c, &cd) * cd).into();
    }
}

/// Rewrites the rotation slots from the physical layout (`v` = angular velocity, `a` =
/// angular acceleration, rotation in `rot`) to the conformal one.
pub fn to_conformal(sys: &System, st: &mut State) {
    for (k, &f) in sys.rotations.iter().enumerate() {
        let n = st.rot[k];
        let c = rotation::from_matrix(&n.matrix());
        let hi = rotation::tangent_inverse(&c);
        let cd = hi * n.omega();
        let cdd = hi * (n.omega_dot() - rotation::tangent_rate(&c, &cd) * cd);
        put(&mut st.q, f, &c);
        put(&mut st.v, f, &cd);
        put(&mut st.a, f, &cdd);
        put(&mut st.alg, f, &cdd);
    }
}

/// Changes the state of every node whose `|c| > 4` (THEORY §2.5); returns how many changed.
pub fn rescale(sys: &System, st: &mut State) -> usize {
    let mut count = 0;
    for &f in &sys.rotations {
        let (c, cd, cdd) = slots(st, f);
        if !rotation::needs_rescale(&c) {
            continue;
        }
        let alg = V3::new(st.alg[f], st.alg[f + 1], st.alg[f + 2]);
        let (c2, cd2, cdd2) = rotation::rescale(&c, &cd, &cdd);
        let (_, _, alg2) = rotation::rescale(&c, &cd, &alg);
        put(&mut st.q, f, &c2);
        put(&mut st.v, f, &cd2);
        put(&mut st.a, f, &cdd2);
        put(&mut st.alg, f, &alg2);
        count += 1;
    }
    count
}

/// `H(c)` of every node.
pub fn tangents(sys: &System, st: &State, out: &mut [M3]) {
    for (k, &f) in sys.rotations.iter().enumerate() {
        out[k] = rotation::tangent(&V3::new(st.q[f], st.q[f + 1], st.q[f + 2]));
    }
}

/// Applies `T^T J T` in place on a matrix with a fixed pattern, where `T` is the identity
/// except for 3x3 blocks starting at given unknowns (`H_k` of the conformal treatment, `R_k`
/// of the SE(3) one). Precomputed once per pattern.
pub struct Transform {
    /// The columns where a block starts, with the block's index.
    columns: Vec<(usize, usize)>,
    /// The entries of the pattern where a block's rows start (the next two entries of the
    /// column are its other rows), with the block's index: the rows' pass visits them alone.
    rows: Vec<(usize, usize)>,
}

impl Transform {
    /// `None` if some block's three columns do not share one row structure (never for patterns
    /// built from element index lists, which couple whole nodes).
    pub fn new(n: usize, firsts: &[usize], p: &Pattern) -> Option<Transform> {
        let mut first_of = vec![None; n];
        let rows = |c: usize| &p.row_idx[p.col_ptr[c]..p.col_ptr[c + 1]];
        for (k, &f) in firsts.iter().enumerate() {
            first_of[f] = Some(k);
            if rows(f) != rows(f + 1) || rows(f) != rows(f + 2) {
                return None;
            }
        }
        // Rows f, f+1, f+2 must appear together in every column: one pass over the pattern.
        // `member[r]` is the offset of row r inside its block (0, 1, 2), or 3 outside blocks.
        let mut member = vec![3u8; n];
        for &f in firsts {
            member[f] = 0;
            member[f + 1] = 1;
            member[f + 2] = 2;
        }
        for c in 0..p.n {
            let r = rows(c);
            for (i, &row) in r.iter().enumerate() {
                let ok = match member[row] {
                    0 => r.get(i + 1) == Some(&(row + 1)) && r.get(i + 2) == Some(&(row + 2)),
                    1 | 2 => i > 0 && r[i - 1] + 1 == row,
                    _ => true,
                };
                if !ok {
                    return None;
                }
            }
        }
        let columns = (0..p.n)
            .filter_map(|c| first_of[c].map(|k| (c, k)))
            .collect();
        let rows = (0..p.row_idx.len())
            .filter(|&i| member[p.row_idx[i]] == 0)
            .filter_map(|i| first_of[p.row_idx[i]].map(|k| (i, k)))
            .collect();
        Some(Transform { columns, rows })
    }

    /// `L^T J T` with `L` from `left` and `T` from `right` (block matrices by block index).
    pub fn apply(&self, p: &Pattern, values: &mut [f64], left: &[M3], right: &[M3]) {
        // Columns: J <- J T.
        for &(c, k) in &self.columns {
            let (s0, s1, s2) = (p.col_ptr[c], p.col_ptr[c + 1], p.col_ptr[c + 2]);
            let len = s1 - s0;
            for r in 0..len {
                let x = V3::new(values[s0 + r], values[s1 + r], values[s2 + r]);
                let y = right[k].transpose() * x;
                values[s0 + r] = y[0];
                values[s1 + r] = y[1];
                values[s2 + r] = y[2];
            }
        }
        // Rows: J <- T^T J.
        for &(i, k) in &self.rows {
            let x = V3::new(values[i], values[i + 1], values[i + 2]);
            let y = left[k].transpose() * x;
            values[i] = y[0];
            values[i + 1] = y[1];
            values[i + 2] = y[2];
        }
    }
}

/// `T^T x`: block `k` (starting at `firsts[k]`) multiplied by `mats[k]^T`.
pub fn transform_vector(firsts: &[usize], mats: &[M3], x: &mut [f64]) {
    for (k, &f) in firsts.iter().enumerate() {
        let y = mats[k].transpose() * V3::new(x[f], x[f + 1], x[f + 2]);
        put(x, f, &y);
    }
}
