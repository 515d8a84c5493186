//! Issue 22 items 4 and 5: modes followed along a stability sweep, checked against the windmill's
//! multiblade equations (`tests/mbc.rs`, independent of mbd). Through the ground-resonance
//! band (Omega_bar 1.3 to 2.2) the regressive lag mode and the hub mode coalesce (one
//! frequency, real parts of opposite sign) and that pair's frequency crosses the lag frequency
//! nu of the collective and differential modes near Omega_bar 1.5: a column that swaps modes
//! at the crossing or between the coalesced pair lands on another family's value.

use crate::cli::{code, mbd, stderr, temp};
use crate::common::within;

/// The blade-frame families of the multiblade roots (4 blades), `(Re s, frequency)` of the
/// three cyclic modes and of the collective and differential ones (nu), at each of `values`
/// (increasing): the cyclic roots followed by continuity from the first value on a grid 100
/// times finer than the sweep's, each step assigning the roots to the families that minimise
/// the distance to their linear extrapolation.
fn families(values: &[f64]) -> Vec<[(f64, f64); 4]> {
    let cyclic = |omega_bar: f64| -> Vec<(f64, f64)> {
        crate::mbc::mbc_roots(4, omega_bar)
            .into_iter()
            .filter(|&(_, w)| w > 0.0)
            .collect()
    };
    let blade = |omega_bar: f64, (re, w): (f64, f64)| (re, (w - omega_bar * 9.26).abs());
    let (sb, ib) = (20.0 * 2.7 / 2.0, 20.0 * 2.7 * 2.7 / 3.0);
    let nu = |omega_bar: f64| {
        let omega = omega_bar * 9.26;
        (0.0, ((14.0 + 0.3 * sb * omega * omega) / ib).sqrt())
    };
    let permutations = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut last = cyclic(values[0]);
    assert_eq!(last.len(), 3);
    let mut before = last.clone();
    let mut out = Vec::new();
    let mut x = values[0];
    for &v in values {
        let fine = (((v - x) / 0.0005).round() as usize).max(1);
        for k in 1..=fine {
            let roots = cyclic(x + (v - x) * k as f64 / fine as f64);
            let guess: Vec<(f64, f64)> = (last.iter().zip(&before))
                .map(|(a, b)| (2.0 * a.0 - b.0, 2.0 * a.1 - b.1))
                .collect();
            let cost = |p: &[usize; 3]| -> f64 {
                (0..3)
                    .map(|f| (roots[p[f]].0 - guess[f].0).hypot(roots[p[f]].1 - guess[f].1))
                    .sum()
            };
            let best = permutations
                .iter()
                .min_by(|a, b| cost(a).total_cmp(&cost(b)))
                .expect("a permutation");
            before = std::mem::replace(&mut last, best.iter().map(|&i| roots[i]).collect());
        }
        x = v;
        out.push([
            blade(v, last[0]),
            blade(v, last[1]),
            blade(v, last[2]),
            nu(v),
        ]);
    }
    out
}

/// Runs `mbd stability` over `sweep` (NAME=START:STOP:STEP) and returns the worst, over the
/// columns `mode1..mode5` and the values, of each column's error against the multiblade
/// family it starts on (the growth rate's error in 1/s and the frequency's relative error,
/// modulo Omega and up to its sign).
fn followed(sweep: &str, chart: Option<&std::path::Path>) -> f64 {
    let csv = temp(&format!("campbell_{sweep}.csv"), "");
    let mut args = vec![
        "stability",
        "models/windmill.mbd",
        "--sweep",
        sweep,
        "-o",
        csv.to_str().expect("path"),
    ];
    if let Some(svg) = chart {
        args.extend([
            "--chart",
            svg.to_str().expect("path"),
            "--chart-kind",
            "campbell",
        ]);
    }
    let o = mbd(&args);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let text = std::fs::read_to_string(&csv).expect("csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|x| x.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    // Five modes (n_f = 5 on the windmill), each followed in a column of its own.
    let tracks: Vec<(usize, usize)> = (1..=5)
        .map(|k| {
            (
                column(&format!("mode{k}_freq")),
                column(&format!("mode{k}_real")),
            )
        })
        .collect();
    assert!(!header.contains(&"mode6_freq"), "{header:?}");
    let values: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let expected = families(&values);
    // The frequency modulo Omega and up to its sign (a conjugate): the dominant harmonic may
    // put a mode at its fixed-frame frequency (a hub-dominated mode) or at its blades'
    // (tests/floquet.rs checks which).
    let error = |row: &[f64], (f, r): (usize, usize), (re, w): (f64, f64)| {
        let omega = row[0] * 9.26;
        let apart = |x: f64| {
            let d = x.rem_euclid(omega);
            d.min(omega - d)
        };
        let d = apart(row[f] - w).min(apart(row[f] + w));
        (row[r] - re).abs().max(d / w)
    };
    // Each column's family at the first value; it must keep it.
    let family: Vec<usize> = tracks
        .iter()
        .map(|&t| {
            (0..4)
                .min_by(|&a, &b| {
                    let e = |f: usize| error(&rows[0], t, expected[0][f]);
                    e(a).total_cmp(&e(b))
                })
                .expect("a family")
        })
        .collect();
    // nu twice (the collective and differential modes), the three cyclic modes once each.
    let mut sorted = family.clone();
    sorted.sort();
    assert_eq!(sorted, vec![0, 1, 2, 3, 3], "{sweep}: {family:?}");
    let mut worst = 0.0f64;
    for (row, e) in rows.iter().zip(&expected) {
        for (&t, &f) in tracks.iter().zip(&family) {
            worst = worst.max(error(row, t, e[f]));
        }
    }
    worst
}

/// `mbd stability --chart-kind campbell`: each `modeK_*` column of the CSV keeps one
/// multiblade family at every value, through the coalesced band (the growing and the decaying
/// mode share a frequency) and past it, where a cyclic mode's frequency crosses nu near
/// Omega_bar 2.82 and the modes' order by real part (all near zero) changes: the worst of the
/// growth rate's error (1/s) and the frequency's relative error (modulo Omega) over both
/// sweeps, measured
/// 1.7e-4 (the step's own error at Omega_bar 2.2); a column that swapped modes would be off by
/// the gap between two families (over 5 %). The chart has both panels and the per-rev lines.
#[test]
fn a_campbell_sweep_keeps_each_multiblade_mode_in_its_column() {
    let svg = temp("campbell.svg", "");
    let worst =
        followed("Omega_bar=1.3:2.2:0.1", Some(&svg)).max(followed("Omega_bar=2.4:2.9:0.05", None));
    within(
        "campbell: each column against its multiblade family over the sweeps",
        worst,
        4e-4,
    );
    let chart = std::fs::read_to_string(&svg).expect("svg");
    crate::charts::check(&chart, Some("campbell"));
    for label in [
        "frequency [rad/s]",
        "Re s [1/s]",
        "1/rev",
        "mode 5",
        "unstable",
    ] {
        assert!(chart.contains(label), "{label}");
    }
}

/// Item 5: the sweep hands its rows out as the grid's points finish: every partial sweep's
/// CSV is the final CSV's first rows (modes followed the same way), the runs grow, and the
/// last one is the whole grid.
#[test]
fn a_sweep_streams_its_rows_as_its_points_finish() {
    use mbd::study::sweep::{self, Method, SweepSpec};
    use std::sync::Mutex;
    let path = "models/windmill.mbd";
    let source = crate::common::read(path);
    let spec = SweepSpec {
        monodromy: mbd::solve::floquet::Monodromy::Tangent,
        param: "Omega_bar".to_string(),
        values: vec![1.0, 1.1, 1.2, 1.3, 1.4],
        methods: vec![Method::Floquet],
        period: None,
        signals: Vec::new(),
        window: None,
        samples: 300,
        threshold: 1e-2,
        refine: 0,
    };
    let compile = |extra: &[String]| {
        mbd::compile(path, &source, extra, mbd::settings::Request::default())
            .map_err(|f| format!("{:?}", f.diagnostics))
    };
    let csv = |s: &sweep::Sweep| {
        let mut out = Vec::new();
        s.write_csv(&mut out).expect("in memory");
        String::from_utf8(out).expect("utf-8")
    };
    let partials = Mutex::new(Vec::new());
    let result = sweep::sweep_streaming(&spec, &compile, &|_| {}, &|s| {
        partials
            .lock()
            .expect("lock")
            .push((s.points.len(), csv(s)));
    });
    let whole = csv(&result);
    let partials = partials.into_inner().expect("lock");
    assert!(!partials.is_empty());
    let mut last = 0;
    for (rows, text) in &partials {
        assert!(*rows > last, "the runs grow: {rows} after {last}");
        last = *rows;
        assert_eq!(text.lines().count(), rows + 1);
        for (a, b) in text.lines().zip(whole.lines()) {
            assert_eq!(a, b);
        }
    }
    assert_eq!(last, spec.values.len());
}
