//! `mbd._mbd`: the Python package's extension. Plain data in and out (texts, numbers, bytes
//! of f64, JSON of diagnostics); the package `mbd` (`python/mbd/__init__.py`) builds the typed
//! API on it. Every analysis compiles the model from its text in the call, with the GIL
//! released, on a worker thread (kept for later calls) that the calling thread watches for
//! Ctrl-C: on a KeyboardInterrupt it stops the run before its next step (as the CLI's Ctrl-C
//! does), waits for it and raises.

use mbd::diagnostics::{render_json, Diagnostic};
use mbd::loader::FsLoader;
use mbd::settings::{Method, NewtonMode, Request, Rotations, Start};
use mbd::study::sweep;
use mbd::{CompileFailure, Compiled};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{mpsc, Mutex};
use std::time::Duration;

mod studies;
mod sweeps;

use studies::study;
use sweeps::{merge, stability, stability_share};

/// How often the waiting thread looks for Ctrl-C.
const WATCH: Duration = Duration::from_millis(50);

/// A job for a worker thread: it runs the work and returns what hands its result over, which
/// the worker calls once it is idle again.
type Job = Box<dyn FnOnce() -> Box<dyn FnOnce() + Send> + Send>;

/// The idle workers, each by its number and the sender of its jobs, and the process they
/// belong to. A worker outlives its call and is reused: a fresh thread's run pays for its
/// stack's and heap's first pages, and the thread's start and end. The pendulum's 50 steps at
/// 0.02 s, `compile` then `run` (medians of 41 pairs, two series each): 80-85 us of the run's
/// thread CPU and 628-659 us of wall clock on fresh threads, 69-72 and 335-363 us on a reused
/// one. A worker idle for [`LINGER`] ends.
static IDLE: Mutex<(u32, Vec<Idle>)> = Mutex::new((0, Vec::new()));

/// An idle worker: its number and the sender of its jobs.
type Idle = (u64, mpsc::Sender<Job>);

/// The workers' numbers.
static WORKERS: AtomicU64 = AtomicU64::new(0);

/// How long a worker waits idle for its next call before it ends (so that a process that ran
/// mbd a while ago, and forks now, has no thread of mbd's).
const LINGER: Duration = Duration::from_secs(1);

/// An idle worker of this process, or a new one. A child forked from a process with idle
/// workers has none of their threads: the process id tells, and the child starts its own. The
/// lock is only tried: a lock that a fork left held, or another call holding it, costs a new
/// thread, never a wait.
fn worker() -> PyResult<mpsc::Sender<Job>> {
    let pid = std::process::id();
    if let Ok(mut idle) = IDLE.try_lock() {
        if idle.0 != pid {
            *idle = (pid, Vec::new());
        }
        if let Some((_, tx)) = idle.1.pop() {
            return Ok(tx);
        }
    }
    spawn(pid)
}

/// A new worker (64 MiB of stack, as the compiler's recursion may need).
fn spawn(pid: u32) -> PyResult<mpsc::Sender<Job>> {
    let (tx, rx) = mpsc::channel::<Job>();
    let me = tx.clone();
    let number = WORKERS.fetch_add(1, Ordering::Relaxed);
    std::thread::Builder::new()
        .name("mbd".to_string())
        .stack_size(64 << 20)
        .spawn(move || loop {
            let job = match rx.recv_timeout(LINGER) {
                Ok(job) => job,
                // Idle too long: the worker leaves the idle list and ends, unless a call has
                // just taken it from there (its job is on the way).
                Err(_) => match IDLE.lock() {
                    Ok(mut idle) => match idle.1.iter().position(|(n, _)| *n == number) {
                        Some(at) => {
                            idle.1.swap_remove(at);
                            return;
                        }
                        None => continue,
                    },
                    Err(_) => return,
                },
            };
            // A job that panicked ends this worker (its result's sender dropped, its caller
            // told of an internal error); the next call starts another.
            let Ok(deliver) = std::panic::catch_unwind(std::panic::AssertUnwindSafe(job)) else {
                return;
            };
            // Idle again before the result is handed over, so that the caller's next call
            // finds this worker. The lock is only tried, as by a caller: in a child forked
            // while the lock was held it stays held, and a worker that waited for it would
            // never hand its result over; a worker that finds it busy ends after this job.
            let back = match IDLE.try_lock() {
                Ok(mut idle) if idle.0 == pid => {
                    idle.1.push((number, me.clone()));
                    true
                }
                _ => false,
            };
            deliver();
            if !back {
                return;
            }
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start a thread: {e}")))?;
    Ok(tx)
}

/// Runs `work` with the GIL released on a worker thread; a KeyboardInterrupt (or any signal
/// handler's exception) stops mbd's runs, waits for `work` to return, and is raised.
pub(crate) fn interruptible<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce() -> T + Send + 'static,
) -> PyResult<T> {
    py.detach(|| {
        let (tx, rx) = mpsc::channel();
        let job: Job = Box::new(move || {
            let out = work();
            Box::new(move || {
                let _ = tx.send(out);
            })
        });
        // A worker that ended as it was taken hands the job back: a new one takes it.
        if let Err(mpsc::SendError(job)) = worker()?.send(job) {
            spawn(std::process::id())?
                .send(job)
                .map_err(|_| PyRuntimeError::new_err("mbd's worker thread has stopped"))?;
        }
        let mut signal: Option<PyErr> = None;
        let result = loop {
            match rx.recv_timeout(WATCH) {
                Ok(r) => break Some(r),
                Err(mpsc::RecvTimeoutError::Disconnected) => break None,
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if signal.is_none() {
                        if let Err(e) = Python::attach(|py| py.check_signals()) {
                            mbd::solve::interrupt();
                            signal = Some(e);
                        }
                    }
                }
            }
        };
        if let Some(e) = signal {
            mbd::solve::clear_interrupt();
            return Err(e);
        }
        result.ok_or_else(|| PyRuntimeError::new_err("mbd stopped on an internal error"))
    })
}

/// The command line's request from the keywords of `run`, `modes` and `stability`.
fn request(solve: Option<&Bound<'_, PyDict>>) -> PyResult<Request> {
    let mut r = Request::default();
    let Some(d) = solve else { return Ok(r) };
    fn named<T: Copy>(what: &str, v: &str, table: &[(&'static str, T)]) -> PyResult<T> {
        let v = v.replace('_', "-");
        table
            .iter()
            .find(|(n, _)| n.replace('_', "-") == v)
            .map(|(_, m)| *m)
            .ok_or_else(|| {
                let names: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
                PyValueError::new_err(format!(
                    "{what} must be one of {}, got `{v}`",
                    names.join(", ")
                ))
            })
    }
    for (k, v) in d.iter() {
        let key: String = k.extract()?;
        if v.is_none() {
            continue;
        }
        match key.as_str() {
            "integrator" => {
                r.method = Some(named::<Method>(&key, &v.extract::<String>()?, &Method::FLAGS)?)
            }
            "rotations" => {
                r.rotations = Some(named::<Rotations>(&key, &v.extract::<String>()?, &Rotations::FLAGS)?)
            }
            "start" => r.start = Some(named::<Start>(&key, &v.extract::<String>()?, &Start::FLAGS)?),
            "newton" => {
                r.newton = Some(named::<NewtonMode>(&key, &v.extract::<String>()?, &NewtonMode::FLAGS)?)
            }
            "alpha" => r.alpha = Some(v.extract()?),
            "rho_inf" => r.rho_inf = Some(v.extract()?),
            "dt" => r.dt = Some(v.extract()?),
            "until" => r.until = Some(v.extract()?),
            "steps" => r.steps = Some(v.extract()?),
            "every" => r.every = Some(v.extract()?),
            "tolerance" => r.tolerance = Some(v.extract()?),
            "max_iterations" => r.max_iterations = Some(v.extract()?),
            other => {
                return Err(PyValueError::new_err(format!(
                    "unknown solver setting `{other}`: the settings are integrator, alpha, rho_inf, rotations, dt, steps, until, every, start, tolerance, max_iterations, newton"
                )))
            }
        }
    }
    if let Some(bad) = r.check().first() {
        let m = bad.flag_message();
        return Err(PyValueError::new_err(
            m.strip_prefix("--").unwrap_or(&m).replace('-', "_"),
        ));
    }
    Ok(r)
}

/// The model text compiled, or its diagnostics as JSON.
pub(crate) fn compile(
    name: &str,
    text: &str,
    sets: &[String],
    r: Request,
) -> Result<Compiled, String> {
    mbd::compile_with(name, text, sets, r, &FsLoader::new()).map_err(
        |CompileFailure {
             sources,
             diagnostics,
         }| render_json(&diagnostics, &sources),
    )
}

/// Compiles a model: `(ok, diagnostics JSON, info)`; with `lint` the sizing lint's warnings
/// too. `info`: the model's name, title, output channels, params (name, SI value or None) and
/// the resolved step and end time.
#[pyfunction]
#[pyo3(signature = (name, text, sets, lint=true))]
fn check(
    py: Python<'_>,
    name: String,
    text: String,
    sets: Vec<String>,
    lint: bool,
) -> PyResult<(bool, String, Py<PyDict>)> {
    let out = interruptible(py, move || {
        match compile(&name, &text, &sets, Request::default()) {
            Err(json) => (false, json, None),
            Ok(c) => {
                let mut all: Vec<Diagnostic> = c.warnings.clone();
                if lint {
                    let l = mbd::lint(
                        &c,
                        &name,
                        &text,
                        &sets,
                        Request::default(),
                        &FsLoader::new(),
                    );
                    all.extend(l.diagnostics);
                }
                let params: Vec<(String, Option<f64>)> = (c.model.params.iter())
                    .map(|(n, v)| {
                        let x = match v {
                            mbd::model::Value::Scalar { value, .. } => Some(*value),
                            _ => None,
                        };
                        (n.clone(), x)
                    })
                    .collect();
                let info = (
                    c.model.name.clone(),
                    c.model.title.clone(),
                    c.model
                        .outputs
                        .iter()
                        .map(|o| o.column.clone())
                        .collect::<Vec<_>>(),
                    params,
                    (
                        c.settings.dt,
                        c.settings.dt * c.settings.steps as f64,
                        c.settings.steps,
                    ),
                );
                (true, render_json(&all, &c.sources), Some(info))
            }
        }
    })?;
    let d = PyDict::new(py);
    if let Some((model, title, channels, params, (dt, until, steps))) = out.2 {
        d.set_item("name", model)?;
        d.set_item("title", title)?;
        d.set_item("channels", channels)?;
        d.set_item("params", params)?;
        d.set_item("dt", dt)?;
        d.set_item("until", until)?;
        d.set_item("steps", steps)?;
    }
    Ok((out.0, out.1, d.unbind()))
}

/// A run's table and record. On a compile error: `{"errors": JSON}`. Else `header`, `data`
/// (row-major f64 bytes, each value the one the CLI's CSV holds), `rows`, `stats`, `cpu_s`,
/// `warnings` (JSON), and on a runtime failure `failure` (JSON of its diagnostic) with
/// `failure_t`, `failure_step`, `failure_entity`.
#[pyfunction]
#[pyo3(signature = (name, text, sets, solve=None))]
fn run(
    py: Python<'_>,
    name: String,
    text: String,
    sets: Vec<String>,
    solve: Option<&Bound<'_, PyDict>>,
) -> PyResult<Py<PyDict>> {
    let r = request(solve)?;
    let out = interruptible(py, move || -> Result<Ran, String> {
        let c = compile(&name, &text, &sets, r)?;
        // The rows' values as the CSV holds them (`t`, then the channels; `+ 0.0` turns a
        // negative zero into zero), taken without the text.
        let channels = &c.lowered.system.channels;
        let header: Vec<String> = std::iter::once("t".to_string())
            .chain(channels.iter().map(|ch| ch.column.clone()))
            .collect();
        let (mut values, mut rows) = (Vec::<f64>::new(), 0usize);
        let cpu = mbd::study::thread_cpu_seconds();
        let ran = mbd::run_values(&c, &mut |_, _| {}, &mut |st, row| {
            values.push(st.t + 0.0);
            values.extend(row.iter().map(|x| x + 0.0));
            rows += 1;
        });
        let cpu_s = mbd::study::thread_cpu_seconds() - cpu;
        let data: Vec<u8> = values.iter().flat_map(|x| x.to_le_bytes()).collect();
        let mut done = Ran {
            header,
            rows,
            data,
            cpu_s,
            stats: None,
            warnings: String::new(),
            failure: None,
        };
        match ran {
            Ok(report) => {
                let s = report.stats;
                done.stats = Some([
                    ("steps", s.steps as f64),
                    ("newton_iterations", s.newton_iterations as f64),
                    ("halvings", s.halvings as f64),
                    ("factorizations", s.factorizations as f64),
                    ("max_constraint_violation", s.max_constraint_violation),
                ]);
                done.warnings = render_json(&report.warnings, &c.sources);
            }
            Err(f) => {
                done.warnings = render_json(&f.warnings, &c.sources);
                let entity = (f.failure.as_ref())
                    .and_then(|x| x.entity)
                    .and_then(|e| c.lowered.system.entities.get(e))
                    .map(|e| format!("{} {}", e.kind, e.name));
                let (t, step) = f.failure.as_ref().map_or((f64::NAN, 0), |x| (x.t, x.step));
                done.failure = Some((render_json(&[f.diagnostic], &c.sources), t, step, entity));
            }
        }
        Ok(done)
    })?;
    let d = PyDict::new(py);
    match out {
        Err(json) => d.set_item("errors", json)?,
        Ok(r) => {
            d.set_item("header", r.header)?;
            d.set_item("rows", r.rows)?;
            d.set_item("data", PyBytes::new(py, &r.data))?;
            d.set_item("cpu_s", r.cpu_s)?;
            d.set_item("warnings", r.warnings)?;
            if let Some(stats) = r.stats {
                let s = PyDict::new(py);
                for (k, v) in stats {
                    s.set_item(k, v)?;
                }
                d.set_item("stats", s)?;
            }
            if let Some((json, t, step, entity)) = r.failure {
                d.set_item("failure", json)?;
                d.set_item("failure_t", t)?;
                d.set_item("failure_step", step)?;
                d.set_item("failure_entity", entity)?;
            }
        }
    }
    Ok(d.unbind())
}

struct Ran {
    header: Vec<String>,
    rows: usize,
    data: Vec<u8>,
    cpu_s: f64,
    stats: Option<[(&'static str, f64); 5]>,
    warnings: String,
    failure: Option<(String, f64, usize, Option<String>)>,
}

/// The modes about the initial state: `(ok, modes CSV or diagnostics JSON, shapes CSV)`, the
/// tables of `mbd modes -o` and `--shapes`.
#[pyfunction]
#[pyo3(signature = (name, text, sets, frozen=false, count=None, solve=None))]
fn modes(
    py: Python<'_>,
    name: String,
    text: String,
    sets: Vec<String>,
    frozen: bool,
    count: Option<usize>,
    solve: Option<&Bound<'_, PyDict>>,
) -> PyResult<(bool, String, String)> {
    let r = request(solve)?;
    interruptible(py, move || {
        let c = match compile(&name, &text, &sets, r) {
            Ok(c) => c,
            Err(json) => return (false, json, String::new()),
        };
        match mbd::modes(&c, frozen) {
            Err(d) => (false, render_json(&[d], &c.sources), String::new()),
            Ok(m) => {
                let n = count.unwrap_or(m.modes.len());
                let (mut table, mut shapes) = (Vec::new(), Vec::new());
                let written = mbd::write_modes(&m, n, &mut table)
                    .and_then(|()| mbd::write_shapes(&c, &m, n, &mut shapes));
                match written {
                    Ok(()) => (
                        true,
                        String::from_utf8_lossy(&table).into_owned(),
                        String::from_utf8_lossy(&shapes).into_owned(),
                    ),
                    Err(e) => (false, format!("[{{\"message\": \"{e}\"}}]"), String::new()),
                }
            }
        }
    })
}

/// The values of `mbd stability --sweep NAME=START:STOP:STEP` (STOP included), exactly.
#[pyfunction]
fn grid(start: f64, stop: f64, step: f64) -> PyResult<Vec<f64>> {
    sweep::grid(start, stop, step).map_err(|e| PyValueError::new_err(e.to_string()))
}

#[pymodule]
fn _mbd(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(modes, m)?)?;
    m.add_function(wrap_pyfunction!(stability, m)?)?;
    m.add_function(wrap_pyfunction!(stability_share, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(grid, m)?)?;
    m.add_function(wrap_pyfunction!(study, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
