//! The perturbation space of a Floquet analysis (THEORY §9.2 step 2): positions along the
//! null space `N0` of the weighted constraint gradient, velocities along its directions that
//! carry inertia; the measure `z` of a state and the perturbed starts.
//!
//! A direction of `N0` without inertia (`N0^T W M W N0 u = 0`: the rotations of beam nodes
//! without rotary inertia) has no velocity state: its motion follows the others' (its
//! acceleration is not an unknown of the equations of motion), and the rate an integrator
//! carries for it is a by-product of its Newmark relations, which no residual reads. Such
//! velocities are neither perturbed nor measured, so the state has `n_f + n_m` entries (`n_m`
//! the directions with inertia) and its multipliers are the motion's. Its positions stay: a
//! perturbation of one relaxes within a step (a multiplier of about zero).

use crate::runtime::rotation::{exp, log, V3};
use crate::runtime::{State, System, UnknownKind};
use crate::solve::integrator::Linearization;
use crate::solve::linear::null_space;
use crate::solve::modes::c64;
use crate::solve::{FailureKind, RuntimeFailure};
use nalgebra::{DMatrix, SymmetricEigen};

/// Directions of `N0` whose generalized mass is below this share of the largest carry no
/// inertia (the exact zeros are round-off, 1e-16; a thin beam's rotary inertia is 1e-6 or
/// more).
const MASSLESS: f64 = 1e-10;

/// The perturbation space, and the consistent reference start it is measured from.
pub(super) struct Space {
    pub(super) free: Vec<usize>,
    pub(super) weights: Vec<f64>,
    /// `N0`, column-major `nfree x r`.
    pub(super) basis: Vec<f64>,
    pub(super) r: usize,
    /// The directions of `N0` with inertia, column-major `nfree x rv` (orthonormal).
    velocities: Vec<f64>,
    rv: usize,
    pub(super) omega: f64,
    pub(super) start: State,
}

/// Per non-multiplier unknown, its velocity (coordinates: the rate; rotations: the angular
/// velocity component).
fn rates(sys: &System, st: &State, i: usize) -> f64 {
    match sys.unknowns[i] {
        UnknownKind::Rotation { node, axis } => st.rot[node].w[axis],
        _ => st.v[i],
    }
}

fn singular(detail: &str) -> RuntimeFailure {
    RuntimeFailure {
        kind: FailureKind::Singular,
        t: 0.0,
        step: 0,
        entity: None,
        detail: detail.into(),
    }
}

impl Space {
    /// The space at the consistent start `start` (linearized in `lin`), for the period of
    /// `omega = 2 pi / T`: the weights of the free coordinates (translations in units of the
    /// length scale, rotations and angles in radians), `N0` (the orthonormal null space of the
    /// weighted constraint gradient), and its directions with inertia.
    pub(super) fn new(
        sys: &System,
        lin: &Linearization,
        omega: f64,
        start: State,
    ) -> Result<Space, RuntimeFailure> {
        let nfree = lin.unknowns.len();
        let angles = sys.angle_unknowns();
        let weights: Vec<f64> = lin
            .unknowns
            .iter()
            .map(|&i| match sys.unknowns[i] {
                UnknownKind::Coordinate if !angles.contains(&i) => sys.length_scale,
                _ => 1.0,
            })
            .collect();
        let mut bw = lin.b.clone();
        for row in 0..lin.rows {
            for (j, w) in weights.iter().enumerate() {
                bw[row * nfree + j] *= w;
            }
        }
        let (basis, r) = null_space(&bw, lin.rows, nfree).ok_or_else(|| {
            singular("the singular value decomposition of the constraint gradient failed")
        })?;
        // The generalized mass over N0 (weighted), and its directions with inertia.
        let nw = DMatrix::from_fn(nfree, r, |j, c| basis[c * nfree + j] * weights[j]);
        let mass = DMatrix::from_row_slice(nfree, nfree, &lin.m);
        let mr = nw.transpose() * mass * &nw;
        let eig = SymmetricEigen::new((&mr + mr.transpose()) * 0.5);
        let top = eig.eigenvalues.iter().fold(0.0f64, |m, &x| m.max(x));
        let kept: Vec<usize> = (0..r)
            .filter(|&c| eig.eigenvalues[c] > MASSLESS * top)
            .collect();
        let n0 = DMatrix::from_column_slice(nfree, r, &basis);
        let mut velocities = Vec::with_capacity(nfree * kept.len());
        for &c in &kept {
            velocities.extend((&n0 * eig.eigenvectors.column(c)).iter());
        }
        Ok(Space {
            free: lin.unknowns.clone(),
            weights,
            basis,
            r,
            velocities,
            rv: kept.len(),
            omega,
            start,
        })
    }

    /// The directions of `N0` without inertia.
    pub(super) fn massless(&self) -> usize {
        self.r - self.rv
    }

    /// The state's dimension: `n_f` positions, `n_m` velocities.
    pub(super) fn dim(&self) -> usize {
        self.r + self.rv
    }

    /// The weighted displacements and rates (over `Omega`) of the free unknowns of `st` from
    /// `reference`: what [`Space::measure`] projects.
    pub(super) fn displacements(
        &self,
        sys: &System,
        st: &State,
        reference: &State,
        (dq, dv): (&mut [f64], &mut [f64]),
    ) {
        let turns: Vec<V3> = (0..sys.rotations.len())
            .map(|k| log(&(st.rot[k].matrix() * reference.rot[k].matrix().transpose())))
            .collect();
        for (j, &i) in self.free.iter().enumerate() {
            let w = self.weights[j];
            dq[j] = match sys.unknowns[i] {
                UnknownKind::Rotation { node, axis } => turns[node][axis],
                _ => st.q[i] - reference.q[i],
            } / w;
            dv[j] = (rates(sys, st, i) - rates(sys, reference, i)) / (w * self.omega);
        }
    }

    /// `z` from displacements and rates (columns of `dq`, `dv`, `nfree` rows each):
    /// `(N0^T dq, V^T dv)`.
    pub(super) fn project(&self, dq: &DMatrix<f64>, dv: &DMatrix<f64>) -> DMatrix<f64> {
        let nfree = self.free.len();
        let n0 = DMatrix::from_column_slice(nfree, self.r, &self.basis);
        let v = DMatrix::from_column_slice(nfree, self.rv, &self.velocities);
        let mut z = DMatrix::<f64>::zeros(self.dim(), dq.ncols());
        z.rows_mut(0, self.r).copy_from(&(n0.transpose() * dq));
        z.rows_mut(self.r, self.rv).copy_from(&(v.transpose() * dv));
        z
    }

    /// The perturbation state `z` of `st` from `reference`.
    pub(super) fn measure(&self, sys: &System, st: &State, reference: &State) -> Vec<f64> {
        let nfree = self.free.len();
        let (mut dq, mut dv) = (DMatrix::zeros(nfree, 1), DMatrix::zeros(nfree, 1));
        self.displacements(sys, st, reference, (dq.as_mut_slice(), dv.as_mut_slice()));
        self.project(&dq, &dv).as_slice().to_vec()
    }

    /// A mode's shape at the start from its eigenvector `v` (`dim` entries): the free
    /// coordinates' weighted displacements, then their weighted rates over `Omega`.
    pub(super) fn shape(&self, v: &[(f64, f64)]) -> Vec<c64> {
        let nfree = self.free.len();
        let mut out = vec![c64::new(0.0, 0.0); 2 * nfree];
        let halves = [(&self.basis, 0, 0), (&self.velocities, nfree, self.r)];
        for (cols, half, at) in halves {
            for (c, col) in cols.chunks(nfree).enumerate() {
                let x = v[at + c];
                for (o, b) in out[half..half + nfree].iter_mut().zip(col) {
                    o.re += b * x.0;
                    o.im += b * x.1;
                }
            }
        }
        out
    }

    /// The model's initial state perturbed by `eps` along state direction `dir` (positions
    /// along `N0` for `dir < r`, velocities along the directions with inertia otherwise).
    pub(super) fn perturbed(&self, sys: &System, dir: usize, eps: f64) -> State {
        let nfree = self.free.len();
        let (col, velocity) = if dir < self.r {
            (&self.basis[dir * nfree..(dir + 1) * nfree], false)
        } else {
            let c = dir - self.r;
            (&self.velocities[c * nfree..(c + 1) * nfree], true)
        };
        let mut st = sys.initial.clone();
        let mut turns = vec![V3::zeros(); sys.rotations.len()];
        for (j, &i) in self.free.iter().enumerate() {
            let d = eps * self.weights[j] * col[j];
            match (sys.unknowns[i], velocity) {
                (UnknownKind::Rotation { node, axis }, false) => turns[node][axis] += d,
                (UnknownKind::Rotation { node, axis }, true) => {
                    st.rot[node].w[axis] += d * self.omega
                }
                (_, false) => st.q[i] += d,
                (_, true) => st.v[i] += d * self.omega,
            }
        }
        for (k, th) in turns.iter().enumerate() {
            if th.norm() > 0.0 {
                let m = exp(th) * st.rot[k].matrix();
                st.rot[k].set_matrix(&m);
            }
        }
        st
    }
}
