//! `mbd check --emit ast|model|dofs`: the contents of each stage's JSON against what the model
//! text says (`tests/cli.rs` checks only that every stage is JSON and that the IR has 4
//! unknowns for the pendulum). The expectations are read from the model text here, or follow
//! from it by hand: declarations in file order with their spans, values in SI, bodies, joints,
//! and the unknowns numbered as ARCHITECTURE.md promises (a node's unknowns contiguous, each
//! joint's angle and multipliers right after the last node it couples).

use crate::cli::{code, mbd, stderr, temp};
use crate::common::read;
use serde_json::Value;

/// The JSON that `mbd check MODEL ARGS...` prints on stdout; it must succeed.
fn check(model: &str, args: &[&str]) -> Value {
    let o = mbd(&[&["check", model], args].concat());
    assert_eq!(code(&o), 0, "mbd check {model} {args:?}: {}", stderr(&o));
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{model} {args:?}: {e}"))
}

fn emit(model: &str, stage: &str) -> Value {
    check(model, &["--emit", stage])
}

fn num(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap_or_else(|| panic!("not an array: {v}"))
        .iter()
        .map(num)
        .collect()
}

fn close(what: &str, got: &[f64], want: &[f64]) {
    assert_eq!(got.len(), want.len(), "{what}: {got:?} against {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g - w).abs() <= 1e-12 * w.abs().max(1.0),
            "{what}: {got:?} against {want:?}"
        );
    }
}

/// The declarations of a model file as its text lays them out: `(keyword, name)` for each line
/// that starts a declaration at the left margin (the shipped models write one per line).
fn declarations(text: &str) -> Vec<(String, String)> {
    let word = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = Vec::new();
    for line in text.lines() {
        let Some(first) = line.split_whitespace().next() else {
            continue;
        };
        if line.starts_with([' ', '#', ')', '}']) {
            continue;
        }
        let rest = line[first.len()..].trim_start();
        let name = match first {
            "joint" => format!(
                "{} {}",
                word(rest),
                word(rest.split('=').nth(1).unwrap_or("").trim())
            ),
            "gravity" | "output" => String::new(),
            "solve" => word(rest),
            _ => word(rest),
        };
        out.push((word(first), name));
    }
    out
}

/// The AST item as `(keyword, name)`, named as [`declarations`] names it, with its name's span
/// checked against the text.
fn ast_item(item: &Value, text: &str) -> (String, String) {
    let spanned = |n: &Value| -> String {
        let name = n["name"]
            .as_str()
            .unwrap_or_else(|| panic!("no name in {n}"))
            .to_string();
        let (a, b) = (n["span"]["start"].as_u64(), n["span"]["end"].as_u64());
        let (a, b) = (a.unwrap_or(0) as usize, b.unwrap_or(0) as usize);
        assert_eq!(&text[a..b], name, "the span of `{name}`");
        name
    };
    let kind = item["item"].as_str().unwrap_or_default();
    match kind {
        "model" | "param" | "function" => (kind.to_string(), spanned(&item["name"])),
        "entity" => (spanned(&item["kind"]), spanned(&item["name"]["ident"])),
        "joint" => (
            "joint".to_string(),
            format!(
                "{} {}",
                spanned(&item["name"]["ident"]),
                spanned(&item["kind"])
            ),
        ),
        "solve" => ("solve".to_string(), spanned(&item["method"])),
        _ => (kind.to_string(), String::new()),
    }
}

/// The AST holds every declaration in file order, named and spanned as written; values stay
/// as written (a quantity and its unit, not SI).
#[test]
fn the_ast_holds_the_declarations_as_written() {
    for model in ["models/pendulum.mbd", "models/two_bar.mbd"] {
        let text = read(model);
        let ast = emit(model, "ast");
        let items = ast["items"].as_array().expect("items");
        let got: Vec<(String, String)> = items.iter().map(|i| ast_item(i, &text)).collect();
        let want = declarations(&text);
        assert!(want.len() >= 10, "{model}: {want:?}");
        assert_eq!(got, want, "{model}");
        // The file's span runs to the end of its last declaration.
        let end = text.trim_end().len() as u64;
        assert_eq!(ast["span"]["end"].as_u64(), Some(end), "{model}");
    }
    // `param L = 0.5 m` of the pendulum: the number and the unit's name as written.
    let ast = emit("models/pendulum.mbd", "ast");
    let l = &ast["items"].as_array().expect("items")[2];
    assert_eq!(l["name"]["name"], "L");
    assert_eq!(l["value"]["kind"]["expr"], "quantity");
    assert_eq!(num(&l["value"]["kind"]["value"]), 0.5);
    assert_eq!(
        l["value"]["kind"]["unit"]["factors"][0]["name"]["name"],
        "m"
    );
    // The output columns in the order written, and the solve block's settings.
    let out = ast["items"]
        .as_array()
        .expect("items")
        .iter()
        .find(|i| i["item"] == "output");
    let columns: Vec<&str> = out.expect("an output item")["items"]
        .as_array()
        .expect("output items")
        .iter()
        .filter_map(|o| o["name"]["ident"]["name"].as_str())
        .collect();
    assert_eq!(columns, ["x", "y", "vx", "vy", "ax", "ay", "tension"]);
    // `solve hht(alpha = -0.1) { dt = 0.005 s, until = 1 s }`.
    let solve = &ast["items"]
        .as_array()
        .expect("items")
        .last()
        .expect("a solve item");
    assert_eq!(solve["args"][0]["name"]["name"], "alpha");
    let alpha = &solve["args"][0]["value"]["kind"];
    assert_eq!(alpha["expr"], "neg");
    assert_eq!(num(&alpha["operand"]["kind"]["value"]), 0.1);
    let props = solve["block"]["props"].as_array().expect("props");
    let settings: Vec<(&str, f64, &str)> = props
        .iter()
        .map(|p| {
            let v = &p["value"]["kind"];
            let unit = v["unit"]["factors"][0]["name"]["name"].as_str();
            (
                p["name"]["name"].as_str().unwrap_or_default(),
                num(&v["value"]),
                unit.unwrap_or_default(),
            )
        })
        .collect();
    assert_eq!(settings, [("dt", 0.005, "s"), ("until", 1.0, "s")]);
}

fn param<'a>(model: &'a Value, name: &str) -> &'a Value {
    let params = model["params"].as_array().expect("params");
    let p = params.iter().find(|p| p[0] == name);
    &p.unwrap_or_else(|| panic!("no param {name} in {params:?}"))[1]
}

/// `(mass, length, time)` powers of a param's dimension.
fn dim(p: &Value) -> [i64; 3] {
    ["mass", "length", "time"].map(|d| p["dim"][d].as_i64().unwrap_or(99))
}

/// The model stage holds values in SI with their dimensions, and the bodies and joints
/// resolved: positions, masses, inertias, markers and axes in inertial coordinates.
#[test]
fn the_model_stage_holds_si_values() {
    let si = temp(
        "si.mbd",
        "model si \"Units converted to SI\"
param L = 50 cm
param m = 1500 g
param w = 60 rpm
param tilt = 30 deg
param k = 2 kN*m/rad
gravity = (0, -981, 0) cm/s^2
ground earth
rigid_rod arm { from = (0, 0, 0) m, to = (L, 0, 0), mass = m, angular_velocity = (0, 0, w) }
joint pin = revolute(earth, arm.start) { axis = (0, 0, 2), spring = k, rest_angle = tilt }
solve hht { dt = 2 ms, until = 0.5 s }
",
    );
    let model = emit(si.to_str().expect("path"), "model");
    let pi = std::f64::consts::PI;
    for (name, value, d) in [
        ("L", 0.5, [0, 1, 0]),
        ("m", 1.5, [1, 0, 0]),
        ("w", 2.0 * pi, [0, 0, -1]),
        ("tilt", pi / 6.0, [0, 0, 0]),
        ("k", 2000.0, [1, 2, -2]),
    ] {
        let p = param(&model, name);
        close(name, &[num(&p["value"])], &[value]);
        assert_eq!(dim(p), d, "dimension of {name}");
    }
    close("gravity", &nums(&model["gravity"]), &[0.0, -9.81, 0.0]);
    let arm = &model["bodies"][0];
    assert_eq!(
        (arm["name"].as_str(), arm["kind"].as_str()),
        (Some("arm"), Some("rigid"))
    );
    close("arm mass", &[num(&arm["mass"])], &[1.5]);
    // A rod's reference point is its centre; m L^2 / 12 about the transverse axes, 0 along it.
    close("arm position", &nums(&arm["position"]), &[0.25, 0.0, 0.0]);
    let inertia: Vec<f64> = (0..3).map(|i| num(&arm["inertia"][i][i])).collect();
    close(
        "arm inertia",
        &inertia,
        &[0.0, 1.5 * 0.25 / 12.0, 1.5 * 0.25 / 12.0],
    );
    close(
        "arm spin",
        &nums(&arm["angular_velocity"]),
        &[0.0, 0.0, 2.0 * pi],
    );
    let pin = &model["joints"][0];
    assert_eq!(pin["kind"]["kind"], "revolute");
    close(
        "axis, normalised",
        &nums(&pin["kind"]["axis"]),
        &[0.0, 0.0, 1.0],
    );
    close("spring", &[num(&pin["kind"]["spring"])], &[2000.0]);
    close(
        "rest angle",
        &[num(&pin["kind"]["rest_angle"])],
        &[pi / 6.0],
    );
    assert_eq!(pin["markers"][0]["attach"]["on"], "ground");
    assert_eq!(pin["markers"][1]["attach"]["body"], 0);
    close(
        "arm.start",
        &nums(&pin["markers"][1]["position"]),
        &[0.0, 0.0, 0.0],
    );
    close(
        "arm.start offset",
        &nums(&pin["markers"][1]["offset"]),
        &[-0.25, 0.0, 0.0],
    );
}

/// The two-bar mechanism of models/two_bar.mbd in the model stage: l1 = l2 = 0.5 m,
/// m1 = m2 = 1.6 kg, rods (centred reference points, no inertia along them), bar 2 hinged at
/// the junction (0.5, 0, 0) and standing along +z (theta2_0 = pi / 2), the torque on j2 and the
/// force at bar1.end.
#[test]
fn the_model_stage_resolves_the_two_bar_bodies_and_joints() {
    let pi = std::f64::consts::PI;
    let model = emit("models/two_bar.mbd", "model");
    close(
        "theta2_0",
        &[num(&param(&model, "theta2_0")["value"])],
        &[pi / 2.0],
    );
    assert_eq!(dim(param(&model, "F0")), [1, 1, -3], "F0 is N/s");
    assert_eq!(dim(param(&model, "T0")), [1, 2, -3], "T0 is N*m/s");
    let ml = 1.6 * 0.25 / 12.0;
    for (k, name, at, inertia) in [
        (0, "bar1", [0.25, 0.0, 0.0], [0.0, ml, ml]),
        (1, "bar2", [0.5, 0.0, 0.25], [ml, ml, 0.0]),
    ] {
        let b = &model["bodies"][k];
        assert_eq!(b["name"], name);
        close(name, &[num(&b["mass"])], &[1.6]);
        close(name, &nums(&b["position"]), &at);
        let diag: Vec<f64> = (0..3).map(|i| num(&b["inertia"][i][i])).collect();
        close(name, &diag, &inertia);
    }
    for (k, name, axis) in [(0, "j1", [0.0, 0.0, 1.0]), (1, "j2", [1.0, 0.0, 0.0])] {
        let j = &model["joints"][k];
        assert_eq!(
            (j["name"].as_str(), j["kind"]["kind"].as_str()),
            (Some(name), Some("revolute"))
        );
        close(name, &nums(&j["kind"]["axis"]), &axis);
    }
    assert!(
        model["joints"][0]["kind"]["torque"].is_null(),
        "j1 has no torque"
    );
    assert!(
        model["joints"][1]["kind"]["torque"].is_object(),
        "j2 has the torque T0 <t>"
    );
    close(
        "junction",
        &nums(&model["joints"][1]["markers"][0]["position"]),
        &[0.5, 0.0, 0.0],
    );
    let push = &model["loads"][0];
    assert_eq!(
        (push["name"].as_str(), push["kind"].as_str()),
        (Some("push"), Some("force"))
    );
    close(
        "push at bar1.end",
        &nums(&push["marker"]["position"]),
        &[0.5, 0.0, 0.0],
    );
}

/// One body of each kind and one joint of each kind, each joint to ground but `tether`, which
/// ties the point mass `q` to the rigid body `a`.
const EVERY_JOINT: &str = "model every_joint
ground earth
point_mass p { mass = 1 kg, at = (0, -1, 0) m }
joint rope = distance(earth, p)
rigid a { mass = 1 kg, inertia = (0.01, 0.01, 0.01) kg*m^2, at = (0, 1, 0) m }
joint hinge = revolute(earth @ (0, 1, 0) m, a) { axis = z }
rigid b { mass = 1 kg, inertia = (0.01, 0.01, 0.01) kg*m^2, at = (0, 2, 0) m }
joint rail = prismatic(earth @ (0, 2, 0) m, b) { axis = x }
rigid c { mass = 1 kg, inertia = (0.01, 0.01, 0.01) kg*m^2, at = (0, 3, 0) m }
joint axle = cylindrical(earth @ (0, 3, 0) m, c) { axis = z }
rigid d { mass = 1 kg, inertia = (0.01, 0.01, 0.01) kg*m^2, at = (0, 4, 0) m }
joint cardan = universal(earth @ (0, 4, 0) m, d) { axis1 = x, axis2 = y }
rigid e { mass = 1 kg, inertia = (0.01, 0.01, 0.01) kg*m^2, at = (0, 5, 0) m }
joint ball = spherical(earth @ (0, 5, 0) m, e)
rigid f { mass = 1 kg, inertia = (0.01, 0.01, 0.01) kg*m^2, at = (0, 6, 0) m }
joint weld = fixed(earth @ (0, 6, 0) m, f)
rigid g { mass = 1 kg, inertia = (0.01, 0.01, 0.01) kg*m^2, at = (0, 7, 0) m }
joint motor = revolute(earth @ (0, 7, 0) m, g) { axis = z, rate = 1 rad/s }
point_mass q { mass = 1 kg, at = (1, 0.5, 0) m }
joint tether = distance(a @ (1, 0, 0) m, q)
solve hht { dt = 1 ms, until = 0.1 s }
";

/// The nodes (body indices) a joint of the model stage couples.
fn joint_bodies(joint: &Value) -> Vec<u64> {
    let markers = joint["markers"].as_array().expect("markers");
    markers
        .iter()
        .filter_map(|m| m["attach"]["body"].as_u64())
        .collect()
}

/// The dofs stage: 3 unknowns per point mass and 6 per rigid body (3 translations, then 3
/// rotations, contiguous), one angle per revolute joint, and per joint the multipliers its kind
/// needs: distance 1, spherical 3, universal and cylindrical 4, prismatic 5, fixed 6, revolute
/// 5 and one more for the equation of its angle (6), plus one for a drive (7). Each unknown
/// once; after each node come exactly the joints whose last coupled node it is, each as its
/// angle and then its multipliers; the bandwidth is the widest of those couplings.
#[test]
fn the_dofs_stage_numbers_every_unknown_once_in_the_promised_order() {
    let path = temp("every_joint.mbd", EVERY_JOINT);
    let path = path.to_str().expect("path");
    let dofs = emit(path, "dofs");
    let model = emit(path, "model");
    assert_eq!(
        model["dofs"], dofs,
        "--emit model carries the same numbering"
    );
    let (bodies, joints) = (
        model["bodies"].as_array().expect("bodies"),
        model["joints"].as_array().expect("joints"),
    );
    let names: Vec<&str> = bodies.iter().filter_map(|b| b["name"].as_str()).collect();
    assert_eq!(names, ["p", "a", "b", "c", "d", "e", "f", "g", "q"]);
    let unknowns = dofs["unknowns"].as_array().expect("unknowns");
    let kind = |i: usize| unknowns[i]["kind"].as_str().unwrap_or_default().to_string();
    // Bodies: contiguous translations 0..3, then rotations 0..3 for a rigid body.
    for (n, body) in bodies.iter().enumerate() {
        let start = dofs["body_start"][n].as_u64().expect("body_start") as usize;
        let rigid = body["kind"] == "rigid";
        let count = if rigid { 6 } else { 3 };
        for i in 0..count {
            let u = &unknowns[start + i];
            let want = if i < 3 { "translation" } else { "rotation" };
            assert_eq!(
                (kind(start + i).as_str(), &u["body"], &u["axis"]),
                (want, &Value::from(n), &Value::from(i % 3))
            );
        }
    }
    // Joints: multipliers rows 0..n contiguous from joint_start, the angle right before them.
    let want_rows = [1, 6, 5, 4, 4, 3, 6, 7, 1];
    let mut block_of_joint = Vec::new();
    for (j, joint) in joints.iter().enumerate() {
        let start = dofs["joint_start"][j].as_u64().expect("joint_start") as usize;
        let rows = (start..unknowns.len())
            .take_while(|&i| kind(i) == "multiplier" && unknowns[i]["joint"] == j)
            .count();
        assert_eq!(rows, want_rows[j], "multipliers of {}", joint["name"]);
        for (r, i) in (start..start + rows).enumerate() {
            assert_eq!(unknowns[i]["row"], r, "row {r} of {}", joint["name"]);
        }
        let revolute = joint["kind"]["kind"] == "revolute";
        let first = match dofs["joint_extra"][j].as_u64() {
            Some(angle) => {
                assert!(revolute, "only revolute joints have an angle");
                assert_eq!(
                    angle as usize + 1,
                    start,
                    "the angle comes right before the multipliers"
                );
                assert_eq!(
                    (
                        kind(angle as usize).as_str(),
                        &unknowns[angle as usize]["joint"]
                    ),
                    ("joint_angle", &Value::from(j))
                );
                angle as usize
            }
            None => {
                assert!(!revolute, "a revolute joint has an angle");
                start
            }
        };
        block_of_joint.push((first, start + rows));
    }
    let total = 3 * 2 + 6 * 7 + 2 + want_rows.iter().sum::<usize>();
    assert_eq!(unknowns.len(), total);
    check_order(&dofs, bodies, joints, &block_of_joint);
    let summary = check(path, &["--format", "json"]);
    assert_eq!(summary["unknowns"], total);
    assert_eq!(summary["dofs"], 3 * 2 + 6 * 7);
    assert_eq!(summary["extra_unknowns"], 2);
    assert_eq!(summary["multipliers"], want_rows.iter().sum::<usize>());
    assert_eq!(summary["bandwidth"], dofs["bandwidth"]);
}

/// The order of the blocks: every node once; right after each node's unknowns, the joints whose
/// last coupled node (in `order`) it is, and nothing else; the unknowns a permutation. The
/// bandwidth is the widest coupling: a joint's last unknown against the first unknown of the
/// first node it couples (or a node's own span).
fn check_order(dofs: &Value, bodies: &[Value], joints: &[Value], blocks: &[(usize, usize)]) {
    let order: Vec<usize> = dofs["order"]
        .as_array()
        .expect("order")
        .iter()
        .map(|n| n["body"].as_u64().expect("a body node") as usize)
        .collect();
    let mut sorted = order.clone();
    sorted.sort();
    assert_eq!(
        sorted,
        (0..bodies.len()).collect::<Vec<_>>(),
        "every node once: {order:?}"
    );
    let position = |b: usize| order.iter().position(|&o| o == b).expect("in order");
    let span = |b: usize| {
        let s = dofs["body_start"][b].as_u64().expect("start") as usize;
        (s, s + if bodies[b]["kind"] == "rigid" { 6 } else { 3 })
    };
    let mut next = 0;
    let mut bandwidth = 0;
    for &b in &order {
        let (s, e) = span(b);
        assert_eq!(
            s, next,
            "node {} starts where the previous blocks end",
            bodies[b]["name"]
        );
        bandwidth = bandwidth.max(e - s - 1);
        next = e;
        let mut after: Vec<usize> = (0..joints.len())
            .filter(|&j| {
                joint_bodies(&joints[j])
                    .iter()
                    .map(|&n| position(n as usize))
                    .max()
                    == Some(position(b))
            })
            .collect();
        after.sort_by_key(|&j| blocks[j].0);
        for j in after {
            assert_eq!(
                blocks[j].0, next,
                "{} right after {}",
                joints[j]["name"], bodies[b]["name"]
            );
            let first_node = joint_bodies(&joints[j])
                .iter()
                .map(|&n| span(n as usize).0)
                .min();
            bandwidth = bandwidth.max(blocks[j].1 - 1 - first_node.expect("a node"));
            next = blocks[j].1;
        }
    }
    assert_eq!(
        next,
        dofs["unknowns"].as_array().expect("unknowns").len(),
        "nothing left over"
    );
    assert_eq!(dofs["bandwidth"], bandwidth, "the widest coupling");
}

/// The shipped two-bar mechanism in the summary's words: bar1, j1's angle and multipliers,
/// bar2, j2's (j2 couples both bars, so it follows bar2, whichever comes first).
#[test]
fn the_two_bar_unknowns_follow_their_nodes() {
    let dofs = emit("models/two_bar.mbd", "dofs");
    let model = emit("models/two_bar.mbd", "model");
    let blocks: Vec<(usize, usize)> = (0..2)
        .map(|j| {
            let angle = dofs["joint_extra"][j].as_u64().expect("a revolute angle") as usize;
            (angle, angle + 7)
        })
        .collect();
    let bodies = model["bodies"].as_array().expect("bodies");
    let joints = model["joints"].as_array().expect("joints");
    assert_eq!(
        dofs["unknowns"].as_array().map(|u| u.len()),
        Some(2 * 6 + 2 * 7)
    );
    check_order(&dofs, bodies, joints, &blocks);
}
