//! Values (constants and signals, always in SI) and the 3x3 matrix arithmetic of rotations.
//! Contract: plain data and arithmetic; must not know names, scopes or diagnostics.

use super::units::Dim;
use crate::runtime::timefn::TimeFn;
use serde::Serialize;

/// A value, always in SI.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Value {
    Scalar {
        value: f64,
        dim: Dim,
    },
    Vector {
        value: [f64; 3],
        dim: Dim,
    },
    /// A rotation matrix, from `rotate(axis, angle)`.
    Rotation {
        matrix: [[f64; 3]; 3],
    },
    /// A scalar (one part) or vector (three parts) that varies in time.
    Signal {
        parts: Vec<TimeFn>,
        dim: Dim,
    },
}

impl Value {
    pub fn scalar(value: f64, dim: Dim) -> Value {
        Value::Scalar { value, dim }
    }

    pub fn dim(&self) -> Dim {
        match self {
            Value::Scalar { dim, .. } | Value::Vector { dim, .. } | Value::Signal { dim, .. } => {
                *dim
            }
            Value::Rotation { .. } => Dim::NONE,
        }
    }

    pub fn with_dim(self, dim: Dim) -> Value {
        match self {
            Value::Scalar { value, .. } => Value::Scalar { value, dim },
            Value::Vector { value, .. } => Value::Vector { value, dim },
            Value::Signal { parts, .. } => Value::Signal { parts, dim },
            r => r,
        }
    }

    pub fn kind_name(&self) -> &'static str {
        match self {
            Value::Scalar { .. } => "a scalar",
            Value::Vector { .. } => "a vector",
            Value::Rotation { .. } => "a rotation",
            Value::Signal { parts, .. } if parts.len() == 1 => "a function of time",
            Value::Signal { .. } => "a vector function of time",
        }
    }

    /// Components as time functions, with the dimension (`None` for a rotation).
    pub fn parts(&self) -> Option<(Vec<TimeFn>, Dim)> {
        match self {
            Value::Scalar { value, dim } => Some((vec![TimeFn::constant(*value)], *dim)),
            Value::Vector { value, dim } => {
                Some((value.iter().map(|x| TimeFn::constant(*x)).collect(), *dim))
            }
            Value::Signal { parts, dim } => Some((parts.clone(), *dim)),
            Value::Rotation { .. } => None,
        }
    }

    /// Builds a value from parts, folding constants.
    pub fn from_parts(parts: Vec<TimeFn>, dim: Dim) -> Value {
        let consts: Option<Vec<f64>> = parts.iter().map(|p| p.as_constant()).collect();
        match (consts, parts.len()) {
            (Some(c), 1) => Value::Scalar { value: c[0], dim },
            (Some(c), 3) => Value::Vector {
                value: [c[0], c[1], c[2]],
                dim,
            },
            _ => Value::Signal { parts, dim },
        }
    }

    pub(super) fn is_finite(&self) -> bool {
        match self {
            Value::Scalar { value, .. } => value.is_finite(),
            Value::Vector { value, .. } => value.iter().all(|x| x.is_finite()),
            Value::Rotation { matrix } => matrix.iter().flatten().all(|x| x.is_finite()),
            Value::Signal { .. } => true,
        }
    }
}

pub fn transpose(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = m[j][i];
        }
    }
    t
}

pub fn mat_mul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

pub fn mat_vec(a: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

/// The rotation by `angle` about the unit vector `n` (Rodrigues).
pub fn rotation(n: [f64; 3], angle: f64) -> [[f64; 3]; 3] {
    let (s, c) = angle.sin_cos();
    let k = [[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]];
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let id = if i == j { 1.0 } else { 0.0 };
            r[i][j] = id * c + s * k[i][j] + (1.0 - c) * n[i] * n[j];
        }
    }
    r
}
