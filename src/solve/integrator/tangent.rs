//! The step's own tangent (THEORY §9.2, the monodromy by the implicit function theorem): how
//! the state a converged step ends in moves with the state it started from, carried along a
//! run for a set of directions (the columns of `S_n = d s_n / d z_0`).
//!
//! The step's state `s` is what the next step reads: positions, and for every coordinate
//! its rate, acceleration and algorithmic acceleration (`v, a, A`); the SE(3) frames' body
//! twists in their place. A direction is a flat vector of `4 n` entries: `[position, v, a,
//! A]`, each indexed by unknown; a frame's translation and rotation slots hold its body-frame
//! increment `H <- H exp(d)` and its twists' components, a beam node's rotation slots its
//! body-frame rotation; multiplier slots stay zero (the converged step does not depend on the
//! multipliers it started from: they are unknowns of the step).
//!
//! A step solves `r(x; s_n) = 0` for its increment and multipliers `x`, and
//! `s_{n+1} = f(x; s_n)` (the Newmark relations and `H_{n+1} = H_n exp(x)`). With the
//! iteration matrix `J = dr/dx` factored at the converged `x`,
//! `dx = -J^-1 (dr/ds_n) S` and `S_{n+1} = (df/dx) dx + (df/ds_n) S`. `dr/ds_n S` and
//! `f`'s derivatives are directional derivatives by central differences of the step's own
//! functions at the converged increment (a residual per sign and direction): they are taken
//! along one direction each, never assembled, so they agree with the step to the last digit
//! the residual has, whatever the element; their truncation error at `EPSILON` of the state's
//! scale is below 1e-10 relative, below the Newton tolerance.

use super::newton::Reuse;
use super::{rotations, se3, Integrator, Layout, StepFailure};
use crate::runtime::rotation::{exp, left_jacobian, left_jacobian_inverse, log, M3, V3};
use crate::runtime::{State, System, UnknownKind};
use crate::settings::{Method, NewtonMode};

/// The size of a direction's differences of the joints' rate rows, relative to their scale
/// (lengths in the model's length scale over the tracked time scale): the rows are linear in
/// the velocities, so the differences are exact but for round-off, which a large step keeps
/// small.
const EPSILON: f64 = 1e-3;

/// The directions carried along a run, and the step's workspace (made once).
pub(super) struct Tracked {
    /// Column-major `4 n x columns`.
    pub(super) columns: Vec<f64>,
    pub(super) count: usize,
    /// Per unknown, the scale of its position (the length scale for coordinates that are not
    /// angles, 1 rad otherwise); rates are scaled by `tau`, accelerations by `tau^2`.
    pub(super) scale: Vec<f64>,
    pub(super) tau: f64,
    /// Column-major `count x original`: the directions given to [`Integrator::track`] are the
    /// columns times it (the identity until [`Integrator::deflate`] drops some).
    pub(super) map: Vec<f64>,
    /// Deflate every this many steps (0: never), and the steps carried so far.
    pub(super) deflate_every: usize,
    pub(super) steps: usize,
    /// Whether the first deflation settles ([`Integrator::deflate_every`]); then its
    /// orthonormal columns (`U`, weighted), and the current columns' combinations that are
    /// their images (column-major `count x settled`), and the last step's size.
    pub(super) settle: bool,
    pub(super) settled: Vec<f64>,
    pub(super) since: Vec<f64>,
    pub(super) h: f64,
    nodes: Vec<NodeMap>,
    dir: Vec<f64>,
    part: Vec<f64>,
    /// Each direction's velocities and accelerations as the state holds them (column-major
    /// `n x columns`).
    pub(super) physical: (Vec<f64>, Vec<f64>),
    /// Column-major `n x columns`: each direction's correction of the increment.
    pub(super) gradients: Vec<f64>,
    /// The unknowns of the joints whose rate rows are differenced along the rates (the rates
    /// they read, the rows they write), and the rotating nodes among them.
    differenced: (Vec<usize>, Vec<usize>),
}

/// The Newmark relations as a matrix ([`Integrator::coefficients`]).
pub(super) type Coefficients = [[f64; 4]; 3];

/// A node's part of one step's map ([`Integrator::transport`], [`Integrator::correct`]).
#[derive(Clone, Copy, Default)]
pub(super) struct NodeMap {
    /// `R_D^T` of the increment `D`, and its translation `p_D = J_l(theta) u`.
    rt: M3,
    p: V3,
    /// The increment's inverse right Jacobian `[[ja, jb], [0, ja]]`.
    ja: M3,
    jb: M3,
}

/// Whether unknown `i` is a coordinate integrated by Newmark in the flat slots (not a frame's
/// or a rotation's, not a multiplier).
fn flat(sys: &System, in_frame: &[bool], i: usize) -> bool {
    !in_frame[i] && !sys.unknowns[i].is_multiplier()
}

/// Node `k`'s slots of frame component `j` (translations of frames only).
fn slot(sys: &System, k: usize, j: usize) -> Option<usize> {
    if j < 3 {
        sys.is_frame(k).then(|| sys.translations[k] + j)
    } else {
        Some(sys.rotations[k] + j - 3)
    }
}

/// `out = base (+) eps dir`: coordinates shifted, frames moved by body-frame increments,
/// rates shifted; the nodes' inertial kinematics made to match.
pub(super) fn perturb(
    sys: &System,
    in_frame: &[bool],
    base: &State,
    dir: &[f64],
    eps: f64,
    out: &mut State,
) {
    let n = sys.len();
    out.assign(base);
    for i in (0..n).filter(|&i| flat(sys, in_frame, i)) {
        out.q[i] += eps * dir[i];
        out.v[i] += eps * dir[n + i];
        out.a[i] += eps * dir[2 * n + i];
        out.alg[i] += eps * dir[3 * n + i];
    }
    for k in 0..sys.rotations.len() {
        let d: [f64; 6] = std::array::from_fn(|j| slot(sys, k, j).map_or(0.0, |s| eps * dir[s]));
        se3::displace(sys, base, out, k, &d);
        let f = &mut out.frames[k];
        for j in 0..6 {
            if let Some(s) = slot(sys, k, j) {
                f.v[j] += eps * dir[n + s];
                f.dv[j] += eps * dir[2 * n + s];
                f.alg[j] += eps * dir[3 * n + s];
            }
        }
        se3::to_physical(sys, out, k);
    }
}

/// [`perturb`] along a direction of the rates alone (its positions zero), into an `out` that
/// already holds `base`'s positions: only the rates are written, the frames not displaced.
pub(super) fn perturb_rates(
    sys: &System,
    in_frame: &[bool],
    base: &State,
    dir: &[f64],
    eps: f64,
    (unknowns, nodes): (&[usize], &[usize]),
    out: &mut State,
) {
    let n = sys.len();
    for &i in unknowns.iter().filter(|&&i| flat(sys, in_frame, i)) {
        out.v[i] = base.v[i] + eps * dir[n + i];
        out.a[i] = base.a[i] + eps * dir[2 * n + i];
        out.alg[i] = base.alg[i] + eps * dir[3 * n + i];
    }
    for &k in nodes {
        let (b, f) = (&base.frames[k], &mut out.frames[k]);
        for j in 0..6 {
            (f.v[j], f.dv[j], f.alg[j]) = match slot(sys, k, j) {
                Some(s) => (
                    b.v[j] + eps * dir[n + s],
                    b.dv[j] + eps * dir[2 * n + s],
                    b.alg[j] + eps * dir[3 * n + s],
                ),
                None => (b.v[j], b.dv[j], b.alg[j]),
            };
        }
        se3::to_physical(sys, out, k);
    }
}

/// The rotating nodes with an unknown among `unknowns` (sorted).
fn nodes_of(sys: &System, unknowns: &[usize]) -> Vec<usize> {
    (0..sys.rotations.len())
        .filter(|&k| {
            (0..6).any(|j| slot(sys, k, j).is_some_and(|s| unknowns.binary_search(&s).is_ok()))
        })
        .collect()
}

/// The velocities and accelerations as `base` holds them (rotations: angular velocity and
/// acceleration; frames' translations: in inertial axes) moved by each of `count` directions
/// of the rates alone (`dirs` column-major, `4 n` a direction; `dv`, `da` column-major
/// `n x count`): [`perturb_rates`]'s change to first order, which is exact but for the
/// frames' `w x v` (`se3::to_physical`).
pub(super) fn physical_rates(
    sys: &System,
    in_frame: &[bool],
    base: &State,
    (dirs, count): (&[f64], usize),
    (dv, da): (&mut [f64], &mut [f64]),
) {
    let n = sys.len();
    dv.fill(0.0);
    da.fill(0.0);
    for i in (0..n).filter(|&i| flat(sys, in_frame, i)) {
        for c in 0..count {
            dv[c * n + i] = dirs[c * 4 * n + n + i];
            da[c * n + i] = dirs[c * 4 * n + 2 * n + i];
        }
    }
    for k in 0..sys.rotations.len() {
        let (t, r) = (sys.translations[k], sys.rotations[k]);
        let rm = base.rot[k].matrix();
        let f = &base.frames[k];
        let (v, w) = (
            V3::new(f.v[0], f.v[1], f.v[2]),
            V3::new(f.v[3], f.v[4], f.v[5]),
        );
        let frame = sys.is_frame(k);
        let slots: [Option<usize>; 6] = std::array::from_fn(|j| slot(sys, k, j));
        for c in 0..count {
            let dir = &dirs[c * 4 * n..(c + 1) * 4 * n];
            let part = |at: usize, from: usize| {
                V3::from_fn(|j, _| slots[from + j].map_or(0.0, |s| dir[at * n + s]))
            };
            let (dw, ddw) = (part(1, 3), part(2, 3));
            let (dv, da) = (&mut dv[c * n..(c + 1) * n], &mut da[c * n..(c + 1) * n]);
            if frame {
                let (du, ddu) = (part(1, 0), part(2, 0));
                let (xd, xdd) = (rm * du, rm * (ddu + dw.cross(&v) + w.cross(&du)));
                for j in 0..3 {
                    dv[t + j] = xd[j];
                    da[t + j] = xdd[j];
                }
            }
            let (om, omd) = (rm * dw, rm * ddw);
            for j in 0..3 {
                dv[r + j] = om[j];
                da[r + j] = omd[j];
            }
        }
    }
}

/// `out = a (-) b`, the direction that [`perturb`] takes from `b` to `a` (to first order).
pub(super) fn difference(sys: &System, in_frame: &[bool], a: &State, b: &State, out: &mut [f64]) {
    let n = sys.len();
    out.iter_mut().for_each(|x| *x = 0.0);
    for i in (0..n).filter(|&i| flat(sys, in_frame, i)) {
        out[i] = a.q[i] - b.q[i];
        out[n + i] = a.v[i] - b.v[i];
        out[2 * n + i] = a.a[i] - b.a[i];
        out[3 * n + i] = a.alg[i] - b.alg[i];
    }
    for k in 0..sys.rotations.len() {
        let rb = b.rot[k].matrix();
        let th = log(&(rb.transpose() * a.rot[k].matrix()));
        let (t, r) = (sys.translations[k], sys.rotations[k]);
        if sys.is_frame(k) {
            let dx = V3::new(
                a.q[t] - b.q[t],
                a.q[t + 1] - b.q[t + 1],
                a.q[t + 2] - b.q[t + 2],
            );
            let u = left_jacobian_inverse(&th) * (rb.transpose() * dx);
            out[t..t + 3].copy_from_slice(u.as_slice());
        }
        out[r..r + 3].copy_from_slice(th.as_slice());
        let (fa, fb) = (&a.frames[k], &b.frames[k]);
        for j in 0..6 {
            if let Some(s) = slot(sys, k, j) {
                out[n + s] = fa.v[j] - fb.v[j];
                out[2 * n + s] = fa.dv[j] - fb.dv[j];
                out[3 * n + s] = fa.alg[j] - fb.alg[j];
            }
        }
    }
}

/// The scaled size of a direction's rates: the largest of its rates times `tau` and its
/// accelerations times `tau^2`, over the position's scale.
fn rate_size(scale: &[f64], tau: f64, dir: &[f64], on: &[usize]) -> f64 {
    let n = scale.len();
    let mut size = 0.0f64;
    for &i in on {
        let s = scale[i];
        size = size
            .max(tau * dir[n + i].abs() / s)
            .max(tau * tau * dir[2 * n + i].abs() / s);
    }
    size
}

impl Integrator<'_> {
    /// Whether the step's tangent can be carried: the Newmark family with the incremental
    /// rotation treatment (time finite elements and conformal rotations cannot yet).
    pub fn can_track(&self) -> bool {
        self.layout == Layout::Increments
            && matches!(self.method, Method::Hht | Method::GeneralizedAlpha)
    }

    /// The length of a direction of the step's state.
    pub fn direction_len(&self) -> usize {
        4 * self.sys.len()
    }

    /// Carries the directions `columns` (column-major, [`Integrator::direction_len`] rows)
    /// through every step from now on; `tau` is the motion's time scale (rates are compared
    /// with positions over it).
    pub fn track(&mut self, columns: Vec<f64>, tau: f64) {
        let (n, nodes) = (self.sys.len(), self.sys.rotations.len());
        let count = columns.len() / (4 * n).max(1);
        let angles = self.sys.angle_unknowns();
        let scale = (0..n)
            .map(|i| match self.sys.unknowns[i] {
                UnknownKind::Coordinate if !angles.contains(&i) => self.sys.length_scale,
                _ => 1.0,
            })
            .collect();
        // Each step ends with the matrix factored exactly at its converged state, which the
        // next step's Newton keeps while it contracts (its first matrix costs nothing then),
        // whatever the settings' mode: the step converges to the same tolerance either way.
        self.reuse = Reuse::new(NewtonMode::Modified, self.method);
        let on = self.asm.rate_support(false).to_vec();
        let differenced = (nodes_of(self.sys, &on), on);
        let map = (0..count * count)
            .map(|k| if k % (count + 1) == 0 { 1.0 } else { 0.0 })
            .collect();
        self.tracked = Some(Box::new(Tracked {
            columns,
            count,
            scale,
            tau,
            map,
            deflate_every: 0,
            steps: 0,
            settle: false,
            settled: Vec::new(),
            since: Vec::new(),
            h: 0.0,
            nodes: vec![NodeMap::default(); nodes],
            dir: vec![0.0; 4 * n],
            part: vec![0.0; n],
            physical: (vec![0.0; n * count], vec![0.0; n * count]),
            gradients: vec![0.0; n * count],
            differenced: (differenced.1, differenced.0),
        }));
    }

    /// The carried directions at the current state.
    pub fn tracked(&self) -> Option<&[f64]> {
        self.tracked.as_ref().map(|t| t.columns.as_slice())
    }

    /// How the directions given to [`Integrator::track`] are made of the carried ones:
    /// column-major `carried x given` (the identity but after [`Integrator::deflate`]).
    pub fn tracked_map(&self) -> Option<&[f64]> {
        self.tracked.as_ref().map(|t| t.map.as_slice())
    }

    /// `out = base (+) eps dir` in this integrator's state layout (see [`perturb`]).
    pub fn perturb_state(&self, base: &State, dir: &[f64], eps: f64, out: &mut State) {
        perturb(self.sys, &self.in_frame, base, dir, eps, out);
    }

    /// `out = a (-) b` in this integrator's state layout (see [`difference`]).
    pub fn state_difference(&self, a: &State, b: &State, out: &mut [f64]) {
        difference(self.sys, &self.in_frame, a, b, out);
    }

    /// After a converged step of `h` (`cur` its end, the step's increments in `step_q`,
    /// `step_frames`): the carried directions moved to its end.
    pub(super) fn propagate(&mut self, h: f64) -> Result<(), StepFailure> {
        let Some(mut tk) = self.tracked.take() else {
            return Ok(());
        };
        let result = self.propagate_with(h, &mut tk);
        self.tracked = Some(tk);
        result
    }

    /// The Newmark relations of a step of `h` as a matrix: row `k` of (rate, acceleration,
    /// algorithmic acceleration) over (increment, rate, acceleration, algorithmic
    /// acceleration) of the start.
    pub(super) fn coefficients(&self, h: f64) -> Coefficients {
        let unit = |k: usize| {
            let e = |j: usize| if j == k { 1.0 } else { 0.0 };
            self.sc.relation(h, e(0), e(1), e(2), e(3))
        };
        let cols = [unit(0), unit(1), unit(2), unit(3)];
        std::array::from_fn(|r| {
            std::array::from_fn(|k| match r {
                0 => cols[k].0,
                1 => cols[k].1,
                _ => cols[k].2,
            })
        })
    }

    /// Each node's part of the step's map: `exp(-increment)`'s action on a body-frame
    /// perturbation of the start, and the increment's inverse right Jacobian.
    pub(super) fn node_maps(&self, nodes: &mut [NodeMap]) {
        for (k, m) in nodes.iter_mut().enumerate() {
            let d = &self.step_frames[k];
            let (u, th) = (V3::new(d[0], d[1], d[2]), V3::new(d[3], d[4], d[5]));
            m.rt = exp(&th).transpose();
            if self.sys.is_frame(k) {
                m.p = left_jacobian(&th) * u;
                (m.ja, m.jb) = se3::right_jacobian_inverse(d);
            } else {
                m.p = V3::zeros();
                (m.ja, m.jb) = (left_jacobian_inverse(&-th), M3::zeros());
            }
        }
    }

    /// `out = T dir`: where a perturbation `dir` of the step's start moves its end at a fixed
    /// increment. Coordinates keep their shift; a frame's body-frame perturbation `d` of the
    /// start becomes `Ad(exp(-D)) d` at the end (`H exp(d) exp(D) = H exp(D) exp(Ad d)`):
    /// `R_D^T (du - p_D x dtheta)`, `R_D^T dtheta`; the rates move by the Newmark relations
    /// at a zero increment.
    pub(super) fn transport(
        &self,
        coef: &Coefficients,
        nodes: &[NodeMap],
        dir: &[f64],
        out: &mut [f64],
    ) {
        let n = self.sys.len();
        let g = |x: &[f64], i: usize| V3::new(x[i], x[i + 1], x[i + 2]);
        out.iter_mut().for_each(|x| *x = 0.0);
        for &i in &self.coords.0 {
            let (v, a, alg) = (dir[n + i], dir[2 * n + i], dir[3 * n + i]);
            for (k, c) in coef.iter().enumerate() {
                out[(k + 1) * n + i] = c[1] * v + c[2] * a + c[3] * alg;
            }
            if !self.in_frame[i] {
                out[i] = dir[i];
            }
        }
        for (k, m) in nodes.iter().enumerate() {
            let (t, r) = (self.sys.translations[k], self.sys.rotations[k]);
            let th = g(dir, r);
            if self.sys.is_frame(k) {
                let u = m.rt * (g(dir, t) - m.p.cross(&th));
                out[t..t + 3].copy_from_slice(u.as_slice());
            }
            out[r..r + 3].copy_from_slice((m.rt * th).as_slice());
        }
    }

    /// `out += D x`: where a correction `x` of the step's increment (the Newton correction's
    /// layout: a frame's end moves by `H exp(x)`) moves the end. Coordinates shift by it; the
    /// rates move by the Newmark relations with the increment's change, `J_r^-1(D) x` for a
    /// frame.
    pub(super) fn correct(
        &self,
        coef: &Coefficients,
        nodes: &[NodeMap],
        x: &[f64],
        out: &mut [f64],
    ) {
        let n = self.sys.len();
        // Slot `s` moved by `x_s`, its increment by `d`.
        let add = |out: &mut [f64], s: usize, d: f64| {
            out[s] += x[s];
            out[n + s] += coef[0][0] * d;
            out[2 * n + s] += coef[1][0] * d;
            out[3 * n + s] += coef[2][0] * d;
        };
        for &i in &self.coords.1 {
            add(out, i, x[i]);
        }
        let g = |i: usize| V3::new(x[i], x[i + 1], x[i + 2]);
        for (k, m) in nodes.iter().enumerate() {
            let (t, r) = (self.sys.translations[k], self.sys.rotations[k]);
            let th = g(r);
            if self.sys.is_frame(k) {
                let du = m.ja * g(t) + m.jb * th;
                for j in 0..3 {
                    add(out, t + j, du[j]);
                }
            }
            let dth = m.ja * th;
            for j in 0..3 {
                add(out, r + j, dth[j]);
            }
        }
    }

    fn propagate_with(&mut self, h: f64, tk: &mut Tracked) -> Result<(), StepFailure> {
        let (n, aug) = (self.sys.len(), self.aug);
        let dim = 4 * n;
        // The iteration matrix at the converged increment (its residual, Newton's last, is
        // not needed: the matrix reads the state and the nodes' rotations alone).
        self.trial.assign(&self.cur);
        self.block_matrices();
        // The elements with inertia through their derivatives, assembled once a step for the
        // carried directions: the matrix's rate columns take them too.
        let held = tk.count > 0;
        if held {
            self.asm.rate_jacobians(self.sys, &self.cur, aug);
        }
        (self.exact_rates, self.rates_held) = (true, held);
        let factored = self.refactor(h, aug, false);
        (self.exact_rates, self.rates_held) = (false, false);
        factored?;
        tk.h = h;
        if tk.count == 0 {
            // Nothing carried (partial Floquet's way to a period's phase): the matrix is
            // still factored at the converged step, as the next step's Newton expects.
            return Ok(());
        }
        self.node_maps(&mut tk.nodes);
        let coef = self.coefficients(h);
        tk.gradients.iter_mut().for_each(|x| *x = 0.0);
        // The perturbed states below differ from the end's (`trial`, which the matrix only
        // read) in their rates alone.
        for c in 0..tk.count {
            tk.dir.copy_from_slice(&tk.columns[c * dim..(c + 1) * dim]);
            let moved = &mut tk.columns[c * dim..(c + 1) * dim];
            self.transport(&coef, &tk.nodes, &tk.dir, moved);
            // The end's perturbation `m` as a correction of the increment by its positions
            // `x_m` (`D x_m`, whose residual is `J x_m`) and a perturbation of the rates alone,
            // `w = m - D x_m`. Then `x = -x_m - J^-1 r_w` and `S' = w + D (x + x_m)`
            // `= w - D J^-1 r_w`: the positions' part is exact through `J`, and `r_w` is the
            // residual's derivative along the rates at fixed positions.
            tk.part.copy_from_slice(&moved[..n]);
            tk.part.iter_mut().for_each(|x| *x = -*x);
            self.correct(&coef, &tk.nodes, &tk.part, moved);
        }
        let (dv, da) = (&mut tk.physical.0, &mut tk.physical.1);
        let dirs = (&tk.columns[..tk.count * dim], tk.count);
        physical_rates(self.sys, &self.in_frame, &self.cur, dirs, (dv, da));
        // The elements with inertia or damping through their derivatives, `-(M da + C dv)`.
        let (dv, da) = (&tk.physical.0, &tk.physical.1);
        self.asm.rate_products(dv, da, tk.count, &mut tk.gradients);
        tk.gradients.iter_mut().for_each(|g| *g = -*g);
        // The joints' rate rows, linear in the velocities: differences from the end's values
        // are exact but for round-off.
        let on = tk.differenced.0.as_slice();
        let differenced = self.asm.has_rate_residual(false);
        if differenced {
            self.asm.rate_residual(self.sys, &self.cur, aug, false);
            for &i in on {
                tk.part[i] = self.asm.residual.constraint[i];
            }
        }
        for c in 0..tk.count {
            let moved = &tk.columns[c * dim..(c + 1) * dim];
            let gradient = &mut tk.gradients[c * n..(c + 1) * n];
            let size = if differenced {
                rate_size(&tk.scale, tk.tau, moved, on)
            } else {
                0.0
            };
            if size > 0.0 {
                let eps = EPSILON / size;
                let support = (on, tk.differenced.1.as_slice());
                perturb_rates(
                    self.sys,
                    &self.in_frame,
                    &self.cur,
                    moved,
                    eps,
                    support,
                    &mut self.trial,
                );
                self.asm.rate_residual(self.sys, &self.trial, aug, false);
                let r = &self.asm.residual.constraint;
                for &i in on.iter().filter(|&&i| self.sys.unknowns[i].is_multiplier()) {
                    gradient[i] -= aug.s * (r[i] - tk.part[i]) / eps;
                }
            }
            // In the treatment's unknowns (the blocks' `R` at the end, as `rhs`).
            rotations::transform_vector(&self.blocks, &self.mats, gradient);
        }
        // Every direction's `J^-1 r_w` at once.
        self.lu
            .solve_many_unrefined(&mut tk.gradients, tk.count)
            .map_err(|e| self.singular(e))?;
        for c in 0..tk.count {
            let moved = &mut tk.columns[c * dim..(c + 1) * dim];
            self.correct(&coef, &tk.nodes, &tk.gradients[c * n..(c + 1) * n], moved);
        }
        self.trial.assign(&self.cur);
        tk.steps += 1;
        tk.h = h;
        if tk.deflate_every > 0 && tk.steps.is_multiple_of(tk.deflate_every) {
            super::deflate::deflate(tk, n, h);
        }
        Ok(())
    }
}
