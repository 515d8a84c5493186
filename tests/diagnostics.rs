//! Every diagnostic code, rendered against its source and snapshotted (SOURCE + DIAGNOSTICS).
//! The tests assert the code; the snapshots hold the text.

use crate::common::{read, repo};
use mbd::diagnostics::{render_human, Code, Diagnostic, ALL_CODES};
use mbd::settings::Request;
use mbd::source::SourceMap;

/// (case under tests/ui, the codes it must produce, in order: exactly these)
const CASES: &[(&str, &[Code])] = &[
    ("empty", &[Code::E0102]),
    ("syntax_missing_equals", &[Code::E0101]),
    ("missing_header", &[Code::E0103]),
    ("unknown_name", &[Code::E0201, Code::W0201]),
    ("unit_mismatch", &[Code::E0202]),
    ("unit_mismatch_sum", &[Code::E0202]),
    ("duplicate_name", &[Code::E0203]),
    ("unknown_unit", &[Code::E0204]),
    ("unknown_property", &[Code::E0205]),
    ("missing_property", &[Code::E0206]),
    ("param_cycle", &[Code::E0207]),
    ("vector_expected", &[Code::E0209]),
    ("unknown_function", &[Code::E0210]),
    ("unknown_joint_kind", &[Code::E0211]),
    ("unknown_output", &[Code::E0212]),
    ("alpha_out_of_range", &[Code::E0213]),
    ("unknown_newton_mode", &[Code::E0211]),
    ("twist_stations", &[Code::E0213, Code::E0209, Code::E0213]),
    ("curve_points", &[Code::E0224, Code::E0303, Code::E0213]),
    ("section_centres", &[Code::E0224]),
    ("mass_matrix", &[Code::E0224, Code::E0213]),
    (
        "distributed_loads",
        &[Code::E0222, Code::E0222, Code::E0202, Code::E0401],
    ),
    ("joint_to_itself", &[Code::E0301]),
    ("negative_mass", &[Code::E0302]),
    ("zero_length", &[Code::E0303]),
    ("no_bodies", &[Code::E0304]),
    ("two_grounds", &[Code::E0305]),
    ("marker_offset_on_point_mass", &[Code::E0306]),
    ("unused_param", &[Code::W0201]),
    ("several_errors", &[Code::E0202, Code::E0202, Code::E0201]),
    ("repeated_in_loop", &[Code::E0202, Code::E0214]),
    ("index_out_of_range", &[Code::E0214]),
    ("component_argument", &[Code::E0215, Code::E0215]),
    ("module_not_found", &[Code::E0216]),
    ("runaway_recursion", &[Code::E0218]),
    ("not_exported", &[Code::E0219]),
    ("misplaced_declaration", &[Code::E0220]),
    ("wrong_reference", &[Code::E0222]),
    ("loop_too_long", &[Code::E0223]),
    ("declaration_shape", &[Code::E0224]),
    (
        "shapes",
        &[
            Code::E0213,
            Code::E0206,
            Code::E0213,
            Code::E0224,
            Code::E0224,
        ],
    ),
    ("output_function_unknown", &[Code::E0225]),
    ("output_function_arguments", &[Code::E0225, Code::E0225]),
    ("multiblade_single_joint", &[Code::E0226]),
    ("multiblade_not_revolute", &[Code::E0226]),
    ("multiblade_one_blade", &[Code::E0226]),
    ("multiblade_azimuth", &[Code::E0227, Code::E0227]),
    ("center_of_mass_massless", &[Code::E0228, Code::E0228]),
    ("missing_solve", &[Code::E0229]),
    ("run_cannot_finish", &[Code::E0230]),
    ("output_call_component", &[Code::E0212, Code::E0212]),
    ("redundant_constraints", &[Code::W0303]),
    ("redundant_drive", &[Code::E0307]),
    ("massless_motion", &[Code::E0308]),
    ("markers_apart", &[Code::E0310]),
    ("inertia_not_physical", &[Code::E0311]),
    ("varies_in_time", &[Code::E0401]),
    ("knots_out_of_order", &[Code::E0402]),
    ("piecewise_mode", &[Code::E0403]),
    ("driven_twice", &[Code::E0404]),
    ("exact_unknown_channel", &[Code::E0405]),
    ("exact_twice", &[Code::E0406]),
    ("exact_not_a_function", &[Code::E0407]),
    ("unused_declaration", &[Code::W0202, Code::W0202]),
    ("angle_without_unit", &[Code::W0203]),
    ("floating_body", &[Code::W0301]),
    ("stiff_beam", &[Code::W0701]),
    ("flexible_rigid_beam", &[Code::W0702]),
    ("unread_part", &[Code::W0703]),
];

/// Codes snapshotted by the other tests of this file (run-time failures, `--set`, imports).
const ELSEWHERE: &[Code] = &[
    Code::E0104,
    Code::E0607,
    Code::W0302,
    Code::E0208,
    Code::E0217,
    Code::E0601,
    Code::E0602,
    Code::E0603,
    Code::E0604,
    Code::E0605,
    Code::W0601,
    Code::W0602,
    Code::E0608,
];

#[test]
fn every_code_has_a_snapshot_case() {
    for c in ALL_CODES {
        assert!(
            CASES.iter().any(|(_, k)| k.contains(c)) || ELSEWHERE.contains(c),
            "{} has no snapshot case",
            c.as_str()
        );
    }
}

/// Modules held in memory, for import tests.
struct Modules(&'static [(&'static str, &'static str)]);

impl mbd::model::Loader for Modules {
    fn load(&self, r: &mbd::model::LoadRequest) -> Result<(String, String), Option<String>> {
        let key = match r {
            mbd::model::LoadRequest::Module { path, .. } => format!("{}.mbd", path.join("/")),
            mbd::model::LoadRequest::File { path, .. } => path.to_string(),
        };
        self.0
            .iter()
            .find(|m| m.0 == key)
            .map(|m| (m.0.to_string(), m.1.to_string()))
            .ok_or(None)
    }
}

#[test]
fn import_cycles_are_reported_and_user_modules_load() {
    let model = "model m\nuse parts::a\nground earth\np = pend(base = earth)\nsolve hht { dt = 0.01 s, until = 1 s }\n";
    const A: &str = "use \"parts/b.mbd\"\ncomponent pend(base: marker) {\n    point_mass bob { mass = 1 kg, at = (0, -1, 0) m }\n    joint link = distance(base, bob)\n}\n";
    const FILES: &[(&str, &str)] = &[("parts/a.mbd", A), ("parts/b.mbd", "use parts::a\n")];
    let cyclic = Modules(FILES);
    let f = match mbd::compile_with("m.mbd", model, &[], Request::default(), &cyclic) {
        Ok(_) => panic!("an import cycle must be an error"),
        Err(f) => f,
    };
    let codes: Vec<Code> = f.diagnostics.iter().map(|d| d.code).collect();
    assert!(codes.contains(&Code::E0217), "{codes:?}");
    insta::assert_snapshot!("import_cycle", render_all(&f.diagnostics, &f.sources));
    // Without the cycle the same component loads from the user's module.
    const FINE: &[(&str, &str)] = &[("parts/a.mbd", "component pend(base: marker) {\n    point_mass bob { mass = 1 kg, at = (0, -1, 0) m }\n    joint link = distance(base, bob)\n}\n")];
    let fine = Modules(FINE);
    let c = mbd::compile_with("m.mbd", model, &[], Request::default(), &fine);
    match c {
        Ok(c) => assert_eq!(c.model.bodies[0].name, "p.bob"),
        Err(f) => panic!("{}", render_all(&f.diagnostics, &f.sources)),
    }
}

fn render_all(diags: &[Diagnostic], sources: &SourceMap) -> String {
    diags
        .iter()
        .map(|d| render_human(d, sources, false))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Every diagnostic points at its source (a primary label over a non-empty span, with text) and
/// says what to do (a non-empty hint): what the snapshots show, asserted so that accepting a
/// snapshot blindly cannot lose it.
/// A zero-width span is allowed only at the end of its source, where a file (or a `--set`
/// value) stops short: there is no character to point at.
fn assert_located(name: &str, diags: &[Diagnostic], sources: &SourceMap) {
    for d in diags {
        let code = d.code.as_str();
        let primary = d
            .labels
            .first()
            .unwrap_or_else(|| panic!("{name}: {code} has no label: {}", d.message));
        let at_end = primary.span.start as usize == sources.text(primary.span.source).len();
        assert!(
            !primary.span.is_empty() || at_end,
            "{name}: {code}'s label spans nothing"
        );
        assert!(
            !primary.text.trim().is_empty(),
            "{name}: {code}'s label says nothing"
        );
        let hint = d.hint.as_deref().unwrap_or("");
        assert!(
            hint.trim().len() > 10,
            "{name}: {code} has no hint: {}",
            d.message
        );
    }
}

fn codes_of(diags: &[Diagnostic]) -> Vec<Code> {
    diags.iter().map(|d| d.code).collect()
}

/// Compiles a case, checks that its diagnostics are located, and returns them with the rendered
/// snapshot text.
fn compile_case(name: &str, source: &str, sets: &[String]) -> (Vec<Diagnostic>, String) {
    let (diags, sources) = match mbd::compile(
        &format!("tests/ui/{name}.mbd"),
        source,
        sets,
        Request::default(),
    ) {
        Ok(c) => {
            // The sizing lint's warnings follow the compiler's, as `mbd check` reports them.
            let lint = mbd::lint(
                &c,
                name,
                source,
                sets,
                Request::default(),
                &mbd::model::NoFiles,
            );
            (
                c.warnings.into_iter().chain(lint.diagnostics).collect(),
                c.sources,
            )
        }
        Err(f) => (f.diagnostics, f.sources),
    };
    assert_located(name, &diags, &sources);
    (
        diags.clone(),
        format!(
            "SOURCE\n{source}\nDIAGNOSTICS\n{}",
            render_all(&diags, &sources)
        ),
    )
}

#[test]
fn every_ui_case_reports_its_code_with_a_span_and_a_hint() {
    for (name, code) in CASES {
        let source = read(&format!("tests/ui/{name}.mbd"));
        let (diags, text) = compile_case(name, &source, &[]);
        let got: Vec<Code> = diags.iter().map(|d| d.code).collect();
        assert_eq!(&got, code, "{name}\n{text}");
        insta::assert_snapshot!(format!("ui_{name}"), text);
    }
}

#[test]
fn every_ui_case_file_is_listed() {
    let mut files: Vec<String> = std::fs::read_dir(repo("tests/ui"))
        .expect("tests/ui")
        .filter_map(|e| e.ok())
        .map(|e| {
            e.file_name()
                .to_string_lossy()
                .trim_end_matches(".mbd")
                .to_string()
        })
        .collect();
    files.sort();
    let mut listed: Vec<String> = CASES.iter().map(|(n, _)| n.to_string()).collect();
    listed.sort();
    listed.dedup();
    assert_eq!(files, listed);
}

#[test]
fn several_errors_are_reported_in_one_run() {
    let source = read("tests/ui/several_errors.mbd");
    let (diags, _) = compile_case("several_errors", &source, &[]);
    assert_eq!(
        codes_of(&diags),
        vec![Code::E0202, Code::E0202, Code::E0201],
        "{diags:?}"
    );
}

#[test]
fn set_of_an_unknown_param_points_at_the_argument() {
    let source = read("models/pendulum.mbd");
    let (diags, text) = compile_case("pendulum", &source, &["V1=3".to_string()]);
    let codes = codes_of(&diags);
    assert_eq!(codes, vec![Code::E0208]);
    let text = text
        .split("DIAGNOSTICS\n")
        .nth(1)
        .unwrap_or_default()
        .to_string();
    assert!(text.contains("did you mean `V0`"), "{text}");
    insta::assert_snapshot!("set_unknown_param", text);
}

#[test]
fn set_with_a_syntax_error_or_wrong_unit_is_reported() {
    let source = read("models/pendulum.mbd");
    let (diags, text) = compile_case("pendulum", &source, &["V0=3 m/".to_string()]);
    let codes = codes_of(&diags);
    assert_eq!(codes, vec![Code::E0101]);
    insta::assert_snapshot!(
        "set_syntax_error",
        text.split("DIAGNOSTICS\n").nth(1).unwrap_or_default()
    );
    let (diags, text) = compile_case("pendulum", &source, &["V0=3 kg".to_string()]);
    let codes = codes_of(&diags);
    assert_eq!(codes, vec![Code::E0202]);
    insta::assert_snapshot!(
        "set_wrong_unit",
        text.split("DIAGNOSTICS\n").nth(1).unwrap_or_default()
    );
}

#[test]
fn every_code_has_an_explanation_and_a_distinct_spelling() {
    let mut seen = std::collections::HashSet::new();
    for c in ALL_CODES {
        assert!(seen.insert(c.as_str()), "{} twice", c.as_str());
        assert!(
            c.doc().len() > 40,
            "{} lacks a real explanation",
            c.as_str()
        );
        let text = mbd::diagnostics::explain(c.as_str()).expect("explain");
        assert!(text.starts_with(c.as_str()));
    }
    assert!(mbd::diagnostics::explain("E9999").is_none());
}

/// Runs a model, checks that what the run reports is located, and renders it: warnings, then
/// the failure if any.
fn run_case(name: &str, text: &str, overrides: Request) -> (Vec<Diagnostic>, String) {
    let c = match mbd::compile(name, text, &[], overrides) {
        Ok(c) => c,
        Err(f) => panic!("{name} does not compile: {:?}", f.diagnostics),
    };
    let mut out = Vec::new();
    let diags = match mbd::run(&c, &mut out) {
        Ok(r) => r.warnings,
        Err(f) => f
            .warnings
            .into_iter()
            .chain(std::iter::once(f.diagnostic))
            .collect(),
    };
    assert_located(name, &diags, &c.sources);
    let shown: Vec<Diagnostic> = diags
        .iter()
        .map(|d| Diagnostic {
            message: without_solver_digits(&d.message),
            ..d.clone()
        })
        .collect();
    (diags, render_all(&shown, &c.sources))
}

/// A message with the solver's residual and increment norms (`residual 2.007e-10 against
/// 4.500e-8`) replaced by `[norm]`: they are the arithmetic's, not the contract's. The contract
/// (the failed norm exceeds its tolerance) is asserted by `newton_failure_reports_its_norms`.
fn without_solver_digits(text: &str) -> String {
    let mut out = String::new();
    for (k, word) in text.split(' ').enumerate() {
        if k > 0 {
            out.push(' ');
        }
        let number = word.trim_end_matches([';', ',', ')']);
        let is_norm = number.contains('e') && number.parse::<f64>().is_ok() && number != "e";
        if is_norm {
            out.push_str("[norm]");
            out.push_str(&word[number.len()..]);
        } else {
            out.push_str(word);
        }
    }
    out
}

/// A parallelogram four-bar started with its links in line: a singular position, where its
/// joints' equations are dependent (W0303) only there.
const PARALLELOGRAM_IN_LINE: &str =
    "model para \"a parallelogram four-bar started with its links in line\"
gravity = (0, -9.81, 0) m/s^2
ground earth
rigid_rod crank { from = (0, 0, 0) m, to = (0.3, 0, 0) m, mass = 1 kg }
rigid_rod coupler { from = (0.3, 0, 0) m, to = (0.8, 0, 0) m, mass = 2 kg }
rigid_rod rocker { from = (0.5, 0, 0) m, to = (0.8, 0, 0) m, mass = 1 kg }
joint j1 = revolute(earth, crank.start) { axis = z }
joint j2 = revolute(crank.end, coupler.start) { axis = z }
joint j3 = revolute(coupler.end, rocker.end) { axis = z }
joint j4 = revolute(earth @ (0.5, 0, 0) m, rocker.start) { axis = z }
output theta = j1.angle
solve hht { dt = 1 ms, until = 1 s }
";

#[test]
fn runtime_diagnostics_name_when_and_where() {
    let pendulum = read("models/pendulum.mbd");
    let two_steps = || Request {
        steps: Some(2),
        ..Default::default()
    };
    let fet = Request {
        method: Some(mbd::settings::Method::Fet),
        rotations: Some(mbd::settings::Rotations::Conformal),
        ..Default::default()
    };
    let cases = [
        (
            "run_newton_failure",
            pendulum.replace(
                "solve hht(alpha = -0.1) {",
                "solve hht(alpha = -0.1, max_iterations = 1) {",
            ),
            Request::default(),
            Code::E0601,
        ),
        (
            "run_fet_conformal_unavailable",
            pendulum.clone(),
            fet,
            Code::E0604,
        ),
        (
            "run_non_finite",
            pendulum.replacen("param V0 = 1.5 m/s", "param V0 = 1e150 m/s", 1),
            Request::default(),
            Code::E0603,
        ),
        (
            "run_singular",
            pendulum.replacen("param V0 = 1.5 m/s", "param V0 = 1e160 m/s", 1),
            Request::default(),
            Code::E0602,
        ),
        (
            "run_velocity_projected",
            pendulum.replace("velocity = (V0, 0, 0)", "velocity = (V0, -0.05 m/s, 0)"),
            two_steps(),
            Code::W0601,
        ),
        (
            "run_redundant_inconsistent",
            PARALLELOGRAM_IN_LINE.to_string(),
            Request::default(),
            Code::E0608,
        ),
        (
            "run_position_projected",
            pendulum.replace("{ length = L }", "{ length = 0.6 m }"),
            two_steps(),
            Code::W0602,
        ),
    ];
    for (name, text, overrides, code) in cases {
        let (diags, rendered) = run_case(&format!("{name}.mbd"), &text, overrides);
        assert_eq!(codes_of(&diags), vec![code], "{name}");
        insta::assert_snapshot!(name, rendered);
    }
}

/// The number after `key` in `m` and the tolerance after the `against` that follows it.
fn norm_against(m: &str, key: &str) -> (f64, f64) {
    let number = |text: &str| -> f64 {
        let word = text.split([' ', ';', ')']).next().unwrap_or("");
        word.parse()
            .unwrap_or_else(|_| panic!("`{word}` is not a number in {m}"))
    };
    let at = m.find(key).unwrap_or_else(|| panic!("no `{key}` in {m}")) + key.len();
    let against = m[at..].find("against ").expect("a tolerance") + at + "against ".len();
    (number(&m[at..]), number(&m[against..]))
}

/// The numbers the snapshots leave out: a Newton failure reports a residual or increment above
/// its tolerance, and the projection warnings the violations the model text sets (0.1 m: a link
/// of 0.6 m whose markers are 0.5 m apart; 0.05 m/s: the vertical start velocity).
#[test]
fn newton_failure_reports_its_norms() {
    let pendulum = read("models/pendulum.mbd");
    let failing = pendulum.replace(
        "solve hht(alpha = -0.1) {",
        "solve hht(alpha = -0.1, max_iterations = 1) {",
    );
    let (diags, _) = run_case("newton.mbd", &failing, Request::default());
    let m = &diags[0].message;
    let (residual, r_tol) = norm_against(m, "(residual ");
    let (increment, i_tol) = norm_against(m, "last increment ");
    assert!(
        residual > r_tol || increment > i_tol,
        "a failure must exceed a tolerance: {m}"
    );
    let two_steps = Request {
        steps: Some(2),
        ..Default::default()
    };
    let moved = pendulum.replace("{ length = L }", "{ length = 0.6 m }");
    let (diags, _) = run_case("moved.mbd", &moved, two_steps.clone());
    assert!(
        diags[0].message.contains("up to 1.000e-1 m"),
        "{}",
        diags[0].message
    );
    let pushed = pendulum.replace("velocity = (V0, 0, 0)", "velocity = (V0, -0.05 m/s, 0)");
    let (diags, _) = run_case("pushed.mbd", &pushed, two_steps);
    assert!(
        diags[0].message.contains("up to 5.000e-2 m/s"),
        "{}",
        diags[0].message
    );
}

#[test]
fn modes_refuses_a_rotor_on_a_still_mast_and_names_both() {
    let text = crate::modes::teetering(true);
    let c = match mbd::compile("teeter.mbd", &text, &[], Request::default()) {
        Ok(c) => c,
        Err(f) => panic!("teeter does not compile: {:?}", f.diagnostics),
    };
    let d = match mbd::modes(&c, false) {
        Err(d) => d,
        Ok(_) => panic!("modes of a rotor on an elastic mast must be refused"),
    };
    assert_eq!(d.code, Code::E0605);
    // The still mast and the turning hub, each at its declaration.
    assert_eq!(d.labels.len(), 2, "{:?}", d.labels);
    insta::assert_snapshot!("modes_not_steady", render_all(&[d], &c.sources));
}
