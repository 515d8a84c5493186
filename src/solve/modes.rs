//! Linearized modal analysis about the initial state (`mbd modes`).
//!
//! The element matrices at the consistent initial state give `M x'' + G x' + K x = 0` with
//! `B x = 0` (THEORY §3.6, §6). Modes exist only about a steady motion: an equilibrium, or a
//! rigid rotation at `Omega` about a fixed axis that the equations do not notice (a relative
//! equilibrium of a system symmetric about the axis). [`super::steady`] decides which, or
//! why neither, and brings a state that moves rigidly onto its steady motion; a model that is neither (a rotor on a non-rotating flexible structure, two rotors,
//! gravity across the spin axis) has periodic or time-varying equations, and the analysis
//! refuses it unless frozen-time eigenvalues are asked for.
//!
//! About a rigid rotation, perturbations are written in the frame turning with it,
//! `dx = Q xi`, `dtheta = Q psi`, `Q = exp(Omega~ t)`, which with
//! `d omega = d theta-dot - omega~ d theta` gives constant coefficients:
//! `G_r = G + 2 M_x Omega~ + M_theta Omega~` and `K_r = K + G_x Omega~ + M_x Omega~^2`
//! (`_x` the translation columns, `_theta` the rotation columns). The equations are reduced
//! to the null space of `B` and the quadratic eigenproblem is solved as a generalized one,
//! `[0 I; -K -G] z = s [I 0; 0 M] z` (QZ), so massless unknowns give infinite eigenvalues,
//! which are dropped.

use super::integrator::{Integrator, Linearization};
use super::linear::{generalized_eigen, null_space};
use super::steady::{
    coordinates, periodic_change, relax, rigid_motion, uniform_spin, PERIODIC_TOL,
};
use super::RuntimeFailure;
use crate::runtime::rotation::{tilde, V3};
use crate::runtime::System;
use crate::settings::Settings;
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

/// Why the initial state is not a steady motion.
#[derive(Clone, Debug, PartialEq)]
pub enum Unsteady {
    /// Two rotating nodes (of entities `a` and `b`) turn at different rates: a rotor on a
    /// non-rotating structure, or two rotors.
    Spins {
        a: usize,
        wa: [f64; 3],
        b: usize,
        wb: [f64; 3],
    },
    /// The velocities are not a rigid rotation (entity, deviation in m/s).
    Velocities { entity: usize, deviation: f64 },
    /// The state accelerates: not an equilibrium or steady rotation (entity, deviation in
    /// m/s^2 or rad/s^2).
    Accelerates {
        entity: usize,
        deviation: f64,
        angular: bool,
    },
    /// The model turns rigidly at `spin`, but its linearized equations change as it turns
    /// (largest relative change over a turn of one radian): they are periodic.
    Periodic { spin: [f64; 3], change: f64 },
}

/// The frame the modes are referred to.
#[derive(Clone, Debug, PartialEq)]
pub enum Frame {
    /// About an equilibrium.
    Inertial,
    /// About a steady rotation, in the frame turning at `spin` (rad/s).
    Rotating { spin: [f64; 3] },
    /// Frozen-time eigenvalues at t = 0 of a motion that is not steady (asked for): not the
    /// system's modes. Referred to the frame turning at `spin` when every node turns alike.
    Frozen {
        spin: Option<[f64; 3]>,
        why: Unsteady,
    },
}

impl Frame {
    pub fn spin(&self) -> Option<[f64; 3]> {
        match self {
            Frame::Inertial => None,
            Frame::Rotating { spin } => Some(*spin),
            Frame::Frozen { spin, .. } => *spin,
        }
    }

    /// The CSV label: `inertial`, `rotating` or `frozen`.
    pub fn label(&self) -> &'static str {
        match self {
            Frame::Inertial => "inertial",
            Frame::Rotating { .. } => "rotating",
            Frame::Frozen { .. } => "frozen",
        }
    }
}

/// What the analysis found.
pub struct Modes {
    /// By increasing natural frequency; one of each complex-conjugate pair (`Im s >= 0`).
    pub modes: Vec<Mode>,
    pub frame: Frame,
    /// Degrees of freedom: unknowns less independent constraints.
    pub dofs: usize,
    /// Of those, the motions without inertia (infinite eigenvalues, no mode).
    pub massless: usize,
    /// The fastest spin of any rotating node at the start (rad/s).
    pub rotor_speed: f64,
    /// How far the steady motion is from the initial state: the largest translation (m).
    pub moved: f64,
}

/// Why the analysis gave no modes.
#[derive(Clone, Debug, PartialEq)]
pub enum ModesFailure {
    Runtime(RuntimeFailure),
    Unsteady(Unsteady),
}

impl From<RuntimeFailure> for ModesFailure {
    fn from(f: RuntimeFailure) -> ModesFailure {
        ModesFailure::Runtime(f)
    }
}

/// The modes about the steady motion of the initial state. With `frozen`, a state that is not
/// a steady motion gives the frozen-time eigenvalues (marked as such) instead of
/// [`ModesFailure::Unsteady`].
///
/// A state that moves rigidly but does not yet balance (a beam's stretch from a formula, a blade
/// not yet at its steady lag or coning angle, a structure before its static deflection) is
/// first brought to the nearest steady motion by Newton's method on the rotating-frame
/// equations ([`super::steady::relax`]); [`Modes::moved`] says how far.
pub fn modes(sys: &System, set: &Settings, frozen: bool) -> Result<Modes, ModesFailure> {
    let mut it = Integrator::new(sys, set)?;
    it.initialize()?;
    let st = it.state().clone();
    let found = match rigid_motion(sys, &st) {
        Err(why) => Err(why),
        Ok(motion) => {
            let periodic = if motion.spin.norm() > 0.0 {
                let lin = it.linearize();
                periodic_change(sys, &mut it, &st, &lin, &motion)?
            } else {
                0.0
            };
            if periodic > PERIODIC_TOL {
                Err(Unsteady::Periodic {
                    spin: motion.spin.into(),
                    change: periodic,
                })
            } else {
                relax(sys, &mut it, &st, &motion, set.increment_tolerance)?
                    .map(|moved| (motion, moved))
            }
        }
    };
    let (frame, moved) = match found {
        Ok((motion, moved)) if motion.spin.norm() > 0.0 => (
            Frame::Rotating {
                spin: motion.spin.into(),
            },
            moved,
        ),
        Ok((_, moved)) => (Frame::Inertial, moved),
        Err(why) if frozen => {
            // Frozen at the initial state itself.
            it.restart(&st)?;
            let spin = uniform_spin(sys, &st).ok().flatten().map(Into::into);
            (Frame::Frozen { spin, why }, 0.0)
        }
        Err(why) => return Err(ModesFailure::Unsteady(why)),
    };
    let state = it.state().clone();
    let lin = it.linearize();
    let (m, g, k) = rotating_frame(sys, &lin, frame.spin().map(V3::from));
    let mut out = eigen(sys, &lin, m, g, k, frame)?;
    out.rotor_speed = state
        .rot
        .iter()
        .map(|r| r.omega().norm())
        .fold(0.0, f64::max);
    out.moved = moved;
    Ok(out)
}

/// `M`, `G`, `K` over the free unknowns, in the frame turning at `spin` when given.
pub(super) fn rotating_frame(
    sys: &System,
    lin: &Linearization,
    spin: Option<V3>,
) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let nf = lin.unknowns.len();
    let dense = |a: &[f64]| DMatrix::<f64>::from_row_slice(nf, nf, a);
    let (m, mut g, mut k) = (dense(&lin.m), dense(&lin.g), dense(&lin.k));
    let Some(w) = spin else { return (m, g, k) };
    // Omega~ on the translation and rotation triplets of each rotating node and point mass.
    let wt = tilde(&w);
    let mut om = DMatrix::<f64>::zeros(nf, nf);
    let mut is_rot = vec![false; nf];
    let mut pos = vec![usize::MAX; sys.len()];
    for (j, &i) in lin.unknowns.iter().enumerate() {
        pos[i] = j;
    }
    let (tr, _) = coordinates(sys);
    let triplets = tr
        .iter()
        .map(|&t| (t, false))
        .chain(sys.rotations.iter().map(|&r| (r, true)));
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
    (m, g, k)
}

/// The eigenvalues and shapes of `M x'' + G x' + K x = 0` on the null space of `B`.
fn eigen(
    sys: &System,
    lin: &Linearization,
    m: DMatrix<f64>,
    g: DMatrix<f64>,
    k: DMatrix<f64>,
    frame: Frame,
) -> Result<Modes, RuntimeFailure> {
    let nf = lin.unknowns.len();
    let (basis, r) = null_space(&lin.b, lin.rows, nf)
        .ok_or_else(|| failure("the constraint gradient could not be decomposed"))?;
    let basis = DMatrix::<f64>::from_column_slice(nf, r, &basis);
    let red = |a: &DMatrix<f64>| basis.transpose() * a * &basis;
    let (m, g, k) = (red(&m), red(&g), red(&k));
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
    let mut infinite = 0;
    for ((xr, xi), (yr, yi), z) in ev {
        let den = yr * yr + yi * yi;
        if den.sqrt() <= 1e-12 * bnorm.max(1.0) {
            infinite += 1;
            continue;
        }
        let s = c64::new((xr * yr + xi * yi) / den, (xi * yr - xr * yi) / den);
        if !(s.re.is_finite() && s.im.is_finite()) {
            infinite += 1;
            continue;
        }
        if s.im < 0.0 {
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
        frame,
        dofs: r,
        massless: infinite / 2,
        rotor_speed: 0.0,
        moved: 0.0,
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
