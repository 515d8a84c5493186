//! Issue 20, item 5: no allocation per step. A counting allocator (per thread, so the other
//! tests running in parallel do not count) measures the heap allocations of a run of N steps
//! and of 2N steps with the same written rows: their difference is what the steps allocate.
//! Before this test, every step allocated 2 to 8 times (the constraint scaling's mean mass and
//! stiffness collected into vectors) and the windmill's multiblade probes 4 times a row.

use crate::common::read;
use mbd::settings::{Method, NewtonMode, Request};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static COUNT: Cell<u64> = const { Cell::new(0) };
}

// SAFETY: every call is forwarded to the system allocator unchanged; the count is a
// thread-local `Cell` without a destructor, so counting allocates nothing.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        // SAFETY: forwarded with the caller's layout.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System.alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        // SAFETY: forwarded with the caller's layout.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = COUNT.try_with(|c| c.set(c.get() + 1));
        // SAFETY: `ptr` came from this allocator with `layout`.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn count() -> u64 {
    COUNT.with(|c| c.get())
}

/// Allocations of a run of `steps` steps writing only its first and last rows.
/// `base` sets the method and Newton's mode; `every: Some(1)` writes every step's row.
fn allocations(model: &str, sets: &[&str], steps: usize, base: &Request) -> u64 {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    // The model's own step: `until` is cut to `steps` of it.
    let dt = mbd::compile(model, &read(model), &sets, Request::default())
        .unwrap_or_else(|f| panic!("{model}: {:?}", f.diagnostics))
        .settings
        .dt;
    let request = Request {
        until: Some(dt * steps as f64),
        steps: Some(steps),
        every: Some(base.every.unwrap_or(steps)),
        ..base.clone()
    };
    let c = mbd::compile(model, &read(model), &sets, request)
        .unwrap_or_else(|f| panic!("{model}: {:?}", f.diagnostics));
    let mut out = std::io::sink();
    let before = count();
    let r = mbd::run(&c, &mut out).unwrap_or_else(|f| panic!("{model}: {}", f.diagnostic.message));
    assert_eq!(r.stats.steps, steps, "{model}");
    count() - before
}

#[test]
fn steps_allocate_nothing() {
    let newton = |mode| Request {
        newton: Some(mode),
        ..Request::default()
    };
    let method = |m| Request {
        method: Some(m),
        ..Request::default()
    };
    let every_row = Request {
        every: Some(1),
        ..Request::default()
    };
    let default = Request::default();
    let cases: &[(&str, &[&str], &Request)] = &[
        ("models/pendulum.mbd", &[], &default),
        ("models/pendulum.mbd", &[], &every_row),
        ("models/pendulum.mbd", &[], &method(Method::Fet)),
        (
            "models/pendulum.mbd",
            &[],
            &method(Method::GeneralizedAlpha),
        ),
        ("models/two_bar.mbd", &[], &default),
        ("models/windmill.mbd", &[], &default),
        ("models/windmill.mbd", &[], &every_row),
        ("models/windmill.mbd", &[], &newton(NewtonMode::Auto)),
        (
            "models/windmill.mbd",
            &["Omega_bar=2"],
            &newton(NewtonMode::Modified),
        ),
        ("models/rotating_beam.mbd", &[], &default),
        ("models/windmill_elastic.mbd", &[], &default),
        // Not FET on beams: its end velocities solve the constrained mass matrix every step
        // with faer's supernodal pivoting LU, which allocates its contribution blocks in
        // every factorization (faer 0.24; measured 19 allocations a step on the elastic
        // windmill). FET on the pendulum's simplicial pattern allocates nothing.
    ];
    let counts: Vec<(String, u64, u64)> = cases
        .iter()
        .map(|(model, sets, base)| {
            // A first run pays for what the process sets up once (lazy statics, thread-locals).
            allocations(model, sets, 10, base);
            (
                format!("{model} {sets:?} {base:?}"),
                allocations(model, sets, 50, base),
                allocations(model, sets, 100, base),
            )
        })
        .collect();
    let text: Vec<String> = counts
        .iter()
        .map(|(what, a, b)| format!("{what}: {a} allocations in 50 steps, {b} in 100"))
        .collect();
    let text = text.join("\n");
    eprintln!("{text}");
    assert!(
        counts.iter().all(|(_, a, b)| a == b),
        "the steps allocate:\n{text}"
    );
}
