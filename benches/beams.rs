//! Benchmarks of the beam runtime.
//!
//! `scaling`: per-step cost of the rotating beam (P1) against its number of three-node elements,
//! 10 to 10,000 (about 60 to 120,000 unknowns): the same 4 HHT steps of the paper's step size
//! (1/360 of the half turn) are run at every size, so the median divided by 4 is the cost of one
//! step. The cost must grow linearly with the number of elements (printed per element).
//!
//! `fig6`: the CPU time of the paper's Fig. 6 runs, the rotating beam with 4 elements over half a
//! turn in 12, 18, 36, 180, 360 and 720 steps; the relative error (phi - pi)/pi of each is printed
//! once before timing, so error and time sit side by side.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use mbd::settings::{Method, Request};
use std::time::Duration;

mod common;

fn source() -> String {
    common::model_text("rotating_beam.mbd")
}

fn scaling(c: &mut Criterion) {
    let text = source();
    let mut group = c.benchmark_group("rotating_beam: 4 steps");
    group.sample_size(10);
    group.warm_up_time(Duration::from_millis(500));
    for elements in [10usize, 100, 1_000, 10_000] {
        let sets = vec![format!("elements={elements}")];
        let dt = std::f64::consts::PI / 98.17 / 360.0;
        let o = Request {
            dt: Some(dt),
            until: Some(4.0 * dt),
            ..Request::default()
        };
        let Ok(compiled) = mbd::compile("rotating_beam", &text, &sets, o) else {
            eprintln!("{elements} elements: does not compile");
            continue;
        };
        let mut out = Vec::with_capacity(1 << 16);
        match mbd::run(&compiled, &mut out) {
            Ok(r) => eprintln!(
                "{elements} elements: {} steps, {:.2} Newton iterations per step",
                r.stats.steps,
                r.stats.newton_iterations as f64 / r.stats.steps as f64
            ),
            Err(f) => eprintln!("{elements} elements: failed ({})", f.diagnostic.message),
        }
        group.bench_with_input(BenchmarkId::from_parameter(elements), &compiled, |b, c| {
            b.iter(|| {
                out.clear();
                mbd::run(c, &mut out).is_ok()
            })
        });
    }
    group.finish();
}

fn fig6(c: &mut Criterion) {
    let text = source();
    let mut group = c.benchmark_group("rotating_beam: half turn (Fig. 6)");
    group.sample_size(10);
    let runs = [12usize, 18, 36, 180, 360, 720]
        .map(|n| (n, Method::Hht))
        .into_iter()
        .chain([36usize, 180, 720].map(|n| (n, Method::Fet)));
    for (steps, integrator) in runs {
        let o = Request {
            steps: Some(steps),
            method: Some(integrator),
            ..Request::default()
        };
        let label = match integrator {
            Method::Fet => format!("fet/{steps}"),
            _ => steps.to_string(),
        };
        let Ok(compiled) = mbd::compile("rotating_beam", &text, &[], o) else {
            continue;
        };
        let mut out = Vec::with_capacity(1 << 20);
        if mbd::run(&compiled, &mut out).is_ok() {
            let csv = String::from_utf8_lossy(&out);
            let last = csv
                .lines()
                .last()
                .unwrap_or_else(|| panic!("{label} steps: the run wrote no CSV"));
            let phi: f64 = last
                .split(',')
                .nth(1)
                .and_then(|s| s.trim().parse().ok())
                .unwrap_or_else(|| panic!("{label} steps: no phi in the last CSV row `{last}`"));
            let pi = std::f64::consts::PI;
            eprintln!("{label} steps: (phi - pi)/pi = {:.3e}", (phi - pi) / pi);
        }
        group.bench_with_input(BenchmarkId::from_parameter(label), &compiled, |b, c| {
            b.iter(|| {
                out.clear();
                mbd::run(c, &mut out).is_ok()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, scaling, fig6);
criterion_main!(benches);
