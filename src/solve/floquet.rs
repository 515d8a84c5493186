//! Floquet analysis with the time integrator (THEORY §9.2): the monodromy matrix of the motion
//! over one period, of the discrete map of the model's own integrator and step, in the
//! constraint-free subspace.
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
//! 3. Each state direction is perturbed by `+-eps` and made consistent the same way as the
//!    reference (positions projected back onto the joints, velocities made tangent, consistent
//!    accelerations): `Z_0`, the central differences of their measure.
//! 4. [`Monodromy::Tangent`] (the default): the same starts' differences in the integrator's
//!    whole step state `(q, v, a, A)` (`A` the algorithmic accelerations; frames as body-frame
//!    increments and twists) are the directions `S_0`, carried through one run of the period by
//!    each converged step's own tangent (`integrator/tangent.rs`: `S_{n+1} = T S_n + D x`,
//!    `J x = -dr/ds S_n` with the exact iteration matrix `J` factored at the converged step);
//!    `Z_T` is their measure at the end. [`Monodromy::Runs`]: each perturbed start integrated
//!    over the period, `Z_T` the central differences of the ends. `Phi = Z_T Z_0^-1`.
//! 5. The eigenvalues of `Phi` are the characteristic multipliers `Lambda`; the exponents are
//!    `s = (ln|Lambda| + i arg Lambda) / T`, frequencies on the principal branch
//!    `|Im s| <= pi / T` (known only modulo `2 pi / T`).
//!
//! The step's own state: HHT and generalized-alpha carry `a` and `A`, so the discrete map
//! lives in `(q, v, a, A)`, twice the dimension of `z`. Both monodromies chain the
//! sensitivities through the consistent start (accelerations as functions of `(q, v)` at
//! `t = 0`) and carry the whole step state inside the period, measuring `(q, v)` at its end.
//! The discrete map's extra multipliers are algorithmic: an HHT or generalized-alpha step
//! damps them by `rho_inf` (0.82 at alpha -0.1), so over the `N` steps of a period (hundreds)
//! their share of `Z_T` is `rho_inf^N` (1e-79 on the windmill): `Phi` is the physical block of
//! the discrete monodromy to that order, and no algorithmic multiplier needs separating.
//!
//! The reference is the model's own motion from its initial state, loads included: a pulse that
//! acts in the first period is in every run and cancels in the differences (to first order
//! in its size). The monodromy matrix is that of the discrete map, so its damping carries the
//! integrator's numerical damping (§7.4).

mod harmonics;

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
    /// Characteristic exponents (1/s), in the multipliers' order, on the principal branch
    /// `|Im s| <= pi / T`.
    pub exponents: Vec<c64>,
    /// Each exponent's frequency (rad/s) resolved by the dominant harmonic of its mode's time
    /// history over the period (THEORY §9.2 step 4): `Im s + l 2 pi / T`. From perturbed
    /// runs, which keep no history, the principal branch's.
    pub frequencies: Vec<f64>,
    /// Each mode's shape at the start (in the multipliers' order): the weighted displacements
    /// of the free coordinates, then their weighted rates over `2 pi / T`; what a sweep
    /// follows its modes by.
    pub shapes: Vec<Vec<c64>>,
    /// Newton iterations over all runs.
    pub newton_iterations: usize,
    /// How the monodromy matrix was built.
    pub how: Monodromy,
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

/// How the monodromy matrix is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Monodromy {
    /// From the step's own tangent carried along one run (the Newmark family with
    /// incremental rotations; other integrators fall back to [`Monodromy::Runs`]).
    Tangent,
    /// From `4 n_f` perturbed runs of one period, by central differences (any integrator).
    Runs,
}

/// What the start of a Floquet analysis leaves: the integrator at the consistent reference
/// start, and the perturbation space.
struct Space {
    free: Vec<usize>,
    weights: Vec<f64>,
    basis: Vec<f64>,
    r: usize,
    omega: f64,
    start: State,
}

impl Space {
    fn measure(&self, sys: &System, st: &State, reference: &State) -> Vec<f64> {
        measure(
            sys,
            st,
            reference,
            &self.free,
            &self.basis,
            &self.weights,
            self.omega,
        )
    }

    /// A mode's shape at the start from its eigenvector `v` (`2 r` entries): the free
    /// coordinates' weighted displacements, then their weighted rates over `Omega`.
    fn shape(&self, v: &[(f64, f64)]) -> Vec<c64> {
        let nfree = self.free.len();
        let mut out = vec![c64::new(0.0, 0.0); 2 * nfree];
        for (c, col) in self.basis.chunks(nfree).enumerate() {
            for (half, x) in [(0, v[c]), (nfree, v[self.r + c])] {
                for (o, b) in out[half..half + nfree].iter_mut().zip(col) {
                    o.re += b * x.0;
                    o.im += b * x.1;
                }
            }
        }
        out
    }

    fn perturbed(&self, sys: &System, dir: usize, eps: f64) -> State {
        perturbed(
            sys,
            &self.free,
            &self.basis,
            &self.weights,
            self.omega,
            dir,
            eps,
        )
    }
}

/// Floquet analysis of the model's motion over `period` seconds (THEORY §9.2), with the
/// integrator and step of `set`, the monodromy from the step's tangent where the integrator
/// carries one. `progress` is called after each integration.
pub fn floquet(
    sys: &System,
    set: &Settings,
    period: f64,
    progress: &dyn Fn(),
) -> Result<Floquet, FloquetFailure> {
    floquet_by(sys, set, period, Monodromy::Tangent, progress)
}

/// [`floquet`] with the monodromy built as `how` says.
pub fn floquet_by(
    sys: &System,
    set: &Settings,
    period: f64,
    how: Monodromy,
    progress: &dyn Fn(),
) -> Result<Floquet, FloquetFailure> {
    let reference_failure = |failure| FloquetFailure { run: None, failure };
    let set = set.over(period);
    let (steps, h) = (set.steps, set.dt);
    let mut it = Integrator::new(sys, &set).map_err(reference_failure)?;
    it.initialize().map_err(reference_failure)?;
    let lin = it.linearize();
    let (weights, basis, r) = perturbation_space(sys, &lin).map_err(reference_failure)?;
    let space = Space {
        free: lin.unknowns.clone(),
        weights,
        basis,
        r,
        omega: 2.0 * std::f64::consts::PI / period,
        start: it.state().clone(),
    };
    let how = if it.can_track() { how } else { Monodromy::Runs };
    let Columns {
        z0,
        zt,
        newton_iterations,
        history,
    } = match how {
        Monodromy::Tangent => by_tangent(sys, &mut it, &space, progress)?,
        Monodromy::Runs => by_runs(sys, &mut it, &space, progress)?,
    };
    let n = 2 * r;
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
    let modes = eigen(&phi, n).ok_or_else(|| {
        reference_failure(RuntimeFailure {
            kind: super::FailureKind::Singular,
            t: period,
            step: steps,
            entity: None,
            detail: "the eigenvalues of the monodromy matrix could not be computed".into(),
        })
    })?;
    let multipliers: Vec<c64> = modes.iter().map(|(m, _)| *m).collect();
    let shapes = modes.iter().map(|(_, v)| space.shape(v)).collect();
    let exponents: Vec<c64> = multipliers.iter().map(|&m| exponent(m, period)).collect();
    let principal = || exponents.iter().map(|s| s.im).collect();
    let frequencies = if history.len() > 2 {
        let shapes: Vec<harmonics::Mode> = exponents
            .iter()
            .zip(modes)
            .map(|(s, (_, v))| ((s.re, s.im), v))
            .collect();
        harmonics::resolve(&history, &z0, &shapes, period).unwrap_or_else(principal)
    } else {
        principal()
    };
    Ok(Floquet {
        period,
        steps,
        dt: h,
        free: r,
        monodromy: phi,
        multipliers,
        exponents,
        frequencies,
        shapes,
        newton_iterations,
        how,
    })
}

/// The columns of the perturbations at the start and after one period, the Newton
/// iterations they took, and (from the tangent) their history over the period.
struct Columns {
    z0: DMatrix<f64>,
    zt: DMatrix<f64>,
    newton_iterations: usize,
    history: Vec<(f64, DMatrix<f64>)>,
}

/// The perturbed starts, each made consistent: their measure `Z_0` (central differences);
/// `each(it, dir, sign)` is called with the integrator at each start.
fn starts<F>(
    sys: &System,
    it: &mut Integrator,
    space: &Space,
    mut each: F,
) -> Result<DMatrix<f64>, FloquetFailure>
where
    F: FnMut(&mut Integrator, usize, f64) -> Result<(), RuntimeFailure>,
{
    let n = 2 * space.r;
    let mut z0 = DMatrix::<f64>::zeros(n, n);
    for dir in 0..n {
        for sign in [1.0, -1.0] {
            let fail = |failure| FloquetFailure {
                run: Some((dir, sign)),
                failure,
            };
            it.restart(&space.perturbed(sys, dir, sign * EPSILON))
                .map_err(fail)?;
            let a = space.measure(sys, it.state(), &space.start);
            for i in 0..n {
                z0[(i, dir)] += sign * a[i] / (2.0 * EPSILON);
            }
            each(it, dir, sign).map_err(fail)?;
        }
    }
    Ok(z0)
}

/// The monodromy's columns from the step's tangent: the perturbed starts' directions carried
/// through one run of the period (THEORY §9.2), measured at its end.
fn by_tangent(
    sys: &System,
    it: &mut Integrator,
    space: &Space,
    progress: &dyn Fn(),
) -> Result<Columns, FloquetFailure> {
    let reference_failure = |failure| FloquetFailure { run: None, failure };
    let n = 2 * space.r;
    let dim = it.direction_len();
    let mut directions = vec![0.0; n * dim];
    let mut diff = vec![0.0; dim];
    // Each start's difference from the reference start in the step's state layout.
    let z0 = starts(sys, it, space, |it, dir, sign| {
        it.state_difference(it.state(), &space.start, &mut diff);
        let col = &mut directions[dir * dim..(dir + 1) * dim];
        for (c, d) in col.iter_mut().zip(&diff) {
            *c += sign * d / (2.0 * EPSILON);
        }
        Ok(())
    })?;
    it.restart(&sys.initial).map_err(reference_failure)?;
    it.track(directions, 1.0 / space.omega);
    // The directions' measure at evenly spaced steps, for the modes' time histories.
    let stride = (it.steps() / harmonics::SAMPLES).max(1);
    let (t0, mut history) = (it.state().t, Vec::new());
    history.push((0.0, z0.clone()));
    it.run(|k, it| {
        if k % stride == 0 && k < it.steps() {
            history.push((
                it.state().t - t0,
                carried_measure(sys, it, space, it.state()),
            ));
        }
        Ok::<(), Infallible>(())
    })
    .map_err(|s| match s {
        Stop::Failed(f) => reference_failure(f),
        Stop::Stopped(never) => match never {},
    })?;
    progress();
    let zt = carried_measure(sys, it, space, it.state());
    Ok(Columns {
        z0,
        zt,
        newton_iterations: it.stats().newton_iterations,
        history,
    })
}

/// The measure of the carried directions at the integrator's current state `reference`.
fn carried_measure(
    sys: &System,
    it: &Integrator,
    space: &Space,
    reference: &State,
) -> DMatrix<f64> {
    let (n, dim) = (2 * space.r, it.direction_len());
    let carried = it.tracked().unwrap_or_default();
    let mut zt = DMatrix::<f64>::zeros(n, n);
    let mut st = reference.clone();
    for dir in 0..n {
        let col = &carried[dir * dim..(dir + 1) * dim];
        // The measure reads positions and rates; it is linear but for the rotations'
        // logarithm: a small step of each sign, sized by them (a stiff mode's accelerations
        // would shrink it into round-off).
        let size = col[..dim / 2].iter().enumerate().fold(0.0f64, |m, (i, x)| {
            let scale = if i < dim / 4 { 1.0 } else { 1.0 / space.omega };
            m.max(x.abs() * scale / sys.length_scale.min(1.0))
        });
        if size == 0.0 {
            continue;
        }
        let e = 1e-6 / size;
        it.perturb_state(reference, col, e, &mut st);
        let b = space.measure(sys, &st, reference);
        it.perturb_state(reference, col, -e, &mut st);
        let c = space.measure(sys, &st, reference);
        for i in 0..n {
            zt[(i, dir)] = (b[i] - c[i]) / (2.0 * e);
        }
    }
    zt
}

/// The monodromy's columns from `4 n_f` perturbed runs of one period.
fn by_runs(
    sys: &System,
    it: &mut Integrator,
    space: &Space,
    progress: &dyn Fn(),
) -> Result<Columns, FloquetFailure> {
    let reference_failure = |failure| FloquetFailure { run: None, failure };
    let reference = integrate(it).map_err(reference_failure)?;
    progress();
    let mut newton_iterations = it.stats().newton_iterations;
    let n = 2 * space.r;
    // Each perturbed start integrated over the period (the projection onto the joints at the
    // start moves the dependent velocities of a position perturbation): Phi = Z_T Z_0^-1.
    let mut zt = DMatrix::<f64>::zeros(n, n);
    let z0 = starts(sys, it, space, |it, dir, sign| {
        let end = integrate(it)?;
        newton_iterations += it.stats().newton_iterations;
        let b = space.measure(sys, &end, &reference);
        for i in 0..n {
            zt[(i, dir)] += sign * b[i] / (2.0 * EPSILON);
        }
        progress();
        Ok(())
    })?;
    Ok(Columns {
        z0,
        zt,
        newton_iterations,
        history: Vec::new(),
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

/// The eigenvalues of the `n x n` column-major matrix `phi` and their eigenvectors, by
/// decreasing modulus.
#[allow(clippy::type_complexity)]
fn eigen(phi: &[f64], n: usize) -> Option<Vec<(c64, Vec<(f64, f64)>)>> {
    let identity: Vec<f64> = (0..n * n)
        .map(|k| if k % (n + 1) == 0 { 1.0 } else { 0.0 })
        .collect();
    let eig = if n == 0 {
        Vec::new()
    } else {
        generalized_eigen(phi, &identity, n)?
    };
    let mut modes: Vec<(c64, Vec<(f64, f64)>)> = eig
        .into_iter()
        .map(|((ar, ai), (br, bi), v)| {
            // alpha / beta
            let d = br * br + bi * bi;
            (
                c64::new((ar * br + ai * bi) / d, (ai * br - ar * bi) / d),
                v,
            )
        })
        .collect();
    let modulus = |m: &c64| (m.re * m.re + m.im * m.im).sqrt();
    modes.sort_by(|a, b| modulus(&b.0).total_cmp(&modulus(&a.0)));
    Some(modes)
}
