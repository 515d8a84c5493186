//! Joints: constraint rows between two markers, with exact Jacobians and their derivatives
//! (THEORY §5, §6).
//!
//! Every user-facing joint lowers to one [`Joint`]: two ends and a list of primitive [`Row`]s.
//! A row is a scalar function `G` of the two ends (and of the revolute angle `phi`), its
//! gradient over 13 slots `(u_A, theta_A, u_B, theta_B, phi)` and the derivative of
//! `mu * grad G` (the "geometric stiffness"). Slots an end does not have (a ground, a point
//! mass's rotation) are computed but not assembled. Rows with a prescribed motion subtract a
//! time function; rate rows are velocity-level constraints `grad G . V - f(t)`.

use super::rotation::{tilde, tilde_tilde, M3, V3};
use super::timefn::TimeFn;
use super::{Augment, Rate, Residual, State};
use serde::{Deserialize, Serialize};

/// Slots of the 13-component generalized vectors of a joint.
const UA: usize = 0;
const TA: usize = 3;
const UB: usize = 6;
const TB: usize = 9;
const PHI: usize = 12;
pub(crate) const SLOTS: usize = 13;

pub(crate) type Grad = [f64; SLOTS];
pub(crate) type Hess = [[f64; SLOTS]; SLOTS];

mod ends;
mod outputs;
mod redundant;
mod tangent;

pub use ends::{Between, End, EndKin};
pub(crate) use ends::{Geo, Spreads};
pub use redundant::{min_norm_forces, min_norm_reaction, select_dropped};

/// A primitive constraint row. Axis indices are 0-based (`a_0` is the marker's first axis).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "row", rename_all = "snake_case")]
pub enum Row {
    /// Inertial component `k` of `x_B - x_A`.
    Point { k: usize },
    /// `a_i . b_j`: axis `i` of end A against axis `j` of end B.
    Dot { i: usize, j: usize },
    /// `a_i . (x_B - x_A) - offset`.
    Along { i: usize, offset: f64 },
    /// `wrap(phi_m - phi)`: the revolute's measured angle about `a_2` against its unknown.
    Angle,
    /// `|x_B - x_A| - length`.
    Distance { length: f64 },
    /// The revolute angle unknown `phi` itself (for forces on it).
    Phi,
    /// `phi - f(t)`.
    AngleDrive { f: TimeFn },
    /// `phi-dot - f(t)` (velocity level).
    AngleRate { f: TimeFn },
    /// `a_2 . (x_B - x_A) - offset - f(t)`.
    SlideDrive { offset: f64, f: TimeFn },
    /// `d/dt (a_2 . (x_B - x_A)) - f(t)` (velocity level).
    SlideRate { f: TimeFn },
}

impl Row {
    /// A velocity-level row.
    pub fn is_rate(&self) -> bool {
        matches!(self, Row::AngleRate { .. } | Row::SlideRate { .. })
    }

    /// The prescribed function of time, if any.
    fn drive(&self) -> Option<&TimeFn> {
        match self {
            Row::AngleDrive { f }
            | Row::AngleRate { f }
            | Row::SlideDrive { f, .. }
            | Row::SlideRate { f } => Some(f),
            _ => None,
        }
    }

    /// The geometric part `G` and its gradient.
    pub(crate) fn geom(&self, g: &Geo) -> (f64, Grad) {
        let mut gr = [0.0; SLOTS];
        let value = match self {
            Row::Point { k } => {
                let (pa, pb) = (tilde(&g.a.p), tilde(&g.b.p));
                gr[UA + k] = -1.0;
                gr[UB + k] = 1.0;
                for j in 0..3 {
                    gr[TA + j] = pa[(*k, j)];
                    gr[TB + j] = -pb[(*k, j)];
                }
                g.d()[*k]
            }
            Row::Dot { i, j } => {
                let (a, b) = (g.a.e.column(*i).into_owned(), g.b.e.column(*j).into_owned());
                let c = a.cross(&b);
                put(&mut gr, TA, &c);
                put(&mut gr, TB, &-c);
                a.dot(&b)
            }
            Row::Along { i, offset } => along(g, *i, *offset, &mut gr),
            Row::SlideDrive { offset, .. } => along(g, 2, *offset, &mut gr),
            Row::SlideRate { .. } => along(g, 2, 0.0, &mut gr),
            Row::Angle => {
                let an = AngleGeo::new(g);
                put(&mut gr, TA, &an.g);
                put(&mut gr, TB, &-an.g);
                gr[PHI] = -1.0;
                wrap(an.phi_m - g.phase)
            }
            Row::Phi | Row::AngleDrive { .. } | Row::AngleRate { .. } => {
                gr[PHI] = 1.0;
                g.phi
            }
            Row::Distance { length } => {
                let d = g.d();
                let len = d.norm();
                let n = if len > 0.0 { d / len } else { V3::zeros() };
                distance_grad(g, &n, &mut gr);
                len - length
            }
        };
        (value, gr)
    }

    /// Adds `d(mu grad G)/dq` (13 x 13, row = force slot, column = perturbed slot) to `h`.
    pub(crate) fn hess(&self, g: &Geo, mu: f64, h: &mut Hess) {
        if mu == 0.0 {
            return;
        }
        // Blocks on the rotation slots of an end without them (a ground, a point mass) are
        // never assembled: they are not formed.
        let (ra, rb) = (g.a.turns, g.b.turns);
        match self {
            Row::Point { k } => {
                let mut m = V3::zeros();
                m[*k] = mu;
                if ra {
                    block(h, TA, TA, &-tilde_tilde(&m, &g.a.p));
                }
                if rb {
                    block(h, TB, TB, &tilde_tilde(&m, &g.b.p));
                }
            }
            Row::Dot { i, j } => {
                let (a, b) = (g.a.e.column(*i).into_owned(), g.b.e.column(*j).into_owned());
                if ra {
                    let ba = tilde_tilde(&b, &a) * mu;
                    block(h, TA, TA, &ba);
                    if rb {
                        block(h, TB, TA, &-ba);
                    }
                }
                if rb {
                    let ab = tilde_tilde(&a, &b) * mu;
                    block(h, TB, TB, &ab);
                    if ra {
                        block(h, TA, TB, &-ab);
                    }
                }
            }
            Row::Along { i, .. } => along_hess(g, *i, mu, h),
            Row::SlideDrive { .. } | Row::SlideRate { .. } => along_hess(g, 2, mu, h),
            Row::Angle => {
                let an = AngleGeo::new(g);
                let (da, db) = an.derivatives();
                if ra {
                    block(h, TA, TA, &(da * mu));
                    block(h, TA, TB, &(db * mu));
                }
                if rb {
                    block(h, TB, TA, &(-da * mu));
                    block(h, TB, TB, &(-db * mu));
                }
            }
            Row::Phi | Row::AngleDrive { .. } | Row::AngleRate { .. } => {}
            Row::Distance { .. } => {
                let d = g.d();
                let len = d.norm();
                if len <= 0.0 {
                    return;
                }
                let n = d / len;
                let proj = (M3::identity() - n * n.transpose()) * (mu / len);
                // D: d(d)/dq = [-I, p_A~, I, -p_B~] over (u_A, theta_A, u_B, theta_B).
                let (pa, pb) = (tilde(&g.a.p), tilde(&g.b.p));
                // Forces: u_A: -mu n, theta_A: -mu p_A~ n, u_B: mu n, theta_B: mu p_B~ n; each
                // block is the force's row operator times `proj D_c`. An end without an arm (a
                // ground, a point mass) has no rotation's blocks: their operator is zero.
                // (Their products are not even formed: on the pendulum they were 8 % of a step.)
                let (arm_a, arm_b) = (g.a.p != V3::zeros(), g.b.p != V3::zeros());
                let arm = |live: bool, x: &dyn Fn() -> M3| if live { x() } else { M3::zeros() };
                let cols = [
                    (UA, -proj, true),
                    (TA, arm(arm_a, &|| proj * pa), arm_a),
                    (UB, proj, true),
                    (TB, arm(arm_b, &|| -(proj * pb)), arm_b),
                ];
                for (c0, x, live) in cols {
                    if !live {
                        continue;
                    }
                    block(h, UA, c0, &-x);
                    if arm_a {
                        block(h, TA, c0, &(-pa * x));
                    }
                    block(h, UB, c0, &x);
                    if arm_b {
                        block(h, TB, c0, &(pb * x));
                    }
                }
                let nt = tilde(&n);
                if arm_a {
                    block(h, TA, TA, &(-nt * pa * mu));
                }
                if arm_b {
                    block(h, TB, TB, &(nt * pb * mu));
                }
            }
        }
    }
}

/// `a_i . (x_B - x_A) - offset` and its gradient.
fn along(g: &Geo, i: usize, offset: f64, gr: &mut Grad) -> f64 {
    let a = g.a.e.column(i).into_owned();
    let d = g.d();
    let w = d + g.a.p;
    put(gr, UA, &-a);
    put(gr, TA, &a.cross(&w));
    put(gr, UB, &a);
    put(gr, TB, &g.b.p.cross(&a));
    a.dot(&d) - offset
}

fn along_hess(g: &Geo, i: usize, mu: f64, h: &mut Hess) {
    let a = g.a.e.column(i).into_owned();
    let at = tilde(&a) * mu;
    let w = g.d() + g.a.p;
    let pb = &g.b.p;
    // As in `Row::hess`: no blocks on an end's missing rotation slots.
    let (ra, rb) = (g.a.turns, g.b.turns);
    if ra {
        block(h, UA, TA, &at);
        block(h, UB, TA, &-at);
        block(h, TA, UA, &-at);
        block(h, TA, UB, &at);
        block(h, TA, TA, &(tilde_tilde(&w, &a) * mu));
        if rb {
            block(h, TA, TB, &(tilde_tilde(&a, pb) * -mu));
            block(h, TB, TA, &(tilde_tilde(pb, &a) * -mu));
        }
    }
    if rb {
        block(h, TB, TB, &(tilde_tilde(&a, pb) * mu));
    }
}

fn distance_grad(g: &Geo, n: &V3, gr: &mut Grad) {
    put(gr, UA, &-n);
    put(gr, TA, &(tilde(&g.a.p).transpose() * n));
    put(gr, UB, n);
    put(gr, TB, &(-tilde(&g.b.p).transpose() * n));
}

/// The revolute's measured angle about `a_2` (0-based), from `s = a_1.b_0 - a_0.b_1` and
/// `c = a_0.b_0 + a_1.b_1` (THEORY §5), with its gradient `g` (on `theta_A`; `-g` on
/// `theta_B`).
struct AngleGeo {
    a: [V3; 2],
    b: [V3; 2],
    s: f64,
    c: f64,
    sigma: V3,
    kappa: V3,
    g: V3,
    phi_m: f64,
}

impl AngleGeo {
    fn new(geo: &Geo) -> AngleGeo {
        let a = [
            geo.a.e.column(0).into_owned(),
            geo.a.e.column(1).into_owned(),
        ];
        let b = [
            geo.b.e.column(0).into_owned(),
            geo.b.e.column(1).into_owned(),
        ];
        let s = a[1].dot(&b[0]) - a[0].dot(&b[1]);
        let c = a[0].dot(&b[0]) + a[1].dot(&b[1]);
        let sigma = a[1].cross(&b[0]) - a[0].cross(&b[1]);
        let kappa = a[0].cross(&b[0]) + a[1].cross(&b[1]);
        let dd = s * s + c * c;
        let g = if dd > 0.0 {
            (sigma * c - kappa * s) / dd
        } else {
            V3::zeros()
        };
        AngleGeo {
            a,
            b,
            s,
            c,
            sigma,
            kappa,
            g,
            phi_m: s.atan2(c),
        }
    }

    /// `dg/dtheta_A` and `dg/dtheta_B`.
    fn derivatives(&self) -> (M3, M3) {
        let dd = self.s * self.s + self.c * self.c;
        if dd <= 0.0 {
            return (M3::zeros(), M3::zeros());
        }
        let (a0, a1) = (tilde(&self.a[0]), tilde(&self.a[1]));
        let (b0, b1) = (tilde(&self.b[0]), tilde(&self.b[1]));
        let (sig, kap, g) = (self.sigma, self.kappa, self.g);
        let (s, c) = (self.s, self.c);
        let common = sig * kap.transpose() - kap * sig.transpose();
        let q = g * (sig * s + kap * c).transpose() * 2.0;
        let da = (common + (b0 * a1 - b1 * a0) * c - (b0 * a0 + b1 * a1) * s - q) / dd;
        let db = (-common - (a1 * b0 - a0 * b1) * c + (a0 * b0 + a1 * b1) * s + q) / dd;
        (da, db)
    }
}

/// Wraps an angle into `[-pi, pi]` ([`crate::runtime::precise::reduce_angle`]).
fn wrap(x: f64) -> f64 {
    super::precise::reduce_angle(x)
}

#[inline]
fn put(gr: &mut Grad, at: usize, v: &V3) {
    gr[at..at + 3].copy_from_slice(v.as_slice());
}

#[inline(always)]
fn block(h: &mut Hess, r0: usize, c0: usize, m: &M3) {
    for i in 0..3 {
        for j in 0..3 {
            h[r0 + i][c0 + j] += m[(i, j)];
        }
    }
}

/// A joint: rows between two ends, with multipliers `first..first + rows.len()` and the
/// revolute angle unknown `angle`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Joint {
    pub a: End,
    pub b: End,
    pub angle: Option<usize>,
    pub first: usize,
    pub rows: Vec<Row>,
    /// For prismatic joints: the initial `a_2 . d`, so the displacement starts at zero.
    pub slide_offset: Option<f64>,
    /// For a joint whose equations are redundant (W0303): its entry in `State::dropped`, the
    /// rows dropped now (the other joints' rows imply them). A dropped row keeps its
    /// multiplier, held at zero (`lambda = 0`, diagonal `s`), applies no force, and is
    /// watched: [`Joint::violation`] still measures it.
    #[serde(default)]
    pub slot: Option<usize>,
}

impl Joint {
    /// Whether row `k` is dropped as redundant at `st`.
    #[inline(always)]
    pub fn is_dropped(&self, k: usize, st: &State) -> bool {
        self.slot
            .is_some_and(|s| st.dropped.get(s).is_some_and(|m| m & (1 << k) != 0))
    }

    pub fn indices(&self) -> Vec<usize> {
        let mut v = Vec::with_capacity(13 + self.rows.len());
        v.extend_from_slice(self.a.dofs());
        v.extend_from_slice(self.b.dofs());
        v.extend(self.angle);
        v.extend(self.first..self.first + self.rows.len());
        v
    }

    pub fn residual(&self, st: &State, aug: Augment, r: &mut Residual) {
        if self.a.is_between() || self.b.is_between() {
            return self.residual_between(st, aug, r);
        }
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        let glob = globals(&self.a, &self.b, self.angle);
        for (k, row) in self.rows.iter().enumerate() {
            let (mu, gr) = self.row_residual(k, row, &geo, st, aug, r);
            add_force(&glob, mu, &gr, r);
        }
    }

    /// The rate rows' equations alone into `r.constraint`: the only part of the residual
    /// that reads the rates (their forces `s lambda` do not).
    pub fn rate_rows(&self, st: &State, aug: Augment, r: &mut Residual) {
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        for (k, row) in self.rows.iter().enumerate() {
            if row.is_rate() {
                self.row_residual(k, row, &geo, st, aug, r);
            }
        }
    }

    /// Row `k`'s equation into `r.constraint`, and its force `mu` with its gradient.
    #[inline(always)]
    fn row_residual(
        &self,
        k: usize,
        row: &Row,
        geo: &Geo,
        st: &State,
        aug: Augment,
        r: &mut Residual,
    ) -> (f64, Grad) {
        let m = self.first + k;
        if self.is_dropped(k, st) {
            r.constraint[m] = st.lambda[m];
            return (0.0, [0.0; SLOTS]);
        }
        let (gv, gr) = row.geom(geo);
        let f = row.drive().map_or(0.0, |f| f.eval(st.t));
        (
            Self::row_equation(m, row, (gv, &gr, f), geo, st, aug, r),
            gr,
        )
    }

    /// Row equation `m` (its value `gv`, gradient `gr` and drive `f`) into `r.constraint`;
    /// its force `mu`.
    #[inline(always)]
    fn row_equation(
        m: usize,
        row: &Row,
        (gv, gr, f): (f64, &Grad, f64),
        geo: &Geo,
        st: &State,
        aug: Augment,
        r: &mut Residual,
    ) -> f64 {
        if row.is_rate() {
            r.constraint[m] = aug.rate_scale * (dot13(gr, &geo.vel) - f);
            aug.s * st.lambda[m]
        } else {
            let c = gv - f;
            r.constraint[m] = c;
            aug.s * st.lambda[m] + aug.p * c
        }
    }

    /// The residual with an end between beam nodes: the rows' forces summed on the slots, then
    /// spread through `Spreads`.
    #[inline(never)]
    fn residual_between(&self, st: &State, aug: Augment, r: &mut Residual) {
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        let mut force = [0.0; SLOTS];
        for (k, row) in self.rows.iter().enumerate() {
            let (mu, gr) = self.row_residual(k, row, &geo, st, aug, r);
            force.iter_mut().zip(&gr).for_each(|(f, g)| *f += mu * g);
        }
        let sp = Spreads::new(&self.a, &self.b, self.angle, st);
        sp.add_forces(&force, (&self.a, &self.b, self.angle), &mut r.force);
    }

    pub fn constraint_rate(&self, st: &State, rate: Rate, out: &mut [f64]) {
        let geo = Geo::new(&self.a, &self.b, self.angle, st);
        for (k, row) in self.rows.iter().enumerate() {
            if self.is_dropped(k, st) {
                out[self.first + k] = 0.0;
                continue;
            }
            let (_, gr) = row.geom(&geo);
            let jet = row.drive().map(|f| f.jet(st.t));
            let (f0, f1, f2) = jet.map_or((0.0, 0.0, 0.0), |j| (j.v, j.d, j.dd));
            out[self.first + k] = match rate {
                Rate::Velocity => dot13(&gr, &geo.vel) - if row.is_rate() { f0 } else { f1 },
                Rate::AccelerationBias => {
                    let mut h = [[0.0; SLOTS]; SLOTS];
                    row.hess(&geo, 1.0, &mut h);
                    let mut vhv = 0.0;
                    for (i, hi) in h.iter().enumerate() {
                        vhv += geo.vel[i] * dot13(hi, &geo.vel);
                    }
                    vhv - if row.is_rate() { f1 } else { f2 }
                }
            };
        }
    }
}

/// Local position of each slot for ends `a`, `b` and angle unknown, in the local order
/// `(a dofs, b dofs, angle)`, and the number of local coordinates.
pub(crate) fn slots(a: &End, b: &End, angle: Option<usize>) -> ([Option<usize>; SLOTS], usize) {
    let mut map = [None; SLOTS];
    let na = a.slot_map(0, UA, &mut map);
    let nb = b.slot_map(na, UB, &mut map);
    let mut at = na + nb;
    if angle.is_some() {
        map[PHI] = Some(at);
        at += 1;
    }
    (map, at)
}

/// A row's force `mu grad` onto the global unknowns of its slots.
#[inline(always)]
pub(crate) fn add_force(glob: &[Option<usize>; SLOTS], mu: f64, gr: &Grad, r: &mut Residual) {
    for (s, gi) in glob.iter().enumerate() {
        if let Some(i) = gi {
            r.force[*i] += mu * gr[s];
        }
    }
}

/// The global unknown of each slot (no allocation: called every iteration).
pub(crate) fn globals(a: &End, b: &End, angle: Option<usize>) -> [Option<usize>; SLOTS] {
    // Ends between nodes are assembled through `Spreads`, never here.
    debug_assert!(!a.is_between() && !b.is_between());
    let mut g = [None; SLOTS];
    for (k, d) in a.dofs().iter().enumerate() {
        g[UA + k] = Some(*d);
    }
    for (k, d) in b.dofs().iter().enumerate() {
        g[UB + k] = Some(*d);
    }
    g[PHI] = angle;
    g
}

#[inline]
pub(crate) fn dot13(a: &Grad, b: &Grad) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
