//! Deflation of the directions carried by the step's tangent (`tangent.rs`): a stiff mode
//! that the integrator damps (`rho_inf` a step, at `omega h >> 1`) leaves nothing of its
//! directions after a few hundred steps but their combinations that are the slower modes'.
//! Every so many steps the carried columns `S` are replaced by `S V_r`, `V_r` the right
//! singular vectors of the weighted columns (positions over their scale, rates times the
//! motion's time scale, accelerations times `h^2`: what each moves the positions by) whose
//! singular values exceed `DEAD`; the directions given (of unit measure at the start) are
//! `S V_r V_r^T` to that size, and the rest of the period carries fewer columns. The elastic
//! windmill (4 elements per blade) carries 90 of its 194 after half the period.

use super::tangent::Tracked;
use super::Integrator;
use crate::solve::linear::svd_right;
use nalgebra::DMatrix;

/// Singular values of the weighted columns below this are dropped (the directions start at
/// unit size): what they carry reaches the measure at the end at about this size times the
/// growth over the rest of the period.
pub const DEAD: f64 = 1e-10;

impl Integrator<'_> {
    /// Deflates the carried directions every `every` steps from now on (0: never), while a
    /// pass drops some; with `settle`, the first pass also makes the columns orthonormal
    /// (weighted) and keeps them: [`Integrator::settled_monodromy`] then projects their images.
    pub fn deflate_every(&mut self, every: usize, settle: bool) {
        if let Some(tk) = self.tracked.as_mut() {
            tk.deflate_every = every;
            tk.settle = settle && every > 0;
        }
    }

    /// Whether the settling pass has run.
    pub fn is_settled(&self) -> bool {
        self.tracked.as_ref().is_some_and(|t| !t.settled.is_empty())
    }

    /// The current columns' combinations that are the images of the settled ones (column-major
    /// `carried x settled`).
    pub fn settled_images(&self) -> Option<&[f64]> {
        let tk = self.tracked.as_ref()?;
        (!tk.settled.is_empty()).then_some(tk.since.as_slice())
    }

    /// The map's Rayleigh-Ritz projection on the settled columns `U` (orthonormal in the
    /// weighted state): `U^T W S`, `S` their images now. Over a period from the settling pass,
    /// its eigenvalues are the multipliers of the discrete map whose directions the pass kept.
    pub fn settled_monodromy(&self) -> Option<DMatrix<f64>> {
        let tk = self.tracked.as_ref()?;
        if tk.settled.is_empty() {
            return None;
        }
        let n = self.sys.len();
        let dim = 4 * n;
        let r = tk.settled.len() / dim;
        let w = |i: usize| weight(tk, n, tk.h, i);
        let u = DMatrix::from_fn(dim, r, |i, j| tk.settled[j * dim + i] * w(i));
        let now = DMatrix::from_fn(dim, tk.count, |i, j| tk.columns[j * dim + i] * w(i));
        let since = DMatrix::from_column_slice(tk.count, r, &tk.since);
        Some(u.transpose() * now * since)
    }
}

impl Integrator<'_> {
    /// The weight of each slot of a carried direction (positions over their scale, rates
    /// times the motion's time scale, accelerations times `h^2`): the weighted state in which
    /// deflation and the settled directions are orthonormal; `None` before
    /// [`Integrator::track`].
    pub fn direction_weights(&self) -> Option<Vec<f64>> {
        let tk = self.tracked.as_ref()?;
        let n = self.sys.len();
        Some((0..4 * n).map(|i| weight(tk, n, self.set.dt, i)).collect())
    }
}

impl Integrator<'_> {
    /// The largest share of a carried direction's weighted measure in its accelerations (and
    /// algorithmic accelerations): a bound on the algorithmic part of directions started
    /// consistently (1 before [`Integrator::track`]). In the Arnold-Bruls form a step's
    /// accelerations satisfy the equations of motion at its end, so a consistent start
    /// differs from the discrete map's own directions only in its algorithmic accelerations,
    /// by about `a_f omega h` of its accelerations; weighted by `h^2`, these are `(omega h)^2`
    /// of the direction's fastest part. The rigid windmill's starts read 4.3e-5 to 1.8e-4
    /// (Omega_bar 1.0 to 2.5: 65 to 72 settling steps instead of 115); a model with stiff
    /// modes (an elastic tower or blades) reads about 1 and settles as long as before.
    pub fn acceleration_share(&self) -> f64 {
        let Some(tk) = self.tracked.as_ref() else {
            return 1.0;
        };
        let n = self.sys.len();
        let dim = 4 * n;
        let w = |i: usize| weight(tk, n, self.set.dt, i);
        let mut share = 0.0f64;
        for col in tk.columns.chunks_exact(dim) {
            let sq = |i: usize| (col[i] * w(i)).powi(2);
            let all: f64 = (0..dim).map(sq).sum();
            let rates: f64 = (2 * n..dim).map(sq).sum();
            if all > 0.0 {
                share = share.max((rates / all).sqrt());
            }
        }
        share
    }
}

/// The weight of slot `i` of a direction (`n` unknowns, steps of `h`): positions over their
/// scale, rates times the motion's time scale, accelerations times `h^2`.
fn weight(tk: &Tracked, n: usize, h: f64, i: usize) -> f64 {
    [1.0, tk.tau, h * h, h * h][i / n] / tk.scale[i % n]
}

/// One pass over `tk` (`n` unknowns, steps of `h`): the columns' weighted singular value
/// decomposition, the live combinations kept; deflation stops once a pass drops none.
pub(super) fn deflate(tk: &mut Tracked, n: usize, h: f64) {
    let (dim, count) = (4 * n, tk.count);
    let weights: Vec<f64> = (0..dim).map(|i| weight(tk, n, h, i)).collect();
    let weight = |i: usize| weights[i];
    // Row-major `dim x count`.
    let mut a = vec![0.0; dim * count];
    for c in 0..count {
        for i in 0..dim {
            a[i * count + c] = tk.columns[c * dim + i] * weight(i);
        }
    }
    let Some((values, vectors)) = svd_right(&a, dim, count) else {
        tk.deflate_every = 0;
        return;
    };
    let keep = values.iter().filter(|&&s| s > DEAD).count();
    let settling = tk.settle && tk.settled.is_empty();
    if (keep == count && !settling) || keep == 0 {
        tk.deflate_every = 0;
        return;
    }
    // New columns S V_r; the map becomes V_r^T times the old.
    let v = |i: usize, j: usize| vectors[j * count + i];
    let mut columns = vec![0.0; dim * keep];
    for j in 0..keep {
        let col = &mut columns[j * dim..(j + 1) * dim];
        for i in 0..count {
            let f = v(i, j);
            for (o, x) in col.iter_mut().zip(&tk.columns[i * dim..(i + 1) * dim]) {
                *o += f * x;
            }
        }
    }
    let original = tk.map.len() / count;
    let mut map = vec![0.0; keep * original];
    for g in 0..original {
        for j in 0..keep {
            map[g * keep + j] = (0..count).map(|i| v(i, j) * tk.map[g * count + i]).sum();
        }
    }
    // The settled columns' images: the dropped part aside, the old columns are the new ones
    // times V_r^T.
    if !tk.settled.is_empty() {
        let r = tk.since.len() / count;
        let mut since = vec![0.0; keep * r];
        for g in 0..r {
            for j in 0..keep {
                since[g * keep + j] = (0..count).map(|i| v(i, j) * tk.since[g * count + i]).sum();
            }
        }
        tk.since = since;
    }
    if settling {
        // The settled directions, orthonormal in the weighted state: W S V_r = Q R gives
        // W^-1 Q, whose images are the carried columns' times R^-1 (upper triangular: the
        // directions kept first, the slow ones, never take the others' parts). The carried
        // columns stay S V_r, so later passes drop what decays as before.
        let wc = DMatrix::from_fn(dim, keep, |i, j| columns[j * dim + i] * weight(i));
        let qr = wc.qr();
        let (q, r) = (qr.q(), qr.r());
        let Some(inverse) = r.solve_upper_triangular(&DMatrix::identity(keep, keep)) else {
            tk.settle = false;
            return;
        };
        tk.settled = (0..keep * dim)
            .map(|k| q[(k % dim, k / dim)] / weight(k % dim))
            .collect();
        tk.since = inverse.as_slice().to_vec();
    }
    tk.columns = columns;
    tk.map = map;
    tk.count = keep;
    tk.physical.0.truncate(n * keep);
    tk.physical.1.truncate(n * keep);
    tk.gradients.truncate(n * keep);
}
