//! Solve: System -> trajectory. Newton, HHT-alpha, generalized-alpha and time finite elements,
//! sparse LU reuse.
//!
//! Contract: drives the runtime through its generic interface (residual parts, tangent with
//! coefficients, constraint rates, rotating nodes); knows no concrete element type and no
//! spans. Failures are typed [`RuntimeFailure`]s naming the time, the step and the entity with
//! the largest residual.

pub mod floquet;
mod integrator;
pub mod linear;
pub mod modes;
mod newton;
mod rotations;
mod se3;
mod start;
mod steady;

pub use integrator::Integrator;

use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// HHT-alpha (THEORY §7.2).
    Hht,
    /// Generalized-alpha, Arnold-Bruls form (THEORY §7.5).
    GeneralizedAlpha,
    /// Time finite elements: the bilinear mixed element with midpoint quadrature (THEORY §8.1).
    Fet,
    /// Static equilibrium at each step's time: steps are load steps (loads and prescribed
    /// motions as functions of time), no inertia.
    Static,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StartMode {
    /// Solve consistent accelerations and multipliers at t = 0 (THEORY §7.3).
    Consistent,
    /// Start from zero accelerations and multipliers (the paper's start, Fig. 8).
    ZeroAcceleration,
}

/// How rotations are integrated (THEORY §2.7, §7.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RotationTreatment {
    /// A stored rotation matrix updated by incremental rotations; Newmark on the rotation
    /// increment, angular velocity and acceleration. Never rescales.
    Incremental,
    /// The paper's: the total conformal rotation vector is the unknown, Newmark on `c`,
    /// `c-dot`, `c-ddot`, with the change of state when `|c| > 4`.
    Conformal,
}

/// Solver settings. Every field: default, range, effect.
#[derive(Clone, Debug, Serialize)]
pub struct Settings {
    /// Time integrator. Default HHT.
    pub method: Method,
    /// HHT alpha, in [-1/3, 0]. Default -0.1. More negative damps high frequencies more
    /// (spectral radius at infinity (1+alpha)/(1-alpha)); 0 is the trapezoidal rule.
    pub alpha: f64,
    /// Generalized-alpha spectral radius at infinity, in [0, 1]. Default 0.8.
    pub rho_inf: f64,
    /// Rotation treatment. Default incremental.
    pub rotation: RotationTreatment,
    /// Time step [s], > 0. Default from the model's `solve` block.
    pub dt: f64,
    /// Number of steps, >= 1; the run ends at `steps * dt`.
    pub steps: usize,
    /// Write every K-th step (K >= 1). Default 1.
    pub every: usize,
    /// How to start. Default consistent.
    pub start: StartMode,
    /// Newton increment tolerance relative to the model's length scale (and in radians for
    /// rotations), in (0, 1e-2). Default 1e-10; also bounds the constraint violation.
    pub increment_tolerance: f64,
    /// Residual tolerance relative to the largest force of the step. Default 1e-8.
    pub residual_tolerance: f64,
    /// Newton iterations per step before the step is halved. Default 25.
    pub max_iterations: usize,
    /// How many times a failing step is halved before the run fails. Default 1.
    pub max_halvings: usize,
}

/// What went wrong at run time.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureKind {
    NewtonDiverged,
    Singular,
    NonFinite,
    Unsupported,
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
    /// Changes of state of conformal rotation vectors (conformal treatment only).
    pub rescalings: usize,
    /// Largest |C| over all steps [m].
    pub max_constraint_violation: f64,
}
