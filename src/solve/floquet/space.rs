//! The perturbation space of a Floquet analysis (THEORY §9.2 step 2): positions and
//! velocities along the directions of the null space `N0` of the weighted constraint gradient
//! that carry inertia; the measure `z` of a state and the perturbed starts.
//!
//! A direction of `N0` without inertia (`N0^T W M W N0 u = 0`: the rotations of beam nodes
//! without rotary inertia) is no state: the balance holds along it at every step, so its
//! position follows the others' (and the rate an integrator carries for it is a by-product of
//! its Newmark relations, which no residual reads). Each perturbed start displaces such
//! directions into the equilibrium of the balance linearized at the start (stiffness, and the
//! damping of a velocity perturbation), so it is a state of the motion, and the measure reads
//! only the directions with inertia: `z` has `2 n_m` entries and its multipliers are the
//! motion's.

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
    /// The dimension of `N0`.
    pub(super) r: usize,
    /// The directions of `N0` with inertia, column-major `nfree x rv` (orthonormal): the
    /// state's positions and velocities both.
    velocities: Vec<f64>,
    rv: usize,
    /// Column-major `nfree x 2 rv`: the displacement along the directions without inertia
    /// that keeps them in equilibrium when the position (column `c`) or the velocity
    /// (column `rv + c`) of direction `c` moves by one.
    slaved: Vec<f64>,
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
        let massless: Vec<usize> = (0..r).filter(|c| !kept.contains(c)).collect();
        let pick =
            |cols: &[usize]| DMatrix::from_fn(r, cols.len(), |i, j| eig.eigenvectors[(i, cols[j])]);
        let (uv, uk) = (pick(&kept), pick(&massless));
        let slaved = slaved(lin, &nw, &n0, (&uv, &uk), omega);
        Ok(Space {
            free: lin.unknowns.clone(),
            weights,
            r,
            velocities,
            rv: kept.len(),
            slaved,
            omega,
            start,
        })
    }

    /// The state's dimension: positions and velocities along the `n_m` directions with
    /// inertia.
    pub(super) fn dim(&self) -> usize {
        2 * self.rv
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
    /// `(V^T dq, V^T dv)` (the directions without inertia follow the others).
    pub(super) fn project(&self, dq: &DMatrix<f64>, dv: &DMatrix<f64>) -> DMatrix<f64> {
        let nfree = self.free.len();
        let v = DMatrix::from_column_slice(nfree, self.rv, &self.velocities);
        let mut z = DMatrix::<f64>::zeros(self.dim(), dq.ncols());
        z.rows_mut(0, self.rv).copy_from(&(v.transpose() * dq));
        z.rows_mut(self.rv, self.rv)
            .copy_from(&(v.transpose() * dv));
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
        let mut add = |half: usize, col: &[f64], x: (f64, f64)| {
            for (o, b) in out[half..half + nfree].iter_mut().zip(col) {
                o.re += b * x.0;
                o.im += b * x.1;
            }
        };
        for c in 0..self.rv {
            let (col, (p, u)) = (
                &self.velocities[c * nfree..][..nfree],
                (v[c], v[self.rv + c]),
            );
            add(0, col, p);
            add(0, &self.slaved[c * nfree..][..nfree], p);
            add(0, &self.slaved[(self.rv + c) * nfree..][..nfree], u);
            add(nfree, col, u);
        }
        out
    }

    /// The model's initial state perturbed by `eps` along state direction `dir` (the
    /// position of direction `dir < rv`, else the velocity of `dir - rv`), the directions
    /// without inertia displaced to stay in equilibrium.
    pub(super) fn perturbed(&self, sys: &System, dir: usize, eps: f64) -> State {
        let mut x = vec![0.0; self.dim()];
        x[dir] = 1.0;
        self.perturbed_along(sys, &x, eps)
    }

    /// The model's initial state perturbed by `eps` along the state `x` (`dim` entries: the
    /// positions of the directions with inertia, then their velocities), the directions
    /// without inertia displaced to stay in equilibrium.
    pub(super) fn perturbed_along(&self, sys: &System, x: &[f64], eps: f64) -> State {
        let nfree = self.free.len();
        let mut st = sys.initial.clone();
        let mut turns = vec![V3::zeros(); sys.rotations.len()];
        for (dir, &xd) in x.iter().enumerate().filter(|(_, &xd)| xd != 0.0) {
            let (c, velocity) = (dir % self.rv, dir >= self.rv);
            let col = &self.velocities[c * nfree..(c + 1) * nfree];
            let follow = &self.slaved[dir * nfree..(dir + 1) * nfree];
            let moves = col.iter().map(|&x| (x, velocity)).enumerate();
            let follows = follow.iter().map(|&x| (x, false)).enumerate();
            for (j, (x, velocity)) in moves.chain(follows) {
                let i = self.free[j];
                let d = eps * xd * self.weights[j] * x;
                match (sys.unknowns[i], velocity) {
                    (UnknownKind::Rotation { node, axis }, false) => turns[node][axis] += d,
                    (UnknownKind::Rotation { node, axis }, true) => {
                        st.rot[node].w[axis] += d * self.omega
                    }
                    (_, false) => st.q[i] += d,
                    (_, true) => st.v[i] += d * self.omega,
                }
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

/// The displacements along the directions without inertia (`uk`, in `N0`'s coordinates) that
/// keep them in equilibrium when a direction with inertia (`uv`) moves: the linearized balance
/// along them, `Uk^T (K dq + G dv) = 0` (stiffness and damping over `N0`, weighted by `nw`),
/// solved for their part of `dq`; column-major `nfree x 2 rv` in weighted coordinates, the
/// positions' columns then the velocities' (a velocity of one is `omega` in rate).
fn slaved(
    lin: &Linearization,
    nw: &DMatrix<f64>,
    n0: &DMatrix<f64>,
    (uv, uk): (&DMatrix<f64>, &DMatrix<f64>),
    omega: f64,
) -> Vec<f64> {
    let (nfree, rv) = (n0.nrows(), uv.ncols());
    if uk.ncols() == 0 {
        return vec![0.0; nfree * 2 * rv];
    }
    let over = |flat: &[f64]| nw.transpose() * DMatrix::from_row_slice(nfree, nfree, flat) * nw;
    let (kr, gr) = (over(&lin.k), over(&lin.g));
    let kkk = uk.transpose() * &kr * uk;
    // Directions with neither inertia nor stiffness (none in a well-posed model) stay put.
    let top = kkk.amax();
    let inverse = kkk
        .pseudo_inverse(1e-12 * top.max(f64::MIN_POSITIVE))
        .unwrap_or_else(|_| DMatrix::zeros(uk.ncols(), uk.ncols()));
    let mut rhs = DMatrix::<f64>::zeros(uk.ncols(), 2 * rv);
    rhs.columns_mut(0, rv)
        .copy_from(&(uk.transpose() * &kr * uv));
    rhs.columns_mut(rv, rv)
        .copy_from(&(uk.transpose() * &gr * uv * omega));
    let follow = n0 * uk * (inverse * rhs) * -1.0;
    follow.as_slice().to_vec()
}
