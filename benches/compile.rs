//! Benchmarks of the compiler on the validation models: parse, elaborate the stdlib components,
//! build, topology checks (ranks block by block) and unknown numbering.

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

criterion_group!(benches, compile);
criterion_main!(benches);
