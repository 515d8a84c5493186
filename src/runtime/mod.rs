//! Runtime: the lowered system, its state, the elements and their assembly.
//!
//! Contract: elements compute residuals and tangents from a state and coefficients that the
//! integrator supplies; the runtime is integrator-agnostic. It knows entity names (for
//! messages) but nothing of spans or files, and it never touches faer.

mod assembly;
mod elements;
pub mod timefn;

pub use assembly::{Assembler, Pattern};
pub use elements::{Anchor, Element, Rate};

use serde::{Deserialize, Serialize};

/// What an unknown is: a coordinate with inertia and Newmark relations, or a multiplier.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UnknownKind {
    Coordinate,
    Multiplier,
}

/// A named thing of the model (body or joint), for runtime messages.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Entity {
    pub name: String,
    pub kind: String,
}

/// A quantity written to the output.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "probe", rename_all = "snake_case")]
pub enum Probe {
    Position {
        index: usize,
    },
    Velocity {
        index: usize,
    },
    Acceleration {
        index: usize,
    },
    /// The physical constraint force `mu = s*lambda + p*C` of a multiplier.
    ConstraintForce {
        element: usize,
        row: usize,
    },
    ConstraintViolation {
        element: usize,
        row: usize,
    },
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Channel {
    pub column: String,
    pub probe: Probe,
}

/// The lowered system: what the solvers integrate. Serializable (`mbd check --emit ir`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct System {
    pub unknowns: Vec<UnknownKind>,
    /// The entity each unknown belongs to.
    pub owners: Vec<usize>,
    pub entities: Vec<Entity>,
    pub elements: Vec<Element>,
    pub initial: State,
    pub channels: Vec<Channel>,
    /// A length typical of the model, for scaling Newton increments.
    pub length_scale: f64,
}

impl System {
    pub fn len(&self) -> usize {
        self.unknowns.len()
    }

    pub fn is_empty(&self) -> bool {
        self.unknowns.is_empty()
    }

    /// Mean translational mass, for constraint scaling (THEORY §6).
    pub fn mean_mass(&self) -> f64 {
        let masses: Vec<f64> = self
            .elements
            .iter()
            .filter_map(|e| e.translational_mass())
            .collect();
        if masses.is_empty() {
            1.0
        } else {
            masses.iter().sum::<f64>() / masses.len() as f64
        }
    }

    /// Mean elastic stiffness diagonal, for constraint scaling (no elastic elements yet).
    pub fn mean_stiffness(&self) -> f64 {
        0.0
    }

    /// The value of a probe in a state (scaling `s`, `p` to form physical constraint forces).
    pub fn probe(&self, probe: Probe, st: &State, aug: Augment) -> f64 {
        match probe {
            Probe::Position { index } => st.q[index],
            Probe::Velocity { index } => st.v[index],
            Probe::Acceleration { index } => st.a[index],
            Probe::ConstraintForce { element, row } => {
                self.elements[element].constraint_force(st, aug, row)
            }
            Probe::ConstraintViolation { element, row } => {
                self.elements[element].violation(st, row)
            }
        }
    }
}

/// The state at one instant. All vectors have one entry per unknown; multiplier entries of
/// `q`, `v`, `a` are unused, and `lambda` is used only at multipliers.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct State {
    pub t: f64,
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    pub lambda: Vec<f64>,
}

impl State {
    pub fn zeros(n: usize) -> State {
        State {
            t: 0.0,
            q: vec![0.0; n],
            v: vec![0.0; n],
            a: vec![0.0; n],
            lambda: vec![0.0; n],
        }
    }

    /// The first unknown holding a non-finite value, if any.
    pub fn first_non_finite(&self) -> Option<usize> {
        (0..self.q.len()).find(|&i| {
            !(self.q[i].is_finite()
                && self.v[i].is_finite()
                && self.a[i].is_finite()
                && self.lambda[i].is_finite())
        })
    }
}

/// Augmented-Lagrangian scaling `s` and penalty `p` (THEORY §6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Augment {
    pub s: f64,
    pub p: f64,
}

/// Coefficients the integrator supplies to combine the element matrices:
/// `mass * M + velocity * G + position * K_inertia + force_weight * (position * K + velocity * D)`,
/// with the constraint coupling column weighted by `force_weight` and the constraint rows
/// always `s * B`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentCoeffs {
    pub mass: f64,
    pub velocity: f64,
    pub position: f64,
    pub force_weight: f64,
}

/// Residual parts, each one entry per unknown.
#[derive(Clone, Debug)]
pub struct Residual {
    /// Inertial forces `F^I`.
    pub inertia: Vec<f64>,
    /// `F^int + F^c - F^ext`.
    pub force: Vec<f64>,
    /// Constraint values `C` (or their rates) at multiplier rows.
    pub constraint: Vec<f64>,
}

impl Residual {
    pub fn new(n: usize) -> Residual {
        Residual {
            inertia: vec![0.0; n],
            force: vec![0.0; n],
            constraint: vec![0.0; n],
        }
    }

    pub fn clear(&mut self) {
        self.inertia.iter_mut().for_each(|x| *x = 0.0);
        self.force.iter_mut().for_each(|x| *x = 0.0);
        self.constraint.iter_mut().for_each(|x| *x = 0.0);
    }
}
