//! Physical dimensions and the unit table. Values are stored in SI; angles are dimensionless
//! (radians), so `rad`, `deg`, `rev` are pure numbers; `rpm` (revolutions per minute) and `Hz`
//! (cycles per second) are frequencies that carry the 2 pi of a cycle: `1 Hz` is 2 pi rad/s.
//!
//! Contract: plain data (dimensions, units, the quantities named in messages); must not know
//! expressions or names.

use serde::Serialize;
use std::fmt;

/// Exponents of mass, length and time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, Serialize)]
pub struct Dim {
    pub mass: i8,
    pub length: i8,
    pub time: i8,
}

impl Dim {
    pub const NONE: Dim = Dim {
        mass: 0,
        length: 0,
        time: 0,
    };
    pub const MASS: Dim = Dim {
        mass: 1,
        length: 0,
        time: 0,
    };
    pub const LENGTH: Dim = Dim {
        mass: 0,
        length: 1,
        time: 0,
    };
    pub const TIME: Dim = Dim {
        mass: 0,
        length: 0,
        time: 1,
    };
    pub const VELOCITY: Dim = Dim {
        mass: 0,
        length: 1,
        time: -1,
    };
    pub const ACCELERATION: Dim = Dim {
        mass: 0,
        length: 1,
        time: -2,
    };
    pub const FORCE: Dim = Dim {
        mass: 1,
        length: 1,
        time: -2,
    };

    pub const fn new(mass: i8, length: i8, time: i8) -> Dim {
        Dim { mass, length, time }
    }

    pub fn times(self, o: Dim) -> Dim {
        Dim::new(
            self.mass + o.mass,
            self.length + o.length,
            self.time + o.time,
        )
    }

    pub fn over(self, o: Dim) -> Dim {
        Dim::new(
            self.mass - o.mass,
            self.length - o.length,
            self.time - o.time,
        )
    }

    pub fn powi(self, n: i32) -> Dim {
        let n = n.clamp(-64, 64) as i8;
        Dim::new(
            self.mass.saturating_mul(n),
            self.length.saturating_mul(n),
            self.time.saturating_mul(n),
        )
    }

    /// The square root, if every exponent is even.
    pub fn sqrt(self) -> Option<Dim> {
        if self.mass % 2 == 0 && self.length % 2 == 0 && self.time % 2 == 0 {
            Some(Dim::new(self.mass / 2, self.length / 2, self.time / 2))
        } else {
            None
        }
    }

    pub fn is_none(self) -> bool {
        self == Dim::NONE
    }

    /// How messages name a value of this dimension, with the unit engineers write it in:
    /// `a bending stiffness [N*m^2]`, `a moment [N*m]`, `a dimensionless number`.
    pub fn describe(self) -> String {
        self.quantity().describe()
    }

    /// The quantity this dimension usually is, for messages (see [`NAMED`]).
    pub const fn quantity(self) -> Quantity {
        let mut i = 0;
        while i < NAMED.len() {
            let d = NAMED[i].dim;
            if d.mass == self.mass && d.length == self.length && d.time == self.time {
                return NAMED[i];
            }
            i += 1;
        }
        Quantity::new(self, "", "", "")
    }

    /// The dimension in conventional units: newtons for force-like dimensions (`N*s/m`,
    /// `N*m^3`), kilograms otherwise (`kg*m^2`), a positive power before a `/`.
    pub fn unit(self) -> String {
        let (mut kg, mut m, mut s) = (self.mass, self.length, self.time);
        let mut n = 0;
        if kg > 0 && s < 0 {
            n = kg;
            m -= kg;
            s += 2 * kg;
            kg = 0;
        }
        let (mut num, mut den) = (Vec::new(), Vec::new());
        for (name, e) in [("N", n), ("kg", kg), ("m", m), ("s", s)] {
            let power = |e: i8| {
                if e == 1 {
                    name.to_string()
                } else {
                    format!("{name}^{e}")
                }
            };
            match e {
                0 => {}
                e if e > 0 => num.push(power(e)),
                e => den.push(power(-e)),
            }
        }
        let num = if num.is_empty() {
            "1".to_string()
        } else {
            num.join("*")
        };
        match den.len() {
            0 => num,
            1 => format!("{num}/{}", den[0]),
            _ => format!("{num}/({})", den.join("*")),
        }
    }
}

/// A quantity as messages name it: what it is, the unit engineers write it in, and an example
/// value for hints. Where a dimension means several things (a moment and a torsional
/// stiffness are both N*m), the place that expects one names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Quantity {
    pub dim: Dim,
    /// With its article: "a bending stiffness"; empty for a dimension without a name.
    name: &'static str,
    /// Empty: [`Dim::unit`].
    unit: &'static str,
    /// A literal for hints, e.g. "14 N*m/rad"; empty: one of the unit.
    example: &'static str,
}

impl Quantity {
    pub const fn new(
        dim: Dim,
        name: &'static str,
        unit: &'static str,
        example: &'static str,
    ) -> Quantity {
        Quantity {
            dim,
            name,
            unit,
            example,
        }
    }

    /// `a bending stiffness [N*m^2]`; `a dimensionless number`; `a quantity in [N*m^3]`.
    pub fn describe(&self) -> String {
        let unit = if self.unit.is_empty() {
            self.dim.unit()
        } else {
            self.unit.to_string()
        };
        match (self.name, self.dim.is_none() && self.unit.is_empty()) {
            (n, true) if !n.is_empty() => n.to_string(),
            ("", true) => "a dimensionless number".to_string(),
            ("", false) => format!("a quantity in [{unit}]"),
            (n, _) => format!("{n} [{unit}]"),
        }
    }

    /// An example value, quoted: "`14 N*m/rad`".
    pub fn example(&self) -> String {
        match (self.example, self.dim.is_none()) {
            ("", true) => "`0.5`".to_string(),
            ("", false) => format!("`1 {}`", self.dim.unit()),
            (e, _) => format!("`{e}`"),
        }
    }
}

impl From<Dim> for Quantity {
    fn from(d: Dim) -> Quantity {
        d.quantity()
    }
}

/// What a value of each dimension is called when nothing says otherwise.
pub const NAMED: &[Quantity] = &[
    Quantity::new(Dim::NONE, "a dimensionless number", "", "0.5"),
    Quantity::new(Dim::MASS, "a mass", "kg", "1.0 kg"),
    Quantity::new(Dim::LENGTH, "a length", "m", "0.5 m"),
    Quantity::new(Dim::TIME, "a time", "s", "0.005 s"),
    Quantity::new(Dim::VELOCITY, "a velocity", "m/s", "1.5 m/s"),
    Quantity::new(Dim::ACCELERATION, "an acceleration", "m/s^2", "9.81 m/s^2"),
    Quantity::new(
        Dim::new(0, 0, -1),
        "an angular velocity",
        "rad/s",
        "98.17 rad/s",
    ),
    Quantity::new(
        Dim::new(0, 0, -2),
        "an angular acceleration",
        "rad/s^2",
        "2 rad/s^2",
    ),
    Quantity::new(Dim::FORCE, "a force", "N", "20 N"),
    Quantity::new(Dim::new(1, 2, -2), "a moment", "N*m", "14 N*m"),
    Quantity::new(Dim::new(1, 0, -2), "a stiffness", "N/m", "15434 N/m"),
    Quantity::new(Dim::new(1, 0, -1), "a damping", "N*s/m", "100 N*s/m"),
    Quantity::new(
        Dim::new(1, 2, -1),
        "a torsional damping",
        "N*m*s/rad",
        "2 N*m*s/rad",
    ),
    Quantity::new(
        Dim::new(1, 3, -2),
        "a bending stiffness",
        "N*m^2",
        "1.28e4 N*m^2",
    ),
    Quantity::new(Dim::new(1, -1, -2), "a pressure", "Pa", "70 GPa"),
    Quantity::new(Dim::new(1, 2, -3), "a power", "W", "100 W"),
    Quantity::new(Dim::new(1, 1, -1), "a momentum", "N*s", "1 N*s"),
    Quantity::new(
        Dim::new(1, 2, 0),
        "a moment of inertia",
        "kg*m^2",
        "48.6 kg*m^2",
    ),
    Quantity::new(Dim::new(1, -1, 0), "a mass per length", "kg/m", "3.29 kg/m"),
    Quantity::new(
        Dim::new(1, 1, 0),
        "an inertia per length",
        "kg*m^2/m",
        "0.1 kg*m",
    ),
    Quantity::new(Dim::new(1, -3, 0), "a density", "kg/m^3", "2700 kg/m^3"),
    Quantity::new(Dim::new(0, 2, 0), "an area", "m^2", "0.01 m^2"),
    Quantity::new(Dim::new(0, 3, 0), "a volume", "m^3", "0.001 m^3"),
];

/// Quantities that share a dimension with a more common one, named where they are expected.
pub const ANGLE: Quantity = Quantity::new(Dim::NONE, "an angle", "rad", "30 deg");
pub const TORQUE: Quantity = Quantity::new(Dim::new(1, 2, -2), "a torque", "N*m", "2.5 N*m");
pub const TORSIONAL_STIFFNESS: Quantity = Quantity::new(
    Dim::new(1, 2, -2),
    "a torsional stiffness",
    "N*m/rad",
    "14 N*m/rad",
);
pub const FREQUENCY: Quantity =
    Quantity::new(Dim::new(0, 0, -1), "a frequency", "rad/s", "9.26 rad/s");
pub const AXIAL_STIFFNESS: Quantity =
    Quantity::new(Dim::FORCE, "an axial stiffness", "N", "8.53e7 N");
pub const SHEAR_STIFFNESS: Quantity = Quantity::new(Dim::FORCE, "a shear stiffness", "N", "1e6 N");
pub const TORSIONAL_RIGIDITY: Quantity = Quantity::new(
    Dim::new(1, 3, -2),
    "a torsional stiffness",
    "N*m^2",
    "1e3 N*m^2",
);

impl fmt::Display for Dim {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        for (name, e) in [("kg", self.mass), ("m", self.length), ("s", self.time)] {
            match e {
                0 => {}
                1 => parts.push(name.to_string()),
                e => parts.push(format!("{name}^{e}")),
            }
        }
        if parts.is_empty() {
            write!(f, "1")
        } else {
            write!(f, "{}", parts.join("*"))
        }
    }
}

/// The units the compiler knows: name, factor to SI, dimension.
pub const UNITS: &[(&str, f64, Dim)] = &[
    ("kg", 1.0, Dim::MASS),
    ("g", 1e-3, Dim::MASS),
    ("m", 1.0, Dim::LENGTH),
    ("mm", 1e-3, Dim::LENGTH),
    ("cm", 1e-2, Dim::LENGTH),
    ("km", 1e3, Dim::LENGTH),
    ("s", 1.0, Dim::TIME),
    ("ms", 1e-3, Dim::TIME),
    ("min", 60.0, Dim::TIME),
    ("h", 3600.0, Dim::TIME),
    ("rad", 1.0, Dim::NONE),
    ("deg", std::f64::consts::PI / 180.0, Dim::NONE),
    ("rev", 2.0 * std::f64::consts::PI, Dim::NONE),
    ("rpm", 2.0 * std::f64::consts::PI / 60.0, Dim::new(0, 0, -1)),
    ("Hz", 2.0 * std::f64::consts::PI, Dim::new(0, 0, -1)),
    ("N", 1.0, Dim::FORCE),
    ("kN", 1e3, Dim::FORCE),
    ("J", 1.0, Dim::new(1, 2, -2)),
    ("W", 1.0, Dim::new(1, 2, -3)),
    ("Pa", 1.0, Dim::new(1, -1, -2)),
    ("kPa", 1e3, Dim::new(1, -1, -2)),
    ("MPa", 1e6, Dim::new(1, -1, -2)),
    ("GPa", 1e9, Dim::new(1, -1, -2)),
];

pub fn lookup(name: &str) -> Option<(f64, Dim)> {
    UNITS
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, f, d)| (*f, *d))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derived_dimensions_compose() {
        let (_, n) = lookup("N").unwrap_or((0.0, Dim::NONE));
        assert_eq!(n, Dim::MASS.times(Dim::ACCELERATION));
        assert_eq!(Dim::LENGTH.powi(2).sqrt(), Some(Dim::LENGTH));
        assert_eq!(Dim::LENGTH.sqrt(), None);
        assert_eq!(Dim::ACCELERATION.to_string(), "m*s^-2");
    }

    #[test]
    fn dimensions_read_as_engineers_write_them() {
        assert_eq!(Dim::new(1, 3, -2).describe(), "a bending stiffness [N*m^2]");
        assert_eq!(Dim::new(1, 2, -2).describe(), "a moment [N*m]");
        assert_eq!(
            TORSIONAL_STIFFNESS.describe(),
            "a torsional stiffness [N*m/rad]"
        );
        assert_eq!(Dim::NONE.describe(), "a dimensionless number");
        assert_eq!(ANGLE.describe(), "an angle [rad]");
        assert_eq!(Dim::new(1, 4, -2).describe(), "a quantity in [N*m^3]");
        assert_eq!(Dim::new(1, 0, -1).unit(), "N*s/m");
        assert_eq!(Dim::new(1, 2, 0).unit(), "kg*m^2");
        assert_eq!(Dim::new(0, 1, -2).unit(), "m/s^2");
        assert_eq!(Dim::new(1, -2, -1).unit(), "N*s/m^3");
        assert_eq!(Dim::new(-1, -1, 0).unit(), "1/(kg*m)");
        assert_eq!(Dim::new(0, 0, -1).quantity().example(), "`98.17 rad/s`");
        // Every name is distinct per dimension.
        for (i, q) in NAMED.iter().enumerate() {
            assert!(NAMED[i + 1..].iter().all(|p| p.dim != q.dim), "{q:?}");
        }
    }
}
