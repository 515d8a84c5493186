//! Floquet analysis with the time integrator (THEORY §9.2): the monodromy matrix of the motion
//! over one period, built from perturbed integrations in the constraint-free subspace.
//!
//! 1. The reference run starts from the model's initial state, made consistent (positions,
//!    velocities, then accelerations and multipliers: a consistent start whatever the model's
//!    `start`, so that a perturbation starts on the constraint manifold at every level).
//! 2. The perturbation space is the null space `N0` of the constraint gradient at the start
//!    (rate rows included: a prescribed motion is not perturbed; a revolute's angle unknown
//!    moves with its bodies), weighted so that translations count in units of the model's
//!    length scale and rotations in radians. States are `z = (N0^T W^-1 dq, N0^T W^-1 dv / w)`
//!    with `w = 2 pi / T`, of dimension `2 n_f`; rotations differ by
//!    `axial log(R Rbar^T)` (spatial, as the perturbation `R <- exp(dtheta~) R`).
//! 3. Each state direction is perturbed by `+-eps`, the perturbed state is made consistent the
//!    same way as the reference (positions projected back onto the joints, velocities made
//!    tangent: this moves the velocities that depend on a position perturbation), and
//!    integrated over one period with the production integrator and step (rounded so that a
//!    whole number of steps fills the period). With `Z_0` and `Z_T` the central differences
//!    `(z+ - z-) / 2 eps` at the start (after the projection) and after one period,
//!    `Phi = Z_T Z_0^-1`.
//! 4. The eigenvalues of `Phi` are the characteristic multipliers `Lambda`; the exponents are
//!    `s = (ln|Lambda| + i arg Lambda) / T`, frequencies on the principal branch
//!    `|Im s| <= pi / T` (known only modulo `2 pi / T`).
//!
//! The reference is the model's own motion from its initial state, loads included: a pulse that
//! acts in the first period is in every run and cancels in the differences (to first order
//! in its size). The monodromy matrix is that of the discrete map, so its damping carries the
//! integrator's numerical damping (§7.4).

use super::integrator::{Integrator, Linearization};
use super::linear::{generalized_eigen, null_space};
use super::modes::c64;
use super::{RuntimeFailure, Stop};
use crate::runtime::rotation::{exp, log, V3};
use crate::runtime::{State, System, UnknownKind};
use crate::settings::Settings;
use nalgebra::DMatrix;
use std::convert::Infallible;

/// Relative size of the perturbations (of the length scale, of a radian).
pub const EPSILON: f64 = 1e-5;

/// What the analysis found.
#[derive(Clone, Debug)]
pub struct Floquet {
    /// The period `T` (s).
    pub period: f64,
    /// Steps per period and their size.
    pub steps: usize,
    pub dt: f64,
    /// Dimension `n_f` of the constraint-free position space (the state has `2 n_f`).
    pub free: usize,
    /// The monodromy matrix, column-major `2 n_f x 2 n_f`.
    pub monodromy: Vec<f64>,
    /// Characteristic multipliers, largest modulus first.
    pub multipliers: Vec<c64>,
    /// Characteristic exponents (1/s), in the multipliers' order.
    pub exponents: Vec<c64>,
    /// Newton iterations over all runs.
    pub newton_iterations: usize,
}

/// Where a Floquet analysis failed: a run and the integrator's failure.
#[derive(Clone, Debug)]
pub struct FloquetFailure {
    /// `None`: the reference run; `Some((direction, sign))`: a perturbed run.
    pub run: Option<(usize, f64)>,
    pub failure: RuntimeFailure,
}

impl FloquetFailure {
    /// The run, for messages.
    pub fn which(&self) -> String {
        match self.run {
            None => "the reference run".to_string(),
            Some((j, s)) => format!(
                "the run perturbed along direction {} ({})",
                j + 1,
                if s > 0.0 { "+" } else { "-" }
            ),
        }
    }
}

/// The characteristic exponent of a multiplier over period `t`, principal branch.
pub fn exponent(m: c64, t: f64) -> c64 {
    let r = (m.re * m.re + m.im * m.im).sqrt();
    c64::new(r.ln() / t, m.im.atan2(m.re) / t)
}

/// Physical quantities of a state: per non-multiplier unknown, its position (coordinates) and
/// its velocity (coordinates: the rate; rotations: the angular velocity component).
fn rates(sys: &System, st: &State, i: usize) -> f64 {
    match sys.unknowns[i] {
        UnknownKind::Rotation { node, axis } => st.rot[node].w[axis],
        _ => st.v[i],
    }
}

/// The perturbation state `z` of `st` from `reference`, over the free unknowns.
fn measure(
    sys: &System,
    st: &State,
    reference: &State,
    free: &[usize],
    basis: &[f64],
    weights: &[f64],
    omega: f64,
) -> Vec<f64> {
    let nfree = free.len();
    let r = basis.len() / nfree;
    // Rotation differences per node.
    let turns: Vec<V3> = (0..sys.rotations.len())
        .map(|k| log(&(st.rot[k].matrix() * reference.rot[k].matrix().transpose())))
        .collect();
    let mut dq = vec![0.0; nfree];
    let mut dv = vec![0.0; nfree];
    for (j, &i) in free.iter().enumerate() {
        dq[j] = match sys.unknowns[i] {
            UnknownKind::Rotation { node, axis } => turns[node][axis],
            _ => st.q[i] - reference.q[i],
        } / weights[j];
        dv[j] = (rates(sys, st, i) - rates(sys, reference, i)) / (weights[j] * omega);
    }
    let mut z = vec![0.0; 2 * r];
    for c in 0..r {
        let col = &basis[c * nfree..(c + 1) * nfree];
        z[c] = col.iter().zip(&dq).map(|(a, b)| a * b).sum();
        z[r + c] = col.iter().zip(&dv).map(|(a, b)| a * b).sum();
    }
    z
}

/// The model's initial state perturbed by `eps` along state direction `dir` (positions for
/// `dir < r`, velocities otherwise).
#[allow(clippy::too_many_arguments)]
fn perturbed(
    sys: &System,
    free: &[usize],
    basis: &[f64],
    weights: &[f64],
    omega: f64,
    dir: usize,
    eps: f64,
) -> State {
    let nfree = free.len();
    let r = basis.len() / nfree;
    let (col, velocity) = if dir < r {
        (dir, false)
    } else {
        (dir - r, true)
    };
    let col = &basis[col * nfree..(col + 1) * nfree];
    let mut st = sys.initial.clone();
    let mut turns = vec![V3::zeros(); sys.rotations.len()];
    for (j, &i) in free.iter().enumerate() {
        let d = eps * weights[j] * col[j];
        match (sys.unknowns[i], velocity) {
            (UnknownKind::Rotation { node, axis }, false) => turns[node][axis] += d,
            (UnknownKind::Rotation { node, axis }, true) => st.rot[node].w[axis] += d * omega,
            (_, false) => st.q[i] += d,
            (_, true) => st.v[i] += d * omega,
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

/// Integrates from the integrator's current (initialized) state over its settings' steps.
fn integrate(it: &mut Integrator) -> Result<State, RuntimeFailure> {
    it.run(|_, _| Ok::<(), Infallible>(()))
        .map_err(|s| match s {
            Stop::Failed(f) => f,
            Stop::Stopped(never) => match never {},
        })?;
    Ok(it.state().clone())
}

/// Floquet analysis of the model's motion over `period` seconds (THEORY §9.2), with the
/// integrator and step of `set`. `progress` is called after each integration.
pub fn floquet(
    sys: &System,
    set: &Settings,
    period: f64,
    progress: &dyn Fn(),
) -> Result<Floquet, FloquetFailure> {
    let reference_failure = |failure| FloquetFailure { run: None, failure };
    let set = set.over(period);
    let (steps, h) = (set.steps, set.dt);
    let mut it = Integrator::new(sys, &set).map_err(reference_failure)?;
    it.initialize().map_err(reference_failure)?;
    let lin = it.linearize();
    let free = lin.unknowns.clone();
    let (weights, basis, r) = perturbation_space(sys, &lin).map_err(reference_failure)?;
    let omega = 2.0 * std::f64::consts::PI / period;
    let start_reference = it.state().clone();
    let reference = integrate(&mut it).map_err(reference_failure)?;
    progress();
    let mut newton_iterations = it.stats().newton_iterations;
    let n = 2 * r;
    // Columns of the perturbations at the start (after the projection onto the joints, which
    // moves the dependent velocities of a position perturbation) and after one period:
    // Phi = Z_T Z_0^-1.
    let mut z0 = DMatrix::<f64>::zeros(n, n);
    let mut zt = DMatrix::<f64>::zeros(n, n);
    for dir in 0..n {
        for sign in [1.0, -1.0] {
            let fail = |failure| FloquetFailure {
                run: Some((dir, sign)),
                failure,
            };
            let start = perturbed(sys, &free, &basis, &weights, omega, dir, sign * EPSILON);
            it.restart(&start).map_err(fail)?;
            let a = measure(
                sys,
                it.state(),
                &start_reference,
                &free,
                &basis,
                &weights,
                omega,
            );
            let end = integrate(&mut it).map_err(fail)?;
            newton_iterations += it.stats().newton_iterations;
            let b = measure(sys, &end, &reference, &free, &basis, &weights, omega);
            for i in 0..n {
                z0[(i, dir)] += sign * a[i] / (2.0 * EPSILON);
                zt[(i, dir)] += sign * b[i] / (2.0 * EPSILON);
            }
            progress();
        }
    }
    let phi_m = match z0.clone().lu().solve(&DMatrix::<f64>::identity(n, n)) {
        Some(inv) => &zt * inv,
        None => {
            return Err(reference_failure(RuntimeFailure {
                kind: super::FailureKind::Singular,
                t: 0.0,
                step: 0,
                entity: None,
                detail: "the perturbed starts are not independent once projected onto the joints"
                    .into(),
            }))
        }
    };
    let phi: Vec<f64> = (0..n * n).map(|k| phi_m[(k % n, k / n)]).collect();
    let multipliers = eigenvalues(&phi, n).ok_or_else(|| {
        reference_failure(RuntimeFailure {
            kind: super::FailureKind::Singular,
            t: period,
            step: steps,
            entity: None,
            detail: "the eigenvalues of the monodromy matrix could not be computed".into(),
        })
    })?;
    let exponents = multipliers.iter().map(|&m| exponent(m, period)).collect();
    Ok(Floquet {
        period,
        steps,
        dt: h,
        free: r,
        monodromy: phi,
        multipliers,
        exponents,
        newton_iterations,
    })
}

/// The weighted perturbation space: the weights of the free coordinates (translations in
/// units of the length scale, rotations and angles in radians), the orthonormal basis of the
/// null space of the weighted constraint gradient, and its dimension.
fn perturbation_space(
    sys: &System,
    lin: &Linearization,
) -> Result<(Vec<f64>, Vec<f64>, usize), RuntimeFailure> {
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
    let (basis, r) = null_space(&bw, lin.rows, nfree).ok_or_else(|| RuntimeFailure {
        kind: super::FailureKind::Singular,
        t: 0.0,
        step: 0,
        entity: None,
        detail: "the singular value decomposition of the constraint gradient failed".into(),
    })?;
    Ok((weights, basis, r))
}

/// The eigenvalues of the `n x n` column-major matrix `phi`, by decreasing modulus.
fn eigenvalues(phi: &[f64], n: usize) -> Option<Vec<c64>> {
    let identity: Vec<f64> = (0..n * n)
        .map(|k| if k % (n + 1) == 0 { 1.0 } else { 0.0 })
        .collect();
    let eig = if n == 0 {
        Vec::new()
    } else {
        generalized_eigen(phi, &identity, n)?
    };
    let mut multipliers: Vec<c64> = eig
        .iter()
        .map(|((ar, ai), (br, bi), _)| {
            // alpha / beta
            let d = br * br + bi * bi;
            c64::new((ar * br + ai * bi) / d, (ai * br - ar * bi) / d)
        })
        .collect();
    let modulus = |m: &c64| (m.re * m.re + m.im * m.im).sqrt();
    multipliers.sort_by(|a, b| modulus(b).total_cmp(&modulus(a)));
    Some(multipliers)
}
