//! The Newmark family in the Arnold-Bruls form: HHT-alpha and generalized-alpha (and the
//! load steps of statics, which share its residual and correction): predictor, residual and
//! norms, iteration matrix, correction and commit of one Newton step.
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
//! body-frame increments ([`super::se3`]); with the conformal treatment the rotation
//! unknowns hold `c`, `c-dot`, `c-ddot` like any coordinate ([`super::rotations`]).

use super::history::{History, ORDERS, RINGS};
use super::newton::larger;
use super::{rotations, se3};
use super::{Integrator, Layout, Norms, Predictor, StepFailure};
use crate::runtime::precise;
use crate::runtime::rotation::{self as rot};
use crate::runtime::{Augment, State, TangentCoeffs, UnknownKind};
use crate::settings::{Method, NewtonMode, Settings};
use crate::solve::FailureKind;

/// The scheme's constants.
#[derive(Clone, Copy, Debug)]
pub(super) struct Scheme {
    pub(super) am: f64,
    pub(super) af: f64,
    pub(super) beta: f64,
    pub(super) gamma: f64,
}

impl Scheme {
    pub(super) fn of(set: &Settings) -> Scheme {
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
                }
            }
            // Time finite elements: the trapezoidal constants size the constraint scaling
            // (`s = 4 m / h^2 + k`) and the start.
            Method::Fet => Scheme {
                am: 0.0,
                af: 0.0,
                beta: 0.25,
                gamma: 0.5,
            },
            // HHT in the Arnold-Bruls form: equations at t_{n+1}, a_m = 0, a_f = -alpha. Same
            // linear amplification as the force-weighted form, and second order with
            // configuration-dependent inertia (the weighted form is first order there). Statics
            // takes these constants for its scaling and start.
            _ => Scheme {
                am: 0.0,
                af: -set.alpha,
                beta: (1.0 - set.alpha).powi(2) / 4.0,
                gamma: 0.5 - set.alpha,
            },
        }
    }

    /// The ringing of a constrained unknown: with its increments held, the Newmark relations
    /// carry an error of its rate and algorithmic acceleration from step to step as the roots
    /// of `beta z^2 + (1/2 - 2 beta + gamma) z + (1/2 - gamma + beta)`, a double root at
    /// `-rho_inf` under generalized-alpha and HHT. The accelerations ring so after a load
    /// reversal (the paper's two-bar at 0.05 s) and after the consistent start (`alg_0 = a_0`),
    /// and a polynomial extrapolation multiplies the ringing by up to 2^(p+1)
    /// ([`super::step::Predictor::Ringing`] continues it instead). Returned as `(b1, b0)` of
    /// the monic `z^2 + b1 z + b0`.
    pub(super) fn ringing(&self) -> (f64, f64) {
        let Scheme { beta, gamma, .. } = *self;
        if beta <= 0.0 {
            return (0.0, 0.0);
        }
        (
            (0.5 - 2.0 * beta + gamma) / beta,
            (0.5 - gamma + beta) / beta,
        )
    }

    /// The Newmark relations of a step of `h`: (increment, previous rate, previous
    /// acceleration, previous algorithmic acceleration) -> (rate, acceleration, algorithmic
    /// acceleration). Linear in all four.
    pub(super) fn relation(&self, h: f64, dq: f64, v: f64, a: f64, alg0: f64) -> (f64, f64, f64) {
        let beta = self.beta;
        let alg = (dq - h * v - h * h * (0.5 - beta) * alg0) / (beta * h * h);
        let (v, a) = self.rates(h, v, a, alg0, alg);
        (v, a, alg)
    }

    /// The rate and acceleration at the step's end from its algorithmic acceleration `alg`
    /// (and the start's rate, acceleration and algorithmic acceleration).
    #[inline]
    pub(super) fn rates(&self, h: f64, v: f64, a: f64, alg0: f64, alg: f64) -> (f64, f64) {
        let Scheme { am, af, gamma, .. } = *self;
        (
            v + h * ((1.0 - gamma) * alg0 + gamma * alg),
            ((1.0 - am) * alg + am * alg0 - af * a) / (1.0 - af),
        )
    }

    /// A step's increment from the start's rate and algorithmic acceleration and the end's
    /// algorithmic acceleration.
    #[inline]
    pub(super) fn increment(&self, h: f64, v: f64, alg0: f64, alg: f64) -> f64 {
        h * v + h * h * ((0.5 - self.beta) * alg0 + self.beta * alg)
    }

    /// The predicted increment and the algorithmic acceleration it implies.
    pub(super) fn predicted_pair(
        &self,
        h: f64,
        predictor: Predictor,
        (v, a, alg0): (f64, f64, f64),
        (past, slot): (&History, usize),
    ) -> (f64, f64) {
        let alg = match predictor {
            Predictor::Velocity => return (h * v, -(0.5 - self.beta) / self.beta * alg0),
            Predictor::Acceleration => (a - self.am * alg0) / (1.0 - self.am),
            Predictor::Extrapolated(p) => past.extrapolate(p, slot, alg0),
            Predictor::Ringing(d) => past.ringing(d, slot, alg0),
        };
        (self.increment(h, v, alg0, alg), alg)
    }

    /// `d a_{n+1} / d q_{n+1}`.
    fn mass_coefficient(&self, h: f64) -> f64 {
        (1.0 - self.am) / ((1.0 - self.af) * self.beta * h * h)
    }
}

impl Integrator<'_> {
    /// Predictor: the acceleration `a_{n+1} = a_n` (statics: the previous load step's
    /// equilibrium); the multipliers carried over at the new scaling.
    pub(super) fn newmark_predict(
        &mut self,
        h: f64,
        rescale: f64,
        extrapolate: bool,
        predictor: Predictor,
    ) {
        let sc = self.sc;
        // A kept matrix corrects the multipliers slowly (joint forces in inertial components
        // turn with the bodies, by about `omega h` a step): they start from their quadratic
        // extrapolation over the last three steps of this size (linear over two). On the
        // windmill's rotating joints it misses by `(omega h)^3` instead of `(omega h)^2` of
        // the load (residual 3.3e-3 N instead of 0.31 N at Omega_bar 1.5), and most steps end
        // after one correction instead of two. A step that starts that close ends at the
        // residual tolerance where one from farther overshoots it, so a kept matrix's residual
        // test holds each entity's forces to their own scale (`Newton::own`): the windmill
        // under `auto` took 8,364 iterations and 442 factorizations for its 6,000 steps and
        // landed 1.1e-7 of the hub's motion off the discrete solution, against 23,302, 135 and
        // 1.5e-6 with the linear extrapolation, the acceleration predictor and the residual
        // against the largest force (1.6e-5 with the quadratic one alone).
        let extrapolate = extrapolate && self.lambda_prev.1 == Some(h);
        let quadratic = extrapolate && self.lambda_prev2.1;
        let hold = self.method == Method::Static;
        let n = self.sys.len();
        // An extrapolation goes as far back as the steps of this size go.
        let predictor = match predictor {
            Predictor::Extrapolated(p) => match p.min(self.history.orders(h)) {
                0 => Predictor::Acceleration,
                p => Predictor::Extrapolated(p),
            },
            Predictor::Ringing(d) => match d.min(self.history.orders(h).saturating_sub(1)) {
                0 => Predictor::Acceleration,
                d => Predictor::Ringing(d),
            },
            other => other,
        };
        let (cur, tr, past) = (&self.cur, &mut self.trial, &self.history);
        tr.t = cur.t + h;
        let step = |v: f64, a: f64, alg0: f64, slot: usize| {
            if hold {
                (0.0, 0.0)
            } else {
                sc.predicted_pair(h, predictor, (v, a, alg0), (past, slot))
            }
        };
        for i in 0..n {
            if self.sys.unknowns[i].is_multiplier() {
                tr.lambda[i] = if quadratic {
                    3.0 * (cur.lambda[i] - self.lambda_prev.0[i]) + self.lambda_prev2.0[i]
                } else if extrapolate {
                    2.0 * cur.lambda[i] - self.lambda_prev.0[i]
                } else {
                    cur.lambda[i] * rescale
                };
            } else {
                tr.lambda[i] = 0.0;
                if !self.in_frame[i] {
                    (self.step_q[i], tr.alg[i]) = step(cur.v[i], cur.a[i], cur.alg[i], i);
                    advance(self.is_angle[i], cur, tr, i, self.step_q[i]);
                }
            }
        }
        if self.layout == Layout::Increments {
            for k in 0..self.sys.rotations.len() {
                let f = cur.frames[k];
                let frame = self.sys.is_frame(k);
                let mut d = [0.0; 6];
                for j in 0..6 {
                    // Non-frames' translations are coordinates, in `step_q`.
                    (d[j], tr.frames[k].alg[j]) = match frame || j >= 3 {
                        true => step(f.v[j], f.dv[j], f.alg[j], past.frame_slot(k, j)),
                        false => (0.0, 0.0),
                    };
                }
                self.step_frames[k] = d;
                se3::displace(self.sys, cur, tr, k, &d);
            }
        }
        // The trust region's centre: the step at constant velocities.
        for (p, f) in self.predicted.iter_mut().zip(&self.cur.frames) {
            *p = f.v.map(|v| h * v);
        }
        self.newmark(h);
    }

    /// The predictor whose step came nearest the converged step, before the commit: the
    /// largest difference over the unknowns, scaled as Newton's increments are, compared over
    /// the velocity, the acceleration and each order of extrapolation the steps allow.
    /// Extrapolations serve rigid models: the stiff-beam two-bar at the paper's step, chaotic,
    /// failed at 12.8 s from them. Not a tracked run with kept matrices: the windmill's tracked
    /// Floquet run took 1,232 iterations over 972 steps instead of 995 from them.
    pub(super) fn best_predictor(&self, h: f64) -> Predictor {
        let orders = if self.extrapolates() {
            self.history.orders(h)
        } else {
            0
        };
        let rings = orders.saturating_sub(1);
        let mut all = [Predictor::Velocity; 2 + ORDERS + RINGS];
        all[1] = Predictor::Acceleration;
        for p in 1..=orders {
            all[1 + p] = Predictor::Extrapolated(p);
        }
        for d in 1..=rings {
            all[1 + orders + d] = Predictor::Ringing(d);
        }
        let all = &all[..2 + orders + rings];
        let mut miss = [0.0f64; 2 + ORDERS + RINGS];
        let (cur, sys, sc, past) = (&self.cur, self.sys, self.sc, &self.history);
        // Each slot's past values read once for all the predictors (they were 4 % of a
        // windmill run under `auto`, read predictor by predictor); the same arithmetic as
        // `Scheme::predicted_pair`.
        let mut count = |taken: f64, (v, a, alg0): (f64, f64, f64), slot: usize, scale: f64| {
            let x = past.slot(slot);
            for (m, &p) in miss.iter_mut().zip(all) {
                let step = match p {
                    Predictor::Velocity => h * v,
                    Predictor::Acceleration => {
                        sc.increment(h, v, alg0, (a - sc.am * alg0) / (1.0 - sc.am))
                    }
                    Predictor::Extrapolated(q) => {
                        sc.increment(h, v, alg0, History::extrapolate_from(q, alg0, &x))
                    }
                    Predictor::Ringing(d) => {
                        sc.increment(h, v, alg0, past.ringing_from(d, alg0, &x))
                    }
                };
                *m = larger(*m, (taken - step).abs() * scale);
            }
        };
        for i in (0..sys.len()).filter(|&i| !self.in_frame[i]) {
            let scale = match sys.unknowns[i] {
                UnknownKind::Rotation { .. } => 1.0,
                UnknownKind::Coordinate => 1.0 / sys.length_scale,
                _ => continue,
            };
            count(self.step_q[i], (cur.v[i], cur.a[i], cur.alg[i]), i, scale);
        }
        if self.layout == Layout::Increments {
            for (k, (f, taken)) in cur.frames.iter().zip(&self.step_frames).enumerate() {
                // Translations of nodes that are not frames are coordinates, counted above.
                let first = if sys.is_frame(k) { 0 } else { 3 };
                for j in first..6 {
                    let scale = if j < 3 { 1.0 / sys.length_scale } else { 1.0 };
                    let slot = past.frame_slot(k, j);
                    count(taken[j], (f.v[j], f.dv[j], f.alg[j]), slot, scale);
                }
            }
        }
        // The nearest; of equal misses, the one listed first (the simpler).
        let mut best = 0;
        for (j, m) in miss[..all.len()].iter().enumerate() {
            if *m < miss[best] {
                best = j;
            }
        }
        all[best]
    }

    /// Whether steps may start from extrapolated accelerations (see `best_predictor`).
    pub(super) fn extrapolates(&self) -> bool {
        self.rigid && (self.reuse.mode() == NewtonMode::Full || self.tracked.is_none())
    }

    /// The residual at the iterate, in `rhs` in the treatment's unknowns, and its norms.
    pub(super) fn newmark_residual(
        &mut self,
        aug: Augment,
        floor: f64,
    ) -> Result<Norms, StepFailure> {
        let n = self.sys.len();
        self.fused.1 = match self.fused.0.take() {
            Some(c) => {
                (self.asm).residual_and_tangent(self.sys, &self.trial, aug, c);
                true
            }
            None => {
                self.asm.residual(self.sys, &self.trial, aug);
                false
            }
        };
        self.block_matrices();
        let r = &self.asm.residual;
        // `larger`, not `f64::max`: a NaN shows in `rhs` (checked below).
        let (mut scale, mut cnorm) = (floor, 0.0f64);
        for i in 0..n {
            if self.sys.unknowns[i].is_multiplier() {
                cnorm = larger(cnorm, r.constraint[i].abs());
                self.rhs[i] = -aug.s * r.constraint[i];
            } else {
                scale = larger(larger(scale, r.inertia[i].abs()), r.force[i].abs());
                self.rhs[i] = -(r.inertia[i] + r.force[i]);
            }
        }
        rotations::transform_vector(&self.blocks, &self.mats, &mut self.rhs);
        // Under kept matrices on rigid models (untracked), each entity's forces against their
        // own scale as well.
        let own = self.rigid && self.reuse.mode() != NewtonMode::Full && self.tracked.is_none();
        if own {
            self.own_scale.fill(floor);
            for i in (0..n).filter(|&i| !self.sys.unknowns[i].is_multiplier()) {
                let o = &mut self.own_scale[self.sys.owners[i]];
                *o = larger(larger(*o, r.inertia[i].abs()), r.force[i].abs());
            }
        }
        let (mut rnorm, mut worst, mut relative) = (0.0f64, (0.0f64, 0usize), 0.0f64);
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
                rnorm = larger(rnorm, ri.abs());
                if own {
                    relative = larger(relative, ri.abs() / self.own_scale[self.sys.owners[i]]);
                }
                ri.abs()
            };
            if size > worst.0 {
                worst = (size, i);
            }
        }
        Ok(Norms {
            force: rnorm,
            scale,
            constraint: cnorm,
            worst: worst.1,
            own: own.then_some(relative),
        })
    }

    /// The tangent's coefficients for a step of `h`.
    pub(super) fn newmark_coefficients(&self, h: f64) -> TangentCoeffs {
        let sc = self.sc;
        if self.method == Method::Static {
            Self::static_coefficients()
        } else {
            TangentCoeffs {
                mass: sc.mass_coefficient(h),
                velocity: sc.gamma / (sc.beta * h),
                position: 1.0,
                force_weight: 1.0,
            }
        }
    }

    /// The iteration matrix at the iterate, `T^T J T` in the treatment's unknowns.
    pub(super) fn newmark_matrix(&mut self, h: f64, aug: Augment) {
        let coeffs = self.newmark_coefficients(h);
        if !std::mem::take(&mut self.fused.1) {
            self.asm.tangent(self.sys, &self.trial, aug, coeffs);
        }
        // SE(3) frames: the Newmark relations act on body-frame twists, so the inertial
        // terms' columns take how those move with a correction (`se3::rate_maps`).
        if self.layout == Layout::Increments && self.method != Method::Static {
            let all = self.exact_rates;
            for k in 0..self.sys.rotations.len() {
                if all || self.sys.is_frame(k) {
                    self.jinv[k] = se3::Jinv::new(&self.step_frames[k]);
                    self.rate_maps[k] = se3::rate_maps(
                        self.sys,
                        &self.trial,
                        k,
                        &self.jinv[k],
                        coeffs.velocity,
                        coeffs.mass,
                    );
                }
            }
            // A tracked step's matrix is made at the state whose `M` and `C` the step's
            // tangent has just evaluated (`Integrator::propagate`).
            if self.rates_held {
                let maps = &self.rate_maps;
                (self.asm).add_kept_rate_columns(self.sys, &self.trial, aug, maps, !all);
            } else {
                (self.asm).add_rate_columns(self.sys, &self.trial, aug, 1.0, &self.rate_maps, !all);
            }
        }
        self.transform.apply(
            &self.asm.pattern,
            &mut self.asm.values,
            &self.mats,
            &self.mats,
        );
    }

    /// Applies the correction in `rhs` (multipliers, coordinates, node increments) and
    /// updates the rates; the largest scaled increment.
    pub(super) fn newmark_correct(&mut self, h: f64) -> f64 {
        let n = self.sys.len();
        let conformal = self.layout == Layout::Conformal;
        let mut dmax = 0.0f64;
        let (cur, tr) = (&self.cur, &mut self.trial);
        // Each correction moves the algorithmic accelerations by its own size over
        // `beta h^2`: they never come from the increment less its predictable part, whose
        // round-off (`ulp(h v)`, the same every step of a steady spin) `1/(beta h^2)` would
        // amplify into a steady load (`se3::increment`).
        let inv = match self.method {
            Method::Static => 0.0,
            _ => 1.0 / (self.sc.beta * h * h),
        };
        // Coordinates move by the step's increment, kept apart (see `se3::increment`).
        for i in 0..n {
            let d = self.rhs[i];
            let angle = self.is_angle[i];
            let shift = |tr: &mut State, step: &mut [f64]| {
                step[i] += d;
                tr.alg[i] += d * inv;
                advance(angle, cur, tr, i, step[i]);
            };
            match self.sys.unknowns[i] {
                UnknownKind::Multiplier | UnknownKind::RateMultiplier => tr.lambda[i] += d,
                UnknownKind::Rotation { .. } => {
                    dmax = dmax.max(d.abs());
                    if conformal {
                        shift(tr, &mut self.step_q);
                    }
                }
                UnknownKind::Coordinate => {
                    dmax = dmax.max(d.abs() / self.sys.length_scale);
                    if !self.in_frame[i] {
                        shift(tr, &mut self.step_q);
                    }
                }
            }
        }
        if !conformal {
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
                let d0 = &self.step_frames[k];
                let dd = se3::increment(self.sys, k, d0, &d, self.jinv[k].at(d0));
                let (step, alg) = (&mut self.step_frames[k], &mut tr.frames[k].alg);
                for j in 0..6 {
                    step[j] += dd[j];
                    alg[j] += dd[j] * inv;
                }
                se3::displace(self.sys, cur, tr, k, &self.step_frames[k]);
            }
        }
        self.newmark(h);
        dmax
    }

    /// The converged iterate becomes current: conformal vectors rescaled past pi, rotation
    /// matrices re-orthonormalized.
    pub(super) fn newmark_commit(&mut self) -> Result<(), StepFailure> {
        std::mem::swap(&mut self.cur, &mut self.trial);
        // The angles' rounding moves into `q` as far as it can (`q` the nearest value to
        // `q + carry`).
        for &a in &self.angles {
            (self.cur.q[a], self.cur.carry[a]) = precise::two_sum(self.cur.q[a], self.cur.carry[a]);
        }
        if self.layout == Layout::Conformal {
            self.stats.rescalings += rotations::rescale(self.sys, &mut self.cur);
            rotations::sync(self.sys, &mut self.cur);
        } else {
            for k in 0..self.sys.rotations.len() {
                let r = rot::reorthogonalize(&self.cur.rot[k].matrix());
                self.cur.rot[k].set_matrix(&r);
            }
        }
        self.check_finite()
    }

    /// The transform's block matrices at the iterate: `H(c)` (conformal) or `R` for the
    /// translation and rotation blocks of each node (SE(3)).
    pub(super) fn block_matrices(&mut self) {
        let nodes = self.sys.rotations.len();
        if self.layout == Layout::Conformal {
            rotations::tangents(self.sys, &self.trial, &mut self.mats);
        } else {
            // Rotation blocks come last, one per node in order.
            let first = self.blocks.len() - nodes;
            for k in 0..nodes {
                // A correction moves the frame by exactly `R d`: `R` for every column, the
                // Newmark rates' dependence on the increment added by `se3::rate_maps`.
                self.mats[first + k] = self.trial.rot[k].matrix();
            }
            for b in 0..first {
                let k = self.block_node[b];
                self.mats[b] = self.mats[first + k];
            }
        }
    }

    /// Updates velocities and accelerations of the iterate from its algorithmic
    /// accelerations (Newmark; the increments hold the same relation, see
    /// `newmark_correct`).
    pub(super) fn newmark(&mut self, h: f64) {
        if self.method == Method::Static {
            self.static_rates();
            return;
        }
        let sc = self.sc;
        let (cur, tr) = (&self.cur, &mut self.trial);
        for i in 0..self.sys.len() {
            if self.in_frame[i] || self.sys.unknowns[i].is_multiplier() {
                continue;
            }
            (tr.v[i], tr.a[i]) = sc.rates(h, cur.v[i], cur.a[i], cur.alg[i], tr.alg[i]);
        }
        if self.layout == Layout::Conformal {
            rotations::sync(self.sys, tr);
            return;
        }
        for k in 0..self.sys.rotations.len() {
            let f0 = cur.frames[k];
            let f = &mut tr.frames[k];
            for j in 0..6 {
                (f.v[j], f.dv[j]) = sc.rates(h, f0.v[j], f0.dv[j], f0.alg[j], f.alg[j]);
            }
            se3::to_physical(self.sys, tr, k);
        }
    }
}

/// `q_{n+1} = q_n + step` of unknown `i`. A revolute angle keeps what the sum rounds off in
/// `State::carry`, and so its reduced angle ([`State::phase`]), which the angle row holds the
/// bodies to, moves by exactly the step. Otherwise the angle's `ulp` (3.6e-15 rad at 27.8 rad,
/// the windmill's 3 s) jittered each step's rotation of the hub, `1/(beta h^2)` larger in its
/// acceleration, and the collective lag's error grew as the step fell below 2.5e-5 s
/// (ARCHITECTURE.md, "No round-off the step amplifies").
#[inline]
pub(super) fn advance(angle: bool, cur: &State, tr: &mut State, i: usize, step: f64) {
    if angle {
        let (q, e) = precise::two_sum(cur.q[i], step);
        tr.q[i] = q;
        tr.carry[i] = cur.carry[i] + e;
    } else {
        tr.q[i] = cur.q[i] + step;
    }
}
