//! Probes: the quantities written to the output, evaluated on a state.

use super::joints::{End, EndKin};
use super::rotation::{from_matrix, V3};
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

/// One multiblade (Coleman) coordinate of `N` blade coordinates `zeta_k` at azimuths
/// `psi_k = psi + 2 pi k / N` (THEORY §9.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "coordinate", rename_all = "snake_case")]
pub enum Coleman {
    /// `zeta_0 = (1/N) sum zeta_k`.
    Collective,
    /// `zeta_nc = (2/N) sum zeta_k cos(n psi_k)`.
    Cosine { harmonic: usize },
    /// `zeta_ns = (2/N) sum zeta_k sin(n psi_k)`.
    Sine { harmonic: usize },
    /// `zeta_d = (1/N) sum zeta_k (-1)^k`, for even `N`.
    Differential,
}

impl Coleman {
    /// The coordinates of `n` blades, in column order: `0`, `1c`, `1s`, `2c`, ..., `d`. Odd
    /// `n` has harmonics 1 to (n - 1)/2, even `n` harmonics 1 to n/2 - 1 and the differential
    /// coordinate, so there are always `n` of them and the transform is invertible.
    pub fn all(n: usize) -> Vec<Coleman> {
        let mut out = vec![Coleman::Collective];
        for h in 1..=(n.saturating_sub(1) / 2) {
            out.push(Coleman::Cosine { harmonic: h });
            out.push(Coleman::Sine { harmonic: h });
        }
        if n.is_multiple_of(2) {
            out.push(Coleman::Differential);
        }
        out
    }

    /// The column suffix: `0`, `1c`, `1s`, ..., `d`.
    pub fn suffix(self) -> String {
        match self {
            Coleman::Collective => "0".to_string(),
            Coleman::Cosine { harmonic } => format!("{harmonic}c"),
            Coleman::Sine { harmonic } => format!("{harmonic}s"),
            Coleman::Differential => "d".to_string(),
        }
    }

    /// The coordinate of blade values `zeta` at rotor azimuth `psi`.
    pub fn of(self, zeta: &[f64], psi: f64) -> f64 {
        self.of_blades(zeta.len(), |k| zeta[k], psi)
    }

    /// The coordinate of `n` blade values `zeta(k)` at rotor azimuth `psi`, without
    /// gathering them (a probe at every written row).
    pub fn of_blades(self, n: usize, zeta: impl Fn(usize) -> f64, psi: f64) -> f64 {
        let count = n as f64;
        let azimuth = |k: usize| psi + std::f64::consts::TAU * k as f64 / count;
        let sum = |w: &dyn Fn(usize) -> f64| -> f64 { (0..n).map(|k| zeta(k) * w(k)).sum() };
        match self {
            Coleman::Collective => sum(&|_| 1.0) / count,
            Coleman::Cosine { harmonic } => {
                2.0 / count * sum(&|k| (harmonic as f64 * azimuth(k)).cos())
            }
            Coleman::Sine { harmonic } => {
                2.0 / count * sum(&|k| (harmonic as f64 * azimuth(k)).sin())
            }
            Coleman::Differential => sum(&|k| if k % 2 == 0 { 1.0 } else { -1.0 }) / count,
        }
    }
}

/// The mass of a set of elements and its first moments: `sum m`, and the sums of `m` times
/// the position, velocity and acceleration of each mass centre (inertial). A rigid body's
/// centre is `x + R eta0`; a beam's distributed mass is integrated at the element's inertial
/// quadrature points, the points its mass matrix uses.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MassMoments {
    pub mass: f64,
    pub position: V3,
    pub velocity: V3,
    pub acceleration: V3,
}

impl std::ops::AddAssign for MassMoments {
    fn add_assign(&mut self, o: MassMoments) {
        self.mass += o.mass;
        self.position += o.position;
        self.velocity += o.velocity;
        self.acceleration += o.acceleration;
    }
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
    /// The force the joint applies on its second end (inertial component, or in the axes of
    /// `axes` as they turn), or for a one-row joint (`component: None`) the row's force `mu`
    /// (a distance joint's tension).
    JointForce {
        element: usize,
        component: Option<usize>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        axes: Option<End>,
    },
    /// The moment the joint applies on its second end about its marker point (inertial
    /// component, or in the axes of `axes`).
    JointMoment {
        element: usize,
        component: usize,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        axes: Option<End>,
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
    /// Multiblade coordinate `coordinate` of the angles of the revolute joints `blades` (in
    /// order: blade k at azimuth `psi + 2 pi k / N`), with `psi` the angle of joint `azimuth`.
    Multiblade {
        blades: Vec<usize>,
        azimuth: usize,
        coordinate: Coleman,
    },
    /// The centre of mass of the bodies and beam elements `elements`: its position, velocity
    /// or acceleration (inertial component).
    CenterOfMass {
        elements: Vec<usize>,
        quantity: ProbeQuantity,
        component: usize,
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

/// Component `c` of a marker's `quantity`, from its kinematics `k` at `st`.
fn point_value(end: &End, k: &EndKin, st: &State, quantity: ProbeQuantity, c: usize) -> f64 {
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

/// An inertial vector in the axes of `axes` at `st` (unchanged without).
fn resolve(v: V3, axes: Option<&End>, st: &State) -> V3 {
    match axes {
        Some(e) => e.kin(st).e.transpose() * v,
        None => v,
    }
}

impl System {
    /// The values of `probes` in a state, in order, each handed to `out`: as [`System::probe`]
    /// gives them, with a marker's kinematics made once for a run of probes on it (a body's
    /// position, velocity and acceleration components) instead of once for each. On the
    /// two-bar's 14 channels at 1 ms this took the rows from 11 % of the run to 8 % (`perf`).
    pub fn probe_each<'p>(
        &self,
        probes: impl IntoIterator<Item = &'p Probe>,
        st: &State,
        aug: Augment,
        mut out: impl FnMut(f64),
    ) {
        let mut last: Option<(&End, EndKin)> = None;
        for probe in probes {
            let Probe::Point {
                end,
                quantity,
                component,
            } = probe
            else {
                out(self.probe(probe, st, aug));
                continue;
            };
            if last.as_ref().is_none_or(|(e, _)| *e != end) {
                last = Some((end, end.kin(st)));
            }
            if let Some((_, k)) = &last {
                out(point_value(end, k, st, *quantity, *component));
            }
        }
    }

    /// The value of a probe in a state.
    pub fn probe(&self, probe: &Probe, st: &State, aug: Augment) -> f64 {
        match probe {
            Probe::Point {
                end,
                quantity,
                component,
            } => point_value(end, &end.kin(st), st, *quantity, *component),
            Probe::JointForce {
                element,
                component,
                axes,
            } => match (&self.elements[*element], component) {
                (Element::Joint(_), Some(c)) => match self.joint_reaction(*element, st, aug) {
                    Some((f, _)) => resolve(f, axes.as_ref(), st)[*c],
                    None => f64::NAN,
                },
                (Element::Joint(_), None) => self.joint_row_force(*element, st, aug, 0),
                _ => f64::NAN,
            },
            Probe::JointMoment {
                element,
                component,
                axes,
            } => match self.joint_reaction(*element, st, aug) {
                Some((_, m)) => resolve(m, axes.as_ref(), st)[*component],
                None => f64::NAN,
            },
            Probe::JointAngle { element } => self.joint_angle(*element, st, false),
            Probe::JointRate { element } => self.joint_angle(*element, st, true),
            Probe::Multiblade {
                blades,
                azimuth,
                coordinate,
            } => {
                let zeta = |k: usize| self.joint_angle(blades[k], st, false);
                let psi = self.joint_angle(*azimuth, st, false);
                coordinate.of_blades(blades.len(), zeta, psi)
            }
            Probe::CenterOfMass {
                elements,
                quantity,
                component,
            } => {
                let mut total = MassMoments::default();
                for &e in elements {
                    if let Some(m) = self.elements[e].mass_moments(st) {
                        total += m;
                    }
                }
                let moment = match quantity {
                    ProbeQuantity::Velocity => total.velocity,
                    ProbeQuantity::Acceleration => total.acceleration,
                    _ => total.position,
                };
                moment[*component] / total.mass
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

    /// A revolute joint's angle (or a prismatic joint's displacement), or its rate.
    fn joint_angle(&self, element: usize, st: &State, rate: bool) -> f64 {
        match &self.elements[element] {
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

#[cfg(test)]
mod tests {
    use super::Coleman;

    #[test]
    fn multiblade_coordinates_are_as_many_as_blades_and_invert() {
        let names =
            |n: usize| -> Vec<String> { Coleman::all(n).into_iter().map(|c| c.suffix()).collect() };
        assert_eq!(names(2), ["0", "d"]);
        assert_eq!(names(3), ["0", "1c", "1s"]);
        assert_eq!(names(4), ["0", "1c", "1s", "d"]);
        assert_eq!(names(5), ["0", "1c", "1s", "2c", "2s"]);
        assert_eq!(names(6), ["0", "1c", "1s", "2c", "2s", "d"]);
        for n in 2..=9 {
            let zeta: Vec<f64> = (0..n).map(|k| (0.7 * k as f64 + 0.3).sin()).collect();
            let psi = 1.234;
            let coords = Coleman::all(n);
            assert_eq!(coords.len(), n);
            // zeta_k = zeta_0 + sum_n (zeta_nc cos n psi_k + zeta_ns sin n psi_k) + zeta_d (-1)^k
            for (k, zk) in zeta.iter().enumerate() {
                let psi_k = psi + std::f64::consts::TAU * k as f64 / n as f64;
                let back: f64 = coords
                    .iter()
                    .map(|c| {
                        c.of(&zeta, psi)
                            * match *c {
                                Coleman::Collective => 1.0,
                                Coleman::Cosine { harmonic } => (harmonic as f64 * psi_k).cos(),
                                Coleman::Sine { harmonic } => (harmonic as f64 * psi_k).sin(),
                                Coleman::Differential => (-1f64).powi(k as i32),
                            }
                    })
                    .sum();
                assert!((back - zk).abs() < 1e-13, "N = {n}, blade {k}");
            }
        }
    }
}
