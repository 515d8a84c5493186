//! Articulated two-bar mechanism (P3, P4): reduced equations and their reference runs.
//!
//! Contract: plain `f64` arithmetic only (see `mod.rs`): no `mbd`, no other crate.

use super::dopri_breaks;

/// Relative and absolute tolerances of the two-bar reference runs.
const TWO_BAR_RTOL: f64 = 1e-12;
const TWO_BAR_ATOL: f64 = 1e-14;
/// Kinks of the load history `<t>`.
const TWO_BAR_BREAKS: [f64; 2] = [10.0, 20.0];

/// The articulated two-bar mechanism of PROBLEMS.md P3/P4 (THEORY.md §10.2 item 6).
///
/// Kinetic energy (bar 1 a slender rod about z, inertia `m1 l1^2/3`; bar 2 a slender rod hinged
/// at the junction, no inertia about its own axis), re-derived by integrating `|v(s)|^2` along
/// bar 2 with `v(s) = l1 th1' e2 + s n'` (`n'` as in `bar2_point`):
///
/// `T = D1 th1'^2/2 - D2 sin th2 th1' th2' + D3 th2'^2/2`,
/// `D1 = (m1/3 + m2) l1^2 + (m2 l2^2/3) cos^2 th2`, `D2 = m2 l1 l2/2`, `D3 = m2 l2^2/3`.
///
/// Lagrange's equations (generalized forces `Q1 = F l1 cos th1 + tau`, from `dJ = l1 dth1 e2`
/// and a drive torque `tau` about z on bar 1; `Q2 = T`, since the relative angular velocity of
/// bar 2 with respect to bar 1 is `th2' e1`), agreeing term by term with THEORY.md:
///
/// `D1 th1'' - D2 sin th2 th2'' = F l1 cos th1 + tau + D3 sin 2th2 th1' th2' + D2 cos th2 th2'^2`
/// `-D2 sin th2 th1'' + D3 th2'' = T - (D3/2) sin 2th2 th1'^2`
///
/// The mass matrix is positive definite: `D1 D3 - D2^2 sin^2 th2 >= m2^2 l1^2 l2^2 (1/3 - 1/4)`.
#[derive(Clone, Copy, Debug)]
pub struct TwoBar {
    pub l1: f64,
    pub l2: f64,
    pub m1: f64,
    pub m2: f64,
    /// Slope of the force along +y at the junction, N/s: `F = f0 <t>`.
    pub f0: f64,
    /// Slope of the torque on bar 2 about e1, N*m/s: `T = t0 <t>`.
    pub t0: f64,
}

/// One sample of a two-bar solution. Angles are absolute and continuous: th2 starts at
/// `theta2_0`, so subtract it to compare with the models' `theta2` channel (zero at the start).
#[derive(Clone, Copy, Debug)]
pub struct TwoBarState {
    pub t: f64,
    pub th1: f64,
    pub th1d: f64,
    pub th1dd: f64,
    pub th2: f64,
    pub th2d: f64,
    pub th2dd: f64,
    /// Torque the drive applies to bar 1 about +z (case 2, for t > 0: the impulse at t = 0 that
    /// sets up `th2'(0+)` is not included); 0 in case 1.
    pub torque: f64,
    /// Bar 2's centre of mass `l1 e1 + (l2/2) n` and its exact velocity and acceleration,
    /// inertial xyz.
    pub xc: [f64; 3],
    pub vc: [f64; 3],
    pub ac: [f64; 3],
}

impl TwoBar {
    /// P3 data: `l = 0.5 m`, `m = 1.6 kg`, `F = 0.1 <t> N`, `T = 0.01 <t> N*m`.
    pub fn paper_case1() -> TwoBar {
        TwoBar {
            l1: 0.5,
            l2: 0.5,
            m1: 1.6,
            m2: 1.6,
            f0: 0.1,
            t0: 0.01,
        }
    }

    /// P4 data: the same bars, no loads.
    pub fn paper_case2() -> TwoBar {
        TwoBar {
            f0: 0.0,
            t0: 0.0,
            ..TwoBar::paper_case1()
        }
    }

    /// The load history `<t>`: `t` on [0, 10], `20 - t` on [10, 20], 0 after.
    pub fn ramp(t: f64) -> f64 {
        if t <= 10.0 {
            t
        } else if t <= 20.0 {
            20.0 - t
        } else {
            0.0
        }
    }

    /// `(F, T)` at time `t`.
    pub fn loads(&self, t: f64) -> (f64, f64) {
        let r = TwoBar::ramp(t);
        (self.f0 * r, self.t0 * r)
    }

    /// `(D1(th2), D2, D3)`.
    pub fn inertia(&self, th2: f64) -> (f64, f64, f64) {
        let d3 = self.m2 * self.l2 * self.l2 / 3.0;
        let d1 = (self.m1 / 3.0 + self.m2) * self.l1 * self.l1 + d3 * th2.cos().powi(2);
        (d1, 0.5 * self.m2 * self.l1 * self.l2, d3)
    }

    /// Kinetic energy of both bars, `T` above.
    pub fn kinetic_energy(&self, th2: f64, th1d: f64, th2d: f64) -> f64 {
        let (d1, d2, d3) = self.inertia(th2);
        0.5 * d1 * th1d * th1d - d2 * th2.sin() * th1d * th2d + 0.5 * d3 * th2d * th2d
    }

    /// Angular momentum about z, `dT/dth1'` (conserved when `F = 0`: the z hinge and the
    /// internal torque `T`, which is about e1, exert no moment about z).
    pub fn momentum_z(&self, th2: f64, th1d: f64, th2d: f64) -> f64 {
        let (d1, d2, _) = self.inertia(th2);
        d1 * th1d - d2 * th2.sin() * th2d
    }

    /// `th2'` just after the drive imposes `th1' = omega` on the mechanism at rest (P4). The
    /// drive's impulse acts on th1 only, so the conjugate momentum `p2 = dT/dth2' =
    /// -D2 sin th2 th1' + D3 th2'` keeps its value 0 across the jump: `th2' = (D2/D3) omega
    /// sin th2`. This is also the projection of the rest state onto the new velocity
    /// constraint in the mass-matrix metric (minimize the kinetic energy of the jump subject to
    /// `th1' = omega`), i.e. a consistent start. With P4 data `D2/D3 = 3 l1/(2 l2) = 1.5`, so
    /// `0.75 rad/s`: bar 2's instantaneous centre is at `2 l2/3`, the centre of percussion.
    pub fn impulsive_th2dot(&self, omega: f64, theta2_0: f64) -> f64 {
        let (_, d2, d3) = self.inertia(theta2_0);
        d2 / d3 * omega * theta2_0.sin()
    }

    /// Free accelerations `(th1'', th2'')` (case 1: no drive).
    pub fn accelerations(&self, t: f64, th1: f64, th2: f64, th1d: f64, th2d: f64) -> (f64, f64) {
        let (f, tq) = self.loads(t);
        let (d1, d2, d3) = self.inertia(th2);
        let (s, c) = th2.sin_cos();
        let s2 = (2.0 * th2).sin();
        let r1 = f * self.l1 * th1.cos() + d3 * s2 * th1d * th2d + d2 * c * th2d * th2d;
        let r2 = tq - 0.5 * d3 * s2 * th1d * th1d;
        // [[d1, -d2 s], [-d2 s, d3]] [th1'', th2''] = [r1, r2]
        let det = d1 * d3 - d2 * d2 * s * s;
        ((d3 * r1 + d2 * s * r2) / det, (d2 * s * r1 + d1 * r2) / det)
    }

    /// The drive torque about z needed for the motion `a1 = [th1, th1', th1'']`,
    /// `a2 = [th2, th2', th2'']`: the residual of the first equation.
    pub fn drive_torque(&self, t: f64, a1: [f64; 3], a2: [f64; 3]) -> f64 {
        let ([th1, th1d, th1dd], [th2, th2d, th2dd]) = (a1, a2);
        let (f, _) = self.loads(t);
        let (d1, d2, d3) = self.inertia(th2);
        let (s, c) = th2.sin_cos();
        d1 * th1dd
            - d2 * s * th2dd
            - f * self.l1 * th1.cos()
            - d3 * (2.0 * th2).sin() * th1d * th2d
            - d2 * c * th2d * th2d
    }

    /// Power of the external loads: `F (junction velocity . y) + T th2'`.
    pub fn load_power(&self, t: f64, th1: f64, th1d: f64, th2d: f64) -> f64 {
        let (f, tq) = self.loads(t);
        f * self.l1 * th1d * th1.cos() + tq * th2d
    }

    /// Position, velocity and acceleration of the point at distance `s` along bar 2 for the
    /// motion `a1 = [th1, th1', th1'']`, `a2 = [th2, th2', th2'']`. Chain rule with
    /// `e1' = th1' e2`, `e2' = -th1' e1`, `x = l1 e1 + s n`:
    /// `n'  = -cos th2 th1' e1 - sin th2 th2' e2 + cos th2 th2' z`,
    /// `n'' = (2 sin th2 th1' th2' - cos th2 th1'') e1 - (cos th2 (th1'^2 + th2'^2)
    ///        + sin th2 th2'') e2 + (cos th2 th2'' - sin th2 th2'^2) z`.
    pub fn bar2_point(&self, s: f64, a1: [f64; 3], a2: [f64; 3]) -> [[f64; 3]; 3] {
        let ([th1, th1d, th1dd], [th2, th2d, th2dd]) = (a1, a2);
        let (s1, c1) = th1.sin_cos();
        let (s2, c2) = th2.sin_cos();
        // Components along (e1, e2, z) to inertial xyz.
        let xyz = |a: f64, b: f64, cz: f64| [a * c1 - b * s1, a * s1 + b * c1, cz];
        let l1 = self.l1;
        [
            xyz(l1, s * c2, s * s2),
            xyz(-s * c2 * th1d, l1 * th1d - s * s2 * th2d, s * c2 * th2d),
            xyz(
                -l1 * th1d * th1d + s * (2.0 * s2 * th1d * th2d - c2 * th1dd),
                l1 * th1dd - s * (c2 * (th1d * th1d + th2d * th2d) + s2 * th2dd),
                s * (c2 * th2dd - s2 * th2d * th2d),
            ),
        ]
    }

    /// Assembles a sample, with bar 2's centre-of-mass kinematics, from the motion
    /// `a1 = [th1, th1', th1'']`, `a2 = [th2, th2', th2'']`.
    pub fn state(&self, t: f64, a1: [f64; 3], a2: [f64; 3], torque: f64) -> TwoBarState {
        let [xc, vc, ac] = self.bar2_point(0.5 * self.l2, a1, a2);
        let ([th1, th1d, th1dd], [th2, th2d, th2dd]) = (a1, a2);
        TwoBarState {
            t,
            th1,
            th1d,
            th1dd,
            th2,
            th2d,
            th2dd,
            torque,
            xc,
            vc,
            ac,
        }
    }

    /// Case I (P3): free mechanism from rest at `th1 = 0`, `th2 = theta2_0`, loaded by `F`, `T`.
    pub fn case1(&self, theta2_0: f64, times: &[f64]) -> Vec<TwoBarState> {
        self.case1_general(0.0, theta2_0, 0.0, 0.0, times)
    }

    /// Case I from any initial angles and rates.
    pub fn case1_general(
        &self,
        th1_0: f64,
        th2_0: f64,
        th1d_0: f64,
        th2d_0: f64,
        times: &[f64],
    ) -> Vec<TwoBarState> {
        self.case1_with_work(th1_0, th2_0, th1d_0, th2d_0, times)
            .into_iter()
            .map(|(s, _)| s)
            .collect()
    }

    /// Case I with the work of the loads since t = 0, integrated as an extra state component.
    pub fn case1_with_work(
        &self,
        th1_0: f64,
        th2_0: f64,
        th1d_0: f64,
        th2d_0: f64,
        times: &[f64],
    ) -> Vec<(TwoBarState, f64)> {
        let rhs = |t: f64, y: &[f64; 5]| {
            let [th1, th2, th1d, th2d, _] = *y;
            let (a1, a2) = self.accelerations(t, th1, th2, th1d, th2d);
            [th1d, th2d, a1, a2, self.load_power(t, th1, th1d, th2d)]
        };
        let y0 = [th1_0, th2_0, th1d_0, th2d_0, 0.0];
        let ys = dopri_breaks(
            rhs,
            0.0,
            y0,
            times,
            &TWO_BAR_BREAKS,
            TWO_BAR_RTOL,
            TWO_BAR_ATOL,
        );
        times
            .iter()
            .zip(ys)
            .map(|(&t, [th1, th2, th1d, th2d, w])| {
                let (a1, a2) = self.accelerations(t, th1, th2, th1d, th2d);
                (self.state(t, [th1, th1d, a1], [th2, th2d, a2], 0.0), w)
            })
            .collect()
    }

    /// Case II (P4): `th1 = omega t` prescribed, th2 from the second equation with `th1'' = 0`
    /// starting at `(theta2_0, th2dot0)` (use `impulsive_th2dot` for the paper's start), and
    /// the drive torque from the first. The loads `f0`, `t0` are applied if nonzero; P4 has
    /// none (`TwoBar::paper_case2`).
    pub fn case2(
        &self,
        omega: f64,
        theta2_0: f64,
        th2dot0: f64,
        times: &[f64],
    ) -> Vec<TwoBarState> {
        self.case2_with_work(omega, theta2_0, th2dot0, times)
            .into_iter()
            .map(|(s, _)| s)
            .collect()
    }

    /// Case II with the work of the drive and the loads since t = 0+ as an extra state component.
    pub fn case2_with_work(
        &self,
        omega: f64,
        theta2_0: f64,
        th2dot0: f64,
        times: &[f64],
    ) -> Vec<(TwoBarState, f64)> {
        let th2dd = |t: f64, th2: f64| {
            let (_, tq) = self.loads(t);
            let (_, _, d3) = self.inertia(th2);
            (tq - 0.5 * d3 * (2.0 * th2).sin() * omega * omega) / d3
        };
        let rhs = |t: f64, y: &[f64; 3]| {
            let [th2, th2d, _] = *y;
            let a2 = th2dd(t, th2);
            let th1 = omega * t;
            let tau = self.drive_torque(t, [th1, omega, 0.0], [th2, th2d, a2]);
            [th2d, a2, tau * omega + self.load_power(t, th1, omega, th2d)]
        };
        let ys = dopri_breaks(
            rhs,
            0.0,
            [theta2_0, th2dot0, 0.0],
            times,
            &TWO_BAR_BREAKS,
            TWO_BAR_RTOL,
            TWO_BAR_ATOL,
        );
        times
            .iter()
            .zip(ys)
            .map(|(&t, [th2, th2d, w])| {
                let a2 = th2dd(t, th2);
                let th1 = omega * t;
                let tau = self.drive_torque(t, [th1, omega, 0.0], [th2, th2d, a2]);
                (self.state(t, [th1, omega, 0.0], [th2, th2d, a2], tau), w)
            })
            .collect()
    }
}
