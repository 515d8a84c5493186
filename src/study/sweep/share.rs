//! A sweep cut into shares (`mbd stability --shard K/N`) and the shares joined again (`mbd
//! merge`), so that a job array on a cluster runs one sweep: the joined sweep is the unsharded
//! one, bit for bit.
//!
//! Share K of N owns the grid's values `(K-1) m / N .. K m / N` (of `m`) and the intervals that
//! start at them: it evaluates its values with every method, the next share's first value with
//! the primary method (to see whether an edge lies between the two), and bisects the edges in
//! its intervals. The modes are followed along the whole grid when the shares are joined, so a
//! share keeps its points' shapes. Numbers are stored as the shortest text that reads back to
//! the same `f64` (`NaN` and `inf` included).

use super::{brackets, grid_points, point::evaluate, refine_edges, tracks};
use super::{CompileWith, Edge, Method, Point, PointError, Sweep, SweepSpec, Tick};
use crate::solve::modes::c64;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt::{self, Display};
use std::ops::Range;

/// What a share file says it is.
pub const FORMAT: &str = "mbd sweep share 1";

/// The grid indices share `k` of `n` (1-based) owns among `m` values.
pub fn block(m: usize, k: usize, n: usize) -> Range<usize> {
    (k - 1) * m / n..k * m / n
}

/// An `f64` stored exactly, as text.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exact(pub f64);

impl Serialize for Exact {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&format!("{:?}", self.0))
    }
}

impl<'de> Deserialize<'de> for Exact {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        text.parse::<f64>()
            .map(Exact)
            .map_err(|_| serde::de::Error::custom(format!("`{text}` is not a number")))
    }
}

fn exact(v: &[f64]) -> Vec<Exact> {
    v.iter().copied().map(Exact).collect()
}

fn complex(v: &[c64]) -> Vec<[Exact; 2]> {
    v.iter().map(|z| [Exact(z.re), Exact(z.im)]).collect()
}

fn uncomplex(v: &[[Exact; 2]]) -> Vec<c64> {
    v.iter().map(|[re, im]| c64::new(re.0, im.0)).collect()
}

/// One evaluation as a share keeps it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SharedPoint {
    pub value: Exact,
    pub method: String,
    pub modes: Vec<[Exact; 2]>,
    pub shapes: Vec<Vec<[Exact; 2]>>,
    pub rotor_speed: Exact,
    /// The failure as its row shows it.
    pub failure: Option<String>,
    pub cpu_s: Exact,
    pub detail: String,
}

/// An edge as a share keeps it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SharedEdge {
    pub value: Exact,
    pub bracket: [Exact; 2],
    pub onset: bool,
}

/// One share of a sweep, as `mbd stability --shard K/N` writes it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Share {
    pub format: String,
    /// K of N, 1-based.
    pub shard: usize,
    pub shards: usize,
    /// What the shares of one sweep agree on besides the grid: the model's text and the
    /// options of the analysis, as the caller describes them.
    pub run: String,
    /// The model's name and the param's axis label, for the chart.
    pub model: String,
    pub param_label: String,
    pub param: String,
    /// The whole grid.
    pub values: Vec<Exact>,
    pub methods: Vec<String>,
    pub threshold: Exact,
    pub refine: usize,
    pub points: Vec<SharedPoint>,
    pub refinements: Vec<SharedPoint>,
    pub edges: Vec<SharedEdge>,
    pub notes: Vec<String>,
}

/// Why shares do not join into one sweep.
#[derive(Clone, Debug, PartialEq)]
pub enum MergeError {
    /// No share was given.
    Empty,
    /// A file is not a share of this version.
    Format { share: usize, found: String },
    /// Two shares belong to different sweeps: what differs.
    Mismatch { share: usize, what: String },
    /// The same K twice.
    Repeated { shard: usize },
    /// Shares missing (1-based K).
    Missing { shards: Vec<usize>, of: usize },
    /// A method or a number the share cannot hold.
    Corrupt { share: usize, what: String },
}

impl Display for MergeError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            MergeError::Empty => write!(f, "no share to merge"),
            MergeError::Format { share, found } => write!(
                f,
                "share {share} is not a sweep share of this mbd (format `{found}`, expected `{FORMAT}`)"
            ),
            MergeError::Mismatch { share, what } => write!(
                f,
                "share {share} belongs to another sweep than the first: its {what} differs"
            ),
            MergeError::Repeated { shard } => write!(f, "share {shard} is given twice"),
            MergeError::Missing { shards, of } => {
                let list: Vec<String> = shards.iter().map(|k| format!("{k}/{of}")).collect();
                write!(f, "shares missing: {}", list.join(", "))
            }
            MergeError::Corrupt { share, what } => write!(f, "share {share}: {what}"),
        }
    }
}

impl std::error::Error for MergeError {}

/// Runs share `k` of `n` (1-based) of the sweep: its grid values with every method, the next
/// share's first value with the primary one, and the edges between its values and up to that
/// one. Its points keep their shapes and have no tracks; `run`, `model` and `param_label` are
/// stored as given.
pub fn sweep_share<E: Display>(
    spec: &SweepSpec,
    (k, n): (usize, usize),
    compile: &CompileWith<E>,
    tick: &(dyn Fn(Tick) + Sync),
    (run, model, param_label): (&str, &str, &str),
) -> Share {
    let m = spec.values.len();
    let own = block(m, k, n);
    let mut sub = spec.clone();
    sub.values = spec.values[own.clone()].to_vec();
    let points = grid_points(&sub, compile, tick, &|_| {});
    let (edges, refinements, notes) = match spec.methods.first() {
        Some(&primary) => {
            let mut seen: Vec<Point> = points.clone();
            if !own.is_empty() && own.end < m {
                tick(Tick::Planned(1));
                seen.push(evaluate(spec, spec.values[own.end], primary, compile, tick));
            }
            let brackets = brackets(spec, &seen, primary);
            refine_edges(spec, &brackets, primary, compile, tick)
        }
        None => (
            Vec::new(),
            Vec::new(),
            vec!["no method was given".to_string()],
        ),
    };
    let shared = |p: &Point| SharedPoint {
        value: Exact(p.value),
        method: p.method.name().to_string(),
        modes: complex(&p.modes),
        shapes: p.shapes.iter().map(|s| complex(s)).collect(),
        rotor_speed: Exact(p.rotor_speed),
        failure: p.failure.as_ref().map(|f| f.to_string()),
        cpu_s: Exact(p.cpu_s),
        detail: p.detail.clone(),
    };
    Share {
        format: FORMAT.to_string(),
        shard: k,
        shards: n,
        run: run.to_string(),
        model: model.to_string(),
        param_label: param_label.to_string(),
        param: spec.param.clone(),
        values: exact(&spec.values),
        methods: spec.methods.iter().map(|m| m.name().to_string()).collect(),
        threshold: Exact(spec.threshold),
        refine: spec.refine,
        points: points.iter().map(shared).collect(),
        refinements: refinements.iter().map(shared).collect(),
        edges: edges
            .iter()
            .map(|e| SharedEdge {
                value: Exact(e.value),
                bracket: [Exact(e.bracket.0), Exact(e.bracket.1)],
                onset: e.onset,
            })
            .collect(),
        notes,
    }
}

/// The shares joined: the sweep an unsharded run gives (its modes followed along the whole
/// grid), and the first share, whose `model` and `param_label` name the chart.
pub fn merge(mut shares: Vec<Share>) -> Result<(Sweep, Share), MergeError> {
    let first = shares.first().ok_or(MergeError::Empty)?.clone();
    for (i, s) in shares.iter().enumerate() {
        if s.format != FORMAT {
            return Err(MergeError::Format {
                share: i + 1,
                found: s.format.clone(),
            });
        }
        let differs = [
            ("number of shares", s.shards != first.shards),
            ("model or options", s.run != first.run),
            ("param", s.param != first.param),
            ("grid", s.values != first.values),
            ("methods", s.methods != first.methods),
            ("threshold", s.threshold != first.threshold),
            ("bisections", s.refine != first.refine),
        ];
        if let Some((what, _)) = differs.iter().find(|(_, d)| *d) {
            return Err(MergeError::Mismatch {
                share: i + 1,
                what: what.to_string(),
            });
        }
    }
    shares.sort_by_key(|s| s.shard);
    for w in shares.windows(2) {
        if w[0].shard == w[1].shard {
            return Err(MergeError::Repeated { shard: w[0].shard });
        }
    }
    let missing: Vec<usize> = (1..=first.shards)
        .filter(|k| !shares.iter().any(|s| s.shard == *k))
        .collect();
    if !missing.is_empty()
        || shares
            .iter()
            .any(|s| s.shard == 0 || s.shard > first.shards)
    {
        return Err(MergeError::Missing {
            shards: missing,
            of: first.shards,
        });
    }
    let mut sweep = Sweep {
        param: first.param.clone(),
        points: Vec::new(),
        refinements: Vec::new(),
        edges: Vec::new(),
        threshold: first.threshold.0,
        notes: Vec::new(),
    };
    for (i, s) in shares.iter().enumerate() {
        let point = |p: &SharedPoint| unshare(p, i + 1);
        for p in &s.points {
            sweep.points.push(point(p)?);
        }
        for p in &s.refinements {
            sweep.refinements.push(point(p)?);
        }
        sweep.edges.extend(s.edges.iter().map(|e| Edge {
            value: e.value.0,
            bracket: (e.bracket[0].0, e.bracket[1].0),
            onset: e.onset,
        }));
        sweep.notes.extend(s.notes.iter().cloned());
    }
    tracks::follow(&mut sweep.points);
    sweep.edges.sort_by(|a, b| a.value.total_cmp(&b.value));
    sweep
        .refinements
        .sort_by(|a, b| a.value.total_cmp(&b.value));
    Ok((sweep, first))
}

fn unshare(p: &SharedPoint, share: usize) -> Result<Point, MergeError> {
    let method = match p.method.as_str() {
        "floquet" => Method::Floquet,
        "prony" => Method::Prony,
        other => {
            return Err(MergeError::Corrupt {
                share,
                what: format!("unknown method `{other}`"),
            })
        }
    };
    Ok(Point {
        value: p.value.0,
        method,
        modes: uncomplex(&p.modes),
        shapes: p.shapes.iter().map(|s| uncomplex(s)).collect(),
        tracks: Vec::new(),
        rotor_speed: p.rotor_speed.0,
        failure: p.failure.clone().map(PointError::Shared),
        cpu_s: p.cpu_s.0,
        detail: p.detail.clone(),
    })
}
