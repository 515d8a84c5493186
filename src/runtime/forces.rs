//! Springs, dampers and applied loads.
//!
//! A [`Spring`] acts on one joint row's geometric function `G` (a distance, a component of
//! `x_B - x_A`, a revolute angle, a slide displacement) with the generalized force
//! `f = k (G - rest) + c dG/dt - load(t)` along `grad G`: linear springs, the springs,
//! dampers, torques and forces of revolute and prismatic joints. A torsional spring acts on
//! the relative rotation vector of two markers' axes. A [`Load`] is a force or torque at a
//! marker, fixed in space or following the marker's axes.

use super::joints::{dot13, globals, slots, End, EndKin, Geo, Grad, Hess, Row, Spreads, SLOTS};
use super::rotation::{left_jacobian_inverse, log, tilde, M3, V3};
use super::timefn::TimeFn;
use super::{Energy, Residual, State, TangentCoeffs};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpringKind {
    /// On a joint row's function (see the module doc).
    Row,
    /// On the relative rotation vector `psi = log(E_B E_A^T)` of the markers' axes: moment
    /// `k psi + c (w_B - w_A)` resisting on B, its opposite on A.
    Torsional,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spring {
    pub kind: SpringKind,
    pub a: End,
    pub b: End,
    pub angle: Option<usize>,
    /// The row whose function the spring acts on (ignored by torsional springs).
    pub row: Row,
    pub stiffness: f64,
    pub damping: f64,
    pub rest: f64,
    /// An applied generalized force along the row (a joint's torque or force).
    pub load: Option<TimeFn>,
}

impl Spring {
    pub fn indices(&self) -> Vec<usize> {
        let mut v = Vec::with_capacity(13);
        v.extend_from_slice(self.a.dofs());
        v.extend_from_slice(self.b.dofs());
        v.extend(self.angle);
        v
    }

    /// The generalized force `f` of a row spring and the row's gradient.
    fn row_force(&self, st: &State, geo: &Geo) -> (f64, [f64; SLOTS]) {
        let (g, gr) = self.row.geom(geo);
        let load = self.load.as_ref().map_or(0.0, |f| f.eval(st.t));
        let f = self.stiffness * (g - self.rest) + self.damping * dot13(&gr, &geo.vel) - load;
        (f, gr)
    }

    pub fn residual(&self, st: &State, r: &mut Residual) {
        if self.a.is_between() || self.b.is_between() {
            return self.residual_between(st, r);
        }
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        let glob = globals(&self.a, &self.b, self.angle);
        match self.kind {
            SpringKind::Row => {
                let (f, gr) = self.row_force(st, &geo);
                for (s, gi) in glob.iter().enumerate() {
                    if let Some(i) = gi {
                        r.force[*i] += f * gr[s];
                    }
                }
            }
            SpringKind::Torsional => {
                let m = self.torsion(&geo).1;
                for k in 0..3 {
                    if let Some(i) = glob[3 + k] {
                        r.force[i] -= m[k];
                    }
                    if let Some(i) = glob[9 + k] {
                        r.force[i] += m[k];
                    }
                }
            }
        }
    }

    /// The residual with an end between beam nodes: the slot forces through `Spreads`.
    fn residual_between(&self, st: &State, r: &mut Residual) {
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        // The generalized force on the slots.
        let mut force = [0.0; SLOTS];
        match self.kind {
            SpringKind::Row => {
                let (f, gr) = self.row_force(st, &geo);
                force.iter_mut().zip(&gr).for_each(|(x, g)| *x = f * g);
            }
            SpringKind::Torsional => {
                let m = self.torsion(&geo).1;
                for k in 0..3 {
                    force[3 + k] = -m[k];
                    force[9 + k] = m[k];
                }
            }
        }
        let sp = Spreads::new(&self.a, &self.b, self.angle, st);
        sp.add_forces(&force, (&self.a, &self.b, self.angle), &mut r.force);
    }

    /// A row spring's gradient, the derivative of its force through the positions,
    /// `d f / d q_j = k g_j c_q + c c_q (V^T H1)_j` (the damper's `c c_v g_j` apart), and its
    /// geometric stiffness `f H` added to `h`.
    fn row_parts(&self, st: &State, geo: &Geo, c: TangentCoeffs, h: &mut Hess) -> (Grad, Grad) {
        let (f, gr) = self.row_force(st, geo);
        self.row.hess(geo, f, h);
        let mut h1 = [[0.0; SLOTS]; SLOTS];
        if self.damping != 0.0 {
            self.row.hess(geo, 1.0, &mut h1);
        }
        let mut df = [0.0; SLOTS];
        for (j, d) in df.iter_mut().enumerate() {
            let vh: f64 = (0..SLOTS).map(|i| geo.vel[i] * h1[i][j]).sum();
            *d = self.stiffness * gr[j] * c.position + self.damping * c.position * vh;
        }
        (gr, df)
    }

    /// A torsional spring's moment derivatives: `k dpsi/dtheta_A`, `k dpsi/dtheta_B` (times
    /// `c_q`) and the damper's `c c_v I`.
    fn torsion_parts(&self, geo: &Geo, c: TangentCoeffs) -> (M3, M3, M3) {
        let (psi, _, rrel) = self.torsion(geo);
        let jinv = left_jacobian_inverse(&psi);
        // d psi / d theta_B = J^-1, d psi / d theta_A = -J^-1 R_rel.
        let dpsi_b = jinv * self.stiffness * c.position;
        let dpsi_a = -jinv * rrel * self.stiffness * c.position;
        (dpsi_a, dpsi_b, M3::identity() * (self.damping * c.velocity))
    }

    /// Relative rotation `psi`, the moment `k psi + c (w_B - w_A)` and `R_rel = E_B E_A^T`.
    fn torsion(&self, geo: &Geo) -> (V3, V3, M3) {
        let rrel = geo.b.e * geo.a.e.transpose();
        let psi = log(&rrel);
        let m = psi * self.stiffness + (geo.b.w - geo.a.w) * self.damping;
        (psi, m, rrel)
    }

    pub fn tangent(&self, st: &State, c: TangentCoeffs, k: &mut [f64]) {
        if self.a.is_between() || self.b.is_between() {
            return self.tangent_between(st, c, k);
        }
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        let (map, nl) = slots(&self.a, &self.b, self.angle);
        k[..nl * nl].iter_mut().for_each(|x| *x = 0.0);
        let w = c.force_weight;
        let mut h = [[0.0; SLOTS]; SLOTS];
        match self.kind {
            SpringKind::Row => {
                let (gr, mut df) = self.row_parts(st, &geo, c, &mut h);
                for (d, g) in df.iter_mut().zip(&gr) {
                    *d += self.damping * c.velocity * g;
                }
                for (si, li) in map.iter().enumerate() {
                    let Some(li) = li else { continue };
                    for (sj, lj) in map.iter().enumerate() {
                        if let Some(lj) = lj {
                            k[li * nl + lj] += w * (gr[si] * df[sj] + c.position * h[si][sj]);
                        }
                    }
                }
            }
            SpringKind::Torsional => {
                let (dpsi_a, dpsi_b, dw) = self.torsion_parts(&geo, c);
                let by_a = dpsi_a - dw;
                let by_b = dpsi_b + dw;
                // Moment m on theta_B (+) and theta_A (-).
                for (rs, sign) in [(9usize, 1.0), (3usize, -1.0)] {
                    for (cs, blk) in [(3usize, &by_a), (9usize, &by_b)] {
                        for i in 0..3 {
                            let (Some(li), Some(lj)) = (map[rs + i], map[cs]) else {
                                continue;
                            };
                            for j in 0..3 {
                                k[li * nl + lj + j] += w * sign * blk[(i, j)];
                            }
                        }
                    }
                }
            }
        }
    }

    /// The tangent with an end between beam nodes: the slot matrices through `Spreads`, the
    /// part from the velocities through their interpolation.
    fn tangent_between(&self, st: &State, c: TangentCoeffs, k: &mut [f64]) {
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        let (_, nl) = slots(&self.a, &self.b, self.angle);
        k[..nl * nl].iter_mut().for_each(|x| *x = 0.0);
        // The derivative of the slot forces over the slots, through the positions (`hs`) and
        // the velocities (`hv`).
        let mut hs = [[0.0; SLOTS]; SLOTS];
        let mut hv = [[0.0; SLOTS]; SLOTS];
        match self.kind {
            SpringKind::Row => {
                let mut h = [[0.0; SLOTS]; SLOTS];
                let (gr, df) = self.row_parts(st, &geo, c, &mut h);
                for si in 0..SLOTS {
                    for sj in 0..SLOTS {
                        hs[si][sj] = gr[si] * df[sj] + c.position * h[si][sj];
                        hv[si][sj] = gr[si] * self.damping * c.velocity * gr[sj];
                    }
                }
            }
            SpringKind::Torsional => {
                let (dpsi_a, dpsi_b, dw) = self.torsion_parts(&geo, c);
                // Moment m on theta_B (+) and theta_A (-).
                for (rs, sign) in [(9usize, 1.0), (3usize, -1.0)] {
                    for (cs, blk, rate) in [(3usize, &dpsi_a, -dw), (9usize, &dpsi_b, dw)] {
                        for i in 0..3 {
                            for j in 0..3 {
                                hs[rs + i][cs + j] = sign * blk[(i, j)];
                                hv[rs + i][cs + j] = sign * rate[(i, j)];
                            }
                        }
                    }
                }
            }
        }
        let sp = Spreads::new(&self.a, &self.b, self.angle, st);
        sp.add_matrix(&hs, c.force_weight, false, k, nl);
        sp.add_matrix(&hv, c.force_weight, true, k, nl);
    }

    pub fn energy(&self, st: &State) -> Energy {
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        let potential = match self.kind {
            SpringKind::Row => {
                let (g, _) = self.row.geom(&geo);
                0.5 * self.stiffness * (g - self.rest).powi(2)
            }
            SpringKind::Torsional => 0.5 * self.stiffness * self.torsion(&geo).0.norm_squared(),
        };
        Energy {
            kinetic: 0.0,
            potential,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoadKind {
    Force,
    Torque,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Load {
    pub kind: LoadKind,
    pub end: End,
    pub value: [TimeFn; 3],
    /// Components in the marker's axes, turning with them.
    pub follower: bool,
}

impl Load {
    fn value(&self, st: &State, e: &M3) -> V3 {
        let v = V3::new(
            self.value[0].eval(st.t),
            self.value[1].eval(st.t),
            self.value[2].eval(st.t),
        );
        if self.follower {
            e * v
        } else {
            v
        }
    }

    pub fn residual(&self, st: &State, r: &mut Residual) {
        if self.end.dofs().is_empty() {
            return;
        }
        let kin = self.end.kin(st);
        let v = self.value(st, &kin.e);
        self.residual_at(st, (&kin, v), r);
    }

    /// [`Load::residual`] and [`Load::tangent`] from one evaluation of the end's kinematics
    /// and the load's value.
    pub fn residual_and_tangent(
        &self,
        st: &State,
        c: TangentCoeffs,
        r: &mut Residual,
        k: &mut [f64],
    ) {
        let n = self.end.dofs().len();
        if n == 0 {
            return;
        }
        let kin = self.end.kin(st);
        let v = self.value(st, &kin.e);
        self.residual_at(st, (&kin, v), r);
        k[..n * n].iter_mut().for_each(|x| *x = 0.0);
        if n >= 6 {
            self.tangent_at(st, (&kin, v), c, k);
        }
    }

    fn residual_at(&self, st: &State, (kin, v): (&EndKin, V3), r: &mut Residual) {
        let d = self.end.dofs();
        // Minus the force and the moment about the end's node (its reference point).
        let (f, m) = match self.kind {
            LoadKind::Force => (-v, -kin.p.cross(&v)),
            LoadKind::Torque => (V3::zeros(), -v),
        };
        if self.end.is_between() {
            let mut force = [0.0; SLOTS];
            force[..3].copy_from_slice(f.as_slice());
            force[3..6].copy_from_slice(m.as_slice());
            let ground = End::ground();
            let sp = Spreads::new(&self.end, &ground, None, st);
            sp.add_forces(&force, (&self.end, &ground, None), &mut r.force);
            return;
        }
        for k in 0..3 {
            r.force[d[k]] += f[k];
            if d.len() == 6 {
                r.force[d[3 + k]] += m[k];
            }
        }
    }

    pub fn tangent(&self, st: &State, c: TangentCoeffs, k: &mut [f64]) {
        let n = self.end.dofs().len();
        k[..n * n].iter_mut().for_each(|x| *x = 0.0);
        if n < 6 {
            return;
        }
        let kin = self.end.kin(st);
        let v = self.value(st, &kin.e);
        self.tangent_at(st, (&kin, v), c, k);
    }

    /// Adds the tangent's rotation columns into a zeroed `k`.
    fn tangent_at(&self, st: &State, (kin, v): (&EndKin, V3), c: TangentCoeffs, k: &mut [f64]) {
        let n = self.end.dofs().len();
        let (vt, pt) = (tilde(&v), tilde(&kin.p));
        let s = c.force_weight * c.position;
        let (ut, tt) = match (self.kind, self.follower) {
            (LoadKind::Force, false) => (M3::zeros(), -vt * pt),
            (LoadKind::Force, true) => (vt, pt * vt - vt * pt),
            (LoadKind::Torque, false) => (M3::zeros(), M3::zeros()),
            (LoadKind::Torque, true) => (M3::zeros(), vt),
        };
        if self.end.is_between() {
            let mut hs = [[0.0; SLOTS]; SLOTS];
            for i in 0..3 {
                for j in 0..3 {
                    hs[i][3 + j] = ut[(i, j)];
                    hs[3 + i][3 + j] = tt[(i, j)];
                }
            }
            let ground = End::ground();
            Spreads::new(&self.end, &ground, None, st).add_matrix(&hs, s, false, k, n);
            return;
        }
        for i in 0..3 {
            for j in 0..3 {
                k[i * 6 + 3 + j] += s * ut[(i, j)];
                k[(3 + i) * 6 + 3 + j] += s * tt[(i, j)];
            }
        }
    }
}
