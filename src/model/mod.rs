//! Model: AST -> validated, evaluated model with a fixed unknown ordering.
//!
//! Contract: resolves names, evaluates params and properties with their units, checks
//! dimensions and topology, and fixes the order of the unknowns (each multiplier after the
//! unknowns it couples). Reports every error it finds. Must not know integrators or faer.

mod build;
pub mod dofs;
pub mod eval;
mod params;
pub mod units;

pub use build::build;
pub use dofs::DofMap;
pub use eval::Value;

use crate::source::Span;
use serde::Serialize;

/// Command-line overrides of params and of the `solve` block.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// `--set NAME=VALUE`, parsed from their own source texts.
    pub sets: Vec<(crate::syntax::ast::Ident, crate::syntax::ast::Expr)>,
    pub integrator: Option<Integrator>,
    pub alpha: Option<f64>,
    pub dt: Option<f64>,
    pub steps: Option<usize>,
    pub until: Option<f64>,
    pub every: Option<usize>,
    pub start: Option<Start>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Model {
    pub name: String,
    pub title: Option<String>,
    pub params: Vec<(String, Value)>,
    pub gravity: [f64; 3],
    pub grounds: Vec<Ground>,
    pub bodies: Vec<Body>,
    pub joints: Vec<Joint>,
    pub outputs: Vec<OutputChannel>,
    pub solve: SolveSpec,
    pub dofs: DofMap,
}

#[derive(Clone, Debug, Serialize)]
pub struct Ground {
    pub name: String,
    pub span: Span,
}

/// A point mass: 3 translational unknowns.
#[derive(Clone, Debug, Serialize)]
pub struct Body {
    pub name: String,
    pub span: Span,
    pub mass: f64,
    pub position: [f64; 3],
    pub velocity: [f64; 3],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "on", content = "index", rename_all = "snake_case")]
pub enum Attach {
    Ground(usize),
    Body(usize),
}

/// A joint's attachment point, fixed on a ground or a body.
#[derive(Clone, Debug, Serialize)]
pub struct Marker {
    pub attach: Attach,
    /// Offset from the ground's origin (a point mass takes none).
    pub offset: [f64; 3],
    pub span: Span,
}

#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum JointKind {
    /// `|x_b - x_a| = length`: one multiplier, the link tension.
    Distance { length: f64 },
}

impl JointKind {
    pub fn multipliers(&self) -> usize {
        match self {
            JointKind::Distance { .. } => 1,
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Joint {
    pub name: String,
    pub span: Span,
    pub kind: JointKind,
    pub markers: [Marker; 2],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyQuantity {
    Position,
    Velocity,
    Acceleration,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum JointQuantity {
    /// The reaction force (for a distance joint: the tension, positive in traction).
    Force,
    /// The constraint violation (for a distance joint: length error in metres).
    Violation,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "of", rename_all = "snake_case")]
pub enum Probe {
    Body {
        body: usize,
        quantity: BodyQuantity,
        component: usize,
    },
    Joint {
        joint: usize,
        quantity: JointQuantity,
    },
}

#[derive(Clone, Debug, Serialize)]
pub struct OutputChannel {
    /// The CSV column name.
    pub column: String,
    pub probe: Probe,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    Hht,
    Fet,
}

/// How the first step starts.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Start {
    /// Accelerations and multipliers solved from the equations at t = 0 (THEORY §7.3).
    Consistent,
    /// Zero accelerations and multipliers, as the paper did (its Fig. 8).
    ZeroAcceleration,
}

#[derive(Clone, Debug, Serialize)]
pub struct SolveSpec {
    pub integrator: Integrator,
    /// HHT alpha in [-1/3, 0].
    pub alpha: f64,
    pub dt: f64,
    pub steps: usize,
    pub until: f64,
    pub every: usize,
    pub start: Start,
    /// Newton increment tolerance (relative to the model's length scale).
    pub tolerance: f64,
    pub max_iterations: usize,
    pub span: Span,
}
