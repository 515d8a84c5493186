//! Mesh convergence of the 2-, 3- and 4-node (linear, quadratic, cubic) beam elements on the
//! cantilever of `models/cantilever.mbd` (L = 1 m, EI = 100 N*m^2, GA = 1e7 N, 1 kg/m):
//! the tip deflection under a small tip force against the Timoshenko closed form, the roll-up
//! under a tip moment against the exact arc, and the bending frequencies against the Timoshenko
//! beam's, solved in `tests/timoshenko.rs`. The measured orders are 2 (p - 1) for p-node
//! elements: 2, 4, 6.

use crate::common::{read, simulate, within};
use crate::timoshenko;
use mbd::settings::Request;
use std::f64::consts::PI;

const MODEL: &str = "models/cantilever.mbd";
const EI: f64 = 100.0;
const GA: f64 = 1e7;

fn last(sets: &[String], column: &str) -> f64 {
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    *simulate(MODEL, &sets, Request::default())
        .col(column)
        .last()
        .expect("rows")
}

fn mesh(order: usize, elements: usize) -> Vec<String> {
    vec![format!("order={order}"), format!("elements={elements}")]
}

fn sci(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{x:.3e}")).collect();
    items.join(", ")
}

fn order_between(e_coarse: f64, e_fine: f64) -> f64 {
    (e_coarse / e_fine).log2()
}

#[test]
fn quadratic_and_cubic_elements_give_the_exact_tip_deflection_and_linear_ones_lose_1_over_4n2() {
    // P L^3 / (3 EI) + P L / GA for a tip force (linear moment): quadratic and cubic elements
    // with reduced integration are exact at the nodes. A linear element with one-point shear
    // integration is exact for a shear stiffness lowered by le^2 / (12 EI): n of them lose
    // P L^3 / (12 EI n^2). P = 1 mN: the geometric stiffening is ~(P L^2 / EI)^2 = 1e-10.
    let p = 1e-3;
    let exact = p / (3.0 * EI) + p / GA;
    let mut higher = 0.0f64;
    for order in [3, 4] {
        for n in [1, 2, 4] {
            let mut sets = mesh(order, n);
            sets.push(format!("P={p}"));
            let tip = -last(&sets, "z");
            higher = higher.max((tip - exact).abs() / exact);
        }
    }
    within(
        "3- and 4-node tip deflection vs Timoshenko",
        higher,
        3.5e-11,
    ); // measured 1.2e-11
    let mut linear = 0.0f64;
    let mut errors = Vec::new();
    for n in [1, 2, 4, 8] {
        let mut sets = mesh(2, n);
        sets.push(format!("P={p}"));
        let tip = -last(&sets, "z");
        let discrete = exact - p / (12.0 * EI * (n * n) as f64);
        linear = linear.max((tip - discrete).abs() / exact);
        errors.push((exact - tip) / exact);
    }
    within("2-node tip deflection vs its closed form", linear, 3.5e-11); // measured 1.1e-11
    let worst_order = errors
        .windows(2)
        .map(|w| (order_between(w[0], w[1]) - 2.0).abs())
        .fold(0.0, f64::max);
    within("2-node tip deflection order - 2", worst_order, 1e-8); // measured 3.2e-9
}

#[test]
fn the_roll_up_into_a_quarter_circle_converges_at_orders_2_4_6() {
    // A tip moment M = (pi/2) EI / L bends the beam into a quarter circle: the tip at
    // (sin(kL), 1 - cos(kL)) / k, k = pi / (2 L). Ten load steps, 2, 4 and 8 elements.
    let k = PI / 2.0;
    let m = k * EI;
    let (xe, ye) = (k.sin() / k, (1.0 - k.cos()) / k);
    let mut finest = Vec::new();
    for (order, expected) in [(2, 2.0), (3, 4.0), (4, 6.0)] {
        let errors: Vec<f64> = [2, 4, 8]
            .iter()
            .map(|&n| {
                let mut sets = mesh(order, n);
                sets.push(format!("M={m}"));
                let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
                let t = simulate(MODEL, &sets, Request::default());
                let (x, y) = (t.col("x"), t.col("y"));
                let (x, y) = (x[x.len() - 1], y[y.len() - 1]);
                (x - xe).hypot(y - ye)
            })
            .collect();
        let orders = [
            order_between(errors[0], errors[1]),
            order_between(errors[1], errors[2]),
        ];
        eprintln!(
            "roll-up, {order}-node elements: errors {}, orders {orders:.3?}",
            sci(&errors)
        );
        finest.push((order, expected, orders[1], errors[2]));
    }
    // Measured orders (4 -> 8 elements): 2.010, 4.005, 6.181; tip errors at 8 elements 1.5e-3,
    // 7.0e-7, 9.6e-12 m.
    within(
        "roll-up 2-node order - 2",
        (finest[0].2 - finest[0].1).abs(),
        0.03,
    ); // measured 0.010
    within(
        "roll-up 3-node order - 4",
        (finest[1].2 - finest[1].1).abs(),
        0.015,
    ); // measured 0.005
    within(
        "roll-up 4-node order - 6",
        (finest[2].2 - finest[2].1).abs(),
        0.5,
    ); // measured 0.18
    within("roll-up 4-node tip error, 8 elements", finest[2].3, 3e-11); // measured 9.6e-12
}

fn bending_omegas(order: usize, elements: usize) -> Vec<f64> {
    let c = match mbd::compile(
        MODEL,
        &read(MODEL),
        &mesh(order, elements),
        Request::default(),
    ) {
        Ok(c) => c,
        Err(f) => panic!("{:?}", f.diagnostics),
    };
    let m = mbd::modes(&c, false).unwrap_or_else(|d| panic!("{}", d.message));
    // EI2 = EI3: the bending modes come in equal pairs; one of each.
    m.modes.iter().map(|x| x.omega()).step_by(2).collect()
}

#[test]
fn bending_frequencies_converge_at_orders_2_4_6_to_the_timoshenko_beam() {
    // The second bending mode (beta L = 4.694 without shear; g = EI / (GA L^2) = 1e-5 lowers
    // it by 1.6e-4), for meshes where it is resolved and round-off (1e-9) is far below. (The
    // meshes avoid those on which the eigenvalue solver is slow: with no rotary inertia half
    // of the pencil's eigenvalues are infinite, and the QZ iteration takes from 0.01 s to 47 s
    // depending on the mesh, e.g. 47 s for 4 cubic elements, 22 s for 10 linear ones.)
    let g = EI / (GA * 1.0);
    let b = timoshenko::cantilever(2, g);
    let exact = b * b * (EI / 1.0).sqrt();
    let mut lines = Vec::new();
    for (order, meshes, expected) in [
        (2, [6, 12, 24], 2.0),
        (3, [5, 10, 20], 4.0),
        (4, [2, 8, 12], 6.0),
    ] {
        let errors: Vec<f64> = meshes
            .iter()
            .map(|&n| (bending_omegas(order, n)[1] - exact) / exact)
            .collect();
        assert!(errors.iter().all(|e| *e > 0.0), "{errors:?}: from above");
        let rate = |i: usize| {
            (errors[i] / errors[i + 1]).ln() / (meshes[i + 1] as f64 / meshes[i] as f64).ln()
        };
        let orders = [rate(0), rate(1)];
        eprintln!(
            "mode 2, {order}-node elements {meshes:?}: errors {}, orders {orders:.3?}",
            sci(&errors)
        );
        lines.push((expected, orders[1], errors[2]));
    }
    // Measured orders on the finest pair: 2.010, 3.990, 5.980.
    let off = |i: usize| (lines[i].1 - lines[i].0).abs();
    within("mode 2, 2-node order - 2", off(0), 0.03); // measured 0.0097
    within("mode 2, 3-node order - 4", off(1), 0.03); // measured 0.0096
    within("mode 2, 4-node order - 6", off(2), 0.06); // measured 0.020
    let finest = lines[2].2;
    within("mode 2, 12 cubic elements vs Timoshenko", finest, 1.5e-7); // measured 4.7e-8

    // Per node, cubic elements are far more accurate: 12 of them (37 nodes) against 20
    // quadratic (41 nodes) and 24 linear ones (25 nodes).
    assert!(lines[2].2 < lines[1].2 && lines[1].2 < lines[0].2);
}
