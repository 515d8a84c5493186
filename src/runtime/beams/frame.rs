//! The objective interpolation of an element's triads (THEORY §3.4): every node's triad
//! relative to the middle node's, `p_k = WM(T_r^T T_k)`, and the triad at a point
//! `T(xi) = T_r R(sum N_k p_k)`, with its variation `dtheta(xi) = sum A_l dtheta_l`.

use super::super::rotation::{from_matrix, rotation, tangent, tangent_inverse, M3, V3};
use super::MAXN;

/// Per-element quantities shared by all points: the reference triad, relative parameters and
/// their inverse tangents.
pub(super) struct Relative {
    pub r: usize,
    pub tr: M3,
    pub p: [V3; MAXN],
    /// `H(p_k)^-1 T_r^T`.
    pub g: [M3; MAXN],
}

/// The relative parameters of triads `t` (one per node of an element).
pub(super) fn relative(t: &[M3]) -> Relative {
    let nn = t.len();
    let r = nn / 2;
    let tr = t[r];
    let mut p = [V3::zeros(); MAXN];
    let mut g = [M3::zeros(); MAXN];
    for k in 0..nn {
        p[k] = if k == r {
            V3::zeros()
        } else {
            from_matrix(&(tr.transpose() * t[k]))
        };
        g[k] = tangent_inverse(&p[k]) * tr.transpose();
    }
    Relative { r, tr, p, g }
}

/// The triad interpolated between an element's node triads `t` with shape function values
/// `n`, and the operators `A_l` of its variation `dtheta(xi) = sum A_l dtheta_l`: the same
/// field the element uses at its quadrature points, for a marker between its nodes.
pub(crate) fn triad_between(t: &[M3], n: &[f64]) -> (M3, [M3; MAXN]) {
    let rel = relative(t);
    let mut p = V3::zeros();
    for (k, nk) in n.iter().enumerate().take(t.len()) {
        p += rel.p[k] * *nk;
    }
    let th = rel.tr * tangent(&p);
    let mut a = [M3::zeros(); MAXN];
    let mut sum = M3::zeros();
    for l in 0..t.len() {
        if l != rel.r {
            a[l] = th * rel.g[l] * n[l];
            sum += a[l];
        }
    }
    a[rel.r] = M3::identity() - sum;
    (rel.tr * rotation(&p), a)
}
