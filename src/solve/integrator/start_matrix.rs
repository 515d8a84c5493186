//! The constrained mass matrix of the start (THEORY §7.3): the matrix that projects the
//! initial positions and velocities onto the joints and solves the consistent accelerations
//! and multipliers, `[M, s B^T; s B, 0]`.
//!
//! A motion without inertia makes `M` singular. A rigid body's (a slender rod about its own
//! axis, a massless hub, a point mass built as a rigid body) must be held by its joints (the
//! model stage checks it, E0308), so the matrix stays regular and is used as it is: the
//! accelerations and the multipliers are exact.
//!
//! The rotations of a beam node without rotary inertia are held by the beam's elasticity,
//! which `M` does not see. For exactly those directions `u` of each such node the rows get the
//! elements' stiffness, `u^T (M a + w K a + B^T mu) = u^T f` with `w = beta h^2`, the rate of
//! the quasi-static balance of the massless motion, as in the integrator's first step. `K` is
//! assembled without the joints' penalty (and with zero multipliers), so the joints' reactions
//! enter every row once and the rows with inertia are exact; where a joint also holds such a
//! direction, its reaction moment carries the `O(w)` term.
//!
//! If a rigid body's massless motion is held only by a spring (the model allows it), the plain
//! matrix is singular; the start then regularizes those directions as well ([`StartMetric::widen`]).

use crate::runtime::{Assembler, Augment, State, System, TangentCoeffs};
use nalgebra::{Matrix6, SymmetricEigen};

/// Relative size below which a node's inertia counts as zero.
const TINY: f64 = 1e-10;

/// The massless motions that get the stiffness in the start, found once per start.
#[derive(Clone, Debug, Default)]
pub(super) struct StartMetric {
    /// Per node: its six unknowns (translation, rotation) and the orthogonal projector onto
    /// its massless motions (physical coordinates).
    nodes: Vec<([usize; 6], Matrix6<f64>)>,
    /// The same for the rigid bodies, used only if the plain matrix is singular.
    frames: Vec<([usize; 6], Matrix6<f64>)>,
    /// The weight of the stiffness on those rows, `beta h^2`.
    weight: f64,
    /// Scratch: the stiffness values.
    stiff: Vec<f64>,
    /// Scratch: the columns a node's rows touch.
    cols: Vec<usize>,
}

fn coeffs(mass: f64, position: f64) -> TangentCoeffs {
    TangentCoeffs {
        mass,
        velocity: 0.0,
        position,
        force_weight: 1.0,
    }
}

impl StartMetric {
    /// Finds the massless motions of every rotating node at `st` (whose multipliers must be
    /// zero); `weight` is `beta h^2`.
    pub(super) fn find(
        asm: &mut Assembler,
        sys: &System,
        st: &State,
        aug: Augment,
        weight: f64,
    ) -> StartMetric {
        asm.tangent(sys, st, aug, coeffs(1.0, 0.0));
        let p = &asm.pattern;
        let v = &asm.values;
        let at = |i: usize, j: usize| p.slot(i, j).map_or(0.0, |s| v[s]);
        let ell = sys.length_scale.max(f64::MIN_POSITIVE);
        // Scaled so that rotations count with the model's length.
        let scale = |a: usize| if a < 3 { 1.0 } else { 1.0 / ell };
        let floor = TINY * sys.mean_mass();
        let (mut nodes, mut frames) = (Vec::new(), Vec::new());
        for (k, (&t, &r)) in sys.translations.iter().zip(&sys.rotations).enumerate() {
            let idx = [t, t + 1, t + 2, r, r + 1, r + 2];
            let m = Matrix6::from_fn(|i, j| at(idx[i], idx[j]) * scale(i) * scale(j));
            let eig = SymmetricEigen::new(m);
            let massless: Vec<usize> = (0..6).filter(|&i| eig.eigenvalues[i] <= floor).collect();
            if massless.is_empty() {
                continue;
            }
            // Physical directions `W e`, orthonormalized by a thin SVD; the projector.
            let phys = nalgebra::DMatrix::from_fn(6, massless.len(), |i, c| {
                eig.eigenvectors[(i, massless[c])] * scale(i)
            });
            let svd = phys.svd(true, false);
            let Some(u) = svd.u else { continue };
            let proj = Matrix6::from_fn(|i, j| (0..u.ncols()).map(|c| u[(i, c)] * u[(j, c)]).sum());
            if sys.is_frame(k) {
                frames.push((idx, proj));
            } else {
                nodes.push((idx, proj));
            }
        }
        StartMetric {
            nodes,
            frames,
            weight,
            stiff: Vec::new(),
            cols: Vec::new(),
        }
    }

    /// Regularizes the rigid bodies' massless motions too; false if there are none (the
    /// singular matrix has another cause).
    pub(super) fn widen(&mut self) -> bool {
        if self.frames.is_empty() {
            return false;
        }
        self.nodes.append(&mut self.frames);
        true
    }

    /// Assembles the start's matrix at `st` into `asm.values`.
    pub(super) fn assemble(&mut self, asm: &mut Assembler, sys: &System, st: &State, aug: Augment) {
        if self.nodes.is_empty() {
            asm.tangent(sys, st, aug, coeffs(1.0, 0.0));
            return;
        }
        // The elements' stiffness alone: without the joints' penalty, the difference of the
        // position-weighted and the plain matrices leaves no joint term in a node's rows.
        let bare = Augment { p: 0.0, ..aug };
        asm.tangent(sys, st, bare, coeffs(0.0, 1.0));
        self.stiff.clone_from(&asm.values);
        asm.tangent(sys, st, bare, coeffs(0.0, 0.0));
        for (k, v) in self.stiff.iter_mut().zip(&asm.values) {
            *k -= v;
        }
        asm.tangent(sys, st, aug, coeffs(1.0, 0.0));
        let p = &asm.pattern;
        let cols = &mut self.cols;
        for (idx, proj) in &self.nodes {
            // The pattern is structurally symmetric: the node's rows have entries in the
            // columns that its columns have entries in.
            cols.clear();
            for &c in idx {
                cols.extend_from_slice(&p.row_idx[p.col_ptr[c]..p.col_ptr[c + 1]]);
            }
            cols.sort_unstable();
            cols.dedup();
            for &col in cols.iter() {
                let slots = idx.map(|i| p.slot(i, col));
                let k: [f64; 6] = slots.map(|s| s.map_or(0.0, |s| self.stiff[s]));
                for (i, s) in slots.iter().enumerate() {
                    if let Some(s) = s {
                        let pk: f64 = (0..6).map(|j| proj[(i, j)] * k[j]).sum();
                        asm.values[*s] += self.weight * pk;
                    }
                }
            }
        }
    }
}
