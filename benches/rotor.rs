//! Benchmarks of the rotor analyses on the windmill (P5): the paper's 3 s run (6,000 steps of
//! HHT -0.1), and one point of a stability sweep by each method at Omega_bar = 1.5 (Floquet:
//! the step's tangent carried through one run of the period, the 10 perturbed starts made
//! consistent; Prony: the 3 s run and the matrix-pencil fit). The
//! 3 s run is also timed with the matrix kept (`newton = auto`), and the Floquet point of the
//! elastic windmill (4 elements per blade: 194 directions, deflated to 90 as the integrator
//! damps the stiff modes). A 50-point sweep costs about
//! 50 Floquet points over the cores; its wall time is measured by `mbd stability` itself (see
//! the closing note of issue 7).

use criterion::{criterion_group, criterion_main, Criterion};
use mbd::settings::{NewtonMode, Request};
use mbd::study::sweep::{self, Method, SweepSpec};

mod common;

fn runs(c: &mut Criterion) {
    let source = common::model_text("windmill.mbd");
    for (label, newton) in [("", NewtonMode::Full), (", newton auto", NewtonMode::Auto)] {
        let request = Request {
            newton: Some(newton),
            ..Request::default()
        };
        if let Ok(compiled) = mbd::compile("windmill.mbd", &source, &[], request) {
            let mut out = Vec::with_capacity(1 << 22);
            c.bench_function(&format!("windmill: 3 s run, 6000 steps{label}"), |b| {
                b.iter(|| {
                    out.clear();
                    mbd::run(&compiled, &mut out).is_ok()
                })
            });
        }
    }
    for method in [Method::Floquet, Method::Prony] {
        let spec = SweepSpec {
            monodromy: mbd::solve::floquet::Monodromy::Tangent,
            param: "Omega_bar".to_string(),
            values: vec![1.5],
            methods: vec![method],
            period: None,
            signals: Vec::new(),
            window: None,
            samples: 300,
            threshold: 1e-2,
            refine: 0,
        };
        let compile = |extra: &[String]| {
            mbd::compile("windmill.mbd", &source, extra, Request::default())
                .map_err(|f| format!("{:?}", f.diagnostics))
        };
        c.bench_function(&format!("windmill: one {} point", method.name()), |b| {
            b.iter(|| sweep::sweep(&spec, &compile, &|_| {}).points[0].max_real())
        });
        if method == Method::Floquet {
            // The elastic windmill, 4 elements per blade (issue 22's target).
            let elastic = common::model_text("windmill_elastic.mbd");
            let compile = |extra: &[String]| {
                let mut sets = vec!["elements=4".to_string()];
                sets.extend_from_slice(extra);
                mbd::compile("windmill_elastic.mbd", &elastic, &sets, Request::default())
                    .map_err(|f| format!("{:?}", f.diagnostics))
            };
            let name = "windmill_elastic, 4 elements per blade: one floquet point";
            c.bench_function(name, |b| {
                b.iter(|| sweep::sweep(&spec, &compile, &|_| {}).points[0].max_real())
            });
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = runs
}
criterion_main!(benches);
