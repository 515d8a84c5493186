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
//!    length scale and rotations in radians. `V` are the directions of `N0` with inertia
//!    (`N0^T W M W N0` not zero along them) and the states `z = (V^T W^-1 dq, V^T W^-1 dv / w)`
//!    (`2 n_m` entries) with `w = 2 pi / T`; rotations differ by `axial log(R Rbar^T)`
//!    (spatial, as the perturbation `R <- exp(dtheta~) R`). A direction without inertia (the
//!    rotation of a beam node without rotary inertia) is no state: the balance holds along it
//!    at every step, so its position follows the others. Each perturbed start displaces it
//!    into that equilibrium (the balance linearized at the start, `floquet/space.rs`); left
//!    where it was, the first step answers it 1e4 times over, and the reference's slight
//!    non-periodicity reached the multipliers through that answer (the elastic windmill's
//!    growth rate was off by 0.3 %).
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
//! lives in `(q, v, a, A)`, twice the dimension of `z`. `Phi` chains the sensitivities through
//! the consistent start (accelerations as functions of `(q, v)` at `t = 0`) and carries the
//! whole step state inside the period, measuring `(q, v)` at its end. The discrete map's extra
//! multipliers are algorithmic: the step damps them by `rho_inf` (0.82 at alpha -0.1), so over
//! the `N` steps of a period their share of `Z_T` is `rho_inf^N`. But the start's accelerations
//! are not the discrete motion's: for a beam's stiff axial and shear modes they differ by
//! orders of magnitude, and the multipliers of `Phi` carry that error once (the elastic
//! windmill: 3.5e-4 relative at 0.5 ms, 2.7e-3 at 1 ms, against the discrete motion's own
//! growth). So with the tangent and a damping integrator the multipliers are the discrete
//! map's own (`Settled`): the run goes on for the settling steps past the period; after them
//! (the algorithmic part at 1e-10) the carried directions that are not damped out are made
//! orthonormal in the weighted step state (`integrator/deflate.rs`), carried one period on, and
//! the map's Rayleigh-Ritz projection on them, `U^T W S`, gives the multipliers: its subspace
//! holds the slow invariant one, so they are exact, and no start enters (the elastic windmill:
//! 1.6e-5 from the multiblade equations with stiff blades; the undamped rigid windmill's
//! neutral modes at 1e-9 1/s instead of 8.5e-7). `Phi` (through the start) stays the
//! reported monodromy matrix, which perturbed runs build the same way, and guards the
//! projection: a largest multiplier above `Phi`'s by 1 % would be a Ritz value of the damped
//! directions, and `Phi`'s multipliers are reported then.

//! The reference is the model's own motion from its initial state, loads included: a pulse that
//! acts in the first period is in every run and cancels in the differences (to first order
//! in its size). The monodromy matrix is that of the discrete map, so its damping carries the
//! integrator's numerical damping (§7.4).

mod harmonics;
mod krylov;
mod space;
mod tangent;

use super::integrator::Integrator;
use super::integrator::DEAD;
use super::linear;
use super::modes::c64;
use super::{RuntimeFailure, Stop};
use crate::runtime::{State, System};
use crate::settings::{Method, Settings};
use nalgebra::DMatrix;
use space::Space;
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
    /// Dimension `n_f` of the constraint-free position space (the state has `n_f + n_m`, `n_m`
    /// its directions with inertia).
    pub free: usize,
    /// The monodromy matrix, column-major over the state (`n_f + n_m` square).
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
    /// Steps a run went on past the period for its directions' algorithmic part to die out
    /// (0 without: an integrator that does not damp it, or perturbed runs).
    pub settling: usize,
    /// How the monodromy matrix was built.
    pub how: Monodromy,
    /// Partial Floquet's account ([`Monodromy::Krylov`]; `monodromy` is empty then).
    pub partial: Option<Partial>,
    /// The multipliers left out as round-off of the monodromy, if any ([`Unresolved`]).
    pub unresolved: Option<Unresolved>,
}

/// Multipliers at the monodromy's round-off: their exponents are not resolved, and are not
/// listed (they are known only to lie below `real_below`).
#[derive(Clone, Debug)]
pub struct Unresolved {
    /// How many.
    pub count: usize,
    /// The modulus they do not exceed.
    pub modulus: f64,
    /// The real part (1/s) their exponents lie below: `ln(modulus) / T`.
    pub real_below: f64,
}

/// What partial Floquet did: the multipliers wanted, the block's size, the runs of a period
/// it took (one block each), and whether the wanted ones converged (else the basis reached
/// the state's dimension first).
#[derive(Clone, Debug)]
pub struct Partial {
    pub wanted: usize,
    pub block: usize,
    pub products: usize,
    pub converged: bool,
}

/// Where the directions the whole analysis carries (`2 n_m` of `4 n` entries) would take more
/// bytes than this, the tangent's analysis is partial ([`Monodromy::Krylov`] of
/// [`PARTIAL_MODES`]): it carries a block of a few, at the cost of a run of the period per
/// block, which costs more CPU on every model measured (the elastic windmill with 12
/// elements per blade, 578 state entries: 19 s whole, 48 s partial for 2 modes) but a
/// fraction of the memory (323 MB against 75 MB).
pub const PARTIAL_ABOVE_BYTES: usize = 2 << 30;

/// The multipliers a partial analysis chosen by size looks for.
pub const PARTIAL_MODES: usize = 8;

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

/// Integrates from the integrator's current (initialized) state over its settings' steps.
fn integrate(it: &mut Integrator) -> Result<State, RuntimeFailure> {
    it.run(|_, _| Ok::<(), Infallible>(()))
        .map_err(|s| match s {
            Stop::Failed(f) => f,
            Stop::Stopped(never) => match never {},
        })?;
    Ok(it.state().clone())
}

/// Steps after which the integrator has damped the algorithmic part of directions carrying
/// at most `content` of it (of their weighted size) below
/// [`DEAD`](crate::solve::integrator::DEAD): its spectral radius at infinity to that power
/// reaches `DEAD / content`; the carried directions are deflated that often. 0 (never) for
/// an integrator that does not damp them. A direction of unknown make-up has `content` 1.
fn deflation_steps(set: &Settings, content: f64) -> usize {
    let rho = match set.method {
        Method::Hht => (1.0 + set.alpha) / (1.0 - set.alpha),
        Method::GeneralizedAlpha => set.rho_inf,
        Method::Fet | Method::Static => 1.0,
    };
    if rho.is_nan() || rho >= 0.99 {
        return 0;
    }
    let content = if content.is_finite() {
        content.clamp(DEAD, 1.0)
    } else {
        1.0
    };
    ((DEAD / content).ln() / rho.max(1e-3).ln()).ceil().max(1.0) as usize
}

/// The settled projection's largest multiplier may exceed that of `Phi` (through the
/// consistent start) by this share; beyond it, `Phi`'s multipliers are reported.
const RITZ_GUARD: f64 = 1e-2;

/// How the monodromy matrix is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Monodromy {
    /// From the step's own tangent carried along one run (the Newmark family with
    /// incremental rotations; other integrators fall back to [`Monodromy::Runs`]).
    Tangent,
    /// From two perturbed runs of one period per state direction, by central differences (any
    /// integrator).
    Runs,
    /// Partial Floquet: the given number of multipliers of largest modulus, by block Arnoldi
    /// on the step's tangent over one period (`floquet/krylov.rs`; a damping integrator with
    /// incremental rotations and a state several blocks large, else [`Monodromy::Tangent`]).
    Krylov(usize),
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
    let omega = 2.0 * std::f64::consts::PI / period;
    let space = Space::new(sys, &lin, omega, it.state().clone()).map_err(reference_failure)?;
    let how = chosen(how, &it, space.dim());
    let Columns {
        z0,
        zt,
        newton_iterations,
        settling,
        history,
        settled,
    } = match how {
        Monodromy::Tangent => tangent::by_tangent(sys, &mut it, &space, progress)?,
        Monodromy::Runs => by_runs(sys, &mut it, &space, progress)?,
        Monodromy::Krylov(k) => return krylov::partial(sys, &mut it, &space, k, period, progress),
    };
    let n = space.dim();
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
    // The multipliers: of the discrete map itself where the tangent settled, else of `Phi`.
    // A settled projection whose largest multiplier exceeds `Phi`'s by more than `RITZ_GUARD`
    // holds a Ritz value of the damped-out directions, not a mode: `Phi` is used then.
    let largest = |m: &[f64], n: usize| {
        eigen(m, n).map_or(f64::INFINITY, |e| {
            e.first().map_or(0.0, |(l, _)| l.re.hypot(l.im))
        })
    };
    let settled = settled.filter(|st| {
        largest(st.c.as_slice(), st.c.nrows()) <= (1.0 + RITZ_GUARD) * largest(&phi, n)
    });
    let (matrix, r, history, z0) = match &settled {
        Some(st) => (
            st.c.as_slice().to_vec(),
            st.c.nrows(),
            &st.history,
            DMatrix::identity(st.c.nrows(), st.c.nrows()),
        ),
        None => (phi.clone(), n, &history, z0),
    };
    let (modes, unresolved) = resolved_modes(&matrix, r, period).ok_or_else(|| {
        reference_failure(RuntimeFailure {
            kind: super::FailureKind::Singular,
            t: period,
            step: steps,
            entity: None,
            detail: "the eigenvalues of the monodromy matrix could not be computed".into(),
        })
    })?;
    // Eigenvectors in the measure `z` (the settled directions' measure times theirs).
    let in_z = |v: &[(f64, f64)]| -> Vec<(f64, f64)> {
        match &settled {
            Some(st) => {
                let part = |pick: fn(&(f64, f64)) -> f64| {
                    &st.z * DMatrix::from_iterator(v.len(), 1, v.iter().map(pick))
                };
                let (re, im) = (part(|x| x.0), part(|x| x.1));
                re.iter().zip(im.iter()).map(|(&a, &b)| (a, b)).collect()
            }
            None => v.to_vec(),
        }
    };
    let multipliers: Vec<c64> = modes.iter().map(|(m, _)| *m).collect();
    let shapes = modes.iter().map(|(_, v)| space.shape(&in_z(v))).collect();
    let exponents: Vec<c64> = multipliers.iter().map(|&m| exponent(m, period)).collect();
    let principal = || exponents.iter().map(|s| s.im).collect();
    let frequencies = if history.len() > 2 {
        let shapes: Vec<harmonics::Mode> = exponents
            .iter()
            .zip(modes)
            .map(|(s, (_, v))| ((s.re, s.im), v))
            .collect();
        harmonics::resolve(history, &z0, &shapes, period).unwrap_or_else(principal)
    } else {
        principal()
    };
    Ok(Floquet {
        period,
        steps,
        dt: h,
        free: space.r,
        monodromy: phi,
        multipliers,
        exponents,
        frequencies,
        shapes,
        newton_iterations,
        settling,
        how,
        partial: None,
        unresolved,
    })
}

/// Multipliers with their eigenvectors.
type Modes = Vec<(c64, Vec<(f64, f64)>)>;

/// The eigenpairs of `matrix` (`r x r`, largest multiplier first) whose multipliers exceed its
/// round-off ([`RESOLVED`]), and those left out, if any.
fn resolved_modes(matrix: &[f64], r: usize, period: f64) -> Option<(Modes, Option<Unresolved>)> {
    let mut modes = eigen(matrix, r)?;
    let floor = resolution(matrix);
    let count = modes.len();
    modes.retain(|(m, _)| m.re.hypot(m.im) > floor);
    let unresolved = (modes.len() < count).then_some(Unresolved {
        count: count - modes.len(),
        modulus: floor,
        real_below: floor.ln() / period,
    });
    Some((modes, unresolved))
}

/// Round-offs of the monodromy (`f64::EPSILON` times its Frobenius norm) a multiplier's
/// modulus must exceed to be resolved: its own round-off is then at most 1e-3 of it, and its
/// exponent's real part known to `1e-3 / T`. The elastic windmill at Omega_bar 1.5 (settled
/// projection of norm 124, T = 0.45 s): its multipliers near 1e-9 (Re s = -45.6 1/s) move by
/// 1e-15 of their own when the speed moves by 1e-13; those near 2e-15 (Re s = -75 1/s and
/// below) move by up to 6 1/s, and are round-off.
const RESOLVED: f64 = 1e3;

/// The modulus at or below which a multiplier of `matrix` is round-off ([`RESOLVED`]).
fn resolution(matrix: &[f64]) -> f64 {
    RESOLVED * f64::EPSILON * matrix.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// How the monodromy is built for a state of `dim` entries: from runs where the integrator
/// carries no tangent, the whole analysis where partial does not apply, partial where the whole
/// one's directions would take more than [`PARTIAL_ABOVE_BYTES`].
fn chosen(how: Monodromy, it: &Integrator, dim: usize) -> Monodromy {
    let settle = deflation_steps(it.settings(), 1.0);
    match how {
        _ if !it.can_track() => Monodromy::Runs,
        Monodromy::Krylov(k) if !krylov::applies(dim, k, settle) => Monodromy::Tangent,
        Monodromy::Tangent
            if dim * it.direction_len() * 8 > PARTIAL_ABOVE_BYTES
                && krylov::applies(dim, PARTIAL_MODES, settle) =>
        {
            Monodromy::Krylov(PARTIAL_MODES)
        }
        how => how,
    }
}

/// The columns of the perturbations at the start and after one period, the Newton
/// iterations they took, and (from the tangent) their history over the period.
struct Columns {
    z0: DMatrix<f64>,
    zt: DMatrix<f64>,
    newton_iterations: usize,
    settling: usize,
    history: Vec<(f64, DMatrix<f64>)>,
    /// From the tangent with a damping integrator: the discrete map's own monodromy.
    settled: Option<Settled>,
}

/// The monodromy projected on the directions the integrator kept after the settling steps
/// (`integrator/deflate.rs`), over one period from them: `c` (`r x r`), the measure `z` of
/// those directions (`n x r`), and their history over the period.
struct Settled {
    c: DMatrix<f64>,
    z: DMatrix<f64>,
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
    let n = space.dim();
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

/// The measure of each carried column at the integrator's current state `reference`.
fn carried_raw(sys: &System, it: &Integrator, space: &Space, reference: &State) -> DMatrix<f64> {
    let (dim, nfree) = (it.direction_len(), space.free.len());
    let carried = it.tracked().unwrap_or_default();
    let n = carried.len() / dim.max(1);
    // Each direction's weighted displacements and rates, then projected all at once.
    let (mut dq, mut dv) = (
        DMatrix::<f64>::zeros(nfree, n),
        DMatrix::<f64>::zeros(nfree, n),
    );
    let (mut bq, mut bv) = (vec![0.0; nfree], vec![0.0; nfree]);
    let (mut cq, mut cv) = (vec![0.0; nfree], vec![0.0; nfree]);
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
        space.displacements(sys, &st, reference, (&mut bq, &mut bv));
        it.perturb_state(reference, col, -e, &mut st);
        space.displacements(sys, &st, reference, (&mut cq, &mut cv));
        for j in 0..nfree {
            dq[(j, dir)] = (bq[j] - cq[j]) / (2.0 * e);
            dv[(j, dir)] = (bv[j] - cv[j]) / (2.0 * e);
        }
    }
    space.project(&dq, &dv)
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
    let n = space.dim();
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
        settling: 0,
        history: Vec::new(),
        settled: None,
    })
}

/// The eigenvalues of the `n x n` column-major matrix `phi` and their eigenvectors, by
/// decreasing modulus.
#[allow(clippy::type_complexity)]
fn eigen(phi: &[f64], n: usize) -> Option<Vec<(c64, Vec<(f64, f64)>)>> {
    let mut modes: Vec<(c64, Vec<(f64, f64)>)> = linear::eigen(phi, n)?
        .into_iter()
        .map(|((re, im), v)| (c64::new(re, im), v))
        .collect();
    let modulus = |m: &c64| (m.re * m.re + m.im * m.im).sqrt();
    modes.sort_by(|a, b| modulus(&b.0).total_cmp(&modulus(&a.0)));
    Some(modes)
}
