//! Model: AST -> validated, evaluated model with a fixed unknown ordering.
//!
//! Contract: resolves names, evaluates params and properties with their units, checks
//! dimensions and topology, and fixes the order of the unknowns (each multiplier after the
//! unknowns it couples). Reports every error it finds. Must not know integrators or faer.
//!
//! Its steps live in folders: `scope/` (names, scopes, elaboration, resolution), `eval/`
//! (values, units, expressions and built-in functions), `build/` (entities from declarations,
//! outputs and the `solve` block, recorded as written), `check/` (topology and the numbering
//! of the unknowns). This file holds the stage's public types.

mod build;
mod check;
pub mod eval;
mod scope;

pub use build::{build, channel_dim, check_library};
pub use check::{dofs, topology};
pub use dofs::DofMap;
pub use eval::{units, Value};

use crate::runtime::timefn::TimeFn;
pub use crate::runtime::Coleman;
use crate::source::Span;
use serde::Serialize;

/// A request to load a module the model `use`s (the standard library is built in).
pub enum LoadRequest<'a> {
    /// `use mylib::tower` -> segments `["mylib", "tower"]`.
    Module { path: &'a [String], from: &'a str },
    /// `use "parts/tower.mbd"`.
    File { path: &'a str, from: &'a str },
}

/// Finds the text of modules outside the standard library. The compiler does no file IO:
/// the command line supplies a loader that reads files (next to the model, then MBD_PATH).
pub trait Loader {
    /// `Ok((display name, text))`; `Err(None)` if not found; `Err(Some(reason))` if unreadable.
    fn load(&self, request: &LoadRequest) -> Result<(String, String), Option<String>>;
}

/// A loader that knows only the built-in standard library.
pub struct NoFiles;

impl Loader for NoFiles {
    fn load(&self, _: &LoadRequest) -> Result<(String, String), Option<String>> {
        Err(None)
    }
}

/// Command-line overrides of params and of the `solve` block.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    /// `--set NAME=VALUE`, parsed from their own source texts.
    pub sets: Vec<(crate::syntax::ast::Ident, crate::syntax::ast::Expr)>,
    /// The command line's solver settings, laid over the `solve` block's.
    pub solve: crate::settings::Request,
    /// Build every `beam NAME rigid` as the elastic beam it declares (the sizing lint's
    /// W0702 measures them so).
    pub elastic: bool,
}

pub type Mat3 = [[f64; 3]; 3];

pub const IDENTITY: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

#[derive(Clone, Debug, Serialize)]
pub struct Model {
    pub name: String,
    pub title: Option<String>,
    pub params: Vec<(String, Value)>,
    pub gravity: [f64; 3],
    pub grounds: Vec<Ground>,
    pub bodies: Vec<Body>,
    pub beams: Vec<Beam>,
    pub joints: Vec<Joint>,
    pub springs: Vec<Spring>,
    pub loads: Vec<Load>,
    /// Forces and torques per length along beams.
    pub distributed: Vec<DistributedLoad>,
    /// Shapes drawn by the 3-D view only (`cylinder`, `box`, `sphere`): no mass, no unknowns.
    pub geometry: Vec<Geometry>,
    pub outputs: Vec<OutputChannel>,
    /// Closed-form solutions of output channels (`exact phi = Omega * t`).
    pub exact: Vec<ExactReference>,
    /// What the `solve` block wrote (resolved with the command line by `Settings::resolve`).
    pub solve: crate::settings::Written,
    pub dofs: DofMap,
    /// The joints whose equations are redundant but consistent (W0303): the run drops their
    /// surplus rows.
    pub redundant: Vec<usize>,
    /// How many of their equations are surplus (the run drops that many).
    pub surplus: usize,
}

#[derive(Clone, Debug, Serialize)]
pub struct Ground {
    pub name: String,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyKind {
    /// 3 translational unknowns.
    PointMass,
    /// 6 unknowns: translation of the reference point and rotation.
    Rigid,
}

/// A body. Its frame is fixed in it; at t = 0 the frame is `orientation` (columns: body axes
/// in inertial components) placed at `position`.
#[derive(Clone, Debug, Serialize)]
pub struct Body {
    pub name: String,
    pub span: Span,
    pub kind: BodyKind,
    pub mass: f64,
    /// Centre of mass, from the reference point, in the body frame.
    pub center: [f64; 3],
    /// Inertia tensor about the centre of mass, in the body frame.
    pub inertia: Mat3,
    /// Reference point at t = 0 (inertial).
    pub position: [f64; 3],
    pub orientation: Mat3,
    /// Velocity of the reference point and angular velocity at t = 0 (inertial).
    pub velocity: [f64; 3],
    pub angular_velocity: [f64; 3],
    /// Named markers: name, offset from the reference point and axes, in the body frame.
    pub markers: Vec<(String, [f64; 3], Mat3)>,
    /// For `beam NAME rigid`: its length and node count, so `at(s)` and `node[k]` still name
    /// points along its axis (body axis 1 from the reference point).
    pub beam_axis: Option<(f64, usize)>,
}

/// Sectional properties of a beam, in the section frame (axis 1 along the beam).
#[derive(Clone, Debug, Serialize)]
pub struct Section {
    pub name: String,
    /// 6x6 stiffness: forces (1: axial, 2, 3: shear) and moments (4: torsion, 5, 6: bending).
    pub stiffness: [[f64; 6]; 6],
    pub mass_per_length: f64,
    /// Centre of mass offset in the section plane (axes 2, 3).
    pub mass_offset: [f64; 2],
    /// Mass moments of inertia per length about the centre of mass, in the section's axes
    /// (1: polar), products included.
    pub inertia: [[f64; 3]; 3],
}

/// An elastic beam: geometrically exact beam elements between equally spaced nodes.
#[derive(Clone, Debug, Serialize)]
pub struct Beam {
    pub name: String,
    pub span: Span,
    /// The section (the first station's where the section varies).
    pub section: Section,
    /// Stations `(arc length, section)` of a section varying along the span, linear between
    /// them (empty: `section` everywhere).
    pub sections: Vec<(f64, Section)>,
    pub elements: usize,
    /// Nodes per element: 2, 3 or 4.
    pub order: usize,
    /// Node positions in the undeformed reference configuration.
    pub nodes: Vec<[f64; 3]>,
    /// Node positions at t = 0 (the reference ones unless `spin_stretch` displaces them).
    pub initial_nodes: Vec<[f64; 3]>,
    /// Section frame of each node at t = 0 (columns: axes 1, 2, 3): the beam's frame turned
    /// about axis 1 by the twist there.
    pub frames: Vec<Mat3>,
    pub length: f64,
    /// Velocity and angular velocity of each node at t = 0.
    pub velocities: Vec<[f64; 3]>,
    pub angular_velocities: Vec<[f64; 3]>,
    /// Concentrated masses on nodes: node, mass, inertia (inertial frame at t = 0).
    pub point_masses: Vec<(usize, f64, Mat3)>,
    /// Concentrated masses between nodes: arc length, mass, inertia (inertial frame at t = 0).
    pub masses_between: Vec<(f64, f64, Mat3)>,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "on", rename_all = "snake_case")]
pub enum Attach {
    Ground {
        ground: usize,
    },
    Body {
        body: usize,
    },
    BeamNode {
        beam: usize,
        node: usize,
    },
    /// A point between nodes, at arc length `s` from the beam's start.
    BeamPoint {
        beam: usize,
        s: f64,
    },
}

/// A point with axes, fixed on a ground, a body or a beam.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Marker {
    pub attach: Attach,
    /// Offset from the attachment's reference point, in its frame.
    pub offset: [f64; 3],
    /// Marker axes in the attachment's frame.
    pub axes: Mat3,
    /// Where it is at t = 0, and its axes then (inertial).
    pub position: [f64; 3],
    pub world_axes: Mat3,
    /// How it was written, for messages.
    pub text: String,
    pub span: Span,
}

/// How a revolute or prismatic joint's free motion is driven.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "drive", rename_all = "snake_case")]
pub enum Drive {
    Free,
    /// Prescribed relative angle (or displacement), zero at t = 0.
    Position {
        f: TimeFn,
    },
    /// Prescribed relative rate.
    Rate {
        f: TimeFn,
    },
}

#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum JointKind {
    /// Relative rotation about `axis` only; the relative angle is an extra unknown.
    Revolute {
        axis: [f64; 3],
        spring: f64,
        damper: f64,
        rest_angle: f64,
        drive: Drive,
        torque: Option<TimeFn>,
    },
    /// Relative translation along `axis` only.
    Prismatic {
        axis: [f64; 3],
        spring: f64,
        damper: f64,
        drive: Drive,
        force: Option<TimeFn>,
    },
    /// Rotation about and translation along `axis`.
    Cylindrical { axis: [f64; 3] },
    /// Rotation about `axis_a` (fixed in the first body) and `axis_b` (in the second).
    Universal { axis_a: [f64; 3], axis_b: [f64; 3] },
    /// Coincident points, free rotation.
    Spherical,
    /// No relative motion.
    Fixed,
    /// `|x_b - x_a| = length`: one multiplier, the link tension.
    Distance { length: f64 },
}

impl JointKind {
    /// The number of constraint equations (multipliers). A revolute joint has six: three for
    /// the point, two for the axis, and one tying its angle unknown to the measured angle.
    pub fn multipliers(&self) -> usize {
        match self {
            JointKind::Revolute { drive, .. } => 6 + usize::from(!matches!(drive, Drive::Free)),
            JointKind::Prismatic { drive, .. } => 5 + usize::from(!matches!(drive, Drive::Free)),
            JointKind::Cylindrical { .. } => 4,
            JointKind::Universal { .. } => 4,
            JointKind::Spherical => 3,
            JointKind::Fixed => 6,
            JointKind::Distance { .. } => 1,
        }
    }

    /// Extra unknowns: the revolute joint's relative angle.
    pub fn extra_unknowns(&self) -> usize {
        usize::from(matches!(self, JointKind::Revolute { .. }))
    }

    pub fn name(&self) -> &'static str {
        match self {
            JointKind::Revolute { .. } => "revolute",
            JointKind::Prismatic { .. } => "prismatic",
            JointKind::Cylindrical { .. } => "cylindrical",
            JointKind::Universal { .. } => "universal",
            JointKind::Spherical => "spherical",
            JointKind::Fixed => "fixed",
            JointKind::Distance { .. } => "distance",
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
pub enum SpringKind {
    /// Force along the line between the markers.
    Linear,
    /// Moment on the relative rotation of the markers' axes.
    Torsional,
}

/// A spring and/or damper between two markers.
#[derive(Clone, Debug, Serialize)]
pub struct Spring {
    pub name: String,
    pub span: Span,
    pub kind: SpringKind,
    pub stiffness: f64,
    pub damping: f64,
    /// Free length (linear springs).
    pub length: f64,
    pub markers: [Marker; 2],
}

/// What a `cylinder`, `box` or `sphere` declaration draws (m).
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "shape", rename_all = "snake_case")]
pub enum GeometryShape {
    /// From the first marker to the second, each end following its marker.
    Cylinder {
        radius: f64,
    },
    /// Centred at the marker, along its axes, with these full sizes.
    Box {
        size: [f64; 3],
    },
    Sphere {
        radius: f64,
    },
}

/// A shape the 3-D view draws on markers: the tower under a rotor, a fuselage. It has no
/// mass and adds no unknowns.
#[derive(Clone, Debug, Serialize)]
pub struct Geometry {
    pub name: String,
    pub span: Span,
    pub shape: GeometryShape,
    /// One marker (box, sphere) or two (cylinder).
    pub markers: Vec<Marker>,
    /// sRGB components in 0..1, when given.
    pub color: Option<[f64; 3]>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LoadKind {
    Force,
    Torque,
}

/// A force or torque applied at a marker, as a vector function of time.
#[derive(Clone, Debug, Serialize)]
pub struct Load {
    pub name: String,
    pub span: Span,
    pub kind: LoadKind,
    pub marker: Marker,
    /// Components (inertial, or in the marker's axes if `follower`).
    pub value: [TimeFn; 3],
    pub follower: bool,
}

/// A force or torque per length along a whole beam, a vector function of the time `t` and of
/// the arc length `span` ([`TimeFn::Arc`]).
#[derive(Clone, Debug, Serialize)]
pub struct DistributedLoad {
    pub name: String,
    pub span: Span,
    pub kind: LoadKind,
    pub beam: usize,
    /// Components per length (inertial, or in the section's axes if `follower`).
    pub value: [TimeFn; 3],
    pub follower: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyQuantity {
    Position,
    Velocity,
    Acceleration,
    AngularVelocity,
    AngularAcceleration,
    /// Direction cosines: component = 3 * row + column.
    Rotation,
    /// Conformal rotation vector relative to the initial orientation (principal state).
    Crv,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum JointQuantity {
    /// The reaction force (for a distance joint: the tension, positive in traction).
    Force,
    /// The reaction moment.
    Moment,
    /// The relative angle (revolute) or displacement (prismatic), continuous.
    Angle,
    Rate,
    /// The constraint violation.
    Violation,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EnergyKind {
    Kinetic,
    Potential,
    Total,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "of", rename_all = "snake_case")]
pub enum Probe {
    Body {
        body: usize,
        quantity: BodyQuantity,
        component: usize,
    },
    /// A point that is not a body's reference point: a marker or a beam node.
    Point {
        attach: Attach,
        offset: [f64; 3],
        quantity: BodyQuantity,
        component: usize,
    },
    Joint {
        joint: usize,
        quantity: JointQuantity,
        /// The vector component, for force and moment of joints with several multipliers.
        component: Option<usize>,
        /// `force.in(MARKER)`: the component in the axes of this marker (as they turn), not
        /// in inertial axes.
        #[serde(skip_serializing_if = "Option::is_none")]
        axes: Option<Box<Marker>>,
    },
    Energy {
        kind: EnergyKind,
    },
    /// A multiblade (Coleman) coordinate of the angles of the revolute joints `blades` (blade
    /// k is member k of the family in index order), with the rotor azimuth the angle of the
    /// revolute joint `azimuth`.
    Multiblade {
        blades: Vec<usize>,
        azimuth: usize,
        coordinate: Coleman,
    },
    /// The centre of mass of bodies and beams, each with the concentrated masses it carries:
    /// its position, velocity or acceleration.
    CenterOfMass {
        bodies: Vec<usize>,
        beams: Vec<usize>,
        quantity: BodyQuantity,
        component: usize,
    },
}

#[derive(Clone, Debug, Serialize)]
pub struct OutputChannel {
    /// The CSV column name.
    pub column: String,
    pub probe: Probe,
    pub span: Span,
}

/// `exact CHANNEL = f(t)`: the closed-form solution of one output channel, the reference of
/// `mbd study --reference exact`. Not used by a run.
#[derive(Clone, Debug, Serialize)]
pub struct ExactReference {
    /// The CSV column it describes.
    pub column: String,
    /// The solution in SI units, a function of time.
    pub f: TimeFn,
    pub span: Span,
}
