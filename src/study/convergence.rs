//! Convergence studies: the error of one channel against a reference, for each integrator
//! and step, with each run's CPU time; the observed order of each integrator.

use super::compare::{observed_order, relative_error, Order, Reference, Samples};
use super::{cell, Compile, IntegratorItem};
use crate::output::charts::{Chart, Guide, GuideLine, Series};
use crate::runtime::timefn::TimeFn;
use crate::settings::Request;
use std::io::{self, Write};

/// What the runs are compared with (`--reference`).
#[derive(Clone, Debug, PartialEq)]
pub enum ReferenceSpec {
    /// The model's `exact` solution of the channel.
    Exact(TimeFn),
    /// One extra run of the first integrator at a quarter of the smallest step.
    Finest,
    /// Samples read from a CSV file.
    Samples(Samples),
}

/// A convergence study (`mbd study MODEL --channel NAME --integrator LIST --steps LIST`).
#[derive(Clone, Debug)]
pub struct ConvergenceSpec {
    pub channel: String,
    /// Compare at this time only, else over every output time.
    pub at: Option<f64>,
    pub integrators: Vec<IntegratorItem>,
    /// Step counts; every run ends at `until`.
    pub steps: Vec<usize>,
    pub until: f64,
    pub reference: ReferenceSpec,
}

/// One run: a row of the study's CSV.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The integrator item as written.
    pub integrator: String,
    pub dt: f64,
    pub steps: usize,
    /// `None` when the run failed (or could not be compared).
    pub error: Option<f64>,
    pub cpu_s: Option<f64>,
    pub newton_iterations: Option<usize>,
    /// Why there is no error: the failure's one-line message.
    pub failure: Option<String>,
}

/// The finest run, the reference of `--reference finest`.
#[derive(Clone, Debug, PartialEq)]
pub struct Finest {
    pub integrator: String,
    pub dt: f64,
    pub steps: usize,
    pub cpu_s: f64,
    pub failure: Option<String>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Convergence {
    /// One per (integrator, step), integrators in the order given, then steps as given.
    pub rows: Vec<Row>,
    pub finest: Option<Finest>,
}

/// Runs the study: `base` holds the command line's other overrides.
pub fn convergence(spec: &ConvergenceSpec, base: &Request, compile: &Compile) -> Convergence {
    let mut jobs: Vec<(Request, usize)> = Vec::new();
    for item in &spec.integrators {
        for &n in &spec.steps {
            jobs.push((item.request(base), n));
        }
    }
    let finest_steps = spec.steps.iter().max().map(|n| 4 * n).unwrap_or(1);
    let first = spec.integrators.first();
    if let (ReferenceSpec::Finest, Some(item)) = (&spec.reference, first) {
        jobs.push((item.request(base), finest_steps));
    }
    let mut measured = super::measure_all(compile, &jobs, &spec.channel);
    let (reference, finest) = match &spec.reference {
        ReferenceSpec::Exact(f) => (Ok(Reference::Exact(f.clone())), None),
        ReferenceSpec::Samples(s) => (Ok(Reference::Samples(s.clone())), None),
        ReferenceSpec::Finest => match measured.pop() {
            Some(m) => {
                let finest = Finest {
                    integrator: first.map(|i| i.text.clone()).unwrap_or_default(),
                    dt: spec.until / finest_steps as f64,
                    steps: finest_steps,
                    cpu_s: m.cpu_s,
                    failure: m.failure.as_ref().map(|f| f.message.clone()),
                };
                let reference = match &m.failure {
                    None => Ok(Reference::Samples(m.samples)),
                    Some(f) => Err(format!("the reference run failed: {}", f.message)),
                };
                (reference, Some(finest))
            }
            None => (Err("no reference run".to_string()), None),
        },
    };
    let mut rows = Vec::new();
    let mut k = 0;
    for item in &spec.integrators {
        for &n in &spec.steps {
            let m = &measured[k];
            k += 1;
            let dt = spec.until / n as f64;
            let compared = match (&m.failure, &reference) {
                (Some(f), _) => Err(f.message.clone()),
                (None, Err(e)) => Err(e.clone()),
                (None, Ok(r)) => relative_error(&m.samples, r, spec.at, dt),
            };
            let ok = m.failure.is_none();
            rows.push(Row {
                integrator: item.text.clone(),
                dt,
                steps: n,
                error: compared.as_ref().ok().copied(),
                cpu_s: ok.then_some(m.cpu_s),
                newton_iterations: m.newton_iterations,
                failure: compared.err(),
            });
        }
    }
    Convergence { rows, finest }
}

impl Convergence {
    /// The observed order of each integrator (in the order given), `None` with fewer than
    /// two runs with an error.
    pub fn orders(&self) -> Vec<(String, Option<Order>)> {
        let mut out: Vec<(String, Option<Order>)> = Vec::new();
        for r in &self.rows {
            if !out.iter().any(|(name, _)| *name == r.integrator) {
                let runs: Vec<(f64, f64)> = self
                    .rows
                    .iter()
                    .filter(|x| x.integrator == r.integrator)
                    .filter_map(|x| x.error.map(|e| (x.dt, e)))
                    .collect();
                out.push((r.integrator.clone(), observed_order(&runs)));
            }
        }
        out
    }

    /// The CPU time integrator `name` needs to reach relative error `target`: log-log
    /// interpolation between the two runs that bracket it, else extrapolation along the line
    /// through its two most accurate runs (then `extrapolated` is true). `None` with fewer than
    /// two runs, or when the line does not fall.
    pub fn cpu_to_reach(&self, name: &str, target: f64) -> Option<(f64, bool)> {
        let mut runs: Vec<(f64, f64)> = self
            .rows
            .iter()
            .filter(|r| r.integrator == name)
            .filter_map(|r| Some((r.cpu_s?, r.error?)))
            .filter(|(c, e)| *c > 0.0 && *e > 0.0)
            .collect();
        runs.sort_by(|a, b| b.1.total_cmp(&a.1));
        if runs.len() < 2 || target.is_nan() || target <= 0.0 {
            return None;
        }
        let through = |(c0, e0): (f64, f64), (c1, e1): (f64, f64)| -> Option<f64> {
            let slope = (e1.ln() - e0.ln()) / (c1.ln() - c0.ln());
            (slope < 0.0 && slope.is_finite())
                .then(|| (c0.ln() + (target.ln() - e0.ln()) / slope).exp())
        };
        if let Some(w) = runs
            .windows(2)
            .find(|w| w[0].1 >= target && target >= w[1].1)
        {
            return through(w[0], w[1]).map(|c| (c, false));
        }
        let n = runs.len();
        let (a, b) = if target > runs[0].1 {
            (runs[0], runs[1])
        } else {
            (runs[n - 2], runs[n - 1])
        };
        through(a, b).map(|c| (c, true))
    }

    /// The study's CSV: `integrator,dt,steps,error,cpu_s,newton_iters`, one row per run;
    /// empty cells where a run failed.
    pub fn write_csv(&self, out: &mut dyn Write) -> io::Result<()> {
        writeln!(out, "integrator,dt,steps,error,cpu_s,newton_iters")?;
        for r in &self.rows {
            writeln!(
                out,
                "{},{},{},{},{},{}",
                r.integrator,
                cell(Some(r.dt)),
                r.steps,
                cell(r.error),
                cell(r.cpu_s),
                r.newton_iterations
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            )?;
        }
        Ok(())
    }

    /// Error against CPU time on log-log axes, one line per integrator (runs by step count)
    /// with its observed order in the legend; dashed guides of slope -2 (and -4 when an
    /// integrator's observed order exceeds 3) below the most accurate run, since the CPU time
    /// of a fixed-step run is proportional to its step count; dotted lines at the [`TARGETS`].
    pub fn chart(&self, model: &str, channel: &str) -> Chart {
        let mut series: Vec<Series> = Vec::new();
        let orders = self.orders();
        for (name, order) in &orders {
            let mut runs: Vec<&Row> = self.rows.iter().filter(|r| r.integrator == *name).collect();
            runs.sort_by_key(|r| r.steps);
            let label = match order {
                Some(o) => format!("{name}: order {:.2}", o.fit),
                None => name.clone(),
            };
            series.push(Series {
                label,
                points: runs
                    .iter()
                    .filter_map(|r| Some((r.cpu_s?, r.error?)))
                    .collect(),
                markers_only: false,
            });
        }
        // Each guide passes a factor 2 below the most accurate run of the integrator whose
        // observed order is nearest to the guide's (of all runs if none is within 1).
        let best = |of: &[&Series]| {
            of.iter()
                .flat_map(|s| s.points.iter().copied())
                .filter(|&(c, e)| c > 0.0 && e > 0.0 && c.is_finite() && e.is_finite())
                .min_by(|a, b| a.1.total_cmp(&b.1))
        };
        let fits: Vec<Option<f64>> = orders
            .iter()
            .map(|(_, o)| o.as_ref().map(|o| o.fit))
            .collect();
        let fourth = fits.iter().flatten().any(|&f| f > 3.0);
        let mut guides = Vec::new();
        for p in [2.0, 4.0].into_iter().filter(|&p| p < 3.0 || fourth) {
            let nearest = series
                .iter()
                .zip(&fits)
                .filter_map(|(s, f)| Some((s, (f.as_ref()? - p).abs())))
                .filter(|(_, d)| *d < 1.0)
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(s, _)| s);
            let anchor = match nearest {
                Some(s) => best(&[s]),
                None => best(&series.iter().collect::<Vec<_>>()),
            };
            if let Some((c, e)) = anchor {
                guides.push(Guide {
                    label: format!("order {p}: error ~ CPU^-{p}"),
                    line: GuideLine::Slope {
                        through: (c, e / 2.0),
                        slope: -p,
                    },
                });
            }
        }
        for t in TARGETS {
            guides.push(Guide {
                label: "target errors".to_string(),
                line: GuideLine::Level(t),
            });
        }
        Chart {
            title: format!("{model}: relative error of {channel} against CPU time"),
            x_label: "CPU time per run [s]".to_string(),
            y_label: format!("relative error of {channel}"),
            log_x: true,
            log_y: true,
            series,
            shaded: Vec::new(),
            guides,
        }
    }
}

/// The relative errors whose CPU cost the study reports (`mbd study` prints it; the chart
/// draws them).
pub const TARGETS: [f64; 2] = [1e-3, 1e-6];

#[cfg(test)]
mod tests {
    use super::*;

    fn row(cpu: f64, error: f64) -> Row {
        Row {
            integrator: "hht".to_string(),
            dt: 0.0,
            steps: 0,
            error: Some(error),
            cpu_s: Some(cpu),
            newton_iterations: None,
            failure: None,
        }
    }

    #[test]
    fn cpu_to_reach_interpolates_and_extrapolates_in_log_log() {
        // error = 1e-6 / cpu^2: 1e-2 at 0.01 s, 1e-4 at 0.1 s.
        let study = Convergence {
            rows: vec![row(0.01, 1e-2), row(0.1, 1e-4)],
            finest: None,
        };
        let (c, extrapolated) = study.cpu_to_reach("hht", 1e-3).expect("bracketed");
        assert!(!extrapolated && (c - 10f64.powf(-1.5)).abs() < 1e-12, "{c}");
        let (c, extrapolated) = study.cpu_to_reach("hht", 1e-6).expect("extrapolated");
        assert!(extrapolated && (c - 1.0).abs() < 1e-12, "{c}");
        assert_eq!(study.cpu_to_reach("other", 1e-3), None);
        let flat = Convergence {
            rows: vec![row(0.01, 1e-2), row(0.1, 1e-2)],
            finest: None,
        };
        assert_eq!(flat.cpu_to_reach("hht", 1e-6), None);
    }
}
