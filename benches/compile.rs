//! Benchmarks of the compiler on the validation models: parse, elaborate the stdlib components,
//! build, topology checks (ranks block by block) and unknown numbering; and its growth with
//! size (issue 21): a chain of 10 to 10,000 links, the elastic windmill with 4 to 64 blades of
//! 2 to 20 elements. Linear cost shows as a time proportional to the size.

use criterion::{criterion_group, criterion_main, Criterion};
use mbd::settings::Request;

mod common;

fn compile(c: &mut Criterion) {
    for (name, sets) in [
        ("two_bar", vec![]),
        ("windmill", vec![]),
        ("windmill", vec!["blades=8".to_string()]),
        ("windmill_elastic", vec![]),
        ("rotating_beam", vec!["elements=40".to_string()]),
    ] {
        let text = common::model_text(&format!("{name}.mbd"));
        let label = format!("check {name} {}", sets.join(" "));
        c.bench_function(label.trim(), |b| {
            b.iter(|| mbd::compile(name, &text, &sets, Request::default()).is_ok())
        });
    }
}

fn sizes(c: &mut Criterion) {
    let mut group = c.benchmark_group("check chain");
    group.sample_size(10);
    for n in [10, 100, 1000, 10000] {
        let (text, sets) = common::chain(n, 10);
        assert!(mbd::compile("chain.mbd", &text, &sets, Request::default()).is_ok());
        group.bench_function(format!("{n} links"), |b| {
            b.iter(|| mbd::compile("chain.mbd", &text, &sets, Request::default()).is_ok())
        });
    }
    group.finish();
    let mut group = c.benchmark_group("check elastic rotor");
    group.sample_size(10);
    let text = common::model_text("windmill_elastic.mbd");
    for (blades, elements) in [(4, 2), (4, 20), (16, 20), (64, 20)] {
        let sets = vec![format!("blades={blades}"), format!("elements={elements}")];
        assert!(mbd::compile("windmill_elastic.mbd", &text, &sets, Request::default()).is_ok());
        group.bench_function(format!("{blades} blades of {elements} elements"), |b| {
            b.iter(|| {
                mbd::compile("windmill_elastic.mbd", &text, &sets, Request::default()).is_ok()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, compile, sizes);
criterion_main!(benches);
