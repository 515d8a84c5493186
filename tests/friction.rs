//! The friction points of a new user's first hour (issue 16), one regression test each.

use crate::common::within;
use crate::common::{simulate_text, Trace};
use mbd::diagnostics::{Code, Diagnostic};
use mbd::settings::Request;
use mbd::source::SourceMap;

/// Compiles model text; `Ok` with the warnings, `Err` with every diagnostic.
fn check(text: &str) -> Result<Vec<Diagnostic>, (Vec<Diagnostic>, SourceMap)> {
    match mbd::compile("friction.mbd", text, &[], Request::default()) {
        Ok(c) => Ok(c.warnings),
        Err(f) => Err((f.diagnostics, f.sources)),
    }
}

fn codes(d: &[Diagnostic]) -> Vec<Code> {
    d.iter().map(|d| d.code).collect()
}

/// The diagnostics of a model that must not compile.
fn errors(text: &str) -> Vec<Diagnostic> {
    match check(text) {
        Ok(w) => panic!("must not compile; warnings: {:?}", codes(&w)),
        Err((d, _)) => d,
    }
}

fn run(text: &str) -> Trace {
    match simulate_text("friction.mbd", text, Request::default()) {
        Ok(t) => t,
        Err((_, msg)) => panic!("run failed: {msg}"),
    }
}

/// The text of `text`'s span in `source`.
fn spanned<'a>(source: &'a str, d: &Diagnostic, label: usize) -> &'a str {
    let s = d.labels[label].span;
    &source[s.start as usize..s.end as usize]
}

/// Gravity, the ground, the outputs of the hinged rod `arm` (at `path`) and the solve block.
fn swing(path: &str) -> String {
    format!(
        "gravity = (0, -9.81, 0) m/s^2
ground earth
output tip = {path}.end.position, f = {path}.hinge.force, a = {path}.hinge.angle
solve hht {{ dt = 10 ms, until = 0.5 s }}
"
    )
}

#[test]
fn a_marker_with_an_offset_is_a_component_argument() {
    // The offset written at the instance...
    let passed = format!(
        "model passed\nuse stdlib::rod::hinged_rod\n{}\
arm = hinged_rod(base = earth @ (0, 0, 1) m, root = (0, 0, 1) m, direction = x, length = 1 m, mass = 1 kg)\n",
        swing("arm")
    );
    // ... runs the same as the offset written inside the component,
    let inside = format!(
        "model inside\n{}\
component hinged_rod(base: marker, root: position, direction: direction, length: length, mass: mass) {{
    rigid_rod bar {{ from = root, to = root + length * direction, mass = mass }}
    joint hinge = revolute(base @ (0, 0, 1) m, bar.start) {{ axis = z }}
    export bar, hinge, end = bar.end
}}
arm = hinged_rod(base = earth, root = (0, 0, 1) m, direction = x, length = 1 m, mass = 1 kg)\n",
        swing("arm")
    );
    // ... and as offsets passed on through a second component and added up.
    let nested = format!(
        "model nested\nuse stdlib::rod::hinged_rod\n{}\
component stand(base: marker) {{
    arm = hinged_rod(base = base @ (0, 0, 0.25) m, root = (0, 0, 1) m, direction = x, length = 1 m, mass = 1 kg)
    export arm
}}
s = stand(base = earth @ (0, 0, 0.75) m)\n",
        swing("s.arm")
    );
    let a = run(&passed);
    let b = run(&inside);
    let c = run(&nested);
    assert_eq!(a.header, b.header);
    assert_eq!(a.header, c.header);
    assert!(a.rows.len() > 10);
    for (t, (ra, rb)) in a.rows.iter().zip(&b.rows).enumerate() {
        assert_eq!(ra, rb, "row {t}");
        assert_eq!(ra, &c.rows[t], "row {t}");
    }
    // It swung: the tip left its start at (2, 0, 1).
    let y = a.col("tip.y");
    within(&format!("{y:?}"), y.last().copied().unwrap_or(0.0), -0.5);
    assert_eq!(a.col("tip.z")[5], 1.0);
}

#[test]
fn only_marker_arguments_take_an_offset_and_only_as_markers() {
    let text = "model m
ground earth
component c(base: marker, b: body) {
    rigid_rod bar { from = (0, 0, 1) m, to = (0, 1, 1) m, mass = 1 kg }
    joint pin = revolute(base, bar.start) { axis = z }
    initial spin of base = 1 rad/s about z
}
rigid_rod r { from = (0, 0, 1) m, to = (1, 0, 1) m, mass = 1 kg }
joint hold = fixed(earth @ (0, 0, 1) m, r.start)
x = c(base = earth @ (0, 0, 1) m, b = r @ (1, 0, 0) m)
solve hht { dt = 0.01 s, until = 0.1 s }
";
    let d = errors(text);
    assert_eq!(codes(&d), vec![Code::E0215, Code::E0222], "{d:#?}");
    assert_eq!(spanned(text, &d[0], 0), "(1, 0, 0) m");
    assert_eq!(d[0].labels[0].text, "an offset");
    assert!(d[0].message.contains("argument `b` of `c` is a body"));
    assert_eq!(spanned(text, &d[1], 0), "base");
    assert!(
        d[1].message.contains("usable only as a marker"),
        "{}",
        d[1].message
    );
}

#[test]
fn a_missing_solve_block_is_named_at_the_model_header() {
    let text = "model pendulum \"no solve block\"
ground earth
point_mass bob { mass = 1 kg, at = (0, -1, 0) m }
joint link = distance(earth, bob)
";
    let d = errors(text);
    assert_eq!(codes(&d), vec![Code::E0229]);
    assert_eq!(d[0].message, "the model has no `solve` block");
    assert_eq!(spanned(text, &d[0], 0), "model pendulum \"no solve block\"");
    assert_eq!(d[0].labels[0].text, "this model has no `solve` block");
    assert!(d[0].hint.as_deref().unwrap_or("").contains("solve hht {"));
    // Without a header, at the start of the file, next to E0103.
    let d = errors(&text.replace("model pendulum \"no solve block\"\n", ""));
    assert_eq!(codes(&d), vec![Code::E0103, Code::E0229]);
    assert_eq!(d[1].labels[0].span.start, 0);
    // The command line may stand in for the block.
    let o = Request {
        until: Some(0.1),
        dt: Some(0.01),
        ..Default::default()
    };
    assert!(mbd::compile("p.mbd", text, &[], o).is_ok());
}

#[test]
fn a_failed_argument_is_one_error_not_three() {
    // Issue 16's model: `h` is a bare number where the rod's length is needed. The rod is not
    // built, so neither the initial spin nor the centre of mass finds a body; both stay silent.
    let text = "model m
use stdlib::rod::hinged_rod
param h = 1.5
ground earth
arm = hinged_rod(base = earth, root = (0,0,0) m, direction = x, length = h, mass = 1 kg)
initial spin of arm = 1 rad/s about z
initial spin of arm.bar = 1 rad/s about z
output cm = center_of_mass(arm), tip = arm.end.position
solve hht { dt = 0.01 s, until = 0.1 s }
";
    let d = errors(text);
    assert_eq!(codes(&d), vec![Code::E0215], "{d:#?}");
    assert_eq!(spanned(text, &d[0], 0), "h");
    // An unknown component: the names through the instance are not unknown too.
    let text = "model m
param Omega = 3 rad/s
ground earth
rotor = lag_hinged_rotr(hub = earth, speed = Omega)
initial spin of rotor = Omega about z
output r = rotor.drive.rate, cm = center_of_mass(rotor)
solve hht { dt = 0.01 s, until = 0.1 s }
";
    let d = errors(text);
    assert_eq!(codes(&d), vec![Code::E0201], "{d:#?}");
    assert_eq!(spanned(text, &d[0], 0), "lag_hinged_rotr");
}

#[test]
fn a_mistake_in_a_loop_is_reported_once_with_the_iterations_that_hit_it() {
    let text = "model m
ground earth
for i in 0..3 {
    point_mass bob[i] { mass = 1 m, at = (i, -1, 0) m }
    joint link[i] = distance(earth, bob[i + 1])
    if i {
        force push[i] on bob[i] = (1, 0, 0) kg
    }
}
solve hht { dt = 0.01 s, until = 0.1 s }
";
    let d = errors(text);
    assert_eq!(
        codes(&d),
        vec![Code::E0202, Code::E0202, Code::E0214],
        "{d:#?}"
    );
    let label = |d: &Diagnostic| {
        let l = d.labels.last().map(|l| l.span).unwrap_or(d.labels[0].span);
        (
            &text[l.start as usize..l.end as usize],
            d.labels.last().map(|l| l.text.clone()).unwrap_or_default(),
        )
    };
    // Every iteration: the mass (the message names no member: `bob[..]`).
    assert_eq!(spanned(text, &d[0], 0), "1 m");
    assert_eq!(
        label(&d[0]),
        (
            "for i in 0..3",
            "in all 3 iterations of this loop".to_string()
        )
    );
    // Two of three: the force.
    assert_eq!(spanned(text, &d[1], 0), "(1, 0, 0) kg");
    assert_eq!(
        label(&d[1]).1,
        "in 2 of the 3 iterations of this loop (`i` = 1, 2)"
    );
    // The last only: the index past the end.
    assert_eq!(spanned(text, &d[2], 0), "i + 1");
    assert_eq!(label(&d[2]).1, "in the iteration `i = 2` of this loop");
    assert_eq!(d[2].message, "index 3 is out of range for `bob`");
}

#[test]
fn a_loop_whose_messages_differ_says_whose_is_shown() {
    let text = "model m
ground earth
for i in 0..3 {
    rigid_rod bar[i] { from = (i + 1, 0, 0) m, to = (i + 2, 0, 0) m, mass = 1 kg }
    joint pin[i] = revolute(earth, bar[i].start) { axis = z }
}
solve hht { dt = 0.01 s, until = 0.1 s }
";
    let d = errors(text);
    assert_eq!(codes(&d), vec![Code::E0310], "{d:#?}");
    assert!(
        d[0].message.contains("apart by 1.000000 m"),
        "{}",
        d[0].message
    );
    let last = d[0].labels.last().map(|l| l.text.as_str());
    assert_eq!(
        last,
        Some("in all 3 iterations of this loop; the message is that of `i = 0`")
    );
}

#[test]
fn indices_that_differ_between_iterations_read_as_a_family() {
    let text = "model m
ground earth
for i in 0..2 {
    point_mass bob[i] { mass = -1 kg, at = (i, -1, 0) m }
}
solve hht { dt = 0.01 s, until = 0.1 s }
";
    let d = errors(text);
    assert_eq!(codes(&d), vec![Code::E0302]);
    assert_eq!(d[0].message, "the mass of `bob[..]` is not positive");
}

#[test]
fn a_param_whose_only_user_failed_is_not_reported_unused() {
    let text = "model m
param k = 10 N*m/rad
param c = 1 N*m*s/rad
ground earth
rigid_rod bar { from = (0, 0, 0) m, to = (1, 0, 0) m, mass = 1 kg }
joint hinge = revolute(earth, bar.strat) { axis = z, spring = k }
for i in 0..2 {
    joint j[i] = revolute(earth, bar.stat) { axis = z, damper = c }
}
param unused = 2
solve hht { dt = 0.01 s, until = 0.1 s }
";
    let d = errors(text);
    // `k` and `c` were given to joints whose markers failed; `unused` really is unused.
    assert_eq!(
        codes(&d),
        vec![Code::E0201, Code::E0201, Code::W0201],
        "{d:#?}"
    );
    assert!(d[2].message.contains("`unused`"), "{}", d[2].message);
    // The label stays on the declaration's line (no trailing whitespace in spans).
    assert_eq!(spanned(text, &d[2], 0), "param unused = 2");
}

#[test]
fn unit_errors_name_quantities_and_the_param_that_holds_the_value() {
    let text = "model m
param EI = 100 N*m
section s { EA = 1e7 N, GA2 = 1e6 N, GA3 = 1e6 N, GJ = 1e3 N*m^2, EI2 = EI, EI3 = 1e3 N*m^2, mass_per_length = 1 kg/m }
ground earth
beam blade { from = (0, 0, 0) m, to = (2, 0, 0) m, section = s, elements = 2 }
joint clamp = fixed(earth, blade.start)
rigid_rod bar { from = (0, 0, 0) m, to = (0, 1, 0) m, mass = 1 kg }
joint pin = revolute(earth, bar.start) { axis = z, torque = 2 N }
torsional_spring twist(earth @ (0, 1, 0) m, bar.end) { stiffness = 3 N/m }
solve hht { dt = 1 ms, until = 1 s }
";
    let d = errors(text);
    assert_eq!(
        codes(&d),
        vec![Code::E0202, Code::E0202, Code::E0202],
        "{d:#?}"
    );
    let ei = &d[0];
    assert_eq!(
        ei.message,
        "`EI2` must be a bending stiffness [N*m^2], found a moment [N*m]"
    );
    // At the use, then at the param.
    assert_eq!(spanned(text, ei, 0), "EI");
    assert_eq!(ei.labels[0].text, "this is a moment [N*m]");
    assert_eq!(spanned(text, ei, 1), "param EI = 100 N*m");
    assert_eq!(ei.labels[1].text, "defined here as a moment [N*m]");
    let texts: Vec<&str> = d[1..].iter().map(|d| d.message.as_str()).collect();
    assert!(
        texts.contains(
            &"`stiffness` must be a torsional stiffness [N*m/rad], found a stiffness [N/m]"
        ),
        "{texts:?}"
    );
    assert!(
        texts.contains(&"`torque` must be a torque [N*m], found a force [N]"),
        "{texts:?}"
    );
    // A component argument: the same, through the argument to the param.
    let text = "model m
use stdlib::rod::hinged_rod
param h = 1.5
ground earth
arm = hinged_rod(base = earth, root = (0,0,0) m, direction = x, length = h, mass = 1 kg)
solve hht { dt = 0.01 s, until = 0.1 s }
";
    let d = errors(text);
    assert_eq!(codes(&d), vec![Code::E0215]);
    assert_eq!(
        d[0].message,
        "argument `length` of `hinged_rod` must be a length [m]"
    );
    assert_eq!(d[0].labels[0].text, "this is a dimensionless number");
    assert_eq!(spanned(text, &d[0], 1), "param h = 1.5");
    assert_eq!(
        d[0].labels[1].text,
        "defined here as a dimensionless number"
    );
}

#[test]
fn an_angle_without_a_unit_is_a_warning() {
    let text = "model m
param theta = 10
param phi = 20 deg
ground earth
component arm(a: angle, at: position) {
    rigid_rod bar { from = at, to = at + (1, 0, 0) m, mass = 1 kg }
    joint hinge = revolute(earth @ at, bar.start) { axis = z, spring = 1 N*m/rad, rest_angle = a }
}
x = arm(a = 45, at = (0, 1, 0) m)
y = arm(a = phi, at = (0, 2, 0) m)
rigid_rod bar { from = (0, 0, 0) m, to = (1, 0, 0) m, mass = 1 kg, angular_velocity = rotate(z, 3) * (0, 0, 1) rad/s }
joint hinge = revolute(earth, bar.start) { axis = z, spring = 10 N*m/rad, rest_angle = 3 }
rigid_rod bar2 { from = (0, 0, 2) m, to = (1, 0, 2) m, mass = 1 kg }
joint h2 = revolute(earth @ (0, 0, 2) m, bar2.start) { axis = z, angle = theta * sin(2 * t / 1 s) }
rigid_rod bar3 { from = (0, 0, 3) m, to = (1, 0, 3) m, mass = 1 kg }
joint h3 = revolute(earth @ (0, 0, 3) m, bar3.start) { axis = z, angle = 0.1 * sin(2 rad/s * t), spring = 1 N*m/rad, rest_angle = pi / 6 }
force f on bar3.end = (0, 1, 0) N * sine(1, 2 rad/s, 1)
rigid_rod bar4 { from = (0, 0, 4) m, to = (1, 0, 4) m, mass = 1 kg }
joint h4 = revolute(earth @ (0, 0, 4) m, bar4.start) { axis = z, spring = 1 N*m/rad, rest_angle = 0 }
solve hht { dt = 0.01 s, until = 0.1 s }
";
    let w = match check(text) {
        Ok(w) => w,
        Err((d, _)) => panic!("{d:#?}"),
    };
    assert!(w.iter().all(|d| d.code == Code::W0203), "{w:#?}");
    let found: Vec<(&str, &str)> = w
        .iter()
        .map(|d| (spanned(text, d, 0), d.message.as_str()))
        .collect();
    // The argument is reported where it is given, once (not again at `rest_angle = a`);
    // `phi` (deg), `0.1 * sin(2 rad/s * t)` (rad), `pi / 6` and `0` are angles.
    assert_eq!(
        found,
        vec![
            (
                "3",
                "`rest_angle` has no angle unit: 3 is read as 3 rad (171.9 deg)"
            ),
            (
                "theta * sin(2 * t / 1 s)",
                "the prescribed `angle` has no angle unit, so it is read in radians"
            ),
            (
                "3",
                "the angle of `rotate` has no angle unit: 3 is read as 3 rad (171.9 deg)"
            ),
            (
                "1",
                "the phase of `sine` has no angle unit: 1 is read as 1 rad (57.3 deg)"
            ),
            (
                "45",
                "argument `a` of `arm` has no angle unit: 45 is read as 45 rad (2578 deg)"
            ),
        ]
    );
    assert_eq!(
        w[0].hint.as_deref(),
        Some("write `3 deg` for degrees, or `3 rad` to say it is radians")
    );
}

#[test]
fn initial_motion_of_a_family_moves_every_member() {
    // A family of bodies and a family of instances.
    let text = "model fan
ground earth
component pendulum(x: length) {
    point_mass bob { mass = 1 kg, at = (x, -1 m, 0) }
    joint link = distance(earth @ (x, 0 m, 0), bob)
}
for i in 0..3 {
    rigid_rod blade[i] { from = (0, 0, 0) m, to = rotate(z, i * 120 deg) * (1, 0, 0) m, mass = 1 kg }
    joint hinge[i] = revolute(earth, blade[i].start) { axis = z }
    p[i] = pendulum(x = (i + 2) * 1 m)
}
initial spin of blade = 2 rad/s about z
initial velocity of p = (0, 0, 1) m/s
output v0 = blade[0].end.velocity, v1 = blade[1].end.velocity, v2 = blade[2].end.velocity,
       w2 = blade[2].angular_velocity, u0 = p[0].bob.velocity, u2 = p[2].bob.velocity
solve hht { dt = 1 ms, until = 0.01 s }
";
    let t = run(text);
    let at0 = |c: &str| t.col(c)[0];
    for (k, v) in ["v0", "v1", "v2"].iter().enumerate() {
        // omega x r with r = 1 m at 120 deg steps: 2 m/s along the tangent.
        let a = (k as f64 * 120.0).to_radians();
        within(v, (at0(&format!("{v}.x")) + 2.0 * a.sin()).abs(), 8e-16); // measured 2.2e-16
        within(v, (at0(&format!("{v}.y")) - 2.0 * a.cos()).abs(), 1e-9);
    }
    within(
        "(at0('w2.z') - 2.0).abs()",
        (at0("w2.z") - 2.0).abs(),
        1e-12,
    );
    assert_eq!((at0("u0.z"), at0("u2.z")), (1.0, 1.0));
    // A family of something that does not move is still an error, with its code.
    let d = errors(&text.replace("initial spin of blade", "initial spin of hinge"));
    assert!(codes(&d).contains(&Code::E0222), "{d:#?}");
}

#[test]
fn a_set_angle_param_is_judged_by_its_declaration() {
    // `--set` values are SI: `tilt=0.1` is 0.1 rad, as the reference says; no W0203.
    let text = "model m
param tilt = 5 deg
ground earth
rigid_rod bar { from = (0, 0, 0) m, to = (1, 0, 0) m, mass = 1 kg }
joint pin = revolute(earth, bar.start) { axis = z, spring = 1 N*m/rad, rest_angle = tilt }
solve hht { dt = 0.01 s, until = 0.1 s }
";
    match mbd::compile("m.mbd", text, &["tilt=0.1".to_string()], Request::default()) {
        Ok(c) => assert!(c.warnings.is_empty(), "{:?}", codes(&c.warnings)),
        Err(f) => panic!("{:?}", codes(&f.diagnostics)),
    }
}
