//! Each grammar rule alone: inputs it must accept and inputs it must reject.

use mbd::syntax::{parse_rule, Rule};

fn check(rule: Rule, accept: &[&str], reject: &[&str]) {
    for a in accept {
        assert!(parse_rule(rule, a), "{rule:?} must accept {a:?}");
    }
    for r in reject {
        assert!(!parse_rule(rule, r), "{rule:?} must reject {r:?}");
    }
}

#[test]
fn ident() {
    check(
        Rule::ident,
        &["bob", "_x", "V0", "blade_2", "models"],
        &["2bob", "model", "param", "joint", "a-b", ""],
    );
}

#[test]
fn number() {
    check(
        Rule::number,
        &["1", "1.5", ".5", "1.", "1e3", "2.5E-4", "0"],
        &["-1", "e3", "1e", "1.2.3", ""],
    );
}

#[test]
fn quantity_and_unit() {
    check(
        Rule::quantity,
        &[
            "1 kg",
            "9.81 m/s^2",
            "14 N*m/rad",
            "5m/s",
            "3",
            "1e-3 s^-1",
            "2 kg*m^2",
        ],
        &["1 m / s", "1 m/", "1 ^2", "kg"],
    );
    check(
        Rule::unit,
        &["kg", "m/s^2", "N*m/rad", "s^-1"],
        &["m /s", "*m", "m^", "m^x"],
    );
}

#[test]
fn vector() {
    check(
        Rule::vector,
        &[
            "(0, -9.81, 0) m/s^2",
            "(e, -L, 0)",
            "( 1 , 2 , 3 )",
            "(1, 2)",
        ],
        &["(1)", "(1,)", "(1, 2, 3", "()"],
    );
}

#[test]
fn expr() {
    check(
        Rule::expr_only,
        &[
            "1 + 2 * 3",
            "-L",
            "-(a + b) / 2",
            "2^3^2",
            "sqrt(g / L)",
            "atan2(1, 2)",
            "pi * L",
            "a.b.c",
            "V0 * 2 s",
        ],
        &["1 +", "* 2", "f(", "(1 + 2", "1 2 3", "a..b", ""],
    );
}

#[test]
fn declarations() {
    check(
        Rule::model_decl,
        &["model pendulum", "model p \"a title\""],
        &["model", "model \"x\"", "model p \"unclosed"],
    );
    check(
        Rule::param_decl,
        &["param L = 0.5 m", "param k = 2 * L / s"],
        &["param L", "param = 3", "param L 3"],
    );
    check(
        Rule::gravity_decl,
        &["gravity = (0, -9.81, 0) m/s^2"],
        &["gravity (0, 0, 0)", "gravity ="],
    );
    check(
        Rule::ground_decl,
        &["ground earth"],
        &["ground", "ground 3"],
    );
    check(
        Rule::point_mass_decl,
        &[
            "point_mass bob { mass = 1 kg, at = (0, 0, 0) m }",
            "point_mass bob {\n mass = m\n at = (0, -L, 0)\n}",
            "point_mass b {}",
        ],
        &[
            "point_mass { mass = 1 kg }",
            "point_mass bob { mass 1 kg }",
            "point_mass bob mass = 1 kg",
        ],
    );
    check(
        Rule::joint_decl,
        &[
            "joint link = distance(earth @ (0, 0, 0), bob) { length = L }",
            "joint j = distance(a, b)",
        ],
        &[
            "joint = distance(a, b)",
            "joint j = distance()",
            "joint j distance(a, b)",
            "joint j = distance(a @, b)",
        ],
    );
    check(
        Rule::output_decl,
        &[
            "output bob.position",
            "output x = bob.position.x, link.force",
            "output a,\n b",
        ],
        &["output", "output x =", "output bob.", "output x = 3"],
    );
    check(
        Rule::solve_decl,
        &[
            "solve hht(alpha = -0.1) { dt = 0.005 s, until = 1 s }",
            "solve hht { until = 1 s }",
            "solve hht()",
            "solve fet",
        ],
        &["solve", "solve hht(alpha) {}", "solve hht { dt }"],
    );
}

#[test]
fn file() {
    check(
        Rule::file,
        &[
            "",
            "# only a comment\n",
            "model a\nground g # trailing comment\n",
            "model a ground g",
        ],
        &[
            "model",
            "ground g extra",
            "param x = 1 kg\n}",
            "model a \"t\" 3",
        ],
    );
}

#[test]
fn set_arg() {
    check(
        Rule::set_arg,
        &["V0=5", "V0 = 5 m/s", "L=0.6m", "k=2*3"],
        &["V0", "=5", "V0=", "V0=5=6", "1=2"],
    );
}
