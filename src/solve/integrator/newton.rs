//! Newton's bookkeeping within one step, shared by the integrators: tolerances, the
//! convergence test and the divergence test (THEORY §7.3).

use crate::runtime::System;
use crate::settings::{Method, NewtonMode, Settings};

/// Newton's bookkeeping within one step, shared by the integrators (THEORY §7.3).
pub(super) struct Newton {
    /// Constraint tolerance (m), increment tolerance (relative), force floor of the residual.
    ltol: f64,
    atol: f64,
    pub(super) floor: f64,
    rtol: f64,
    increment_ok: bool,
    last_increment: f64,
    previous_increment: f64,
    /// The increment before `previous_increment`, and how many corrections in a row, ending
    /// with the last, new matrices made.
    before_increment: f64,
    fresh_run: usize,
    last: f64,
    growth: usize,
    /// Whether the last correction came from a matrix made at its iterate.
    fresh: bool,
    /// A kept matrix is as good as new (`newton = full` keeps one only after a correction of
    /// at most [`WITHIN`]).
    pub(super) as_new: bool,
    /// The model has no elastic elements: a kept matrix's measured contraction may end a
    /// step above the increment tolerance.
    pub(super) rigid: bool,
    /// The residual's totals after the last correction and before it, whose ratio is its
    /// contraction: a kept matrix's rate after the first correction of a step, where no two
    /// increments measure it yet. A tracked windmill step whose first correction (4e-12)
    /// leaves the residual within the tolerance ends there (its second, measured, contracted
    /// 5e-3). Divided only where it is read (the division was 1.5 % of a pendulum step).
    pub(super) residual_totals: (f64, f64),
    /// Kept matrices' corrections in a row that [`Newton::stuck`] found stalled.
    stalls: usize,
    /// Under kept matrices, the residual's largest force over its own entity's scale (the
    /// largest inertial or applied force on the entity, at least the force floor), which
    /// the residual test then holds to the tolerance instead of the largest force over the
    /// largest of all. A kept matrix's step ends at the residual tolerance where a new
    /// matrix's quadratic contraction overshoots it, and on the windmill the largest force
    /// is a blade's centrifugal load (about 5 kN) while the hub's is about 1 N: against the
    /// largest, `auto` ended its steps up to 1.5e-6 of the hub's motion off the discrete
    /// solution, against its own 1.1e-7 (full: 6e-11).
    pub(super) own: Option<f64>,
}

/// `newton = full` keeps the step's matrix for the next correction after a new matrix's
/// correction at most this large (scaled): the matrix then differs from one made at the new
/// iterate by about this much, relative, and contracts the next correction about as far
/// (factorizations and iterations a step: the two-bar at 1 ms over 50 s 1.08 and 2.02, 1.16
/// and 2.02 with 1e-6, 2.02 and 2.02 without; the spin-up windmill 1.02 and 2.01, 1.54 and
/// 2.00 with 1e-6; P3 at 0.05 s 3.20 and 3.74, 3.36 and 3.73 with 1e-6, before the test of
/// the contraction's order, [`Newton::order`]). Beam models keep it
/// only while their steps converge in two iterations (`Integrator::smooth`).
const WITHIN: f64 = 1e-5;

/// A kept matrix's step is converged only when the geometric tail of its corrections (what the
/// linear contraction leaves, `d rate / (1 - rate)`) is below this fraction of the increment
/// tolerance, so that it stops as close to the solution as a new matrix's (THEORY §7.3).
const TAIL: f64 = 1e-2;

/// Stalled kept corrections in a row after which [`Newton::stuck`] asks for a new matrix.
const STALLS: usize = 2;

impl Newton {
    /// The bookkeeping of a step of `sys` under `set`, whose mean translational mass is
    /// `mean_mass` ([`System::mean_mass`]).
    pub(super) fn new(set: &Settings, sys: &System, mean_mass: f64) -> Newton {
        let length = sys.length_scale;
        let tolerances = [set.increment_tolerance, set.residual_tolerance];
        Newton::with(tolerances, length, mean_mass * length)
    }

    /// The bookkeeping of a step before its first correction, at increment and residual
    /// tolerances, the length scale and the residual's force floor.
    fn with([atol, rtol]: [f64; 2], length: f64, floor: f64) -> Newton {
        Newton {
            ltol: atol * length,
            atol,
            floor,
            rtol,
            increment_ok: false,
            last_increment: f64::NAN,
            previous_increment: f64::NAN,
            before_increment: f64::NAN,
            fresh_run: 0,
            last: f64::INFINITY,
            growth: 0,
            fresh: true,
            as_new: false,
            rigid: false,
            residual_totals: (0.0, f64::INFINITY),
            stalls: 0,
            own: None,
        }
    }

    /// Converged: a small increment, a satisfied constraint, and a small residual or an
    /// increment at round-off level: 1e-3 of the increment tolerance, or a small increment that
    /// no longer shrinks (Newton's quadratic contraction has reached the noise of the residual,
    /// which holds the round-off of accelerations amplified by 1/(beta h^2) and of stiff
    /// elastic forces). After a kept matrix's correction, which contracts linearly, the
    /// residual must be small and the contraction's tail below [`TAIL`] of the tolerance (its
    /// rate, after a step's first correction, the residual's: [`Newton::residual_totals`]); on a
    /// rigid model such a tail ends the step even above the increment tolerance, as a new
    /// matrix's does.
    pub(super) fn converged(&self, rnorm: f64, scale: f64, cnorm: f64) -> bool {
        let small = self.increment_ok && cnorm <= self.ltol;
        let noise = self.at_noise();
        if !self.fresh {
            let rate = if self.previous_increment.is_nan() {
                self.residual_totals.0 / self.residual_totals.1
            } else {
                self.rate()
            };
            let tail = noise
                || (rate > 0.0 && rate < 1.0)
                    && self.last_increment * rate / (1.0 - rate) <= TAIL * self.atol;
            // A matrix kept as good as new (`full`) settles as a new one does: at an
            // increment at round-off the residual is at its noise.
            let settled = self.within(rnorm, scale) || (self.as_new && noise);
            // As after a new matrix's, a correction above the tolerance ends a rigid model's
            // step when the contraction it measured against the step's correction before it
            // (not the residual's, after a step's first) leaves a tail below TAIL of the
            // tolerance (the pendulum at 0.02 s: 102 iterations and 58 factorizations
            // instead of 124 and 80). A beam's stiff forces make a kept matrix's tail less
            // certain: the rotating beam's step then differs from its derivative 7.4e-11
            // instead of 1.9e-11 (`the_carried_direction_is_the_derivative_of_a_step`).
            let contracted = self.rigid
                && !self.previous_increment.is_nan()
                && tail
                && self.within(rnorm, scale)
                && cnorm <= self.ltol;
            return (small && tail && settled) || contracted;
        }
        let stalled =
            self.last_increment <= self.atol && self.last_increment > 0.1 * self.previous_increment;
        let settled = self.within(rnorm, scale) || noise || stalled;
        // The contraction measured over the last two corrections bounds what is left: a
        // correction above the tolerance may end the step when its tail is below TAIL of it.
        // Over three new matrices' corrections the contraction's order shows too (THEORY §7.3).
        let theta = self.last_increment / self.previous_increment;
        let contracted = theta < 1.0
            && self.last_increment * theta.powf(self.order(theta)) / (1.0 - theta)
                <= TAIL * self.atol
            && self.within(rnorm, scale);
        (small && settled) || (contracted && cnorm <= self.ltol)
    }

    /// Whether the residual is within its tolerance: its largest force over the largest of
    /// all, or under kept matrices over its own entity's scale ([`Newton::own`]).
    fn within(&self, rnorm: f64, scale: f64) -> bool {
        match self.own {
            Some(relative) => relative <= self.rtol,
            None => rnorm <= self.rtol * scale,
        }
    }

    /// The order p of the contraction over the last three corrections when new matrices made
    /// them all: the last contraction theta is about the one before to the power p, so what is
    /// left after the last correction is about `d theta^p` (Newton's quadratic contraction
    /// p = 2, a linear one p = 1). Clamped to [1, 2], and 1 (linear) unless measured.
    fn order(&self, theta: f64) -> f64 {
        let before = self.previous_increment / self.before_increment;
        if self.fresh_run < 3 || !(before > 0.0 && before < 1.0 && theta > 0.0) {
            return 1.0;
        }
        (theta.ln() / before.ln()).clamp(1.0, 2.0)
    }

    /// Whether the last correction came from a new matrix and was small enough that the same
    /// matrix contracts the next one by about as much as a new one would ([`WITHIN`]).
    pub(super) fn quadratic(&self) -> bool {
        self.fresh && self.last_increment <= WITHIN
    }

    /// The contraction of the last correction: its increment over the one before (0 before
    /// the second correction of a step, and at round-off level, 1e-3 of the tolerance, where
    /// it is not measurable; infinite after a zero increment).
    pub(super) fn rate(&self) -> f64 {
        if self.previous_increment.is_nan() || self.at_noise() {
            0.0
        } else if self.previous_increment > 0.0 {
            self.last_increment / self.previous_increment
        } else {
            f64::INFINITY
        }
    }

    /// Whether the last correction is at round-off: 1e-3 of the increment tolerance.
    fn at_noise(&self) -> bool {
        self.last_increment <= 1e-3 * self.atol
    }

    /// Whether kept matrices' last [`STALLS`] corrections were at round-off and each left the
    /// residual's total where it was (not halved): the residual is at its noise floor, above
    /// its tolerance, where only a new matrix's correction, whose increment at round-off
    /// settles the step, ends it. (The two-bar at 0.39 ms under `auto` kept its matrix through
    /// 25 such corrections, its residual held at 1.681e-8 against 8.944e-9, and halved 9 times
    /// in 50 s. After one stalled correction, not two, the windmill at Omega_bar 2 made 3,744
    /// matrices instead of 1,605, and took 135 ms instead of 116: its floor lies about its
    /// tolerance, and a further kept correction usually ends the step.)
    pub(super) fn stuck(&mut self) -> bool {
        let stalled = !self.fresh
            && self.at_noise()
            && self.residual_totals.0 >= 0.5 * self.residual_totals.1;
        self.stalls = if stalled { self.stalls + 1 } else { 0 };
        self.stalls >= STALLS
    }

    /// Records a residual norm that did not converge; after the last allowed iteration, or when
    /// the norm grew three times in a row, the failure's description.
    pub(super) fn check(
        &mut self,
        it: usize,
        max: usize,
        total: f64,
        (rnorm, scale, cnorm): (f64, f64, f64),
        what: &str,
    ) -> Option<String> {
        self.growth = if total > self.last {
            self.growth + 1
        } else {
            0
        };
        self.last = total;
        (self.growth >= 3 || it == max).then(|| {
            format!(
                "Newton {} after {it} iteration(s){what} (residual {rnorm:.3e} against {:.3e}; constraint violation {cnorm:.3e} m and last increment {:.3e} against {:.3e})",
                if self.growth >= 3 { "diverged" } else { "did not converge" },
                self.rtol * scale,
                self.last_increment,
                self.atol
            )
        })
    }

    /// Records a correction: the largest scaled increment of the unknowns, and whether its
    /// matrix was made at its iterate.
    pub(super) fn record(&mut self, dmax: f64, fresh: bool) {
        self.fresh = fresh;
        self.fresh_run = if fresh { self.fresh_run + 1 } else { 0 };
        self.increment_ok = dmax <= self.atol;
        self.before_increment = self.previous_increment;
        self.previous_increment = self.last_increment;
        self.last_increment = dmax;
    }
}

/// A new iteration (the tangent, the factorization, a refined substitution and the residual)
/// costs about this many kept ones (a residual and a substitution): measured 3.1 on the
/// two-bar, 4 on the windmill, 5.7 on a 1,000-link chain.
const FRESH_COST: f64 = 3.0;

/// Steps with new matrices after a kept step that cost more, doubling up to this many while
/// kept steps keep losing.
const MAX_BACKOFF: usize = 64;

/// Kept steps between two steps with new matrices, which measure what those cost now.
const REMEASURE: usize = 256;

/// Whether a step may keep the iteration matrix, by the settings' mode; `auto` chooses step
/// by step from what the last steps cost, counted in kept iterations ([`FRESH_COST`] for a new
/// one): a step with new matrices measures their cost, and a kept step that costs more sends
/// the next steps (1, 2, 4, ... up to [`MAX_BACKOFF`]) back to new matrices. Counts, not
/// clocks, so a run's result does not depend on the machine's load.
pub(super) struct Reuse {
    mode: NewtonMode,
    full_cost: Option<f64>,
    backoff: usize,
    next_backoff: usize,
    since_full: usize,
    keeping: bool,
}

impl Reuse {
    /// Statics' load steps always refactor under `auto`: its tests meet the exact linear
    /// deflection to 4e-11, which a kept matrix (3.7e-10) does not.
    pub(super) fn new(mode: NewtonMode, method: Method) -> Reuse {
        Reuse {
            mode: match (mode, method) {
                (NewtonMode::Auto, Method::Static) => NewtonMode::Full,
                _ => mode,
            },
            full_cost: None,
            backoff: 0,
            next_backoff: 1,
            since_full: 0,
            keeping: false,
        }
    }

    /// The mode in force (`auto` is `full` for statics).
    pub(super) fn mode(&self) -> NewtonMode {
        self.mode
    }

    /// The slowest contraction at which the step about to be taken uses a kept matrix again.
    pub(super) fn begin(&mut self) -> f64 {
        self.keeping = match self.mode {
            NewtonMode::Full => false,
            NewtonMode::Modified => true,
            NewtonMode::Auto => {
                self.full_cost.is_some() && self.backoff == 0 && self.since_full < REMEASURE
            }
        };
        if self.keeping {
            self.mode.keep_rate()
        } else {
            0.0
        }
    }

    /// The step converged after `iterations`, `factorizations` of them with new matrices.
    pub(super) fn end(&mut self, iterations: usize, factorizations: usize) {
        if self.mode != NewtonMode::Auto {
            return;
        }
        let fresh = factorizations.min(iterations) as f64;
        let cost = (iterations as f64 - fresh) + FRESH_COST * fresh;
        if !self.keeping {
            self.full_cost = Some(cost);
            self.backoff = self.backoff.saturating_sub(1);
            self.since_full = 0;
            return;
        }
        self.since_full += 1;
        if self.full_cost.is_some_and(|full| cost > full) {
            self.backoff = self.next_backoff;
            self.next_backoff = (2 * self.next_backoff).min(MAX_BACKOFF);
        } else {
            self.next_backoff = 1;
        }
    }
}

/// The larger of `m` and `a`, ignoring a NaN `a` as `f64::max` does, in one `maxsd` (the NaN
/// handling of `f64::max` was a quarter of the residual's norms).
#[inline(always)]
pub(super) fn larger(m: f64, a: f64) -> f64 {
    if a > m {
        a
    } else {
        m
    }
}

#[cfg(test)]
mod tests {
    use super::Newton;

    /// Bookkeeping at a tolerance of 1e-10 after new matrices' corrections of these sizes.
    fn after(increments: &[f64]) -> Newton {
        let mut newton = Newton::with([1e-10, 1e-8], 1.0, 1.0);
        for &d in increments {
            newton.record(d, true);
        }
        newton
    }

    /// The last two corrections, 1e-3 then 1e-7, leave 1e-11 by a linear contraction (above
    /// TAIL of the tolerance, 1e-12) and 1e-15 by a quadratic one: the correction before them
    /// tells which.
    #[test]
    fn the_contraction_order_decides_what_the_last_correction_leaves() {
        let quadratic = after(&[1e-1, 1e-3, 1e-7]);
        assert!((quadratic.order(1e-4) - 2.0).abs() < 1e-12);
        assert!(quadratic.converged(1e-12, 1.0, 0.0));
        // Contracting by 1e-4 twice is linear: what is left is 1e-11.
        let linear = after(&[10.0, 1e-3, 1e-7]);
        assert!((linear.order(1e-4) - 1.0).abs() < 1e-12);
        assert!(!linear.converged(1e-12, 1.0, 0.0));
        // Two corrections do not measure the order.
        let two = after(&[1e-3, 1e-7]);
        assert_eq!(two.order(1e-4), 1.0);
        assert!(!two.converged(1e-12, 1.0, 0.0));
        // A kept matrix's correction in the three breaks the measurement.
        let mut kept = after(&[1e-1, 1e-3]);
        kept.record(1e-7, false);
        kept.record(1e-9, true);
        assert_eq!(kept.order(1e-2), 1.0);
    }

    /// A kept matrix's correction of 6.5e-10 after a new one's of 5.8e-6 (the pendulum at
    /// 0.02 s) contracted by 1.1e-4: it leaves about 7e-14, below TAIL of the tolerance, and
    /// ends a rigid model's step with the residual small, though above the tolerance of 1e-10.
    #[test]
    fn a_kept_matrix_contraction_ends_a_rigid_step_above_the_tolerance() {
        let step = |rigid: bool| {
            let mut newton = after(&[5.8e-6]);
            newton.rigid = rigid;
            newton.record(6.5e-10, false);
            newton
        };
        assert!(step(true).converged(1e-10, 1.0, 0.0));
        // Not with the residual above its tolerance, nor a constraint violated, nor on a
        // model with beams.
        assert!(!step(true).converged(1e-7, 1.0, 0.0));
        assert!(!step(true).converged(1e-10, 1.0, 1e-9));
        assert!(!step(false).converged(1e-10, 1.0, 0.0));
        // A contraction of 1e-2 leaves 6.6e-12, above TAIL of the tolerance.
        let mut slow = after(&[6.5e-8]);
        slow.rigid = true;
        slow.record(6.5e-10, false);
        assert!(!slow.converged(1e-10, 1.0, 0.0));
    }
}
