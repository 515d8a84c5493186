//! The sizing lint: is the model the size the scene needs? Warnings `mbd check` prints, and
//! `mbd run` before it runs (`mbd explain W0701` states the measures and thresholds):
//! - W0701: an elastic beam that behaves as a rigid body at this step and these loads;
//! - W0702: a `beam NAME rigid` that, elastic, would deform or resonate in the scene;
//! - W0703: a part that no output depends on.
//!
//! Contract: reads a compiled model (and, for W0702, the same model compiled with its rigid
//! beams elastic); the numbers come from [`crate::solve::sizing`]. Never fails: a model it
//! cannot size says why in [`Lint::not_sized`].

use crate::diagnostics::{Code, Diagnostic};
use crate::model::{Attach, Drive, JointKind, Model, Probe};
use crate::settings::Method;
use crate::solve::sizing::{size_parts, NotSized, Part, PartSize, Sizing, MAX_FREE, MAX_UNKNOWNS};
use crate::Compiled;

/// The scene's band times this is where an elastic beam stops mattering (W0701).
pub const ABOVE_BAND: f64 = 10.0;
/// Deformation, relative to its length, below which a beam counts as rigid (W0701) when
/// nothing excites it or the step cannot follow it.
pub const RIGID_DEFORMATION: f64 = 1e-4;
/// Deformation, relative to its length, below which a beam counts as rigid whatever excites
/// it: a resonance amplifying it 1,000 times (damping ratio 0.05 %) stays below
/// [`RIGID_DEFORMATION`].
pub const RIGID_AT_RESONANCE: f64 = 1e-7;
/// A rigid beam's elastic frequency within this factor of the band resonates (W0702).
pub const NEAR_BAND: f64 = 3.0;
/// Deformation, relative to its length, above which a rigid beam should be elastic (W0702).
pub const ELASTIC_DEFORMATION: f64 = 1e-3;
/// Rotor harmonics in the scene's band: 10/rev.
pub const HARMONICS: f64 = 10.0;
/// Times at which the loads are sampled over the run.
pub const LOAD_SAMPLES: usize = 65;

/// What the lint found.
#[derive(Clone, Debug)]
pub struct Lint {
    pub diagnostics: Vec<Diagnostic>,
    /// The scene's band (rad/s).
    pub band: f64,
    /// The step (s), `None` in statics.
    pub dt: Option<f64>,
    pub beams: Vec<BeamSizing>,
    /// Why the beams were not sized, if they were not.
    pub not_sized: Option<String>,
}

/// One beam's figures and verdict.
#[derive(Clone, Debug)]
pub struct BeamSizing {
    pub name: String,
    /// Declared `rigid` (the figures are its elastic version's).
    pub rigid: bool,
    /// Lowest frequency of a mode it stores a tenth of the strain energy of (rad/s).
    pub omega: Option<f64>,
    /// Largest quasi-static elastic displacement (m).
    pub deflection: f64,
    pub length: f64,
    pub verdict: Verdict,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Elastic and its elasticity matters.
    Elastic,
    /// Elastic, and it behaves rigidly (W0701).
    CouldBeRigid,
    /// Rigid, and rightly so.
    Rigid,
    /// Rigid, and it would deform or resonate (W0702).
    ShouldBeElastic,
    /// Between the two thresholds: neither warned.
    Either,
    /// Nothing loads or moves it, and nothing varies in time: not judged.
    Unloaded,
}

impl Verdict {
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Elastic => "elastic, needed",
            Verdict::CouldBeRigid => "could be rigid (W0701)",
            Verdict::Rigid => "rigid, fine",
            Verdict::ShouldBeElastic => "should be elastic (W0702)",
            Verdict::Either => "either (between the thresholds)",
            Verdict::Unloaded => "not judged (nothing loads or moves it)",
        }
    }
}

/// Lints `c`; `elastic` is the same model compiled with its rigid beams elastic (W0702 needs
/// it; `None` skips that check).
pub fn lint(c: &Compiled, elastic: Option<&Compiled>) -> Lint {
    let m = &c.model;
    let dt = (c.settings.method != Method::Static).then_some(c.settings.dt);
    let times = load_times(m, c.settings.until);
    let mut not_sized = None;
    let mut size = |c: &Compiled| match sized(c, &times) {
        Ok(s) => Some(s),
        Err(why) => {
            not_sized = Some(why);
            None
        }
    };
    let own = (!m.beams.is_empty()).then(|| size(c)).flatten();
    let rigid = elastic
        .filter(|e| !e.model.beams.is_empty())
        .and_then(|e| size(e).map(|s| (e, s)));
    let unowned = own
        .iter()
        .chain(rigid.as_ref().map(|r| &r.1))
        .map(|s| s.unowned);
    let band = unowned.fold(band(c), f64::max);
    let mut out = Lint {
        diagnostics: unread_parts(m),
        band,
        dt,
        beams: Vec::new(),
        not_sized,
    };
    if let Some(sizing) = own {
        for (b, s) in m.beams.iter().zip(alike(&m.beams, sizing.parts)) {
            let verdict = judge(&s, b.length, false, band, dt);
            if verdict == Verdict::CouldBeRigid {
                out.diagnostics.push(could_be_rigid(c, b, &s, band, dt));
            }
            out.beams.push(BeamSizing::of(b, &s, false, verdict));
        }
    }
    if let Some((e, sizing)) = rigid {
        let sizes = alike(&e.model.beams, sizing.parts);
        for body in m.bodies.iter().filter(|b| b.beam_axis.is_some()) {
            let Some((b, s)) = e
                .model
                .beams
                .iter()
                .zip(&sizes)
                .find(|(b, _)| b.name == body.name)
            else {
                continue;
            };
            let verdict = judge(s, b.length, true, band, dt);
            if verdict == Verdict::ShouldBeElastic {
                out.diagnostics
                    .push(should_be_elastic(body.span, b, s, band, dt));
            }
            out.beams.push(BeamSizing::of(b, s, true, verdict));
        }
    }
    out
}

impl BeamSizing {
    fn of(b: &crate::model::Beam, s: &PartSize, rigid: bool, verdict: Verdict) -> BeamSizing {
        BeamSizing {
            name: b.name.clone(),
            rigid,
            omega: s.omega,
            deflection: s.deflection,
            length: b.length,
            verdict,
        }
    }
}

/// The verdict on a beam of these figures (`rigid`: declared rigid, the figures its elastic
/// version's) in a scene of this band and step.
fn judge(s: &PartSize, length: f64, rigid: bool, band: f64, dt: Option<f64>) -> Verdict {
    let w = s.omega.unwrap_or(f64::INFINITY);
    let steps = dt.map_or(0.0, |h| w * h);
    let d = s.deflection / length;
    if s.deflection == 0.0 && band == 0.0 {
        return Verdict::Unloaded;
    }
    let rigid_enough = d <= RIGID_DEFORMATION
        && (w >= ABOVE_BAND * band || steps >= 1.0 || d <= RIGID_AT_RESONANCE);
    let elastic_needed = d >= ELASTIC_DEFORMATION || (w <= NEAR_BAND * band && steps < 1.0);
    match (rigid, rigid_enough, elastic_needed) {
        (false, true, _) => Verdict::CouldBeRigid,
        (false, false, _) => Verdict::Elastic,
        (true, _, true) => Verdict::ShouldBeElastic,
        (true, true, false) => Verdict::Rigid,
        (true, false, false) => Verdict::Either,
    }
}

/// `t = 0`, then [`LOAD_SAMPLES`] times evenly over the run and the knots of the loads'
/// piecewise functions inside it (where they peak).
fn load_times(m: &Model, until: f64) -> Vec<f64> {
    let mut times: Vec<f64> = (0..LOAD_SAMPLES)
        .map(|k| until * k as f64 / (LOAD_SAMPLES - 1) as f64)
        .collect();
    let torques = m.joints.iter().filter_map(|j| match &j.kind {
        JointKind::Revolute { torque: f, .. } | JointKind::Prismatic { force: f, .. } => f.as_ref(),
        _ => None,
    });
    let values = m.loads.iter().flat_map(|l| l.value.iter());
    let along = m.distributed.iter().flat_map(|d| d.value.iter());
    for f in values.chain(along).chain(torques) {
        times.extend(
            f.knot_times()
                .into_iter()
                .filter(|t| (0.0..=until).contains(t)),
        );
    }
    times
}

/// Beams alike (the same length and node count, lowest frequencies within 1e-6) take the
/// largest deformation among them: a rotor's blades trade places as it turns, so the blade
/// that the start leaves unloaded is loaded a quarter turn later.
fn alike(beams: &[crate::model::Beam], sizes: Vec<PartSize>) -> Vec<PartSize> {
    let same = |i: usize, j: usize| {
        let (a, b) = (&beams[i], &beams[j]);
        let w = match (sizes[i].omega, sizes[j].omega) {
            (Some(x), Some(y)) => (x - y).abs() <= 1e-6 * x.abs().max(y.abs()),
            (None, None) => true,
            _ => false,
        };
        w && a.nodes.len() == b.nodes.len() && (a.length - b.length).abs() <= 1e-9 * a.length
    };
    (0..sizes.len())
        .map(|i| PartSize {
            deflection: (0..sizes.len())
                .filter(|&j| same(i, j))
                .map(|j| sizes[j].deflection)
                .fold(0.0, f64::max),
            ..sizes[i]
        })
        .collect()
}

/// Every beam of `c` sized in its assembly.
fn sized(c: &Compiled, times: &[f64]) -> Result<Sizing, String> {
    let m = &c.model;
    let parts: Vec<Part> = m
        .beams
        .iter()
        .enumerate()
        .map(|(bi, b)| Part {
            nodes: m.dofs.node_start[bi].clone(),
            length: b.length,
        })
        .collect();
    size_parts(&c.lowered.system, &c.settings, &parts, times).map_err(|e| match e {
        NotSized::TooLarge { unknowns } => {
            format!("{unknowns} unknowns, over the lint's {MAX_UNKNOWNS} (or over {MAX_FREE} free motions)")
        }
        NotSized::Failed(why) => why,
    })
}

/// The scene's band as the model states it (rad/s): 10 times the fastest rotor speed, and
/// every load's and drive's characteristic frequency (the sizing adds its unowned modes).
fn band(c: &Compiled) -> f64 {
    let m = &c.model;
    let until = c.settings.until;
    let mut spin = c
        .lowered
        .system
        .initial
        .rot
        .iter()
        .map(|r| r.omega().norm())
        .fold(0.0, f64::max);
    let mut w: f64 = 0.0;
    let mut f = |t: &crate::runtime::timefn::TimeFn| w = w.max(t.frequency(until));
    for l in &m.loads {
        l.value.iter().for_each(&mut f);
    }
    for d in &m.distributed {
        let length = m.beams.get(d.beam).map_or(0.0, |b| b.length);
        for v in &d.value {
            f(&v.at_arc(0.0));
            f(&v.at_arc(length));
        }
    }
    for j in &m.joints {
        let (drive, load) = match &j.kind {
            JointKind::Revolute { drive, torque, .. } => (drive, torque),
            JointKind::Prismatic { drive, force, .. } => (drive, force),
            _ => continue,
        };
        if let Some(t) = load {
            f(t);
        }
        let revolute = matches!(j.kind, JointKind::Revolute { .. });
        match drive {
            Drive::Free => {}
            Drive::Position { f: p } => {
                f(p);
                if revolute {
                    spin = spin.max(peak(until, |t| p.jet(t).d));
                }
            }
            Drive::Rate { f: r } => {
                f(r);
                if revolute {
                    spin = spin.max(peak(until, |t| r.eval(t)));
                }
            }
        }
    }
    w.max(HARMONICS * spin)
}

/// The largest `|g(t)|` over 1,000 samples of `[0, until]`.
fn peak(until: f64, g: impl Fn(f64) -> f64) -> f64 {
    (0..=1000)
        .map(|k| g(until * k as f64 / 1000.0).abs())
        .fold(0.0, f64::max)
}

/// Three significant figures for messages: `0.628`, `35.2`, `8970`, `1.4e4`, `5.2e-11`.
pub fn sci(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if !(0.01..10_000.0).contains(&x.abs()) {
        return format!("{x:.1e}");
    }
    let digits = 2 - x.abs().log10().floor() as i32;
    let r = format!("{:.*}", digits.max(0) as usize, x);
    if r.contains('.') {
        r.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        r
    }
}

fn could_be_rigid(
    c: &Compiled,
    b: &crate::model::Beam,
    s: &PartSize,
    band: f64,
    dt: Option<f64>,
) -> Diagnostic {
    let why = match s.omega {
        None => "its joints hold every elastic motion".to_string(),
        Some(w) => {
            let mut parts = vec![format!(
                "its lowest elastic frequency in the assembly is {} rad/s",
                sci(w)
            )];
            if band > 0.0 {
                parts.push(format!(
                    "{} times the scene's band ({} rad/s)",
                    sci(w / band),
                    sci(band)
                ));
            }
            if let Some(h) = dt {
                parts.push(format!(
                    "{} per step (w h at dt = {} s)",
                    sci(w * h),
                    sci(h)
                ));
            }
            parts.join(", ")
        }
    };
    let saved = 6 * b.nodes.len() - 6;
    let total = c.lowered.system.len();
    Diagnostic::warning(
        Code::W0701,
        format!(
            "beam `{}` is stiffer than the scene needs: {why}; it deforms at most {} m ({} of its length)",
            b.name,
            sci(s.deflection),
            sci(s.deflection / b.length)
        ),
    )
    .at(b.span, "elastic beam declared here")
    .hint(format!(
        "write `beam {} rigid {{ ... }}`: {saved} of the model's {total} unknowns fewer ({:.0} %), and no vibration the step cannot follow; see `mbd explain W0701`",
        b.name,
        100.0 * saved as f64 / total as f64
    ))
}

fn should_be_elastic(
    span: crate::source::Span,
    b: &crate::model::Beam,
    s: &PartSize,
    band: f64,
    dt: Option<f64>,
) -> Diagnostic {
    let d = s.deflection / b.length;
    let why = if d >= ELASTIC_DEFORMATION {
        format!(
            "it would deform {} m ({} of its length) under the scene's loads",
            sci(s.deflection),
            sci(d)
        )
    } else {
        let w = s.omega.unwrap_or(f64::INFINITY);
        let step = dt.map_or(String::new(), |h| format!(", {} per step", sci(w * h)));
        format!(
            "its lowest elastic frequency in the assembly would be {} rad/s, within {NEAR_BAND} times the scene's band ({} rad/s){step}",
            sci(w),
            sci(band)
        )
    };
    Diagnostic::warning(
        Code::W0702,
        format!(
            "rigid beam `{}` is more flexible than the scene allows: {why}",
            b.name
        ),
    )
    .at(span, "rigid beam declared here")
    .hint(format!(
        "drop `rigid` to model it as a beam ({} elements, {} unknowns); see `mbd explain W0702`",
        b.elements,
        6 * b.nodes.len()
    ))
}

/// W0703: the parts that no output reads, directly or through joints, springs and beams.
fn unread_parts(m: &Model) -> Vec<Diagnostic> {
    let nb = m.bodies.len();
    let n = nb + m.beams.len();
    let part = |a: &Attach| match *a {
        Attach::Ground { .. } => None,
        Attach::Body { body } => Some(body),
        Attach::BeamNode { beam, .. } | Attach::BeamPoint { beam, .. } => Some(nb + beam),
    };
    let mut read = vec![false; n];
    for o in &m.outputs {
        match &o.probe {
            Probe::Energy { .. } => return Vec::new(),
            Probe::Body { body, .. } => read[*body] = true,
            Probe::Point { attach, .. } => part(attach).into_iter().for_each(|p| read[p] = true),
            Probe::Joint { joint, axes, .. } => {
                let j = &m.joints[*joint];
                let markers = j.markers.iter().chain(axes.as_deref());
                markers
                    .filter_map(|k| part(&k.attach))
                    .for_each(|p| read[p] = true);
            }
            Probe::Multiblade {
                blades, azimuth, ..
            } => {
                for &j in blades.iter().chain(std::iter::once(azimuth)) {
                    m.joints[j]
                        .markers
                        .iter()
                        .filter_map(|k| part(&k.attach))
                        .for_each(|p| read[p] = true);
                }
            }
            Probe::CenterOfMass { bodies, beams, .. } => {
                bodies.iter().for_each(|&b| read[b] = true);
                beams.iter().for_each(|&b| read[nb + b] = true);
            }
        }
    }
    if m.outputs.is_empty() {
        return Vec::new();
    }
    // Union-find over the parts, joined by joints and springs.
    let mut root: Vec<usize> = (0..n).collect();
    fn find(root: &mut [usize], mut i: usize) -> usize {
        while root[i] != i {
            root[i] = root[root[i]];
            i = root[i];
        }
        i
    }
    let pairs = m
        .joints
        .iter()
        .map(|j| &j.markers)
        .chain(m.springs.iter().map(|s| &s.markers));
    for [a, b] in pairs {
        if let (Some(a), Some(b)) = (part(&a.attach), part(&b.attach)) {
            let (ra, rb) = (find(&mut root, a), find(&mut root, b));
            root[ra] = rb;
        }
    }
    let mut live = vec![false; n];
    for p in 0..n {
        if read[p] {
            let r = find(&mut root, p);
            live[r] = true;
        }
    }
    (0..n)
        .filter(|&p| !live[find(&mut root, p)])
        .map(|p| {
            let (kind, name, span) = if p < nb {
                ("body", &m.bodies[p].name, m.bodies[p].span)
            } else {
                ("beam", &m.beams[p - nb].name, m.beams[p - nb].span)
            };
            Diagnostic::warning(
                Code::W0703,
                format!("no output depends on {kind} `{name}`: no output reads it or anything joined to it"),
            )
            .at(span, "declared here")
            .hint("remove it, or add an output that reads it (e.g. its position); see `mbd explain W0703`")
        })
        .collect()
}
