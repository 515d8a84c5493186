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
pub mod convergence;
pub mod fan;
pub mod prony;
pub mod stability;
pub mod sweep;

use crate::settings::{self, Method, Request};
use crate::Compiled;
use compare::Samples;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Compiles the model with the given overrides (the `--set` params are the caller's); the
/// error is a one-line message. Called from worker threads.
pub type Compile<'a> = dyn Fn(&Request) -> Result<Compiled, String> + Sync + 'a;

/// One item of `--integrator LIST`, kept as written for the CSV.
#[derive(Clone, Debug, PartialEq)]
pub struct IntegratorItem {
    /// As written: `hht`, `hht:-0.3`, `generalized-alpha:0.5`, `fet`.
    pub text: String,
    pub integrator: Method,
    /// HHT alpha (`hht:ALPHA`), in [-1/3, 0]; `None`: the model's.
    pub alpha: Option<f64>,
    /// Generalized-alpha spectral radius at infinity (`generalized-alpha:RHO`), in [0, 1].
    pub rho_inf: Option<f64>,
}

impl IntegratorItem {
    /// Parses `hht`, `hht:ALPHA`, `generalized-alpha`, `generalized-alpha:RHO_INF` or `fet`.
    pub fn parse(text: &str) -> Result<IntegratorItem, String> {
        let text = text.trim();
        let (name, arg) = match text.split_once(':') {
            Some((n, a)) => (n, Some(a)),
            None => (text, None),
        };
        let item = |integrator, alpha, rho_inf| IntegratorItem {
            text: text.to_string(),
            integrator,
            alpha,
            rho_inf,
        };
        match (name, arg) {
            ("hht", a) => {
                let alpha = a
                    .map(|a| bounded(text, "alpha", a, settings::ALPHA))
                    .transpose()?;
                Ok(item(Method::Hht, alpha, None))
            }
            ("generalized-alpha" | "generalized_alpha", a) => {
                let rho = a
                    .map(|a| bounded(text, "rho_inf", a, settings::RHO_INF))
                    .transpose()?;
                Ok(item(Method::GeneralizedAlpha, None, rho))
            }
            ("fet", None) => Ok(item(Method::Fet, None, None)),
            ("fet", Some(_)) => Err(format!("`{text}`: fet takes no parameter")),
            _ => Err(format!(
                "unknown integrator `{text}`; the items are hht, hht:ALPHA (e.g. hht:-0.3), generalized-alpha, generalized-alpha:RHO_INF (e.g. generalized-alpha:0.5) and fet"
            )),
        }
    }

    /// `base` with this integrator setting.
    pub fn request(&self, base: &Request) -> Request {
        let mut o = base.clone();
        o.method = Some(self.integrator);
        o.alpha = self.alpha.or(base.alpha);
        o.rho_inf = self.rho_inf.or(base.rho_inf);
        o
    }
}

fn bounded(item: &str, what: &str, text: &str, range: settings::Range) -> Result<f64, String> {
    let v: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{item}`: {what} `{text}` is not a number"))?;
    if !range.contains(v) {
        return Err(format!("`{item}`: {what} = {v} is outside {}", range.text));
    }
    Ok(v)
}

/// The items of a comma-separated list (`--steps 100,200`); an empty list or item is an error.
pub fn split_list<'t>(text: &'t str, flag: &str) -> Result<Vec<&'t str>, String> {
    let items: Vec<&str> = text.split(',').map(str::trim).collect();
    if items.iter().any(|i| i.is_empty()) {
        return Err(format!(
            "{flag} takes a comma-separated list without empty items, got `{text}`"
        ));
    }
    Ok(items)
}

/// The runs' steps: `--steps LIST` (counts; dt = until / N) or `--dt LIST` (seconds;
/// N = round(until / dt)). Either way every run ends at the model's end time.
#[derive(Clone, Debug, PartialEq)]
pub enum StepList {
    Counts(Vec<usize>),
    Dt(Vec<f64>),
}

impl StepList {
    pub fn parse_counts(text: &str) -> Result<StepList, String> {
        let mut out = Vec::new();
        for s in split_list(text, "--steps")? {
            match s.parse::<usize>() {
                Ok(n) if n >= 1 => out.push(n),
                _ => {
                    return Err(format!(
                        "--steps: `{s}` is not a whole number of steps of at least 1"
                    ))
                }
            }
        }
        Ok(StepList::Counts(out))
    }

    pub fn parse_dt(text: &str) -> Result<StepList, String> {
        let mut out = Vec::new();
        for s in split_list(text, "--dt")? {
            match s.parse::<f64>() {
                Ok(d) if d > 0.0 && d.is_finite() => out.push(d),
                _ => return Err(format!("--dt: `{s}` is not a positive number of seconds")),
            }
        }
        Ok(StepList::Dt(out))
    }

    /// Step counts for a run that ends at `until`.
    pub fn counts(&self, until: f64) -> Result<Vec<usize>, String> {
        match self {
            StepList::Counts(n) => Ok(n.clone()),
            StepList::Dt(dts) => dts
                .iter()
                .map(|&dt| {
                    let n = (until / dt).round();
                    if (1.0..=1e9).contains(&n) {
                        Ok(n as usize)
                    } else {
                        Err(format!(
                            "--dt {dt} s does not fit the run's {until} s (round(until / dt) = {n})"
                        ))
                    }
                })
                .collect(),
        }
    }
}

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
        Err(e) => return Measured::failed(e),
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
    fn integrator_items_parse_as_written() {
        let hht = IntegratorItem::parse("hht:-0.3").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((hht.integrator, hht.alpha), (Method::Hht, Some(-0.3)));
        assert_eq!(hht.text, "hht:-0.3");
        let ga = IntegratorItem::parse("generalized-alpha:0.5").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            (ga.integrator, ga.rho_inf),
            (Method::GeneralizedAlpha, Some(0.5))
        );
        assert!(IntegratorItem::parse("fet").is_ok());
        for bad in [
            "hht:0.5",
            "hht:x",
            "rk4",
            "generalized-alpha:2",
            "fet:1",
            "",
        ] {
            assert!(IntegratorItem::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn step_lists_keep_the_end_time() {
        let dt = StepList::parse_dt("0.1,0.05").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(dt.counts(1.0), Ok(vec![10, 20]));
        assert!(StepList::parse_dt("0.1,,0.05").is_err());
        assert!(StepList::parse_counts("0").is_err());
        assert!(StepList::parse_dt("5")
            .map(|d| d.counts(1.0).is_err())
            .unwrap_or(false));
    }

    #[test]
    fn parallel_returns_every_job_in_order() {
        let out = parallel(17, |i| i * i);
        let want: Vec<Option<usize>> = (0..17).map(|i| Some(i * i)).collect();
        assert_eq!(out, want);
        assert!(parallel(0, |i| i).is_empty());
    }
}
