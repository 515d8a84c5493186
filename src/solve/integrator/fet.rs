//! Time finite elements (THEORY §8.1): the bilinear mixed element with midpoint quadrature.
//!
//! In each element `[t_n, t_{n+1}]` the displacements are linear in time and the momenta
//! constant. Unknowns: the end configuration `(q_{n+1}, R_{n+1})` and the multipliers (constant
//! over the element). With the mid-configuration `q_m` (`u_m = (u_n + u_{n+1})/2`,
//! `R_m = exp(theta/2) R_n`, `R_{n+1} = exp(theta) R_n`) and the constant velocities
//! `V = (Delta u / h, theta / h)`, momentum balance over the element and the constraints at its
//! end read
//!
//! `2 (P(q_m, V) - P_n)/h + G(q_m, V) + F^int(q_m, V) - F^ext(t_m, q_m) + B(q_m)^T s lambda
//!  + B(q_{n+1})^T p C(q_{n+1}) = 0`, `s C(q_{n+1}) = 0`,
//!
//! with velocity-level constraints (prescribed rates) enforced on `V` at the midpoint. Then
//! `P_{n+1} = 2 P(q_m, V) - P_n`. The penalty acts at the end configuration, where `C` vanishes
//! at convergence, so it does not alter the converged step. The element code is the HHT one:
//! the iteration matrix is the element tangent at the mid-configuration with coefficients
//! `(2/h^2, 1/h, 1/2)`, the constraint rows and penalty from the end configuration.
//!
//! The state stays in the physical layout (virtual rotations, `omega` in the rotation slots);
//! `State::alg` holds the nodal momenta `P_n`, so a halved step restores them with the state.
//! Output velocities solve `M(q_{n+1}) V_{n+1} = P_{n+1}` projected onto the velocity
//! constraints (massless directions: the revolute angles through their rows); output
//! accelerations are the element's mean `(V_{n+1} - V_n)/h`; output multipliers the element's.

use super::{Integrator, Norms, StepFailure};
use crate::runtime::rotation as rot;
use crate::runtime::{Augment, Rate, TangentCoeffs, UnknownKind};
use crate::solve::FailureKind;

impl Integrator<'_> {
    /// The mid-configuration and constant velocities of the element from `cur` and `trial`.
    fn fet_mid(&mut self, h: f64) {
        let (sys, cur, tr, mid) = (self.sys, &self.cur, &self.trial, &mut self.mid);
        for (i, k) in sys.unknowns.iter().enumerate() {
            if *k == UnknownKind::Coordinate {
                mid.q[i] = 0.5 * (cur.q[i] + tr.q[i]);
                mid.v[i] = (tr.q[i] - cur.q[i]) / h;
                mid.a[i] = 0.0;
            }
        }
        for (k, &r) in sys.rotations.iter().enumerate() {
            let r0 = cur.rot[k].matrix();
            let th = rot::log(&(tr.rot[k].matrix() * r0.transpose()));
            mid.rot[k].set_matrix(&(rot::exp(&(0.5 * th)) * r0));
            let w = th / h;
            mid.rot[k].w = w.into();
            mid.rot[k].dw = [0.0; 3];
            for j in 0..3 {
                (mid.q[r + j], mid.v[r + j], mid.a[r + j]) = (0.0, w[j], 0.0);
            }
        }
    }

    /// Predictor: Taylor to second order from the current rates; the multipliers carried
    /// over at the new scaling.
    pub(super) fn fet_predict(&mut self, h: f64, rescale: f64) {
        let (sys, cur, tr, mid) = (self.sys, &self.cur, &mut self.trial, &mut self.mid);
        tr.t = cur.t + h;
        mid.t = cur.t + 0.5 * h;
        for (i, k) in sys.unknowns.iter().enumerate() {
            tr.lambda[i] = 0.0;
            match k {
                UnknownKind::Coordinate => {
                    tr.q[i] = cur.q[i] + h * cur.v[i] + 0.5 * h * h * cur.a[i];
                }
                UnknownKind::Multiplier | UnknownKind::RateMultiplier => {
                    mid.lambda[i] = cur.lambda[i] * rescale;
                }
                UnknownKind::Rotation { .. } => {}
            }
        }
        for k in 0..sys.rotations.len() {
            let th = h * cur.rot[k].omega() + 0.5 * h * h * cur.rot[k].omega_dot();
            tr.rot[k].set_matrix(&(rot::exp(&th) * cur.rot[k].matrix()));
        }
    }

    /// The element's residual (momentum balance at the mid-configuration, the joints at the
    /// end), in `rhs`, and its norms.
    pub(super) fn fet_residual(
        &mut self,
        h: f64,
        aug: Augment,
        floor: f64,
    ) -> Result<Norms, StepFailure> {
        let n = self.sys.len();
        self.fet_mid(h);
        self.asm
            .residual(self.sys, &self.mid, Augment { p: 0.0, ..aug });
        self.asm.momentum(self.sys, &self.mid);
        self.asm
            .joint_residual(self.sys, &self.trial, aug, &mut self.end_res);
        let (r, e) = (&self.asm.residual, &self.end_res);
        let (pm, g) = (&self.asm.momentum, &self.asm.transport);
        let (mut scale, mut cnorm) = (floor, 0.0f64);
        let (mut rnorm, mut worst) = (0.0f64, (0.0f64, 0usize));
        for i in 0..n {
            let (ri, size) = match self.sys.unknowns[i] {
                UnknownKind::Multiplier => (-aug.s * e.constraint[i], e.constraint[i].abs()),
                UnknownKind::RateMultiplier => (-aug.s * r.constraint[i], r.constraint[i].abs()),
                _ => {
                    let rate = 2.0 * (pm[i] - self.cur.alg[i]) / h;
                    let f = g[i] + r.force[i] + e.force[i];
                    scale = scale.max(rate.abs()).max(g[i].abs()).max(r.force[i].abs());
                    let ri = -(rate + f);
                    rnorm = rnorm.max(ri.abs());
                    (ri, ri.abs())
                }
            };
            if self.sys.unknowns[i].is_multiplier() {
                cnorm = cnorm.max(size);
            }
            if !ri.is_finite() {
                return Err(StepFailure {
                    kind: FailureKind::NonFinite,
                    entity: Some(self.sys.owners[i]),
                    detail: "the residual became NaN or infinite".to_string(),
                });
            }
            if size > worst.0 {
                worst = (size, i);
            }
            self.rhs[i] = ri;
        }
        Ok(Norms {
            force: rnorm,
            scale,
            constraint: cnorm,
            worst: worst.1,
            own: None,
        })
    }

    /// The iteration matrix: the element tangent at the mid-configuration with coefficients
    /// `(2/h^2, 1/h, 1/2)`, the constraint rows and penalty from the end configuration.
    pub(super) fn fet_matrix(&mut self, h: f64, aug: Augment) {
        let coeffs = TangentCoeffs {
            mass: 2.0 / (h * h),
            velocity: 1.0 / h,
            position: 0.5,
            force_weight: 1.0,
        };
        let aug_mid = Augment { p: 0.0, ..aug };
        self.asm
            .tangent_split(self.sys, &self.mid, &self.trial, aug_mid, aug, coeffs);
    }

    /// Applies the correction in `rhs` to the element's multipliers and end configuration;
    /// the largest scaled increment.
    pub(super) fn fet_correct(&mut self) -> f64 {
        let n = self.sys.len();
        let mut dmax = 0.0f64;
        for i in 0..n {
            let d = self.rhs[i];
            match self.sys.unknowns[i] {
                UnknownKind::Multiplier | UnknownKind::RateMultiplier => self.mid.lambda[i] += d,
                UnknownKind::Rotation { .. } => dmax = dmax.max(d.abs()),
                UnknownKind::Coordinate => dmax = dmax.max(d.abs() / self.sys.length_scale),
            }
        }
        let dx = std::mem::take(&mut self.rhs);
        self.apply_physical(&dx, 0);
        self.rhs = dx;
        dmax
    }

    /// After convergence (the momenta of the mid-configuration in `asm.momentum`): the end
    /// momenta, output velocities, accelerations and multipliers; `trial` becomes current.
    pub(super) fn fet_commit(&mut self, h: f64) -> Result<(), StepFailure> {
        let n = self.sys.len();
        for i in 0..n {
            if !self.sys.unknowns[i].is_multiplier() {
                self.trial.alg[i] = 2.0 * self.asm.momentum[i] - self.cur.alg[i];
            }
        }
        // Start from the element's velocities V: P(q_{n+1}, V), and the velocity constraints.
        {
            let (tr, mid) = (&mut self.trial, &self.mid);
            for (i, k) in self.sys.unknowns.iter().enumerate() {
                if !k.is_multiplier() {
                    tr.v[i] = mid.v[i];
                }
            }
            for k in 0..self.sys.rotations.len() {
                tr.rot[k].w = mid.rot[k].w;
            }
        }
        self.asm.momentum(self.sys, &self.trial);
        self.asm
            .constraint_rate(self.sys, &self.trial, Rate::Velocity);
        let s = self.aug.s;
        let mut x = std::mem::take(&mut self.rhs);
        for (i, k) in self.sys.unknowns.iter().enumerate() {
            x[i] = if k.is_multiplier() {
                -s * self.asm.residual.constraint[i]
            } else {
                self.trial.alg[i] - self.asm.momentum[i]
            };
        }
        let solved = self.solve_constrained_mass(&mut x);
        if solved.is_ok() {
            let (cur, tr, mid) = (&self.cur, &mut self.trial, &self.mid);
            for (i, k) in self.sys.unknowns.iter().enumerate() {
                match k {
                    UnknownKind::Coordinate => {
                        tr.v[i] += x[i];
                        tr.a[i] = (tr.v[i] - cur.v[i]) / h;
                    }
                    UnknownKind::Rotation { node, axis } => {
                        tr.v[i] += x[i];
                        tr.a[i] = (tr.v[i] - cur.v[i]) / h;
                        tr.rot[*node].w[*axis] = tr.v[i];
                        tr.rot[*node].dw[*axis] = tr.a[i];
                    }
                    _ => tr.lambda[i] = mid.lambda[i],
                }
            }
        }
        self.rhs = x;
        solved?;
        std::mem::swap(&mut self.cur, &mut self.trial);
        for k in 0..self.sys.rotations.len() {
            let r = rot::reorthogonalize(&self.cur.rot[k].matrix());
            self.cur.rot[k].set_matrix(&r);
        }
        self.check_finite()
    }
}
