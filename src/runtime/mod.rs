//! Runtime: the lowered system, its state, the elements and their assembly.
//!
//! Contract: elements compute residuals and tangents from a state and coefficients that the
//! integrator supplies; the runtime is integrator-agnostic. It knows entity names (for
//! messages) but nothing of spans or files, and it never touches faer.
//!
//! Rotations: every rotating node keeps its rotation matrix `R`, angular velocity `omega` and
//! angular acceleration `omega-dot` (inertial components) in [`State::rot`]. Elements read
//! rotations only from there and give forces conjugate to virtual rotations `delta theta`
//! (`R <- exp(delta theta~) R`), so the same element code serves every rotation treatment of
//! the integrator (THEORY §1, §7.1).

mod assembly;
pub mod beams;
mod bodies;
mod elements;
mod forces;
pub mod joints;
pub mod precise;
mod probes;
pub mod rotation;
pub mod scene;
pub mod timefn;

pub use assembly::{Assembler, Pattern};
pub use beams::BeamElement;
pub use bodies::{PointMass, RigidBody};
pub use elements::Element;
pub use forces::{Load, LoadKind, Spring, SpringKind};
pub use joints::{Between, End, EndKin, Joint, Row};
pub use probes::{Coleman, EnergyKind, MassMoments, Probe, ProbeQuantity};

use rotation::{M3, V3};
use serde::{Deserialize, Serialize};

/// What an unknown is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UnknownKind {
    /// A translation or a joint scalar: Newmark relations on `q`, `v`, `a`.
    Coordinate,
    /// Component `axis` of the rotation of rotating node `node`.
    Rotation { node: usize, axis: usize },
    /// A position-level constraint's multiplier.
    Multiplier,
    /// A velocity-level constraint's multiplier (a prescribed rate).
    RateMultiplier,
}

impl UnknownKind {
    pub fn is_multiplier(self) -> bool {
        matches!(self, UnknownKind::Multiplier | UnknownKind::RateMultiplier)
    }
}

/// A named thing of the model (body or joint), for runtime messages.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Entity {
    pub name: String,
    pub kind: String,
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
    /// The first of the three rotation unknowns of each rotating node.
    pub rotations: Vec<usize>,
    /// The first of the three translation unknowns of each rotating node (its position).
    pub translations: Vec<usize>,
    /// Per rotating node: whether its translation and rotation move together as one SE(3)
    /// frame (rigid bodies), or separately (beam nodes: SO(3) x R^3). Empty: all frames.
    #[serde(default)]
    pub coupled: Vec<bool>,
    pub entities: Vec<Entity>,
    pub elements: Vec<Element>,
    pub initial: State,
    pub channels: Vec<Channel>,
    /// A length typical of the model, for scaling Newton increments.
    pub length_scale: f64,
    /// The joints (element indices) whose equations are redundant but consistent: some of
    /// their rows dropped, their reactions reported as the minimum-norm split.
    #[serde(default)]
    pub redundant: Vec<usize>,
}

impl System {
    pub fn len(&self) -> usize {
        self.unknowns.len()
    }

    /// The force and moment joint element `e` applies on its end B: the minimum-norm split
    /// for a redundant joint ([`joints::min_norm_reaction`]).
    pub fn joint_reaction(&self, e: usize, st: &State, aug: Augment) -> Option<(V3, V3)> {
        let Element::Joint(j) = &self.elements[e] else {
            return None;
        };
        if self.redundant.contains(&e) {
            if let Some(r) = joints::min_norm_reaction(
                &self.elements,
                &self.redundant,
                e,
                st,
                aug,
                self.length_scale,
            ) {
                return Some(r);
            }
        }
        Some(j.reaction(st, aug))
    }

    /// The rows of the redundant joints to drop at `st`, `count` of them (see
    /// [`joints::select_dropped`]): `st.dropped` while the rows it keeps stay well apart;
    /// `None` without redundant joints.
    pub fn select_dropped(&self, st: &State, count: usize) -> Option<Vec<u16>> {
        (!self.redundant.is_empty()).then(|| {
            joints::select_dropped(
                &self.elements,
                &self.redundant,
                &self.unknowns,
                st,
                self.length_scale,
                Some(count),
            )
        })
    }

    /// Row `row`'s force of joint element `e` (a distance joint's tension): its share in the
    /// minimum-norm split for a redundant joint.
    pub fn joint_row_force(&self, e: usize, st: &State, aug: Augment, row: usize) -> f64 {
        let Element::Joint(j) = &self.elements[e] else {
            return f64::NAN;
        };
        if self.redundant.contains(&e) {
            let split = joints::min_norm_forces(
                &self.elements,
                &self.redundant,
                e,
                st,
                aug,
                self.length_scale,
            );
            if let Some(mu) = split {
                return mu[row];
            }
        }
        j.multiplier_force(st, aug, row)
    }

    /// The largest drift of a dropped redundant row and its joint's entity (the owner of
    /// its first multiplier), if any row is dropped.
    pub fn dropped_violation(&self, st: &State) -> Option<(f64, usize)> {
        self.redundant
            .iter()
            .filter_map(|&e| match &self.elements[e] {
                Element::Joint(j) => Some((j.dropped_violation(st), self.owners[j.first])),
                _ => None,
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// The `(multiplier, angle unknown)` pairs of the revolute joints' angle rows, whose
    /// velocity constraint is `phi-dot_measured - phi-dot`.
    pub fn angle_rows(&self) -> Vec<(usize, usize)> {
        self.elements
            .iter()
            .filter_map(|e| match e {
                Element::Joint(j) => j.angle.and_then(|a| {
                    j.rows
                        .iter()
                        .position(|r| matches!(r, Row::Angle))
                        .map(|r| (j.first + r, a))
                }),
                _ => None,
            })
            .collect()
    }

    /// The first unknown of each translation triplet: the rotating nodes' positions, then
    /// the point masses'.
    pub fn translation_triplets(&self) -> Vec<usize> {
        let points = self.elements.iter().filter_map(|e| match e {
            Element::PointMass(p) => Some(p.dofs[0]),
            _ => None,
        });
        self.translations.iter().copied().chain(points).collect()
    }

    /// The revolute joints' angle unknowns.
    pub fn angle_unknowns(&self) -> Vec<usize> {
        self.elements
            .iter()
            .filter_map(|e| match e {
                Element::Joint(j) => j.angle,
                _ => None,
            })
            .collect()
    }

    /// Whether rotating node `k` is an SE(3) frame (see `coupled`).
    #[inline]
    pub fn is_frame(&self, k: usize) -> bool {
        self.coupled.get(k).copied().unwrap_or(true)
    }

    pub fn is_empty(&self) -> bool {
        self.unknowns.is_empty()
    }

    /// Mean translational mass, for constraint scaling (THEORY §6). Allocates nothing: it is
    /// asked once a step.
    pub fn mean_mass(&self) -> f64 {
        let masses = self.elements.iter().filter_map(|e| e.translational_mass());
        mean(masses.filter(|m| *m > 0.0)).unwrap_or(1.0)
    }

    /// Mean elastic stiffness diagonal, for constraint scaling (THEORY §6).
    pub fn mean_stiffness(&self) -> f64 {
        mean(self.elements.iter().filter_map(|e| e.stiffness_scale())).unwrap_or(0.0)
    }
}

/// The mean of the values, `None` for none.
fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    (n > 0).then(|| sum / n as f64)
}

/// Kinematics of one rotating node: rotation from its initial orientation, angular velocity
/// and angular acceleration (inertial components).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NodeRotation {
    pub r: [[f64; 3]; 3],
    pub w: [f64; 3],
    pub dw: [f64; 3],
}

impl NodeRotation {
    pub const REST: NodeRotation = NodeRotation {
        r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        w: [0.0; 3],
        dw: [0.0; 3],
    };

    #[inline]
    pub fn matrix(&self) -> M3 {
        M3::from_fn(|i, j| self.r[i][j])
    }

    #[inline]
    pub fn set_matrix(&mut self, m: &M3) {
        for i in 0..3 {
            for j in 0..3 {
                self.r[i][j] = m[(i, j)];
            }
        }
    }

    #[inline]
    pub fn omega(&self) -> V3 {
        V3::from(self.w)
    }

    #[inline]
    pub fn omega_dot(&self) -> V3 {
        V3::from(self.dw)
    }
}

/// The state at one instant. `q`, `v`, `a` have one entry per unknown: positions, velocities
/// and accelerations of coordinates; for rotation unknowns, whatever the integrator's
/// rotation treatment keeps there (the rotating nodes' kinematics are in `rot`). `lambda`
/// is used only at multipliers. `alg` holds generalized-alpha's algorithmic accelerations, or the
/// nodal momenta of time finite elements.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct State {
    pub t: f64,
    pub q: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    pub lambda: Vec<f64>,
    pub alg: Vec<f64>,
    pub rot: Vec<NodeRotation>,
    /// Body-frame velocities of the rotating nodes (incremental treatment).
    pub frames: Vec<Frame>,
    /// Per redundant joint (W0303, in the order of [`System::redundant`]): the rows dropped
    /// now (bit `k`: row `k`), chosen again as the mechanism moves.
    #[serde(default)]
    pub dropped: Vec<u16>,
    /// What rounding left out of `q` (the exact value is `q + carry`): kept by the integrator
    /// for the revolute angles, which grow by whole turns while each step moves them by a
    /// little (ARCHITECTURE.md, "No round-off the step amplifies"); zero elsewhere.
    #[serde(default)]
    pub carry: Vec<f64>,
}

/// A rotating node's body-frame twist `(R^T x-dot, R^T omega)`, its rate and the integrator's
/// algorithmic rate: what the SE(3) Newmark relations act on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    pub v: [f64; 6],
    pub dv: [f64; 6],
    pub alg: [f64; 6],
}

impl State {
    pub fn zeros(n: usize, nodes: usize) -> State {
        State {
            t: 0.0,
            q: vec![0.0; n],
            v: vec![0.0; n],
            a: vec![0.0; n],
            lambda: vec![0.0; n],
            alg: vec![0.0; n],
            rot: vec![NodeRotation::REST; nodes],
            frames: vec![Frame::default(); nodes],
            dropped: Vec::new(),
            carry: vec![0.0; n],
        }
    }

    /// Becomes a copy of `other` (of the same size) without allocating.
    pub fn assign(&mut self, other: &State) {
        self.t = other.t;
        for (a, b) in [
            (&mut self.q, &other.q),
            (&mut self.v, &other.v),
            (&mut self.a, &other.a),
            (&mut self.lambda, &other.lambda),
            (&mut self.alg, &other.alg),
        ] {
            a.copy_from_slice(b);
        }
        self.rot.copy_from_slice(&other.rot);
        self.frames.copy_from_slice(&other.frames);
        self.dropped.copy_from_slice(&other.dropped);
        self.carry.clear();
        self.carry.extend_from_slice(&other.carry);
        self.carry.resize(self.q.len(), 0.0);
    }

    /// Revolute angle `i` reduced by whole turns into `[-pi, pi]`, with what rounding left out
    /// of `q`: accurate to `1e-16` rad however many turns the angle has made.
    #[inline]
    pub fn phase(&self, i: usize) -> f64 {
        precise::reduce_angle(self.q[i]) + self.carry.get(i).copied().unwrap_or(0.0)
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

    /// The first rotating node with a non-finite rotation, rate or acceleration.
    pub fn first_non_finite_node(&self) -> Option<usize> {
        self.rot.iter().position(|n| {
            !(n.r.iter().flatten().all(|x| x.is_finite())
                && n.w.iter().all(|x| x.is_finite())
                && n.dw.iter().all(|x| x.is_finite()))
        })
    }
}

/// Augmented-Lagrangian scaling `s`, penalty `p` (THEORY §6), and the time scale that turns a
/// velocity-level constraint row into a position-like one (`1 / (d v / d q)` of the
/// integrator, `beta h / gamma` for Newmark).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Augment {
    pub s: f64,
    pub p: f64,
    pub rate_scale: f64,
}

/// Coefficients the integrator supplies to combine the element matrices: the derivatives of
/// the accelerations (`mass`) and velocities (`velocity`) with respect to the positions, the
/// weight of the configuration-dependent inertial terms (`position`), and the weight of the
/// forces `F^int + F^c - F^ext` (`force_weight`, `1 + alpha` for HHT). The iteration matrix is
/// `mass M + velocity G + position K^I + force_weight (position K + velocity D)`, with the
/// constraint coupling column weighted by `force_weight` and the constraint rows `s B`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TangentCoeffs {
    pub mass: f64,
    pub velocity: f64,
    pub position: f64,
    pub force_weight: f64,
}

/// Which time derivative of the constraints to evaluate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rate {
    /// `B v + dC/dt`: the velocity constraint (for rate rows, their value).
    Velocity,
    /// `dB/dt v + d2C/dt2`: with `B a`, the second time derivative of `C`.
    AccelerationBias,
}

/// Residual parts, each one entry per unknown.
#[derive(Clone, Debug)]
pub struct Residual {
    /// Inertial forces `F^I`.
    pub inertia: Vec<f64>,
    /// `F^int + F^c - F^ext`.
    pub force: Vec<f64>,
    /// Constraint values `C` at multiplier rows (rate rows: `rate_scale` times their value).
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

/// Mechanical energies of a state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Energy {
    pub kinetic: f64,
    pub potential: f64,
}

/// A 3x3 matrix stored as rows, as in the IR.
#[inline]
pub fn m3(a: &[[f64; 3]; 3]) -> M3 {
    M3::from_fn(|i, j| a[i][j])
}

#[inline]
pub fn arr3(m: &M3) -> [[f64; 3]; 3] {
    let mut a = [[0.0; 3]; 3];
    for (i, row) in a.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = m[(i, j)];
        }
    }
    a
}
