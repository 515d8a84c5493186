//! Benchmarks of the cost per Newton iteration against model size (issue 20): a planar chain
//! of N rigid rods hinged end to end by revolute joints (13 unknowns a link: 6 for the rod, the
//! hinge's angle and its 6 multipliers), hanging from a pin and falling under gravity, for
//! N = 10, 100, 1,000 and 10,000. Each run is 5 steps of HHT -0.1 at 1 ms; the Newton
//! iterations of a run are printed once, so the cost per iteration is the median over that
//! count. Linear cost shows as a per-iteration figure proportional to N.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use mbd::settings::Request;

/// The chain's text, `n` links of 0.1 m and 0.1 kg.
pub fn chain(n: usize) -> String {
    format!(
        "model chain \"{n} rods on revolute hinges\"
param l = 0.1 m
gravity = (0, -9.81, 0) m/s^2
ground earth
for i in 1..={n} {{
    rigid_rod rod[i] {{ from = ((i - 1) * l, 0, 0), to = (i * l, 0, 0), mass = 0.1 kg }}
}}
joint pin = revolute(earth, rod[1].start) {{ axis = z }}
for i in 1..{n} {{
    joint hinge[i] = revolute(rod[i].end, rod[i + 1].start) {{ axis = z }}
}}
output tip_y = rod[{n}].end.position.y
solve hht(alpha = -0.1) {{ dt = 1 ms, until = 5 ms }}
"
    )
}

fn runs(c: &mut Criterion) {
    let mut group = c.benchmark_group("chain: 5 steps");
    group.sample_size(10);
    for n in [10, 100, 1000, 10000] {
        let source = chain(n);
        let compiled = match mbd::compile("chain.mbd", &source, &[], Request::default()) {
            Ok(c) => c,
            Err(f) => panic!("the {n}-link chain does not compile: {:?}", f.diagnostics),
        };
        let mut out = Vec::with_capacity(1 << 16);
        match mbd::run(&compiled, &mut out) {
            Ok(r) => eprintln!(
                "chain of {n}: {} unknowns, {} steps, {} Newton iterations",
                compiled.lowered.as_ref().map_or(0, |l| l.system.len()),
                r.stats.steps,
                r.stats.newton_iterations
            ),
            Err(f) => panic!("the {n}-link chain fails: {}", f.diagnostic.message),
        }
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
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
