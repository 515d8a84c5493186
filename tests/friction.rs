//! The friction points of a new user's first hour (issue 16), one regression test each.

use crate::common::{simulate_text, Trace};
use mbd::diagnostics::{Code, Diagnostic};
use mbd::model::Overrides;
use mbd::source::SourceMap;

/// Compiles model text; `Ok` with the warnings, `Err` with every diagnostic.
fn check(text: &str) -> Result<Vec<Diagnostic>, (Vec<Diagnostic>, SourceMap)> {
    match mbd::compile("friction.mbd", text, &[], Overrides::default()) {
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
    match simulate_text("friction.mbd", text, Overrides::default()) {
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
    assert!(y.last().copied().unwrap_or(0.0) < -0.5, "{y:?}");
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
    let o = Overrides {
        until: Some(0.1),
        dt: Some(0.01),
        ..Default::default()
    };
    assert!(mbd::compile("p.mbd", text, &[], o).is_ok());
}
