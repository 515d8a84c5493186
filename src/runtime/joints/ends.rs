//! The ends of joints, springs and loads: markers on the ground, a body, a beam node or a
//! point between a beam element's nodes, their kinematics at a state, how each end's slots
//! reach its unknowns (`Spreads`), and both ends of a joint with its angle (`Geo`).
//!
//! A point between nodes moves with the element's field: its reference point at
//! `sum N_k x_k`, its triad the element's interpolated `T(xi)`, whose variation is
//! `dtheta(xi) = sum A_l dtheta_l`; its velocities are interpolated as the element's inertia
//! interpolates them, `sum N_k v_k` and `sum N_k w_k`. A joint's rows are differentiated
//! through that variation (the trial side: exact rows), and the forces on the end reach the
//! nodes through the element's own test functions `N_k` (Petrov-Galerkin, as the element's
//! distributed forces), so the tangent is exact without second derivatives of the
//! interpolation.

use super::{Grad, PHI, SLOTS, TA, TB, UA, UB};
use crate::runtime::beams::{triad_between, MAXN};
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
    /// Between the nodes of a beam element.
    Between(Box<Between>),
}

/// A marker between the nodes of a beam element.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Between {
    /// 6 unknowns per element node: translation, then rotation.
    pub dofs: Vec<usize>,
    /// The rotating node of each element node.
    pub nodes: Vec<usize>,
    /// Each element node's section triad at t = 0 (columns).
    pub triads: Vec<[[f64; 3]; 3]>,
    /// The shape functions at the point.
    pub n: [f64; MAXN],
    /// The marker's offset from the interpolated point and its axes, in the interpolated
    /// triad's axes at t = 0.
    pub offset: [f64; 3],
    pub axes: [[f64; 3]; 3],
}

impl Between {
    /// The interpolated triad now and its variation operators.
    fn triad(&self, st: &State) -> (M3, [M3; MAXN]) {
        let mut t = [M3::identity(); MAXN];
        for (k, tk) in t.iter_mut().enumerate().take(self.nodes.len()) {
            *tk = st.rot[self.nodes[k]].matrix() * m3(&self.triads[k]);
        }
        triad_between(&t[..self.nodes.len()], &self.n)
    }

    fn kin(&self, st: &State) -> EndKin {
        let (t, _) = self.triad(st);
        let p = t * V3::from(self.offset);
        let mut k = EndKin {
            x: p,
            p,
            e: t * m3(&self.axes),
            v: V3::zeros(),
            w: V3::zeros(),
            a: V3::zeros(),
            dw: V3::zeros(),
            turns: true,
        };
        let at = |v: &[f64], d: &[usize]| V3::new(v[d[0]], v[d[1]], v[d[2]]);
        for (j, d) in self.dofs.chunks(6).enumerate() {
            let n = self.n[j];
            k.x += at(&st.q, d) * n;
            k.v += at(&st.v, d) * n;
            k.a += at(&st.a, d) * n;
            let node = &st.rot[self.nodes[j]];
            k.w += node.omega() * n;
            k.dw += node.omega_dot() * n;
        }
        k
    }
}

/// Where one slot of an end reaches the end's local unknowns: up to `3 MAXN` pairs
/// (local index, coefficient).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Spread {
    at: [usize; 3 * MAXN],
    c: [f64; 3 * MAXN],
    len: usize,
}

impl Spread {
    const EMPTY: Spread = Spread {
        at: [0; 3 * MAXN],
        c: [0.0; 3 * MAXN],
        len: 0,
    };

    fn one(at: usize) -> Spread {
        let mut s = Spread::EMPTY;
        s.push(at, 1.0);
        s
    }

    fn push(&mut self, at: usize, c: f64) {
        self.at[self.len] = at;
        self.c[self.len] = c;
        self.len += 1;
    }

    pub fn iter(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.at[..self.len]
            .iter()
            .copied()
            .zip(self.c[..self.len].iter().copied())
    }
}

/// How the 13 slots of a joint, spring or load reach its local unknowns `(a dofs, b dofs,
/// angle)`: `trial[s]`, the slot's variation as a combination of them (rows and the columns
/// of the tangent); `rate[s]`, the slot's velocity as a combination of their rates; `test[s]`,
/// where a generalized force on the slot lands (residual rows). A slot an end lacks is empty.
pub(crate) struct Spreads {
    pub trial: [Spread; SLOTS],
    pub rate: [Spread; SLOTS],
    pub test: [Spread; SLOTS],
    /// Local unknowns.
    pub locals: usize,
    /// Whether every slot is at most one unknown with coefficient 1 (no end between nodes).
    pub plain: bool,
}

impl Spreads {
    pub fn new(a: &End, b: &End, angle: Option<usize>, st: &State) -> Spreads {
        let mut sp = Spreads {
            trial: [Spread::EMPTY; SLOTS],
            rate: [Spread::EMPTY; SLOTS],
            test: [Spread::EMPTY; SLOTS],
            locals: 0,
            plain: true,
        };
        for (end, base) in [(a, UA), (b, UB)] {
            let at = sp.locals;
            sp.locals += end.dofs().len();
            match end {
                End::Ground { .. } => {}
                End::Point { .. } | End::Node { .. } => {
                    for k in 0..end.dofs().len() {
                        sp.trial[base + k] = Spread::one(at + k);
                        sp.rate[base + k] = Spread::one(at + k);
                        sp.test[base + k] = Spread::one(at + k);
                    }
                }
                End::Between(bt) => {
                    sp.plain = false;
                    let (_, ops) = bt.triad(st);
                    for j in 0..bt.nodes.len() {
                        let n = bt.n[j];
                        for i in 0..3 {
                            let (u, t) = (at + 6 * j + i, at + 6 * j + 3 + i);
                            sp.trial[base + i].push(u, n);
                            sp.rate[base + i].push(u, n);
                            sp.test[base + i].push(u, n);
                            sp.rate[base + 3 + i].push(t, n);
                            sp.test[base + 3 + i].push(t, n);
                            for c in 0..3 {
                                sp.trial[base + 3 + i].push(at + 6 * j + 3 + c, ops[j][(i, c)]);
                            }
                        }
                    }
                }
            }
        }
        if angle.is_some() {
            sp.trial[PHI] = Spread::one(sp.locals);
            sp.rate[PHI] = Spread::one(sp.locals);
            sp.test[PHI] = Spread::one(sp.locals);
            sp.locals += 1;
        }
        sp
    }

    /// Adds the slot forces `force` to the residual `out` at the unknowns of `ends` (the two
    /// ends and the angle: the local order's globals).
    pub fn add_forces(
        &self,
        force: &[f64; SLOTS],
        (a, b, angle): (&End, &End, Option<usize>),
        out: &mut [f64],
    ) {
        let (da, db) = (a.dofs(), b.dofs());
        let global = |l: usize| match l {
            l if l < da.len() => da[l],
            l if l < da.len() + db.len() => db[l - da.len()],
            _ => angle.unwrap_or(usize::MAX),
        };
        for (s, f) in force.iter().enumerate() {
            for (l, c) in self.test[s].iter() {
                out[global(l)] += c * f;
            }
        }
    }

    /// Adds the slot-space matrix `h` (rows: test, columns: trial, or `rate` for the part
    /// from the velocities) times `w` to the local matrix `k` (`nl` columns).
    pub fn add_matrix(
        &self,
        h: &[[f64; SLOTS]; SLOTS],
        w: f64,
        rate: bool,
        k: &mut [f64],
        nl: usize,
    ) {
        let columns = if rate { &self.rate } else { &self.trial };
        for (si, row) in h.iter().enumerate() {
            for (sj, &hij) in row.iter().enumerate() {
                if hij == 0.0 {
                    continue;
                }
                for (li, ci) in self.test[si].iter() {
                    for (lj, cj) in columns[sj].iter() {
                        k[li * nl + lj] += w * hij * ci * cj;
                    }
                }
            }
        }
    }
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
    /// The end has rotation slots (a node or a point between nodes): a joint's derivatives
    /// on `theta` of an end without them are never assembled, and never formed.
    pub turns: bool,
}

impl End {
    pub fn dofs(&self) -> &[usize] {
        match self {
            End::Ground { .. } => &[],
            End::Point { dofs, .. } => dofs,
            End::Node { dofs, .. } => dofs,
            End::Between(b) => &b.dofs,
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
                turns: false,
            },
            End::Point { dofs, axes } => EndKin {
                x: V3::from(dofs.map(|i| st.q[i])),
                p: V3::zeros(),
                e: m3(axes),
                v: V3::from(dofs.map(|i| st.v[i])),
                w: V3::zeros(),
                a: V3::from(dofs.map(|i| st.a[i])),
                dw: V3::zeros(),
                turns: false,
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
                    turns: true,
                }
            }
            End::Between(b) => b.kin(st),
        }
    }

    /// The inertial origin (no unknowns).
    pub fn ground() -> End {
        End::Ground {
            point: [0.0; 3],
            axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    /// A marker between the nodes of a beam element.
    pub fn is_between(&self) -> bool {
        matches!(self, End::Between(_))
    }

    /// Local positions of this end's slots, starting at local index `at`.
    pub(super) fn slot_map(
        &self,
        at: usize,
        base: usize,
        map: &mut [Option<usize>; SLOTS],
    ) -> usize {
        // An end between nodes has its six slots over more unknowns (`Spreads`).
        let n = self.dofs().len();
        for (k, m) in map[base..base + n.min(6)].iter_mut().enumerate() {
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
    /// `phi` reduced by whole turns, to round-off of the reduced angle ([`State::phase`]).
    pub phase: f64,
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
        let (mut phi, mut phase) = (0.0, 0.0);
        if let Some(i) = angle {
            phi = st.q[i];
            phase = st.phase(i);
            vel[PHI] = st.v[i];
        }
        Geo {
            a: ka,
            b: kb,
            phi,
            phase,
            vel,
        }
    }

    /// `d = x_B - x_A` between the marker points.
    pub(super) fn d(&self) -> V3 {
        self.b.x - self.a.x
    }
}
