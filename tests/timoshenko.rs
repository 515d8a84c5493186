//! The natural frequencies of a uniform Timoshenko beam without rotary inertia (the beams' model
//! with `i2 = i3 = 0`), solved here as a boundary-value problem: the references of
//! `tests/beam_order.rs` and `tests/towers.rs`. Plain `f64` arithmetic, no `mbd`.
//!
//! In the lateral deflection `w`, the section rotation `psi`, the bending moment `M` and the
//! shear force `V` (positive as an end load in `+w`), with `m omega^2 w` the inertial load:
//! `w' = psi + V / GA`, `psi' = M / EI`, `M' = -V`, `V' = -m omega^2 w`. Scaled by the length
//! `L` and `b = beta L` (`beta^4 = m omega^2 / EI`), the state
//! `u = (w / L, psi / b, M L / (EI b^2), V L^2 / (EI b^3))` obeys `u' = b A u` on `[0, 1]` with
//! `A = [[0, 1, 0, g b^2], [0, 0, 1, 0], [0, 0, 0, -1], [-1, 0, 0, 0]]` and `g = EI / (GA L^2)`
//! the shear flexibility. The transfer matrix `exp(b A)` (scaling and squaring of the Taylor
//! series) carries the clamped root's two free unknowns (`M`, `V`) to the other end, whose two
//! conditions make a 2x2 determinant that vanishes at the natural frequencies (bisection).

/// `beta_n L` of the Euler-Bernoulli cantilever: the roots of `1 + cosh(x) cos(x) = 0`.
pub const CANTILEVER_EB: [f64; 4] = [
    1.875_104_068_711_961,
    4.694_091_132_974_175,
    7.854_757_438_237_613,
    10.995_540_734_875_467,
];

type M4 = [[f64; 4]; 4];

fn product(a: &M4, b: &M4) -> M4 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..4).map(|k| a[i][k] * b[k][j]).sum()))
}

/// `exp(b A)`: the transfer matrix of the scaled state over the beam.
pub fn transfer(b: f64, g: f64) -> M4 {
    let a: M4 = [
        [0.0, b, 0.0, g * b * b * b],
        [0.0, 0.0, b, 0.0],
        [0.0, 0.0, 0.0, -b],
        [-b, 0.0, 0.0, 0.0],
    ];
    let norm = (0..4)
        .map(|j| (0..4).map(|i| a[i][j].abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let squarings = if norm > 0.25 {
        (norm / 0.25).log2().ceil() as i32
    } else {
        0
    };
    let scale = 0.5f64.powi(squarings);
    let small: M4 = std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] * scale));
    let mut e: M4 = std::array::from_fn(|i| std::array::from_fn(|j| f64::from(u8::from(i == j))));
    let mut term = e;
    for k in 1..=24 {
        term = product(&term, &small);
        term.iter_mut().flatten().for_each(|x| *x /= k as f64);
        for (ei, ti) in e.iter_mut().zip(&term) {
            ei.iter_mut().zip(ti).for_each(|(x, t)| *x += t);
        }
    }
    for _ in 0..squarings {
        e = product(&e, &e);
    }
    e
}

/// The root of `f` in `[lo, hi]`, where it changes sign.
pub fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let flo = f(lo);
    assert!(
        flo * f(hi) < 0.0,
        "no sign change in [{lo}, {hi}]: {flo} and {}",
        f(hi)
    );
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let fm = f(mid);
        if fm == 0.0 {
            return mid;
        }
        if (fm > 0.0) == (flo > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// `beta_n L` of the n-th bending mode (n from 1) of a clamped-free beam of shear flexibility
/// `g`: `M = V = 0` at the free end. Shear lowers it below the Euler-Bernoulli root.
pub fn cantilever(n: usize, g: f64) -> f64 {
    let eb = CANTILEVER_EB[n - 1];
    let d = |b: f64| {
        let t = transfer(b, g);
        t[2][2] * t[3][3] - t[2][3] * t[3][2]
    };
    bisect(d, 0.9 * eb, eb * (1.0 + 1e-9))
}

/// `beta L` of the first mode of a beam clamped at its root and guided at its top (no rotation,
/// free to translate), carrying there a mass `mu` times the beam's: `psi = 0` and
/// `V = m_top omega^2 w`, that is `u4 = mu b u1`. `guess` is a nearby `beta L` (a Rayleigh
/// estimate).
pub fn guided_with_tip_mass(mu: f64, g: f64, guess: f64) -> f64 {
    let d = |b: f64| {
        let t = transfer(b, g);
        t[1][2] * (t[3][3] - mu * b * t[0][3]) - t[1][3] * (t[3][2] - mu * b * t[0][2])
    };
    bisect(d, 0.8 * guess, 1.05 * guess)
}

#[test]
fn the_shooting_reference_gives_the_euler_bernoulli_roots_without_shear() {
    // g = 0: 1 + cosh cos = 0, and the guided beam with a massive top tends to the Rayleigh
    // value of a spring 12 EI / L^3 and mass m_top + 13/35 m L: (beta L)^4 = 12 / (mu + 13/35).
    let mut worst = 0.0f64;
    for (n, eb) in CANTILEVER_EB.iter().enumerate() {
        let b = cantilever(n + 1, 0.0);
        worst = worst.max((b - eb).abs() / eb);
        assert!((1.0 + b.cosh() * b.cos()).abs() < 1e-9 * b.cosh(), "{n}");
    }
    crate::common::within(
        "shooting cantilever roots vs 1 + cosh cos = 0",
        worst,
        3e-13,
    ); // measured 1.0e-13
    let mu: f64 = 1e4;
    let rayleigh = (12.0 / (mu + 13.0 / 35.0)).powf(0.25);
    let b = guided_with_tip_mass(mu, 0.0, rayleigh);
    crate::common::within(
        "guided beam with a heavy top vs Rayleigh",
        (b - rayleigh).abs() / rayleigh,
        3.3e-11,
    ); // measured 1.1e-11
}
