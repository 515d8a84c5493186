//! Pendulum (P2, THEORY.md §10.2 item 5): the reduced equation `theta'' = -(g/l) sin theta`.
//!
//! Contract: plain `f64` arithmetic only (see `mod.rs`): no `mbd`, no other crate.

use super::dopri;

/// Simple pendulum of length `l` started at the bottom with speed `v0` (counterclockwise):
/// `theta'' = -(g/l) sin theta`, `theta(0) = 0`, `theta'(0) = v0/l` (rtol 1e-12). Returns
/// `(theta, theta')` at each time. The P2 mass sits at `(e + l sin theta, -l cos theta)`.
pub fn pendulum(l: f64, g: f64, v0: f64, times: &[f64]) -> Vec<(f64, f64)> {
    let w2 = g / l;
    dopri(
        |_t, y: &[f64; 2]| [y[1], -w2 * y[0].sin()],
        0.0,
        [0.0, v0 / l],
        times,
        1e-12,
        1e-14,
    )
    .into_iter()
    .map(|[th, thd]| (th, thd))
    .collect()
}
