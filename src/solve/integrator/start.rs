//! The start of a run (THEORY §7.3): the initial positions and velocities projected onto the
//! joints in the mass metric, then consistent accelerations and multipliers (or zeros: the
//! paper's start), all from the constrained mass matrix of [`super::start_matrix`]; the
//! state leaves in the layout of the integrator's rotation treatment.

use super::newton::Reuse;
use super::start_matrix::StartMetric;
use super::{rotations, se3};
use super::{Integrator, Layout, StepFailure};
use crate::runtime::rotation::{self as rot, V3};
use crate::runtime::{Rate, State, UnknownKind};
use crate::settings::{Method, Start};
use crate::solve::linear::SparseLu;
use crate::solve::{FailureKind, Notice, NoticeKind, RunStats, RuntimeFailure};

impl Integrator<'_> {
    /// Solves `[M, s B^T; s B, 0] x = rhs` at `trial` (the constrained mass matrix, in the
    /// physical layout: virtual rotations).
    pub(super) fn solve_constrained_mass(
        &mut self,
        rhs_and_x: &mut [f64],
    ) -> Result<(), StepFailure> {
        self.mass_rhs.copy_from_slice(rhs_and_x);
        loop {
            self.start
                .assemble(&mut self.asm, self.sys, &self.trial, self.aug);
            // Massless directions are allowed here: faer's pivoting LU, made on first use.
            if self.mass_lu.is_none() {
                let lu = SparseLu::new(&self.asm.pattern).map_err(|e| self.singular(e))?;
                self.mass_lu = Some(lu);
            }
            let lu = self.mass_lu.as_mut().expect("made above");
            let solved = match lu.factor(&self.asm.values) {
                Ok(()) => lu.solve(rhs_and_x),
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
    pub(super) fn apply_physical(&mut self, dx: &[f64], level: usize) {
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
        // A kept matrix made with other rows dropped (W0303) is not this start's.
        if self.cur.dropped != initial.dropped {
            self.kept = None;
        }
        self.cur.clone_from(initial);
        self.trial.clone_from(initial);
        self.mid.clone_from(initial);
        self.tracked = None;
        // The multipliers' and accelerations' past are the last run's.
        self.last_h = None;
        self.history.clear();
        self.reuse = Reuse::new(self.set.newton, self.set.method);
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
        notices.extend(self.project_positions()?);
        // Redundant joints (W0303): the rows dropped are projected with the others only
        // through them, so they must hold already.
        if let Some((off, entity)) = self.sys.dropped_violation(&self.trial) {
            if off > self.dropped_limit() {
                return Err(StepFailure {
                    kind: FailureKind::Inconsistent,
                    entity: Some(entity),
                    detail: format!("a redundant equation the run dropped is off by {off:.2e} (m, or rad for an axis) at the start: the joints' equations do not hold together"),
                });
            }
        }
        if self.method == Method::Static {
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
        notices.extend(self.project_velocities()?);
        // Accelerations and multipliers.
        let zero: Vec<f64> = self.trial.a.iter().map(|a| -a).collect();
        self.apply_physical(&zero, 2);
        self.trial.lambda.iter_mut().for_each(|x| *x = 0.0);
        if self.set.start == Start::Consistent {
            self.consistent_accelerations()?;
        }
        self.finish_initialization(notices)
    }

    /// Positions: the minimum mass-weighted correction onto the joints, iterated
    /// (Gauss-Newton); a notice if they moved.
    fn project_positions(&mut self) -> Result<Option<Notice>, StepFailure> {
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
        Ok(moved.map(|(worst, who)| Notice {
            kind: NoticeKind::PositionProjected,
            entity: who,
            detail: format!("initial positions violated the joints by up to {worst:.3e} m and were projected onto them"),
        }))
    }

    /// Velocities: the revolute angles' rates measured, then the bodies' projected onto
    /// `B v + dC/dt = 0` in the mass metric (the impulsive response); a notice if they moved.
    fn project_velocities(&mut self) -> Result<Option<Notice>, StepFailure> {
        // Revolute angle rates: the measured relative rates (they carry no mass, so only the
        // bodies' velocities decide whether the start is consistent).
        self.asm
            .constraint_rate(self.sys, &self.trial, Rate::Velocity);
        for (row, angle) in self.sys.angle_rows() {
            self.trial.v[angle] += self.asm.residual.constraint[row];
        }
        self.asm
            .constraint_rate(self.sys, &self.trial, Rate::Velocity);
        let g = self.asm.residual.constraint.clone();
        let vmax = self.trial.v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let vtol = self.set.increment_tolerance
            * vmax.max(self.sys.length_scale / (self.set.dt * self.set.steps as f64));
        let (worst, who) = self.largest(&g, true);
        if worst <= vtol {
            return Ok(None);
        }
        let dv = self.constraint_correction(&g)?;
        self.apply_physical(&dv, 1);
        Ok(Some(Notice {
            kind: NoticeKind::VelocityProjected,
            entity: who,
            detail: format!("initial velocities violated the joints by up to {worst:.3e} m/s and were projected onto them"),
        }))
    }

    /// The accelerations and multipliers that satisfy the equations of motion and the
    /// joints' acceleration constraints at the start.
    fn consistent_accelerations(&mut self) -> Result<(), StepFailure> {
        let (n, s) = (self.sys.len(), self.aug.s);
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
        Ok(())
    }

    /// From the physical layout to the treatment's, and the initial state becomes current.
    fn finish_initialization(&mut self, notices: Vec<Notice>) -> Result<Vec<Notice>, StepFailure> {
        if self.layout == Layout::Physical {
            // The nodal momenta P_0 = M(q_0) V_0.
            self.asm.momentum(self.sys, &self.trial);
            for (i, x) in self.trial.alg.iter_mut().enumerate() {
                *x = if self.sys.unknowns[i].is_multiplier() {
                    0.0
                } else {
                    self.asm.momentum[i]
                };
            }
        } else if self.layout == Layout::Conformal {
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
}
