//! Benchmarks of the rigid runtime: the two-bar runs of P3 (1,000 steps) and P4 under each
//! rotation treatment of HHT, with HHT's matrix kept (`newton = auto`), and under time
//! finite elements. Per-step cost = the median divided by 1,000; Newton iterations per step
//! are printed once before timing.

use criterion::{criterion_group, criterion_main, Criterion};
use mbd::settings::{Method, NewtonMode, Request, Rotations};

mod common;

fn runs(c: &mut Criterion) {
    for model in ["two_bar.mbd", "two_bar_spin.mbd", "pendulum.mbd"] {
        let source = common::model_text(model);
        for (name, rotations, integrator, newton) in [
            (
                "incremental rotations",
                Rotations::Incremental,
                Method::Hht,
                NewtonMode::Full,
            ),
            (
                "conformal rotations",
                Rotations::Conformal,
                Method::Hht,
                NewtonMode::Full,
            ),
            (
                "fet rotations",
                Rotations::Incremental,
                Method::Fet,
                NewtonMode::Full,
            ),
            (
                "incremental rotations, newton auto",
                Rotations::Incremental,
                Method::Hht,
                NewtonMode::Auto,
            ),
        ] {
            let o = Request {
                rotations: Some(rotations),
                method: Some(integrator),
                newton: Some(newton),
                ..Request::default()
            };
            let Ok(compiled) = mbd::compile(model, &source, &[], o) else {
                continue;
            };
            let mut out = Vec::with_capacity(1 << 20);
            match mbd::run(&compiled, &mut out) {
                Ok(r) => eprintln!(
                    "{model} {name}: {} steps, {:.2} Newton iterations per step, {} halvings",
                    r.stats.steps,
                    r.stats.newton_iterations as f64 / r.stats.steps as f64,
                    r.stats.halvings
                ),
                Err(f) => eprintln!("{model} {name}: failed ({})", f.diagnostic.message),
            }
            c.bench_function(&format!("{model}: run, {name}"), |b| {
                b.iter(|| {
                    out.clear();
                    mbd::run(&compiled, &mut out).is_ok()
                })
            });
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = runs
}
criterion_main!(benches);
