//! The windmill's linearized multiblade equations (THEORY §9.1), independent of mbd: shared by
//! the stability tests and by `examples/windmill_mbc.rs`, which writes the reference curve of
//! the stability chart in docs/charts.
//!
//! With `q = (x, zeta_1c, zeta_1s)`, constant coefficients for `N >= 3` blades:
//! `M x'' + kT x - (N/2) Sb zeta_1s'' = 0`,
//! `Ib (zeta_1c'' + 2 Omega zeta_1s' + (nu^2 - Omega^2) zeta_1c) = 0`,
//! `Ib (zeta_1s'' - 2 Omega zeta_1c' + (nu^2 - Omega^2) zeta_1s) - Sb x'' = 0`,
//! `nu^2 = (k_zeta + e Sb Omega^2) / Ib`. The roots of `det(M s^2 + G s + K) = 0` by the
//! Durand-Kerner iteration.

use nalgebra::Complex;

type C = Complex<f64>;

fn det3(a: &[[C; 3]; 3]) -> C {
    a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
}

/// The roots of `det(M s^2 + G s + K) = 0` (degree 6) by the Durand-Kerner iteration on the
/// monic polynomial `det(...) / det(M)`.
fn quadratic_roots(m: [[f64; 3]; 3], g: [[f64; 3]; 3], k: [[f64; 3]; 3]) -> Vec<C> {
    let at = |s: C| -> C {
        let mut d = [[C::new(0.0, 0.0); 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                d[i][j] = s * s * m[i][j] + s * g[i][j] + k[i][j];
            }
        }
        det3(&d)
    };
    let lead = det3(&m.map(|r| r.map(|x| C::new(x, 0.0))));
    let p = |s: C| at(s) / lead;
    let seed = C::new(0.4, 0.9);
    let mut z: Vec<C> = (0..6).map(|i| seed.powi(i) * 10.0).collect();
    for _ in 0..100_000 {
        let mut change = 0.0f64;
        for i in 0..6 {
            let mut den = C::new(1.0, 0.0);
            for j in 0..6 {
                if j != i {
                    den *= z[i] - z[j];
                }
            }
            let step = p(z[i]) / den;
            z[i] -= step;
            change = change.max(step.norm());
        }
        if change < 1e-13 {
            break;
        }
    }
    z
}
/// The windmill of P5 with `blades` blades: `(Re s, Im s)` of the six roots at `Omega_bar`.
pub fn mbc_roots(blades: usize, omega_bar: f64) -> Vec<(f64, f64)> {
    let (mb, l, e, k_zeta, ma, omega_t) = (20.0, 2.7, 0.3, 14.0, 100.0, 9.26);
    let n = blades as f64;
    let (sb, ib) = (mb * l / 2.0, mb * l * l / 3.0);
    let m = ma + n * mb;
    let kt = m * omega_t * omega_t;
    let w = omega_bar * omega_t;
    let nu2 = (k_zeta + e * sb * w * w) / ib;
    let mass = [[m, 0.0, -n / 2.0 * sb], [0.0, ib, 0.0], [-sb, 0.0, ib]];
    let gyro = [
        [0.0; 3],
        [0.0, 0.0, 2.0 * w * ib],
        [0.0, -2.0 * w * ib, 0.0],
    ];
    let s2 = ib * (nu2 - w * w);
    let stiff = [[kt, 0.0, 0.0], [0.0, s2, 0.0], [0.0, 0.0, s2]];
    quadratic_roots(mass, gyro, stiff)
        .iter()
        .map(|z| (z.re, z.im))
        .collect()
}

/// The largest real part of the roots.
pub fn mbc_growth(blades: usize, omega_bar: f64) -> f64 {
    mbc_roots(blades, omega_bar)
        .iter()
        .map(|r| r.0)
        .fold(f64::NEG_INFINITY, f64::max)
}

/// The edge of the unstable band between `lo` and `hi` (one stable, one not), by bisection
/// to 1e-10.
pub fn mbc_edge(blades: usize, mut lo: f64, mut hi: f64) -> f64 {
    let unstable = |w: f64| mbc_growth(blades, w) > 1e-9;
    let lo_unstable = unstable(lo);
    assert_ne!(lo_unstable, unstable(hi), "no edge between {lo} and {hi}");
    while (hi - lo).abs() > 1e-10 {
        let mid = 0.5 * (lo + hi);
        if unstable(mid) == lo_unstable {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}
