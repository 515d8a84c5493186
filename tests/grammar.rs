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
        Rule::entity_decl,
        &[
            "ground earth",
            "point_mass bob { mass = 1 kg, at = (0, 0, 0) m }",
            "point_mass bob {\n mass = m\n at = (0, -L, 0)\n}",
            "point_mass b {}",
            "rigid_rod blade[i] { from = (0, 0, 0) m, to = (L, 0, 0) }",
            "beam mast rigid { from = (0, 0, 0) m, to = (0, 0, h) }",
            "beam mast { section = { EA = 1 N }, elements = 4 }",
            "force kick on hub.center = (f, 0, 0)",
            "torque t follower on bar.end = (0, 0, 1) N*m",
            "spring s(a, b @ (1, 0, 0) m) { stiffness = k }",
            "rigid hub { marker tip = (1, 0, 0) m, marker root { at = (0, 0, 0) m } }",
        ],
        &[
            "ground",
            "ground 3",
            "point_mass { mass = 1 kg }",
            "point_mass bob { mass 1 kg }",
            "point_mass bob mass = 1 kg",
            "force kick on = 3",
            "spring s() {}",
        ],
    );
    check(
        Rule::block,
        &[
            "{}",
            "{ a = 1, b = 2 }",
            "{ a = 1\n b = { c = 2 } }",
            "{ marker m = (0, 0, 1) m }",
        ],
        &["{ a }", "{ a = }", "{ marker }", "{ , }"],
    );
    check(
        Rule::marker_item,
        &[
            "marker tip = (L, 0, 0)",
            "marker tip { at = (1, 0, 0) m, axes = rotate(z, 90 deg) }",
            "marker m",
        ],
        &["marker = 3", "markers tip = 1", "marker 3"],
    );
    check(
        Rule::prop,
        &[
            "mass = 1 kg",
            "torque = ramp(0 s, 1 s) * T0",
            "section = { EA = 1 N }",
            "rate = 0.5 rad/s",
        ],
        &["mass", "= 3", "mass = ", "2x = 3"],
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
fn names_paths_and_markers() {
    check(
        Rule::name,
        &["blade", "blade[i]", "blade[i + 1]"],
        &["blade[]", "blade [i]", "1blade", "blade[i"],
    );
    check(
        Rule::path,
        &[
            "bob",
            "bob.position.x",
            "rotor.blade[2].root",
            "mast.at(1.5 m)",
            "mast.node[k - 1]",
            "blade[i].end",
        ],
        &["bob.", ".bob", "a..b", "mast.at()", "bob. position"],
    );
    check(
        Rule::marker,
        &[
            "earth",
            "earth @ (e, 0, 0)",
            "hub @ rotate(z, psi) * (e, 0, 0)",
            "tower.tip",
        ],
        &["@ (0, 0, 0)", "earth @", "earth (1, 2, 3)"],
    );
}

#[test]
fn time_functions() {
    check(
        Rule::piecewise,
        &[
            "piecewise { 0 s: 0 N, 5 ms: 20 N, 10 ms: 0 N }",
            "piecewise extrapolate { 0 s: 0, 1 s: 1 }",
            "piecewise periodic { 0 s: 0, 1 s: 1, }",
        ],
        &[
            "piecewise {}",
            "piecewise { 0 s 0 N }",
            "piecewise { 0 s: }",
            "piecewise 0 s: 1",
        ],
    );
    check(
        Rule::function_decl,
        &[
            "function kick = piecewise { 0 s: 0 N, 5 ms: 20 N, 10 ms: 0 N }",
            "function w = 2 rad/s * ramp(0 s, 1 s)",
        ],
        &["function = 3", "function f", "function f(t) = t"],
    );
}

#[test]
fn components_and_loops() {
    check(
        Rule::let_decl,
        &["let psi = i * 360 deg / N"],
        &["let = 3", "let x", "let x == 3"],
    );
    check(
        Rule::component_decl,
        &[
            "component rod(L: length, m: mass = 1 kg) { rigid_rod bar { from = (0, 0, 0) m, to = (L, 0, 0), mass = m } }",
            "component c() {}",
            "component c(a: int,) { export a }",
        ],
        &["component c { }", "component c(a) {}", "component c(a: ) {}", "component (a: int) {}"],
    );
    check(
        Rule::comp_param,
        &["blades: int = 4", "hub: marker", "axis: direction = z"],
        &["blades", "blades: ", ": int"],
    );
    check(
        Rule::for_decl,
        &[
            "for i in 0..N { rigid_rod b[i] {} }",
            "for i in 1..=blades {}",
            "for k in 0 .. 2 * N { }",
        ],
        &[
            "for i 0..N {}",
            "for i in 0..N",
            "for in 0..3 {}",
            "for i in 0..3 {",
        ],
    );
    check(
        Rule::export_decl,
        &["export hub, blade, lag", "export tip = mast.end"],
        &["export", "export tip =", "export 3"],
    );
    check(
        Rule::instance_decl,
        &[
            "rotor = lag_hinged_rotor(blades = 4, hub = tower.tip)",
            "t = tower()",
            "r[i] = rod(L = 1 m,)",
            "arm = hinged_rod(base = earth @ (0, 0, 1) m, root = (0, 0, 1) m)",
        ],
        &[
            "rotor = lag_hinged_rotor(4)",
            "rotor = (blades = 4)",
            "= rotor()",
            "rotor = a.b(x = 1)",
        ],
    );
    check(
        Rule::use_decl,
        &[
            "use stdlib::rotor::lag_hinged_rotor",
            "use stdlib::tower",
            "use \"parts/tower.mbd\"",
        ],
        &["use", "use stdlib::", "use ::rotor", "use stdlib.rotor"],
    );
    check(
        Rule::initial_decl,
        &[
            "initial spin of rotor = 98.17 rad/s about z through (0, 0, 0) m",
            "initial spin of beam = Omega about z",
            "initial velocity of bob = (1, 0, 0) m/s",
        ],
        &[
            "initial spin rotor = 1 rad/s",
            "initial of rotor = 1",
            "initial spin of = 1 rad/s",
        ],
    );
    check(
        Rule::exact_decl,
        &[
            "exact phi = Omega * t",
            "exact rotor.lag[1].angle = 0",
            "exact zeta[i + 1] = 0.1 * sin(w * t)",
            "exact x = piecewise { 0 s: 0 m, 1 s: 1 m }",
        ],
        &[
            "exact = 1",
            "exact phi",
            "exact phi = ",
            "exactphi = t",
            "exact 3 = t",
        ],
    );
}

#[test]
fn exact_is_a_keyword_only_where_it_starts_an_exact_declaration() {
    // `param exact = 1` and `exact = c()` stay a param and an instance.
    let text = "model m\nparam exact = 1\nexact = c()\nexact phi = exact * t\n";
    let file = mbd::syntax::parse_file(text, mbd::source::SourceId(0));
    let kinds: Vec<&str> = match &file {
        Ok(f) => f
            .items
            .iter()
            .map(|i| match i {
                mbd::syntax::ast::Item::Param { .. } => "param",
                mbd::syntax::ast::Item::Instance { .. } => "instance",
                mbd::syntax::ast::Item::Exact { .. } => "exact",
                _ => "other",
            })
            .collect(),
        Err(d) => panic!("{}", d.message),
    };
    assert_eq!(kinds, ["other", "param", "instance", "exact"]);
}

#[test]
fn conditions_and_parts() {
    check(
        Rule::if_decl,
        &[
            "if elastic { beam b {} } else { rigid_rod b {} }",
            "if n { }",
            "if a {} else if b {} else {}",
        ],
        &["if { }", "if a", "if a {} else", "if a {} elif b {}"],
    );
    check(
        Rule::knot,
        &["0 s: 0 N", "5 ms : 20 N", "T: -x"],
        &["0 s", ": 1", "0 s: "],
    );
    check(
        Rule::flag,
        &["rigid", "follower", "polyline"],
        &["rigidly", "fixed", "polylines", ""],
    );
    check(
        Rule::connection,
        &["(a, b)", "(earth @ (0, 0, 1) m, bar.start)", "(a)"],
        &["()", "(a, )", "a, b"],
    );
    check(
        Rule::on_clause,
        &["on hub", "on bar.end @ (0, 0.1, 0) m"],
        &["on", "onhub", "at hub"],
    );
    check(
        Rule::export_item,
        &["hub", "tip = mast.end", "hub = hub_body"],
        &["tip =", "= mast", "3"],
    );
    check(
        Rule::arg,
        &[
            "blades = 4",
            "hub = tower.tip",
            "torque = T0 * ramp(0 s, 0.5 s)",
            // A marker argument may carry an offset (issue 16).
            "base = earth @ (0, 0, 1) m",
            "hub = tower.tip @ (0, 0, h)",
            "base = rotor.blade[2].end @ (0.1, 0, 0) m",
            "base = mast.at(1 m) @ offset",
        ],
        &[
            "blades",
            "= 4",
            "4 = blades",
            // Only a path takes an offset, once, and the offset is a value.
            "base = 2 * earth @ (0, 0, 1) m",
            "base = (0, 0, 1) m @ earth",
            "base = earth @",
            "base = earth @ (0, 0, 1) m @ (1, 0, 0) m",
            "base = @ (0, 0, 1) m",
        ],
    );
    check(
        Rule::output_item,
        &[
            "bob.position",
            "x = bob.position.x",
            "zeta[i] = rotor.lag[i - 1].angle",
            "zeta = multiblade(rotor.lag, azimuth = rotor.drive)",
            "cm = center_of_mass(rotor)",
            "center_of_mass(rotor).x",
        ],
        &["x =", "= bob", "x = 3", "cm = center_of_mass(rotor) .x"],
    );
    check(
        Rule::index,
        &["[i]", "[i - 1]", "[ 2 ]"],
        &["[]", "[i", "i]"],
    );
}

#[test]
fn output_functions() {
    check(
        Rule::output_call,
        &[
            "multiblade(rotor.lag, azimuth = rotor.drive)",
            "multiblade( rotor.lag ,\n azimuth=rotor.drive )",
            "multiblade(rotor.lag.angle, rotor.drive)",
            "multiblade(lag, azimuth = drive)",
            "center_of_mass(rotor)",
            "center_of_mass(rotor).x",
            "center_of_mass(rotor.blade[2]).velocity.y",
            "center_of_mass(of = rotor)",
            "center_of_mass()",
        ],
        &[
            // A space before `(` or around a dot, as in a path.
            "center_of_mass (rotor)",
            "center_of_mass(rotor) .x",
            "center_of_mass(rotor). x",
            // Arguments are references, not expressions or bare values.
            "multiblade(rotor.lag, azimuth = 3)",
            "multiblade(rotor.lag, azimuth = rotor.drive + 1)",
            "center_of_mass(1 kg)",
            "center_of_mass((rotor))",
            // Malformed calls.
            "center_of_mass(rotor",
            "center_of_mass(rotor,)",
            "center_of_mass(, rotor)",
            "multiblade(rotor.lag, azimuth =)",
            "multiblade(rotor.lag, = rotor.drive)",
            "center_of_mass(rotor).",
            "center_of_mass(rotor).1",
            "center_of_mass(rotor)[1]",
            "center_of_mass(rotor)(x)",
            "a.center_of_mass(rotor)",
            "output(rotor)",
            "(rotor)",
        ],
    );
    check(
        Rule::output_arg,
        &[
            "rotor.lag",
            "azimuth = rotor.drive",
            "of=rotor",
            "rotor.blade[i - 1]",
        ],
        &["azimuth =", "= rotor", "3", "azimuth = 3 m", "a = b = c"],
    );
    check(
        Rule::output_decl,
        &[
            "output zeta = multiblade(rotor.lag, azimuth = rotor.drive), x = hub.position.x",
            "output center_of_mass(rotor), rotor_cm = center_of_mass(rotor).velocity",
        ],
        &[
            "output zeta = multiblade(rotor.lag, azimuth = rotor.drive",
            "output zeta = multiblade (rotor.lag)",
            "output = center_of_mass(rotor)",
        ],
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
            "ground earth\nrigid hub { mass = 1 kg }",
            "beam b rigid { }\nforce f on b.end = (1, 0, 0) N follower",
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
