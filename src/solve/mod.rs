//! Solve: System -> trajectory, with the [`crate::settings::Settings`] of the run: the
//! integrators ([`Integrator`]: HHT-alpha, generalized-alpha, statics, time finite elements on
//! one Newton loop and one sparse LU), modes about a steady motion, Floquet analysis.
//!
//! Contract: drives the runtime through its generic interface (residual parts, tangent with
//! coefficients, constraint rates, rotating nodes); knows no concrete element type and no
//! spans. Failures are typed [`RuntimeFailure`]s naming the time, the step and the entity with
//! the largest residual.

pub mod floquet;
mod integrator;
pub mod linear;
pub mod modes;
mod ordering;
mod pivot_free;
pub mod sizing;
mod steady;

pub use integrator::{Integrator, Linearization, Stop};

use serde::Serialize;

/// What went wrong at run time.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureKind {
    NewtonDiverged,
    Singular,
    NonFinite,
    Unsupported,
    /// Stopped by [`interrupt`] (Ctrl-C) between steps.
    Interrupted,
    /// A redundant joint's dropped equation drifted: not redundant along the motion.
    Inconsistent,
}

static INTERRUPTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Asks every run in this process to stop after its current step (the CLI's Ctrl-C handler):
/// each ends with a [`FailureKind::Interrupted`] failure, its rows so far written.
pub fn interrupt() {
    INTERRUPTED.store(true, std::sync::atomic::Ordering::Relaxed);
}

/// Clears [`interrupt`]: a library user (the Python package) that stopped one run goes on
/// with the next.
pub fn clear_interrupt() {
    INTERRUPTED.store(false, std::sync::atomic::Ordering::Relaxed);
}

/// Whether [`interrupt`] was called.
pub fn interrupted() -> bool {
    INTERRUPTED.load(std::sync::atomic::Ordering::Relaxed)
}

/// A run-time failure: when, where and what.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RuntimeFailure {
    pub kind: FailureKind,
    /// Time at the start of the failing step [s].
    pub t: f64,
    /// Index of the failing step (1-based; 0 is the initial state).
    pub step: usize,
    /// The entity with the largest residual, or where a non-finite value appeared.
    pub entity: Option<usize>,
    pub detail: String,
}

/// Something the solver changed that the user should know (a warning).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Notice {
    pub kind: NoticeKind,
    /// The entity (joint) most involved.
    pub entity: Option<usize>,
    pub detail: String,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NoticeKind {
    VelocityProjected,
    PositionProjected,
}

/// Statistics of a run.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RunStats {
    pub steps: usize,
    pub newton_iterations: usize,
    pub halvings: usize,
    /// Steps started again from constant velocities (Newton headed for another root of the
    /// step's equations from the unchanged acceleration).
    pub repredictions: usize,
    /// Numeric factorizations of the iteration matrix (one per Newton iteration with
    /// `newton = full`; fewer when the matrix is kept).
    pub factorizations: usize,
    /// Changes of state of conformal rotation vectors (conformal treatment only).
    pub rescalings: usize,
    /// Largest |C| over all steps [m].
    pub max_constraint_violation: f64,
}
