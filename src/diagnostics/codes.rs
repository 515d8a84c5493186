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
        "A unit is not one the compiler knows. Known units: kg g t m mm cm km s ms min h rad deg \
rev rpm Hz N kN J W Pa kPa MPa GPa, combined with `*`, `/` and integer powers `^`. A unit is \
written right after its number, without spaces inside (`9.81 m/s^2`). To multiply a quantity by \
a param, write the param first (`L * 2 m`) or use parentheses.";
    E0205 = "E0205", "unknown property",
        "A block sets a property that this kind of declaration does not have. The hint lists the \
properties it accepts.";
    E0206 = "E0206", "missing property",
        "A declaration lacks a property it needs, for example a `point_mass` without `mass` or `at`.";
    E0207 = "E0207", "circular definition",
        "A param is defined in terms of itself, directly or through other params.";
    E0208 = "E0208", "unknown --set name",
        "`--set NAME=VALUE` names a param the model does not declare. Only params can be \
overridden from the command line.";
    E0209 = "E0209", "wrong kind of value",
        "A vector was given where a scalar is needed, or the other way round, or a vector does not \
have three components.";
    E0210 = "E0210", "unknown function or wrong arguments",
        "A call names a function that does not exist, or passes the wrong number of arguments. \
Functions: sin cos tan asin acos atan atan2 sqrt abs exp ln min max; constant: pi.";
    E0211 = "E0211", "unknown declaration kind",
        "A joint kind, solver or option value is not known. The hint lists the known ones.";
    E0212 = "E0212", "unknown output quantity",
        "An `output` path does not name a quantity the model can compute. Bodies provide \
position, velocity and acceleration (and their .x .y .z components); joints provide force and \
violation.";
    E0213 = "E0213", "invalid value",
        "A value is outside its allowed range or not finite: a negative time step, an HHT alpha \
outside [-1/3, 0], a division by zero, the square root of a negative number.";
    E0301 = "E0301", "joint connects a body to itself",
        "Both markers of a joint are on the same body, so the joint constrains nothing. Connect it \
to another body or to ground.";
    E0302 = "E0302", "non-positive mass",
        "A body's mass must be positive. A massless point would make the iteration matrix singular.";
    E0303 = "E0303", "degenerate joint geometry",
        "A joint's geometry leaves its constraint undefined, such as a distance joint whose two \
markers coincide (zero length): its direction is undefined.";
    E0304 = "E0304", "model has no bodies",
        "Nothing moves: declare at least one body.";
    E0305 = "E0305", "joint between two grounds",
        "Both markers of the joint are fixed in the inertial frame, so the joint constrains no \
unknown.";
    E0306 = "E0306", "invalid marker",
        "A marker cannot be placed as written, for example with an offset on a point mass, which \
has no orientation to carry the offset.";
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
        "The requested time integrator is not available in this version of mbd. Use `hht`.";
    W0201 = "W0201", "unused param",
        "A param is declared but nothing uses it, not even an output. Remove it, or use it.";
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
