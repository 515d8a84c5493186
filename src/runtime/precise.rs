//! Arithmetic that keeps what plain floating point would round away where the integrator
//! amplifies it by `1/(beta h^2)` (ARCHITECTURE.md, "No round-off the step amplifies"): whole
//! turns taken off an angle exactly (Cody and Waite), a sum with its rounding error
//! (two-sum), and the Jacobians' coefficients of [`super::rotation`] by their series where the
//! closed forms cancel.

/// `2 pi` in two parts (Cody and Waite): `TAU_HI` keeps 32 significant bits, so `m TAU_HI` is
/// exact for `|m| < 2^21` turns, and `TAU_LO` is the rest.
const TAU_HI: f64 = 6.2831853069365025;
const TAU_LO: f64 = 2.430840202602477e-10;

/// `x` reduced by whole turns into `[-pi, pi]`, to round-off of the result rather than of `x`:
/// `x - m TAU_HI` is exact, and only `m TAU_LO` rounds. The plain `x - 2 pi m` carries
/// `ulp(x)` (3.6e-15 rad at 27.8 rad) and the rounding of `2 pi` times `m`.
#[inline]
pub fn reduce_angle(x: f64) -> f64 {
    let m = (x / std::f64::consts::TAU).round();
    (x - m * TAU_HI) - m * TAU_LO
}

/// `a + b` as the rounded sum and its exact rounding error (Knuth's two-sum).
#[inline]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `(1 - cos t) / t^2`, as `2 sin^2(t/2) / t^2`: accurate to round-off at every angle. The
/// direct form loses `1e-16 / t^2` of itself; a step's rotation (`Omega h`, 1.2e-4 rad on the
/// windmill at 1.25e-5 s) then bent every step's increment the same way, and the windmill's
/// error grew as `1/h^2` below 5e-5 s (ARCHITECTURE.md, "No round-off the step amplifies").
#[inline]
pub(crate) fn versine_coefficient(t: f64) -> f64 {
    if t < 1e-8 {
        return 0.5;
    }
    let sinc = (0.5 * t).sin() / (0.5 * t);
    0.5 * sinc * sinc
}

/// `(t - sin t) / t^3`, by its series below 1 rad (to `t^16 / 19!`, the next term 2e-20),
/// where the direct form cancels.
#[inline]
pub(crate) fn sine_gap_coefficient(t: f64) -> f64 {
    const SERIES: [f64; 9] = [
        1.0 / 6.0,
        -1.0 / 120.0,
        1.0 / 5040.0,
        -1.0 / 362880.0,
        1.0 / 39916800.0,
        -1.0 / 6227020800.0,
        1.0 / 1307674368000.0,
        -1.0 / 355687428096000.0,
        1.0 / 121645100408832000.0,
    ];
    if t < 1.0 {
        horner(&SERIES, t * t)
    } else {
        (t - t.sin()) / (t * t * t)
    }
}

/// `sum c_k x^k`.
#[inline]
fn horner(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ck| acc * x + ck)
}

/// `1/t^2 - (1 + cos t) / (2 t sin t)`, i.e. `(1 - (t/2) cot(t/2)) / t^2`, by its series below
/// 1 rad (to `t^22`, the next term 4e-21), where the direct form cancels `1/t^2` (1e-7 of
/// itself at 1e-4 rad).
#[inline]
pub(crate) fn cot_gap_coefficient(t: f64) -> f64 {
    const SERIES: [f64; 12] = [
        1.0 / 12.0,
        1.0 / 720.0,
        1.0 / 30240.0,
        1.0 / 1209600.0,
        1.0 / 47900160.0,
        691.0 / 1307674368000.0,
        1.0 / 74724249600.0,
        3617.0 / 10670622842880000.0,
        43867.0 / 5109094217170944000.0,
        174611.0 / 802857662698291200000.0,
        77683.0 / 14101100039391805440000.0,
        236364091.0 / 1693824136731743669452800000.0,
    ];
    if t < 1.0 {
        horner(&SERIES, t * t)
    } else {
        1.0 / (t * t) - (1.0 + t.cos()) / (2.0 * t * t.sin())
    }
}

/// The coefficients `(t - sin t) / t^3`, `(t^2 + 2 cos t - 2) / (2 t^4)` and
/// `(2 t - 3 sin t + t cos t) / (2 t^5)` of SE(3)'s translation-rotation Jacobian block, by
/// their series below 1 rad (to `t^18`, the next terms 1e-21), where the closed forms lose
/// `1e-16 / t^2` to `1e-16 / t^4` of themselves (3e-6 of the last at 1e-2 rad).
#[inline]
pub(crate) fn coupling_coefficients(t: f64) -> (f64, f64, f64) {
    const B: [f64; 10] = [
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40320.0,
        -1.0 / 3628800.0,
        1.0 / 479001600.0,
        -1.0 / 87178291200.0,
        1.0 / 20922789888000.0,
        -1.0 / 6402373705728000.0,
        1.0 / 2432902008176640000.0,
        -1.0 / 1124000727777607680000.0,
    ];
    const C: [f64; 10] = [
        1.0 / 120.0,
        -1.0 / 2520.0,
        1.0 / 120960.0,
        -1.0 / 9979200.0,
        1.0 / 1245404160.0,
        -1.0 / 217945728000.0,
        1.0 / 50812489728000.0,
        -1.0 / 15205637551104000.0,
        1.0 / 5676771352412160000.0,
        -1.0 / 2585201673888497664000.0,
    ];
    let (b, c) = if t < 1.0 {
        let t2 = t * t;
        (horner(&B, t2), horner(&C, t2))
    } else {
        let (s, co) = t.sin_cos();
        (
            (t * t + 2.0 * co - 2.0) / (2.0 * t.powi(4)),
            (2.0 * t - 3.0 * s + t * co) / (2.0 * t.powi(5)),
        )
    };
    (sine_gap_coefficient(t), b, c)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Jacobians' coefficients against 40-digit values (mpmath) of their closed forms at
    /// each input's exact binary value: within 2 ulps below 1 rad, where the series take over,
    /// and within 1.5e-15 above. At the windmill's step rotation (1.16e-4 rad) the direct
    /// `(1 - cos t) / t^2` is off by 8.0e-9 of itself, and `1/t^2 - (1 + cos t) / (2 t sin t)` by
    /// 6.0e-8.
    #[test]
    fn jacobian_coefficients_are_accurate_at_every_angle() {
        let cases = [
            (
                1.16e-4,
                [0.4999999994393333, 0.16666666655453333, 0.08333333335202223],
            ),
            (
                1e-3,
                [0.4999999583333347, 0.16666665833333352, 0.08333333472222225],
            ),
            (
                0.3,
                [0.4962612319377109, 0.16591827180223795, 0.08345860179452762],
            ),
            (
                0.999,
                [
                    0.45977558483250813,
                    0.15854489735930935,
                    0.08475322555824442,
                ],
            ),
            (
                1.001,
                [0.4596197360357459, 0.1585131186579003, 0.084759055929927],
            ),
            (
                2.5,
                [0.2881829784875094, 0.12169778277734679, 0.09354531654909429],
            ),
        ];
        for (t, want) in cases {
            let got = [
                versine_coefficient(t),
                sine_gap_coefficient(t),
                cot_gap_coefficient(t),
            ];
            // Above 1 rad the closed forms cancel a little still: the last one lost 5.9e-16 of
            // itself at 1.001 rad (12 ulps of `1/t^2`).
            let bound = if t < 1.0 { 4.5e-16 } else { 1.5e-15 };
            for (g, w) in got.iter().zip(want) {
                assert!((g - w).abs() <= bound * w, "at {t} rad: {g:e}, want {w:e}");
            }
        }
    }

    /// The SE(3) coupling's coefficients against 40-digit values (mpmath) of their closed forms,
    /// as [`jacobian_coefficients_are_accurate_at_every_angle`] (the first is checked there).
    #[test]
    fn coupling_coefficients_are_accurate_at_every_angle() {
        let cases = [
            (0.02, [0.04166611111507935, 0.008333174604497348]),
            (0.5, [0.04132099024596346, 0.008234642121237716]),
            (0.999, [0.04030498483217136, 0.007945436550374139]),
            (1.5, [0.03866413860102774, 0.007481207749095708]),
        ];
        for (t, want) in cases {
            let (_, b, c) = coupling_coefficients(t);
            // Measured above 1 rad: 7.2e-16 and 4.6e-16 of themselves at 1.5 rad.
            let bound = if t < 1.0 { 4.5e-16 } else { 2e-15 };
            for (g, w) in [b, c].iter().zip(want) {
                assert!((g - w).abs() <= bound * w, "at {t} rad: {g:e}, want {w:e}");
            }
        }
    }

    /// Whole turns come off exactly: 27.8 rad (the windmill's drive at 3 s) and 100000.1 rad
    /// against 25-digit values, within an ulp of the reduced angle (the plain
    /// `x - 2 pi m` is off by up to `ulp(x)`, 3.6e-15 rad and 7e-12 rad).
    #[test]
    fn reduce_angle_keeps_the_reduced_angles_precision() {
        let cases = [(27.8, 2.667258771281655), (1e5 + 0.1, -3.077349070292546)];
        for (x, want) in cases {
            let got = reduce_angle(x);
            assert!(
                (got - want).abs() <= 4.5e-16 * want.abs(),
                "{x}: {got:e}, want {want:e}"
            );
        }
        let (s, e) = two_sum(27.8, 1.16e-4);
        assert_eq!(s - 27.8, 1.16e-4 - e);
    }
}
