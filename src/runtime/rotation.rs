//! Rotations through the conformal rotation vector (Wiener–Milenković parameters).
//!
//! A rotation by the angle `phi` about the unit axis `n` has the parameters
//! `c = 4 n tan(phi/4)` and `c0 = 2 - c.c/8`. They are finite for `|phi| < 2 pi`, and `c0 < 0`
//! exactly when `|phi| > pi`, that is when `|c| > 4`. The rotation vector is `theta = phi n`.
//!
//! Conventions (THEORY §1): every vector holds inertial components unless stated;
//! `tilde(a) b = a x b` and `axial` is its inverse; the angular velocity is
//! `tilde(omega) = Rdot R^T`; `compose(p, q)` applies `q` first, then `p`.
//!
//! Contract: pure functions on fixed-size `nalgebra` values. No allocation, no panics, no
//! state. A non-finite input gives a non-finite output instead of a panic. Any `c` is accepted,
//! but `compose` and `from_matrix` return the representative with `|c| <= 4` (`|phi| <= pi`),
//! and `log` the one with `|theta| <= pi`. `rescale` performs that switch on a total `c`
//! together with its rates.
//!
//! Sources: THEORY §2; O. A. Bauchau, "A multibody formulation for helicopter nonlinear
//! dynamic analysis", JAHS 38(2), 1993, Eqs. (1)-(6); O. A. Bauchau and L. Trainelli, "The
//! vectorial parameterization of rotation", Nonlinear Dynamics 32, 2003.

use super::precise::{cot_gap_coefficient, sine_gap_coefficient, versine_coefficient};
use nalgebra::{Matrix3, Vector3};

/// A 3-vector of `f64`.
pub type V3 = Vector3<f64>;
/// A 3x3 matrix of `f64`.
pub type M3 = Matrix3<f64>;

/// Below this norm, conversions between `c` and `theta` use the series `c = theta`. The next
/// term is `theta |theta|^2 / 48`, which is below rounding there.
const SERIES_ROTVEC: f64 = 1e-8;

/// Below this angle, `exp` uses Taylor series; the first neglected terms are of order `phi^6`.
const SERIES_EXP: f64 = 1e-4;

/// Skew-symmetric matrix of `a`, such that `tilde(a) b = a x b`.
#[inline]
pub fn tilde(a: &V3) -> M3 {
    M3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0)
}

/// `tilde(a) tilde(b)`, formed as `b a^T - (a . b) I` (`a x (b x v) = b (a . v) - v (a . b)`)
/// without the product of the two matrices.
#[inline]
pub fn tilde_tilde(a: &V3, b: &V3) -> M3 {
    let mut m = b * a.transpose();
    let d = a.dot(b);
    m.m11 -= d;
    m.m22 -= d;
    m.m33 -= d;
    m
}

/// Axial vector of the skew-symmetric part of `m`, the inverse of `tilde`.
#[inline]
pub fn axial(m: &M3) -> V3 {
    0.5 * V3::new(m.m32 - m.m23, m.m13 - m.m31, m.m21 - m.m12)
}

/// Scalar parameter `c0 = 2 - c.c/8`, negative exactly when the angle exceeds pi.
#[inline]
pub fn c0(c: &V3) -> f64 {
    2.0 - c.norm_squared() / 8.0
}

/// `c c^T - (c.c) I`, which equals `tilde(c) tilde(c)` without a matrix product.
#[inline]
fn tilde_squared(c: &V3) -> M3 {
    c * c.transpose() - M3::from_diagonal_element(c.norm_squared())
}

/// Rotation matrix `R(c) = I + (2 c0 tilde(c) + 2 tilde(c)^2) / (4 - c0)^2` (THEORY §2.2).
#[inline]
pub fn rotation(c: &V3) -> M3 {
    let c0 = c0(c);
    let d = 4.0 - c0;
    M3::identity() + (2.0 / (d * d)) * (c0 * tilde(c) + tilde_squared(c))
}

/// Tangent operator `H(c)`, with `omega = H(c) cdot` in inertial components (THEORY §2.3).
#[inline]
pub fn tangent(c: &V3) -> M3 {
    let c0 = c0(c);
    let d = 4.0 - c0;
    (2.0 / (d * d)) * (M3::from_diagonal_element(c0) + tilde(c) + 0.25 * c * c.transpose())
}

/// Inverse tangent operator `H^{-1}(c) = c0/2 I - tilde(c)/2 + c c^T/8` (THEORY §2.3).
#[inline]
pub fn tangent_inverse(c: &V3) -> M3 {
    M3::from_diagonal_element(0.5 * c0(c)) - 0.5 * tilde(c) + 0.125 * c * c.transpose()
}

/// Time derivative `dH/dt` along the rate `cdot`, so `omegadot = H cddot + Hdot cdot` (§2.3).
#[inline]
pub fn tangent_rate(c: &V3, cdot: &V3) -> M3 {
    let c0 = c0(c);
    let c0dot = -0.25 * c.dot(cdot);
    let d = 4.0 - c0;
    let m = M3::from_diagonal_element(c0) + tilde(c) + 0.25 * c * c.transpose();
    let mdot = M3::from_diagonal_element(c0dot)
        + tilde(cdot)
        + 0.25 * (cdot * c.transpose() + c * cdot.transpose());
    (4.0 * c0dot / (d * d * d)) * m + (2.0 / (d * d)) * mdot
}

/// Parameters `r` of `R(p) R(q)`, switched so that `|r| <= 4` (THEORY §2.4).
#[inline]
pub fn compose(p: &V3, q: &V3) -> V3 {
    let (p0, q0) = (c0(p), c0(q));
    // (p0, p)/(4 - p0) are unit Euler parameters, so this is the quaternion product scaled by
    // delta1 > 0; delta2 carries the sign of the product's scalar part.
    let delta1 = (4.0 - p0) * (4.0 - q0);
    let delta2 = p0 * q0 - p.dot(q);
    let numerator = q0 * p + p0 * q + p.cross(q);
    if delta2 >= 0.0 {
        (4.0 / (delta1 + delta2)) * numerator
    } else {
        (-4.0 / (delta1 - delta2)) * numerator
    }
}

/// Parameters of the relative rotation `R(a)^T R(b)`, that is `compose(-a, b)` (THEORY §2.4).
#[inline]
pub fn relative(a: &V3, b: &V3) -> V3 {
    compose(&-a, b)
}

/// Unit Euler parameters `(e0, e)` of `r` with `e0 >= 0` (Shepperd's method, THEORY §2.6).
///
/// The pivot is the largest of `tr r, r11, r22, r33`, so the square root is at least 1/2 for a
/// rotation. The result is normalized, which projects an almost-orthogonal `r` onto SO(3).
fn euler_parameters(r: &M3) -> (f64, V3) {
    let tr = r.trace();
    let (e0, e) = if tr >= r.m11 && tr >= r.m22 && tr >= r.m33 {
        let e0 = 0.5 * (1.0 + tr).sqrt();
        let s = 0.25 / e0;
        (e0, s * V3::new(r.m32 - r.m23, r.m13 - r.m31, r.m21 - r.m12))
    } else if r.m11 >= r.m22 && r.m11 >= r.m33 {
        let e1 = 0.5 * (1.0 + 2.0 * r.m11 - tr).sqrt();
        let s = 0.25 / e1;
        (
            s * (r.m32 - r.m23),
            V3::new(e1, s * (r.m21 + r.m12), s * (r.m31 + r.m13)),
        )
    } else if r.m22 >= r.m33 {
        let e2 = 0.5 * (1.0 + 2.0 * r.m22 - tr).sqrt();
        let s = 0.25 / e2;
        (
            s * (r.m13 - r.m31),
            V3::new(s * (r.m12 + r.m21), e2, s * (r.m32 + r.m23)),
        )
    } else {
        let e3 = 0.5 * (1.0 + 2.0 * r.m33 - tr).sqrt();
        let s = 0.25 / e3;
        (
            s * (r.m21 - r.m12),
            V3::new(s * (r.m13 + r.m31), s * (r.m23 + r.m32), e3),
        )
    };
    let norm = (e0 * e0 + e.norm_squared()).sqrt();
    let s = if e0 < 0.0 { -1.0 / norm } else { 1.0 / norm };
    (s * e0, s * e)
}

/// Parameters of a rotation matrix with `|c| <= 4`, through Shepperd's method (THEORY §2.6).
#[inline]
pub fn from_matrix(r: &M3) -> V3 {
    let (e0, e) = euler_parameters(r);
    (4.0 / (1.0 + e0)) * e
}

/// Parameters of the rotation vector `theta`: `c = 4 tan(|theta|/4) theta/|theta|`.
#[inline]
pub fn from_rotvec(theta: &V3) -> V3 {
    let angle = theta.norm();
    if angle < SERIES_ROTVEC {
        *theta
    } else {
        (4.0 * (0.25 * angle).tan() / angle) * theta
    }
}

/// Rotation vector of the parameters `c`: `theta = 4 atan(|c|/4) c/|c|`, `|theta| < 2 pi`.
#[inline]
pub fn to_rotvec(c: &V3) -> V3 {
    let norm = c.norm();
    if norm < SERIES_ROTVEC {
        *c
    } else {
        (4.0 * (0.25 * norm).atan() / norm) * c
    }
}

/// Matrix exponential of `tilde(theta)` by the Rodrigues formula.
#[inline]
pub fn exp(theta: &V3) -> M3 {
    let angle2 = theta.norm_squared();
    let angle = angle2.sqrt();
    // sin(phi)/phi and (1 - cos(phi))/phi^2, the latter as 2 sin^2(phi/2)/phi^2 to avoid the
    // cancellation in 1 - cos(phi).
    let (a, b) = if angle < SERIES_EXP {
        (
            1.0 - angle2 / 6.0 * (1.0 - angle2 / 20.0),
            0.5 - angle2 / 24.0 * (1.0 - angle2 / 30.0),
        )
    } else {
        let sinc_half = (0.5 * angle).sin() / (0.5 * angle);
        (angle.sin() / angle, 0.5 * sinc_half * sinc_half)
    };
    M3::identity() + a * tilde(theta) + b * tilde_squared(theta)
}

/// Rotation vector of a rotation matrix, with `|theta| <= pi`.
#[inline]
pub fn log(r: &M3) -> V3 {
    to_rotvec(&from_matrix(r))
}

/// Whether `c` describes an angle beyond pi (`c0 < 0`, `|c| > 4`) and should be rescaled.
#[inline]
pub fn needs_rescale(c: &V3) -> bool {
    c0(c) < 0.0
}

/// Change of state `c* = -16 c/nu` with rates mapped so that omega and omegadot are kept (§2.5).
///
/// The map is an involution, valid for any `c != 0`; the caller applies it when
/// `needs_rescale(c)`, after which `|c*| < 4`. The velocity map is `H(c*)^{-1} H(c)`.
#[inline]
pub fn rescale(c: &V3, cdot: &V3, cddot: &V3) -> (V3, V3, V3) {
    let nu = c.norm_squared();
    let cc = c.dot(cdot) / nu;
    let s = -16.0 / nu;
    let c_star = s * c;
    let cdot_star = s * (cdot - (2.0 * cc) * c);
    let cddot_star = s
        * (cddot
            - (4.0 * cc) * cdot
            - (2.0 * (cdot.norm_squared() + c.dot(cddot)) / nu - 8.0 * cc * cc) * c);
    (c_star, cdot_star, cddot_star)
}

/// Parameters of the half rotation, `c/(1 + sqrt(1 + c.c/16))`, so `R(half(c))^2 = R(c)`.
#[inline]
pub fn half(c: &V3) -> V3 {
    c / (1.0 + (1.0 + c.norm_squared() / 16.0).sqrt())
}

/// The nearest rotation to `r` within round-off (one Newton step of the polar decomposition,
/// `r (3 I - r^T r) / 2`, orthogonal to `O(||r^T r - I||^2)`) for an `r` a few `ulp` from
/// orthogonal, as a product of rotations is. It moves `r` only along its departure from
/// orthogonality: [`orthonormalize`]'s round trip through the quaternion also turns `r` by
/// its rounding, about 0.3 ulp a step the same way on one side of `pi` and the other way on
/// the other side, which kicked the windmill's collective lag each time the hub passed `pi`
/// (by `3e-12 rad/s` at 25 us steps, as `1/h`).
#[inline]
pub fn reorthogonalize(r: &M3) -> M3 {
    r * (M3::identity() * 3.0 - r.transpose() * r) * 0.5
}

/// A proper rotation within `O(||r^T r - I||)` of an almost-orthogonal `r`.
///
/// It is `rotation(from_matrix(r))`: the Shepperd quaternion is normalized, which is close to,
/// but not exactly, the orthogonal polar factor.
#[inline]
pub fn orthonormalize(r: &M3) -> M3 {
    rotation(&from_matrix(r))
}

/// Left Jacobian of the exponential map, `exp((theta + d)~) = exp((J d)~) exp(theta~)` to first
/// order; also the translation part of the SE(3) exponential.
#[inline]
pub fn left_jacobian(theta: &V3) -> M3 {
    let t = theta.norm();
    let tt = tilde(theta);
    M3::identity() + tt * versine_coefficient(t) + tt * tt * sine_gap_coefficient(t)
}

/// Inverse of [`left_jacobian`].
#[inline]
pub fn left_jacobian_inverse(theta: &V3) -> M3 {
    let t = theta.norm();
    let tt = tilde(theta);
    M3::identity() - tt * 0.5 + tt * tt * cot_gap_coefficient(t)
}

#[cfg(test)]
mod tests {
    #[test]
    fn left_jacobian_is_the_derivative_of_exp_and_inverts() {
        let th = V3::new(0.7, -1.1, 0.4);
        let d = V3::new(0.3, 0.2, -0.5) * 1e-6;
        // exp(th + d) exp(th)^T = exp((J d)~) to first order: compare axial parts (1e-10).
        let lhs = axial(&(exp(&(th + d)) * exp(&th).transpose() - M3::identity()));
        assert!((lhs - left_jacobian(&th) * d).norm() < 1e-12);
        assert!((left_jacobian(&th) * left_jacobian_inverse(&th) - M3::identity()).norm() < 1e-13);
        let small = V3::new(1e-6, 2e-6, -1e-6);
        assert!(
            (left_jacobian(&small) * left_jacobian_inverse(&small) - M3::identity()).norm() < 1e-13
        );
    }

    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    /// Frobenius norm of a difference; all tolerances below are on it.
    fn dist(a: &M3, b: &M3) -> f64 {
        (a - b).norm()
    }

    /// `||a - b|| <= tol max(||a||, ||b||)`.
    fn close_rel(a: &V3, b: &V3, tol: f64) -> bool {
        (a - b).norm() <= tol * a.norm().max(b.norm())
    }

    fn close_rel_m(a: &M3, b: &M3, tol: f64) -> bool {
        dist(a, b) <= tol * a.norm().max(b.norm())
    }

    /// A vector in the box `[-2.25, 2.25]^3`, so `|c| < 3.9`.
    fn in_box() -> impl Strategy<Value = V3> {
        let s = -2.25..2.25f64;
        (s.clone(), s.clone(), s).prop_map(|(x, y, z)| V3::new(x, y, z))
    }

    fn unit() -> impl Strategy<Value = V3> {
        let s = -1.0..1.0f64;
        (s.clone(), s.clone(), s).prop_filter_map("axis too short", |(x, y, z)| {
            let v = V3::new(x, y, z);
            let n = v.norm();
            (n > 1e-3).then(|| v / n)
        })
    }

    /// A vector with norm in `[lo, hi)` and a random direction.
    fn with_norm(lo: f64, hi: f64) -> impl Strategy<Value = V3> {
        (unit(), lo..hi).prop_map(|(n, r)| r * n)
    }

    /// A vector with norm `10^u`, `u` uniform in `[lo, hi)`, and a random direction.
    fn with_log_norm(lo: f64, hi: f64) -> impl Strategy<Value = V3> {
        (unit(), lo..hi).prop_map(|(n, u)| 10f64.powf(u) * n)
    }

    /// The Shepperd pivot: 0 for the trace, `j + 1` for the diagonal element `r_jj`.
    fn pivot(r: &M3) -> usize {
        let d = [r.trace(), r.m11, r.m22, r.m33];
        (0..4).fold(0, |best, i| if d[i] > d[best] { i } else { best })
    }

    fn det_is_one(r: &M3) -> bool {
        (r.determinant() - 1.0).abs() < 1e-13
    }

    #[test]
    fn quarter_turn_about_z() {
        // Exact up to rounding: 1e-15.
        let c = V3::new(0.0, 0.0, 4.0 * (PI / 8.0).tan());
        let r = M3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        assert!((from_rotvec(&V3::new(0.0, 0.0, PI / 2.0)) - c).norm() < 1e-15);
        assert!(dist(&rotation(&c), &r) < 1e-15);
        assert!(dist(&exp(&V3::new(0.0, 0.0, PI / 2.0)), &r) < 1e-15);
        assert!((from_matrix(&r) - c).norm() < 1e-15);
    }

    #[test]
    fn compose_switches_past_pi() {
        // Two turns of 2.5 rad about one axis give 5 rad, represented as 5 - 2 pi: 1e-14.
        let n = V3::new(1.0, 2.0, -2.0) / 3.0;
        let p = from_rotvec(&(2.5 * n));
        let r = compose(&p, &p);
        assert!((r - from_rotvec(&((5.0 - 2.0 * PI) * n))).norm() < 1e-14);
        assert!((relative(&-p, &p) - r).norm() < 1e-14);
    }

    #[test]
    fn each_shepperd_pivot_is_reached() {
        // Turns of 3 rad about each axis, and a small turn: 1e-14.
        let cases = [
            (V3::new(0.1, -0.2, 0.05), 0),
            (3.0 * V3::x(), 1),
            (3.0 * V3::y(), 2),
            (3.0 * V3::z(), 3),
        ];
        for (theta, branch) in cases {
            let r = exp(&theta);
            assert_eq!(pivot(&r), branch);
            assert!((log(&r) - theta).norm() < 1e-14);
        }
    }

    proptest! {
        #[test]
        fn tilde_and_axial(a in in_box(), b in in_box()) {
            // Exact up to rounding: 1e-14.
            prop_assert!((tilde(&a) * b - a.cross(&b)).norm() < 1e-14);
            prop_assert!((axial(&tilde(&a)) - a).norm() == 0.0);
        }

        #[test]
        fn rotation_is_proper_and_equals_exp(c in in_box()) {
            // Orthogonality and det 1e-13, against exp 1e-12, R(-c) = R^T and R c = c 1e-14.
            let r = rotation(&c);
            prop_assert!(dist(&(r.transpose() * r), &M3::identity()) < 1e-13);
            prop_assert!(det_is_one(&r));
            prop_assert!(dist(&r, &exp(&to_rotvec(&c))) < 1e-12);
            prop_assert!(dist(&rotation(&-c), &r.transpose()) < 1e-14);
            prop_assert!((r * c - c).norm() < 1e-14);
        }

        #[test]
        fn compose_is_the_matrix_product(p in with_norm(0.0, 4.0), q in with_norm(0.0, 4.0)) {
            // Products cross pi here. Matrices 1e-12, |r| <= 4 + 1e-12.
            let r = compose(&p, &q);
            prop_assert!(dist(&rotation(&r), &(rotation(&p) * rotation(&q))) < 1e-12);
            prop_assert!(r.norm() <= 4.0 + 1e-12);
            let rel = relative(&p, &q);
            prop_assert!(dist(&rotation(&rel), &(rotation(&p).transpose() * rotation(&q))) < 1e-12);
            prop_assert!(rel.norm() <= 4.0 + 1e-12);
        }

        #[test]
        fn rescale_keeps_rotation_and_rates(
            c in with_norm(4.0 + 1e-9, 12.0), cdot in in_box(), cddot in in_box()
        ) {
            // R 1e-12; omega and omegadot 1e-10 relative; the map is an involution (1e-12 rel).
            prop_assert!(needs_rescale(&c));
            let (cs, cdots, cddots) = rescale(&c, &cdot, &cddot);
            prop_assert!(cs.norm() < 4.0 && !needs_rescale(&cs));
            prop_assert!(dist(&rotation(&cs), &rotation(&c)) < 1e-12);
            let omega = tangent(&c) * cdot;
            prop_assert!(close_rel(&(tangent(&cs) * cdots), &omega, 1e-10));
            let omegadot = tangent(&c) * cddot + tangent_rate(&c, &cdot) * cdot;
            let omegadot_s = tangent(&cs) * cddots + tangent_rate(&cs, &cdots) * cdots;
            prop_assert!(close_rel(&omegadot_s, &omegadot, 1e-10));
            let map = tangent_inverse(&cs) * tangent(&c);
            prop_assert!(close_rel(&(map * cdot), &cdots, 1e-10));
            let (cb, cdotb, cddotb) = rescale(&cs, &cdots, &cddots);
            prop_assert!(close_rel(&cb, &c, 1e-12));
            prop_assert!(close_rel(&cdotb, &cdot, 1e-12));
            prop_assert!(close_rel(&cddotb, &cddot, 1e-12));
        }

        #[test]
        fn from_matrix_inverts_rotation(c in in_box()) {
            // 1e-12.
            prop_assert!((from_matrix(&rotation(&c)) - c).norm() < 1e-12);
        }

        #[test]
        fn from_matrix_near_pi(n in unit(), gap in -9.0..-2.0f64) {
            // |c| = 4 - 10^gap, angles within about 1e-9 of pi: 1e-12.
            let c = (4.0 - 10f64.powf(gap)) * n;
            prop_assert!((from_matrix(&rotation(&c)) - c).norm() < 1e-12);
        }

        #[test]
        fn from_matrix_on_each_diagonal_pivot(
            j in 0..3usize, u in in_box(), angle in 2.2..(PI - 1e-4)
        ) {
            // The axis is dominated by e_j and the angle is large, so r_jj is the pivot: 1e-12.
            let mut axis = 0.2 * u;
            axis[j] = 1.0;
            let c = from_rotvec(&(angle * axis.normalize()));
            let r = rotation(&c);
            prop_assert_eq!(pivot(&r), j + 1);
            prop_assert!((from_matrix(&r) - c).norm() < 1e-12);
        }

        #[test]
        fn from_matrix_of_half_turns(n in unit()) {
            // R = 2 n n^T - I: |c| = 4 and R(c) = R within 1e-12, c along n.
            let r = 2.0 * n * n.transpose() - M3::identity();
            let c = from_matrix(&r);
            prop_assert!((c.norm() - 4.0).abs() < 1e-12);
            prop_assert!(c.cross(&n).norm() < 1e-12);
            prop_assert!(dist(&rotation(&c), &r) < 1e-12);
        }

        #[test]
        fn tangent_against_central_differences(c in in_box(), cdot in in_box()) {
            // Differences with step 1e-5: 1e-7 relative. Inverse and H^T = R^T H: 1e-12.
            let h = 1e-5;
            let rdot = (rotation(&(c + h * cdot)) - rotation(&(c - h * cdot))) / (2.0 * h);
            let omega_fd = axial(&(rdot * rotation(&c).transpose()));
            prop_assert!(close_rel(&(tangent(&c) * cdot), &omega_fd, 1e-7));
            prop_assert!(dist(&(tangent_inverse(&c) * tangent(&c)), &M3::identity()) < 1e-12);
            let hdot_fd = (tangent(&(c + h * cdot)) - tangent(&(c - h * cdot))) / (2.0 * h);
            prop_assert!(close_rel_m(&tangent_rate(&c, &cdot), &hdot_fd, 1e-7));
            let body = rotation(&c).transpose() * tangent(&c);
            prop_assert!(dist(&tangent(&c).transpose(), &body) < 1e-12);
        }

        #[test]
        fn rotvec_round_trip(theta in with_norm(0.0, 2.0 * PI - 0.1)) {
            // 1e-13 absolute (|theta| < 6.2).
            prop_assert!((to_rotvec(&from_rotvec(&theta)) - theta).norm() < 1e-13);
        }

        #[test]
        fn rotvec_small_angles(theta in with_log_norm(-12.0, -6.0)) {
            // Includes |theta| ~ 1e-10 and the series switch at 1e-8: 1e-13 relative, and c agrees
            // with theta (1 + |theta|^2/48) to 1e-15 relative.
            let c = from_rotvec(&theta);
            prop_assert!(close_rel(&to_rotvec(&c), &theta, 1e-13));
            prop_assert!(close_rel(&c, &(theta * (1.0 + theta.norm_squared() / 48.0)), 1e-15));
        }

        #[test]
        fn exp_log_round_trip(theta in with_norm(0.0, PI - 1e-6)) {
            // 1e-12; exp is orthogonal to 1e-13.
            let r = exp(&theta);
            prop_assert!(dist(&(r.transpose() * r), &M3::identity()) < 1e-13);
            prop_assert!((log(&r) - theta).norm() < 1e-12);
        }

        #[test]
        fn exp_small_angles(theta in with_log_norm(-12.0, -2.0)) {
            // Across the series switch at 1e-4, against R(c): 1e-15.
            prop_assert!(dist(&exp(&theta), &rotation(&from_rotvec(&theta))) < 1e-15);
        }

        #[test]
        fn half_squares_to_the_rotation(c in in_box()) {
            // 1e-12.
            let r = rotation(&half(&c));
            prop_assert!(dist(&(r * r), &rotation(&c)) < 1e-12);
        }

        #[test]
        fn reorthogonalize_keeps_the_rotation(
            c in in_box(), noise in prop::array::uniform9(-1e-13..1e-13f64)
        ) {
            // A rotation a few hundred ulp from orthogonal: orthogonal to round-off after it
            // (measured 6.7e-16 over the cases), and no farther from the rotation than the
            // noise (measured 1.9e-13; the noise's norm is at most 3e-13).
            let r = rotation(&c);
            let perturbed = r + M3::from_fn(|i, j| noise[3 * i + j]);
            let q = reorthogonalize(&perturbed);
            prop_assert!(dist(&(q.transpose() * q), &M3::identity()) < 1.5e-15);
            prop_assert!(det_is_one(&q));
            prop_assert!(dist(&q, &r) < 3e-13);
        }

        #[test]
        fn orthonormalize_projects(
            c in in_box(), noise in prop::array::uniform9(-1e-9..1e-9f64)
        ) {
            // Exact R returned within 1e-13; with 1e-9 noise per entry: orthogonal to 1e-13,
            // det 1, within 1e-8 of R.
            let r = rotation(&c);
            prop_assert!(dist(&orthonormalize(&r), &r) < 1e-13);
            let perturbed = r + M3::from_fn(|i, j| noise[3 * i + j]);
            let q = orthonormalize(&perturbed);
            prop_assert!(dist(&(q.transpose() * q), &M3::identity()) < 1e-13);
            prop_assert!(det_is_one(&q));
            prop_assert!(dist(&q, &r) < 1e-8);
        }
    }
}
