//! The integrators' spectral properties on a linear undamped oscillator, against the
//! amplification matrix built here from the schemes' published definitions (Chung & Hulbert
//! 1993 for generalized-alpha, Hilber-Hughes-Taylor 1977 for HHT; THEORY §7.4, §7.5, §8.2).
//!
//! The oscillator is a rigid body on a prismatic joint with a spring, `x'' = -omega^2 x`, with
//! `h = 1 s` so that `omega h = omega`: the prismatic spring acts on the joint's displacement
//! exactly linearly, and the joint's five locked motions stay at exactly zero. The run is
//! therefore the scheme's linear recursion to round-off: its positions and velocities obey the
//! recurrence of the amplification matrix's characteristic polynomial. The roots of that
//! recurrence, fitted to the run by least squares, are the measured eigenvalues: their largest
//! modulus is the measured spectral radius (the decay per step of the slowest-decaying part),
//! and the principal pair's modulus and argument are the decay per step and the phase per step
//! of the oscillation (the period elongation is `omega h / phase - 1`).
//!
//! The reference is plain `f64` arithmetic (no `mbd`, no other crate): the 3x3 amplification
//! matrix of `(q, h v, h^2 a)`, its characteristic polynomial and the polynomial's roots.

use crate::common::{simulate_text, within, Trace};
use mbd::settings::{Method, Request};

// ---------------------------------------------------------------------------------------------
// The reference: the schemes' constants, the amplification matrix and its eigenvalues
// ---------------------------------------------------------------------------------------------

/// A complex number, as the roots need it.
#[derive(Clone, Copy, Debug)]
struct Root {
    re: f64,
    im: f64,
}

impl Root {
    fn modulus(self) -> f64 {
        self.re.hypot(self.im)
    }
    fn arg(self) -> f64 {
        self.im.atan2(self.re)
    }
}

/// The roots of `l^2 + b l + c`.
fn quadratic(b: f64, c: f64) -> [Root; 2] {
    let d = b * b - 4.0 * c;
    if d < 0.0 {
        let im = 0.5 * (-d).sqrt();
        [
            Root { re: -b / 2.0, im },
            Root {
                re: -b / 2.0,
                im: -im,
            },
        ]
    } else {
        // The larger root first, the other from the product (no cancellation).
        let big = -0.5 * (b + b.signum() * d.sqrt());
        let small = if big == 0.0 { 0.0 } else { c / big };
        [Root { re: big, im: 0.0 }, Root { re: small, im: 0.0 }]
    }
}

/// The roots of `l^3 + a l^2 + b l + c`: the real root by bisection polished by Newton, the
/// other two from the deflated quadratic.
fn cubic(a: f64, b: f64, c: f64) -> [Root; 3] {
    let p = |l: f64| ((l + a) * l + b) * l + c;
    let bound = 1.0 + a.abs().max(b.abs()).max(c.abs());
    let (mut lo, mut hi) = (-bound, bound);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if p(mid) <= 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let mut r = 0.5 * (lo + hi);
    for _ in 0..3 {
        let dp = (3.0 * r + 2.0 * a) * r + b;
        if dp != 0.0 {
            r -= p(r) / dp;
        }
    }
    let [q1, q2] = quadratic(a + r, b + r * (a + r));
    [Root { re: r, im: 0.0 }, q1, q2]
}

/// A Newmark-family scheme in the Chung-Hulbert form
/// `(1 - a_m) a_{n+1} + a_m a_n + omega^2 ((1 - a_f) q_{n+1} + a_f q_n) = 0`.
#[derive(Clone, Copy, Debug)]
struct Scheme {
    am: f64,
    af: f64,
    beta: f64,
    gamma: f64,
}

impl Scheme {
    /// Chung & Hulbert (1993): the constants from the spectral radius at infinity.
    fn generalized_alpha(rho: f64) -> Scheme {
        let am = (2.0 * rho - 1.0) / (rho + 1.0);
        let af = rho / (rho + 1.0);
        Scheme {
            am,
            af,
            beta: 0.25 * (1.0 - am + af).powi(2),
            gamma: 0.5 - am + af,
        }
    }

    /// Hilber, Hughes & Taylor (1977), alpha in [-1/3, 0]: the stiffness weighted by
    /// `1 + alpha` at `t_{n+1}` and `-alpha` at `t_n`, the inertia at `t_{n+1}`.
    fn hht(alpha: f64) -> Scheme {
        Scheme {
            am: 0.0,
            af: -alpha,
            beta: (1.0 - alpha).powi(2) / 4.0,
            gamma: 0.5 - alpha,
        }
    }

    /// The trapezoidal rule (FET on a linear problem, THEORY §8.2).
    fn trapezoidal() -> Scheme {
        Scheme::hht(0.0)
    }

    /// The amplification matrix `G` of `z = (q, h v, h^2 a)` at `w = omega h`:
    /// `L z_{n+1} = R z_n` from the two Newmark relations and the balance.
    fn amplification(&self, w: f64) -> [[f64; 3]; 3] {
        let Scheme {
            am,
            af,
            beta,
            gamma,
        } = *self;
        let w2 = w * w;
        let l = [
            [1.0, 0.0, -beta],
            [0.0, 1.0, -gamma],
            [(1.0 - af) * w2, 0.0, 1.0 - am],
        ];
        let r = [
            [1.0, 1.0, 0.5 - beta],
            [0.0, 1.0, 1.0 - gamma],
            [-af * w2, 0.0, -am],
        ];
        let li = inverse(l);
        std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| li[i][k] * r[k][j]).sum()))
    }

    /// The eigenvalues of the amplification matrix (the roots of its characteristic
    /// polynomial `l^3 - tr l^2 + m2 l - det`).
    fn eigenvalues(&self, w: f64) -> [Root; 3] {
        let g = self.amplification(w);
        let tr = g[0][0] + g[1][1] + g[2][2];
        let minor = |i: usize, j: usize| g[i][i] * g[j][j] - g[i][j] * g[j][i];
        let m2 = minor(0, 1) + minor(0, 2) + minor(1, 2);
        cubic(-tr, m2, -det(g))
    }

    /// Whether the scheme is the trapezoidal rule on a linear problem (`a_m = a_f`,
    /// `beta = 1/4`, `gamma = 1/2`): its third root is then absent from a consistent start.
    fn is_trapezoidal(&self) -> bool {
        (self.am - self.af).abs() < 1e-15
            && (self.beta - 0.25).abs() < 1e-15
            && (self.gamma - 0.5).abs() < 1e-15
    }
}

fn det(m: [[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

fn inverse(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let d = det(m);
    let c = |i: usize, j: usize| {
        let (r0, r1) = ((i + 1) % 3, (i + 2) % 3);
        let (c0, c1) = ((j + 1) % 3, (j + 2) % 3);
        m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
    };
    // The inverse is the transposed cofactor matrix over the determinant.
    std::array::from_fn(|i| std::array::from_fn(|j| c(j, i) / d))
}

/// The principal root (the one with the largest imaginary part) and the spectral radius.
fn principal_and_radius(roots: &[Root]) -> (Root, f64) {
    let principal = *roots
        .iter()
        .max_by(|a, b| a.im.total_cmp(&b.im))
        .expect("roots");
    let radius = roots.iter().map(|r| r.modulus()).fold(0.0, f64::max);
    (principal, radius)
}

// ---------------------------------------------------------------------------------------------
// The measurement: the recurrence of the run, fitted by least squares
// ---------------------------------------------------------------------------------------------

/// Least squares `min |A c - b|` by Householder QR, for a few columns.
fn least_squares(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let (m, n) = (a.len(), a[0].len());
    assert!(m >= n, "{m} equations for {n} unknowns");
    for k in 0..n {
        let norm = (k..m).map(|i| a[i][k] * a[i][k]).sum::<f64>().sqrt();
        let alpha = if a[k][k] > 0.0 { -norm } else { norm };
        let mut v: Vec<f64> = (k..m).map(|i| a[i][k]).collect();
        v[0] -= alpha;
        let vv: f64 = v.iter().map(|x| x * x).sum();
        if vv == 0.0 {
            continue;
        }
        let s: Vec<f64> = (k..n)
            .map(|j| 2.0 * (k..m).map(|i| v[i - k] * a[i][j]).sum::<f64>() / vv)
            .collect();
        for (row, vi) in a[k..].iter_mut().zip(&v) {
            row[k..]
                .iter_mut()
                .zip(&s)
                .for_each(|(x, sj)| *x -= sj * vi);
        }
        let s = 2.0 * (k..m).map(|i| v[i - k] * b[i]).sum::<f64>() / vv;
        (k..m).for_each(|i| b[i] -= s * v[i - k]);
    }
    let mut c = vec![0.0; n];
    for k in (0..n).rev() {
        c[k] = (b[k] - (k + 1..n).map(|j| a[k][j] * c[j]).sum::<f64>()) / a[k][k];
    }
    c
}

/// The roots of the recurrence `y_{n+p} = c_1 y_{n+p-1} + ... + c_p y_n` (p = 2 or 3) that the
/// sequences obey, fitted over their steps `0..=last`.
fn fitted_roots(seqs: &[Vec<f64>], order: usize, last: usize) -> Vec<Root> {
    let (mut rows, mut rhs) = (Vec::new(), Vec::new());
    for s in seqs {
        for n in 0..=last - order {
            rows.push((0..order).map(|j| s[n + order - 1 - j]).collect());
            rhs.push(s[n + order]);
        }
    }
    let c = least_squares(rows, rhs);
    match order {
        2 => quadratic(-c[0], -c[1]).to_vec(),
        _ => cubic(-c[0], -c[1], -c[2]).to_vec(),
    }
}

/// Position and velocity of the run, each scaled by its largest magnitude, and the last step
/// at which the motion is still above 1e-10 of its largest (below, round-off dominates).
fn sequences(tr: &Trace) -> (Vec<Vec<f64>>, usize) {
    let seqs: Vec<Vec<f64>> = ["x", "v"]
        .iter()
        .map(|c| {
            let s = tr.col(c);
            let top = s.iter().fold(0.0f64, |m, y| m.max(y.abs()));
            s.iter().map(|y| y / top).collect()
        })
        .collect();
    let last = (0..seqs[0].len())
        .filter(|&n| seqs[0][n].abs().max(seqs[1][n].abs()) > 1e-10)
        .max()
        .expect("motion");
    (seqs, last)
}

// ---------------------------------------------------------------------------------------------
// The runs
// ---------------------------------------------------------------------------------------------

/// The oscillator at `omega = w rad/s`, stepped at `h = 1 s` for `steps` steps by `solve`.
fn oscillator(w: f64, solve: &str, steps: usize) -> String {
    format!(
        "model oscillator \"A linear oscillator on a prismatic joint\"
ground earth
rigid b {{ mass = 1 kg, inertia = (1, 1, 1) kg*m^2, velocity = (1, 0, 0) m/s }}
joint slide = prismatic(earth, b) {{ axis = x, spring = {k:e} N/m }}
output x = slide.displacement, v = slide.speed
solve {solve} {{ dt = 1 s, until = {steps} s }}
",
        k = w * w
    )
}

fn run(text: &str, overrides: Request) -> Trace {
    simulate_text("oscillator.mbd", text, overrides).unwrap_or_else(|(_, m)| panic!("{m}"))
}

/// One scheme as the model's solve block names it, and its reference constants.
struct Case {
    solve: &'static str,
    scheme: Scheme,
    /// The closed-form spectral radius at infinite frequency.
    rho_inf: f64,
}

fn cases() -> Vec<Case> {
    let ga = |solve, rho| Case {
        solve,
        scheme: Scheme::generalized_alpha(rho),
        rho_inf: rho,
    };
    let hht = |solve, alpha: f64| Case {
        solve,
        scheme: Scheme::hht(alpha),
        rho_inf: (1.0 + alpha) / (1.0 - alpha),
    };
    vec![
        ga("generalized_alpha(rho_inf = 0)", 0.0),
        ga("generalized_alpha(rho_inf = 0.5)", 0.5),
        ga("generalized_alpha(rho_inf = 0.8)", 0.8),
        ga("generalized_alpha(rho_inf = 1)", 1.0),
        hht("hht(alpha = 0)", 0.0),
        hht("hht(alpha = -0.1)", -0.1),
        hht("hht(alpha = -0.3)", -0.3),
        Case {
            solve: "fet",
            scheme: Scheme::trapezoidal(),
            rho_inf: 1.0,
        },
    ]
}

/// The measured against the reference, for one scheme at one `omega h`.
struct Measured {
    radius: (f64, f64),
    decay: (f64, f64),
    phase: (f64, f64),
}

fn measure(case: &Case, w: f64) -> Measured {
    let reference = case.scheme.eigenvalues(w);
    let (p_ref, rho_ref) = principal_and_radius(&reference);
    // Enough steps for the motion to fall to 1e-12, at most 400.
    let steps = if rho_ref < 1.0 - 1e-12 {
        ((-12.0 * 10f64.ln() / rho_ref.ln()).ceil() as usize + 3).clamp(8, 400)
    } else {
        400
    };
    let tr = run(&oscillator(w, case.solve, steps), Request::default());
    let (seqs, last) = sequences(&tr);
    let order = if case.scheme.is_trapezoidal() { 2 } else { 3 };
    let fitted = fitted_roots(&seqs, order, last);
    let (p, rho) = principal_and_radius(&fitted);
    Measured {
        radius: (rho, rho_ref),
        decay: (p.modulus(), p_ref.modulus()),
        phase: (p.arg(), p_ref.arg()),
    }
}

#[test]
fn the_reference_amplification_matrices_have_the_published_asymptotes() {
    // The test's own reference against the closed forms: spectral radius rho_inf (HHT:
    // (1 + alpha)/(1 - alpha)) at omega h -> infinity, and the trapezoidal rule's roots
    // exp(+-2i atan(omega h / 2)) on the unit circle.
    // Generalized-alpha's three roots meet at -rho_inf at infinity (a triple root), so its
    // spectral radius approaches rho_inf as (omega h)^(-2/3): 1e-4 at 1e6 (rho_inf = 0); HHT's
    // as (omega h)^-2.
    let worst = cases()
        .iter()
        .map(|c| (principal_and_radius(&c.scheme.eigenvalues(1e6)).1 - c.rho_inf).abs())
        .fold(0.0, f64::max);
    within(
        "reference spectral radius at omega h = 1e6 vs rho_inf",
        worst,
        3e-4,
    ); // measured 1.0e-4
    let mut trapezoidal = 0.0f64;
    for w in [0.5, 2.0, 1e3] {
        let (p, rho) = principal_and_radius(&Scheme::trapezoidal().eigenvalues(w));
        let phase = (p.arg() - 2.0 * (w / 2.0).atan()).abs();
        trapezoidal = trapezoidal.max((rho - 1.0).abs()).max(phase);
    }
    within(
        "reference trapezoidal roots vs exp(+-2i atan(w/2))",
        trapezoidal,
        5e-14,
    ); // measured 1.8e-14
}

#[test]
fn every_integrator_has_the_spectral_radius_decay_and_phase_of_its_amplification_matrix() {
    let (mut radius, mut decay, mut phase) = (0.0f64, 0.0f64, 0.0f64);
    // |rho(1000) - rho_inf| of generalized-alpha, and of HHT and FET.
    let (mut asymptote_ga, mut asymptote_hht) = (0.0f64, 0.0f64);
    for case in cases() {
        for w in [0.5, 1.0, 2.0, 1e3] {
            let m = measure(&case, w);
            eprintln!(
                "{:34} w {w:6}: rho {:.12} (ref {:.12}), |l1| {:.12} (ref {:.12}), \
                 phase {:.12} (ref {:.12}), period elongation {:.4e}",
                case.solve,
                m.radius.0,
                m.radius.1,
                m.decay.0,
                m.decay.1,
                m.phase.0,
                m.phase.1,
                w / m.phase.0 - 1.0
            );
            radius = radius.max((m.radius.0 - m.radius.1).abs());
            decay = decay.max((m.decay.0 - m.decay.1).abs());
            phase = phase.max((m.phase.0 - m.phase.1).abs());
            if w == 1e3 {
                let off = (m.radius.0 - case.rho_inf).abs();
                if !case.solve.starts_with("generalized") {
                    asymptote_hht = asymptote_hht.max(off);
                } else {
                    asymptote_ga = asymptote_ga.max(off);
                }
            }
        }
    }
    within(
        "spectral radius, run vs amplification matrix",
        radius,
        1e-11,
    ); // measured 2.8e-12
    within("principal root modulus, run vs matrix", decay, 1e-11); // measured 2.8e-12
    within("principal root phase (rad), run vs matrix", phase, 1.5e-11); // measured 4.6e-12

    // At omega h = 1000 the spectral radius is near its limit: generalized-alpha's within
    // O((omega h)^(-2/3)) (largest at rho_inf = 0: rho = 0.0101), HHT's within O((omega h)^-2)
    // of (1 + alpha)/(1 - alpha) (largest at alpha = -0.3).
    within(
        "generalized-alpha rho at omega h = 1e3 vs rho_inf",
        asymptote_ga,
        3e-2,
    ); // measured 1.0e-2
    within(
        "HHT rho at omega h = 1e3 vs (1+a)/(1-a)",
        asymptote_hht,
        4.5e-4,
    ); // measured 1.5e-4
}

#[test]
fn the_command_line_s_rho_inf_and_alpha_override_the_solve_block() {
    // `--integrator generalized-alpha --rho-inf 0.5` on a model whose block says HHT: the run
    // is the one the block `generalized_alpha(rho_inf = 0.5)` gives, bit for bit; likewise
    // `--alpha -0.3` over `hht(alpha = -0.1)`.
    let (w, steps) = (2.0, 40);
    let from_block = run(
        &oscillator(w, "generalized_alpha(rho_inf = 0.5)", steps),
        Request::default(),
    );
    let from_flags = run(
        &oscillator(w, "hht", steps),
        Request {
            method: Some(Method::GeneralizedAlpha),
            rho_inf: Some(0.5),
            ..Request::default()
        },
    );
    assert_eq!(from_block.rows, from_flags.rows);
    let hht_block = run(
        &oscillator(w, "hht(alpha = -0.3)", steps),
        Request::default(),
    );
    let hht_flag = run(
        &oscillator(w, "hht(alpha = -0.1)", steps),
        Request {
            alpha: Some(-0.3),
            ..Request::default()
        },
    );
    assert_eq!(hht_block.rows, hht_flag.rows);
    assert_ne!(hht_block.rows, from_block.rows);
}
