//! HHT-alpha for the index-3 DAE with the scaled augmented Lagrangian (THEORY §6, §7).
//!
//! Unknowns per Newton iteration: position increments of the coordinates and multiplier
//! increments. Residual (coordinates):
//! `F^I_{n+1} + (1+alpha) F_{n+1} - alpha F_n = 0`, `F = F^int + F^c - F^ext`;
//! (multipliers) `s C(q_{n+1}) = 0`. Newmark relations with `beta = (1-alpha)^2/4`,
//! `gamma = 1/2 - alpha`.

use super::linear::{LinearError, SparseLu};
use super::{FailureKind, Notice, NoticeKind, RunStats, RuntimeFailure, Settings, StartMode};
use crate::runtime::{Assembler, Augment, Rate, State, System, TangentCoeffs, UnknownKind};

pub struct Hht<'s> {
    sys: &'s System,
    set: Settings,
    beta: f64,
    gamma: f64,
    asm: Assembler,
    lu: SparseLu,
    /// The converged state at the current time.
    cur: State,
    /// The iterate of the step being solved.
    trial: State,
    /// `F^int + F^c - F^ext` at `cur`.
    force_n: Vec<f64>,
    rhs: Vec<f64>,
    /// Scaling used for the current step and for `cur.lambda`.
    aug: Augment,
    stats: RunStats,
    /// Index of the step being taken (for messages).
    step_index: usize,
}

/// Why a step attempt failed, before it is turned into a [`RuntimeFailure`].
struct StepFailure {
    kind: FailureKind,
    entity: Option<usize>,
    detail: String,
}

impl<'s> Hht<'s> {
    pub fn new(sys: &'s System, set: &Settings) -> Result<Hht<'s>, RuntimeFailure> {
        let asm = Assembler::new(sys);
        let lu = SparseLu::new(&asm.pattern).map_err(|e| RuntimeFailure {
            kind: FailureKind::Singular,
            t: 0.0,
            step: 0,
            entity: None,
            detail: format!("the sparse LU could not be set up ({e:?})"),
        })?;
        let alpha = set.alpha;
        let n = sys.len();
        let mut hht = Hht {
            sys,
            set: set.clone(),
            beta: (1.0 - alpha) * (1.0 - alpha) / 4.0,
            gamma: 0.5 - alpha,
            asm,
            lu,
            cur: sys.initial.clone(),
            trial: sys.initial.clone(),
            force_n: vec![0.0; n],
            rhs: vec![0.0; n],
            aug: Augment { s: 1.0, p: 1.0 },
            stats: RunStats::default(),
            step_index: 0,
        };
        hht.aug = hht.scaling(set.dt);
        Ok(hht)
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

    /// `s = p = m/(beta h^2) + k` (THEORY §6).
    fn scaling(&self, h: f64) -> Augment {
        let k = self.sys.mean_mass() / (self.beta * h * h) + self.sys.mean_stiffness();
        Augment { s: k, p: k }
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

    /// Solves `[M, s B^T; s B, 0] x = rhs` at `trial` (the constrained mass matrix).
    fn solve_constrained_mass(&mut self, rhs_and_x: &mut [f64]) -> Result<(), StepFailure> {
        let c = TangentCoeffs {
            mass: 1.0,
            velocity: 0.0,
            position: 0.0,
            force_weight: 1.0,
        };
        self.asm.tangent(self.sys, &self.trial, self.aug, c);
        self.lu
            .factor(&self.asm.values)
            .map_err(|e| self.singular(e))?;
        self.lu.solve(rhs_and_x).map_err(|e| self.singular(e))
    }

    /// The smallest mass-weighted correction `dx` of the coordinates that cancels the current
    /// constraint values `g` to first order: `[M, s B^T; s B, 0] [dx; nu] = [0; -s g]`.
    /// Multiplier entries of the result are zero.
    fn constraint_correction(&mut self) -> Result<Vec<f64>, StepFailure> {
        let s = self.aug.s;
        let mut x: Vec<f64> = self
            .sys
            .unknowns
            .iter()
            .zip(&self.asm.residual.constraint)
            .map(|(k, g)| {
                if *k == UnknownKind::Multiplier {
                    -s * g
                } else {
                    0.0
                }
            })
            .collect();
        self.solve_constrained_mass(&mut x)?;
        for (xi, k) in x.iter_mut().zip(&self.sys.unknowns) {
            if *k == UnknownKind::Multiplier {
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

    fn largest_constraint(&self) -> (f64, Option<usize>) {
        let mut worst = (0.0, None);
        for (i, k) in self.sys.unknowns.iter().enumerate() {
            if *k == UnknownKind::Multiplier {
                let c = self.asm.residual.constraint[i].abs();
                if c > worst.0 || worst.1.is_none() {
                    worst = (c.max(worst.0), Some(self.sys.owners[i]));
                }
            }
        }
        worst
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
        let is_mult = |i: usize| self.sys.unknowns[i] == UnknownKind::Multiplier;
        self.trial = self.cur.clone();
        // Positions: minimum mass-weighted correction, iterated (Gauss-Newton).
        let mut moved = None;
        for _ in 0..50 {
            self.asm.residual(self.sys, &self.trial, self.aug);
            let (worst, who) = self.largest_constraint();
            if worst <= self.ctol() {
                break;
            }
            moved.get_or_insert((worst, who));
            let dq = self.constraint_correction()?;
            self.trial.q.iter_mut().zip(&dq).for_each(|(q, d)| *q += d);
        }
        self.asm.residual(self.sys, &self.trial, self.aug);
        if self.largest_constraint().0 > self.ctol() {
            return Err(StepFailure {
                kind: FailureKind::NewtonDiverged,
                entity: self.largest_constraint().1,
                detail: "the initial positions could not be brought onto the joints".to_string(),
            });
        }
        if let Some((worst, who)) = moved {
            notices.push(Notice {
                kind: NoticeKind::PositionProjected,
                entity: who,
                detail: format!("initial positions violated the joints by up to {worst:.3e} m and were projected onto them"),
            });
        }
        // Velocities: project onto B v = 0 in the mass metric (the impulsive response).
        self.asm
            .constraint_rate(self.sys, &self.trial, Rate::Velocity);
        let vmax = self.trial.v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let vtol = self.set.increment_tolerance
            * vmax.max(self.sys.length_scale / (self.set.dt * self.set.steps as f64));
        let (worst, who) = self.largest_constraint();
        if worst > vtol {
            let dv = self.constraint_correction()?;
            self.trial.v.iter_mut().zip(&dv).for_each(|(v, d)| *v += d);
            notices.push(Notice {
                kind: NoticeKind::VelocityProjected,
                entity: who,
                detail: format!("initial velocities violated the joints by up to {worst:.3e} m/s and were projected onto them"),
            });
        }
        // Accelerations and multipliers.
        self.trial.a.iter_mut().for_each(|x| *x = 0.0);
        self.trial.lambda.iter_mut().for_each(|x| *x = 0.0);
        if self.set.start == StartMode::Consistent {
            self.asm.residual(self.sys, &self.trial, self.aug);
            let mut x = vec![0.0; n];
            for (i, xi) in x.iter_mut().enumerate() {
                if !is_mult(i) {
                    *xi = -(self.asm.residual.inertia[i] + self.asm.residual.force[i]);
                }
            }
            self.asm
                .constraint_rate(self.sys, &self.trial, Rate::AccelerationBias);
            for (i, xi) in x.iter_mut().enumerate() {
                if is_mult(i) {
                    *xi = -s * self.asm.residual.constraint[i];
                }
            }
            self.solve_constrained_mass(&mut x)?;
            for (i, xi) in x.iter().enumerate() {
                if is_mult(i) {
                    self.trial.lambda[i] = *xi;
                } else {
                    self.trial.a[i] = *xi;
                }
            }
        }
        self.asm.residual(self.sys, &self.trial, self.aug);
        self.force_n.copy_from_slice(&self.asm.residual.force);
        std::mem::swap(&mut self.cur, &mut self.trial);
        if let Some(i) = self.cur.first_non_finite() {
            return Err(StepFailure {
                kind: FailureKind::NonFinite,
                entity: Some(self.sys.owners[i]),
                detail: "the initial state is not finite".to_string(),
            });
        }
        Ok(notices)
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
                let backup = (self.cur.clone(), self.force_n.clone(), self.aug);
                let result = self
                    .advance(h / 2.0, depth + 1)
                    .and_then(|_| self.advance(h / 2.0, depth + 1));
                if result.is_err() {
                    (self.cur, self.force_n, self.aug) = backup;
                }
                result
            }
        }
    }

    /// One step of size `h` from `cur`; on success `cur` holds the new state.
    fn attempt(&mut self, h: f64) -> Result<(), StepFailure> {
        let (alpha, beta, gamma) = (self.set.alpha, self.beta, self.gamma);
        let w = 1.0 + alpha;
        let aug = self.scaling(h);
        let rescale = self.aug.s / aug.s;
        let n = self.sys.len();
        let cur = &self.cur;
        let tr = &mut self.trial;
        tr.t = cur.t + h;
        // Predictor: a_{n+1} = a_n.
        for i in 0..n {
            match self.sys.unknowns[i] {
                UnknownKind::Coordinate => {
                    tr.a[i] = cur.a[i];
                    tr.q[i] = cur.q[i] + h * cur.v[i] + h * h * 0.5 * cur.a[i];
                    tr.v[i] = cur.v[i] + h * cur.a[i];
                    tr.lambda[i] = 0.0;
                }
                UnknownKind::Multiplier => {
                    tr.lambda[i] = cur.lambda[i] * rescale;
                }
            }
        }
        let coeffs = TangentCoeffs {
            mass: 1.0 / (beta * h * h),
            velocity: gamma / (beta * h),
            position: 1.0,
            force_weight: w,
        };
        let ltol = self.set.increment_tolerance * self.sys.length_scale;
        let floor = self.sys.mean_mass() * self.sys.length_scale;
        let mut increment_ok = false;
        let mut last_increment = f64::NAN;
        let mut last = f64::INFINITY;
        let mut growth = 0;
        for it in 0..=self.set.max_iterations {
            self.asm.residual(self.sys, &self.trial, aug);
            let r = &self.asm.residual;
            let (mut rnorm, mut scale, mut cnorm, mut worst) =
                (0.0f64, floor, 0.0f64, (0.0f64, 0usize));
            for i in 0..n {
                let ri = match self.sys.unknowns[i] {
                    UnknownKind::Coordinate => {
                        scale = scale.max(r.inertia[i].abs()).max(r.force[i].abs());
                        let ri = r.inertia[i] + w * r.force[i] - alpha * self.force_n[i];
                        rnorm = rnorm.max(ri.abs());
                        ri
                    }
                    UnknownKind::Multiplier => {
                        cnorm = cnorm.max(r.constraint[i].abs());
                        aug.s * r.constraint[i]
                    }
                };
                if !ri.is_finite() {
                    return Err(StepFailure {
                        kind: FailureKind::NonFinite,
                        entity: Some(self.sys.owners[i]),
                        detail: "the residual became NaN or infinite".to_string(),
                    });
                }
                if ri.abs()
                    / if self.sys.unknowns[i] == UnknownKind::Multiplier {
                        aug.s
                    } else {
                        1.0
                    }
                    > worst.0
                {
                    worst = (ri.abs(), i);
                }
                self.rhs[i] = -ri;
            }
            if increment_ok && rnorm <= self.set.residual_tolerance * scale && cnorm <= ltol {
                self.stats.newton_iterations += it;
                self.stats.max_constraint_violation =
                    self.stats.max_constraint_violation.max(cnorm);
                self.force_n.copy_from_slice(&self.asm.residual.force);
                self.aug = aug;
                std::mem::swap(&mut self.cur, &mut self.trial);
                return Ok(());
            }
            let total = rnorm + aug.s * cnorm;
            growth = if total > last { growth + 1 } else { 0 };
            last = total;
            if growth >= 3 || it == self.set.max_iterations {
                return Err(StepFailure {
                    kind: FailureKind::NewtonDiverged,
                    entity: Some(self.sys.owners[worst.1]),
                    detail: format!(
                        "Newton {} after {it} iteration(s), step halved {} time(s) (residual {rnorm:.3e} N against {:.3e} N; constraint violation {cnorm:.3e} m and last increment {last_increment:.3e} m against {ltol:.3e} m)",
                        if growth >= 3 { "diverged" } else { "did not converge" },
                        self.set.max_halvings,
                        self.set.residual_tolerance * scale
                    ),
                });
            }
            self.asm.tangent(self.sys, &self.trial, aug, coeffs);
            self.lu
                .factor(&self.asm.values)
                .map_err(|e| self.singular(e))?;
            self.lu.solve(&mut self.rhs).map_err(|e| self.singular(e))?;
            let (cur, tr) = (&self.cur, &mut self.trial);
            let mut dmax = 0.0f64;
            for i in 0..n {
                match self.sys.unknowns[i] {
                    UnknownKind::Coordinate => {
                        tr.q[i] += self.rhs[i];
                        dmax = dmax.max(self.rhs[i].abs());
                        tr.a[i] =
                            (tr.q[i] - cur.q[i] - h * cur.v[i] - h * h * (0.5 - beta) * cur.a[i])
                                / (beta * h * h);
                        tr.v[i] = cur.v[i] + h * ((1.0 - gamma) * cur.a[i] + gamma * tr.a[i]);
                    }
                    UnknownKind::Multiplier => tr.lambda[i] += self.rhs[i],
                }
            }
            increment_ok = dmax <= ltol;
            last_increment = dmax;
        }
        Err(StepFailure {
            kind: FailureKind::NewtonDiverged,
            entity: None,
            detail: "Newton did not converge".to_string(),
        })
    }
}
