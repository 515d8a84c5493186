//! Physical dimensions and the unit table. Values are stored in SI; angles are dimensionless
//! (radians), so `rad`, `deg`, `rev` are pure numbers; `rpm` (revolutions per minute) and `Hz`
//! (cycles per second) are frequencies that carry the 2 pi of a cycle: `1 Hz` is 2 pi rad/s.

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

    /// A name an engineer recognises, for messages.
    pub fn describe(self) -> String {
        let named = match (self.mass, self.length, self.time) {
            (0, 0, 0) => Some("dimensionless"),
            (1, 0, 0) => Some("mass"),
            (0, 1, 0) => Some("length"),
            (0, 0, 1) => Some("time"),
            (0, 1, -1) => Some("velocity"),
            (0, 1, -2) => Some("acceleration"),
            (0, 0, -1) => Some("frequency"),
            (1, 1, -2) => Some("force"),
            (1, 2, -2) => Some("moment or energy"),
            (1, 0, -2) => Some("stiffness"),
            (1, -1, -2) => Some("pressure"),
            (1, 2, 0) => Some("moment of inertia"),
            _ => None,
        };
        match named {
            Some(n) => format!("{n} [{self}]"),
            None => format!("[{self}]"),
        }
    }
}

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
}
