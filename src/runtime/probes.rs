//! Probes: the quantities written to the output, evaluated on a state.

use super::joints::End;
use super::rotation::from_matrix;
use super::{Augment, Element, Energy, State, System};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProbeQuantity {
    Position,
    Velocity,
    Acceleration,
    AngularVelocity,
    AngularAcceleration,
    /// Direction cosines of the marker's axes: component = 3 * row + column.
    Rotation,
    /// Conformal rotation vector of the node's rotation from its initial orientation, principal
    /// state (`|c| <= 4`).
    Crv,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EnergyKind {
    Kinetic,
    Potential,
    Total,
}

/// A quantity written to the output.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "probe", rename_all = "snake_case")]
pub enum Probe {
    /// A point (a body's reference point or a marker) and its axes.
    Point {
        end: End,
        quantity: ProbeQuantity,
        component: usize,
    },
    /// The joint's force on its second end (inertial component), or for a one-row joint
    /// (`component: None`) the row's force `mu` (a distance joint's tension).
    JointForce {
        element: usize,
        component: Option<usize>,
    },
    /// The joint's moment on its second end about the marker point (inertial component).
    JointMoment {
        element: usize,
        component: usize,
    },
    /// The revolute's angle or the prismatic joint's displacement.
    JointAngle {
        element: usize,
    },
    JointRate {
        element: usize,
    },
    /// The joint's largest constraint violation.
    Violation {
        element: usize,
    },
    Energy {
        kind: EnergyKind,
    },
    /// A point between beam nodes: `sum w_k x_k` of the element's node translations (position,
    /// velocity or acceleration), with the element's shape functions as weights.
    Interpolated {
        dofs: Vec<[usize; 3]>,
        weights: Vec<f64>,
        quantity: ProbeQuantity,
        component: usize,
    },
}

impl System {
    /// The value of a probe in a state.
    pub fn probe(&self, probe: &Probe, st: &State, aug: Augment) -> f64 {
        match probe {
            Probe::Point {
                end,
                quantity,
                component,
            } => {
                let k = end.kin(st);
                let c = *component;
                match quantity {
                    ProbeQuantity::Position => k.x[c],
                    ProbeQuantity::Velocity => k.point_velocity()[c],
                    ProbeQuantity::Acceleration => k.point_acceleration()[c],
                    ProbeQuantity::AngularVelocity => k.w[c],
                    ProbeQuantity::AngularAcceleration => k.dw[c],
                    ProbeQuantity::Rotation => k.e[(c / 3, c % 3)],
                    ProbeQuantity::Crv => match end {
                        End::Node { node, .. } => from_matrix(&st.rot[*node].matrix())[c],
                        _ => 0.0,
                    },
                }
            }
            Probe::JointForce { element, component } => match &self.elements[*element] {
                Element::Joint(j) => match component {
                    Some(c) => j.reaction(st, aug).0[*c],
                    None => j.multiplier_force(st, aug, 0),
                },
                _ => f64::NAN,
            },
            Probe::JointMoment { element, component } => match &self.elements[*element] {
                Element::Joint(j) => j.reaction(st, aug).1[*component],
                _ => f64::NAN,
            },
            Probe::JointAngle { element } | Probe::JointRate { element } => {
                let rate = matches!(probe, Probe::JointRate { .. });
                match &self.elements[*element] {
                    Element::Joint(j) => match j.angle {
                        Some(i) => {
                            if rate {
                                st.v[i]
                            } else {
                                st.q[i]
                            }
                        }
                        None => {
                            let (x, v) = j.slide(st);
                            if rate {
                                v
                            } else {
                                x
                            }
                        }
                    },
                    _ => f64::NAN,
                }
            }
            Probe::Violation { element } => match &self.elements[*element] {
                Element::Joint(j) => j.violation(st),
                _ => f64::NAN,
            },
            Probe::Interpolated {
                dofs,
                weights,
                quantity,
                component,
            } => {
                let v = match quantity {
                    ProbeQuantity::Velocity => &st.v,
                    ProbeQuantity::Acceleration => &st.a,
                    _ => &st.q,
                };
                dofs.iter()
                    .zip(weights)
                    .map(|(d, w)| w * v[d[*component]])
                    .sum()
            }
            Probe::Energy { kind } => {
                let e = self.energy(st);
                match kind {
                    EnergyKind::Kinetic => e.kinetic,
                    EnergyKind::Potential => e.potential,
                    EnergyKind::Total => e.kinetic + e.potential,
                }
            }
        }
    }

    /// Kinetic energy and potential energy (gravity and springs) of a state.
    pub fn energy(&self, st: &State) -> Energy {
        let mut total = Energy::default();
        for e in &self.elements {
            let x = e.energy(st);
            total.kinetic += x.kinetic;
            total.potential += x.potential;
        }
        total
    }
}
