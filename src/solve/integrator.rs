//! HHT-alpha and generalized-alpha for the index-3 DAE with the scaled augmented Lagrangian
//! (THEORY §6, §7).
//!
//! Both in the Arnold-Bruls form: the balance `F^I + F^int + F^c - F^ext = 0` and `s C = 0`
//! at `t_{n+1}`, with Newmark relations on algorithmic accelerations `A`,
//! `(1 - a_m) A_{n+1} + a_m A_n = (1 - a_f) a_{n+1} + a_f a_n`.
//! HHT: `a_m = 0`, `a_f = -alpha`, `beta = (1 - alpha)^2 / 4`, `gamma = 1/2 - alpha`: the same
//! amplification as THEORY §7.2's force-weighted form on linear problems (spectral radius at
//! infinity `(1 + alpha)/(1 - alpha)`), and second order with configuration-dependent inertia,
//! where the force-weighted form with `F^I` at `t_{n+1}` was measured first order (a free
//! rigid body with an offset centre of mass). Generalized-alpha: `a_m`, `a_f`, `beta`, `gamma`
//! from `rho_inf` (THEORY §7.5).
//!
//! Rotations: with the incremental treatment each rotating node is an SE(3) frame updated by
//! body-frame increments ([`super::se3`]); with the conformal treatment the rotation unknowns
//! hold `c`, `c-dot`, `c-ddot` like any coordinate ([`super::rotations`]).

#[path = "fet.rs"]
mod fet;

use super::linear::{LinearError, SparseLu};
use super::newton::Newton;
use super::rotations::{self, Transform};
use super::se3;
use super::start::StartMetric;
use super::{
    FailureKind, Method, Notice, NoticeKind, RotationTreatment, RunStats, RuntimeFailure, Settings,
    StartMode,
};
use crate::runtime::rotation::{self as rot, M3, V3};
use crate::runtime::{
    Assembler, Augment, Rate, Residual, State, System, TangentCoeffs, UnknownKind,
};

/// The scheme's constants.
#[derive(Clone, Copy, Debug)]
struct Scheme {
    am: f64,
    af: f64,
    beta: f64,
    gamma: f64,
    /// Static analysis: no inertia, no rates; steps are load steps.
    stat: bool,
}

impl Scheme {
    fn of(set: &Settings) -> Scheme {
        match set.method {
            Method::GeneralizedAlpha => {
                let r = set.rho_inf;
                let am = (2.0 * r - 1.0) / (r + 1.0);
                let af = r / (r + 1.0);
                Scheme {
                    am,
                    af,
                    gamma: 0.5 - am + af,
                    beta: 0.25 * (1.0 - am + af).powi(2),
                    stat: false,
                }
            }
            // Time finite elements: the trapezoidal constants size the constraint scaling
            // (`s = 4 m / h^2 + k`) and the start.
            Method::Fet => Scheme {
                am: 0.0,
                af: 0.0,
                beta: 0.25,
                gamma: 0.5,
                stat: false,
            },
            // HHT in the Arnold-Bruls form: equations at t_{n+1}, a_m = 0, a_f = -alpha. Same
            // linear amplification as the force-weighted form, and second order with
            // configuration-dependent inertia (the weighted form is first order there).
            _ => Scheme {
                am: 0.0,
                af: -set.alpha,
                beta: (1.0 - set.alpha).powi(2) / 4.0,
                gamma: 0.5 - set.alpha,
                stat: set.method == Method::Static,
            },
        }
    }

    /// `d a_{n+1} / d q_{n+1}`.
    fn mass_coefficient(&self, h: f64) -> f64 {
        (1.0 - self.am) / ((1.0 - self.af) * self.beta * h * h)
    }
}

/// Largest rotation of a node in one Newton correction (rad).
const MAX_TURN: f64 = 0.5;

pub struct Integrator<'s> {
    sys: &'s System,
    set: Settings,
    sc: Scheme,
    conformal: bool,
    /// Time finite elements (THEORY §8) instead of the Newmark family: the state is kept in
    /// the physical layout, `alg` holds the nodal momenta `P`.
    fet: bool,
    /// FET: the mid-configuration of the step (constant velocities, the multipliers).
    mid: State,
    /// FET: the joints' residual at the end configuration.
    end_res: Residual,
    asm: Assembler,
    lu: SparseLu,
    /// `T^T J T` on the blocks: rotation unknowns with `H(c)` (conformal), or translation and
    /// rotation unknowns of each node with `R` (incremental, SE(3)).
    transform: Transform,
    blocks: Vec<usize>,
    /// Block matrices for the rows (`H(c)` or `R`) and for the columns (`H(c)`, or
    /// `R J_r^-1(increment)`, which accounts for the increment's dependence on the correction).
    mats: Vec<M3>,
    cols: Vec<M3>,
    /// Unknowns moved by the SE(3) node updates instead of Newmark on coordinates.
    in_frame: Vec<bool>,
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
    /// motions that no joint holds ([`super::start`]).
    start: StartMetric,
}

/// Why a step attempt failed, before it is turned into a [`RuntimeFailure`].
struct StepFailure {
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
        let lu = SparseLu::new(&asm.pattern)
            .map_err(|e| setup(format!("the sparse LU could not be set up ({e:?})")))?;
        let fet = set.method == Method::Fet;
        // FET integrates rotations incrementally (THEORY §8.1) whatever the treatment.
        let conformal = set.rotation == RotationTreatment::Conformal && !fet;
        let n = sys.len();
        // Transformed 3x3 blocks and the rotating node of each.
        let nodes = sys.rotations.len();
        let (blocks, block_node): (Vec<usize>, Vec<usize>) = if conformal {
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
        if !conformal && !fet {
            for &f in &blocks {
                in_frame[f..f + 3].iter_mut().for_each(|x| *x = true);
            }
        }
        let mut it = Integrator {
            sys,
            set: set.clone(),
            sc: Scheme::of(set),
            conformal,
            fet,
            mid: sys.initial.clone(),
            end_res: Residual::new(n),
            asm,
            lu,
            transform,
            mats: vec![M3::identity(); blocks.len()],
            cols: vec![M3::identity(); blocks.len()],
            blocks,
            block_node,
            in_frame,
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
        };
        it.aug = it.scaling(set.dt);
        Ok(it)
    }

    pub fn state(&self) -> &State {
        &self.cur
    }

    /// Sets the current time (to remove round-off accumulated over many steps).
    pub fn set_time(&mut self, t: f64) {
        self.cur.t = t;
    }

    pub fn augment(&self) -> Augment {
        self.aug
    }

    pub fn stats(&self) -> &RunStats {
        &self.stats
    }

    /// `s = p = m/(beta h^2) + k` (THEORY §6); rate rows scaled by `beta h / gamma`.
    fn scaling(&self, h: f64) -> Augment {
        let inertia = self.sys.mean_mass() / (self.sc.beta * h * h);
        let k = if self.sc.stat && self.sys.mean_stiffness() > 0.0 {
            self.sys.mean_stiffness()
        } else {
            inertia + self.sys.mean_stiffness()
        };
        Augment {
            s: k,
            p: k,
            // FET: the constant velocity of the element moves by 1/h per unit correction.
            rate_scale: if self.fet {
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

    fn is_mult(&self, i: usize) -> bool {
        self.sys.unknowns[i].is_multiplier()
    }

    /// Solves `[M, s B^T; s B, 0] x = rhs` at `trial` (the constrained mass matrix, in the
    /// physical layout: virtual rotations).
    fn solve_constrained_mass(&mut self, rhs_and_x: &mut [f64]) -> Result<(), StepFailure> {
        self.mass_rhs.copy_from_slice(rhs_and_x);
        loop {
            self.start
                .assemble(&mut self.asm, self.sys, &self.trial, self.aug);
            let solved = match self.lu.factor(&self.asm.values) {
                Ok(()) => self.lu.solve(rhs_and_x),
                Err(e) => Err(e),
            };
            match solved {
                Ok(()) => return Ok(()),
                // A rigid body's massless motion held by a spring alone: regularize it too.
                Err(_) if self.start.widen() => rhs_and_x.copy_from_slice(&self.mass_rhs),
                Err(e) => return Err(self.singular(e)),
            }
        }
    }

    /// The smallest mass-weighted correction of the coordinates that cancels `g` (the
    /// constraint values at multiplier rows) to first order:
    /// `[M, s B^T; s B, 0] [dx; nu] = [0; -s g]`. Multiplier entries of the result are zero.
    fn constraint_correction(&mut self, g: &[f64]) -> Result<Vec<f64>, StepFailure> {
        let s = self.aug.s;
        let mut x: Vec<f64> = (0..self.sys.len())
            .map(|i| if self.is_mult(i) { -s * g[i] } else { 0.0 })
            .collect();
        self.solve_constrained_mass(&mut x)?;
        for (i, xi) in x.iter_mut().enumerate() {
            if self.is_mult(i) {
                *xi = 0.0;
            }
        }
        Ok(x)
    }

    fn singular(&self, e: LinearError) -> StepFailure {
        StepFailure {
            kind: FailureKind::Singular,
            entity: None,
            detail: format!("the iteration matrix could not be factored ({e:?}); a body may lack mass in some direction, or joints may be redundant"),
        }
    }

    /// The largest entry of `g` at (position-level, or all) multiplier rows and its owner.
    fn largest(&self, g: &[f64], rate_rows: bool) -> (f64, Option<usize>) {
        let mut worst = (0.0, None);
        for (i, k) in self.sys.unknowns.iter().enumerate() {
            let take = match k {
                UnknownKind::Multiplier => true,
                UnknownKind::RateMultiplier => rate_rows,
                _ => false,
            };
            if take && (g[i].abs() > worst.0 || worst.1.is_none()) {
                worst = (g[i].abs().max(worst.0), Some(self.sys.owners[i]));
            }
        }
        worst
    }

    /// Applies a correction of the coordinates in the physical layout (rotations by
    /// `R <- exp(dtheta~) R`), to positions (`level` 0), velocities (1) or accelerations (2).
    fn apply_physical(&mut self, dx: &[f64], level: usize) {
        let tr = &mut self.trial;
        for (i, k) in self.sys.unknowns.iter().enumerate() {
            match k {
                UnknownKind::Coordinate => match level {
                    0 => tr.q[i] += dx[i],
                    1 => tr.v[i] += dx[i],
                    _ => tr.a[i] += dx[i],
                },
                UnknownKind::Rotation { node, axis } => match level {
                    0 => {
                        if *axis == 0 {
                            let d = V3::new(dx[i], dx[i + 1], dx[i + 2]);
                            let r = rot::exp(&d) * tr.rot[*node].matrix();
                            tr.rot[*node].set_matrix(&rot::orthonormalize(&r));
                        }
                    }
                    1 => {
                        tr.v[i] += dx[i];
                        tr.rot[*node].w[*axis] = tr.v[i];
                    }
                    _ => {
                        tr.a[i] += dx[i];
                        tr.rot[*node].dw[*axis] = tr.a[i];
                    }
                },
                _ => {}
            }
        }
    }

    /// Starts over from `initial` (a state in the physical layout, like `System::initial`)
    /// at its time, keeping the symbolic factorization, then initializes as [`Self::initialize`]
    /// does. Floquet analysis starts its perturbed runs this way.
    pub fn restart(&mut self, initial: &State) -> Result<Vec<Notice>, RuntimeFailure> {
        self.cur.clone_from(initial);
        self.trial.clone_from(initial);
        self.mid.clone_from(initial);
        self.stats = RunStats::default();
        self.step_index = 0;
        self.aug = self.scaling(self.set.dt);
        self.initialize()
    }

    /// Makes the initial state consistent: positions and velocities onto the constraints,
    /// then accelerations and multipliers (consistent start) or zeros (the paper's start).
    pub fn initialize(&mut self) -> Result<Vec<Notice>, RuntimeFailure> {
        self.initialize_inner().map_err(|f| self.fail(f))
    }

    fn initialize_inner(&mut self) -> Result<Vec<Notice>, StepFailure> {
        let mut notices = Vec::new();
        let n = self.sys.len();
        let s = self.aug.s;
        self.trial = self.cur.clone();
        // Physical layout: rotation slots of v and a hold omega and omega-dot.
        for (i, k) in self.sys.unknowns.iter().enumerate() {
            if let UnknownKind::Rotation { node, axis } = k {
                self.trial.q[i] = 0.0;
                self.trial.v[i] = self.trial.rot[*node].w[*axis];
                self.trial.a[i] = self.trial.rot[*node].dw[*axis];
            }
        }
        // Multipliers are solved below; stale ones would enter the matrix's stiffness.
        self.trial.lambda.iter_mut().for_each(|x| *x = 0.0);
        // Motions without inertia that no joint holds get their stiffness in the start.
        self.start = StartMetric::find(
            &mut self.asm,
            self.sys,
            &self.trial,
            self.aug,
            self.sc.beta * self.set.dt * self.set.dt,
        );
        // Positions: minimum mass-weighted correction, iterated (Gauss-Newton).
        let mut moved = None;
        for _ in 0..50 {
            self.asm.residual(self.sys, &self.trial, self.aug);
            let g = self.asm.residual.constraint.clone();
            let (worst, who) = self.largest(&g, false);
            if worst <= self.ctol() {
                break;
            }
            moved.get_or_insert((worst, who));
            let mut g = g;
            for (i, k) in self.sys.unknowns.iter().enumerate() {
                if *k == UnknownKind::RateMultiplier {
                    g[i] = 0.0;
                }
            }
            let dq = self.constraint_correction(&g)?;
            self.apply_physical(&dq, 0);
        }
        self.asm.residual(self.sys, &self.trial, self.aug);
        let (worst, who) = self.largest(&self.asm.residual.constraint.clone(), false);
        if worst > self.ctol() {
            return Err(StepFailure {
                kind: FailureKind::NewtonDiverged,
                entity: who,
                detail: format!("the initial positions could not be brought onto the joints (violation {worst:.3e} m)"),
            });
        }
        if let Some((worst, who)) = moved {
            notices.push(Notice {
                kind: NoticeKind::PositionProjected,
                entity: who,
                detail: format!("initial positions violated the joints by up to {worst:.3e} m and were projected onto them"),
            });
        }
        if self.sc.stat {
            // Statics: no rates; multipliers come with the first load step.
            let tr = &mut self.trial;
            for x in
                tr.v.iter_mut()
                    .chain(tr.a.iter_mut())
                    .chain(tr.lambda.iter_mut())
            {
                *x = 0.0;
            }
            for r in tr.rot.iter_mut() {
                (r.w, r.dw) = ([0.0; 3], [0.0; 3]);
            }
            return self.finish_initialization(notices);
        }
        // Revolute angle rates: the measured relative rates (they carry no mass, so only the
        // bodies' velocities decide whether the start is consistent).
        self.asm
            .constraint_rate(self.sys, &self.trial, Rate::Velocity);
        for (row, angle) in self.sys.angle_rows() {
            self.trial.v[angle] += self.asm.residual.constraint[row];
        }
        // Velocities: project onto B v + dC/dt = 0 in the mass metric (the impulsive response).
        self.asm
            .constraint_rate(self.sys, &self.trial, Rate::Velocity);
        let g = self.asm.residual.constraint.clone();
        let vmax = self.trial.v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let vtol = self.set.increment_tolerance
            * vmax.max(self.sys.length_scale / (self.set.dt * self.set.steps as f64));
        let (worst, who) = self.largest(&g, true);
        if worst > vtol {
            let dv = self.constraint_correction(&g)?;
            self.apply_physical(&dv, 1);
            notices.push(Notice {
                kind: NoticeKind::VelocityProjected,
                entity: who,
                detail: format!("initial velocities violated the joints by up to {worst:.3e} m/s and were projected onto them"),
            });
        }
        // Accelerations and multipliers.
        let zero: Vec<f64> = self.trial.a.iter().map(|a| -a).collect();
        self.apply_physical(&zero, 2);
        self.trial.lambda.iter_mut().for_each(|x| *x = 0.0);
        if self.set.start == StartMode::Consistent {
            self.asm.residual(self.sys, &self.trial, self.aug);
            let mut x = vec![0.0; n];
            for (i, xi) in x.iter_mut().enumerate() {
                if !self.is_mult(i) {
                    *xi = -(self.asm.residual.inertia[i] + self.asm.residual.force[i]);
                }
            }
            self.asm
                .constraint_rate(self.sys, &self.trial, Rate::AccelerationBias);
            for (i, xi) in x.iter_mut().enumerate() {
                if self.is_mult(i) {
                    *xi = -s * self.asm.residual.constraint[i];
                }
            }
            self.solve_constrained_mass(&mut x)?;
            let mut acc = x.clone();
            for (i, a) in acc.iter_mut().enumerate() {
                if self.is_mult(i) {
                    self.trial.lambda[i] = x[i];
                    *a = 0.0;
                }
            }
            self.apply_physical(&acc, 2);
        }
        self.finish_initialization(notices)
    }

    /// From the physical layout to the treatment's, and the initial state becomes current.
    fn finish_initialization(&mut self, notices: Vec<Notice>) -> Result<Vec<Notice>, StepFailure> {
        if self.fet {
            // The nodal momenta P_0 = M(q_0) V_0.
            self.asm.momentum(self.sys, &self.trial);
            for (i, x) in self.trial.alg.iter_mut().enumerate() {
                *x = if self.sys.unknowns[i].is_multiplier() {
                    0.0
                } else {
                    self.asm.momentum[i]
                };
            }
        } else if self.conformal {
            self.trial.alg.clone_from(&self.trial.a);
            rotations::to_conformal(self.sys, &mut self.trial);
        } else {
            self.trial.alg.clone_from(&self.trial.a);
            se3::to_frames(self.sys, &mut self.trial);
        }
        std::mem::swap(&mut self.cur, &mut self.trial);
        self.check_finite()?;
        Ok(notices)
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

    /// Advances from the current state by `h` (halving the step on failure).
    pub fn step(&mut self, index: usize, h: f64) -> Result<(), RuntimeFailure> {
        self.step_index = index;
        self.advance(h, 0).map_err(|f| self.fail(f))?;
        self.stats.steps += 1;
        Ok(())
    }

    fn advance(&mut self, h: f64, depth: usize) -> Result<(), StepFailure> {
        match self.attempt(h) {
            Ok(()) => Ok(()),
            Err(f) if depth >= self.set.max_halvings => Err(f),
            Err(_) => {
                self.stats.halvings += 1;
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

    /// The transform's block matrices at the iterate: `H(c)` (conformal) or `R` for the
    /// translation and rotation blocks of each node (SE(3)).
    fn block_matrices(&mut self) {
        let nodes = self.sys.rotations.len();
        if self.conformal {
            rotations::tangents(self.sys, &self.trial, &mut self.mats);
            self.cols.copy_from_slice(&self.mats);
        } else {
            // Rotation blocks come last, one per node in order.
            let first = self.blocks.len() - nodes;
            for k in 0..nodes {
                let r = self.trial.rot[k].matrix();
                self.mats[first + k] = r;
                let th = rot::log(&(self.cur.rot[k].matrix().transpose() * r));
                // The correction moves R by exactly R d, and the step increment by
                // J_r^-1(th) d, on which the Newmark rates depend: R J_r^-1 is exact for the
                // inertial terms, R for the configuration terms. Beam nodes take R (their
                // elastic stiffness dominates, and would leak through an O(th) error from stiff
                // to soft directions), frames R J_r^-1 (their tangent is all inertia; the
                // constraint columns then carry an O(th) error and Newton converges linearly at
                // a rate near omega h / 2: the exact SE(3) columns, on branch
                // `exact-se3-newton`, halve the iterations but lose Newton in the violent
                // motion of P3 after 15 s at dt = 0.05).
                self.cols[first + k] = if self.sys.is_frame(k) && !self.sc.stat {
                    r * rot::left_jacobian_inverse(&-th)
                } else {
                    r
                };
            }
            for b in 0..first {
                let k = self.block_node[b];
                self.mats[b] = self.mats[first + k];
                self.cols[b] = self.cols[first + k];
            }
        }
    }

    /// Updates velocities and accelerations of the iterate from its positions (Newmark).
    fn newmark(&mut self, h: f64) {
        if self.sc.stat {
            let tr = &mut self.trial;
            for i in 0..self.sys.len() {
                if !self.sys.unknowns[i].is_multiplier() {
                    (tr.v[i], tr.a[i], tr.alg[i]) = (0.0, 0.0, 0.0);
                }
            }
            if self.conformal {
                rotations::sync(self.sys, tr);
            }
            for k in 0..self.sys.rotations.len() {
                tr.frames[k] = Default::default();
                (tr.rot[k].w, tr.rot[k].dw) = ([0.0; 3], [0.0; 3]);
            }
            return;
        }
        let Scheme {
            am,
            af,
            beta,
            gamma,
            ..
        } = self.sc;
        // (increment, previous rate, previous acceleration, previous algorithmic acceleration)
        // -> (rate, acceleration, algorithmic acceleration).
        let relation = |dq: f64, v: f64, a: f64, alg0: f64| {
            let alg = (dq - h * v - h * h * (0.5 - beta) * alg0) / (beta * h * h);
            (
                v + h * ((1.0 - gamma) * alg0 + gamma * alg),
                ((1.0 - am) * alg + am * alg0 - af * a) / (1.0 - af),
                alg,
            )
        };
        let (cur, tr) = (&self.cur, &mut self.trial);
        for i in 0..self.sys.len() {
            if self.in_frame[i] || self.sys.unknowns[i].is_multiplier() {
                continue;
            }
            let (v, a, alg) = relation(tr.q[i] - cur.q[i], cur.v[i], cur.a[i], cur.alg[i]);
            (tr.v[i], tr.a[i], tr.alg[i]) = (v, a, alg);
        }
        if self.conformal {
            rotations::sync(self.sys, tr);
            return;
        }
        for k in 0..self.sys.rotations.len() {
            let d = se3::increment(self.sys, cur, tr, k);
            let f0 = cur.frames[k];
            let f = &mut tr.frames[k];
            for j in 0..6 {
                (f.v[j], f.dv[j], f.alg[j]) = relation(d[j], f0.v[j], f0.dv[j], f0.alg[j]);
            }
            se3::to_physical(self.sys, tr, k);
        }
    }

    /// One step of size `h` from `cur`; on success `cur` holds the new state.
    fn attempt(&mut self, h: f64) -> Result<(), StepFailure> {
        if self.fet {
            return self.attempt_fet(h);
        }
        let sc = self.sc;
        let aug = self.scaling(h);
        let rescale = self.aug.s / aug.s;
        let n = self.sys.len();
        // Predictor: the acceleration a_{n+1} = a_n.
        {
            let (cur, tr) = (&self.cur, &mut self.trial);
            tr.t = cur.t + h;
            // Statics: the previous load step's equilibrium.
            let step = |v: f64, a: f64, alg0: f64| {
                let alg = (a - sc.am * alg0) / (1.0 - sc.am);
                if sc.stat {
                    0.0
                } else {
                    h * v + h * h * ((0.5 - sc.beta) * alg0 + sc.beta * alg)
                }
            };
            for i in 0..n {
                if self.sys.unknowns[i].is_multiplier() {
                    tr.lambda[i] = cur.lambda[i] * rescale;
                } else {
                    tr.lambda[i] = 0.0;
                    if !self.in_frame[i] {
                        tr.q[i] = cur.q[i] + step(cur.v[i], cur.a[i], cur.alg[i]);
                    }
                }
            }
            if !self.conformal {
                for k in 0..self.sys.rotations.len() {
                    let f = cur.frames[k];
                    let d: [f64; 6] = std::array::from_fn(|j| step(f.v[j], f.dv[j], f.alg[j]));
                    se3::displace(self.sys, cur, tr, k, &d);
                }
            }
        }
        self.newmark(h);
        let coeffs = if sc.stat {
            TangentCoeffs {
                mass: 0.0,
                velocity: 0.0,
                position: 1.0,
                force_weight: 1.0,
            }
        } else {
            TangentCoeffs {
                mass: sc.mass_coefficient(h),
                velocity: sc.gamma / (sc.beta * h),
                position: 1.0,
                force_weight: 1.0,
            }
        };
        let mut newton = Newton::new(&self.set, self.sys);
        for it in 0..=self.set.max_iterations {
            self.asm.residual(self.sys, &self.trial, aug);
            self.block_matrices();
            let r = &self.asm.residual;
            let (mut scale, mut cnorm) = (newton.floor, 0.0f64);
            for i in 0..n {
                if self.sys.unknowns[i].is_multiplier() {
                    cnorm = cnorm.max(r.constraint[i].abs());
                    self.rhs[i] = -aug.s * r.constraint[i];
                } else {
                    scale = scale.max(r.inertia[i].abs()).max(r.force[i].abs());
                    self.rhs[i] = -(r.inertia[i] + r.force[i]);
                }
            }
            rotations::transform_vector(&self.blocks, &self.mats, &mut self.rhs);
            let (mut rnorm, mut worst) = (0.0f64, (0.0f64, 0usize));
            for i in 0..n {
                let ri = self.rhs[i];
                if !ri.is_finite() {
                    return Err(StepFailure {
                        kind: FailureKind::NonFinite,
                        entity: Some(self.sys.owners[i]),
                        detail: "the residual became NaN or infinite".to_string(),
                    });
                }
                let size = if self.sys.unknowns[i].is_multiplier() {
                    ri.abs() / aug.s
                } else {
                    rnorm = rnorm.max(ri.abs());
                    ri.abs()
                };
                if size > worst.0 {
                    worst = (size, i);
                }
            }
            if newton.converged(rnorm, scale, cnorm) {
                self.stats.newton_iterations += it;
                self.stats.max_constraint_violation =
                    self.stats.max_constraint_violation.max(cnorm);
                self.aug = aug;
                std::mem::swap(&mut self.cur, &mut self.trial);
                if self.conformal {
                    self.stats.rescalings += rotations::rescale(self.sys, &mut self.cur);
                    rotations::sync(self.sys, &mut self.cur);
                } else {
                    for k in 0..self.sys.rotations.len() {
                        let r = rot::orthonormalize(&self.cur.rot[k].matrix());
                        self.cur.rot[k].set_matrix(&r);
                    }
                }
                self.check_finite()?;
                return Ok(());
            }
            let max = self.set.max_iterations;
            let total = rnorm + aug.s * cnorm;
            if let Some(detail) = newton.check(it, max, total, (rnorm, scale, cnorm), "") {
                return Err(StepFailure {
                    kind: FailureKind::NewtonDiverged,
                    entity: Some(self.sys.owners[worst.1]),
                    detail,
                });
            }
            self.asm.tangent(self.sys, &self.trial, aug, coeffs);
            self.transform.apply(
                &self.asm.pattern,
                &mut self.asm.values,
                &self.mats,
                &self.cols,
            );
            self.lu
                .factor(&self.asm.values)
                .map_err(|e| self.singular(e))?;
            self.lu.solve(&mut self.rhs).map_err(|e| self.singular(e))?;
            if !self.conformal {
                self.limit_turn();
            }
            let mut dmax = 0.0f64;
            let tr = &mut self.trial;
            for i in 0..n {
                let d = self.rhs[i];
                match self.sys.unknowns[i] {
                    UnknownKind::Multiplier | UnknownKind::RateMultiplier => tr.lambda[i] += d,
                    UnknownKind::Rotation { .. } => {
                        dmax = dmax.max(d.abs());
                        if self.conformal {
                            tr.q[i] += d;
                        }
                    }
                    UnknownKind::Coordinate => {
                        dmax = dmax.max(d.abs() / self.sys.length_scale);
                        if !self.in_frame[i] {
                            tr.q[i] += d;
                        }
                    }
                }
            }
            if !self.conformal {
                for (k, (&t, &r)) in self
                    .sys
                    .translations
                    .iter()
                    .zip(&self.sys.rotations)
                    .enumerate()
                {
                    let rhs = &self.rhs;
                    let d = [
                        rhs[t],
                        rhs[t + 1],
                        rhs[t + 2],
                        rhs[r],
                        rhs[r + 1],
                        rhs[r + 2],
                    ];
                    se3::displace_in_place(self.sys, tr, k, &d);
                }
            }
            self.newmark(h);
            newton.record(dmax);
        }
        Err(StepFailure {
            kind: FailureKind::NewtonDiverged,
            entity: None,
            detail: "Newton did not converge".to_string(),
        })
    }
}

/// The linearized equations at the current state, dense, over the non-multiplier unknowns
/// (physical layout: virtual rotations): `M x'' + G x' + K x = 0` subject to `B x = 0`.
pub struct Linearization {
    /// The non-multiplier unknowns, in order.
    pub unknowns: Vec<usize>,
    pub m: Vec<f64>,
    pub g: Vec<f64>,
    pub k: Vec<f64>,
    /// Constraint rows (one per multiplier), row-major over `unknowns`.
    pub b: Vec<f64>,
    pub rows: usize,
}

impl Integrator<'_> {
    /// The element matrices at the current state (after `initialize`): mass, gyroscopic and
    /// damping, stiffness (elastic, inertial, and the constraint forces' geometric stiffness),
    /// and the constraint gradient (rate rows included: a driven coordinate is not perturbed).
    pub fn linearize(&mut self) -> Linearization {
        let n = self.sys.len();
        let free: Vec<usize> = (0..n).filter(|&i| !self.is_mult(i)).collect();
        let mults: Vec<usize> = (0..n).filter(|&i| self.is_mult(i)).collect();
        let mut col = vec![usize::MAX; n];
        for (j, &i) in free.iter().enumerate() {
            col[i] = j;
        }
        let nf = free.len();
        let aug = self.aug;
        let st = self.cur.clone();
        let mut dense = |c: TangentCoeffs, rows: &[usize]| -> Vec<f64> {
            self.asm.tangent(self.sys, &st, aug, c);
            let p = &self.asm.pattern;
            let mut out = vec![0.0; rows.len() * nf];
            let mut row_of = vec![usize::MAX; n];
            for (r, &i) in rows.iter().enumerate() {
                row_of[i] = r;
            }
            for j in 0..n {
                if col[j] == usize::MAX {
                    continue;
                }
                for s in p.col_ptr[j]..p.col_ptr[j + 1] {
                    let i = p.row_idx[s];
                    if row_of[i] != usize::MAX {
                        out[row_of[i] * nf + col[j]] = self.asm.values[s];
                    }
                }
            }
            out
        };
        let coeffs = |mass: f64, velocity: f64, position: f64| TangentCoeffs {
            mass,
            velocity,
            position,
            force_weight: 1.0,
        };
        let m = dense(coeffs(1.0, 0.0, 0.0), &free);
        let g = dense(coeffs(0.0, 1.0, 0.0), &free);
        let k = dense(coeffs(0.0, 0.0, 1.0), &free);
        let mut b = dense(coeffs(0.0, 1.0, 0.0), &mults);
        b.iter_mut().for_each(|x| *x /= aug.s);
        Linearization {
            unknowns: free,
            m,
            g,
            k,
            b,
            rows: mults.len(),
        }
    }
}
