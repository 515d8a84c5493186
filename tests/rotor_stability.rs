//! `mbd stability` on the windmill (P5): Floquet and Prony exponents against the multiblade
//! eigenvalues computed here (tests/mbc.rs), and the unstable band's edges.

use crate::cli::{code, mbd, stderr, temp};
use crate::common::read;
use crate::common::within;
use crate::mbc::{mbc_edge, mbc_growth, mbc_roots};
use mbd::settings::Request;
use mbd::study::sweep::{self, Method, Point, Sweep, SweepSpec};

const OMEGA_T: f64 = 9.26;

fn spec(values: Vec<f64>, methods: Vec<Method>, refine: usize) -> SweepSpec {
    SweepSpec {
        monodromy: mbd::solve::floquet::Monodromy::Tangent,
        param: "Omega_bar".to_string(),
        values,
        methods,
        period: None,
        // The fixed-frame signals: hub motion and the cyclic lag (THEORY §9.3).
        signals: vec!["x_hub".into(), "zeta_1c".into(), "zeta_1s".into()],
        window: None,
        samples: 300,
        threshold: 1e-2,
        refine,
    }
}

fn run(spec: &SweepSpec, blades: usize) -> Sweep {
    let text = read("models/windmill.mbd");
    let compile = |extra: &[String]| {
        let mut sets = vec![format!("blades={blades}")];
        sets.extend_from_slice(extra);
        mbd::compile("models/windmill.mbd", &text, &sets, Request::default())
            .map_err(|f| format!("{:?}", f.diagnostics))
    };
    sweep::sweep(spec, &compile, &|_| {})
}

fn ok(p: &Point) -> &Point {
    assert!(
        p.failure.is_none(),
        "{} at {}: {:?}",
        p.method.name(),
        p.value,
        p.failure
    );
    p
}

/// The multiblade equations' band, then `mbd stability`'s (Floquet, 4 blades, the model's
/// HHT -0.1 at 0.5 ms): a grid of 0.2 and five bisections bracket each edge within 0.00625.
#[test]
fn floquet_finds_the_ground_resonance_band_of_the_multiblade_equations() {
    let (lo, hi) = (mbc_edge(4, 1.0, 1.5), mbc_edge(4, 2.0, 2.6));
    println!("multiblade band: {lo:.5} .. {hi:.5}");
    assert!((lo - 1.1774).abs() < 1e-4 && (hi - 2.3186).abs() < 1e-4);
    let values: Vec<f64> = (0..9).map(|k| 1.0 + 0.2 * k as f64).collect();
    let s = run(&spec(values, vec![Method::Floquet], 5), 4);
    for p in &s.points {
        ok(p);
    }
    let edges: Vec<f64> = s.edges.iter().map(|e| e.value).collect();
    println!("mbd stability edges: {edges:?}");
    assert_eq!(s.edges.len(), 2, "{:?}", s.edges);
    assert!(s.edges[0].onset && !s.edges[1].onset);
    for (e, want) in s.edges.iter().zip([1.1774, 2.3186]) {
        within(
            &format!("edge {} vs {want}", e.value),
            (e.value - want).abs(),
            0.01,
        ); // measured 3.0e-3
        within(
            &format!("{:?}", e.bracket),
            e.bracket.1 - e.bracket.0,
            0.0063,
        );
    }
    // Against the test's own edges, to the bracket.
    assert!((s.edges[0].value - lo).abs() < 0.004 && (s.edges[1].value - hi).abs() < 0.004);
    assert_eq!(s.unstable_ranges().len(), 1);
    // Outside the band every exponent is neutral: no numerical growth beyond 1e-4 1/s.
    for p in s.points.iter().filter(|p| p.value < 1.1 || p.value > 2.4) {
        within(
            &format!("{}: {}", p.value, p.max_real()),
            p.max_real().abs(),
            1e-4,
        );
    }
}

/// The band edges for 3 and 5 blades: a grid just around each multiblade edge (0.01 either
/// side), bisected three times, brackets it within 0.0025.
#[test]
fn floquet_band_edges_for_3_and_5_blades_match_their_multiblade_equations() {
    for blades in [3usize, 5] {
        let (lo, hi) = (mbc_edge(blades, 1.0, 1.5), mbc_edge(blades, 2.0, 3.0));
        let values = vec![lo - 0.01, lo + 0.01, hi - 0.01, hi + 0.01];
        let s = run(&spec(values, vec![Method::Floquet], 3), blades);
        for p in &s.points {
            ok(p);
        }
        let edges: Vec<f64> = s.edges.iter().map(|e| e.value).collect();
        println!("N = {blades}: multiblade band {lo:.5} .. {hi:.5}, mbd stability {edges:?}");
        assert_eq!(s.edges.len(), 2, "{:?}", s.edges);
        for (e, want) in s.edges.iter().zip([lo, hi]) {
            assert!(
                e.bracket.0 <= want && want <= e.bracket.1 && e.bracket.1 - e.bracket.0 < 0.0026,
                "N = {blades}: edge {:?} vs {want}",
                e.bracket
            );
        }
    }
}

/// Growth rates of the regressing lag mode within 2 % of the multiblade eigenvalues, for 3, 4
/// and 5 blades, by Floquet and by Prony (fixed-frame signals); the frequencies agree too
/// (Floquet's modulo Omega).
#[test]
fn growth_rates_match_the_multiblade_eigenvalues_for_3_4_and_5_blades() {
    for blades in [3usize, 4, 5] {
        let s = run(
            &spec(vec![1.5, 2.0], vec![Method::Floquet, Method::Prony], 0),
            blades,
        );
        for p in &s.points {
            let p = ok(p);
            let roots = mbc_roots(blades, p.value);
            let (_, im) = roots
                .iter()
                .copied()
                .max_by(|a, b| a.0.total_cmp(&b.0))
                .expect("roots");
            let want = mbc_growth(blades, p.value);
            let got = p.max_real();
            let rel = (got - want).abs() / want;
            println!(
                "N = {blades}, Omega_bar = {}: {} {got:.5} (freq {:.4}) vs multiblade {want:.5} (freq {:.4}): {:.2e}",
                p.value,
                p.method.name(),
                p.modes[0].im,
                im.abs(),
                rel
            );
            // The README's claim is 1e-4 relative; measured: Floquet 6.0e-5, Prony 6.3e-5.
            // (Floquet 5.0e-5 with 115 settling steps instead of 70: the model's pulse makes
            // the reference motion depart from the periodic one, so the map over a period
            // depends on where it starts; without the pulse the exponent holds to 2e-12.)
            // (Floquet measured 1.2e-5 while Newton's SE(3) columns were inexact: its runs
            // stopped off the discrete solution. The old columns at tolerance 1e-14 give
            // 5.0e-5 too, the exact ones at 1e-10 and at 1e-14 alike.)
            let bound = match p.method {
                Method::Floquet => 1.5e-4,
                Method::Prony => 1e-4,
            };
            let what = format!("{} growth, N = {blades} at {}", p.method.name(), p.value);
            within(&what, rel, bound);
            let top = p.modes[0];
            match p.method {
                Method::Prony => within(
                    &format!("prony frequency, N = {blades} at {}", p.value),
                    (top.im - im.abs()).abs() / im.abs(),
                    1.2e-5,
                ), // measured 4.3e-6 (relative)
                Method::Floquet => {
                    // Known modulo Omega: the distance of the frequencies to a multiple of it.
                    let omega = p.value * OMEGA_T;
                    let d = [top.im - im.abs(), top.im + im.abs()]
                        .iter()
                        .map(|x| (x / omega - (x / omega).round()).abs() * omega)
                        .fold(f64::INFINITY, f64::min);
                    within(
                        &format!("floquet frequency {} vs {im} mod {omega}", top.im),
                        d / im.abs(),
                        6e-6,
                    ); // measured 1.7e-6 (relative)
                }
            }
        }
    }
}

/// At Omega_bar = 1 (stable, no damping) Prony finds the three neutral fixed-frame modes of
/// THEORY §9.1: 5.653, 7.856 and 16.256 rad/s.
#[test]
fn prony_finds_the_neutral_modes_of_the_stable_rotor() {
    let s = run(&spec(vec![1.0], vec![Method::Prony], 0), 4);
    let p = ok(&s.points[0]);
    for want in [5.653, 7.856, 16.256] {
        let m = p
            .modes
            .iter()
            .find(|m| (m.im - want).abs() < 2e-3)
            .unwrap_or_else(|| panic!("no mode at {want} rad/s: {:?}", p.modes));
        within(&format!("{m:?}"), m.re.abs(), 5e-7); // measured 1.6e-7
    }
    within("p.max_real().abs()", p.max_real().abs(), 5e-7); // measured 1.6e-7
}

#[test]
fn the_stability_command_writes_its_csv_and_chart() {
    let out = temp("stab.csv", "");
    let chart = temp("stab.svg", "");
    let o = mbd(&[
        "stability",
        "models/windmill.mbd",
        "--sweep",
        "Omega_bar=1.0:1.5:0.5",
        "--method",
        "both",
        "--refine",
        "2",
        "-o",
        out.to_str().expect("path"),
        "--chart",
        chart.to_str().expect("path"),
    ]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    // Off a terminal, a line per finished evaluation (issue 16: 20-30 s of silence before).
    let err = stderr(&o);
    for v in [
        "Omega_bar = 1 (floquet)",
        "Omega_bar = 1 (prony)",
        "Omega_bar = 1.5 (floquet)",
    ] {
        assert!(err.contains(v), "{v}: {err}");
    }
    // The method column is text: split by hand.
    let text = std::fs::read_to_string(&out).expect("csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    assert_eq!(
        &header[..6],
        &[
            "Omega_bar",
            "max_real",
            "min_damping_ratio",
            "method",
            "freq1",
            "real1"
        ]
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 4);
    assert_eq!(
        rows.iter().map(|r| (r[0], r[3])).collect::<Vec<_>>(),
        vec![
            ("1", "floquet"),
            ("1", "prony"),
            ("1.5", "floquet"),
            ("1.5", "prony")
        ]
    );
    for r in &rows {
        assert_eq!(r.len(), header.len());
        let max_real: f64 = r[1].parse().expect("max_real");
        assert_eq!(max_real > 0.5, r[0] == "1.5", "{r:?}");
    }
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("edge: Omega_bar = "), "{stdout}");
    assert!(stdout.contains("unstable: "), "{stdout}");
    let svg = std::fs::read_to_string(&chart).expect("svg");
    assert!(svg.starts_with("<svg") && svg.contains("unstable"), "chart");
    crate::charts::check(&svg, Some("stability_map"));
}

#[test]
fn the_stability_command_rejects_bad_requests_with_usage_errors() {
    let out = temp("bad.csv", "");
    let o = out.to_str().expect("path");
    let cases: &[(&[&str], &str)] = &[
        (
            &["models/windmill.mbd", "--sweep", "Omega_bar=1:2"],
            "START:STOP:STEP",
        ),
        (
            &[
                "models/windmill.mbd",
                "--sweep",
                "Omega_bar=1:2:0.5",
                "--set",
                "Omega_bar=3",
            ],
            "conflicts",
        ),
        (
            &["models/windmill_spinup.mbd", "--sweep", "T0=500:1000:500"],
            "--period",
        ),
        (
            &[
                "models/windmill.mbd",
                "--sweep",
                "omega_T=9rad/s:10m:1rad/s",
            ],
            "the range's STOP `10m`",
        ),
        (
            &[
                "models/windmill.mbd",
                "--sweep",
                "Omega_bar=1:2:0.5",
                "--method",
                "prony",
                "--signals",
                "x_hub,nope",
            ],
            "no output channel `nope`",
        ),
        (
            &[
                "models/windmill.mbd",
                "--sweep",
                "Omega_bar=1:2:0.5",
                "--window",
                "1:3",
            ],
            "--method prony",
        ),
    ];
    for (args, says) in cases {
        let mut all = vec!["stability"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["-o", o]);
        let r = mbd(&all);
        assert_eq!(code(&r), 2, "{args:?}: {}", stderr(&r));
        assert!(stderr(&r).contains(says), "{args:?}: {}", stderr(&r));
    }
    // An unknown param is the model's error (E0208, exit 1), reported with its span.
    let r = mbd(&[
        "stability",
        "models/windmill.mbd",
        "--sweep",
        "Omega=1:2:0.5",
        "-o",
        o,
    ]);
    assert_eq!(code(&r), 1);
    assert!(stderr(&r).contains("E0208") && stderr(&r).contains("no param `Omega`"));
}
