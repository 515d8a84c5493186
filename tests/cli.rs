//! The command-line contract: commands, flags, CSV shape and exit codes.

use crate::common::within;
use crate::common::{read, repo};
use std::path::PathBuf;
use std::process::{Command, Output};

pub fn mbd(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mbd"))
        .args(args)
        .current_dir(repo(""))
        .env("NO_COLOR", "1")
        .output()
        .expect("run mbd")
}

pub fn code(o: &Output) -> i32 {
    o.status.code().unwrap_or(-1)
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

pub fn temp(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mbd-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write temp");
    p
}

fn csv(o: &Output) -> (Vec<String>, Vec<Vec<f64>>) {
    mbd::output::read_csv(&String::from_utf8_lossy(&o.stdout)).expect("CSV on stdout")
}

#[test]
fn run_writes_the_pendulum_channels_one_row_per_step() {
    let out = temp("pendulum.csv", "");
    let o = mbd(&[
        "run",
        "models/pendulum.mbd",
        "-o",
        out.to_str().unwrap_or_default(),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let (header, rows) =
        mbd::output::read_csv(&std::fs::read_to_string(&out).expect("csv")).expect("parse");
    assert_eq!(header, ["t", "x", "y", "vx", "vy", "ax", "ay", "tension"]);
    assert_eq!(rows.len(), 201);
    assert_eq!(rows[0][0], 0.0);
    assert_eq!(rows[200][0], 1.0);
    assert_eq!(rows[100][0], 0.5);
}

#[test]
fn values_are_printed_at_round_trip_precision() {
    let o = mbd(&["run", "models/pendulum.mbd", "--steps", "3"]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    let (_, rows) = csv(&o);
    let line = text.lines().nth(2).unwrap_or_default();
    for (field, value) in line.split(',').zip(&rows[1]) {
        assert_eq!(
            format!("{value:?}"),
            field,
            "field {field} does not round-trip"
        );
    }
}

#[test]
fn flags_override_the_solve_block() {
    let (_, rows) = csv(&mbd(&["run", "models/pendulum.mbd", "--every", "10"]));
    assert_eq!(rows.len(), 21);
    assert_eq!(rows[20][0], 1.0);
    let (_, rows) = csv(&mbd(&["run", "models/pendulum.mbd", "--steps", "100"]));
    assert_eq!(rows.len(), 101);
    assert_eq!(rows[1][0], 0.01);
    let (_, rows) = csv(&mbd(&[
        "run",
        "models/pendulum.mbd",
        "--dt",
        "0.01",
        "--until",
        "0.5",
    ]));
    assert_eq!(rows.len(), 51);
    let (_, a) = csv(&mbd(&[
        "run",
        "models/pendulum.mbd",
        "--alpha",
        "0",
        "--start",
        "zero",
    ]));
    let (_, b) = csv(&mbd(&["run", "models/pendulum.mbd"]));
    assert_ne!(a[5][5], b[5][5], "alpha and start reach the solver");
    let o = mbd(&[
        "run",
        "models/pendulum.mbd",
        "--set",
        "V0=5",
        "--set",
        "L=0.6m",
        "--steps",
        "10",
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let (_, rows) = csv(&o);
    assert_eq!((rows[0][2], rows[0][3]), (-0.6, 5.0));
}

#[test]
fn bad_models_exit_1_with_coded_diagnostics() {
    for (case, code_text) in [
        ("tests/ui/empty.mbd", "E0102"),
        ("tests/ui/syntax_missing_equals.mbd", "E0101"),
        ("tests/ui/unknown_name.mbd", "E0201"),
        ("tests/ui/unit_mismatch.mbd", "E0202"),
    ] {
        for cmd in ["run", "check"] {
            let o = mbd(&[cmd, case]);
            assert_eq!(code(&o), 1, "{cmd} {case}: {}", stderr(&o));
            let err = stderr(&o);
            assert!(err.contains(code_text), "{case}: {err}");
            assert!(err.contains("help:"), "{case} has a hint: {err}");
            assert!(!err.contains("panicked"), "{err}");
        }
    }
    let o = mbd(&["run", "models/pendulum.mbd", "--set", "Vzero=3"]);
    assert_eq!(code(&o), 1);
    assert!(stderr(&o).contains("E0208"), "{}", stderr(&o));
}

#[test]
fn bad_usage_exits_2() {
    for args in [
        vec!["run"],
        vec!["run", "models/does_not_exist.mbd"],
        vec!["run", "models/pendulum.mbd", "--alpha", "0.5"],
        vec![
            "run",
            "models/pendulum.mbd",
            "--dt",
            "0.01",
            "--steps",
            "10",
        ],
        vec!["run", "models/pendulum.mbd", "--dt", "-1"],
        vec!["run", "models/pendulum.mbd", "--every", "0"],
        vec!["run", "models/pendulum.mbd", "--integrator", "rk4"],
        vec!["frobnicate"],
        vec!["explain", "E9999"],
    ] {
        let o = mbd(&args);
        assert_eq!(code(&o), 2, "{args:?}: {}", stderr(&o));
    }
}

#[test]
fn runtime_failure_exits_3_says_when_and_where_and_keeps_the_rows() {
    // A Newton budget of one iteration cannot converge a step, even halved three times.
    let text = read("models/pendulum.mbd").replace(
        "solve hht(alpha = -0.1) {",
        "solve hht(alpha = -0.1, max_iterations = 1) {",
    );
    let model = temp("newton_budget.mbd", &text);
    let out = temp("newton_budget.csv", "");
    let o = mbd(&[
        "run",
        model.to_str().unwrap_or_default(),
        "-o",
        out.to_str().unwrap_or_default(),
    ]);
    assert_eq!(code(&o), 3, "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains("E0601") && err.contains("t = 0 s (step 1)"),
        "{err}"
    );
    assert!(
        err.contains("`link`") || err.contains("`bob`"),
        "names where: {err}"
    );
    assert!(err.contains("--dt"), "says what to try: {err}");
    let (header, rows) =
        mbd::output::read_csv(&std::fs::read_to_string(&out).expect("csv")).expect("parse");
    assert_eq!(header[0], "t");
    assert_eq!(rows.len(), 1, "the initial row is kept");
    let o = mbd(&[
        "run",
        "models/pendulum.mbd",
        "--integrator",
        "fet",
        "--rotations",
        "conformal",
    ]);
    assert_eq!(code(&o), 3);
    assert!(stderr(&o).contains("E0604"), "{}", stderr(&o));
}

#[test]
fn inconsistent_initial_velocity_is_projected_with_a_warning() {
    let text = read("models/pendulum.mbd")
        .replace("velocity = (V0, 0, 0)", "velocity = (V0, -0.05 m/s, 0)");
    let model = temp("radial.mbd", &text);
    let o = mbd(&["run", model.to_str().unwrap_or_default(), "--steps", "20"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert!(stderr(&o).contains("W0601"), "{}", stderr(&o));
    let (_, rows) = csv(&o);
    // Tangent to the circle about the pivot at the bottom: no vertical velocity left.
    within(&format!("vy = {}", rows[0][4]), rows[0][4].abs(), 3e-17); // measured 6.9e-18
    assert_eq!(rows[0][3], 1.5, "the tangential velocity is untouched");
}

#[test]
fn check_prints_the_topology_and_every_stage() {
    let o = mbd(&["check", "models/pendulum.mbd"]);
    assert_eq!(code(&o), 0);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    for want in [
        "bodies",
        "3 DOFs, 0 extra unknowns, 1 multipliers",
        "order: bob [0..2] λ link [3..3]",
        "bandwidth 3",
    ] {
        assert!(text.contains(want), "missing {want}: {text}");
    }
    for stage in ["ast", "model", "dofs", "ir"] {
        let o = mbd(&["check", "models/pendulum.mbd", "--emit", stage]);
        assert_eq!(code(&o), 0);
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("stage is JSON");
        assert!(!v.is_null());
    }
    let o = mbd(&["check", "models/pendulum.mbd", "--emit", "ir"]);
    let ir: mbd::runtime::System = serde_json::from_slice(&o.stdout).expect("IR deserializes");
    assert_eq!(ir.unknowns.len(), 4);
    let o = mbd(&["check", "models/pendulum.mbd", "--format", "json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("summary JSON");
    assert_eq!(v["multipliers"], 1);
    // The sizing lint: its verdict on each beam, in the summary and as warnings.
    let o = mbd(&["check", "models/two_bar_beams.mbd", "--format", "json"]);
    assert_eq!(code(&o), 0);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("summary JSON");
    assert_eq!(v["sizing"]["beams"][0]["beam"], "bar1");
    assert_eq!(v["sizing"]["beams"][0]["verdict"], "could be rigid (W0701)");
    let w: serde_json::Value = serde_json::from_slice(&o.stderr).expect("JSON warnings");
    assert_eq!(
        (w[0]["code"].as_str(), w[1]["code"].as_str()),
        (Some("W0701"), Some("W0701"))
    );
    let o = mbd(&["check", "models/windmill_paper.mbd"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("tower: lowest elastic"), "{text}");
    assert!(text.contains("elastic, needed"), "{text}");
    // Every shipped model gets the lint's verdict.
    for entry in std::fs::read_dir(crate::common::repo("models")).expect("models/") {
        let path = entry.expect("entry").path();
        let o = mbd(&["check", path.to_str().expect("utf-8 path")]);
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(text.contains("  sizing  "), "{}: {text}", path.display());
    }
}

#[test]
fn json_diagnostics_give_file_line_column_code_and_hint() {
    let o = mbd(&["check", "tests/ui/unit_mismatch.mbd", "--format", "json"]);
    assert_eq!(code(&o), 1);
    let v: serde_json::Value = serde_json::from_slice(&o.stderr).expect("JSON diagnostics");
    let d = &v[0];
    assert_eq!(d["code"], "E0202");
    assert_eq!(d["file"], "tests/ui/unit_mismatch.mbd");
    assert_eq!(
        (d["line"].as_u64(), d["column"].as_u64()),
        (Some(3), Some(25))
    );
    assert!(
        d["hint"]
            .as_str()
            .map(|h| h.contains("kg"))
            .unwrap_or(false),
        "{d}"
    );
}

#[test]
fn explain_prints_a_codes_documentation() {
    let o = mbd(&["explain", "E0202"]);
    assert_eq!(code(&o), 0);
    assert!(String::from_utf8_lossy(&o.stdout).contains("unit mismatch"));
}

#[test]
fn plot_draws_the_named_channels_of_a_run() {
    let run_csv = temp("plot_run.csv", "");
    let o = mbd(&[
        "run",
        "models/pendulum.mbd",
        "--until",
        "0.5",
        "-o",
        run_csv.to_str().unwrap_or_default(),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let svg = temp("plot.svg", "");
    let o = mbd(&[
        "plot",
        run_csv.to_str().unwrap_or_default(),
        "--channel",
        "x",
        "--channel",
        "tension",
        "-o",
        svg.to_str().unwrap_or_default(),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let text = std::fs::read_to_string(&svg).unwrap_or_default();
    assert!(text.starts_with("<svg"), "not an SVG");
    crate::charts::check(&text, Some("plot_pendulum"));
    // One line per channel in its own colour (and its legend mark), the time axis labelled.
    for colour in ["#1F77B4", "#FF7F0E"] {
        assert!(
            text.contains(&format!(
                "<polyline fill=\"none\" opacity=\"1\" stroke=\"{colour}\""
            )),
            "no line in {colour}"
        );
    }
    for label in ["tension", "t [s]", "plot_run.csv"] {
        assert!(text.contains(label), "missing `{label}`");
    }
    // An unknown channel is a usage error naming the channels the CSV has.
    let o = mbd(&[
        "plot",
        run_csv.to_str().unwrap_or_default(),
        "--channel",
        "tensoin",
        "-o",
        svg.to_str().unwrap_or_default(),
    ]);
    assert_eq!(code(&o), 2);
    assert!(
        stderr(&o).contains("no channel `tensoin`"),
        "{}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("tension"), "{}", stderr(&o));
}

#[test]
fn plot_with_the_model_puts_each_unit_on_its_own_axis() {
    // Issue 16: a 3e-7 m channel and a 1e-3 rad channel shared one `value (SI)` axis.
    let run_csv = temp("plot_windmill.csv", "");
    let o = mbd(&[
        "run",
        "models/windmill.mbd",
        "--until",
        "0.05",
        "-o",
        run_csv.to_str().unwrap_or_default(),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let svg = temp("plot_windmill.svg", "");
    let args = |model: bool| {
        let mut a = vec![
            "plot".to_string(),
            run_csv.to_string_lossy().to_string(),
            "-o".to_string(),
            svg.to_string_lossy().to_string(),
        ];
        for c in ["x_hub", "zeta1", "zeta2", "rotor_cm.x"] {
            a.push("--channel".into());
            a.push(c.into());
        }
        if model {
            a.push("--model".into());
            a.push("models/windmill.mbd".into());
        }
        a
    };
    let run = |model: bool| {
        let a = args(model);
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        let o = mbd(&refs);
        assert_eq!(code(&o), 0, "{}", stderr(&o));
        std::fs::read_to_string(&svg).unwrap_or_default()
    };
    let grouped = run(true);
    // Two panels: the lengths and the angles, each axis with its unit.
    assert!(grouped.contains("x_hub, rotor_cm.x [m]"), "lengths");
    assert!(grouped.contains("joint angle [rad]"), "angles");
    crate::charts::check(&grouped, Some("plot_windmill"));
    assert_eq!(grouped.matches("t [s]").count(), 2);
    // Without the model the CSV has no units: one axis, in SI, as before.
    let plain = run(false);
    assert!(plain.contains("values (SI units)") && !plain.contains("[rad]"));
    crate::charts::check(&plain, None);
    // `-o NAME.png` writes the same chart as a PNG.
    let png = temp("plot_windmill.png", "");
    let mut a = args(true);
    let at = a.iter().position(|x| x.ends_with(".svg")).unwrap_or(0);
    a[at] = png.to_string_lossy().to_string();
    let refs: Vec<&str> = a.iter().map(String::as_str).collect();
    assert_eq!(code(&mbd(&refs)), 0);
    let bytes = std::fs::read(&png).unwrap_or_default();
    assert!(bytes.starts_with(b"\x89PNG"), "not a PNG");
}
