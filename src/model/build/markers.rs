//! Markers: a marker reference (`earth @ (x, y, z)`, `bar.end`, `mast.node[2]`,
//! `mast.at(1.2 m)`) resolved to a point with axes on a ground, a body or a beam, where it is
//! at t = 0, with the offsets of the marker arguments it was passed through added.
//! Contract: reads built grounds, bodies and beams; must not build them.

use super::{add, scale, Builder, Built};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::model::eval::units::Dim;
use crate::model::eval::{mat_mul, mat_vec, Value};
use crate::model::scope::env::{Ref, Seg};
use crate::model::*;
use crate::syntax::ast::MarkerRef;

/// A marker's offset (its own and its arguments', summed) and where the first was written.
type Offset = Option<([f64; 3], Span)>;

impl Builder<'_> {
    /// Resolves a marker reference: `earth`, `earth @ (x, y, z)`, `bar.end`, `rotor.hub`,
    /// `mast.node[2]`, `mast.at(1.2 m)`.
    pub(super) fn marker(&mut self, scope: usize, m: &MarkerRef) -> Option<Marker> {
        let segs = match self.env.segs(scope, &m.path) {
            Ok(s) => s,
            Err(d) => {
                self.error(scope, d);
                return None;
            }
        };
        let (r, rest, passed) = match self.env.resolve_marker(scope, &segs, m.path.span) {
            Ok(x) => x,
            Err(d) => {
                self.error(scope, d);
                return None;
            }
        };
        // Its own offset and those of the marker arguments it names, all in one frame (the
        // body's, the beam section's or the inertial one), so they add.
        let mut offset: Offset = None;
        let written = m.offset.iter().map(|e| (e.clone(), scope));
        for (e, s) in written.chain(passed) {
            let o = self.vector(s, &e, Dim::LENGTH, "a marker offset")?;
            offset = Some(match offset {
                Some((sum, first)) => (add(sum, o), first),
                None => (o, e.span),
            });
        }
        let d = match r {
            Ref::Decl(d) => d,
            Ref::Instance(s) => {
                let comp = self.env.scopes[s]
                    .instance
                    .clone()
                    .map(|i| i.0)
                    .unwrap_or_default();
                return self.not_marker(scope, m, format!("an instance of `{comp}`"));
            }
            Ref::Component(c) => {
                return self.not_marker(scope, m, format!("component `{}`", c.name.name))
            }
            Ref::Binding(b) => {
                let what = format!("`{}`", self.env.bindings[b].name);
                return self.not_marker(scope, m, what);
            }
            Ref::Builtin(_) | Ref::Family(_) => {
                return self.not_marker(scope, m, format!("`{}`", m.path.text()))
            }
        };
        let text = self.env.decls[d].name.clone();
        match self.built[d] {
            Some(Built::Ground(g)) => {
                if let Some(s) = rest.first() {
                    return self.no_such_marker(scope, s, &text, &[]);
                }
                let o = offset.map(|o| o.0).unwrap_or([0.0; 3]);
                Some(Marker {
                    attach: Attach::Ground { ground: g },
                    offset: o,
                    axes: IDENTITY,
                    position: o,
                    world_axes: IDENTITY,
                    text: text.clone(),
                    span: m.span,
                })
            }
            Some(Built::Body(b)) => self.body_marker(scope, m, b, text, &rest, offset),
            Some(Built::Beam(bi)) => self.beam_marker(scope, m, bi, text, &rest, offset),
            None if !matches!(
                &*self.env.decls[d].item,
                crate::syntax::ast::Item::Joint { .. }
            ) =>
            {
                // Its own declaration failed and was reported.
                None
            }
            _ => self.not_marker(scope, m, format!("`{text}`")),
        }
    }

    fn not_marker(&mut self, scope: usize, m: &MarkerRef, what: String) -> Option<Marker> {
        self.error(
            scope,
            Diagnostic::error(Code::E0222, format!("{what} is not a marker"))
                .at(m.path.span, "a marker is needed here")
                .hint("name a ground, a body or one of its markers (`bar.end`), or a point on a beam (`mast.node[2]`)"),
        );
        None
    }

    /// A marker on body `b`: its reference point, a named marker or a point along a rigid
    /// beam, moved by `offset`.
    fn body_marker(
        &mut self,
        scope: usize,
        m: &MarkerRef,
        b: usize,
        text: String,
        rest: &[Seg],
        offset: Offset,
    ) -> Option<Marker> {
        let body = self.bodies[b].clone();
        let along = |s: &Seg| -> Option<Result<f64, Diagnostic>> { axis_point(&body, s, &text) };
        let names = || -> Vec<String> { body.markers.iter().map(|x| x.0.clone()).collect() };
        let (local, axes) = match rest {
            [] => ([0.0; 3], IDENTITY),
            [s] if along(s).is_some() => match along(s) {
                Some(Ok(x)) => ([x, 0.0, 0.0], IDENTITY),
                Some(Err(d)) => {
                    self.error(scope, d);
                    return None;
                }
                None => return None,
            },
            [s] if s.index.is_none() && s.arg.is_none() => {
                match body.markers.iter().find(|x| x.0 == s.name.name) {
                    Some(x) => (x.1, x.2),
                    None => return self.no_such_marker(scope, s, &text, &names()),
                }
            }
            [s, ..] => return self.no_such_marker(scope, s, &text, &names()),
        };
        if body.kind == BodyKind::PointMass {
            if let Some((_, s)) = offset {
                self.error(
                    scope,
                    Diagnostic::error(Code::E0306, format!("`{text}` is a point mass: a marker on it cannot be offset"))
                        .at(s, "offset on a point mass")
                        .hint("a point mass has no orientation to carry an offset; attach to the point itself, or make the body `rigid`"),
                );
                return None;
            }
        }
        let local = add(local, offset.map(|o| o.0).unwrap_or([0.0; 3]));
        Some(Marker {
            attach: Attach::Body { body: b },
            offset: local,
            axes,
            position: add(body.position, mat_vec(body.orientation, local)),
            world_axes: mat_mul(body.orientation, axes),
            text: format!(
                "{text}{}",
                rest.first()
                    .map(|s| format!(".{}", s.name.name))
                    .unwrap_or_default()
            ),
            span: m.span,
        })
    }

    /// A marker at a point of beam `bi` (`start`, `end`, `node[k]`, `at(s)`), moved by
    /// `offset` in the section frame.
    fn beam_marker(
        &mut self,
        scope: usize,
        m: &MarkerRef,
        bi: usize,
        text: String,
        rest: &[Seg],
        offset: Offset,
    ) -> Option<Marker> {
        let beam = self.beams[bi].clone();
        let n = beam.nodes.len();
        let point = match rest {
            [s] => beam_point(&beam, bi, s, &text),
            _ => None,
        };
        let (attach, s) = match point {
            Some(Ok(x)) => x,
            Some(Err(d)) => {
                self.error(scope, d);
                return None;
            }
            None => {
                let span = rest.first().map(|s| s.span).unwrap_or(m.path.span);
                return self.beam_point_error(scope, span, &text, n);
            }
        };
        let o = offset.map(|o| o.0).unwrap_or([0.0; 3]);
        // Where the point is at t = 0: on the initial (possibly stretched) nodes.
        let h = beam.length / (n - 1) as f64;
        let k = ((s / h).floor() as usize).min(n - 2);
        let w = (s - k as f64 * h) / h;
        let at = add(
            scale(beam.initial_nodes[k], 1.0 - w),
            scale(beam.initial_nodes[k + 1], w),
        );
        // The section frame there: node k's, turned by the share `w` of the twist to the next.
        let frame = match w {
            _ if beam.frames[k] == beam.frames[k + 1] => beam.frames[k],
            0.0 => beam.frames[k],
            1.0 => beam.frames[k + 1],
            _ => {
                let (a, b) = (beam.frames[k], beam.frames[k + 1]);
                let r = |i: usize, j: usize| (0..3).map(|l| a[l][i] * b[l][j]).sum::<f64>();
                let turn = r(2, 1).atan2(r(1, 1));
                mat_mul(a, crate::model::eval::rotation([1.0, 0.0, 0.0], w * turn))
            }
        };
        Some(Marker {
            attach,
            offset: o,
            axes: IDENTITY,
            position: add(at, mat_vec(frame, o)),
            world_axes: frame,
            text: format!(
                "{text}.{}",
                rest.first()
                    .map(|s| s.name.name.clone())
                    .unwrap_or_default()
            ),
            span: m.span,
        })
    }

    fn no_such_marker(
        &mut self,
        scope: usize,
        s: &Seg,
        of: &str,
        names: &[String],
    ) -> Option<Marker> {
        let d = Diagnostic::error(
            Code::E0201,
            format!("`{of}` has no marker `{}`", s.name.name),
        )
        .at(s.span, "no such marker");
        let hint = match did_you_mean(&s.name.name, names.iter().map(|n| n.as_str())) {
            Some(m) => format!("did you mean `{m}`? Markers: {}", names.join(", ")),
            None if names.is_empty() => {
                format!("`{of}` has no named markers; use `{of}` itself, or `{of} @ (x, y, z)`")
            }
            None => format!("markers of `{of}`: {}", names.join(", ")),
        };
        self.error(scope, d.hint(hint));
        None
    }

    fn beam_point_error(&mut self, scope: usize, span: Span, of: &str, n: usize) -> Option<Marker> {
        self.error(
            scope,
            Diagnostic::error(Code::E0306, format!("say which point of beam `{of}`"))
                .at(span, "not a point of the beam")
                .hint(format!("write `{of}.start`, `{of}.end`, `{of}.node[k]` (k in 0..={}) or `{of}.at(s)` with s an arc length", n - 1)),
        );
        None
    }
}

/// `at(s)` or `node[k]` on a rigid beam: the arc length along its axis, if `s` names one.
pub(super) fn axis_point(body: &Body, s: &Seg, of: &str) -> Option<Result<f64, Diagnostic>> {
    let (length, n) = body.beam_axis?;
    match (s.name.name.as_str(), s.index, &s.arg) {
        ("node", Some((k, ks)), None) => Some(if k >= 0 && (k as usize) < n {
            Ok(length * k as f64 / (n - 1) as f64)
        } else {
            Err(Diagnostic::error(
                Code::E0214,
                format!(
                    "node {k} is out of range: beam `{of}` has nodes 0..={}",
                    n - 1
                ),
            )
            .at(ks, "no such node")
            .hint("a rigid beam keeps the node numbering its elements and order give"))
        }),
        ("at", None, Some((Value::Scalar { value, dim }, vs))) => Some(
            if *dim == Dim::LENGTH && (0.0..=length * (1.0 + 1e-12)).contains(value) {
                Ok(*value)
            } else {
                Err(Diagnostic::error(
                    Code::E0214,
                    format!("`at(s)` on beam `{of}` needs an arc length in [0, {length} m]"),
                )
                .at(*vs, "outside the beam")
                .hint("s is the distance from the beam's start, in metres"))
            },
        ),
        _ => None,
    }
}

/// The point of beam `bi` a path segment names (`start`, `end`, `node[k]`, `at(s)`), with its arc
/// length; `None` if the segment names no point of a beam.
pub(super) fn beam_point(
    beam: &Beam,
    bi: usize,
    s: &Seg,
    of: &str,
) -> Option<Result<(Attach, f64), Diagnostic>> {
    let n = beam.nodes.len();
    let node = |k: usize| Attach::BeamNode { beam: bi, node: k };
    Some(Ok(match (s.name.name.as_str(), s.index, &s.arg) {
        ("start", None, None) => (node(0), 0.0),
        ("end", None, None) => (node(n - 1), beam.length),
        ("node", Some((k, ks)), None) => {
            if k < 0 || k as usize >= n {
                return Some(Err(Diagnostic::error(
                    Code::E0214,
                    format!(
                        "node {k} is out of range: beam `{of}` has nodes 0..={}",
                        n - 1
                    ),
                )
                .at(ks, "no such node")
                .hint(format!(
                    "{} elements of {} nodes give {n} nodes",
                    beam.elements, beam.order
                ))));
            }
            (node(k as usize), beam.length * k as f64 / (n - 1) as f64)
        }
        ("at", None, Some((Value::Scalar { value, dim }, vs))) => {
            if *dim != Dim::LENGTH || !(0.0..=beam.length * (1.0 + 1e-12)).contains(value) {
                return Some(Err(Diagnostic::error(
                    Code::E0214,
                    format!(
                        "`at(s)` on beam `{of}` needs an arc length in [0, {} m]",
                        beam.length
                    ),
                )
                .at(*vs, "outside the beam")
                .hint("s is the distance from the beam's start, in metres")));
            }
            let k = value / beam.length * (n - 1) as f64;
            if (k - k.round()).abs() < 1e-9 {
                (node(k.round() as usize), *value)
            } else {
                (
                    Attach::BeamPoint {
                        beam: bi,
                        s: *value,
                    },
                    *value,
                )
            }
        }
        _ => return None,
    }))
}
