//! Every diagnostic code, rendered against its source and snapshotted (SOURCE + DIAGNOSTICS).
//! The tests assert the code; the snapshots hold the text.

use crate::common::{read, repo};
use mbd::diagnostics::{render_human, Code, Diagnostic, ALL_CODES};
use mbd::model::Overrides;
use mbd::source::SourceMap;

/// (case under tests/ui, the code it must produce)
const CASES: &[(&str, Code)] = &[
    ("empty", Code::E0102),
    ("syntax_missing_equals", Code::E0101),
    ("missing_header", Code::E0103),
    ("unknown_name", Code::E0201),
    ("unit_mismatch", Code::E0202),
    ("unit_mismatch_sum", Code::E0202),
    ("duplicate_name", Code::E0203),
    ("unknown_unit", Code::E0204),
    ("unknown_property", Code::E0205),
    ("missing_property", Code::E0206),
    ("param_cycle", Code::E0207),
    ("vector_expected", Code::E0209),
    ("unknown_function", Code::E0210),
    ("unknown_joint_kind", Code::E0211),
    ("unknown_output", Code::E0212),
    ("alpha_out_of_range", Code::E0213),
    ("joint_to_itself", Code::E0301),
    ("negative_mass", Code::E0302),
    ("zero_length", Code::E0303),
    ("no_bodies", Code::E0304),
    ("two_grounds", Code::E0305),
    ("marker_offset_on_point_mass", Code::E0306),
    ("unused_param", Code::W0201),
    ("several_errors", Code::E0202),
];

fn render_all(diags: &[Diagnostic], sources: &SourceMap) -> String {
    diags
        .iter()
        .map(|d| render_human(d, sources, false))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Compiles a case and returns (codes, rendered snapshot text).
fn compile_case(name: &str, source: &str, sets: &[String]) -> (Vec<Code>, String) {
    let (diags, sources) = match mbd::compile(
        &format!("tests/ui/{name}.mbd"),
        source,
        sets,
        Overrides::default(),
    ) {
        Ok(c) => (c.warnings, c.sources),
        Err(f) => (f.diagnostics, f.sources),
    };
    let codes = diags.iter().map(|d| d.code).collect();
    (
        codes,
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
        let (codes, text) = compile_case(name, &source, &[]);
        assert!(
            codes.contains(code),
            "{name}: expected {code:?}, got {codes:?}\n{text}"
        );
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
    let (codes, _) = compile_case("several_errors", &source, &[]);
    assert_eq!(
        codes,
        vec![Code::E0202, Code::E0202, Code::E0201],
        "{codes:?}"
    );
}

#[test]
fn set_of_an_unknown_param_points_at_the_argument() {
    let source = read("models/pendulum.mbd");
    let (codes, text) = compile_case("pendulum", &source, &["V1=3".to_string()]);
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
    let (codes, text) = compile_case("pendulum", &source, &["V0=3 m/".to_string()]);
    assert_eq!(codes, vec![Code::E0101]);
    insta::assert_snapshot!(
        "set_syntax_error",
        text.split("DIAGNOSTICS\n").nth(1).unwrap_or_default()
    );
    let (codes, text) = compile_case("pendulum", &source, &["V0=3 kg".to_string()]);
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

/// Runs a model and renders what the run reports: warnings, then the failure if any.
fn run_case(name: &str, text: &str, overrides: Overrides) -> (Vec<Code>, String) {
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
    (
        diags.iter().map(|d| d.code).collect(),
        render_all(&diags, &c.sources),
    )
}

#[test]
fn runtime_diagnostics_name_when_and_where() {
    let pendulum = read("models/pendulum.mbd");
    let two_steps = || Overrides {
        steps: Some(2),
        ..Default::default()
    };
    let fet = Overrides {
        integrator: Some(mbd::model::Integrator::Fet),
        ..Default::default()
    };
    let cases = [
        (
            "run_newton_failure",
            pendulum.replace(
                "solve hht(alpha = -0.1) {",
                "solve hht(alpha = -0.1, max_iterations = 1) {",
            ),
            Overrides::default(),
            Code::E0601,
        ),
        ("run_fet_unavailable", pendulum.clone(), fet, Code::E0604),
        (
            "run_velocity_projected",
            pendulum.replace("velocity = (V0, 0, 0)", "velocity = (V0, -0.05 m/s, 0)"),
            two_steps(),
            Code::W0601,
        ),
        (
            "run_position_projected",
            pendulum.replace("{ length = L }", "{ length = 0.6 m }"),
            two_steps(),
            Code::W0602,
        ),
    ];
    for (name, text, overrides, code) in cases {
        let (codes, rendered) = run_case(&format!("{name}.mbd"), &text, overrides);
        assert_eq!(codes, vec![code], "{name}");
        insta::assert_snapshot!(name, rendered);
    }
}
