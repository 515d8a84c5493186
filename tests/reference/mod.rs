//! Reference solutions computed in the test code (PROBLEMS.md P2–P4, THEORY.md §10.2 items 3, 5,
//! 6): an adaptive Dormand–Prince 5(4) integrator and the reduced equations of the pendulum, the
//! articulated two-bar mechanism and the free rigid body, integrated to tight tolerance.
//!
//! Contract: plain `f64` arithmetic only. This module must not use `mbd` (nor any other crate),
//! so that a bug in the solver cannot leak into the reference it is judged against.
//!
//! Conventions (all confirmed by the unit tests in `tests.rs`):
//! - Two-bar: `e1 = (cos th1, sin th1, 0)`, `e2 = z x e1`, bar 2 along
//!   `n = cos th2 e2 + sin th2 z = Rot(e1, th2) e2`, so th2 is right-handed about e1 and
//!   `th2 = pi/2` puts bar 2 along +z. The force `F` acts along inertial +y at the junction
//!   `J = l1 e1`; the torque `T` acts on bar 2 about e1 with its reaction on bar 1.
//! - Free body: `R` maps body to inertial components (`R' = R [w]x`, `w` in the body frame),
//!   stored as a Hamilton quaternion with `q' = q (0, w) / 2`.
//! - Pendulum: theta from the bottom, counterclockwise about +z (the P2 start velocity +x at
//!   the bottom is `theta' > 0`).
//!
//! Layout: `dormand_prince` (the integrator); `two_bar`, `rigid_body`, `pendulum` and
//! `windmill` (the equations of motion, each integrated with `dopri`); `tests` (the unit tests of
//! the first four). `windmill` is public as a module, since its P5 parameters (`MB`, `E`, ...)
//! are used by name in `tests/rotor.rs`.

mod dormand_prince;
mod pendulum;
mod rigid_body;
mod two_bar;
pub mod windmill;

pub use dormand_prince::{dopri, dopri_breaks};
pub use pendulum::pendulum;
pub use rigid_body::free_body;
pub use two_bar::{TwoBar, TwoBarState};

#[cfg(test)]
mod tests;
