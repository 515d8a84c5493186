//! Free rigid body (THEORY.md §10.2 item 3): Euler's equations with quaternion kinematics.
//!
//! Contract: plain `f64` arithmetic only (see `mod.rs`): no `mbd`, no other crate.

use super::dopri;

/// Rotation matrix of a (not necessarily unit) quaternion `[w, x, y, z]`, normalized first.
pub fn quat_to_matrix(q: [f64; 4]) -> [[f64; 3]; 3] {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let [w, x, y, z] = q.map(|v| v / n);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// Torque-free rigid body with principal moments `inertia` (body frame), starting at `R = I`
/// with body angular velocity `omega0_body`. Integrates Euler's equations `J w' + w x J w = 0`
/// with the quaternion kinematics `q' = q (0, w)/2` (rtol 1e-13, atol 1e-15), normalizing only
/// at output.
/// Returns `(R, w)` at each time, `R` body to inertial.
pub fn free_body(
    inertia: [f64; 3],
    omega0_body: [f64; 3],
    times: &[f64],
) -> Vec<([[f64; 3]; 3], [f64; 3])> {
    let [j1, j2, j3] = inertia;
    assert!(
        j1 > 0.0 && j2 > 0.0 && j3 > 0.0,
        "free_body: principal moments must be positive"
    );
    let rhs = |_t: f64, y: &[f64; 7]| {
        let [w1, w2, w3, q0, q1, q2, q3] = *y;
        [
            (j2 - j3) / j1 * w2 * w3,
            (j3 - j1) / j2 * w3 * w1,
            (j1 - j2) / j3 * w1 * w2,
            0.5 * (-q1 * w1 - q2 * w2 - q3 * w3),
            0.5 * (q0 * w1 + q2 * w3 - q3 * w2),
            0.5 * (q0 * w2 + q3 * w1 - q1 * w3),
            0.5 * (q0 * w3 + q1 * w2 - q2 * w1),
        ]
    };
    let [w1, w2, w3] = omega0_body;
    let y0 = [w1, w2, w3, 1.0, 0.0, 0.0, 0.0];
    dopri(rhs, 0.0, y0, times, 1e-13, 1e-15)
        .into_iter()
        .map(|[w1, w2, w3, q0, q1, q2, q3]| (quat_to_matrix([q0, q1, q2, q3]), [w1, w2, w3]))
        .collect()
}
