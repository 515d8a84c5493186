//! Distributed loads on a beam element: a force or a torque per unit length, in inertial
//! components or in the section's axes (follower), given at the element's inertial points.
//! Their consistent nodal loads are `int N_k f ds` (the element's Petrov-Galerkin test
//! fields); a follower value `T(xi) f*` varies with the interpolated triad, whose variation is
//! `dtheta(xi) = sum A_l dtheta_l`, so its tangent is exact through the same operators.

use super::super::forces::LoadKind;
use super::super::rotation::{M3, V3};
use super::super::timefn::TimeFn;
use serde::{Deserialize, Serialize};

/// One distributed load on an element.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Distributed {
    pub kind: LoadKind,
    /// Components in the section's axes, turning with the section.
    pub follower: bool,
    /// The value per length at each inertial point (span functions already evaluated there).
    pub values: Vec<[TimeFn; 3]>,
}

impl Distributed {
    /// The value at inertial point `point`; zero at a concentrated mass's point (past the
    /// quadrature's).
    fn value(&self, point: usize, t: f64) -> V3 {
        match self.values.get(point) {
            Some(v) => V3::new(v[0].eval(t), v[1].eval(t), v[2].eval(t)),
            None => V3::zeros(),
        }
    }
}

/// The force and the torque per length (inertial) of all loads at inertial point `point`,
/// where the section triad is `triad`.
pub(super) fn at(loads: &[Distributed], point: usize, t: f64, triad: &M3) -> (V3, V3) {
    let (mut f, mut m) = (V3::zeros(), V3::zeros());
    for l in loads {
        let v = l.value(point, t);
        let v = if l.follower { triad * v } else { v };
        match l.kind {
            LoadKind::Force => f += v,
            LoadKind::Torque => m += v,
        }
    }
    (f, m)
}

/// The follower loads' force and torque per length (inertial) at inertial point `point`: the
/// part of [`at`] that turns with the section.
pub(super) fn followers(loads: &[Distributed], point: usize, t: f64, triad: &M3) -> (V3, V3) {
    let (mut f, mut m) = (V3::zeros(), V3::zeros());
    for l in loads.iter().filter(|l| l.follower) {
        let v = triad * l.value(point, t);
        match l.kind {
            LoadKind::Force => f += v,
            LoadKind::Torque => m += v,
        }
    }
    (f, m)
}
