//! The registry of diagnostic codes: one entry per code, with the text `mbd explain CODE` prints.
//! Ranges: E01xx syntax, E02xx names and units, E03xx topology and DOFs, E04xx time functions and
//! loads, E05xx lowering, E06xx solve and runtime, W… warnings.

use serde::{Serialize, Serializer};

macro_rules! codes {
    ($($variant:ident = $code:literal, $title:literal, $doc:literal;)*) => {
        /// A diagnostic code. Every code has a title and an explanation.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Code { $($variant,)* }

        /// Every registered code, in order.
        pub const ALL_CODES: &[Code] = &[$(Code::$variant,)*];

        impl Code {
            /// The code as written in reports, e.g. `E0202`.
            pub fn as_str(self) -> &'static str {
                match self { $(Code::$variant => $code,)* }
            }
            /// One line naming the problem.
            pub fn title(self) -> &'static str {
                match self { $(Code::$variant => $title,)* }
            }
            /// The long explanation.
            pub fn doc(self) -> &'static str {
                match self { $(Code::$variant => $doc,)* }
            }
        }
    };
}

codes! {
    E0101 = "E0101", "syntax error",
        "The text does not follow the grammar of the .mbd language. The report points at the first \
place where the parser could not continue and lists what it expected there. Common causes: a \
missing `=` in a property, an unclosed `{` or `(`, a unit written with spaces inside (`m / s` \
instead of `m/s`), or a keyword used as a name.";
    E0102 = "E0102", "empty model file",
        "The file declares nothing. A model needs at least a `model NAME` header, a `ground`, one \
body and a `solve` block. See models/pendulum.mbd for a complete example.";
    E0104 = "E0104", "model file is not UTF-8 text",
        "A model file is UTF-8 text, and this one holds a byte sequence that is not UTF-8: \
often a file saved in Latin-1 or Windows-1252 (a `°`, `µ` or `é` in a comment), a binary file \
given by mistake, or a file cut in the middle of a character. The report points at the first \
bad byte (its line and column; the line is shown with the bad bytes replaced). Save the file \
as UTF-8 or remove the character; a byte-order mark at the start is accepted.";
    E0103 = "E0103", "missing or repeated model header",
        "Every file describes one scene and starts with `model NAME \"title\"`. The header is \
missing, or appears more than once.";
    E0201 = "E0201", "unknown name",
        "A name is used that no declaration defines: a param, a body, a joint, a function or a \
property. Names are case-sensitive. Declarations may appear in any order.";
    E0202 = "E0202", "unit mismatch",
        "A quantity has the wrong physical dimension: a mass given in metres, a sum of a length and \
a time, or a function such as `sin` applied to a dimensional argument. Values are stored in SI; \
every literal may carry a unit (`kg`, `m`, `s`, `N`, `rad`, `deg`, `m/s`, `m/s^2`, ...). A bare \
number is dimensionless.";
    E0203 = "E0203", "duplicate name",
        "Two declarations share one name. Every param, ground, body and joint needs a distinct \
name, and so does every output column.";
    E0204 = "E0204", "unknown unit",
        "A unit is not one the compiler knows. Known units: kg g m mm cm km s ms min h rad deg \
rev rpm Hz N kN J W Pa kPa MPa GPa (`rpm` and `Hz` include the 2 pi of a cycle: 1 Hz is 2 pi rad/s), combined with `*`, `/` and integer powers `^`. A unit is \
written right after its number, without spaces inside (`9.81 m/s^2`). To multiply a quantity by \
a param, write the param first (`L * 2 m`) or use parentheses.";
    E0205 = "E0205", "unknown property",
        "A block sets a property that this kind of declaration does not have. The hint lists the \
properties it accepts.";
    E0206 = "E0206", "missing property",
        "A declaration lacks a property it needs, for example a `point_mass` without `mass` or `at`.";
    E0207 = "E0207", "circular definition",
        "A param, a let, a property or an alias is defined in terms of itself, directly or through \
others.";
    E0208 = "E0208", "unknown --set name",
        "`--set NAME=VALUE` names a param the model does not declare. Only params can be \
overridden from the command line.";
    E0209 = "E0209", "wrong kind of value",
        "A vector was given where a scalar is needed, or the other way round, or a vector does not \
have three components.";
    E0210 = "E0210", "unknown function or wrong arguments",
        "A call names a function that does not exist, or passes the wrong number of arguments. \
Functions: sin cos tan asin acos atan atan2 sqrt abs exp ln min max norm dot cross rotate, \
and the time functions ramp step sine constant; a `function NAME = ...` is called with one \
argument, the time: `pulse(t - 1 s)`.";
    E0211 = "E0211", "unknown declaration kind",
        "A declaration kind, joint kind, solver or option value is not known. The hint lists the \
known ones.";
    E0212 = "E0212", "unknown output quantity",
        "An `output` path does not name a quantity the model can compute. Bodies provide \
position, velocity and acceleration (and their .x .y .z components), rigid bodies also \
angular_velocity, angular_acceleration, rotation and crv; markers and beam points provide \
position, velocity and acceleration; joints provide force, moment and violation, revolute joints \
angle and rate, prismatic joints displacement and speed; `kinetic_energy`, `potential_energy` \
and `total_energy` are model outputs. After `center_of_mass(...)` may follow `.position`, \
`.velocity` or `.acceleration` and a component `.x .y .z`; `multiblade(...)` takes none (each \
coordinate is a column).";
    E0213 = "E0213", "invalid value",
        "A value is outside its allowed range or not finite: a negative time step, an HHT alpha \
outside [-1/3, 0], a division by zero, the square root of a negative number.";
    E0214 = "E0214", "bad index",
        "An index is out of range, missing, or given to a name that is not indexed. Loops declare \
indexed families: `for i in 0..4 { rigid_rod blade[i] { ... } }` declares blade[0] to blade[3]; \
refer to one member as `blade[2]`. Beams number their nodes from 0: `mast.node[k]`.";
    E0215 = "E0215", "wrong component argument",
        "A component is instantiated with an argument it does not declare, without an argument it \
requires, or with a value of the wrong type (a mass where a length is expected). Arguments are \
named: `rotor = lag_hinged_rotor(blades = 4, hub = tower.tip, ...)`. The hint lists the \
parameters and their types.";
    E0216 = "E0216", "module not found",
        "A `use` names a module that neither the standard library nor the search path provides. \
`use stdlib::rotor::lag_hinged_rotor` imports from the built-in standard library; other modules \
are searched next to the model file and then in the directories listed in MBD_PATH \
(`use mylib::tower` reads mylib/tower.mbd or mylib.mbd).";
    E0217 = "E0217", "import cycle",
        "Two or more modules `use` each other, so none can be loaded first. Move what they share \
into a third module that imports neither.";
    E0218 = "E0218", "components nested too deep",
        "Component instances nest more than 24 levels deep. This almost always means a component \
instantiates itself, directly or through another component, without an `if` that stops it.";
    E0219 = "E0219", "name not exported",
        "A component declares the name, but its `export` list does not include it, so it is private \
to the component. Add it to the component's `export` line, or use an exported name.";
    E0220 = "E0220", "misplaced declaration",
        "The declaration is not allowed where it is written: `model`, `param`, `gravity`, \
`solve` and `exact` belong at the top level of the model file; `component` and `use` may not appear inside \
a component or a loop; a library file holds components (and the lets, functions and imports \
they need), not bodies.";
    E0222 = "E0222", "wrong kind of reference",
        "A name refers to something of the wrong kind: a joint where a marker is needed, a param \
where a body is needed, or a body used as a number. Markers are written `body`, `body.marker`, \
`body @ (x, y, z)` or, on beams, `beam.start`, `beam.end`, `beam.node[k]`, `beam.at(s)`.";
    E0223 = "E0223", "loop too long",
        "A `for` loop would run more than 100,000 times; the bounds are probably wrong.";
    E0224 = "E0224", "wrong declaration shape",
        "A declaration has parts its kind does not take, or lacks parts it needs: a `force` needs \
`on MARKER = value`, a `spring` connects two markers `(a, b)`, a `rigid` body takes neither, and \
a section gives either its full 6x6 `stiffness` or the diagonal stiffnesses, not both.";
    E0225 = "E0225", "unknown output function or wrong arguments",
        "An output names a function that does not exist, or passes it arguments it does not take. \
The output functions are `multiblade(BLADES, azimuth = JOINT)` (the multiblade coordinates of \
the angles of a family of revolute joints) and `center_of_mass(OF)` (the centre of mass of a \
body, a beam, a component instance or a family of them). Arguments are references, given in \
that order or by name; positional arguments come before named ones, and each is given once: \
`output zeta = multiblade(rotor.lag, azimuth = rotor.drive)`.";
    E0226 = "E0226", "multiblade blades are not a family of revolute joints",
        "The first argument of `multiblade` names the blades' coordinates: an indexed family of \
revolute joints, written without an index (`rotor.lag`, or `rotor.lag.angle`), whose angles \
are the blade coordinates zeta_k. Member k of the family (in index order, without gaps) is \
blade k, at azimuth psi + 2 pi k / N. A single joint (`rotor.lag[0]`), a family of bodies or of \
other joints, or a family of fewer than 2 members has no multiblade coordinates.";
    E0227 = "E0227", "multiblade azimuth missing or not a revolute joint",
        "`multiblade` needs the rotor azimuth psi: `azimuth = JOINT` names the revolute joint the \
rotor turns on (`rotor.drive` in stdlib::rotor), whose angle is psi, zero at t = 0. Blade k \
is taken at psi + 2 pi k / N, so blade 0 must be the one at psi = 0.";
    E0228 = "E0228", "centre of mass of something without mass",
        "`center_of_mass(OF)` weighs a body, a beam, a component instance (every body and beam \
declared in it, recursively, with the concentrated masses they carry) or a family of them. \
What it names is none of these (a joint, a param, a quantity), declares no bodies, or has no \
mass at all (a massless hub), so it has no centre of mass.";
    E0229 = "E0229", "model has no solve block",
        "The model file has no `solve` block, so nothing says how to integrate it or for how \
long. Add one at the top level: `solve hht { dt = 1 ms, until = 1 s }` (the method, the time \
step or the number of steps, and the end time; section 13 of docs/language.md lists the \
settings). Without a block, `mbd run` needs both `--until` and `--dt` (or `--steps`).";
    E0230 = "E0230", "run cannot finish",
        "The time step and the end time ask for more steps than a run may take (10^9, \
`MAX_STEPS`): at a few microseconds a step that is hours of CPU for the smallest model, and \
a step far below the motion's time scales adds round-off, not accuracy. Usually a unit slipped \
(`dt = 1e-15 s` meant `1 ms`, `until = 1e6 s` meant `1 s`). Lengthen `dt` or shorten `until`; \
`mbd run --dt` and `--until` override the solve block.";
    E0301 = "E0301", "joint connects a body to itself",
        "Both markers of a joint are on the same body, so the joint constrains nothing. Connect it \
to another body or to ground.";
    E0302 = "E0302", "non-positive mass",
        "A body's mass must be positive (a rigid body may be massless, mass = 0, if its joints hold \
it), and a beam section's mass per length must be positive. A massless point would make the \
iteration matrix singular.";
    E0303 = "E0303", "degenerate joint geometry",
        "A joint's or a body's geometry is degenerate: a zero axis, a distance joint or a spring \
whose markers coincide (the direction is undefined), universal-joint axes that are not \
perpendicular, a rod or a beam of zero length.";
    E0304 = "E0304", "model has no bodies",
        "Nothing moves: declare at least one body.";
    E0305 = "E0305", "joint between two grounds",
        "Both markers of the joint are fixed in the inertial frame, so the joint constrains no \
unknown.";
    E0306 = "E0306", "invalid marker",
        "A marker cannot be placed as written: an offset on a point mass (it has no orientation to \
carry it), a joint that locks the rotation of a point mass, a load on the ground, a point of a \
beam that does not say which (`start`, `end`, `node[k]`, `at(s)`).";
    E0307 = "E0307", "redundant constraints",
        "Some joints lock the same motion and a drive takes part: the constraint Jacobian at the \
initial configuration has lower rank than the number of constraint equations, and one of the \
dependent equations is a prescribed angle, rate or slide, a motion the other joints already \
fix or tie to another. A prescription cannot be dropped the way a joint's surplus equation is \
(W0303: redundant joints without a drive run, their surplus dropped), so the model is \
refused. So is a redundancy in a loop of over 600 unknowns (its surplus is found on a spanning \
tree at check time, but not dropped at run time). The report names the joints whose equations \
are dependent. Drive a motion the joints \
leave free, or free one of the joints (a spherical instead of a revolute, a cylindrical instead \
of a prismatic).";
    E0308 = "E0308", "motion without inertia or restraint",
        "Some motion of the model has no mass or inertia and is held by no joint or spring, so the \
iteration matrix is singular: for instance a massless rigid body attached by a spherical joint \
only, or a slender rod free to spin about its own axis. Give the motion inertia, or hold it.";
    E0310 = "E0310", "joint markers do not coincide",
        "The two points a joint connects are apart at the start (or off the joint's axis, for \
prismatic and cylindrical joints). Joint equations hold from t = 0, so the bodies must be placed \
where the joint puts them. Move a body, or move a marker with `body @ (x, y, z)`.";
    E0311 = "E0311", "non-physical inertia or stiffness",
        "An inertia tensor has a negative principal moment or breaks the triangle inequality \
(each principal moment must be at most the sum of the other two), or a section's stiffness matrix \
is not symmetric positive definite. No real body or beam has such properties.";
    E0401 = "E0401", "varies in time where a constant is needed",
        "An expression that depends on `t` (or on a time function) was given where a constant is \
needed: a mass, a position, a param. Only loads (`force`, `torque`, joint `torque`), prescribed \
motions (joint `angle`, `rate`) and `function`s may vary in time.";
    E0402 = "E0402", "time function out of order",
        "A `piecewise` function's knots are not in increasing time (two knots may share a time to \
make a jump, three may not), or a `ramp` ends before it starts.";
    E0403 = "E0403", "unknown piecewise mode",
        "`piecewise` takes an optional mode that says what happens outside its knots: `hold` (the \
default: the end values), `extrapolate` (the end slopes continue) or `periodic`.";
    E0404 = "E0404", "contradictory joint drive",
        "A joint is both prescribed and loaded (`angle` and `rate`, or `rate` and `torque`), or its \
prescribed angle is not zero at t = 0. Joint angles are measured from the initial configuration, \
and a prescribed joint takes whatever torque the motion needs.";
    E0405 = "E0405", "exact solution of an unknown channel",
        "An `exact CHANNEL = f(t)` declaration names a channel the model does not output. The \
name is the CSV column an `output` declares: `output phi = root.angle` makes the channel `phi`, \
an unnamed `output rotor.lag[1].angle` the channel `rotor.lag[1].angle`, and `output zeta[i] = \
...` in a loop the channels `zeta1`, `zeta2`, ... The hint lists the model's channels. `mbd \
study --reference exact` compares the channel with this function of time.";
    E0406 = "E0406", "exact solution declared twice",
        "Two `exact` declarations describe the same output channel. A channel has one closed-form \
solution: keep one of them.";
    E0407 = "E0407", "exact solution is not a function of time",
        "The right-hand side of `exact CHANNEL = ...` must be a scalar: a constant or an expression \
of the time `t`, params and time functions (`ramp`, `step`, `sine`, `piecewise`, a `function`), \
with the channel's dimension. A vector, a rotation or a reference to a body is not the value of \
one channel; write the component that channel outputs, e.g. `exact x = L * sin(w * t)` for \
`output x = bob.position.x`.";
    E0601 = "E0601", "Newton iteration failed",
        "The nonlinear equations of a time step did not converge, even after the step was halved \
three times. The report names the time, the step and the element with the largest residual. \
Try a smaller time step (`--dt`), more numerical dissipation (`--alpha -0.3`), or check the \
model for a load or motion that is discontinuous or far too large.";
    E0602 = "E0602", "singular iteration matrix",
        "The linear system of a Newton iteration could not be factored. A body may lack mass in \
some direction, or constraints may be redundant.";
    E0603 = "E0603", "non-finite values",
        "A NaN or infinity appeared in the solution. The report names where it first appeared.";
    E0604 = "E0604", "integrator not available",
        "The requested combination of time integrator and options is not available: time finite \
elements (`fet`) integrate rotations incrementally, so `rotations = conformal` applies to the \
Newmark family (`hht`, `generalized_alpha`) only.";
    E0607 = "E0607", "run interrupted",
        "The run was stopped by Ctrl-C (SIGINT) between two steps: nothing failed. The output \
keeps every row computed before it (the CSV's last row is whole), and `mbd` exits with code \
130. In a sweep or a study every run still to go stops the same way and what was finished \
is written. A second Ctrl-C ends the process at once.";
    E0608 = "E0608", "redundant constraints inconsistent in motion",
        "The joints' equations depended on each other at the initial configuration (W0303), so \
the run dropped the surplus, and it watches the dropped equations: one drifted by more than \
1e-6 (m, or rad for an axis). The start was a singular position, where the joints' equations \
are dependent only there (a four-bar folded flat, a parallelogram with its links in line): \
away from it they are independent, and the dropped equation is a constraint the mechanism \
needs. The run stops at the step that shows it, naming the joint, and keeps the rows so far. \
Start the model away from the singular position, or free one of the joints.";
    E0605 = "E0605", "no steady motion for modal analysis",
        "`mbd modes` linearizes the equations about the initial state, and that linearization has \
modes only if the state is a steady motion: an equilibrium (at rest, or a uniform translation), \
or a rigid rotation of the whole model at one rate about one axis with every acceleration the \
centripetal one, in a model that is symmetric about that axis (then the equations are constant \
in the frame turning with it). A rotor on a non-rotating flexible structure, two rotors, gravity \
across the spin axis, or a support that is not symmetric about it make the equations periodic: \
their stability is Floquet analysis over one period, `mbd stability`. A state that accelerates \
(a pendulum released from the side, a structure not yet deflected under its load) is not an \
equilibrium. `mbd modes --frozen` gives the eigenvalues of the equations frozen at t = 0 anyway, \
marked `frozen` on every output: they are not the system's modes.";
    W0201 = "W0201", "unused param",
        "A param is declared but nothing uses it, not even an output. Remove it, or use it.";
    W0202 = "W0202", "unused declaration",
        "A let, a function, a section or a component is declared in the model file but never \
used. Remove it, or use it.";
    W0203 = "W0203", "angle without a unit",
        "An angle is given as a bare number, so it is read in radians: `rest_angle = 3` is 3 rad \
(172 deg), not 3 deg. Angles are dimensionless, so the compiler cannot tell; it warns when an \
angle (a revolute joint's `rest_angle` or prescribed `angle`, a beam's `twist`, the angle of \
`rotate(axis, angle)`, the phase of `sine`, a component argument of type `angle`) is not zero \
and its expression names no angle: no `rad`, `deg` or `rev` in a unit (`rad/s` counts), no \
`pi`, no `asin`, `acos`, `atan` or `atan2`, also through the params, lets and arguments it uses. \
Write `3 deg`, or `3 rad` to keep radians and silence the warning.";
    W0301 = "W0301", "body not connected to ground",
        "No chain of joints, springs or beams connects the body to a ground, so it floats: the \
warning names the free motions. That is right for a free-flight test and wrong almost everywhere \
else; with gravity, the body falls.";
    W0302 = "W0302", "motions without inertia not checked",
        "The check for motions with neither inertia nor restraint (E0308) looks only at bodies \
short of inertia (massless, or slender about an axis) that the joints do not hold one by one \
from something with inertia or from the ground, and factors each group of them coupled to \
each other densely. A group with more than 3,000 free motions (some 500 massless bodies joined \
to each other, none held) would take minutes, so it is not checked and this warning says so. \
If such a motion exists, the run stops at its first step with a singular iteration matrix \
(E0602). Give the bodies mass and inertia, or hold them.";
    W0701 = "W0701", "beam stiffer than the scene needs",
        "The sizing lint (run by `mbd check` and before `mbd run`) measures each elastic beam in \
its assembly: the model linearized at rest at its initial configuration, on its joints, with \
the masses it carries; the beam's frequency is the lowest of the modes in which it stores at \
least a tenth of the strain energy, and its deformation the quasi-static response in those \
modes to the scene's loads (gravity, the inertial \
forces of the initial motion through its consistent accelerations and the centripetal ones of \
each beam's spin, every load at 65 times over the run and at its piecewise knots), less the \
beam's best rigid motion. The scene's band is the highest of: 10 times the fastest rotor speed \
(its harmonics to 10/rev, from the initial spin and the drives), the characteristic frequency of \
every time function in a load or a drive (`max |f''| / max |f'|` over the run, `w` for \
`sin(w t)`; `2 pi / dt` for a piecewise function's shortest interval), and the highest \
frequency of the modes no beam owns (the scene's own motion: a pendulum's swing, a lag mode). Beams alike (same length, nodes and frequency: a rotor's blades) take the \
largest deformation among them. A beam is reported when it deforms at most 1e-4 of its length \
AND its frequency is at least 10 times the scene's band (nothing excites it), or at least 1 per \
step (`w h >= 1`: the step cannot resolve its vibration, the integrator only damps it), or it \
deforms at most 1e-7 of its length (even a resonance amplifying it 1,000 times, a damping \
ratio of 0.05 %, keeps it under 1e-4). Such a beam \
behaves as a rigid body at this step and these loads, but costs 6 unknowns a node and invites \
the instability of stiff midpoint integration. Write `beam NAME rigid { ... }` (the same \
declaration: its markers, `at(s)` and `node[k]` points keep working). The lint is dense and \
skips models of over 2,000 unknowns besides multipliers or 1,500 free motions (`mbd check` \
says so); `mbd check` prints each beam's figures and verdict.";
    W0702 = "W0702", "rigid beam more flexible than the scene allows",
        "A `beam NAME rigid` is measured as the elastic beam it declares, in its assembly (the \
model compiled with every rigid beam elastic; the figures as for W0701). It is reported when, \
as an elastic beam, it would deform at least 1e-3 of its length under the scene's loads, or \
its frequency would be within 3 times the scene's band while the step resolves it (`w h < 1`): \
then its elasticity changes the motion by more than a tenth of a percent, or its resonance is \
within reach. Drop `rigid` to model it as a beam.";
    W0703 = "W0703", "part that no output depends on",
        "No output channel reads the part, and no joint, spring, beam or two-ended load connects \
it (other than through a ground, which does not move) to a part an output reads: its motion \
cannot change any written column. It still costs unknowns and steps. Remove it, or add an \
output that reads it. Parts are rigid bodies, point masses and beams; a model without outputs \
is not checked.";
    W0303 = "W0303", "redundant but consistent constraints",
        "The joints' equations depend on each other at the initial configuration, no drive among \
them: a planar four-bar of four revolute joints about parallel axes (three equations too many in \
3-D), two hinges on one axis, a swashplate or pitch-link loop. Engineers build mechanisms so; \
the joints hold at the start (their markers coincide) and imply each other. The run drops the \
surplus equations (the rows the others span, chosen by pivoted Gram-Schmidt at the start and \
again after every step, keeping the set while it stays well conditioned), keeps watching \
them, and stops with E0608 if one drifts past 1e-6 (m, or rad for an axis): that is a \
singular position, where the mechanism locks or branches, not a redundancy. How the joints \
share the load is not determined by a rigid model; the reported joint forces are the \
minimum-norm split of the forces the loop carries (rows of moment units weighed divided by \
the model's length). A drive among the dependent equations, or a loop of over 600 unknowns, \
is refused instead (E0307). To have a split of your choosing, free \
joints until the warning goes (a spherical instead of a revolute, a cylindrical instead of a \
prismatic: a four-bar becomes revolute-revolute-spherical-cylindrical), or make a link \
elastic.";
    W0601 = "W0601", "initial velocities projected onto the constraints",
        "The initial velocities violate the joints' velocity constraints. They were projected onto \
the constraints in the metric of the mass matrix, which is exactly the impulsive response of the \
system to the joints being imposed at t = 0. Give consistent velocities to silence this.";
    W0602 = "W0602", "initial positions projected onto the constraints",
        "The initial positions violate a joint (for example a distance joint whose `length` differs \
from the distance between its markers). They were moved onto the constraints by the smallest \
mass-weighted correction.";
}

impl Code {
    pub fn is_warning(self) -> bool {
        self.as_str().starts_with('W')
    }

    pub fn parse(text: &str) -> Option<Code> {
        ALL_CODES
            .iter()
            .copied()
            .find(|c| c.as_str().eq_ignore_ascii_case(text.trim()))
    }
}

impl Serialize for Code {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
    }
}

/// The text `mbd explain CODE` prints, or `None` for an unknown code.
pub fn explain(code: &str) -> Option<String> {
    Code::parse(code).map(|c| format!("{}: {}\n\n{}\n", c.as_str(), c.title(), c.doc()))
}
