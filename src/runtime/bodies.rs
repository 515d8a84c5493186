//! Point masses and rigid bodies (THEORY §4).
//!
//! A rigid body is one node: the translation `x` of its reference point and its rotation `R`
//! from the initial orientation. Its centre of mass is at `eta = R eta0` from the node and its
//! inertia about the node is `J = R J0 R^T`, with `eta0` and `J0` in inertial components at
//! t = 0. Inertial forces (inertial components):
//! `F_u = m a + (dw~ + w~ w~) m eta`, `F_theta = m eta~ a + J dw + w~ J w`.

use super::rotation::{tilde, tilde_tilde, M3, V3};
use super::{m3, Energy, MassMoments, Residual, State, TangentCoeffs};
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointMass {
    pub dofs: [usize; 3],
    pub mass: f64,
    pub gravity: [f64; 3],
}

impl PointMass {
    pub fn residual(&self, st: &State, r: &mut Residual) {
        for k in 0..3 {
            r.inertia[self.dofs[k]] += self.mass * st.a[self.dofs[k]];
            r.force[self.dofs[k]] -= self.mass * self.gravity[k];
        }
    }

    pub fn tangent(&self, c: TangentCoeffs, k: &mut [f64]) {
        k[..9].iter_mut().for_each(|x| *x = 0.0);
        for i in 0..3 {
            k[i * 3 + i] = c.mass * self.mass;
        }
    }

    /// Adds the momentum `m v` (THEORY §8.1); a point mass has no transport term.
    pub fn momentum(&self, st: &State, p: &mut [f64]) {
        for &d in &self.dofs {
            p[d] += self.mass * st.v[d];
        }
    }

    pub fn mass_moments(&self, st: &State) -> MassMoments {
        let at = |v: &[f64]| V3::from(self.dofs.map(|i| v[i])) * self.mass;
        MassMoments {
            mass: self.mass,
            position: at(&st.q),
            velocity: at(&st.v),
            acceleration: at(&st.a),
        }
    }

    pub fn energy(&self, st: &State) -> Energy {
        let v = V3::from(self.dofs.map(|i| st.v[i]));
        let x = V3::from(self.dofs.map(|i| st.q[i]));
        Energy {
            kinetic: 0.5 * self.mass * v.norm_squared(),
            potential: -self.mass * V3::from(self.gravity).dot(&x),
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigidBody {
    /// Translation unknowns of the reference point, then rotation unknowns.
    pub dofs: [usize; 6],
    /// The rotating node.
    pub node: usize,
    pub mass: f64,
    /// Centre of mass from the reference point, inertial components at t = 0.
    pub eta0: [f64; 3],
    /// Inertia tensor about the reference point, inertial components at t = 0.
    pub inertia0: [[f64; 3]; 3],
    pub gravity: [f64; 3],
}

/// The body's configuration-dependent quantities at a state.
struct Kin {
    a: V3,
    w: V3,
    dw: V3,
    /// `m eta` (inertial).
    meta: V3,
    j: M3,
}

impl RigidBody {
    fn kin(&self, st: &State) -> Kin {
        let n = &st.rot[self.node];
        let r = n.matrix();
        Kin {
            a: V3::new(st.a[self.dofs[0]], st.a[self.dofs[1]], st.a[self.dofs[2]]),
            w: n.omega(),
            dw: n.omega_dot(),
            meta: r * V3::from(self.eta0) * self.mass,
            j: r * m3(&self.inertia0) * r.transpose(),
        }
    }

    pub fn residual(&self, st: &State, r: &mut Residual) {
        self.residual_at(&self.kin(st), r);
    }

    /// [`RigidBody::residual`] and [`RigidBody::tangent`] from one evaluation of the
    /// kinematics.
    pub fn residual_and_tangent(
        &self,
        st: &State,
        c: TangentCoeffs,
        r: &mut Residual,
        k: &mut [f64],
    ) {
        let kin = self.kin(st);
        self.residual_at(&kin, r);
        self.tangent_at(&kin, c, k);
    }

    fn residual_at(&self, k: &Kin, r: &mut Residual) {
        let (wt, dwt) = (tilde(&k.w), tilde(&k.dw));
        let g = V3::from(self.gravity);
        let fu = self.mass * k.a + dwt * k.meta + wt * (wt * k.meta);
        let ft = k.meta.cross(&k.a) + k.j * k.dw + k.w.cross(&(k.j * k.w));
        let gt = k.meta.cross(&g);
        for i in 0..3 {
            r.inertia[self.dofs[i]] += fu[i];
            r.inertia[self.dofs[3 + i]] += ft[i];
            r.force[self.dofs[i]] -= self.mass * g[i];
            r.force[self.dofs[3 + i]] -= gt[i];
        }
    }

    /// `mass M + velocity G + position K^I + force_weight position K^grav` (THEORY §3.6, §4).
    pub fn tangent(&self, st: &State, c: TangentCoeffs, k: &mut [f64]) {
        self.tangent_at(&self.kin(st), c, k);
    }

    fn tangent_at(&self, kin: &Kin, c: TangentCoeffs, k: &mut [f64]) {
        let (wt, dwt) = (tilde(&kin.w), tilde(&kin.dw));
        let jw = kin.j * kin.w;
        let jdw = kin.j * kin.dw;
        let g = V3::from(self.gravity);
        let wj = wt * kin.j;
        // Mass.
        let m_uu = M3::identity() * self.mass;
        let m_tt = kin.j;
        // Gyroscopic: d F^I / d(v, w).
        let g_tt = wj - tilde(&jw);
        // Configuration: d F^I / d theta at fixed (a, dw) and (v, w).
        let mut k_tt = kin.j * dwt - tilde(&jdw) + wj * wt - tilde_tilde(&kin.w, &jw);
        // The terms of the first moment of mass about the node, none for a node at the
        // centre of mass (the two-bar's bars): the coupling of translation and rotation and
        // the gravity moment. `e~ = tilde(meta)`; `tilde(a) tilde(b)` as `tilde_tilde`.
        let (mut m_ut, mut g_ut, mut k_ut, mut k_grav) =
            (M3::zeros(), M3::zeros(), M3::zeros(), M3::zeros());
        if kin.meta != V3::zeros() {
            let et = tilde(&kin.meta);
            m_ut = -et;
            g_ut = tilde(&(wt * kin.meta)).transpose() - wt * et;
            k_ut = -(dwt * et + tilde_tilde(&kin.w, &kin.w) * et);
            k_tt += tilde_tilde(&kin.a, &kin.meta);
            k_grav = -tilde_tilde(&g, &kin.meta);
        }
        let m_tu = -m_ut;
        let blocks = [
            (0, 0, m_uu * c.mass),
            (0, 3, m_ut * c.mass + g_ut * c.velocity + k_ut * c.position),
            (3, 0, m_tu * c.mass),
            (
                3,
                3,
                m_tt * c.mass
                    + g_tt * c.velocity
                    + k_tt * c.position
                    + k_grav * (c.position * c.force_weight),
            ),
        ];
        k[..36].iter_mut().for_each(|x| *x = 0.0);
        for (r0, c0, b) in blocks {
            add_block(k, 6, r0, c0, &b);
        }
    }

    /// [`RigidBody::tangent`]'s mass part `M` (unit mass coefficient) into `m` and its
    /// gyroscopic part `G` (unit velocity coefficient) into `c`, from one evaluation of the
    /// kinematics.
    pub fn rate_jacobians(&self, st: &State, m: &mut [f64], c: &mut [f64]) {
        let kin = self.kin(st);
        let wt = tilde(&kin.w);
        let et = tilde(&kin.meta);
        let g_ut = tilde(&(wt * kin.meta)).transpose() + wt * et.transpose();
        let g_tt = wt * kin.j - tilde(&(kin.j * kin.w));
        m[..36].iter_mut().for_each(|x| *x = 0.0);
        c[..36].iter_mut().for_each(|x| *x = 0.0);
        let m_uu = M3::identity() * self.mass;
        for (r0, c0, b) in [
            (0, 0, &m_uu),
            (0, 3, &et.transpose()),
            (3, 0, &et),
            (3, 3, &kin.j),
        ] {
            add_block(m, 6, r0, c0, b);
        }
        add_block(c, 6, 0, 3, &g_ut);
        add_block(c, 6, 3, 3, &g_tt);
    }

    /// Adds the momenta `(m v + w x m eta, J w + m eta x v)` and the transport term
    /// `(0, v x (w x m eta))` (THEORY §8.1): their rate plus the transport term is `F^I`.
    pub fn momentum(&self, st: &State, p: &mut [f64], g: &mut [f64]) {
        let n = &st.rot[self.node];
        let r = n.matrix();
        let w = n.omega();
        let v = V3::new(st.v[self.dofs[0]], st.v[self.dofs[1]], st.v[self.dofs[2]]);
        let meta = r * V3::from(self.eta0) * self.mass;
        let j = r * m3(&self.inertia0) * r.transpose();
        let wm = w.cross(&meta);
        let pu = self.mass * v + wm;
        let pt = j * w + meta.cross(&v);
        let gt = v.cross(&wm);
        for i in 0..3 {
            p[self.dofs[i]] += pu[i];
            p[self.dofs[3 + i]] += pt[i];
            g[self.dofs[3 + i]] += gt[i];
        }
    }

    /// The mass centre `x + R eta0` moves with `v + w x R eta0` and accelerates with
    /// `a + (dw~ + w~ w~) R eta0`: `m` times these (the last is `F_u` of the residual).
    pub fn mass_moments(&self, st: &State) -> MassMoments {
        let k = self.kin(st);
        let at = |v: &[f64]| V3::new(v[self.dofs[0]], v[self.dofs[1]], v[self.dofs[2]]);
        MassMoments {
            mass: self.mass,
            position: at(&st.q) * self.mass + k.meta,
            velocity: at(&st.v) * self.mass + k.w.cross(&k.meta),
            acceleration: k.a * self.mass + k.dw.cross(&k.meta) + k.w.cross(&k.w.cross(&k.meta)),
        }
    }

    pub fn energy(&self, st: &State) -> Energy {
        let n = &st.rot[self.node];
        let r = n.matrix();
        let w = n.omega();
        let v = V3::new(st.v[self.dofs[0]], st.v[self.dofs[1]], st.v[self.dofs[2]]);
        let x = V3::new(st.q[self.dofs[0]], st.q[self.dofs[1]], st.q[self.dofs[2]]);
        let meta = r * V3::from(self.eta0) * self.mass;
        let j = r * m3(&self.inertia0) * r.transpose();
        // T = 1/2 m v.v + v.(w x m eta) + 1/2 w.J w (about the reference point).
        Energy {
            kinetic: 0.5 * self.mass * v.norm_squared()
                + v.dot(&w.cross(&meta))
                + 0.5 * w.dot(&(j * w)),
            potential: -V3::from(self.gravity).dot(&(self.mass * x + meta)),
        }
    }
}

/// Adds a 3x3 block at `(r0, c0)` of a row-major `nl`-column matrix.
#[inline]
pub(crate) fn add_block(k: &mut [f64], nl: usize, r0: usize, c0: usize, b: &M3) {
    for i in 0..3 {
        for j in 0..3 {
            k[(r0 + i) * nl + c0 + j] += b[(i, j)];
        }
    }
}
