//! Benchmarks of one step and one Newton iteration (issue 20, item 7), without a run's setup:
//! each sample makes the integrator and its consistent start untimed, then times `steps`
//! steps from there and reports the time divided by the steps ("per step") or by the Newton
//! iterations they took ("per Newton iteration"). Models: the pendulum (P2, its solve block),
//! the two-bar (theta2_0 = 0 at 1 ms), the windmill (P5 at 0.5 ms) and a chain of 10 to
//! 10,000 links (`models/chain.mbd`, 1 ms). No rows are written. The iterations per step of
//! each model are printed once.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use mbd::settings::Request;
use mbd::solve::{Integrator, Stop};
use std::time::{Duration, Instant};

mod common;

/// One model: its name in the report, text, `--set`s, step and steps a sample times.
struct Case {
    name: String,
    text: String,
    sets: Vec<String>,
    dt: Option<f64>,
    steps: usize,
}

/// The time of `steps` steps from a consistent start, and the Newton iterations they took.
fn timed(compiled: &mbd::Compiled, steps: usize) -> (Duration, usize) {
    let sys = &compiled.lowered.system;
    let mut it = match Integrator::new(sys, &compiled.settings) {
        Ok(it) => it,
        Err(f) => panic!("{}: no integrator: {}", compiled.model.name, f.detail),
    };
    if let Err(f) = it.initialize() {
        panic!("{}: no consistent start: {}", compiled.model.name, f.detail);
    }
    it.set_run(steps);
    let before = it.stats().newton_iterations;
    let start = Instant::now();
    let ran = it.run(|_, _| Ok::<(), ()>(()));
    let elapsed = start.elapsed();
    if let Err(Stop::Failed(f)) = ran {
        panic!(
            "{}: failed at t = {} s: {}",
            compiled.model.name, f.t, f.detail
        );
    }
    (elapsed, it.stats().newton_iterations - before)
}

fn cases() -> Vec<Case> {
    let mut cases = vec![
        Case {
            name: "pendulum".into(),
            text: common::model_text("pendulum.mbd"),
            sets: Vec::new(),
            dt: None,
            steps: 1000,
        },
        Case {
            name: "two-bar, theta2_0 = 0, 1 ms".into(),
            text: common::model_text("two_bar.mbd"),
            sets: vec!["theta2_0=0".into()],
            dt: Some(1e-3),
            steps: 1000,
        },
        Case {
            name: "windmill".into(),
            text: common::model_text("windmill.mbd"),
            sets: Vec::new(),
            dt: None,
            steps: 600,
        },
    ];
    for (n, steps) in [(10, 200), (100, 50), (1000, 10), (10000, 4)] {
        let (text, mut sets) = common::chain(n, steps);
        sets.retain(|s| !s.starts_with("steps="));
        cases.push(Case {
            name: format!("chain, {n} links"),
            text,
            sets,
            dt: None,
            steps,
        });
    }
    cases
}

fn steps(c: &mut Criterion) {
    let mut group = c.benchmark_group("step");
    group.sample_size(10);
    for case in cases() {
        let request = Request {
            dt: case.dt,
            ..Request::default()
        };
        let compiled = match mbd::compile("bench.mbd", &case.text, &case.sets, request) {
            Ok(c) => c,
            Err(f) => panic!("{} does not compile: {:?}", case.name, f.diagnostics),
        };
        let (_, its) = timed(&compiled, case.steps);
        eprintln!(
            "{}: {} unknowns, {:.3} Newton iterations a step over {} steps",
            case.name,
            compiled.lowered.system.len(),
            its as f64 / case.steps as f64,
            case.steps
        );
        for per_iteration in [false, true] {
            let what = if per_iteration {
                "per Newton iteration"
            } else {
                "per step"
            };
            let id = BenchmarkId::new(what, &case.name);
            group.bench_function(id, |b| {
                b.iter_custom(|samples| {
                    let mut total = Duration::ZERO;
                    for _ in 0..samples {
                        let (t, its) = timed(&compiled, case.steps);
                        let per = if per_iteration { its } else { case.steps };
                        total += t / per.max(1) as u32;
                    }
                    total
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, steps);
criterion_main!(benches);
