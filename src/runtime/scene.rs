//! What a 3-D view draws (`mbd view`, `mbd run --view`, `--gltf`): the model's parts as
//! shapes on anchors, each anchor a point with axes that moves with the state ([`End`]), and
//! the anchors' poses sampled along a run.
//!
//! Contract: plain data built by the lowering (`lower::scene`), sampled here from states;
//! knows no file format (the HTML and glTF writers are in `output/view`).

use super::rotation::{M3, V3};
use super::timefn::TimeFn;
use super::{End, State};
use serde::Serialize;

/// A point with axes followed through the run: a body's frame, a beam node's, a marker's.
#[derive(Clone, Debug)]
pub struct Anchor {
    pub end: End,
}

/// How a shape looks, in its anchor's axes (lengths in m).
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Look {
    /// A box with these half-sizes, centred at `center` (anchor axes).
    Box { half: [f64; 3], center: [f64; 3] },
    /// A sphere.
    Sphere { radius: f64, center: [f64; 3] },
    /// A cylinder along the anchor's axis 1, from `-length/2` to `length/2` about `center`.
    Cylinder {
        radius: f64,
        length: f64,
        center: [f64; 3],
    },
    /// The anchor's three axes as lines of this length (red, green, blue).
    Triad { size: f64 },
    /// A tube from this anchor to anchor `to` (beam segments, distance links, springs:
    /// `coils` turns, 0 for a straight tube).
    Link { to: usize, radius: f64, coils: u32 },
    /// An arrow from the anchor along a vector that changes in time (a load): `scale` m per
    /// unit of the load at its largest.
    Arrow { load: usize, scale: f64 },
    /// A square grid in the plane normal to `normal`, this wide (the ground).
    Grid { size: f64, normal: [f64; 3] },
}

/// One drawn shape: what it is (for the names on hover), where, and how.
#[derive(Clone, Debug, Serialize)]
pub struct Shape {
    /// The entity's name as the model writes it (`rotor.blade[1]`).
    pub name: String,
    /// What it is: `rigid body`, `revolute joint`, `beam`, `force`, ...
    pub kind: String,
    /// A line of facts shown on hover, with units (`20 kg`, `axis (0, 0, 1)`).
    pub info: String,
    pub anchor: usize,
    pub look: Look,
    /// sRGB, 0xRRGGBB.
    pub color: u32,
}

/// A load as the view draws it: its components at time t, inertial or in the anchor's axes.
#[derive(Clone, Debug)]
pub struct LoadVector {
    pub value: [TimeFn; 3],
    pub follower: bool,
    /// A torque (drawn as a double-headed arrow), else a force.
    pub torque: bool,
}

/// The scene: anchors, shapes, loads, and the model's size (m), its name and its gravity.
#[derive(Clone, Debug)]
pub struct Scene {
    pub anchors: Vec<Anchor>,
    pub shapes: Vec<Shape>,
    pub loads: Vec<LoadVector>,
    pub size: f64,
    pub up: [f64; 3],
}

/// The anchors' poses at sampled times: per sample, each anchor's position (3) and rotation
/// as a unit quaternion `(x, y, z, w)` (4), and each load's vector (3), inertial.
#[derive(Clone, Debug, Default)]
pub struct Frames {
    pub t: Vec<f64>,
    pub positions: Vec<f32>,
    pub rotations: Vec<f32>,
    pub loads: Vec<f32>,
}

impl Scene {
    /// Appends the poses at a state.
    pub fn sample(&self, st: &State, frames: &mut Frames) {
        frames.t.push(st.t);
        for a in &self.anchors {
            let k = a.end.kin(st);
            frames.positions.extend(k.x.iter().map(|&x| x as f32));
            frames.rotations.extend(quaternion(&k.e).map(|x| x as f32));
        }
        for l in &self.loads {
            let v = V3::new(
                l.value[0].eval(st.t),
                l.value[1].eval(st.t),
                l.value[2].eval(st.t),
            );
            frames.loads.extend(v.iter().map(|&x| x as f32));
        }
    }

    /// Turns the loads sampled in anchor axes (followers) into inertial components.
    pub fn finish(&self, frames: &mut Frames) {
        let (na, nl) = (self.anchors.len(), self.loads.len());
        for s in 0..frames.t.len() {
            for (i, l) in self.loads.iter().enumerate() {
                if !l.follower {
                    continue;
                }
                let Some(Shape { anchor, .. }) = self
                    .shapes
                    .iter()
                    .find(|sh| matches!(sh.look, Look::Arrow { load, .. } if load == i))
                else {
                    continue;
                };
                let q = &frames.rotations[4 * (s * na + anchor)..4 * (s * na + anchor) + 4];
                let r = rotation_of([q[0] as f64, q[1] as f64, q[2] as f64, q[3] as f64]);
                let at = 3 * (s * nl + i);
                let v = V3::new(
                    frames.loads[at] as f64,
                    frames.loads[at + 1] as f64,
                    frames.loads[at + 2] as f64,
                );
                let w = r * v;
                for k in 0..3 {
                    frames.loads[at + k] = w[k] as f32;
                }
            }
        }
    }
}

/// The unit quaternion `(x, y, z, w)` of a rotation matrix whose columns are the axes
/// (Shepperd's method: the largest of the four candidates, so no cancellation).
pub fn quaternion(e: &M3) -> [f64; 4] {
    let (m00, m11, m22) = (e[(0, 0)], e[(1, 1)], e[(2, 2)]);
    let tr = m00 + m11 + m22;
    let q = if tr >= m00.max(m11).max(m22) {
        let s = (1.0 + tr).max(0.0).sqrt() * 2.0;
        [
            (e[(2, 1)] - e[(1, 2)]) / s,
            (e[(0, 2)] - e[(2, 0)]) / s,
            (e[(1, 0)] - e[(0, 1)]) / s,
            0.25 * s,
        ]
    } else if m00 >= m11 && m00 >= m22 {
        let s = (1.0 + m00 - m11 - m22).max(0.0).sqrt() * 2.0;
        [
            0.25 * s,
            (e[(0, 1)] + e[(1, 0)]) / s,
            (e[(0, 2)] + e[(2, 0)]) / s,
            (e[(2, 1)] - e[(1, 2)]) / s,
        ]
    } else if m11 >= m22 {
        let s = (1.0 + m11 - m00 - m22).max(0.0).sqrt() * 2.0;
        [
            (e[(0, 1)] + e[(1, 0)]) / s,
            0.25 * s,
            (e[(1, 2)] + e[(2, 1)]) / s,
            (e[(0, 2)] - e[(2, 0)]) / s,
        ]
    } else {
        let s = (1.0 + m22 - m00 - m11).max(0.0).sqrt() * 2.0;
        [
            (e[(0, 2)] + e[(2, 0)]) / s,
            (e[(1, 2)] + e[(2, 1)]) / s,
            0.25 * s,
            (e[(1, 0)] - e[(0, 1)]) / s,
        ]
    };
    let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    q.map(|x| x / n)
}

/// The rotation matrix of a unit quaternion `(x, y, z, w)`.
pub fn rotation_of([x, y, z, w]: [f64; 4]) -> M3 {
    M3::new(
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - z * w),
        2.0 * (x * z + y * w),
        2.0 * (x * y + z * w),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - x * w),
        2.0 * (x * z - y * w),
        2.0 * (y * z + x * w),
        1.0 - 2.0 * (x * x + y * y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quaternion and its matrix round-trip for rotations near each of Shepperd's branches.
    #[test]
    fn quaternions_round_trip() {
        for (axis, angle) in [
            ([0.0, 0.0, 1.0], 0.3),
            ([1.0, 0.0, 0.0], 3.1),
            ([0.0, 1.0, 0.0], -3.0),
            ([0.0, 0.0, 1.0], 3.13),
            ([0.6, 0.0, 0.8], 2.0),
        ] {
            let r = *nalgebra::Rotation3::from_axis_angle(
                &nalgebra::Unit::new_normalize(V3::from(axis)),
                angle,
            )
            .matrix();
            let back = rotation_of(quaternion(&r));
            assert!((back - r).norm() < 1e-14, "{axis:?} {angle}");
        }
    }
}
