//! Progress on a terminal (indicatif bars on standard error); elsewhere (a log, CI) a line per
//! finished evaluation, or nothing for a run.

use indicatif::{ProgressBar, ProgressStyle};
use mbd::study::sweep::Tick;
use std::io::IsTerminal;
use std::time::Instant;

/// A bar of `len` with the CLI's style: `{elapsed_precise} [{bar:40}] ...what...`.
fn styled_bar(len: u64, what: &str) -> ProgressBar {
    let b = ProgressBar::new(len);
    if let Ok(style) =
        ProgressStyle::with_template(&format!("{{elapsed_precise}} [{{bar:40}}] {what}"))
    {
        b.set_style(style.progress_chars("=> "));
    }
    b
}

/// The progress of many evaluations (`Tick`s of a sweep or a fan plot), counted in `unit`s.
pub struct Evaluations {
    bar: Option<ProgressBar>,
}

impl Evaluations {
    /// A bar on a terminal, e.g. `12/40 values, 3s left`; elsewhere the `Done` lines.
    pub fn new(unit: &str) -> Evaluations {
        let what = format!("{{pos}}/{{len}} {unit}, {{eta}} left");
        Evaluations {
            bar: std::io::stderr()
                .is_terminal()
                .then(|| styled_bar(0, &what)),
        }
    }

    pub fn tick(&self, t: Tick) {
        match (&self.bar, t) {
            (Some(b), Tick::Planned(n)) => b.inc_length(n as u64),
            (Some(b), Tick::Done(_)) => b.inc(1),
            (None, Tick::Done(line)) => eprintln!("{line}"),
            (None, Tick::Planned(_)) => {}
        }
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// The progress of one run, in steps: a bar on a terminal once the run has taken a second.
pub struct Steps {
    started: Instant,
    terminal: bool,
    bar: Option<ProgressBar>,
}

impl Steps {
    pub fn new(started: Instant) -> Steps {
        Steps {
            started,
            terminal: std::io::stderr().is_terminal(),
            bar: None,
        }
    }

    /// Step `k` of `n` is done (looked at every 64 steps and at the last).
    pub fn update(&mut self, k: usize, n: usize) {
        if !self.terminal || !k.is_multiple_of(64) && k != n {
            return;
        }
        if self.bar.is_none() && self.started.elapsed().as_secs_f64() > 1.0 {
            self.bar = Some(styled_bar(n as u64, "step {pos}/{len}, {eta} left"));
        }
        if let Some(b) = &self.bar {
            b.set_position(k as u64);
            if k == n {
                b.finish_and_clear();
            }
        }
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
