//! Studies: one model run many times and the runs compared (`mbd study`).
//!
//! Contract: runs a model once per job (an integrator setting and a step count), in parallel
//! over the cores, each in its own thread: compiled there (a [`Compiled`] holds `Rc`s and
//! stays in its thread), run by [`crate::run`] into an in-memory CSV, timed by the thread's
//! CPU clock around that call only, and read back as the studied channel's samples.
//! [`convergence`] compares the runs with a reference; [`stability`] looks for unbounded
//! growth. A failed run is a result (its row says so), never the end of a study.
//! Must not read or write files: the command line supplies the compile function (which reads
//! `use`d modules), any reference file's samples, and the writers for the CSV and the chart.

pub mod compare;
mod compile_error;
pub mod convergence;
pub mod fan;
mod items;
pub mod prony;
pub mod stability;
pub mod sweep;
pub mod tracking;

pub use compile_error::CompileError;
pub use items::{parse_alphas, split_list, IntegratorItem, StepList, UsageError};

use crate::settings::Request;
use crate::Compiled;
use compare::Samples;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Compiles the model with the given overrides (the `--set` params are the caller's). Called
/// from worker threads.
pub type Compile<'a> = dyn Fn(&Request) -> Result<Compiled, CompileError> + Sync + 'a;

/// Why a run gave no usable result: the failure's one-line message (`E0601 Newton iteration
/// failed at t = ...`), and the time it happened when known.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub message: String,
    pub t: Option<f64>,
}

/// What one run measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// The channel at every written step (up to the failure, for a failed run).
    pub samples: Samples,
    /// Thread CPU time of the call to [`crate::run`], in seconds.
    pub cpu_s: f64,
    /// Newton iterations of a finished run.
    pub newton_iterations: Option<usize>,
    pub failure: Option<Failure>,
}

impl Measured {
    fn failed(message: String) -> Measured {
        Measured {
            samples: Samples::default(),
            cpu_s: f64::NAN,
            newton_iterations: None,
            failure: Some(Failure { message, t: None }),
        }
    }
}

/// Compiles with `overrides` (every step written) and runs, timing the run alone.
pub fn measure(compile: &Compile, overrides: &Request, channel: &str) -> Measured {
    let mut o = overrides.clone();
    o.every = Some(1);
    let c = match compile(&o) {
        Ok(c) => c,
        Err(e) => return Measured::failed(e.to_string()),
    };
    let mut out: Vec<u8> = Vec::new();
    let start = thread_cpu_seconds();
    let result = crate::run(&c, &mut out);
    let cpu_s = thread_cpu_seconds() - start;
    let samples = String::from_utf8(out)
        .ok()
        .and_then(|text| crate::output::read_csv(&text).ok())
        .and_then(|(header, rows)| Samples::from_table(&header, &rows, channel).ok())
        .unwrap_or_default();
    match result {
        Ok(report) => Measured {
            samples,
            cpu_s,
            newton_iterations: Some(report.stats.newton_iterations),
            failure: None,
        },
        Err(f) => Measured {
            samples,
            cpu_s,
            newton_iterations: None,
            failure: Some(Failure {
                message: format!("{} {}", f.diagnostic.code.as_str(), f.diagnostic.message),
                t: f.failure.map(|r| r.t),
            }),
        },
    }
}

/// CPU time of the calling thread, in seconds (`CLOCK_THREAD_CPUTIME_ID`): a run's own cost,
/// whatever the other workers do.
#[cfg(unix)]
pub fn thread_cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes one timespec through a valid, exclusive pointer.
    let r = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if r != 0 {
        return f64::NAN;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

#[cfg(not(unix))]
pub fn thread_cpu_seconds() -> f64 {
    f64::NAN
}

/// Runs `work(0..jobs)` on `available_parallelism()` worker threads that pull job indices
/// from a shared counter (so list the costly jobs first). `None` for a job whose worker
/// panicked.
pub fn parallel<T: Send>(jobs: usize, work: impl Fn(usize) -> T + Sync) -> Vec<Option<T>> {
    let workers = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
        .clamp(1, jobs.max(1));
    let next = AtomicUsize::new(0);
    let mut done: Vec<Option<T>> = (0..jobs).map(|_| None).collect();
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                s.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        if i >= jobs {
                            break;
                        }
                        mine.push((i, work(i)));
                    }
                    mine
                })
            })
            .collect();
        for h in handles {
            if let Ok(mine) = h.join() {
                for (i, r) in mine {
                    done[i] = Some(r);
                }
            }
        }
    });
    done
}

/// Runs the jobs (`(overrides, channel)` each) in parallel, the costliest (most steps) first.
fn measure_all(compile: &Compile, jobs: &[(Request, usize)], channel: &str) -> Vec<Measured> {
    let mut order: Vec<usize> = (0..jobs.len()).collect();
    order.sort_by_key(|&j| std::cmp::Reverse(jobs[j].1));
    let results = parallel(order.len(), |k| {
        let (o, steps) = &jobs[order[k]];
        let mut o = o.clone();
        o.steps = Some(*steps);
        o.dt = None;
        measure(compile, &o, channel)
    });
    let mut out: Vec<Option<Measured>> = (0..jobs.len()).map(|_| None).collect();
    for (k, r) in results.into_iter().enumerate() {
        out[order[k]] = Some(r.unwrap_or_else(|| {
            Measured::failed("the run stopped on an internal error (a bug in mbd)".to_string())
        }));
    }
    out.into_iter()
        .map(|m| m.unwrap_or_else(|| Measured::failed("not run".to_string())))
        .collect()
}

/// A number for a CSV cell: full precision, empty when absent or not finite.
fn cell(x: Option<f64>) -> String {
    match x {
        Some(v) if v.is_finite() => format!("{:?}", v + 0.0),
        _ => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parallel_returns_every_job_in_order() {
        let out = parallel(17, |i| i * i);
        let want: Vec<Option<usize>> = (0..17).map(|i| Some(i * i)).collect();
        assert_eq!(out, want);
        assert!(parallel(0, |i| i).is_empty());
    }
}
