//! The ends of joints, springs and loads: markers on the ground, a body or a beam node, their
//! kinematics at a state, and both ends of a joint with its angle (`Geo`).

use super::{Grad, PHI, SLOTS, TA, TB, UA, UB};
use crate::runtime::rotation::{M3, V3};
use crate::runtime::{m3, State};
use serde::{Deserialize, Serialize};

/// One end of a joint, spring or load: a marker (point and axes).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "end", rename_all = "snake_case")]
pub enum End {
    /// Fixed in the inertial frame. `axes`: columns are the marker axes.
    Ground {
        point: [f64; 3],
        axes: [[f64; 3]; 3],
    },
    /// On a point mass: it translates and never rotates.
    Point {
        dofs: [usize; 3],
        axes: [[f64; 3]; 3],
    },
    /// On a rotating node, at `offset` from it; `offset` and `axes` in inertial components at
    /// t = 0 (they turn with the node's rotation).
    Node {
        dofs: [usize; 6],
        node: usize,
        offset: [f64; 3],
        axes: [[f64; 3]; 3],
    },
}

/// An end's kinematics at a state (inertial components).
#[derive(Clone, Copy, Debug)]
pub struct EndKin {
    /// The marker point.
    pub x: V3,
    /// From the node to the marker point (zero for grounds and point masses).
    pub p: V3,
    /// Marker axes (columns).
    pub e: M3,
    /// Velocity of the node's translation and angular velocity.
    pub v: V3,
    pub w: V3,
    /// Acceleration of the node's translation and angular acceleration.
    pub a: V3,
    pub dw: V3,
}

impl End {
    pub fn dofs(&self) -> &[usize] {
        match self {
            End::Ground { .. } => &[],
            End::Point { dofs, .. } => dofs,
            End::Node { dofs, .. } => dofs,
        }
    }

    pub fn kin(&self, st: &State) -> EndKin {
        match self {
            End::Ground { point, axes } => EndKin {
                x: V3::from(*point),
                p: V3::zeros(),
                e: m3(axes),
                v: V3::zeros(),
                w: V3::zeros(),
                a: V3::zeros(),
                dw: V3::zeros(),
            },
            End::Point { dofs, axes } => EndKin {
                x: V3::from(dofs.map(|i| st.q[i])),
                p: V3::zeros(),
                e: m3(axes),
                v: V3::from(dofs.map(|i| st.v[i])),
                w: V3::zeros(),
                a: V3::from(dofs.map(|i| st.a[i])),
                dw: V3::zeros(),
            },
            End::Node {
                dofs,
                node,
                offset,
                axes,
            } => {
                let n = &st.rot[*node];
                let r = n.matrix();
                let p = r * V3::from(*offset);
                EndKin {
                    x: V3::new(st.q[dofs[0]], st.q[dofs[1]], st.q[dofs[2]]) + p,
                    p,
                    e: r * m3(axes),
                    v: V3::new(st.v[dofs[0]], st.v[dofs[1]], st.v[dofs[2]]),
                    w: n.omega(),
                    a: V3::new(st.a[dofs[0]], st.a[dofs[1]], st.a[dofs[2]]),
                    dw: n.omega_dot(),
                }
            }
        }
    }

    /// Local positions of this end's slots, starting at local index `at`.
    pub(super) fn slot_map(
        &self,
        at: usize,
        base: usize,
        map: &mut [Option<usize>; SLOTS],
    ) -> usize {
        let n = self.dofs().len();
        for (k, m) in map[base..base + n].iter_mut().enumerate() {
            *m = Some(at + k);
        }
        n
    }
}

impl EndKin {
    /// Velocity of the marker point.
    pub fn point_velocity(&self) -> V3 {
        self.v + self.w.cross(&self.p)
    }

    pub fn point_acceleration(&self) -> V3 {
        self.a + self.dw.cross(&self.p) + self.w.cross(&self.w.cross(&self.p))
    }
}

/// Both ends of a joint and its angle, at a state.
pub(crate) struct Geo {
    pub a: EndKin,
    pub b: EndKin,
    pub phi: f64,
    /// Generalized velocities `(v_A, w_A, v_B, w_B, phi-dot)`.
    pub vel: Grad,
}

impl Geo {
    pub fn new(a: &End, b: &End, angle: Option<usize>, st: &State) -> Geo {
        let (ka, kb) = (a.kin(st), b.kin(st));
        let mut vel = [0.0; SLOTS];
        vel[UA..UA + 3].copy_from_slice(ka.v.as_slice());
        vel[TA..TA + 3].copy_from_slice(ka.w.as_slice());
        vel[UB..UB + 3].copy_from_slice(kb.v.as_slice());
        vel[TB..TB + 3].copy_from_slice(kb.w.as_slice());
        let mut phi = 0.0;
        if let Some(i) = angle {
            phi = st.q[i];
            vel[PHI] = st.v[i];
        }
        Geo {
            a: ka,
            b: kb,
            phi,
            vel,
        }
    }

    /// `d = x_B - x_A` between the marker points.
    pub(super) fn d(&self) -> V3 {
        self.b.x - self.a.x
    }
}
