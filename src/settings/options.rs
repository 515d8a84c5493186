//! The named options of a run: methods, rotation treatments, starts and Newton modes, with
//! their names in a `solve` block and on the command line.

use serde::Serialize;

/// The time integrator.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// HHT-alpha (THEORY §7.2), in the Arnold-Bruls form.
    #[default]
    Hht,
    /// Generalized-alpha, Arnold-Bruls form (THEORY §7.5).
    GeneralizedAlpha,
    /// Time finite elements: the bilinear mixed element with midpoint quadrature (THEORY §8.1).
    Fet,
    /// Static equilibrium at each step's time: steps are load steps (loads and prescribed
    /// motions as functions of time), no inertia.
    Static,
}

impl Method {
    /// Every method, with its name in a `solve` block (`solve hht { .. }`).
    pub const NAMES: [(&'static str, Method); 4] = [
        ("hht", Method::Hht),
        ("generalized_alpha", Method::GeneralizedAlpha),
        ("fet", Method::Fet),
        ("static", Method::Static),
    ];

    /// Every method, with its name on the command line (`--integrator generalized-alpha`).
    pub const FLAGS: [(&'static str, Method); 4] = [
        ("hht", Method::Hht),
        ("generalized-alpha", Method::GeneralizedAlpha),
        ("fet", Method::Fet),
        ("static", Method::Static),
    ];

    pub fn parse(name: &str) -> Option<Method> {
        Self::NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, m)| *m)
    }
}

/// How rotations are integrated (THEORY §2.7, §7.1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Rotations {
    /// Stored rotation matrices updated by incremental rotations (rigid bodies as SE(3)
    /// frames); never rescales.
    #[default]
    Incremental,
    /// The paper's: the total conformal rotation vector is the unknown, Newmark on `c`,
    /// `c-dot`, `c-ddot`, rescaled when `|c| > 4` (past pi).
    Conformal,
}

impl Rotations {
    /// Every treatment, with its name in a `solve` block and on the command line.
    pub const FLAGS: [(&'static str, Rotations); 2] = [
        ("incremental", Rotations::Incremental),
        ("conformal", Rotations::Conformal),
    ];
}

/// How the first step starts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Start {
    /// Accelerations and multipliers solved from the equations at t = 0 (THEORY §7.3).
    #[default]
    Consistent,
    /// Zero accelerations and multipliers, as the paper did (its Fig. 8).
    ZeroAcceleration,
}

impl Start {
    /// Every start, with its name on the command line (`--start zero`; in a `solve` block
    /// `start = zero_acceleration`).
    pub const FLAGS: [(&'static str, Start); 2] = [
        ("consistent", Start::Consistent),
        ("zero", Start::ZeroAcceleration),
    ];
}

/// How Newton's iteration matrix is kept (THEORY §7.3).
///
/// A kept matrix contracts linearly, so its step ends where the residual and the contraction's
/// tail are below the tolerances, not at round-off: joint loads to the residual tolerance
/// (about 1e-8 of the largest force) where a new matrix gets them to 1e-13, the constraint to
/// the increment tolerance where a new matrix meets it to round-off. On the windmill a new
/// matrix, exact for rigid frames, lands 9.5e-9 of the hub motion from the discrete equations'
/// solution at 3 s and a kept one 1.5e-6 (both against a run at tolerance 1e-12): `full`
/// stays the default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NewtonMode {
    /// A new iteration matrix at every iteration (the default); in models without beams, and
    /// in beam models while their steps converge in two iterations, a correction of at most
    /// 1e-5 is followed by one with the step's matrix, then as good as new.
    #[default]
    Full,
    /// The factored matrix kept across iterations and steps while each correction it makes
    /// is at most half the one before ([`MODIFIED_RATE`]); refactored when it is not, when the
    /// residual grows, when the step size changes, and on a halving.
    Modified,
    /// As `modified`, with the matrix kept while each correction is at most a fifth of the one
    /// before ([`AUTO_RATE`]), and only in steps where keeping it has cost less than new
    /// matrices (counted in iterations, step by step); statics always refactors.
    Auto,
}

impl NewtonMode {
    /// Every mode, with its name in a `solve` block and on the command line.
    pub const FLAGS: [(&'static str, NewtonMode); 3] = [
        ("full", NewtonMode::Full),
        ("modified", NewtonMode::Modified),
        ("auto", NewtonMode::Auto),
    ];

    /// The slowest contraction of Newton's increment at which a kept matrix is used again
    /// (0: never kept).
    pub fn keep_rate(self) -> f64 {
        match self {
            NewtonMode::Full => 0.0,
            NewtonMode::Modified => MODIFIED_RATE,
            NewtonMode::Auto => AUTO_RATE,
        }
    }
}

/// `modified` keeps the matrix while Newton contracts at least twofold an iteration.
pub const MODIFIED_RATE: f64 = 0.5;
/// `auto` keeps it while Newton contracts at least fivefold an iteration.
pub const AUTO_RATE: f64 = 0.2;
