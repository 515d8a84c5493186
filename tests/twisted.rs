//! Pretwisted and tapered beams (issue 23, item 1). A twist distribution given at stations,
//! linear between, turns each node's section frame; the element subtracts the reference twist
//! rate, so the twist is stress-free and the bending stiffness turns along the span: validated
//! against a separate finite-element model written here, an Euler-Bernoulli cantilever bending
//! in two planes (Hermite cubic elements, its section stiffness turned by the local twist,
//! `D(x) = R(theta) diag(EI2, EI3) R(theta)^T` on the curvatures about y and z). Sections
//! given at stations, linear between, are evaluated at every quadrature point: validated
//! against the Euler-Bernoulli cantilever's closed forms. A reference line through points
//! (the smooth curve through them, or a polyline): against Castigliano's quarter circle.

use crate::common::{simulate_text_with, within};
use mbd::settings::Request;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::PI;

/// A cantilever along +x (length 1 m), clamped at the root, its tip pushed by `P` along +z
/// in one load step; the twist goes through the stations given (degrees).
fn model(stations: &str) -> String {
    format!(
        r#"model twisted "A pretwisted cantilever under a tip force"
param P = 1e-3 N
param elements = 8
param GJ = 50 N*m^2
section s {{
    EA = 1e12 N, GA2 = 1e12 N, GA3 = 1e12 N
    GJ = GJ, EI2 = 10 N*m^2, EI3 = 100 N*m^2
    mass_per_length = 1 kg/m
}}
ground earth
beam b {{ from = (0, 0, 0) m, to = (1, 0, 0) m, section = s, elements = elements, order = 4,
         twist = {stations} }}
joint clamp = fixed(earth, b.start)
force push on b.end = (0, 0, P * t / 1 s)
output y = b.end.position.y, z = b.end.position.z
solve static {{ steps = 1, until = 1 s }}
"#
    )
}

/// The separate model: `n` Hermite elements of the Euler-Bernoulli cantilever (unknowns per
/// node `v, v', w, w'`: displacements along y and z and their slopes), the tip force `p`
/// along z; the twist `theta(x)` turns the principal axes (axis 2 = cos y + sin z). Returns
/// the tip's (v, w).
fn hermite(n: usize, p: f64, (ei2, ei3): (f64, f64), theta: &dyn Fn(f64) -> f64) -> (f64, f64) {
    let len = 1.0;
    let h = len / n as f64;
    let size = 4 * (n + 1);
    let mut k = DMatrix::<f64>::zeros(size, size);
    // 4-point Gauss on each element.
    let (xg, wg) = (
        [
            -0.861_136_311_594_052_6,
            -0.339_981_043_584_856_3,
            0.339_981_043_584_856_3,
            0.861_136_311_594_052_6,
        ],
        [
            0.347_854_845_137_453_9,
            0.652_145_154_862_546_1,
            0.652_145_154_862_546_1,
            0.347_854_845_137_453_9,
        ],
    );
    for e in 0..n {
        for (xi, w) in xg.iter().zip(wg) {
            let x = (e as f64 + (xi + 1.0) / 2.0) * h;
            // Second derivatives of the Hermite functions (value, slope at each end) in x.
            let d2 = [
                (6.0 * xi) / (h * h),
                (3.0 * xi - 1.0) / h,
                -(6.0 * xi) / (h * h),
                (3.0 * xi + 1.0) / h,
            ];
            let (c, s) = (theta(x).cos(), theta(x).sin());
            // Curvatures: about y, -w''; about z, v''. D in (y, z) from the principal axes.
            let d = [
                [ei2 * c * c + ei3 * s * s, (ei2 - ei3) * c * s],
                [(ei2 - ei3) * c * s, ei2 * s * s + ei3 * c * c],
            ];
            // Row of the curvature about y (w dofs, minus) and about z (v dofs).
            let mut b = [[0.0; 8]; 2];
            for a in 0..2 {
                for q in 0..2 {
                    let local = 2 * a + q; // end a, value or slope
                    b[0][4 * a + 2 + q] = -d2[local];
                    b[1][4 * a + q] = d2[local];
                }
            }
            let dofs: Vec<usize> = (0..8).map(|l| 4 * e + l).collect();
            for (i, &gi) in dofs.iter().enumerate() {
                for (j, &gj) in dofs.iter().enumerate() {
                    let mut v = 0.0;
                    for r in 0..2 {
                        for t in 0..2 {
                            v += b[r][i] * d[r][t] * b[t][j];
                        }
                    }
                    k[(gi, gj)] += v * w * h / 2.0;
                }
            }
        }
    }
    // Clamp the root (its four unknowns), load the tip's w.
    let free: Vec<usize> = (4..size).collect();
    let kf = DMatrix::from_fn(free.len(), free.len(), |i, j| k[(free[i], free[j])]);
    let mut f = DVector::<f64>::zeros(free.len());
    f[size - 2 - 4] = p;
    let u = kf.lu().solve(&f).expect("the clamped stiffness is regular");
    (u[size - 4 - 4], u[size - 2 - 4])
}

/// Twist stations in degrees through arc lengths in metres, as the model writes them (one
/// station: the constant angle).
fn stations(points: &[(f64, f64)]) -> String {
    if let [(_, a)] = points {
        return format!("{a} deg");
    }
    let rows: Vec<String> = points
        .iter()
        .map(|(s, a)| format!("({s} m, {a} deg)"))
        .collect();
    format!("({})", rows.join(", "))
}

/// Linear interpolation through the stations, held beyond them (radians).
fn interpolate(points: &[(f64, f64)], x: f64) -> f64 {
    let deg = if x <= points[0].0 {
        points[0].1
    } else if x >= points[points.len() - 1].0 {
        points[points.len() - 1].1
    } else {
        let w = points.windows(2).find(|w| x <= w[1].0).expect("inside");
        w[0].1 + (x - w[0].0) / (w[1].0 - w[0].0) * (w[1].1 - w[0].1)
    };
    deg * PI / 180.0
}

/// The beam's tip `(y, z)` with `elements` cubic elements and the twist through `points`.
fn tip(points: &[(f64, f64)], elements: usize) -> (f64, f64) {
    let text = model(&stations(points));
    let set = format!("elements={elements}");
    let t = simulate_text_with("twisted.mbd", &text, &[&set], Request::default())
        .map_err(|(_, m)| m)
        .expect("the static run");
    let last = |c: &str| *t.col(c).last().expect("row");
    (last("y"), last("z"))
}

/// A quarter turn of twist over the span couples the planes: the tip pushed along z moves
/// along y by 0.30 of its motion (0.09 for a twist that turns back at mid-span, stations at 0,
/// 0.5 and 1 m). The beam of cubic elements against the separate model (64 Hermite elements,
/// itself 1e-8 from its limit), the tip's distance relative to its motion: measured, for 1,
/// 2, 4, 8 elements, 1.6e-3, 1.5e-5, 2.0e-7, 2.6e-8 (quarter turn) and 2.2e-2, 1.1e-4,
/// 1.2e-6, 1.9e-8 (turning back): order 6.2 and 6.5 from 2 to 4 elements (the cubic
/// element's tip converges at order 6, as `tests/beam_order.rs` finds untwisted), down to the
/// separate model's own error at 8.
#[test]
fn a_pretwisted_cantilever_bends_as_its_turning_stiffness_says() {
    let p = 1e-3;
    for (points, coupling) in [
        (vec![(0.0, 0.0), (1.0, 90.0)], 0.25),
        (vec![(0.0, 10.0), (0.5, -30.0), (1.0, 45.0)], 0.08),
    ] {
        let (v, w) = hermite(64, p, (10.0, 100.0), &|x| interpolate(&points, x));
        let size = (v * v + w * w).sqrt();
        assert!(
            v.abs() > coupling * size,
            "the twist couples the planes: {v} of {size}"
        );
        let errors: Vec<f64> = [2, 4, 8]
            .iter()
            .map(|&n| {
                let (y, z) = tip(&points, n);
                ((y - v).powi(2) + (z - w).powi(2)).sqrt() / size
            })
            .collect();
        within(
            &format!(
                "pretwisted cantilever {points:?}, 8 elements: tip against the separate model"
            ),
            errors[2],
            8e-8,
        );
        let order = (errors[0] / errors[1]).log2();
        assert!(
            (5.5..7.5).contains(&order),
            "{points:?}: order {order} from 2 to 4 elements ({errors:?})"
        );
    }
    // Untwisted, the tip moves along z alone, by P L^3 / (3 EI2) (1.1e-9 relative).
    let (y, z) = tip(&[(0.0, 0.0)], 4);
    assert_eq!(y, 0.0);
    within(
        "untwisted cantilever: tip against P L^3 / (3 EI2)",
        (z - p / 30.0).abs() / (p / 30.0),
        4e-9,
    );
}

/// A tapered cantilever along +x (length 1 m): sections `root` at 0 and `tip` at 1 m, linear
/// between; pushed at its tip along +z by `P`, or weighed by `g` along -z, in one load step.
fn tapered(elements: usize, load: &str) -> f64 {
    let text = format!(
        r#"model tapered "A tapered cantilever"
section root {{
    EA = 1e12 N, GA2 = 1e12 N, GA3 = 1e12 N
    GJ = 50 N*m^2, EI2 = 20 N*m^2, EI3 = 100 N*m^2
    mass_per_length = 3 kg/m
}}
section tip {{
    EA = 1e12 N, GA2 = 1e12 N, GA3 = 1e12 N
    GJ = 50 N*m^2, EI2 = 5 N*m^2, EI3 = 100 N*m^2
    mass_per_length = 1 kg/m
}}
{load}
ground earth
beam b {{ from = (0, 0, 0) m, to = (1, 0, 0) m, section = ((0 m, root), (1 m, tip)),
         elements = {elements}, order = 4 }}
joint clamp = fixed(earth, b.start)
output z = b.end.position.z
solve static {{ steps = 1, until = 1 s }}
"#
    );
    let t = simulate_text_with("tapered.mbd", &text, &[], Request::default())
        .map_err(|(_, m)| m)
        .expect("the static run");
    *t.col("z").last().expect("row")
}

/// A section varying along the span (stations, linear between) against the Euler-Bernoulli
/// cantilever: a tip force on a bending stiffness `EI(x) = a + b x` deflects the tip by
/// `P / b^3 (c^2 ln(c / a) - 2 c (c - a) + (c^2 - a^2) / 2)`, `c = a + b L` (closed form); its
/// own weight, the mass per length linear too, by `int M(x) (L - x) / EI(x) dx` (Simpson's rule,
/// 2,000 intervals). Measured, relative, for 2, 4, 8 cubic elements: 6.0e-5, 2.1e-6, 4.9e-8
/// (force) and 1.4e-5, 5.2e-7, 1.2e-8 (weight): order 5.5 from 4 to 8 elements.
#[test]
fn a_tapered_cantilever_bends_as_its_varying_section_says() {
    let p = 1e-3;
    let (a, b, l) = (20.0f64, -15.0f64, 1.0f64);
    let c = a + b * l;
    let exact = p / b.powi(3) * (c * c * (c / a).ln() - 2.0 * c * (c - a) + (c * c - a * a) / 2.0);
    let force = "force push on b.end = (0, 0, 1e-3 N * t / 1 s)";
    let errors: Vec<f64> = [2, 4, 8]
        .iter()
        .map(|&n| (tapered(n, force) - exact).abs() / exact)
        .collect();
    // The weight: m(x) = 3 - 2 x kg/m under g = 1e-4 m/s^2 along -z.
    let g = 1e-4;
    let moment = |x: f64| {
        g * (3.0 * (l - x).powi(2) / 2.0
            - 2.0 * (l.powi(3) / 3.0 - x * l * l / 2.0 + x.powi(3) / 6.0))
    };
    let intervals = 2000;
    let h = l / intervals as f64;
    let weight: f64 = (0..=intervals)
        .map(|k| {
            let x = k as f64 * h;
            let w = if k == 0 || k == intervals {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * moment(x) * (l - x) / (a + b * x)
        })
        .sum::<f64>()
        * h
        / 3.0;
    let gravity = "gravity = (0, 0, -1e-4) m/s^2";
    let werrors: Vec<f64> = [2, 4, 8]
        .iter()
        .map(|&n| (tapered(n, gravity) + weight).abs() / weight)
        .collect();
    for (what, e, bound) in [("tip force", &errors, 1.5e-7), ("weight", &werrors, 3.5e-8)] {
        within(
            &format!("tapered cantilever, {what}: tip against the closed form, 8 elements"),
            e[2],
            bound,
        );
        let order = (e[1] / e[2]).log2();
        assert!(
            (4.5..6.5).contains(&order),
            "{what}: order {order} from 4 to 8 elements ({e:?})"
        );
    }
}

/// The part of a response linear in the load `p`: `2 d(p) - d(2 p) / 2` cancels the part of
/// second order.
fn linear(run: impl Fn(f64) -> (f64, f64), p: f64) -> (f64, f64) {
    let ((a1, b1), (a2, b2)) = (run(p), run(2.0 * p));
    (2.0 * a1 - a2 / 2.0, 2.0 * b1 - b2 / 2.0)
}

/// A quarter circle of radius 1 m in the xy plane, clamped at (1, 0, 0), its tip at (0, 1, 0)
/// pushed along +x by `P` in one load step; the reference line through `count` points of
/// the circle (`polyline`: the flag, else the smooth curve), `elements` cubic elements.
fn quarter_circle(count: usize, elements: usize, flag: &str, p: f64) -> (f64, f64) {
    let points: Vec<String> = (0..count)
        .map(|k| {
            let a = std::f64::consts::FRAC_PI_2 * k as f64 / (count - 1) as f64;
            format!("({}, {}, 0) m", a.cos(), a.sin())
        })
        .collect();
    let text = format!(
        r#"model arc "A quarter-circle cantilever"
section s {{
    EA = 1e12 N, GA2 = 1e12 N, GA3 = 1e12 N
    GJ = 50 N*m^2, EI2 = 10 N*m^2, EI3 = 10 N*m^2
    mass_per_length = 1 kg/m
}}
ground earth
beam b {flag} {{ points = ({}), section = s, elements = {elements}, order = 4 }}
joint clamp = fixed(earth @ (1, 0, 0) m, b.start)
force push on b.end = ({p} N * t / 1 s, 0, 0)
output x = b.end.position.x, y = b.end.position.y
solve static {{ steps = 1, until = 1 s }}
"#,
        points.join(", ")
    );
    let t = simulate_text_with("arc.mbd", &text, &[], Request::default())
        .map_err(|(_, m)| m)
        .expect("the static run");
    let last = |c: &str| *t.col(c).last().expect("row");
    (last("x"), last("y") - 1.0)
}

/// A curved beam (issue 23, item 1) against Castigliano's closed form for the quarter-circle
/// cantilever (inextensible, shear-rigid): a tip force `P` along the clamped end's tangent
/// moves the tip by `(3 pi / 4 - 2) P R^3 / EI` along it and `P R^3 / (2 EI)` across. The
/// reference line is the smooth curve through 33 points of the circle (the not-a-knot
/// spline); the load's second-order part is cancelled (a curved beam's first nonlinear term
/// is `O(d / R)`, 8.5e-5 of the motion at `P` = 1e-3 N). Measured, relative to the tip's
/// motion, for 2, 4, 8 cubic elements: 5.7e-5, 3.1e-6, 1.8e-7, order 4.2 (through 9 points
/// the spline's own distance from the circle leaves 1.3e-5). A `polyline` through collinear
/// points is the straight cantilever: `P L^3 / (3 EI)` (3.0e-11).
#[test]
fn a_curved_cantilever_bends_as_castigliano_says() {
    let (p, r, ei): (f64, f64, f64) = (1e-5, 1.0, 10.0);
    let (ex, ey) = (
        (3.0 * PI / 4.0 - 2.0) * p * r.powi(3) / ei,
        p * r.powi(3) / (2.0 * ei),
    );
    let size = ex.hypot(ey);
    let errors: Vec<f64> = [2, 4, 8]
        .iter()
        .map(|&n| {
            let (x, y) = linear(|load| quarter_circle(33, n, "", load), p);
            (x - ex).hypot(y - ey) / size
        })
        .collect();
    within(
        "quarter-circle cantilever, 8 elements: tip against Castigliano",
        errors[2],
        5e-7,
    );
    for k in 0..2 {
        let order = (errors[k] / errors[k + 1]).log2();
        assert!((3.5..5.0).contains(&order), "order {order} ({errors:?})");
    }
    // Collinear points of a polyline: the straight cantilever, bent by a tip force along z.
    let text = r#"model line "A straight polyline"
section s {
    EA = 1e12 N, GA2 = 1e12 N, GA3 = 1e12 N
    GJ = 50 N*m^2, EI2 = 10 N*m^2, EI3 = 10 N*m^2
    mass_per_length = 1 kg/m
}
ground earth
beam b polyline { points = ((0, 0, 0) m, (0.3, 0, 0) m, (1, 0, 0) m), section = s,
                  elements = 3, order = 4 }
joint clamp = fixed(earth, b.start)
force push on b.end = (0, 0, 1e-5 N * t / 1 s)
output z = b.end.position.z
solve static { steps = 1, until = 1 s }
"#;
    let t = simulate_text_with("line.mbd", text, &[], Request::default())
        .map_err(|(_, m)| m)
        .expect("the static run");
    let z = *t.col("z").last().expect("row");
    let exact = 1e-5 / (3.0 * ei);
    within(
        "straight polyline: tip against P L^3 / (3 EI)",
        (z - exact).abs() / exact,
        1e-10,
    );
}

/// A straight cantilever along +x (1 m) whose section has `offsets` (e.g.
/// `tension_offset3 = 0.05 m`), loaded at its tip (reference line) by `force` times `scale`;
/// its tip's z and rotation about x.
fn offset_section(offsets: &str, force: &str, scale: f64) -> (f64, f64) {
    let text = format!(
        r#"model offsets "A cantilever with offset tension and shear centres"
param f = {scale} N
section s {{
    EA = 1e4 N, GA2 = 1e3 N, GA3 = 1e3 N, GJ = 5 N*m^2, EI2 = 10 N*m^2, EI3 = 10 N*m^2
    {offsets}
    mass_per_length = 1 kg/m
}}
ground earth
beam b {{ from = (0, 0, 0) m, to = (1, 0, 0) m, section = s, elements = 4, order = 4 }}
joint clamp = fixed(earth, b.start)
force push on b.end = {force}
output z = b.end.position.z, twist = b.end.crv.c1
solve static {{ steps = 1, until = 1 s }}
"#
    );
    let t = simulate_text_with("offsets.mbd", &text, &[], Request::default())
        .map_err(|(_, m)| m)
        .expect("the static run");
    let last = |c: &str| *t.col(c).last().expect("row");
    (last("z"), last("twist"))
}

/// Section centres (issue 23, item 2) against statics: pulled along its reference line, a
/// beam whose tension centre sits `t3` above it bends as under the moment `F t3`, the tip
/// rising by `F t3 L^2 / (2 EI2)`; pushed across at its reference line, a beam whose shear
/// centre sits `c2` aside twists by `-c2 F L / GJ`. Both linear parts (the load's second
/// order cancelled, `2 d(F) - d(2 F) / 2`). Measured: 3.5e-9 and 1.7e-9 relative.
#[test]
fn offset_tension_and_shear_centres_bend_and_twist_as_statics_says() {
    let f = 1e-3;
    let (z, _) = linear(
        |load| offset_section("tension_offset3 = 0.05 m", "(f * t / 1 s, 0, 0)", load),
        f,
    );
    let rise = f * 0.05 / (2.0 * 10.0);
    within(
        "tension centre 0.05 m above the reference line: tip rise against F t3 L^2 / (2 EI2)",
        (z - rise).abs() / rise,
        1e-8,
    );
    let (_, twist) = linear(
        |load| offset_section("shear_offset2 = 0.04 m", "(0, 0, f * t / 1 s)", load),
        f,
    );
    let expected = -0.04 * f / 5.0;
    within(
        "shear centre 0.04 m aside: tip twist against -c2 F L / GJ",
        (twist - expected).abs() / expected.abs(),
        5e-9,
    );
}
