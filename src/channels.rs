//! What the output channels and params are, as chart axes name them: a column's unit
//! (`rad`, `m`), its quantity (`joint angle`, `z position`), a param with its unit.
//!
//! Contract: read-only questions to a `Compiled` model; `None` for a name it does not have.

use crate::{model, Compiled};

/// The unit of an output column as axes label it: `m`, `N`, `rad` for angles, `rad/s` for
/// rates of turn, or `None` for a column the model does not write.
pub fn channel_unit(c: &Compiled, column: &str) -> Option<String> {
    use model::{BodyQuantity, JointKind, JointQuantity, Probe};
    let o = c.model.outputs.iter().find(|o| o.column == column)?;
    let turning = |q: &BodyQuantity| match q {
        BodyQuantity::Crv => Some("rad"),
        BodyQuantity::Rotation => Some("1"),
        BodyQuantity::AngularVelocity => Some("rad/s"),
        BodyQuantity::AngularAcceleration => Some("rad/s^2"),
        _ => None,
    };
    let angular = match &o.probe {
        Probe::Body { quantity, .. }
        | Probe::Point { quantity, .. }
        | Probe::CenterOfMass { quantity, .. } => turning(quantity),
        Probe::Multiblade { .. } => Some("rad"),
        Probe::Joint {
            joint, quantity, ..
        } => {
            let revolute = !matches!(
                c.model.joints.get(*joint).map(|j| &j.kind),
                Some(JointKind::Prismatic { .. })
            );
            match quantity {
                JointQuantity::Angle if revolute => Some("rad"),
                JointQuantity::Rate if revolute => Some("rad/s"),
                _ => None,
            }
        }
        _ => None,
    };
    if let Some(u) = angular {
        return Some(u.to_string());
    }
    model::channel_dim(&c.model.joints, &o.probe).map(|d| d.unit())
}

/// A param as an axis names it: `Omega [1/s]`, or the bare name of a dimensionless param
/// (`Omega_bar`) or of one the model does not have.
pub fn param_label(c: &Compiled, name: &str) -> String {
    match c.model.params.iter().find(|(n, _)| n == name) {
        Some((_, model::Value::Scalar { dim, .. })) if !dim.is_none() => {
            format!("{name} [{}]", dim.unit())
        }
        _ => name.to_string(),
    }
}

/// What an output column measures, as an axis names it: `joint angle`, `z position`,
/// `reaction force`, `kinetic energy`; `None` for a column the model does not write.
pub fn channel_quantity(c: &Compiled, column: &str) -> Option<String> {
    use model::{BodyQuantity, EnergyKind, JointKind, JointQuantity, Probe};
    let o = c.model.outputs.iter().find(|o| o.column == column)?;
    let axis = |k: usize| ["x", "y", "z"].get(k).copied().unwrap_or("");
    let motion = |q: &BodyQuantity, k: usize| match q {
        BodyQuantity::Position => format!("{} position", axis(k)),
        BodyQuantity::Velocity => format!("{} velocity", axis(k)),
        BodyQuantity::Acceleration => format!("{} acceleration", axis(k)),
        BodyQuantity::AngularVelocity => format!("{} angular velocity", axis(k)),
        BodyQuantity::AngularAcceleration => format!("{} angular acceleration", axis(k)),
        BodyQuantity::Rotation => "direction cosine".to_string(),
        BodyQuantity::Crv => format!("{} rotation", axis(k)),
    };
    Some(match &o.probe {
        Probe::Body {
            quantity,
            component,
            ..
        }
        | Probe::Point {
            quantity,
            component,
            ..
        } => motion(quantity, *component),
        Probe::CenterOfMass {
            quantity,
            component,
            ..
        } => format!("centre-of-mass {}", motion(quantity, *component)),
        Probe::Joint {
            joint,
            quantity,
            component,
            ..
        } => {
            let sliding = matches!(
                c.model.joints.get(*joint).map(|j| &j.kind),
                Some(JointKind::Prismatic { .. })
            );
            let part = component
                .map(|k| format!("{} ", axis(k)))
                .unwrap_or_default();
            match quantity {
                JointQuantity::Force => format!("{part}reaction force"),
                JointQuantity::Moment => format!("{part}reaction moment"),
                JointQuantity::Angle if sliding => "joint displacement".to_string(),
                JointQuantity::Angle => "joint angle".to_string(),
                JointQuantity::Rate if sliding => "joint sliding rate".to_string(),
                JointQuantity::Rate => "joint rate".to_string(),
                JointQuantity::Violation => "constraint violation".to_string(),
            }
        }
        Probe::Energy { kind } => match kind {
            EnergyKind::Kinetic => "kinetic energy",
            EnergyKind::Potential => "potential energy",
            EnergyKind::Total => "total energy",
        }
        .to_string(),
        Probe::Multiblade { .. } => "multiblade coordinate".to_string(),
    })
}
