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

/// Singular values of the weighted columns below this are dropped (the directions start at
/// unit size): what they carry reaches the measure at the end at about this size times the
/// growth over the rest of the period.
pub const DEAD: f64 = 1e-10;

impl Integrator<'_> {
    /// Deflates the carried directions every `every` steps from now on (0: never), while a
    /// pass drops some.
    pub fn deflate_every(&mut self, every: usize) {
        if let Some(tk) = self.tracked.as_mut() {
            tk.deflate_every = every;
        }
    }
}

/// One pass over `tk` (`n` unknowns, steps of `h`): the columns' weighted singular value
/// decomposition, the live combinations kept; deflation stops once a pass drops none.
pub(super) fn deflate(tk: &mut Tracked, n: usize, h: f64) {
    let (dim, count) = (4 * n, tk.count);
    let weight = |i: usize| {
        let level = [1.0, tk.tau, h * h, h * h][i / n];
        level / tk.scale[i % n]
    };
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
    if keep == count || keep == 0 {
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
    tk.columns = columns;
    tk.map = map;
    tk.count = keep;
    tk.physical.0.truncate(n * keep);
    tk.physical.1.truncate(n * keep);
    tk.gradients.truncate(n * keep);
}
