//! The types of component parameters: `blades: int`, `hinge_offset: length`, `hub: marker`.
//!
//! Contract: parses a parameter type and checks a value against it; must not know scopes.

use crate::model::eval::units::{self, Dim, Quantity};
use crate::model::eval::Value;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamType {
    Int,
    /// `true` or `false` (1 or 0).
    Bool,
    /// A scalar of this dimension (named as the quantity), constant or varying in time.
    Scalar(Quantity),
    /// A vector of this dimension.
    Vector(Dim, &'static str),
    /// A dimensionless non-zero vector, normalised.
    Direction,
    /// A scalar of any dimension, constant or varying in time.
    Function,
    /// A point on a body or ground, written as a path: `tower.tip`, `earth`.
    Marker,
    /// A body, written as a path.
    Body,
    /// A beam section, written as a path.
    Section,
}

/// Every type name, its type, and an example for hints.
pub const TYPES: &[(&str, ParamType, &str)] = &[
    ("int", ParamType::Int, "4"),
    ("bool", ParamType::Bool, "true"),
    (
        "real",
        ParamType::Scalar(Quantity::new(Dim::NONE, "a real number", "", "0.5")),
        "0.5",
    ),
    ("angle", ParamType::Scalar(units::ANGLE), "30 deg"),
    ("length", ParamType::Scalar(Dim::LENGTH.quantity()), "0.3 m"),
    ("mass", ParamType::Scalar(Dim::MASS.quantity()), "20 kg"),
    ("time", ParamType::Scalar(Dim::TIME.quantity()), "0.5 s"),
    (
        "velocity",
        ParamType::Scalar(Dim::VELOCITY.quantity()),
        "1.5 m/s",
    ),
    (
        "acceleration",
        ParamType::Scalar(Dim::ACCELERATION.quantity()),
        "9.81 m/s^2",
    ),
    (
        "angular_velocity",
        ParamType::Scalar(Dim::new(0, 0, -1).quantity()),
        "98.17 rad/s",
    ),
    (
        "frequency",
        ParamType::Scalar(units::FREQUENCY),
        "9.26 rad/s",
    ),
    ("force", ParamType::Scalar(Dim::FORCE.quantity()), "20 N"),
    ("torque", ParamType::Scalar(units::TORQUE), "2.5 kN*m"),
    (
        "stiffness",
        ParamType::Scalar(Dim::new(1, 0, -2).quantity()),
        "15434 N/m",
    ),
    (
        "torsional_stiffness",
        ParamType::Scalar(units::TORSIONAL_STIFFNESS),
        "14 N*m/rad",
    ),
    (
        "damping",
        ParamType::Scalar(Dim::new(1, 0, -1).quantity()),
        "100 N*s/m",
    ),
    (
        "torsional_damping",
        ParamType::Scalar(Dim::new(1, 2, -1).quantity()),
        "2 N*m*s/rad",
    ),
    (
        "inertia",
        ParamType::Scalar(Dim::new(1, 2, 0).quantity()),
        "48.6 kg*m^2",
    ),
    (
        "mass_per_length",
        ParamType::Scalar(Dim::new(1, -1, 0).quantity()),
        "3.29 kg/m",
    ),
    (
        "bending_stiffness",
        ParamType::Scalar(Dim::new(1, 3, -2).quantity()),
        "1.28e4 N*m^2",
    ),
    (
        "axial_stiffness",
        ParamType::Scalar(units::AXIAL_STIFFNESS),
        "8.53e7 N",
    ),
    (
        "pressure",
        ParamType::Scalar(Dim::new(1, -1, -2).quantity()),
        "70 GPa",
    ),
    (
        "position",
        ParamType::Vector(Dim::LENGTH, "position"),
        "(0, 0, 3.6) m",
    ),
    (
        "vector",
        ParamType::Vector(Dim::NONE, "vector"),
        "(1, 0, 0)",
    ),
    ("direction", ParamType::Direction, "z or (0, 0, 1)"),
    (
        "function",
        ParamType::Function,
        "ramp(0 s, 0.5 s) * 2.5 kN*m",
    ),
    ("marker", ParamType::Marker, "tower.tip"),
    ("body", ParamType::Body, "hub"),
    ("section", ParamType::Section, "blade_section"),
];

impl ParamType {
    pub fn parse(name: &str) -> Option<ParamType> {
        TYPES.iter().find(|t| t.0 == name).map(|t| t.1)
    }

    pub fn name(&self) -> &'static str {
        TYPES
            .iter()
            .find(|t| t.1 == *self)
            .map(|t| t.0)
            .unwrap_or("value")
    }

    /// Marker, body and section arguments are references, resolved where they are used.
    pub fn is_reference(&self) -> bool {
        matches!(
            self,
            ParamType::Marker | ParamType::Body | ParamType::Section
        )
    }

    pub fn describe(&self) -> String {
        match self {
            ParamType::Int => "a whole number".to_string(),
            ParamType::Bool => "`true` or `false`".to_string(),
            ParamType::Scalar(q) => q.describe(),
            ParamType::Vector(d, _) if d.is_none() => "a dimensionless vector".to_string(),
            ParamType::Vector(d, n) => format!("a {n} vector [{}]", d.unit()),
            ParamType::Direction => "a direction (a non-zero dimensionless vector)".to_string(),
            ParamType::Function => "a scalar or a function of time".to_string(),
            ParamType::Marker => "a marker".to_string(),
            ParamType::Body => "a body".to_string(),
            ParamType::Section => "a section".to_string(),
        }
    }

    pub fn example(&self) -> String {
        let ex = TYPES
            .iter()
            .find(|t| t.1 == *self)
            .map(|t| t.2)
            .unwrap_or("...");
        format!("give {}, e.g. `{ex}`", self.describe())
    }

    /// Checks a value against the type; `Err` describes what was found.
    pub fn accepts(&self, v: &Value) -> Result<(), String> {
        let found = || match v {
            Value::Scalar { dim, .. } => dim.describe(),
            Value::Vector { dim, .. } if dim.is_none() => "a dimensionless vector".to_string(),
            Value::Vector { dim, .. } => format!("a vector in [{}]", dim.unit()),
            Value::Signal { parts, dim } if parts.len() == 1 => {
                format!("{}, varying in time", dim.describe())
            }
            Value::Signal { dim, .. } => format!("a vector in [{}], varying in time", dim.unit()),
            Value::Rotation { .. } => "a rotation".to_string(),
        };
        let ok = match (self, v) {
            (ParamType::Int, Value::Scalar { value, dim }) => dim.is_none() && value.fract() == 0.0,
            (ParamType::Bool, Value::Scalar { value, dim }) => {
                dim.is_none() && (*value == 0.0 || *value == 1.0)
            }
            (ParamType::Scalar(q), Value::Scalar { dim, .. }) => q.dim == *dim,
            (ParamType::Scalar(q), Value::Signal { parts, dim }) => {
                parts.len() == 1 && q.dim == *dim
            }
            (ParamType::Vector(d, _), Value::Vector { dim, .. }) => d == dim,
            (ParamType::Vector(d, _), Value::Signal { parts, dim }) => parts.len() == 3 && d == dim,
            (ParamType::Direction, Value::Vector { value, dim }) => {
                dim.is_none() && value.iter().any(|x| *x != 0.0)
            }
            (ParamType::Function, Value::Scalar { .. }) => true,
            (ParamType::Function, Value::Signal { parts, .. }) => parts.len() == 1,
            _ => false,
        };
        if ok {
            Ok(())
        } else {
            Err(found())
        }
    }
}
