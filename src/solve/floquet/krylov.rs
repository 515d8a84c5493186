//! Partial Floquet (THEORY §9.2): the dominant multipliers of the discrete map alone, by block
//! Arnoldi on its action over one period, for states too large to carry whole.
//!
//! The operator is the discrete map over one period from the phase `t_s` past the settling
//! steps (`deflation_steps`: the algorithmic part of a direction is damped to `DEAD` there),
//! in the weighted step state of `integrator/deflate.rs`: the same map whose Rayleigh-Ritz
//! projection the whole analysis reports (`Settled`), so no consistent start enters. Its
//! action on a block of `b` directions is one run: the reference restarted, the settling steps
//! with nothing carried, then the block carried through one period by the step's tangent
//! (`b` back-substitutions a step with the step's own factorization). The start block is `b`
//! pseudo-random states lifted by consistent starts and carried through the settling steps.
//! Each image is made orthogonal to the basis (block Gram-Schmidt, twice) and the
//! Rayleigh-Ritz values of the block Hessenberg matrix `H` are the multipliers.
//!
//! Convergence: a Ritz pair `(theta, y)` has the residual `|H_{m+1,m} y_m|` (its last block);
//! the `K` wanted are the largest in modulus, and they are converged when each residual is
//! below [`TOLERANCE`] of `|theta|` and the next Ritz value, if not converged itself, cannot
//! reach them (its modulus plus its residual below theirs minus theirs). The lightly damped
//! modes of a structure sit clustered on the unit circle, where Arnoldi separates them only
//! slowly: the test asks nothing of them while the wanted ones stand clear; when the wanted
//! ones are inside the cluster it goes on until they converge or the basis reaches the state's
//! dimension (then the projection is the whole map, and exact).

use super::{carried_raw, deflation_steps, exponent, harmonics, Floquet, FloquetFailure};
use super::{Monodromy, Partial, Space, EPSILON};
use crate::runtime::System;
use crate::solve::integrator::Integrator;
use crate::solve::linear;
use crate::solve::modes::c64;
use crate::solve::{RuntimeFailure, Stop};
use nalgebra::DMatrix;
use std::convert::Infallible;

/// A Ritz pair is converged when its residual is below this share of its value's modulus
/// (the multiplier's relative error is about the residual for the well-separated modes
/// sought, the exponent's `residual / T`: 2e-6 1/s on the windmill).
pub const TOLERANCE: f64 = 1e-6;

/// What block Arnoldi found.
pub(super) struct Krylov {
    /// The wanted Ritz values and any others converged, largest modulus first, with their
    /// vectors in the basis's coordinates.
    pub(super) modes: Vec<(c64, Vec<(f64, f64)>)>,
    /// The basis's measure `z` at the phase the products start from (`2 n_m x m b`), and its
    /// images' measure at evenly spaced steps of the period after it.
    pub(super) z: DMatrix<f64>,
    pub(super) history: Vec<(f64, DMatrix<f64>)>,
    pub(super) newton_iterations: usize,
    pub(super) products: usize,
    pub(super) block: usize,
    pub(super) converged: bool,
}

/// The block size for `wanted` multipliers: a few more than wanted, so that a conjugate pair
/// or a near neighbour of the last wanted one is in every block.
pub(super) fn block_size(wanted: usize) -> usize {
    wanted.max(1) + 4
}

/// Whether partial Floquet applies to a state of `dim` entries with `set`'s integrator: it
/// needs the settling steps (a damping integrator) and a state several blocks large
/// (otherwise the whole map is cheaper).
pub(super) fn applies(dim: usize, wanted: usize, settle: usize) -> bool {
    settle > 0 && 3 * block_size(wanted) <= dim
}

/// `W u` for the columns of `u` (column-major `dim x count`).
fn weighted(columns: &[f64], weights: &[f64]) -> DMatrix<f64> {
    let dim = weights.len();
    DMatrix::from_fn(dim, columns.len() / dim.max(1), |i, j| {
        columns[j * dim + i] * weights[i]
    })
}

/// Block Arnoldi on the discrete map over one period (see the module's text): `wanted`
/// multipliers of largest modulus.
pub(super) fn by_krylov(
    sys: &System,
    it: &mut Integrator,
    space: &Space,
    wanted: usize,
    progress: &dyn Fn(),
) -> Result<Krylov, FloquetFailure> {
    let reference_failure = |failure| FloquetFailure { run: None, failure };
    let (n, dim) = (space.dim(), it.direction_len());
    let (period, settle) = (it.steps(), deflation_steps(it.settings(), 1.0));
    let b = block_size(wanted);
    let tau = 1.0 / space.omega;
    let lifted = lifted_block(sys, it, space, b)?;
    let mut newton_iterations = 0;
    let integrate = |it: &mut Integrator| -> Result<usize, FloquetFailure> {
        it.run(|_, _| Ok::<(), Infallible>(()))
            .map_err(|s| reference_failure(stopped(s)))?;
        Ok(it.stats().newton_iterations)
    };
    // To the phase: the reference restarted, `columns` carried through the settling steps.
    let to_phase = |it: &mut Integrator, columns: Vec<f64>| -> Result<usize, FloquetFailure> {
        it.restart(&sys.initial).map_err(reference_failure)?;
        it.track(columns, tau);
        it.set_run(settle);
        integrate(it)
    };
    newton_iterations += to_phase(it, lifted)?;
    // The weights exist once `track` was called (in `to_phase`); `weighted` of none is empty.
    let weights = it.direction_weights().unwrap_or_default();
    let first = weighted(it.tracked().unwrap_or_default(), &weights);
    let mut basis = vec![first.qr().q()];
    let mut h = DMatrix::<f64>::zeros(b, 0);
    let (mut zs, mut histories) = (Vec::new(), Vec::<Vec<(f64, DMatrix<f64>)>>::new());
    let stride = (period / harmonics::SAMPLES).max(1);
    let (modes, converged) = loop {
        let j = basis.len() - 1;
        if j > 0 {
            let count = to_phase(it, Vec::new())?;
            newton_iterations += count;
        }
        // The block carried over one period from the phase.
        let q = &basis[j];
        let columns: Vec<f64> = (0..dim * b)
            .map(|k| q[(k % dim, k / dim)] / weights[k % dim])
            .collect();
        it.track(columns, tau);
        it.set_run(period);
        let ts = it.state().t;
        let mut history = vec![(0.0, carried_raw(sys, it, space, it.state()))];
        it.run(|k, it| {
            if k % stride == 0 && k < period {
                let t = it.state().t - ts;
                history.push((t, carried_raw(sys, it, space, it.state())));
            }
            Ok::<(), Infallible>(())
        })
        .map_err(|s| reference_failure(stopped(s)))?;
        newton_iterations += it.stats().newton_iterations;
        progress();
        zs.push(history[0].1.clone());
        histories.push(history);
        // The image made orthogonal to the basis (twice, for the round-off).
        let w = weighted(it.tracked().unwrap_or_default(), &weights);
        h = extend(&mut basis, &h, w);
        let m = basis.len() - 1;
        let last = m * b + b > n;
        let square = h.view((0, 0), (m * b, m * b)).clone_owned();
        let below = h.view((m * b, (m - 1) * b), (b, b)).clone_owned();
        let (found, done) = ritz(&square, &below, wanted);
        if done || last {
            break (found, done);
        }
    };
    let count = basis.len() - 1;
    let z = DMatrix::from_fn(n, count * b, |i, j| zs[j / b][(i, j % b)]);
    let samples = histories[0].len();
    let history = (0..samples)
        .map(|s| {
            let t = histories[0][s].0;
            (
                t,
                DMatrix::from_fn(n, count * b, |i, j| histories[j / b][s].1[(i, j % b)]),
            )
        })
        .collect();
    Ok(Krylov {
        modes,
        z,
        history,
        newton_iterations,
        products: count,
        block: b,
        converged,
    })
}

/// The start block: `b` pseudo-random unit states, each lifted to the step's state by the
/// central difference of two consistent starts (column-major `dim x b`).
fn lifted_block(
    sys: &System,
    it: &mut Integrator,
    space: &Space,
    b: usize,
) -> Result<Vec<f64>, FloquetFailure> {
    let (n, dim) = (space.dim(), it.direction_len());
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut rnd = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    let (mut lifted, mut diff) = (vec![0.0; b * dim], vec![0.0; dim]);
    for c in 0..b {
        let mut x: Vec<f64> = (0..n).map(|_| rnd()).collect();
        let size = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        x.iter_mut().for_each(|v| *v /= size);
        for sign in [1.0, -1.0] {
            let start = space.perturbed_along(sys, &x, sign * EPSILON);
            it.restart(&start).map_err(|failure| FloquetFailure {
                run: Some((c, sign)),
                failure,
            })?;
            it.state_difference(it.state(), &space.start, &mut diff);
            for (o, d) in lifted[c * dim..(c + 1) * dim].iter_mut().zip(&diff) {
                *o += sign * d / (2.0 * EPSILON);
            }
        }
    }
    Ok(lifted)
}

/// A run's stop as a failure (the runs here stop for no reason of their own).
fn stopped(s: Stop<Infallible>) -> RuntimeFailure {
    match s {
        Stop::Failed(f) => f,
        Stop::Stopped(never) => match never {},
    }
}

/// The Ritz pairs of the basis's projection `square` (its coupling to the next block
/// `below`), and whether the `wanted` largest are converged: the wanted ones and every other
/// converged one, largest modulus first.
#[allow(clippy::type_complexity)]
fn ritz(
    square: &DMatrix<f64>,
    below: &DMatrix<f64>,
    wanted: usize,
) -> (Vec<(c64, Vec<(f64, f64)>)>, bool) {
    let size = square.nrows();
    let b = below.nrows();
    let Some(pairs) = linear::eigen(square.as_slice(), size) else {
        return (Vec::new(), false);
    };
    // Each pair's modulus and relative residual `|below y_last| / (|y| |theta|)`.
    let mut rated: Vec<(f64, f64, c64, Vec<(f64, f64)>)> = pairs
        .into_iter()
        .map(|((re, im), y)| {
            let norm = y.iter().map(|(a, c)| a * a + c * c).sum::<f64>().sqrt();
            let tail = |pick: fn(&(f64, f64)) -> f64| {
                below * DMatrix::from_iterator(b, 1, y[size - b..].iter().map(pick))
            };
            let (r_re, r_im) = (tail(|x| x.0), tail(|x| x.1));
            let residual = (r_re.norm_squared() + r_im.norm_squared()).sqrt();
            let modulus = re.hypot(im);
            let relative = residual / (norm * modulus).max(f64::MIN_POSITIVE);
            (modulus, relative, c64::new(re, im), y)
        })
        .collect();
    rated.sort_by(|a, b| b.0.total_cmp(&a.0));
    // The wanted ones, a conjugate pair kept whole.
    let mut k = wanted.min(rated.len());
    if k > 0 && k < rated.len() {
        let (last, next) = (rated[k - 1].2, rated[k].2);
        if last.im != 0.0 && next.re == last.re && next.im == -last.im {
            k += 1;
        }
    }
    let ok = |r: &(f64, f64, c64, Vec<(f64, f64)>)| r.1 <= TOLERANCE;
    let clear = match (rated.get(k), k.checked_sub(1).and_then(|i| rated.get(i))) {
        (Some(next), Some(lowest)) => {
            ok(next) || next.0 * (1.0 + next.1) < lowest.0 * (1.0 - lowest.1)
        }
        _ => true,
    };
    let done = rated[..k].iter().all(ok) && clear;
    let out = rated
        .into_iter()
        .enumerate()
        .filter(|(i, r)| *i < k || ok(r))
        .map(|(_, (_, _, value, y))| (value, y))
        .collect();
    (out, done)
}

/// Partial Floquet of the model's motion over `period` (THEORY §9.2): the `wanted`
/// multipliers of largest modulus, and any others converged on the way.
pub(super) fn partial(
    sys: &System,
    it: &mut Integrator,
    space: &Space,
    wanted: usize,
    period: f64,
    progress: &dyn Fn(),
) -> Result<Floquet, FloquetFailure> {
    let (steps, dt) = (it.steps(), it.settings().dt);
    let k = by_krylov(sys, it, space, wanted, progress)?;
    let multipliers: Vec<c64> = k.modes.iter().map(|(m, _)| *m).collect();
    let exponents: Vec<c64> = multipliers.iter().map(|&m| exponent(m, period)).collect();
    let in_z = |v: &[(f64, f64)]| -> Vec<(f64, f64)> {
        let part = |pick: fn(&(f64, f64)) -> f64| {
            &k.z * DMatrix::from_iterator(v.len(), 1, v.iter().map(pick))
        };
        let (re, im) = (part(|x| x.0), part(|x| x.1));
        re.iter().zip(im.iter()).map(|(&a, &b)| (a, b)).collect()
    };
    let shapes = k.modes.iter().map(|(_, v)| space.shape(&in_z(v))).collect();
    let resolved: Vec<harmonics::Mode> = exponents
        .iter()
        .zip(&k.modes)
        .map(|(s, (_, v))| ((s.re, s.im), v.clone()))
        .collect();
    let basis = k.z.ncols();
    let frequencies = harmonics::resolve(
        &k.history,
        &DMatrix::identity(basis, basis),
        &resolved,
        period,
    )
    .unwrap_or_else(|| exponents.iter().map(|s| s.im).collect());
    Ok(Floquet {
        period,
        steps,
        dt,
        free: space.r,
        monodromy: Vec::new(),
        multipliers,
        exponents,
        frequencies,
        shapes,
        newton_iterations: k.newton_iterations,
        settling: deflation_steps(it.settings(), 1.0),
        how: Monodromy::Krylov(wanted),
        partial: Some(Partial {
            wanted,
            block: k.block,
            products: k.products,
            converged: k.converged,
        }),
        // The Ritz values of largest modulus only: none at round-off.
        unresolved: None,
    })
}

/// Arnoldi's step: the image `w` of the basis's last block made orthogonal to the basis (block
/// Gram-Schmidt, twice for the round-off), its orthonormal rest the next block; the block
/// Hessenberg matrix `h` (`m b x (m - 1) b`) grown by the image's coefficients.
fn extend(basis: &mut Vec<DMatrix<f64>>, h: &DMatrix<f64>, mut w: DMatrix<f64>) -> DMatrix<f64> {
    let (m, b) = (basis.len(), w.ncols());
    let mut column = DMatrix::<f64>::zeros((m + 1) * b, b);
    for _ in 0..2 {
        for (i, qi) in basis.iter().enumerate() {
            let c = qi.transpose() * &w;
            w -= qi * &c;
            let mut rows = column.rows_mut(i * b, b);
            rows += &c;
        }
    }
    let qr = w.qr();
    column.rows_mut(m * b, b).copy_from(&qr.r());
    basis.push(qr.q());
    let mut grown = DMatrix::<f64>::zeros((m + 1) * b, m * b);
    grown.view_mut((0, 0), (m * b, (m - 1) * b)).copy_from(h);
    grown.columns_mut((m - 1) * b, b).copy_from(&column);
    grown
}
