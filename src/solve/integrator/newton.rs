//! Newton's bookkeeping within one step, shared by the integrators: tolerances, the
//! convergence test and the divergence test (THEORY §7.3).

use crate::runtime::System;
use crate::settings::Settings;

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
    last: f64,
    growth: usize,
}

impl Newton {
    pub(super) fn new(set: &Settings, sys: &System) -> Newton {
        Newton {
            ltol: set.increment_tolerance * sys.length_scale,
            atol: set.increment_tolerance,
            floor: sys.mean_mass() * sys.length_scale,
            rtol: set.residual_tolerance,
            increment_ok: false,
            last_increment: f64::NAN,
            previous_increment: f64::NAN,
            last: f64::INFINITY,
            growth: 0,
        }
    }

    /// Converged: a small increment, a satisfied constraint, and a small residual or an
    /// increment at round-off level: 1e-3 of the increment tolerance, or a small increment that
    /// no longer shrinks (Newton's quadratic contraction has reached the noise of the residual,
    /// which holds the round-off of accelerations amplified by 1/(beta h^2) and of stiff
    /// elastic forces).
    pub(super) fn converged(&self, rnorm: f64, scale: f64, cnorm: f64) -> bool {
        let stalled =
            self.last_increment <= self.atol && self.last_increment > 0.1 * self.previous_increment;
        let settled =
            rnorm <= self.rtol * scale || self.last_increment <= 1e-3 * self.atol || stalled;
        self.increment_ok && settled && cnorm <= self.ltol
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

    /// Records the largest scaled increment of a correction.
    pub(super) fn record(&mut self, dmax: f64) {
        self.increment_ok = dmax <= self.atol;
        self.previous_increment = self.last_increment;
        self.last_increment = dmax;
    }
}
