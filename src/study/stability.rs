//! Stability studies: HHT at several alphas (and steps); for each run, when the channel (an
//! acceleration or a joint force) starts to grow without bound.
//!
//! The detector works on the step-to-step alternating part of the channel, the signature of
//! a numerical instability in an index-3 integration:
//!
//! 1. `o_k = |y_{k+1} - 2 y_k + y_{k-1}| / 4` (the amplitude of a `(-1)^k` oscillation), its
//!    envelope `e_k` = the largest `o` over the last 40 steps, and `M_k` = the largest `|y|`
//!    so far.
//! 2. Growth starts at the first step where `o_k > 1e-2 M_k` and `e_k >= 10 e_{k-40}` (tenfold
//!    in 40 steps: growing, not a decaying start-up transient).
//! 3. The growth was bounded, and a later one may start, once the envelope falls below a tenth
//!    of its peak since the start, or sets no new peak for 200 steps.
//! 4. Growth still under way when the run ends or fails is unbounded; its onset is the last
//!    time before the peak at which the envelope was at most 1/100 of the peak (the start of
//!    the growth if it never was): when the blow-up took off.
//! 5. A run that fails (Newton diverged, non-finite values) has its onset at the earlier of
//!    the detected time and the failure's time.
//!
//! So a run that ends while a transient is still growing counts as unstable: run it longer to
//! tell.

use super::compare::Samples;
use super::{cell, measure_all, Compile};
use crate::output::charts::{Chart, Series};
use crate::settings::{Method, Request};
use std::io::{self, Write};

/// The detector's parameters (the module's doc explains them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detector {
    /// Steps over which growth is measured and the envelope taken. Default 40.
    pub window: usize,
    /// Smallest alternating part that counts, relative to the largest |y| so far. Default 1e-2.
    pub level: f64,
    /// Growth over `window` steps that starts an episode; the fall that ends one. Default 10.
    pub growth: f64,
    /// Steps without a new peak after which growth counts as bounded. Default 200.
    pub bounded_after: usize,
    /// The rise, from onset to peak, of an unbounded growth. Default 100.
    pub rise: f64,
}

impl Default for Detector {
    fn default() -> Detector {
        Detector {
            window: 40,
            level: 1e-2,
            growth: 10.0,
            bounded_after: 200,
            rise: 100.0,
        }
    }
}

impl Detector {
    /// The onset of unbounded growth, if any (the failure time is the caller's).
    pub fn onset(&self, s: &Samples) -> Option<f64> {
        let (t, y) = (&s.t, &s.y);
        if let Some(k) = y.iter().position(|v| !v.is_finite()) {
            return Some(t[k]);
        }
        let n = y.len();
        if n < 3 {
            return None;
        }
        let w = self.window.max(1);
        let o: Vec<f64> = (0..n)
            .map(|k| {
                if k == 0 || k + 1 == n {
                    0.0
                } else {
                    (y[k + 1] - 2.0 * y[k] + y[k - 1]).abs() / 4.0
                }
            })
            .collect();
        let env: Vec<f64> = (0..n)
            .map(|k| {
                o[(k + 1).saturating_sub(w)..=k]
                    .iter()
                    .fold(0.0_f64, |a, &b| a.max(b))
            })
            .collect();
        let mut biggest = y[0].abs();
        // An open episode: (start, peak, step of the peak).
        let mut open: Option<(usize, f64, usize)> = None;
        for k in 1..n - 1 {
            biggest = biggest.max(y[k].abs()).max(y[k + 1].abs());
            open = match open {
                None if k >= w
                    && o[k] > self.level * biggest
                    && env[k] >= self.growth * env[k - w] =>
                {
                    Some((k, env[k], k))
                }
                None => None,
                Some((start, peak, at)) => {
                    let (peak, at) = if env[k] > peak {
                        (env[k], k)
                    } else {
                        (peak, at)
                    };
                    if env[k] < peak / self.growth || k - at > self.bounded_after {
                        None
                    } else {
                        Some((start, peak, at))
                    }
                }
            };
        }
        let (start, peak, at) = open?;
        let onset = (start..=at)
            .rev()
            .find(|&k| env[k] <= peak / self.rise)
            .unwrap_or(start);
        Some(t[onset])
    }
}

/// A stability study (`mbd study MODEL --channel NAME --alpha LIST`).
#[derive(Clone, Debug)]
pub struct StabilitySpec {
    pub channel: String,
    pub alphas: Vec<f64>,
    /// Step counts (the model's own if none were given); every run ends at `until`.
    pub steps: Vec<usize>,
    pub until: f64,
    pub detector: Detector,
}

/// One run: a row of the study's CSV, and the channel for the chart.
#[derive(Clone, Debug, PartialEq)]
pub struct StabilityRow {
    pub alpha: f64,
    pub dt: f64,
    pub steps: usize,
    /// When the channel started to grow without bound (`None`: it did not).
    pub onset: Option<f64>,
    /// When the run failed.
    pub failed: Option<f64>,
    /// The failure's one-line message.
    pub failure: Option<String>,
    /// CPU time of the run, up to its failure for a failed run.
    pub cpu_s: Option<f64>,
    /// Newton iterations of a finished run.
    pub newton_iterations: Option<usize>,
    pub samples: Samples,
}

/// Runs HHT at each alpha and step count, in parallel.
pub fn stability(spec: &StabilitySpec, base: &Request, compile: &Compile) -> Vec<StabilityRow> {
    let mut jobs = Vec::new();
    for &alpha in &spec.alphas {
        for &n in &spec.steps {
            let mut o = base.clone();
            o.method = Some(Method::Hht);
            o.alpha = Some(alpha);
            jobs.push((o, n));
        }
    }
    let measured = measure_all(compile, &jobs, &spec.channel);
    jobs.iter()
        .zip(measured)
        .map(|((o, n), m)| {
            let failed = m.failure.as_ref().and_then(|f| f.t);
            let detected = spec.detector.onset(&m.samples);
            let onset = match (detected, failed) {
                (Some(d), Some(f)) => Some(d.min(f)),
                (d, f) => d.or(f),
            };
            StabilityRow {
                alpha: o.alpha.unwrap_or_default(),
                dt: spec.until / *n as f64,
                steps: *n,
                onset,
                failed,
                cpu_s: m.cpu_s.is_finite().then_some(m.cpu_s),
                newton_iterations: m.newton_iterations,
                failure: m.failure.map(|f| f.message),
                samples: m.samples,
            }
        })
        .collect()
}

/// The study's CSV: `integrator,alpha,dt,steps,onset_s,failed_s,cpu_s,newton_iters`; an
/// empty cell means none (no onset, no failure) or unknown.
pub fn write_csv(rows: &[StabilityRow], out: &mut dyn Write) -> io::Result<()> {
    writeln!(
        out,
        "integrator,alpha,dt,steps,onset_s,failed_s,cpu_s,newton_iters"
    )?;
    for r in rows {
        writeln!(
            out,
            "hht,{},{},{},{},{},{},{}",
            cell(Some(r.alpha)),
            cell(Some(r.dt)),
            r.steps,
            cell(r.onset),
            cell(r.failed),
            cell(r.cpu_s),
            r.newton_iterations
                .map(|n| n.to_string())
                .unwrap_or_default()
        )?;
    }
    Ok(())
}

/// |channel| against time on a log axis, one line per run.
pub fn chart(rows: &[StabilityRow], model: &str, channel: &str) -> Chart {
    let several_steps = rows.iter().any(|r| r.steps != rows[0].steps);
    Chart {
        title: format!("{model}: growth of |{channel}| for each alpha"),
        x_label: "t [s]".to_string(),
        y_label: format!("|{channel}|"),
        log_x: false,
        log_y: true,
        series: rows
            .iter()
            .map(|r| Series {
                label: if several_steps {
                    format!("alpha = {}, dt = {} s", r.alpha, r.dt)
                } else {
                    format!("alpha = {}", r.alpha)
                },
                points: r
                    .samples
                    .t
                    .iter()
                    .zip(&r.samples.y)
                    .map(|(&t, &y)| (t, y.abs()))
                    .collect(),
                markers_only: false,
            })
            .collect(),
        shaded: Vec::new(),
        guides: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signal(n: usize, f: impl Fn(usize) -> f64) -> Samples {
        Samples {
            t: (0..n).map(|k| k as f64 * 0.05).collect(),
            y: (0..n).map(f).collect(),
        }
    }

    #[test]
    fn a_smooth_signal_and_a_decaying_transient_have_no_onset() {
        let d = Detector::default();
        assert_eq!(d.onset(&signal(1000, |k| (k as f64 * 0.05).sin())), None);
        let transient = signal(1000, |k| {
            (k as f64 * 0.01).cos()
                + 0.5 * (-(k as f64) / 5.0).exp() * if k.is_multiple_of(2) { 1.0 } else { -1.0 }
        });
        assert_eq!(d.onset(&transient), None);
    }

    #[test]
    fn a_growing_alternation_has_its_onset_where_it_takes_off() {
        // Bounded noise, then from step 400 an alternation growing 10 % a step.
        let y = |k: usize| {
            let alt = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
            let grow = if k < 400 {
                1e-6
            } else {
                1e-6 * 1.1f64.powi((k - 400) as i32)
            };
            (k as f64 * 0.02).sin() + alt * grow
        };
        let s = signal(700, y);
        let onset = Detector::default().onset(&s).unwrap_or(f64::NAN);
        // Growth starts where the alternation passes 1 % of |y| (step 497); the peak is at the
        // end (step 698), and a hundredth of it 1.1^48 = 100 earlier: step 650.
        assert!((onset - 650.0 * 0.05).abs() < 0.11, "onset {onset}");
    }

    #[test]
    fn growth_that_subsides_is_bounded() {
        let y = |k: usize| {
            let alt = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
            let k = k as f64;
            let burst = 1e-4 * (-(k - 300.0).powi(2) / 800.0).exp() * 1e4;
            (k * 0.02).sin() + alt * burst
        };
        assert_eq!(Detector::default().onset(&signal(1000, y)), None);
    }
}
