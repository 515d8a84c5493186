//! The closed set of elements: each reports its unknowns, residual and tangent.
//!
//! Local tangent matrices are dense, row-major, over the element's `indices()` in order.

use super::beams::BeamElement;
use super::bodies::{PointMass, RigidBody};
use super::forces::{Load, Spring};
use super::joints::Joint;
use super::{Augment, Energy, MassMoments, Rate, Residual, State, TangentCoeffs};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "element", rename_all = "snake_case")]
pub enum Element {
    PointMass(PointMass),
    RigidBody(RigidBody),
    Beam(BeamElement),
    Joint(Joint),
    Spring(Spring),
    Load(Load),
}

impl Element {
    /// The unknowns this element couples, in local order.
    pub fn indices(&self) -> Vec<usize> {
        match self {
            Element::PointMass(p) => p.dofs.to_vec(),
            Element::RigidBody(b) => b.dofs.to_vec(),
            Element::Beam(b) => b.dofs.clone(),
            Element::Joint(j) => j.indices(),
            Element::Spring(s) => s.indices(),
            Element::Load(l) => l.end.dofs().to_vec(),
        }
    }

    /// Whether the tangent depends on the rates (inertia, damping).
    /// Whether the element's residual reads velocities or accelerations: inertia, damping,
    /// a joint's prescribed rate rows.
    pub fn reads_rates(&self) -> bool {
        match self {
            Element::Joint(j) => j.rows.iter().any(|r| r.is_rate()),
            _ => self.has_rates(),
        }
    }

    pub fn has_rates(&self) -> bool {
        match self {
            Element::PointMass(_) | Element::RigidBody(_) | Element::Beam(_) => true,
            Element::Spring(s) => s.damping != 0.0,
            Element::Joint(_) | Element::Load(_) => false,
        }
    }

    pub fn translational_mass(&self) -> Option<f64> {
        match self {
            Element::PointMass(p) => Some(p.mass),
            Element::RigidBody(b) => Some(b.mass),
            Element::Beam(b) => Some(b.total_mass() / b.len() as f64),
            _ => None,
        }
    }

    /// Adds this element's residual contributions.
    pub fn residual(&self, st: &State, aug: Augment, r: &mut Residual) {
        match self {
            Element::PointMass(p) => p.residual(st, r),
            Element::RigidBody(b) => b.residual(st, r),
            Element::Beam(b) => b.residual(st, r),
            Element::Joint(j) => j.residual(st, aug, r),
            Element::Spring(s) => s.residual(st, r),
            Element::Load(l) => l.residual(st, r),
        }
    }

    /// The part of [`Element::residual`] that reads the rates, with the rest as it would be
    /// or not written: a joint's rate rows alone (its forces `s lambda` and its other rows
    /// are the positions'), every other element's whole residual.
    pub fn rate_residual(&self, st: &State, aug: Augment, r: &mut Residual) {
        match self {
            Element::Joint(j) => j.rate_rows(st, aug, r),
            e => e.residual(st, aug, r),
        }
    }

    /// [`Element::residual`] into `r` and [`Element::tangent`] into `k` at one state, sharing
    /// what they both evaluate (a joint's rows' geometry, a rigid body's kinematics).
    pub fn residual_and_tangent(
        &self,
        st: &State,
        aug: Augment,
        c: TangentCoeffs,
        r: &mut Residual,
        k: &mut [f64],
    ) {
        match self {
            Element::RigidBody(b) => b.residual_and_tangent(st, c, r, k),
            Element::Joint(j) => j.residual_and_tangent(st, aug, c, r, k),
            Element::Load(l) => l.residual_and_tangent(st, c, r, k),
            e => {
                e.residual(st, aug, r);
                e.tangent(st, aug, c, k);
            }
        }
    }

    /// Writes the tangent's derivatives with respect to the accelerations (`m`: unit mass
    /// coefficient) and the velocities (`c`: unit velocity coefficient, the damping weighted
    /// by `force_weight`) into `m` and `c`, as [`Element::tangent`] with those coefficients
    /// alone writes them; a rigid body makes its kinematics once for both.
    pub fn rate_jacobians(
        &self,
        st: &State,
        aug: Augment,
        force_weight: f64,
        m: &mut [f64],
        c: &mut [f64],
    ) {
        let rates = |mass: f64, velocity: f64| TangentCoeffs {
            mass,
            velocity,
            position: 0.0,
            force_weight,
        };
        match self {
            Element::RigidBody(b) => b.rate_jacobians(st, m, c),
            e => {
                e.tangent(st, aug, rates(1.0, 0.0), m);
                e.tangent(st, aug, rates(0.0, 1.0), c);
            }
        }
    }

    /// Writes the local tangent (row-major, `indices().len()` squared) into `k`.
    pub fn tangent(&self, st: &State, aug: Augment, c: TangentCoeffs, k: &mut [f64]) {
        match self {
            Element::PointMass(p) => p.tangent(c, k),
            Element::RigidBody(b) => b.tangent(st, c, k),
            Element::Beam(b) => b.tangent(st, c, k),
            Element::Joint(j) => j.tangent(st, aug, c, k),
            Element::Spring(s) => s.tangent(st, c, k),
            Element::Load(l) => l.tangent(st, c, k),
        }
    }

    /// Adds this element's generalized momenta `P = M(q) V` and transport term `G` (THEORY
    /// §8.1): `dP/dt + G = F^I`. Elements without inertia add nothing.
    pub fn momentum(&self, st: &State, p: &mut [f64], g: &mut [f64]) {
        match self {
            Element::PointMass(m) => m.momentum(st, p),
            Element::RigidBody(b) => b.momentum(st, p, g),
            Element::Beam(b) => b.momentum(st, p, g),
            Element::Joint(_) | Element::Spring(_) | Element::Load(_) => {}
        }
    }

    /// Writes a time derivative of the constraints into `out` at multiplier rows.
    pub fn constraint_rate(&self, st: &State, rate: Rate, out: &mut [f64]) {
        if let Element::Joint(j) = self {
            j.constraint_rate(st, rate, out);
        }
    }

    /// A typical diagonal stiffness of an elastic element, for constraint scaling.
    pub fn stiffness_scale(&self) -> Option<f64> {
        match self {
            Element::Beam(b) => Some(b.stiffness_scale()),
            _ => None,
        }
    }

    /// Mass and first moments of mass (see [`MassMoments`]); `None` for elements without
    /// mass.
    pub fn mass_moments(&self, st: &State) -> Option<MassMoments> {
        match self {
            Element::PointMass(p) => Some(p.mass_moments(st)),
            Element::RigidBody(b) => Some(b.mass_moments(st)),
            Element::Beam(b) => Some(b.mass_moments(st)),
            Element::Joint(_) | Element::Spring(_) | Element::Load(_) => None,
        }
    }

    pub fn energy(&self, st: &State) -> Energy {
        match self {
            Element::PointMass(p) => p.energy(st),
            Element::RigidBody(b) => b.energy(st),
            Element::Beam(b) => b.energy(st),
            Element::Spring(s) => s.energy(st),
            Element::Joint(_) | Element::Load(_) => Energy::default(),
        }
    }
}

#[cfg(test)]
mod tests;
