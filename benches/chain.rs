//! Benchmarks of the cost per Newton iteration against model size (issue 20): a planar chain
//! of N rigid rods hinged end to end by revolute joints (13 unknowns a link: 6 for the rod, the
//! hinge's angle and its 6 multipliers), hanging from a pin and falling under gravity, for
//! N = 10, 100, 1,000 and 10,000, HHT -0.1 at 1 ms. Each size runs one step and `STEPS`
//! steps, and the Newton iterations of both are printed once: a run's setup (the ordering and
//! symbolic factorization, the consistent start) is in both, so the cost per iteration is the
//! difference of the medians over the difference of the iterations. Linear cost shows as a
//! per-iteration figure proportional to N.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use mbd::settings::Request;

mod common;
use common::chain;

/// Steps of the longer run.
const STEPS: usize = 11;

fn runs(c: &mut Criterion) {
    let mut group = c.benchmark_group("chain");
    group.sample_size(10);
    for (n, steps) in [10, 100, 1000, 10000]
        .into_iter()
        .flat_map(|n| [(n, 1), (n, STEPS)])
    {
        let (source, sets) = chain(n, steps);
        let compiled = match mbd::compile("chain.mbd", &source, &sets, Request::default()) {
            Ok(c) => c,
            Err(f) => panic!("the {n}-link chain does not compile: {:?}", f.diagnostics),
        };
        let mut out = Vec::with_capacity(1 << 16);
        match mbd::run(&compiled, &mut out) {
            Ok(r) => eprintln!(
                "chain of {n}: {} unknowns, {} steps, {} Newton iterations",
                compiled.lowered.system.len(),
                r.stats.steps,
                r.stats.newton_iterations
            ),
            Err(f) => panic!("the {n}-link chain fails: {}", f.diagnostic.message),
        }
        let id = BenchmarkId::new(format!("{steps} steps"), n);
        group.bench_with_input(id, &n, |b, _| {
            b.iter(|| {
                out.clear();
                mbd::run(&compiled, &mut out).is_ok()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, runs);
criterion_main!(benches);
