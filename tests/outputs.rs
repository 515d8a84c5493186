//! Output functions: the multiblade coordinates and the centre of mass of the windmill,
//! checked row by row against formulas computed here from its blade angles (THEORY §9.1), the
//! centre of mass of a floating assembly of every kind of mass, and the diagnostics of bad
//! calls.

use crate::common::{above, within};
use crate::common::{read, simulate, simulate_text, Trace};
use mbd::diagnostics::Code;
use mbd::settings::Request;
use std::f64::consts::TAU;

/// The windmill's data (models/windmill.mbd): rotor speed Omega = Omega_bar omega_T with
/// Omega_bar = 1, hinge offset, blade length, blade mass.
const OMEGA: f64 = 9.26;
const E: f64 = 0.3;
const L: f64 = 2.7;

fn half_second() -> Request {
    Request {
        until: Some(0.5),
        ..Default::default()
    }
}

/// The multiblade coordinates of `n` blades, written out: (suffix, harmonic, kind).
fn coordinates(n: usize) -> Vec<(&'static str, usize, char)> {
    match n {
        3 => vec![("0", 0, '0'), ("1c", 1, 'c'), ("1s", 1, 's')],
        4 => vec![("0", 0, '0'), ("1c", 1, 'c'), ("1s", 1, 's'), ("d", 0, 'd')],
        5 => vec![
            ("0", 0, '0'),
            ("1c", 1, 'c'),
            ("1s", 1, 's'),
            ("2c", 2, 'c'),
            ("2s", 2, 's'),
        ],
        _ => unreachable!("the test runs 3, 4 and 5 blades"),
    }
}

/// THEORY §9.1, term by term.
fn coleman(zeta: &[f64], psi: f64, harmonic: usize, kind: char) -> f64 {
    let n = zeta.len() as f64;
    let mut sum = 0.0;
    for (k, z) in zeta.iter().enumerate() {
        let psi_k = psi + TAU * k as f64 / n;
        let h = harmonic as f64;
        sum += match kind {
            '0' => z / n,
            'c' => 2.0 / n * z * (h * psi_k).cos(),
            's' => 2.0 / n * z * (h * psi_k).sin(),
            _ => z * (-1f64).powi(k as i32) / n,
        };
    }
    sum
}

fn blade_angles(trace: &Trace, n: usize) -> Vec<Vec<f64>> {
    (1..=n).map(|k| trace.col(&format!("zeta{k}"))).collect()
}

#[test]
fn windmill_multiblade_columns_are_the_coleman_transform_of_the_lag_angles() {
    for n in [3usize, 4, 5] {
        let trace = simulate(
            "models/windmill.mbd",
            &[&format!("blades={n}")],
            half_second(),
        );
        let t = trace.col("t");
        let zeta = blade_angles(&trace, n);
        let coords = coordinates(n);
        let cols: Vec<Vec<f64>> = coords
            .iter()
            .map(|c| trace.col(&format!("zeta_{}", c.0)))
            .collect();
        // The pulse must have set the blades lagging, or the check would be vacuous.
        let largest = zeta.iter().flatten().fold(0.0f64, |m, z| m.max(z.abs()));
        let cyclic = cols[1].iter().fold(0.0f64, |m, z| m.max(z.abs()));
        above(
            &format!("N = {n}: the blades barely move ({largest})"),
            largest,
            5e-5,
        );
        above(&format!("N = {n}: no cyclic lag ({cyclic})"), cyclic, 5e-5);
        for (r, &time) in t.iter().enumerate() {
            // The drive is prescribed at the rate Omega from angle 0.
            let psi = OMEGA * time;
            let z: Vec<f64> = zeta.iter().map(|c| c[r]).collect();
            for (j, &(suffix, harmonic, kind)) in coords.iter().enumerate() {
                let want = coleman(&z, psi, harmonic, kind);
                within(
                    &format!(
                        "N = {n}, t = {time}: zeta_{suffix} = {} but the transform gives {want}",
                        cols[j][r]
                    ),
                    (cols[j][r] - want).abs(),
                    3e-17,
                ); // measured 7.6e-18
            }
            // The inverse transform gives the blade angles back.
            for (k, zk) in z.iter().enumerate() {
                let psi_k = psi + TAU * k as f64 / n as f64;
                let back: f64 = coords
                    .iter()
                    .enumerate()
                    .map(|(j, &(_, h, kind))| {
                        let h = h as f64;
                        cols[j][r]
                            * match kind {
                                '0' => 1.0,
                                'c' => (h * psi_k).cos(),
                                's' => (h * psi_k).sin(),
                                _ => (-1f64).powi(k as i32),
                            }
                    })
                    .sum();
                within(
                    &format!("N = {n}, t = {time}: blade {k} is {zk}, the inverse gives {back}"),
                    (back - zk).abs(),
                    3e-17,
                ); // measured 8.8e-18
            }
        }
    }
}

#[test]
fn windmill_center_of_mass_follows_the_hub_and_the_blades() {
    for n in [3usize, 4, 5] {
        let trace = simulate(
            "models/windmill.mbd",
            &[&format!("blades={n}")],
            half_second(),
        );
        let t = trace.col("t");
        let x_hub = trace.col("x_hub");
        let zeta = blade_angles(&trace, n);
        let cm: Vec<Vec<f64>> = ["x", "y", "z"]
            .iter()
            .map(|c| trace.col(&format!("rotor_cm.{c}")))
            .collect();
        // At rest the rotor is balanced: its centre is on the hub.
        assert!(cm[0][0].abs() < 1e-15 && cm[1][0].abs() < 1e-15);
        let mut off_hub = 0.0f64;
        for (r, &time) in t.iter().enumerate() {
            let psi = OMEGA * time;
            // Uniform rigid blades of equal mass, hinged at e on the massless hub: the mean of
            // their midpoints.
            let (mut x, mut y) = (0.0, 0.0);
            for (k, zk) in zeta.iter().enumerate() {
                let psi_k = psi + TAU * k as f64 / n as f64;
                x += E * psi_k.cos() + L / 2.0 * (psi_k + zk[r]).cos();
                y += E * psi_k.sin() + L / 2.0 * (psi_k + zk[r]).sin();
            }
            let want = [x_hub[r] + x / n as f64, y / n as f64, 0.0];
            for c in 0..3 {
                within(
                    &format!(
                        "N = {n}, t = {time}: rotor_cm[{c}] = {} but the blades put it at {}",
                        cm[c][r], want[c]
                    ),
                    (cm[c][r] - want[c]).abs(),
                    4e-14,
                ); // measured 1.0e-14
            }
            off_hub = off_hub.max((cm[0][r] - x_hub[r]).hypot(cm[1][r]));
        }
        // The cyclic lag moves the centre off the hub (the paper's Fig. 22), by 6e-5 to 8e-5 m
        // in this half second.
        above(
            &format!("N = {n}: the centre never leaves the hub"),
            off_hub,
            3e-5,
        );
    }
}

/// The floating assembly of `center_of_mass_weighs_bodies_beams_and_concentrated_masses`.
const CM_MODEL: &str = "model cm \"A floating assembly\"\n\
component weight(at: position) {\n\
    point_mass bob { mass = 1 kg, at = at }\n\
}\n\
component assembly() {\n\
    rigid plate {\n\
        mass = 2 kg, center = (0.2, 0, 0) m, inertia = (0.01, 0.05, 0.06) kg*m^2\n\
        at = (0, 0, 1) m, orientation = rotate(z, 30 deg)\n\
    }\n\
    beam tail {\n\
        from = (1, 0, 0) m, to = (3, 0, 0) m, elements = 3\n\
        section = { EA = 1e7 N, GA2 = 1e6 N, GA3 = 1e6 N, GJ = 1e3 N*m^2, EI2 = 1e3 N*m^2,\n\
                    EI3 = 1e3 N*m^2, mass_per_length = 2 kg/m, mass_offset2 = 0.1 m,\n\
                    i2 = 0.01 kg*m, i3 = 0.01 kg*m }\n\
    }\n\
    concentrated_mass lump on tail.end { mass = 0.5 kg }\n\
    w = weight(at = (0, -1, 0) m)\n\
}\n\
ground earth\n\
a = assembly()\n\
initial spin of a = 2 rad/s about z through (0, 0, 0) m\n\
output cm = center_of_mass(a), v = center_of_mass(a).velocity\n\
output acc = center_of_mass(a).acceleration, plate_x = center_of_mass(a.plate).x\n\
output center_of_mass(a.tail).position.y\n\
solve hht { dt = 1 ms, until = 0.05 s }\n";

#[test]
fn center_of_mass_weighs_bodies_beams_and_concentrated_masses() {
    // A floating assembly, spun about z: a rigid plate whose centre of mass is off its
    // reference point, a free beam whose section's mass is off its axis and that carries a
    // concentrated mass, and a point mass in a nested instance.
    let text = CM_MODEL;
    let compiled = match mbd::compile("cm.mbd", text, &[], Request::default()) {
        Ok(c) => c,
        Err(f) => panic!("{:?}", f.diagnostics),
    };
    let frame = compiled.model.beams[0].frames[0];
    let axis2 = [frame[0][1], frame[1][1], frame[2][1]];
    let trace = match simulate_text("cm.mbd", text, Request::default()) {
        Ok(t) => t,
        Err((_, m)) => panic!("{m}"),
    };
    assert_eq!(
        &trace.header[1..],
        [
            "cm.x",
            "cm.y",
            "cm.z",
            "v.x",
            "v.y",
            "v.z",
            "acc.x",
            "acc.y",
            "acc.z",
            "plate_x",
            "center_of_mass(a.tail).position.y"
        ]
    );
    let (c30, s30) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let plate = [0.2 * c30, 0.2 * s30, 1.0];
    let tail: Vec<f64> = (0..3)
        .map(|k| [2.0, 0.0, 0.0][k] + 0.1 * axis2[k])
        .collect();
    let (m_plate, m_tail, m_lump, m_bob) = (2.0, 4.0, 0.5, 1.0);
    let mass = m_plate + m_tail + m_lump + m_bob;
    let want: Vec<f64> = (0..3)
        .map(|k| {
            (m_plate * plate[k]
                + m_tail * tail[k]
                + m_lump * [3.0, 0.0, 0.0][k]
                + m_bob * [0.0, -1.0, 0.0][k])
                / mass
        })
        .collect();
    let row = &trace.rows[0];
    for k in 0..3 {
        within(
            &format!("cm[{k}] = {} vs {}", row[1 + k], want[k]),
            (row[1 + k] - want[k]).abs(),
            1e-12,
        );
    }
    within(
        "(row[10] - plate[0]).abs()",
        (row[10] - plate[0]).abs(),
        1e-15,
    );
    let tail_y = (m_tail * tail[1]) / (m_tail + m_lump);
    within(
        &format!("{} vs {tail_y}", row[11]),
        (row[11] - tail_y).abs(),
        5e-17,
    ); // measured 1.4e-17
       // Spun as a whole about z at 2 rad/s: the centre moves with w x r.
    let v0 = [-2.0 * want[1], 2.0 * want[0], 0.0];
    for k in 0..3 {
        within(
            &format!("v[{k}] = {}", row[4 + k]),
            (row[4 + k] - v0[k]).abs(),
            1e-12,
        );
    }
    // Nothing pushes the assembly: its centre keeps that velocity and does not accelerate,
    // while its parts spin and the beam vibrates (momentum is conserved to the Newton
    // tolerance: the velocity drifts by 1e-8 m/s in 50 steps; a missing `w x m eta` term
    // would be 0.1 m/s).
    let speed = (v0[0] * v0[0] + v0[1] * v0[1]).sqrt();
    for row in &trace.rows {
        for k in 0..3 {
            within(
                &format!("t = {}: v[{k}] = {}", row[0], row[4 + k]),
                (row[4 + k] - v0[k]).abs(),
                6e-8 * speed,
            ); // measured 1.9e-8 * speed
            within(
                &format!("t = {}: a[{k}] = {}", row[0], row[7 + k]),
                row[7 + k].abs(),
                1.5e-9,
            ); // measured 4.7e-10
            let x = want[k] + v0[k] * row[0];
            within(
                &format!("t = {}: cm[{k}] = {} vs {x}", row[0], row[1 + k]),
                (row[1 + k] - x).abs(),
                1e-8,
            );
        }
    }
}

/// The windmill with one more output line.
fn windmill_with(line: &str) -> String {
    let text = read("models/windmill.mbd");
    let at = text.find("solve hht").expect("solve block");
    format!("{}{line}\n{}", &text[..at], &text[at..])
}

#[test]
fn bad_output_function_calls_are_rejected_with_their_codes() {
    let cases: &[(&str, Code)] = &[
        ("output cm = centre_of_mass(rotor)", Code::E0225),
        ("output cm = centroid(rotor)", Code::E0225),
        ("output cm = center_of_mass()", Code::E0225),
        ("output cm = center_of_mass(rotor, rotor)", Code::E0225),
        ("output cm = center_of_mass(rotor, of = rotor)", Code::E0225),
        (
            "output z = multiblade(rotor.lag, azimut = rotor.drive)",
            Code::E0225,
        ),
        (
            "output z = multiblade(azimuth = rotor.drive, rotor.lag)",
            Code::E0225,
        ),
        (
            "output z = multiblade(rotor.lag[0], azimuth = rotor.drive)",
            Code::E0226,
        ),
        (
            "output z = multiblade(rotor.blade, azimuth = rotor.drive)",
            Code::E0226,
        ),
        (
            "output z = multiblade(rotor.drive, azimuth = rotor.drive)",
            Code::E0226,
        ),
        (
            "output z = multiblade(rotor.lag.rate, azimuth = rotor.drive)",
            Code::E0226,
        ),
        (
            "output z = multiblade(Omega, azimuth = rotor.drive)",
            Code::E0226,
        ),
        ("output z = multiblade(rotor.lag)", Code::E0227),
        (
            "output z = multiblade(rotor.lag, azimuth = rotor.hub)",
            Code::E0227,
        ),
        (
            "output z = multiblade(rotor.lag, azimuth = rotor.lag)",
            Code::E0227,
        ),
        (
            "output z = multiblade(rotor.lag, azimuth = tower.slide)",
            Code::E0227,
        ),
        ("output cm = center_of_mass(rotor.hub)", Code::E0228),
        ("output cm = center_of_mass(rotor.drive)", Code::E0228),
        ("output cm = center_of_mass(earth)", Code::E0228),
        ("output cm = center_of_mass(Omega)", Code::E0228),
        (
            "output cm = center_of_mass(rotor.blade[0].position)",
            Code::E0228,
        ),
        ("output cm = center_of_mass(rotor).w", Code::E0212),
        ("output cm = center_of_mass(rotor).velocity.q", Code::E0212),
        ("output cm = center_of_mass(rotor).x.y", Code::E0212),
        (
            "output z = multiblade(rotor.lag, azimuth = rotor.drive).x",
            Code::E0212,
        ),
        ("output cm = center_of_mass(rotr)", Code::E0201),
        ("output zeta_0 = center_of_mass(rotor).x", Code::E0203),
    ];
    for (line, code) in cases {
        let text = windmill_with(line);
        match mbd::compile("windmill.mbd", &text, &[], Request::default()) {
            Ok(_) => panic!("`{line}` compiles"),
            Err(f) => {
                let codes: Vec<Code> = f.diagnostics.iter().map(|d| d.code).collect();
                assert_eq!(codes, vec![*code], "`{line}`: {:?}", f.diagnostics);
                assert!(
                    f.diagnostics
                        .iter()
                        .all(|d| !d.labels.is_empty() && d.hint.is_some()),
                    "`{line}`: every diagnostic has a span and a hint"
                );
            }
        }
    }
    // A one-bladed rotor has no multiblade coordinates.
    let text = read("models/windmill.mbd");
    match mbd::compile(
        "windmill.mbd",
        &text,
        &["blades=1".to_string()],
        Request::default(),
    ) {
        Ok(_) => panic!("one blade compiles"),
        Err(f) => {
            let codes: Vec<Code> = f.diagnostics.iter().map(|d| d.code).collect();
            assert_eq!(codes, vec![Code::E0226]);
        }
    }
    // The command line reports them the same way.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_mbd"))
        .args(["check", "tests/ui/multiblade_azimuth.mbd"])
        .current_dir(crate::common::repo("."))
        .output()
        .expect("mbd runs");
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("E0227"));
}

#[test]
fn unnamed_output_functions_are_named_after_what_they_measure() {
    let text = windmill_with(
        "output multiblade(rotor.lag.angle, rotor.drive), center_of_mass(rotor.blade[1]).velocity",
    );
    let c = match mbd::compile("windmill.mbd", &text, &[], Request::default()) {
        Ok(c) => c,
        Err(f) => panic!("{:?}", f.diagnostics),
    };
    let columns: Vec<&str> = c.model.outputs.iter().map(|o| o.column.as_str()).collect();
    let tail = &columns[columns.len() - 7..];
    assert_eq!(
        tail,
        [
            "rotor.lag.angle_0",
            "rotor.lag.angle_1c",
            "rotor.lag.angle_1s",
            "rotor.lag.angle_d",
            "center_of_mass(rotor.blade[1]).velocity.x",
            "center_of_mass(rotor.blade[1]).velocity.y",
            "center_of_mass(rotor.blade[1]).velocity.z",
        ]
    );
}
