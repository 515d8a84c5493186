//! Geometrically exact beam elements referred to the inertial frame (THEORY §3).
//!
//! An element has 2, 3 or 4 nodes, each a rotating node with 6 unknowns: the position `x_k`
//! (inertial) and a spatial rotation. The section triad of node `k` is `T_k = R_k E_k`, with
//! `R_k` its rotation from the initial orientation and `E_k` its triad at t = 0. Triads are
//! interpolated objectively, relative to the middle node `r`: `p_k = WM(T_r^T T_k)`,
//! `T(xi) = T_r R(sum N_k p_k)`, curvature `k = T_r H(p) p'` (THEORY §3.4). Strains in section
//! components are `gamma* = T^T x' - i1 - gamma*_0` and `kappa* = T^T k - kappa*_0`, with the
//! strains of the reference configuration subtracted at every quadrature point, so initial
//! curvature and twist (curved beams, pretwist) are stress-free.
//!
//! Residual (THEORY §3.5), Petrov-Galerkin test fields `N_k`: elastic terms at `p` reduced
//! Gauss points, inertial and gravity terms at `p + 1` points. The tangent is the exact
//! derivative of that residual: the variation of the interpolated triad is
//! `dtheta(xi) = sum A_l dtheta_l` with `A_l = N_l T_r H(p) H(p_l)^-1 T_r^T` (and `A_r` the
//! complement to the identity), and `dkappa* = T^T dtheta'` with `A_l'` from `H'`, so Newton
//! converges quadratically and the finite-difference oracle agrees to round-off.

use super::bodies::add_block;
use super::rotation::{rotation, tangent, tangent_rate, tilde, M3, V3};
use super::{m3, Energy, MassMoments, Residual, State, TangentCoeffs};
use serde::{Deserialize, Serialize};

mod frame;
mod loads;
mod quadrature;
pub(crate) use frame::triad_between;
use frame::{relative, Relative};
pub use loads::Distributed;
use quadrature::gauss;
pub use quadrature::{inertial_points, shape, Gauss, SectionAt};

/// Most nodes of an element.
pub(crate) const MAXN: usize = 4;

/// A beam element.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BeamElement {
    /// 6 unknowns per node: translation, then rotation.
    pub dofs: Vec<usize>,
    /// The rotating node of each element node.
    pub nodes: Vec<usize>,
    /// Section triad of each node at t = 0 (columns: axes 1, 2, 3).
    pub triads: Vec<[[f64; 3]; 3]>,
    pub gravity: [f64; 3],
    /// Distributed loads per length, their values at the inertial points.
    pub loads: Vec<Distributed>,
    /// Reduced points (elastic terms) and full points (inertial terms); concentrated masses
    /// between the nodes follow the full points as points of weight 1.
    pub elastic: Vec<Gauss>,
    pub inertial: Vec<Gauss>,
}

/// The interpolated triad, curvature and their variation operators at one point.
struct Field {
    /// Section triad `T(xi)`.
    t: M3,
    /// `x'` (inertial).
    dx: V3,
    /// Total curvature `k` (inertial).
    k: V3,
    /// `dtheta(xi) = sum a[l] dtheta_l`, `dtheta'(xi) = sum da[l] dtheta_l`.
    a: [M3; MAXN],
    da: [M3; MAXN],
}

impl BeamElement {
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Builds an element from its nodes' reference positions and triads, with the reference
    /// strains evaluated at every quadrature point.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        dofs: Vec<usize>,
        nodes: Vec<usize>,
        positions: &[[f64; 3]],
        triads: Vec<[[f64; 3]; 3]>,
        section: &dyn Fn(f64) -> SectionAt,
        gravity: [f64; 3],
    ) -> BeamElement {
        let nn = nodes.len();
        let points = |count: usize| -> Vec<Gauss> {
            let (xs, ws) = gauss(count);
            xs.iter()
                .zip(ws)
                .map(|(&xi, &w)| {
                    let (n, dn) = shape(nn, xi);
                    let mut d = V3::zeros();
                    for k in 0..nn {
                        d += V3::from(positions[k]) * dn[k];
                    }
                    let j = d.norm();
                    Gauss {
                        wj: w * j,
                        n,
                        dn: dn.map(|x| x / j),
                        strain0: [0.0; 6],
                        section: section(xi),
                    }
                })
                .collect()
        };
        let mut e = BeamElement {
            dofs,
            nodes,
            triads,
            gravity,
            loads: Vec::new(),
            elastic: points(nn - 1),
            inertial: points(nn),
        };
        // Reference strains: the same measure in the reference configuration.
        let x: Vec<V3> = positions.iter().map(|p| V3::from(*p)).collect();
        let t: Vec<M3> = e.triads.iter().map(m3).collect();
        let rel = relative(&t[..e.len()]);
        for gi in 0..e.elastic.len() {
            let f = e.field(&rel, &x, &e.elastic[gi], false);
            let (g, k) = (f.t.transpose() * f.dx - V3::x(), f.t.transpose() * f.k);
            e.elastic[gi].strain0 = [g[0], g[1], g[2], k[0], k[1], k[2]];
        }
        e
    }

    fn triads_at(&self, st: &State) -> [M3; MAXN] {
        let mut t = [M3::identity(); MAXN];
        for (k, tk) in t.iter_mut().enumerate().take(self.len()) {
            *tk = st.rot[self.nodes[k]].matrix() * m3(&self.triads[k]);
        }
        t
    }

    fn positions(&self, v: &[f64]) -> [V3; MAXN] {
        let mut x = [V3::zeros(); MAXN];
        for (k, xk) in x.iter_mut().enumerate().take(self.len()) {
            let d = &self.dofs[6 * k..6 * k + 3];
            *xk = V3::new(v[d[0]], v[d[1]], v[d[2]]);
        }
        x
    }

    fn rates(&self, st: &State) -> ([V3; MAXN], [V3; MAXN]) {
        let mut w = [V3::zeros(); MAXN];
        let mut dw = [V3::zeros(); MAXN];
        for k in 0..self.len() {
            w[k] = st.rot[self.nodes[k]].omega();
            dw[k] = st.rot[self.nodes[k]].omega_dot();
        }
        (w, dw)
    }

    /// The interpolated field at a point; `ops` also computes the variation operators.
    fn field(&self, rel: &Relative, x: &[V3], gp: &Gauss, ops: bool) -> Field {
        let nn = self.len();
        let mut p = V3::zeros();
        let mut dp = V3::zeros();
        let mut dx = V3::zeros();
        for k in 0..nn {
            p += rel.p[k] * gp.n[k];
            dp += rel.p[k] * gp.dn[k];
            dx += x[k] * gp.dn[k];
        }
        let h = tangent(&p);
        let t = rel.tr * rotation(&p);
        let k = rel.tr * (h * dp);
        let mut a = [M3::zeros(); MAXN];
        let mut da = [M3::zeros(); MAXN];
        if ops {
            let hd = tangent_rate(&p, &dp);
            let (th, thd) = (rel.tr * h, rel.tr * hd);
            let mut sa = M3::zeros();
            let mut sda = M3::zeros();
            for l in 0..nn {
                if l == rel.r {
                    continue;
                }
                a[l] = th * rel.g[l] * gp.n[l];
                da[l] = (thd * gp.n[l] + th * gp.dn[l]) * rel.g[l];
                sa += a[l];
                sda += da[l];
            }
            a[rel.r] = M3::identity() - sa;
            da[rel.r] = -sda;
        }
        Field { t, dx, k, a, da }
    }

    /// Acceleration, angular velocity and angular acceleration interpolated at a point.
    fn point_rates(&self, st: &State, gp: &Gauss, wn: &[V3], dwn: &[V3]) -> (V3, V3, V3) {
        let (mut a, mut w, mut dw) = (V3::zeros(), V3::zeros(), V3::zeros());
        for k in 0..self.len() {
            let d = &self.dofs[6 * k..6 * k + 3];
            a += V3::new(st.a[d[0]], st.a[d[1]], st.a[d[2]]) * gp.n[k];
            w += wn[k] * gp.n[k];
            dw += dwn[k] * gp.n[k];
        }
        (a, w, dw)
    }

    /// Section resultants (inertial) and the strains at an elastic point.
    fn resultants(&self, f: &Field, gp: &Gauss) -> (V3, V3, [f64; 6]) {
        let g = f.t.transpose() * f.dx - V3::x();
        let k = f.t.transpose() * f.k;
        let e = [
            g[0] - gp.strain0[0],
            g[1] - gp.strain0[1],
            g[2] - gp.strain0[2],
            k[0] - gp.strain0[3],
            k[1] - gp.strain0[4],
            k[2] - gp.strain0[5],
        ];
        let mut n = [0.0; 6];
        for (i, ni) in n.iter_mut().enumerate() {
            *ni = (0..6).map(|j| gp.section.stiffness[i][j] * e[j]).sum();
        }
        (
            f.t * V3::new(n[0], n[1], n[2]),
            f.t * V3::new(n[3], n[4], n[5]),
            e,
        )
    }

    /// Sectional mass quantities at a point: `m eta` and `rho` (inertial).
    fn inertia(t: &M3, gp: &Gauss) -> (V3, M3) {
        let s = &gp.section;
        (t * V3::from(s.eta) * s.mass, t * m3(&s.rho) * t.transpose())
    }

    pub fn residual(&self, st: &State, r: &mut Residual) {
        let nn = self.len();
        let x = self.positions(&st.q);
        let t = self.triads_at(st);
        let rel = relative(&t[..nn]);
        for gp in &self.elastic {
            let f = self.field(&rel, &x, gp, false);
            let (fo, mo, _) = self.resultants(&f, gp);
            let fxd = fo.cross(&f.dx);
            for k in 0..nn {
                let d = &self.dofs[6 * k..6 * k + 6];
                for i in 0..3 {
                    r.force[d[i]] += gp.wj * gp.dn[k] * fo[i];
                    r.force[d[3 + i]] += gp.wj * (gp.dn[k] * mo[i] + gp.n[k] * fxd[i]);
                }
            }
        }
        let (wn, dwn) = self.rates(st);
        let g = V3::from(self.gravity);
        for (gi, gp) in self.inertial.iter().enumerate() {
            let f = self.field(&rel, &x, gp, false);
            let (meta, rho) = Self::inertia(&f.t, gp);
            let (a, w, dw) = self.point_rates(st, gp, &wn, &dwn);
            let (wt, dwt) = (tilde(&w), tilde(&dw));
            let mass = gp.section.mass;
            let fu = mass * a + (dwt + wt * wt) * meta;
            let ft = meta.cross(&a) + rho * dw + w.cross(&(rho * w));
            let (load, torque) = loads::at(&self.loads, gi, st.t, &f.t);
            let ext_u = mass * g + load;
            let ext_t = meta.cross(&g) + torque;
            for k in 0..nn {
                let d = &self.dofs[6 * k..6 * k + 6];
                let c = gp.wj * gp.n[k];
                for i in 0..3 {
                    r.inertia[d[i]] += c * fu[i];
                    r.inertia[d[3 + i]] += c * ft[i];
                    r.force[d[i]] -= c * ext_u[i];
                    r.force[d[3 + i]] -= c * ext_t[i];
                }
            }
        }
    }

    /// `mass M + velocity G + position K^I + force_weight position (K + K^grav)`, row-major
    /// over `dofs`.
    pub fn tangent(&self, st: &State, c: TangentCoeffs, kk: &mut [f64]) {
        let nn = self.len();
        let nl = 6 * nn;
        kk[..nl * nl].iter_mut().for_each(|v| *v = 0.0);
        let x = self.positions(&st.q);
        let t = self.triads_at(st);
        let rel = relative(&t[..nn]);
        let cw = c.position * c.force_weight;
        for gp in &self.elastic {
            let f = self.field(&rel, &x, gp, true);
            let (fo, mo, _) = self.resultants(&f, gp);
            // Inertial 6x6 stiffness, split in blocks.
            let cs = m6_blocks(&gp.section.stiffness);
            let c11 = f.t * cs[0] * f.t.transpose();
            let c12 = f.t * cs[1] * f.t.transpose();
            let c21 = f.t * cs[2] * f.t.transpose();
            let c22 = f.t * cs[3] * f.t.transpose();
            let xt = tilde(&f.dx);
            let (ft, mt) = (tilde(&fo), tilde(&mo));
            // d(F, M) / d(x', theta, theta').
            let f_t = c11 * xt - ft;
            let m_t = c21 * xt - mt;
            for l in 0..nn {
                // Columns of node l: dF/dx_l, dF/dtheta_l, dM/dx_l, dM/dtheta_l.
                let dfx = c11 * gp.dn[l];
                let dft = f_t * f.a[l] + c12 * f.da[l];
                let dmx = c21 * gp.dn[l];
                let dmt = m_t * f.a[l] + c22 * f.da[l];
                for k in 0..nn {
                    let w = gp.wj * cw;
                    let (nk, dnk) = (gp.n[k], gp.dn[k]);
                    let uu = dfx * (dnk * w);
                    let ut = dft * (dnk * w);
                    // theta rows: N_k' dM + N_k (-x'~ dF + F~ dx').
                    let tu = (dmx * dnk + (-xt * dfx + ft * gp.dn[l]) * nk) * w;
                    let tt = (dmt * dnk - xt * dft * nk) * w;
                    let (r0, c0) = (6 * k, 6 * l);
                    add_block(kk, nl, r0, c0, &uu);
                    add_block(kk, nl, r0, c0 + 3, &ut);
                    add_block(kk, nl, r0 + 3, c0, &tu);
                    add_block(kk, nl, r0 + 3, c0 + 3, &tt);
                }
            }
        }
        let (wn, dwn) = self.rates(st);
        let g = V3::from(self.gravity);
        for (gi, gp) in self.inertial.iter().enumerate() {
            let f = self.field(&rel, &x, gp, true);
            let (meta, rho) = Self::inertia(&f.t, gp);
            let (a, w, dw) = self.point_rates(st, gp, &wn, &dwn);
            let (wt, dwt, at) = (tilde(&w), tilde(&dw), tilde(&a));
            // Follower loads: d(T f*) = -(T f*)~ dtheta(xi), so the rows gain (T f*)~ A_l.
            let (fu, ft) = loads::followers(&self.loads, gi, st.t, &f.t);
            let (fu, ft) = (tilde(&fu), tilde(&ft));
            let et = tilde(&meta);
            let (rw, rdw) = (rho * w, rho * dw);
            let m_uu = M3::identity() * gp.section.mass;
            let g_ut = tilde(&(wt * meta)).transpose() + wt * et.transpose();
            let g_tt = wt * rho - tilde(&rw);
            let k_ut = (dwt + wt * wt) * et.transpose();
            let k_tt = at * et + rho * dwt - tilde(&rdw) + wt * rho * wt - wt * tilde(&rw);
            let k_grav = -tilde(&g) * et;
            for l in 0..nn {
                let nl_ = gp.n[l];
                for k in 0..nn {
                    let s = gp.wj * gp.n[k];
                    let (r0, c0) = (6 * k, 6 * l);
                    add_block(kk, nl, r0, c0, &(m_uu * (c.mass * nl_ * s)));
                    let ut = (et.transpose() * c.mass + g_ut * c.velocity) * (nl_ * s)
                        + k_ut * f.a[l] * (c.position * s);
                    add_block(kk, nl, r0, c0 + 3, &ut);
                    add_block(kk, nl, r0 + 3, c0, &(et * (c.mass * nl_ * s)));
                    add_block(kk, nl, r0, c0 + 3, &(fu * f.a[l] * (cw * s)));
                    let tt = (rho * c.mass + g_tt * c.velocity) * (nl_ * s)
                        + k_tt * f.a[l] * (c.position * s)
                        + (k_grav + ft) * f.a[l] * (cw * s);
                    add_block(kk, nl, r0 + 3, c0 + 3, &tt);
                }
            }
        }
    }

    /// Adds the nodal momenta `int N (h, g) ds`, with `h = m (v + w x eta)` and
    /// `g = rho w + m eta x v`, and the transport term `int N (0, v x h) ds` (THEORY §8.1),
    /// at the inertial points.
    pub fn momentum(&self, st: &State, p: &mut [f64], tr: &mut [f64]) {
        let nn = self.len();
        let x = self.positions(&st.q);
        let vn = self.positions(&st.v);
        let t = self.triads_at(st);
        let rel = relative(&t[..nn]);
        let (wn, _) = self.rates(st);
        for gp in &self.inertial {
            let f = self.field(&rel, &x, gp, false);
            let (meta, rho) = Self::inertia(&f.t, gp);
            let (mut v, mut w) = (V3::zeros(), V3::zeros());
            for k in 0..nn {
                v += vn[k] * gp.n[k];
                w += wn[k] * gp.n[k];
            }
            let h = gp.section.mass * v + w.cross(&meta);
            let g = rho * w + meta.cross(&v);
            let gt = v.cross(&h);
            for k in 0..nn {
                let d = &self.dofs[6 * k..6 * k + 6];
                let c = gp.wj * gp.n[k];
                for i in 0..3 {
                    p[d[i]] += c * h[i];
                    p[d[3 + i]] += c * g[i];
                    tr[d[3 + i]] += c * gt[i];
                }
            }
        }
    }

    /// Kinetic energy, and potential energy: elastic plus gravity.
    pub fn energy(&self, st: &State) -> Energy {
        let nn = self.len();
        let x = self.positions(&st.q);
        let t = self.triads_at(st);
        let rel = relative(&t[..nn]);
        let mut e = Energy::default();
        for gp in &self.elastic {
            let f = self.field(&rel, &x, gp, false);
            let (_, _, s) = self.resultants(&f, gp);
            let mut u = 0.0;
            for i in 0..6 {
                for j in 0..6 {
                    u += s[i] * gp.section.stiffness[i][j] * s[j];
                }
            }
            e.potential += 0.5 * gp.wj * u;
        }
        let (wn, _) = self.rates(st);
        let g = V3::from(self.gravity);
        for gp in &self.inertial {
            let f = self.field(&rel, &x, gp, false);
            let (meta, rho) = Self::inertia(&f.t, gp);
            let (mut v, mut w, mut xp) = (V3::zeros(), V3::zeros(), V3::zeros());
            for k in 0..nn {
                let d = &self.dofs[6 * k..6 * k + 3];
                v += V3::new(st.v[d[0]], st.v[d[1]], st.v[d[2]]) * gp.n[k];
                w += wn[k] * gp.n[k];
                xp += x[k] * gp.n[k];
            }
            let mass = gp.section.mass;
            e.kinetic += gp.wj
                * (0.5 * mass * v.norm_squared()
                    + v.dot(&w.cross(&meta))
                    + 0.5 * w.dot(&(rho * w)));
            e.potential -= gp.wj * g.dot(&(mass * xp + meta));
        }
        e
    }

    /// Mass and first moments of mass, integrated like the inertial forces: at the inertial
    /// quadrature points, `m x + T m eta` and its rates `m v + w x (T m eta)`,
    /// `m a + (dw~ + w~ w~) T m eta`.
    pub fn mass_moments(&self, st: &State) -> MassMoments {
        let nn = self.len();
        let x = self.positions(&st.q);
        let t = self.triads_at(st);
        let rel = relative(&t[..nn]);
        let (wn, dwn) = self.rates(st);
        let mut out = MassMoments::default();
        for gp in &self.inertial {
            let f = self.field(&rel, &x, gp, false);
            let (meta, _) = Self::inertia(&f.t, gp);
            let (a, w, dw) = self.point_rates(st, gp, &wn, &dwn);
            let (mut xp, mut v) = (V3::zeros(), V3::zeros());
            for k in 0..nn {
                let d = &self.dofs[6 * k..6 * k + 3];
                xp += x[k] * gp.n[k];
                v += V3::new(st.v[d[0]], st.v[d[1]], st.v[d[2]]) * gp.n[k];
            }
            let mass = gp.section.mass;
            out += MassMoments {
                mass: gp.wj * mass,
                position: (xp * mass + meta) * gp.wj,
                velocity: (v * mass + w.cross(&meta)) * gp.wj,
                acceleration: (a * mass + dw.cross(&meta) + w.cross(&w.cross(&meta))) * gp.wj,
            };
        }
        out
    }

    /// Mass of the element.
    pub fn total_mass(&self) -> f64 {
        match self.uniform() {
            Some(u) => u.mass * self.inertial.iter().map(|g| g.wj).sum::<f64>(),
            None => self
                .inertial
                .iter()
                .map(|g| g.section.mass * g.wj)
                .sum::<f64>(),
        }
    }

    /// A typical diagonal stiffness: the mean sectional stiffness over the element length.
    pub fn stiffness_scale(&self) -> f64 {
        // The element's length: its quadrature points (not concentrated masses' points).
        let l: f64 = self.inertial.iter().take(self.len()).map(|g| g.wj).sum();
        let diagonal = |s: &SectionAt| (0..3).map(|i| s.stiffness[i][i]).sum::<f64>() / 3.0;
        let d: f64 = match self.uniform() {
            Some(u) => diagonal(u),
            None => {
                self.elastic
                    .iter()
                    .map(|g| g.wj * diagonal(&g.section))
                    .sum::<f64>()
                    / self.elastic.iter().map(|g| g.wj).sum::<f64>()
            }
        };
        d / l * (self.len() - 1) as f64
    }

    /// The section of every quadrature point, if they share one.
    fn uniform(&self) -> Option<&SectionAt> {
        let first = &self.inertial.first()?.section;
        self.inertial
            .iter()
            .chain(&self.elastic)
            .all(|g| g.section == *first)
            .then_some(first)
    }
}

/// The four 3x3 blocks of a 6x6 matrix: 11, 12, 21, 22.
fn m6_blocks(c: &[[f64; 6]; 6]) -> [M3; 4] {
    let b = |r0: usize, c0: usize| M3::from_fn(|i, j| c[r0 + i][c0 + j]);
    [b(0, 0), b(0, 3), b(3, 0), b(3, 3)]
}
