//! Statics (`Method::Static`): each step is a load step, the equilibrium at that step's time
//! of the loads and prescribed motions, with no inertia and no rates. It shares the Newmark
//! family's predictor (holding the previous equilibrium), residual, correction and commit;
//! what is its own is here: the rates it zeroes and the iteration matrix's coefficients
//! (stiffness only). A failing load step is split up to 1/16 (`settings::STATIC_HALVINGS`).

use super::rotations;
use super::{Integrator, Layout};
use crate::runtime::TangentCoeffs;

impl Integrator<'_> {
    /// The iterate's rates: zero (multipliers are kept).
    pub(super) fn static_rates(&mut self) {
        let tr = &mut self.trial;
        for i in 0..self.sys.len() {
            if !self.sys.unknowns[i].is_multiplier() {
                (tr.v[i], tr.a[i], tr.alg[i]) = (0.0, 0.0, 0.0);
            }
        }
        if self.layout == Layout::Conformal {
            rotations::sync(self.sys, tr);
        }
        for k in 0..self.sys.rotations.len() {
            tr.frames[k] = Default::default();
            (tr.rot[k].w, tr.rot[k].dw) = ([0.0; 3], [0.0; 3]);
        }
    }

    /// The iteration matrix of a load step: the stiffness alone.
    pub(super) fn static_coefficients() -> TangentCoeffs {
        TangentCoeffs {
            mass: 0.0,
            velocity: 0.0,
            position: 1.0,
            force_weight: 1.0,
        }
    }
}
