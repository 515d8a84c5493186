//! One step's Newton iteration: the predictor, the loop of residual, matrix (new or kept),
//! correction and convergence test, the trust region that tells another root of the step's
//! equations, and the restart from constant velocities.

use super::newton::Newton;
use super::{Integrator, Layout, StepFailure};
use crate::runtime::rotation::V3;
use crate::settings::{Method, NewtonMode};
use crate::solve::FailureKind;

/// Where a step's Newton iteration starts. A step tries first the predictor that came nearest
/// the last step's solution (`Integrator::best_predictor`): the acceleration unchanged, or
/// continued by a polynomial through the last steps' (smooth motion; [`super::history`]), or
/// the velocity unchanged where the accelerations alternate from step to step. On the paper's
/// two-bar at 0.05 s the accelerations alternate after the load reversal (at 18.5 s the
/// acceleration predictor misses the hinge by 0.16 m, the velocity predictor by 0.07 m): 3.73
/// Newton iterations a step and no halving, against 4.32 and 3 from the acceleration
/// predictor alone (3.46 with [`Newton::order`]'s test).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Predictor {
    /// The acceleration unchanged (statics: the last load step's equilibrium).
    Acceleration,
    /// The algorithmic acceleration extrapolated at this order (1 to
    /// [`super::history::ORDERS`]) from the last steps of the same size.
    Extrapolated(usize),
    /// The algorithmic acceleration continued as a polynomial of degree `d - 1` (`d` from 1
    /// to [`super::history::RINGS`]) plus the scheme's ringing (`newmark::Scheme::ringing`),
    /// through the last `d + 2` steps of the same size. On the paper's two-bar at 0.05 s
    /// (HHT, alpha = -0.1, 50 s): 3.23 Newton iterations a step and 2,798 factorizations,
    /// against 3.40 and 3,045 from the other predictors alone (at 0.0498, 0.0499 and
    /// 0.0501 s: 3.23, 3.23, 3.18 against 3.38, 3.41, 3.35).
    Ringing(usize),
    /// The velocity unchanged, for a step too long for the accelerations' changes.
    Velocity,
}

impl Predictor {
    /// The predictor a step falls back on.
    pub(super) fn other(self) -> Predictor {
        match self {
            Predictor::Acceleration | Predictor::Extrapolated(_) | Predictor::Ringing(_) => {
                Predictor::Velocity
            }
            Predictor::Velocity => Predictor::Acceleration,
        }
    }
}

/// The farthest a frame's iterate may turn from the step at constant velocities (rad): beyond
/// it, Newton has left the motion's neighbourhood for another root of the step's equations (on
/// the paper's two-bar at 0.05 s such roots turn a bar by 1.4 to 12 rad in one step, where the
/// motion turns it 0.4 rad).
const TRUST: f64 = 1.0;

impl Integrator<'_> {
    /// Keeps the iterate before a correction (the mid-configuration only for time finite
    /// elements, the only method that reads it).
    fn save(&mut self) {
        self.saved.0.assign(&self.trial);
        if self.method == Method::Fet {
            self.saved.1.assign(&self.mid);
        }
        self.saved_steps.0.copy_from_slice(&self.step_q);
        self.saved_steps.1.copy_from_slice(&self.step_frames);
    }

    /// An iterate that turns a frame farther than [`TRUST`] from the step at constant
    /// velocities is heading for another root of the step's equations than the motion's.
    fn trust(&mut self) -> Result<(), StepFailure> {
        if self.layout != Layout::Increments || self.method == Method::Static {
            return Ok(());
        }
        let turn =
            |a: &[f64; 6], b: &[f64; 6]| V3::new(a[3] - b[3], a[4] - b[4], a[5] - b[5]).norm();
        let (k, far) = self
            .step_frames
            .iter()
            .zip(&self.predicted)
            .map(|(a, b)| turn(a, b))
            .enumerate()
            .filter(|&(k, _)| self.sys.is_frame(k))
            .fold((0, 0.0f64), |m, (k, t)| if t > m.1 { (k, t) } else { m });
        if far <= TRUST {
            return Ok(());
        }
        self.far = true;
        Err(StepFailure {
            kind: FailureKind::NewtonDiverged,
            entity: Some(self.sys.owners[self.sys.rotations[k]]),
            detail: format!("Newton's iterate turned {far:.2} rad away from the step at constant velocities (more than {TRUST} rad), towards another root of the step's equations"),
        })
    }

    /// Returns to the iterate before the last correction.
    fn restore(&mut self) {
        self.trial.assign(&self.saved.0);
        if self.method == Method::Fet {
            self.mid.assign(&self.saved.1);
        }
        self.step_q.copy_from_slice(&self.saved_steps.0);
        self.step_frames.copy_from_slice(&self.saved_steps.1);
    }

    /// One step of size `h` from `cur`; on success `cur` holds the new state. The Newmark
    /// family starts from the [`Predictor`] that served the last step best; when Newton heads
    /// from there for another root of the step's equations ([`TRUST`]), the step starts again
    /// from the other predictor before it is halved. (Starting again from constant velocities
    /// after any failure costs the stiff-beam two-bar 52 more halvings: a stiff element's
    /// velocities carry its vibration.)
    pub(super) fn attempt(&mut self, h: f64) -> Result<(), StepFailure> {
        self.far = false;
        let first = self.newton(h, self.predictor);
        if first.is_ok() || !self.far {
            self.smooth &= first.is_ok();
            return first;
        }
        self.stats.repredictions += 1;
        let second = self.newton(h, self.predictor.other());
        self.smooth &= second.is_ok();
        second
    }

    /// The Newton iteration of one step from the predictor. A failed one leaves no tangent
    /// of its iterate for a later matrix to take.
    fn newton(&mut self, h: f64, predictor: Predictor) -> Result<(), StepFailure> {
        let done = self.iterate(h, predictor);
        if done.is_err() {
            self.fused = (None, false);
        }
        done
    }

    /// [`Integrator::newton`]'s iteration.
    fn iterate(&mut self, h: f64, predictor: Predictor) -> Result<(), StepFailure> {
        let aug = self.scaling(h);
        // (A step of the last one's size, the usual one, is not rescaled: no division.)
        let rescale = if aug.s == self.aug.s {
            1.0
        } else {
            self.aug.s / aug.s
        };
        let fet = self.method == Method::Fet;
        let keep_rate = self.reuse.begin();
        let factorizations = self.stats.factorizations;
        if fet {
            self.fet_predict(h, rescale);
        } else {
            self.newmark_predict(h, rescale, keep_rate > 0.0, predictor);
        }
        let mut newton = Newton::new(&self.set, self.sys, self.means.0);
        newton.as_new = self.reuse.mode() == NewtonMode::Full;
        newton.rigid = self.rigid;
        let max = self.set.max_iterations;
        // Whether the last correction came from a kept matrix, and the residual's total
        // before it.
        let (mut after_kept, mut last_total) = (false, f64::INFINITY);
        // The first residual makes the tangent with it where a new matrix follows it: under
        // `full` (no matrix kept before a correction), after a step that needed one.
        let first = !fet && self.reuse.mode() == NewtonMode::Full && self.corrected;
        self.fused = (first.then(|| self.newmark_coefficients(h)), false);
        for it in 0..=max {
            let mut r = self.residual(fet, h, aug, newton.floor)?;
            // Under kept matrices the forces count against their own entity's scale, as the
            // residual test takes them (`Newton::own`), in the contraction the matrix is kept by.
            let mut total = r.own.map_or(r.force, |x| x * r.scale) + aug.s * r.constraint;
            newton.residual_totals = (total, last_total);
            newton.own = r.own;
            if newton.converged(r.force, r.scale, r.constraint) {
                self.reuse
                    .end(it, self.stats.factorizations - factorizations);
                return self.converge(it, r.constraint, aug, h);
            }
            // A kept matrix's correction that made the residual grow is taken back, and a new
            // matrix made at the iterate before it.
            let rejected = after_kept && total > last_total;
            if rejected {
                self.restore();
                r = self.residual(fet, h, aug, newton.floor)?;
                total = r.own.map_or(r.force, |x| x * r.scale) + aug.s * r.constraint;
            }
            let what = if fet { " of the time element" } else { "" };
            let norms = (r.force, r.scale, r.constraint);
            if let Some(detail) = newton.check(it, max, total, norms, what) {
                return Err(StepFailure {
                    kind: FailureKind::NewtonDiverged,
                    entity: Some(self.sys.owners[r.worst]),
                    detail,
                });
            }
            let keep = if self.reuse.mode() == NewtonMode::Full {
                (self.rigid || self.smooth) && newton.quadratic()
            } else {
                self.kept == Some(h) && newton.rate() <= keep_rate && !newton.stuck()
            };
            let fresh = rejected || !keep;
            if fresh {
                self.refactor(h, aug, fet)?;
                self.lu.solve(&mut self.rhs)
            } else {
                // Newton's next iteration refines a kept matrix's solution.
                self.lu.solve_unrefined(&mut self.rhs)
            }
            .map_err(|e| self.singular(e))?;
            if self.layout != Layout::Conformal {
                self.limit_turn();
            }
            if !fresh {
                self.save();
            }
            let dmax = if fet {
                self.fet_correct()
            } else {
                self.newmark_correct(h)
            };
            newton.record(dmax, fresh);
            self.trust()?;
            (after_kept, last_total) = (!fresh, total);
        }
        Err(StepFailure {
            kind: FailureKind::NewtonDiverged,
            entity: None,
            detail: "Newton did not converge".to_string(),
        })
    }
}
