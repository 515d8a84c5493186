//! The joints that had no numerical test: spherical (a heavy top hanging from a ball joint),
//! universal (the Cardan velocity ratio), cylindrical (free slide and spin, its reactions) and
//! the dampers (a prismatic joint's spring and damper, the standalone `damper`, a revolute's
//! rotational damper and the lag damper of `stdlib::rotor`). Each against a closed form or its
//! reduced equations of motion integrated here by `reference::dopri` (relative tolerance 1e-12);
//! the library is used only for the run under test.

mod cylindrical;
mod dampers;
mod spherical;
mod universal;

use crate::common::{simulate_text, within, Trace};
use crate::rigid::overrides;

/// Runs model text with the step and end time given; a run-time failure fails the test.
pub(crate) fn run(name: &str, text: &str, dt: f64, until: f64) -> Trace {
    simulate_text(name, text, overrides(dt, until)).unwrap_or_else(|(_, m)| panic!("{name}: {m}"))
}

/// The largest absolute value.
pub(crate) fn max_abs(v: impl IntoIterator<Item = f64>) -> f64 {
    v.into_iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Angles made continuous (steps of more than pi taken as wraps).
pub(crate) fn unwrap(angles: &[f64]) -> Vec<f64> {
    use std::f64::consts::{PI, TAU};
    let mut out: Vec<f64> = Vec::with_capacity(angles.len());
    for &a in angles {
        let next = match out.last() {
            Some(&prev) => prev + (a - prev + PI).rem_euclid(TAU) - PI,
            None => a,
        };
        out.push(next);
    }
    out
}

/// The orders `log2(e(dt) / e(dt/2))` of errors measured at halving steps, each within 0.3 of
/// `expected`.
#[track_caller]
pub(crate) fn assert_order(what: &str, errors: &[f64], expected: f64) {
    for w in errors.windows(2) {
        let p = (w[0] / w[1]).log2();
        eprintln!("{what}: order {p:.3}");
        within(
            &format!("{what}: order - {expected}"),
            (p - expected).abs(),
            0.3,
        );
    }
}

/// Entry `i` of each row of measurements.
pub(crate) fn column<const N: usize>(rows: &[[f64; N]], i: usize) -> Vec<f64> {
    rows.iter().map(|r| r[i]).collect()
}

/// Rotation `r` (rows of direction cosines) as output in the columns `NAME.rotation.rIJ`.
pub(crate) fn rotation(tr: &Trace, name: &str, k: usize) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| tr.col(&format!("{name}.rotation.r{}{}", i + 1, j + 1))[k])
    })
}

/// The angle of the rotation taking `a` to `b` (rotation matrices), accurate near zero.
pub(crate) fn rotation_angle(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> f64 {
    // r = a^T b; its axial vector has length sin(angle), its trace is 1 + 2 cos(angle).
    let r: [[f64; 3]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[k][i] * b[k][j]).sum()));
    let axial = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]].map(|x| x / 2.0);
    let sin = dot(axial, axial).sqrt();
    sin.atan2((r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0)
}

/// A vector output as its three columns `NAME.x`, `NAME.y`, `NAME.z` at row `k`.
pub(crate) fn vector(tr: &Trace, name: &str, k: usize) -> [f64; 3] {
    ["x", "y", "z"].map(|c| tr.col(&format!("{name}.{c}"))[k])
}

pub(crate) fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| a[i] * b[i]).sum()
}
