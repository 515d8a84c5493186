//! `mbd modes -o MODES.csv --shapes SHAPES.csv` from the command line: the files' columns as
//! README.md gives them, and on a slender, shear-stiff cantilever with unequal bending
//! stiffnesses (so that no two modes share a frequency) the frequencies against
//! Euler-Bernoulli's `beta_n L` and the shapes, displacements and slopes at every node,
//! against `phi(x) = cosh bx - cos bx - s (sinh bx - sin bx)`. The shapes file names each
//! unknown by its index; `mbd check --emit dofs` says which node and axis that is.

use crate::cli::{code, mbd, stderr, temp};
use crate::common::within;
use crate::study::cells;
use crate::timoshenko::{self, CANTILEVER_EB};
use std::collections::HashMap;
use std::f64::consts::PI;

/// L = 1 m, 12 cubic elements, 1 kg/m; flap (bending about axis 2 = y, deflection along z) EI2 = 100 N*m^2, lag
/// (about z, deflection along y) EI3 = 400 N*m^2: the lag frequencies are twice the flap
/// ones. GA = 1e9 N: a shear flexibility EI / (GA L^2) of 1e-7 (4e-7 in lag). No rotary
/// inertia: torsion has none, and the axial mode is far above.
const CANTILEVER: &str =
    "model slender \"A shear-stiff cantilever with unequal bending stiffnesses\"
section s { EA = 1e9 N, GA2 = 1e9 N, GA3 = 1e9 N, GJ = 100 N*m^2, EI2 = 100 N*m^2,
            EI3 = 400 N*m^2, mass_per_length = 1 kg/m }
ground earth
beam b { from = (0, 0, 0) m, to = (1, 0, 0) m, section = s, elements = 12, order = 4 }
joint clamp = fixed(earth, b.start)
solve hht { dt = 1 ms, until = 1 s }
";
const NODES: usize = 37;

/// The n-th Euler-Bernoulli cantilever mode and its slope at `x` (L = 1).
fn phi(n: usize, x: f64) -> (f64, f64) {
    let b = CANTILEVER_EB[n - 1];
    let s = (b.cosh() + b.cos()) / (b.sinh() + b.sin());
    let y = b * x;
    (
        y.cosh() - y.cos() - s * (y.sinh() - y.sin()),
        b * (y.sinh() + y.sin() - s * (y.cosh() - y.cos())),
    )
}

fn num(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("not a number: {s}"))
}

/// What each unknown is, from `mbd check --emit dofs`: (node, axis, is a rotation).
fn unknowns(model: &str) -> HashMap<usize, (usize, usize, bool)> {
    let o = mbd(&["check", model, "--emit", "dofs"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    let mut out = HashMap::new();
    for (i, u) in v["unknowns"]
        .as_array()
        .expect("unknowns")
        .iter()
        .enumerate()
    {
        let kind = u["kind"].as_str().unwrap_or_default();
        if kind == "node_translation" || kind == "node_rotation" {
            let field = |k: &str| u[k].as_u64().expect("index") as usize;
            out.insert(i, (field("node"), field("axis"), kind == "node_rotation"));
        }
    }
    out
}

/// One mode's shape: per node the (real) translation and rotation vectors, and the largest
/// imaginary part and magnitude of any entry.
struct Shape {
    translation: Vec<[f64; 3]>,
    rotation: Vec<[f64; 3]>,
    largest_imag: f64,
    largest: f64,
}

fn shapes(
    rows: &[Vec<String>],
    what: &HashMap<usize, (usize, usize, bool)>,
    count: usize,
) -> Vec<Shape> {
    let mut out: Vec<Shape> = (0..count)
        .map(|_| Shape {
            translation: vec![[0.0; 3]; NODES],
            rotation: vec![[0.0; 3]; NODES],
            largest_imag: 0.0,
            largest: 0.0,
        })
        .collect();
    for r in rows {
        let (mode, unknown) = (num(&r[0]) as usize, num(&r[1]) as usize);
        let (node, axis, rotation) = what[&unknown];
        let expected = if rotation {
            format!("rotation_{}", ["x", "y", "z"][axis])
        } else {
            "coordinate".to_string()
        };
        assert_eq!(
            (r[2].as_str(), r[3].as_str()),
            ("b", expected.as_str()),
            "{r:?}"
        );
        assert_eq!(r[6], "inertial");
        let (re, im) = (num(&r[4]), num(&r[5]));
        let s = &mut out[mode - 1];
        s.largest_imag = s.largest_imag.max(im.abs());
        s.largest = s.largest.max(re.hypot(im));
        if rotation {
            s.rotation[node][axis] = re;
        } else {
            s.translation[node][axis] = re;
        }
    }
    out
}

/// The shape's displacement and slope along one plane against `phi_n` and `phi_n'`, with one
/// scale fitted for both: the largest difference relative to the largest value, and
/// 1 - MAC of the displacements alone.
fn against_euler_bernoulli(s: &Shape, n: usize, flap: bool) -> (f64, f64) {
    // Flap: w along z, slope -theta_y; lag: v along y, slope theta_z.
    let (axis, slope_axis, sign) = if flap { (2, 1, -1.0) } else { (1, 2, 1.0) };
    let (mut measured, mut reference) = (Vec::new(), Vec::new());
    for k in 0..NODES {
        let (p, dp) = phi(n, k as f64 / (NODES - 1) as f64);
        measured.extend([s.translation[k][axis], sign * s.rotation[k][slope_axis]]);
        reference.extend([p, dp]);
    }
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let scale = dot(&measured, &reference) / dot(&reference, &reference);
    let top = reference
        .iter()
        .fold(0.0f64, |m, r| m.max((scale * r).abs()));
    let diff = measured
        .iter()
        .zip(&reference)
        .fold(0.0f64, |m, (a, r)| m.max((a - scale * r).abs()));
    let (w, p): (Vec<f64>, Vec<f64>) = (
        measured.iter().step_by(2).copied().collect(),
        reference.iter().step_by(2).copied().collect(),
    );
    let mac = dot(&w, &p).powi(2) / (dot(&w, &w) * dot(&p, &p));
    (diff / top, 1.0 - mac)
}

#[test]
fn modes_command_writes_the_euler_bernoulli_frequencies_and_shapes_of_a_cantilever() {
    let model = temp("slender.mbd", CANTILEVER);
    let model = model.to_str().unwrap_or_default();
    let (modes_csv, shapes_csv) = (
        temp("slender_modes.csv", ""),
        temp("slender_shapes.csv", ""),
    );
    let o = mbd(&[
        "modes",
        model,
        "-o",
        modes_csv.to_str().unwrap_or_default(),
        "--shapes",
        shapes_csv.to_str().unwrap_or_default(),
        "--count",
        "5",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let (header, rows) = cells(&modes_csv);
    assert_eq!(
        header,
        "mode,frequency_hz,omega_rad_s,damping_ratio,real_per_s,imag_rad_s,frame"
    );
    assert_eq!(rows.len(), 5);
    // Flap 1, lag 1, flap 2, lag 2, flap 3: omega = (beta_n L)^2 sqrt(EI / (m L^4)).
    let expected = [(1, true), (1, false), (2, true), (2, false), (3, true)];
    let (mut freq, mut timo, mut columns) = (0.0f64, 0.0f64, 0.0f64);
    for (k, (r, &(n, flap))) in rows.iter().zip(&expected).enumerate() {
        assert_eq!((num(&r[0]) as usize, r[6].as_str()), (k + 1, "inertial"));
        let ei: f64 = if flap { 100.0 } else { 400.0 };
        let exact = CANTILEVER_EB[n - 1].powi(2) * ei.sqrt();
        let omega = num(&r[2]);
        freq = freq.max((omega - exact).abs() / exact);
        // The same with the shear flexibility g = EI / (GA L^2) (the beam's own model).
        let b = timoshenko::cantilever(n, ei / 1e9);
        let shear = b * b * ei.sqrt();
        timo = timo.max((omega - shear).abs() / shear);
        // frequency = Im s / 2 pi, omega = |s|, damping ratio = -Re s / |s|: undamped.
        columns = columns
            .max((num(&r[1]) * 2.0 * PI - omega).abs() / omega)
            .max((num(&r[5]) - omega).abs() / omega)
            .max(num(&r[3]).abs())
            .max(num(&r[4]).abs() / omega);
    }
    // Shear lowers the n-th mode by about 16 g (n = 2) and 39 g (n = 3): 6.4e-6 for lag 2.
    within("cantilever frequencies vs Euler-Bernoulli", freq, 2e-5); // measured 6.4e-6
    within("cantilever frequencies vs Timoshenko", timo, 3e-6); // measured 1.1e-6
    within(
        "modes table: undamped, frequency = omega / 2 pi",
        columns,
        3e-11,
    ); // measured 1.4e-11

    let (header, rows) = cells(&shapes_csv);
    assert_eq!(header, "mode,unknown,entity,kind,real,imag,frame");
    let what = unknowns(model);
    // Every node's 6 unknowns for each of the 5 modes (the clamp's multipliers are left out).
    assert_eq!(rows.len(), 5 * 6 * NODES);
    let shapes = shapes(&rows, &what, 5);
    let (mut shape, mut mac, mut imag, mut other) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (s, &(n, flap)) in shapes.iter().zip(&expected) {
        // Scaled so that the largest entry is 1 (here the tip slope).
        assert!(
            (s.largest - 1.0).abs() < 1e-12,
            "largest entry {}",
            s.largest
        );
        let (d, m) = against_euler_bernoulli(s, n, flap);
        eprintln!(
            "mode {n} flap {flap}: shape {d:.3e}, 1 - MAC {m:.3e}, imag {:.3e}",
            s.largest_imag
        );
        shape = shape.max(d);
        mac = mac.max(m);
        imag = imag.max(s.largest_imag);
        // Planar: nothing out of the bending plane, no stretch, no twist.
        let (out_axis, out_rot) = if flap { (1, 2) } else { (2, 1) };
        for k in 0..NODES {
            let (t, r) = (s.translation[k], s.rotation[k]);
            other = other.max(t[out_axis].abs()).max(r[out_rot].abs());
            other = other.max(t[0].abs()).max(r[0].abs());
        }
    }
    // Measured per mode: 2.5e-7, 8.5e-7 (flap 1, lag 1: the shear, rotation = slope - V / GA),
    // 3.2e-6, 6.2e-6 (flap 2, lag 2), 2.5e-5 (flap 3: the mesh).
    within(
        "shapes vs Euler-Bernoulli phi and phi' (of the largest)",
        shape,
        7.5e-5,
    ); // measured 2.5e-5
    within("1 - MAC of the nodal displacements", mac, 1.2e-9); // measured 3.8e-10
    within("imaginary parts of the shapes", imag, 1.2e-10); // measured 3.8e-11

    // The stiff shear (GA / (m omega^2 L^2) ~ 1e6) leaves round-off of the eigenvectors: lag
    // entries of 1e-8 in flap 1.
    within("out-of-plane, axial and twist entries", other, 2e-7); // measured 6.2e-8
}

#[test]
fn modes_of_a_spinning_beam_are_written_in_the_rotating_frame() {
    // models/rotating_beam.mbd spins freely about a hinge: a steady rotation, so both files
    // say `rotating` on every row.
    let (modes_csv, shapes_csv) = (temp("spin_modes.csv", ""), temp("spin_shapes.csv", ""));
    let o = mbd(&[
        "modes",
        "models/rotating_beam.mbd",
        "-o",
        modes_csv.to_str().unwrap_or_default(),
        "--shapes",
        shapes_csv.to_str().unwrap_or_default(),
        "--count",
        "3",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(
        stderr(&o).contains("referred to the frame spinning at"),
        "{}",
        stderr(&o)
    );
    let (_, modes) = cells(&modes_csv);
    let (_, shapes) = cells(&shapes_csv);
    assert_eq!(modes.len(), 3);
    assert!(!shapes.is_empty());
    assert!(modes.iter().chain(&shapes).all(|r| r[6] == "rotating"));
    let listed: std::collections::BTreeSet<usize> =
        shapes.iter().map(|r| num(&r[0]) as usize).collect();
    assert_eq!(listed.into_iter().collect::<Vec<_>>(), vec![1, 2, 3]);
}
