//! The time integrators on one assembly, one sparse LU and one Newton loop (THEORY §6-§8):
//! HHT-alpha and generalized-alpha ([`newmark`]), statics' load steps ([`statics`]), time
//! finite elements ([`fet`]); the consistent start ([`start`], on the constrained mass matrix
//! of [`start_matrix`]); the linearized equations for modes and Floquet ([`linearize`]).
//!
//! This file holds what they share: the integrator's state and workspace, the time loop
//! ([`Integrator::run`]), step halving, the Newton loop of one step (predict, residual and
//! norms, iteration matrix, correction, commit: each method supplies its own), the
//! augmented-Lagrangian scaling and the failures.
//!
//! Rotations (THEORY §2.7, §7.1): [`Layout`] says how the rotation unknowns are held.

mod deflate;
mod fet;
mod history;
mod linearize;
mod newmark;
mod newton;
mod rotations;
mod se3;
mod start;
mod start_matrix;
mod statics;
mod step;
mod tangent;
#[cfg(test)]
mod tests;

pub use deflate::DEAD;
pub use linearize::Linearization;

use super::linear::{LinearError, SparseLu};
use super::{FailureKind, RunStats, RuntimeFailure};
use crate::runtime::rotation::{M3, V3};
use crate::runtime::{Assembler, Augment, Residual, State, System, TangentCoeffs};
use crate::settings::{Method, NewtonMode, Rotations, Settings};
use newmark::Scheme;
use newton::Reuse;
use rotations::Transform;
use start_matrix::StartMetric;
use step::Predictor;

/// Largest rotation of a node in one Newton correction (rad).
const MAX_TURN: f64 = 0.5;

/// Newton iterations within which a beam model's step counts as smooth, so that the next step
/// may keep its matrix after a small correction (`Integrator::smooth`): the elastic windmill
/// converges in 2 a step (factorizations 12,000 -> 6,045 over its 3-s run with the matrix
/// kept); the stiff-beam two-bar at 0.05 s needs 11 and keeps new matrices.
const SMOOTH: usize = 2;

/// How the rotation unknowns are held.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Layout {
    /// Stored rotations moved by body-frame increments: rigid bodies as SE(3) frames, beam
    /// nodes as SO(3) x R3 ([`se3`]); the Newmark family with `Rotations::Incremental`.
    Increments,
    /// The total conformal rotation vector as the unknown, with its rates
    /// ([`rotations`]); the Newmark family with `Rotations::Conformal`.
    Conformal,
    /// Virtual rotations, the state in the physical layout: time finite elements.
    Physical,
}

/// The norms of a residual: forces, their scale, the constraint violation, and the unknown
/// with the largest scaled entry; under kept matrices also the largest force over its own
/// entity's scale ([`Newton::own`]).
#[derive(Clone, Copy, Debug)]
struct Norms {
    force: f64,
    scale: f64,
    constraint: f64,
    worst: usize,
    own: Option<f64>,
}

/// What stopped [`Integrator::run`]: a failed step, or the caller.
#[derive(Debug)]
pub enum Stop<E> {
    Failed(RuntimeFailure),
    Stopped(E),
}

pub struct Integrator<'s> {
    sys: &'s System,
    /// The system's mean translational mass and mean stiffness, for the scaling and the
    /// residual's force floor (made once: each is a pass over the elements).
    means: (f64, f64),
    set: Settings,
    sc: Scheme,
    /// The method (the settings'), and how rotations are held.
    method: Method,
    layout: Layout,
    /// FET: the mid-configuration of the step (constant velocities, the multipliers).
    mid: State,
    /// FET: the joints' residual at the end configuration.
    end_res: Residual,
    asm: Assembler,
    /// The iteration matrix's pivot-free LU, and the step size it was made for while it may be
    /// kept (`newton = modified | auto`); `None` when it must be made anew.
    lu: SparseLu,
    kept: Option<f64>,
    /// The iterate before the last correction (FET's mid-configuration, the step's
    /// increments), to take back a kept matrix's correction.
    saved: (State, State),
    saved_steps: (Vec<f64>, Vec<[f64; 6]>),
    /// The multipliers of the step before the current one, and the size of the last two steps
    /// when they were equal.
    lambda_prev: (Vec<f64>, Option<f64>),
    /// The multipliers of the step before that, and whether the last three steps were equal.
    lambda_prev2: (Vec<f64>, bool),
    last_h: Option<f64>,
    /// The algorithmic accelerations of the last steps, for the extrapolating predictors.
    history: history::History,
    /// Each entity's force scale in the last residual, under kept matrices ([`Norms::own`]).
    own_scale: Vec<f64>,
    /// Whether each step may keep the matrix (`newton = auto` decides step by step).
    reuse: Reuse,
    /// The constrained mass matrix's (the start), with pivoting, made on first use.
    mass_lu: Option<SparseLu>,
    /// `T^T J T` on the blocks: rotation unknowns with `H(c)` (conformal), or translation and
    /// rotation unknowns of each node with `R` (incremental, SE(3)).
    transform: Transform,
    blocks: Vec<usize>,
    /// Block matrices for the rows and the columns: `H(c)` or `R`.
    mats: Vec<M3>,
    /// Unknowns moved by the SE(3) node updates instead of Newmark on coordinates.
    in_frame: Vec<bool>,
    /// The revolute angles (flags, and the list): the rounding of `q_n + step` is kept in
    /// `State::carry` ([`newmark::advance`]).
    is_angle: Vec<bool>,
    angles: Vec<usize>,
    /// The unknowns that are not multipliers, and those of them not in a frame (the flat
    /// slots of the step's tangent, `tangent::flat`): listed once for its loops.
    coords: (Vec<usize>, Vec<usize>),
    /// The step's increment so far: of each coordinate (not in a frame), and of each node's
    /// frame (body-frame `(u, theta)`; rotation only for nodes that are not frames).
    step_q: Vec<f64>,
    step_frames: Vec<[f64; 6]>,
    /// Per rotating node, how its rates move with a correction beyond the scalar coefficients
    /// ([`se3::rate_maps`]).
    rate_maps: Vec<([f64; 36], [f64; 36])>,
    /// Per rotating node, the increment's inverse right Jacobian that the last matrix made,
    /// for the correction after it ([`se3::Jinv`]).
    jinv: Vec<se3::Jinv>,
    /// Each node's frame increment at constant velocities: the centre of [`TRUST`].
    predicted: Vec<[f64; 6]>,
    /// Whether the step's last Newton iteration headed for another root ([`TRUST`]).
    far: bool,
    /// The predictor a step tries first: the one that came nearer the last step's solution.
    predictor: Predictor,
    /// Every rotating node a frame (no beam nodes): `newton = full` may then keep a step's
    /// matrix after a small correction ([`Newton::quadratic`]). Beam models keep it only
    /// while their steps converge in [`SMOOTH`] iterations (`smooth`): the stiff-beam two-bar
    /// at the paper's step (11 iterations a step) is chaotic, and whether it runs its 50 s
    /// depends on the iteration path (with the matrix always kept it fails at 17 s, as
    /// without it at alpha -0.09 or -0.12).
    rigid: bool,
    /// The last step converged in at most [`SMOOTH`] Newton iterations.
    smooth: bool,
    /// Beam nodes' columns exact too (their rates' dependence on the correction,
    /// [`se3::rate_maps`]): for the step's tangent. Newton leaves them out (a linear
    /// contraction on beam models, measured to keep the stiff-beam two-bar on its motion).
    exact_rates: bool,
    /// The assembler holds the elements' `M` and `C` at the iterate
    /// ([`crate::runtime::Assembler::rate_jacobians`]): the matrix's rate columns take them.
    rates_held: bool,
    /// The matrix coefficients for which the next residual also makes the elements' tangent
    /// (the step's first, where a new matrix follows), and whether the assembler holds the
    /// tangent that way at the iterate (taken by the next matrix, cleared by other residuals).
    fused: (Option<TangentCoeffs>, bool),
    /// The last step took a correction (a steady state's predictor may need none).
    corrected: bool,
    /// The converged state at the current time.
    cur: State,
    /// The iterate of the step being solved.
    trial: State,
    rhs: Vec<f64>,
    /// The right-hand side kept while the constrained mass matrix is solved (FET solves it
    /// every step), to retry after [`StartMetric::widen`] without allocating.
    mass_rhs: Vec<f64>,
    /// Scaling used for the current step and for `cur.lambda`.
    aug: Augment,
    stats: RunStats,
    /// Index of the step being taken (for messages).
    step_index: usize,
    /// The rotating node of each transformed block.
    block_node: Vec<usize>,
    /// The constrained mass matrix of the start: plain, or with the stiffness on the massless
    /// motions that no joint holds ([`start_matrix`]).
    start: StartMetric,
    /// Directions of the state carried through every step by the step's tangent
    /// ([`tangent`]: Floquet's monodromy).
    tracked: Option<Box<tangent::Tracked>>,
}

/// Why a step attempt failed, before it is turned into a [`RuntimeFailure`].
/// The drift past which a redundant joint's dropped row stops the run (W0303: the joints were
/// redundant at the start but are not along the motion): this (m, or rad for an axis), or
/// 10^4 Newton tolerances if larger, times the model's length when over 1 m.
pub const DROPPED_DRIFT: f64 = 1e-6;

pub(super) struct StepFailure {
    kind: FailureKind,
    entity: Option<usize>,
    detail: String,
}

impl<'s> Integrator<'s> {
    pub fn new(sys: &'s System, set: &Settings) -> Result<Integrator<'s>, RuntimeFailure> {
        let asm = Assembler::new(sys);
        let setup = |detail: String| RuntimeFailure {
            kind: FailureKind::Singular,
            t: 0.0,
            step: 0,
            entity: None,
            detail,
        };
        let late: Vec<bool> = sys.unknowns.iter().map(|k| k.is_multiplier()).collect();
        let lu = SparseLu::pivot_free(&asm.pattern, &late);
        // FET integrates rotations incrementally (THEORY §8.1) whatever the treatment.
        let layout = match (set.method, set.rotations) {
            (Method::Fet, _) => Layout::Physical,
            (_, Rotations::Conformal) => Layout::Conformal,
            (_, Rotations::Incremental) => Layout::Increments,
        };
        let n = sys.len();
        // Transformed 3x3 blocks and the rotating node of each.
        let nodes = sys.rotations.len();
        let (blocks, block_node): (Vec<usize>, Vec<usize>) = if layout == Layout::Conformal {
            (sys.rotations.clone(), (0..nodes).collect())
        } else {
            (0..nodes)
                .filter(|&k| sys.is_frame(k))
                .map(|k| (sys.translations[k], k))
                .chain((0..nodes).map(|k| (sys.rotations[k], k)))
                .unzip()
        };
        let transform = Transform::new(n, &blocks, &asm.pattern).ok_or_else(|| {
            setup("internal: a rotating node's unknowns are not coupled as a block".into())
        })?;
        let mut in_frame = vec![false; n];
        if layout == Layout::Increments {
            for &f in &blocks {
                in_frame[f..f + 3].iter_mut().for_each(|x| *x = true);
            }
        }
        let coords: Vec<usize> = (0..n)
            .filter(|&i| !sys.unknowns[i].is_multiplier())
            .collect();
        let angles = sys.angle_unknowns();
        let mut is_angle = vec![false; n];
        angles.iter().for_each(|&a| is_angle[a] = true);
        let flat = coords.iter().copied().filter(|&i| !in_frame[i]).collect();
        let mut it = Integrator {
            sys,
            means: (sys.mean_mass(), sys.mean_stiffness()),
            set: set.clone(),
            sc: Scheme::of(set),
            method: set.method,
            layout,
            mid: sys.initial.clone(),
            end_res: Residual::new(n),
            asm,
            lu,
            kept: None,
            saved: (sys.initial.clone(), sys.initial.clone()),
            saved_steps: (vec![0.0; n], vec![[0.0; 6]; nodes]),
            reuse: Reuse::new(set.newton, set.method),
            lambda_prev: (vec![0.0; n], None),
            lambda_prev2: (vec![0.0; n], false),
            last_h: None,
            history: history::History::new(n, nodes, Scheme::of(set).ringing()),
            mass_lu: None,
            own_scale: vec![0.0; sys.owners.iter().max().map_or(0, |&o| o + 1)],
            transform,
            mats: vec![M3::identity(); blocks.len()],
            blocks,
            block_node,
            in_frame,
            is_angle,
            angles,
            coords: (coords, flat),
            step_q: vec![0.0; n],
            step_frames: vec![[0.0; 6]; nodes],
            rate_maps: vec![([0.0; 36], [0.0; 36]); nodes],
            jinv: vec![se3::Jinv::new(&[f64::NAN; 6]); nodes],
            predicted: vec![[0.0; 6]; nodes],
            far: false,
            predictor: Predictor::Acceleration,
            rigid: (0..nodes).all(|k| sys.is_frame(k)),
            smooth: false,
            exact_rates: false,
            rates_held: false,
            fused: (None, false),
            corrected: true,
            cur: sys.initial.clone(),
            trial: sys.initial.clone(),
            rhs: vec![0.0; n],
            mass_rhs: vec![0.0; n],
            aug: Augment {
                s: 1.0,
                p: 1.0,
                rate_scale: 1.0,
            },
            stats: RunStats::default(),
            step_index: 0,
            start: StartMetric::default(),
            tracked: None,
        };
        for st in [&mut it.cur, &mut it.trial] {
            st.carry.resize(n, 0.0);
        }
        it.aug = it.scaling(set.dt);
        Ok(it)
    }

    pub fn state(&self) -> &State {
        &self.cur
    }

    /// The steps of a run (the settings').
    pub fn steps(&self) -> usize {
        self.set.steps
    }

    pub fn settings(&self) -> &Settings {
        &self.set
    }

    /// Makes the next [`Integrator::run`] take `steps` steps of the run's size from the
    /// current state (partial Floquet runs a period in parts).
    pub fn set_run(&mut self, steps: usize) {
        self.set.steps = steps;
        self.set.until = self.cur.t + steps as f64 * self.set.dt;
    }

    /// Lengthens the run by `extra` steps of its size.
    pub fn extend_run(&mut self, extra: usize) {
        self.set.steps += extra;
        self.set.until += extra as f64 * self.set.dt;
    }

    pub fn augment(&self) -> Augment {
        self.aug
    }

    pub fn stats(&self) -> &RunStats {
        &self.stats
    }

    /// `s = p = m/(beta h^2) + k` (THEORY §6); rate rows scaled by `beta h / gamma`.
    fn scaling(&self, h: f64) -> Augment {
        let (mass, stiffness) = self.means;
        let inertia = mass / (self.sc.beta * h * h);
        let k = if self.method == Method::Static && stiffness > 0.0 {
            stiffness
        } else {
            inertia + stiffness
        };
        Augment {
            s: k,
            p: k,
            // FET: the constant velocity of the element moves by 1/h per unit correction.
            rate_scale: if self.method == Method::Fet {
                h
            } else {
                self.sc.beta * h / self.sc.gamma
            },
        }
    }

    fn ctol(&self) -> f64 {
        self.set.increment_tolerance * self.sys.length_scale
    }

    fn fail(&self, f: StepFailure) -> RuntimeFailure {
        RuntimeFailure {
            kind: f.kind,
            t: self.cur.t,
            step: self.step_index,
            entity: f.entity,
            detail: f.detail,
        }
    }

    /// How far a redundant joint's dropped row may drift ([`DROPPED_DRIFT`]).
    fn dropped_limit(&self) -> f64 {
        DROPPED_DRIFT.max(1e4 * self.set.increment_tolerance) * self.sys.length_scale.max(1.0)
    }

    fn is_mult(&self, i: usize) -> bool {
        self.sys.unknowns[i].is_multiplier()
    }

    fn singular(&self, e: LinearError) -> StepFailure {
        StepFailure {
            kind: FailureKind::Singular,
            entity: match e {
                LinearError::TinyPivot(i) => Some(self.sys.owners[i]),
                _ => None,
            },
            detail: format!("the iteration matrix could not be factored ({e:?}); a body may lack mass in some direction, or joints may be redundant"),
        }
    }

    fn check_finite(&self) -> Result<(), StepFailure> {
        let bad = self
            .cur
            .first_non_finite()
            .map(|i| self.sys.owners[i])
            .or_else(|| {
                self.cur
                    .first_non_finite_node()
                    .map(|k| self.sys.owners[self.sys.rotations[k]])
            });
        match bad {
            Some(e) => Err(StepFailure {
                kind: FailureKind::NonFinite,
                entity: Some(e),
                detail: "the state became NaN or infinite".to_string(),
            }),
            None => Ok(()),
        }
    }

    /// Integrates the settings' `steps` steps of `dt` from the current state, calling
    /// `each(k, self)` after step `k` (with the time set to `t0 + k dt`, free of accumulated
    /// round-off). Stops at a step that fails, or when `each` returns an error.
    pub fn run<E>(
        &mut self,
        mut each: impl FnMut(usize, &Self) -> Result<(), E>,
    ) -> Result<(), Stop<E>> {
        let (t0, dt) = (self.cur.t, self.set.dt);
        for k in 1..=self.set.steps {
            if super::interrupted() {
                return Err(Stop::Failed(RuntimeFailure {
                    kind: FailureKind::Interrupted,
                    t: self.cur.t,
                    step: k,
                    entity: None,
                    detail: format!("stopped before step {k} of {}", self.set.steps),
                }));
            }
            self.step(k, dt).map_err(Stop::Failed)?;
            self.cur.t = t0 + k as f64 * dt;
            each(k, self).map_err(Stop::Stopped)?;
        }
        Ok(())
    }

    /// Advances from the current state by `h` (halving the step on failure).
    fn step(&mut self, index: usize, h: f64) -> Result<(), RuntimeFailure> {
        self.step_index = index;
        self.advance(h, 0).map_err(|f| self.fail(f))?;
        self.stats.steps += 1;
        // Redundant joints (W0303): their dropped rows must have held; then the rows to drop
        // are chosen again at the new configuration (those the others span best: where the
        // kept ones grow dependent, as Bricard's linkage passes a special position, others
        // take over), and a kept matrix is made again when they change.
        if let Some((drift, entity)) = self.sys.dropped_violation(&self.cur) {
            if drift > self.dropped_limit() {
                return Err(self.fail(StepFailure {
                    kind: FailureKind::Inconsistent,
                    entity: Some(entity),
                    detail: format!("a redundant equation the run dropped drifted by {drift:.2e} (m, or rad for an axis): the joints are not redundant along the motion, the start was a singular position"),
                }));
            }
            let count = self
                .sys
                .initial
                .dropped
                .iter()
                .map(|m| m.count_ones() as usize)
                .sum();
            if let Some(masks) = self.sys.select_dropped(&self.cur, count) {
                if masks != self.cur.dropped {
                    for st in [&mut self.cur, &mut self.trial, &mut self.mid] {
                        st.dropped.clone_from(&masks);
                    }
                    self.kept = None;
                }
            }
        }
        Ok(())
    }

    fn advance(&mut self, h: f64, depth: usize) -> Result<(), StepFailure> {
        match self.attempt(h) {
            Ok(()) => self.propagate(h),
            Err(f) if depth >= self.set.max_halvings => Err(f),
            Err(_) => {
                self.stats.halvings += 1;
                self.last_h = None;
                self.kept = None;
                // Failure path only: keep a copy to restore if the halves fail too.
                let backup = (self.cur.clone(), self.aug);
                let result = self
                    .advance(h / 2.0, depth + 1)
                    .and_then(|_| self.advance(h / 2.0, depth + 1));
                match result {
                    Ok(()) => Ok(()),
                    Err(mut f) => {
                        (self.cur, self.aug) = backup;
                        if depth == 0 {
                            let levels = self.set.max_halvings;
                            f.detail.push_str(&if levels == 1 {
                                "; the step was retried at half of its size and failed again"
                                    .to_string()
                            } else {
                                format!(
                                    "; the step was retried in halves down to 1/{} of its size and failed again",
                                    1usize << levels
                                )
                            });
                        }
                        Err(f)
                    }
                }
            }
        }
    }

    /// A correction in `rhs` that turns some node by more than half a radian is outside the
    /// reach of the linearization (and can jump to a rotation increment on another branch of
    /// the logarithm): scales the whole correction down to that size.
    fn limit_turn(&mut self) {
        let mut turn = 0.0f64;
        for &r in &self.sys.rotations {
            let d = V3::new(self.rhs[r], self.rhs[r + 1], self.rhs[r + 2]);
            turn = turn.max(d.norm());
        }
        if turn > MAX_TURN {
            let f = MAX_TURN / turn;
            self.rhs.iter_mut().for_each(|x| *x *= f);
        }
    }

    /// The residual at the iterate by the method, and its norms.
    fn residual(
        &mut self,
        fet: bool,
        h: f64,
        aug: Augment,
        floor: f64,
    ) -> Result<Norms, StepFailure> {
        if fet {
            self.fet_residual(h, aug, floor)
        } else {
            self.newmark_residual(aug, floor)
        }
    }

    /// The iteration matrix at the iterate, factored; kept for steps of `h` when the settings
    /// allow.
    fn refactor(&mut self, h: f64, aug: Augment, fet: bool) -> Result<(), StepFailure> {
        self.kept = None;
        if fet {
            self.fet_matrix(h, aug);
        } else {
            self.newmark_matrix(h, aug);
        }
        self.lu
            .factor(&self.asm.values)
            .map_err(|e| self.singular(e))?;
        self.stats.factorizations += 1;
        if self.reuse.mode() != NewtonMode::Full {
            self.kept = Some(h);
        }
        Ok(())
    }

    /// The step's end: the counts, and the converged iterate made current.
    fn converge(&mut self, it: usize, cnorm: f64, aug: Augment, h: f64) -> Result<(), StepFailure> {
        self.stats.newton_iterations += it;
        self.smooth = it <= SMOOTH;
        (self.corrected, self.fused) = (it > 0, (None, false));
        self.stats.max_constraint_violation = self.stats.max_constraint_violation.max(cnorm);
        self.aug = aug;
        std::mem::swap(&mut self.lambda_prev.0, &mut self.lambda_prev2.0);
        self.lambda_prev2.1 = self.lambda_prev.1 == Some(h) && self.last_h == Some(h);
        self.lambda_prev.0.copy_from_slice(&self.cur.lambda);
        self.lambda_prev.1 = (self.last_h == Some(h)).then_some(h);
        let continued = self.last_h == Some(h);
        self.last_h = Some(h);
        if self.method == Method::Fet {
            self.fet_commit(h)
        } else {
            // A predictor that ended the step at its first correction stays.
            if self.method != Method::Static && it > 1 {
                self.predictor = self.best_predictor(h);
            }
            if self.method != Method::Static && self.extrapolates() {
                self.history.push(&self.cur, h, continued);
            }
            self.newmark_commit()
        }
    }
}
