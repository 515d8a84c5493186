//! Benchmarks: parse + lower, and the 200-step pendulum (P2) run.

use criterion::{criterion_group, criterion_main, Criterion};
use mbd::settings::Request;

mod common;

fn pendulum_text() -> String {
    common::model_text("pendulum.mbd")
}

fn compile(c: &mut Criterion) {
    let text = pendulum_text();
    c.bench_function("pendulum: parse + check + lower", |b| {
        b.iter(|| mbd::compile("pendulum.mbd", &text, &[], Request::default()).is_ok())
    });
}

fn run(c: &mut Criterion) {
    let text = pendulum_text();
    let Ok(compiled) = mbd::compile("pendulum.mbd", &text, &[], Request::default()) else {
        return;
    };
    let mut out = Vec::with_capacity(1 << 16);
    c.bench_function("pendulum: 200 HHT steps (run + CSV)", |b| {
        b.iter(|| {
            out.clear();
            mbd::run(&compiled, &mut out).is_ok()
        })
    });
}

criterion_group!(benches, compile, run);
criterion_main!(benches);
