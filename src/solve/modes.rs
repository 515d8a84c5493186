//! Linearized modal analysis about the initial state (`mbd modes`).
//!
//! The element matrices at the consistent initial state give `M x'' + G x' + K x = 0` with
//! `B x = 0` (THEORY §3.6, §6). A state that spins rigidly at `Omega` about a fixed axis (every
//! rotating node with the same angular velocity) is a relative equilibrium: perturbations are
//! then written in the frame turning with it, `dx = Q xi`, `dtheta = Q psi`, `Q = exp(Omega~ t)`,
//! which with `d omega = d theta-dot - omega~ d theta` gives constant coefficients:
//! `G_r = G + 2 M_x Omega~ + M_theta Omega~` and `K_r = K + G_x Omega~ + M_x Omega~^2`
//! (`_x` the translation columns, `_theta` the rotation columns). The equations are reduced
//! to the null space of `B` and the quadratic eigenproblem is solved as a generalized one,
//! `[0 I; -K -G] z = s [I 0; 0 M] z` (QZ), so massless unknowns give infinite eigenvalues,
//! which are dropped.

use super::integrator::Integrator;
use super::linear::{generalized_eigen, null_space};
use super::{RuntimeFailure, Settings};
use crate::runtime::rotation::{tilde, V3};
use crate::runtime::{Element, System};
use nalgebra::DMatrix;

/// A complex number `re + i im`.
#[allow(non_camel_case_types)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct c64 {
    pub re: f64,
    pub im: f64,
}

impl c64 {
    pub fn new(re: f64, im: f64) -> c64 {
        c64 { re, im }
    }
}

/// One mode: the eigenvalue `s` (1/s) and the shape over the system's unknowns (multipliers
/// zero), scaled so that its largest entry is 1.
#[derive(Clone, Debug)]
pub struct Mode {
    pub s: c64,
    pub shape: Vec<c64>,
}

impl Mode {
    /// Undamped natural frequency `|s|` in rad/s.
    pub fn omega(&self) -> f64 {
        (self.s.re * self.s.re + self.s.im * self.s.im).sqrt()
    }

    /// Damped frequency in Hz.
    pub fn frequency_hz(&self) -> f64 {
        self.s.im.abs() / (2.0 * std::f64::consts::PI)
    }

    pub fn damping_ratio(&self) -> f64 {
        let w = self.omega();
        if w > 0.0 {
            -self.s.re / w
        } else {
            0.0
        }
    }
}

/// What the analysis found.
pub struct Modes {
    pub modes: Vec<Mode>,
    /// The spin the perturbations were referred to, if the state spins rigidly.
    pub spin: Option<[f64; 3]>,
}

/// The common angular velocity of every rotating node, if they share one that is not zero.
fn rigid_spin(st: &crate::runtime::State) -> Option<V3> {
    let w0 = st.rot.first()?.omega();
    let scale = w0.norm();
    if scale == 0.0 {
        return None;
    }
    st.rot
        .iter()
        .all(|r| (r.omega() - w0).norm() <= 1e-9 * scale)
        .then_some(w0)
}

pub fn modes(sys: &System, set: &Settings) -> Result<Modes, RuntimeFailure> {
    let mut it = Integrator::new(sys, set)?;
    it.initialize()?;
    let spin = rigid_spin(it.state());
    let lin = it.linearize();
    let nf = lin.unknowns.len();
    let dense = |a: &[f64]| DMatrix::<f64>::from_row_slice(nf, nf, a);
    let (mut m, mut g, mut k) = (dense(&lin.m), dense(&lin.g), dense(&lin.k));
    if let Some(w) = spin {
        // Omega~ on the translation and rotation triplets of each rotating node and point mass.
        let wt = tilde(&w);
        let mut om = DMatrix::<f64>::zeros(nf, nf);
        let mut is_rot = vec![false; nf];
        let mut pos = vec![usize::MAX; sys.len()];
        for (j, &i) in lin.unknowns.iter().enumerate() {
            pos[i] = j;
        }
        let mut triplets: Vec<(usize, bool)> = Vec::new();
        for (n, &t) in sys.translations.iter().enumerate() {
            triplets.push((t, false));
            triplets.push((sys.rotations[n], true));
        }
        for e in &sys.elements {
            if let Element::PointMass(p) = e {
                triplets.push((p.dofs[0], false));
            }
        }
        for (first, rot) in triplets {
            let j = pos[first];
            if j == usize::MAX {
                continue;
            }
            for a in 0..3 {
                is_rot[j + a] = rot;
                for b in 0..3 {
                    om[(j + a, j + b)] = wt[(a, b)];
                }
            }
        }
        let split = |a: &DMatrix<f64>, rot: bool| {
            DMatrix::<f64>::from_fn(
                nf,
                nf,
                |i, j| if is_rot[j] == rot { a[(i, j)] } else { 0.0 },
            )
        };
        let (mx, mt, gx) = (split(&m, false), split(&m, true), split(&g, false));
        g = &g + &mx * &om * 2.0 + &mt * &om;
        k = &k + &gx * &om + &mx * &om * &om;
    }
    // Null space of B.
    let (basis, r) = null_space(&lin.b, lin.rows, nf)
        .ok_or_else(|| failure("the constraint gradient could not be decomposed"))?;
    let basis = DMatrix::<f64>::from_column_slice(nf, r, &basis);
    let red = |a: &DMatrix<f64>| basis.transpose() * a * &basis;
    (m, g, k) = (red(&m), red(&g), red(&k));
    let n2 = 2 * r;
    let a = DMatrix::<f64>::from_fn(n2, n2, |i, j| match (i < r, j < r) {
        (true, true) => 0.0,
        (true, false) => f64::from(u8::from(j - r == i)),
        (false, true) => -k[(i - r, j)],
        (false, false) => -g[(i - r, j - r)],
    });
    let bm = DMatrix::<f64>::from_fn(n2, n2, |i, j| match (i < r, j < r) {
        (true, true) => f64::from(u8::from(i == j)),
        (false, false) => m[(i - r, j - r)],
        _ => 0.0,
    });
    let ev = generalized_eigen(a.as_slice(), bm.as_slice(), n2)
        .ok_or_else(|| failure("the eigenvalue problem did not converge"))?;
    let bnorm = (0..n2).map(|i| bm[(i, i)].abs()).fold(0.0, f64::max);
    let mut out = Vec::new();
    for ((xr, xi), (yr, yi), z) in ev {
        let den = yr * yr + yi * yi;
        if den.sqrt() <= 1e-12 * bnorm.max(1.0) {
            continue;
        }
        let s = c64::new((xr * yr + xi * yi) / den, (xi * yr - xr * yi) / den);
        if !(s.re.is_finite() && s.im.is_finite()) || s.im < 0.0 {
            continue;
        }
        // Shape over the unknowns: the basis times the displacement half of z.
        let mut shape = vec![c64::new(0.0, 0.0); sys.len()];
        for (row, &i) in lin.unknowns.iter().enumerate() {
            let (mut re, mut im) = (0.0, 0.0);
            for (c, zc) in z.iter().take(r).enumerate() {
                re += basis[(row, c)] * zc.0;
                im += basis[(row, c)] * zc.1;
            }
            shape[i] = c64::new(re, im);
        }
        // Scale so that the largest entry is real and 1.
        let lead = shape
            .iter()
            .copied()
            .max_by(|p, q| p.re.hypot(p.im).total_cmp(&q.re.hypot(q.im)))
            .unwrap_or(c64::new(1.0, 0.0));
        let l2 = lead.re * lead.re + lead.im * lead.im;
        if l2 > 0.0 {
            for z in shape.iter_mut() {
                *z = c64::new(
                    (z.re * lead.re + z.im * lead.im) / l2,
                    (z.im * lead.re - z.re * lead.im) / l2,
                );
            }
        }
        out.push(Mode { s, shape });
    }
    out.sort_by(|p, q| p.omega().total_cmp(&q.omega()));
    Ok(Modes {
        modes: out,
        spin: spin.map(Into::into),
    })
}

fn failure(detail: &str) -> RuntimeFailure {
    RuntimeFailure {
        kind: super::FailureKind::Singular,
        t: 0.0,
        step: 0,
        entity: None,
        detail: detail.to_string(),
    }
}
