//! Output channels: `output x = bob.position.x, tension = link.force, rotor.lag[1].angle`.
//!
//! Contract: resolves each output path and names its columns, each once (the quantities of each
//! family of entity are in `probes.rs`); must not know the runtime.

use super::{Builder, Built};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::model::scope::env::{Ref, ScopeId, Seg};
use crate::model::*;
use crate::syntax::ast::{ExprKind, MarkerRef, OutputItem, OutputTarget, Path, Segment};
use std::collections::HashMap;

/// Splits `a.force.in(m).x` into the path before `.in(...)`, the marker, and the segments
/// after it. Only a path argument is a marker (`in(hub)`, `in(rotor.blade[1].start)`).
fn split_in(path: &Path) -> Option<(Path, MarkerRef, Vec<Segment>)> {
    let k = path
        .segments
        .iter()
        .enumerate()
        .skip(1)
        .find(|(_, s)| s.name.name == "in" && s.index.is_none() && s.arg.is_some())?
        .0;
    let arg = path.segments[k].arg.as_deref()?;
    let marker_path = match &arg.kind {
        ExprKind::Path { path } => path.clone(),
        _ => Path {
            segments: Vec::new(),
            span: arg.span,
        },
    };
    let head = Path {
        segments: path.segments[..k].to_vec(),
        span: path.span,
    };
    Some((
        head,
        MarkerRef {
            path: marker_path,
            offset: None,
            span: arg.span,
        },
        path.segments[k + 1..].to_vec(),
    ))
}

impl Builder<'_> {
    pub(super) fn outputs(&mut self, items: &[(OutputItem, ScopeId)]) -> Vec<OutputChannel> {
        let mut out: Vec<OutputChannel> = Vec::new();
        let mut columns: HashMap<String, Span> = HashMap::new();
        columns.insert("t".to_string(), Span::default());
        for (item, scope) in items {
            let scope = *scope;
            let probes = match &item.target {
                OutputTarget::Path(path) => self.probes(scope, path),
                OutputTarget::Call(call) => self.call_probes(scope, call),
            };
            let Some(probes) = probes else {
                continue;
            };
            let base = match &item.name {
                Some(n) => match &n.index {
                    // `zeta[i] = ...` in a loop names columns zeta1, zeta2, ...
                    Some(e) => match self.env.integer_in(scope, e, "an index") {
                        Ok(i) => format!("{}{i}", n.ident.name),
                        Err(d) => {
                            self.error(scope, d);
                            continue;
                        }
                    },
                    None => n.ident.name.clone(),
                },
                None => match &item.target {
                    OutputTarget::Path(path) => self
                        .written(scope, path)
                        .unwrap_or_else(|| path.text().replace("[..]", "").replace("(..)", "")),
                    OutputTarget::Call(call) => self.call_column(scope, call),
                },
            };
            // Outputs declared in a component instance are named after it: `rotor.tension`.
            let home = self.env.scopes[scope].home;
            let base = format!("{}{base}", self.env.scopes[home].prefix);
            for (suffix, probe) in probes {
                let column = format!("{base}{suffix}");
                if let Some(first) = columns.get(&column) {
                    let mut d = Diagnostic::error(
                        Code::E0203,
                        format!("output column `{column}` is declared twice"),
                    )
                    .at(item.span, "second column of that name");
                    if first.end > 0 {
                        d = d.at(*first, "first declared here");
                    }
                    self.error(scope, d.hint("name the output: `output NAME = PATH`"));
                    continue;
                }
                columns.insert(column.clone(), item.span);
                out.push(OutputChannel {
                    column,
                    probe,
                    span: item.span,
                });
            }
        }
        out
    }

    /// `joint.force.in(MARKER)`, `joint.moment.in(MARKER).x`: the vector in the marker's axes.
    fn probes_in(
        &mut self,
        scope: ScopeId,
        path: &Path,
        head: &Path,
        marker: &MarkerRef,
        tail: &[Segment],
    ) -> Option<Vec<(String, Probe)>> {
        let mut plain = head.clone();
        plain.segments.extend_from_slice(tail);
        let probes = self.probes(scope, &plain)?;
        let vector = probes.iter().all(|(_, p)| {
            matches!(
                p,
                Probe::Joint {
                    quantity: JointQuantity::Force | JointQuantity::Moment,
                    component: Some(_),
                    ..
                }
            )
        });
        if !vector {
            self.error(
                scope,
                Diagnostic::error(
                    Code::E0212,
                    format!("`{}`: `.in(MARKER)` applies to a joint's force or moment", path.text()),
                )
                .at(marker.span, "axes for a quantity that has none")
                .hint("write it after a joint's vector load: `hinge.force.in(hub)`, `hinge.moment.in(blade).z` (a distance joint's force is a scalar tension)"),
            );
            return None;
        }
        let m = Box::new(self.marker(scope, marker)?);
        Some(
            probes
                .into_iter()
                .map(|(suffix, p)| match p {
                    Probe::Joint {
                        joint,
                        quantity,
                        component,
                        ..
                    } => (
                        suffix,
                        Probe::Joint {
                            joint,
                            quantity,
                            component,
                            axes: Some(m.clone()),
                        },
                    ),
                    other => (suffix, other),
                })
                .collect(),
        )
    }

    /// The path as the column name: indices evaluated, `rotor.lag[1].angle`,
    /// `lag.force.in(hub).x`.
    pub(super) fn written(&mut self, scope: ScopeId, path: &Path) -> Option<String> {
        if let Some((head, marker, tail)) = split_in(path) {
            let mut text = self.written(scope, &head)?;
            text.push_str(&format!(".in({})", self.written(scope, &marker.path)?));
            for s in &tail {
                text.push('.');
                text.push_str(&s.name.name);
            }
            return Some(text);
        }
        let segs = self.env.segs(scope, path).ok()?;
        Some(
            segs.iter()
                .map(|s| match (s.index, &s.arg) {
                    (Some((i, _)), _) => format!("{}[{i}]", s.name.name),
                    (None, Some((crate::model::eval::Value::Scalar { value, .. }, _))) => {
                        format!("{}({value})", s.name.name)
                    }
                    _ => s.name.name.clone(),
                })
                .collect::<Vec<_>>()
                .join("."),
        )
    }

    pub(super) fn bad_quantity(
        &mut self,
        scope: ScopeId,
        at: &Seg,
        what: &str,
        known: &[&str],
    ) -> Option<Vec<(String, Probe)>> {
        let hint = match did_you_mean(&at.name.name, known.iter().copied()) {
            Some(s) => format!("did you mean `{s}`? {what} provides: {}", known.join(", ")),
            None => format!("{what} provides: {}", known.join(", ")),
        };
        self.error(
            scope,
            Diagnostic::error(
                Code::E0212,
                format!("`{}` is not an output quantity of {what}", at.name.name),
            )
            .at(at.span, "unknown quantity")
            .hint(hint),
        );
        None
    }

    pub(super) fn missing_quantity(
        &mut self,
        scope: ScopeId,
        span: Span,
        what: &str,
        known: &[&str],
    ) -> Option<Vec<(String, Probe)>> {
        self.error(
            scope,
            Diagnostic::error(
                Code::E0212,
                format!("say which quantity of {what} to output"),
            )
            .at(span, "no quantity")
            .hint(format!("{what} provides: {}", known.join(", "))),
        );
        None
    }

    /// The probes a path names, each with its column suffix: `.x` for a component of a
    /// vector, empty for a single column.
    fn probes(&mut self, scope: ScopeId, path: &Path) -> Option<Vec<(String, Probe)>> {
        if let Some((head, marker, tail)) = split_in(path) {
            return self.probes_in(scope, path, &head, &marker, &tail);
        }
        if let Some(single) = path.single() {
            let energy = match single.name.as_str() {
                "kinetic_energy" => Some(EnergyKind::Kinetic),
                "potential_energy" => Some(EnergyKind::Potential),
                "total_energy" => Some(EnergyKind::Total),
                _ => None,
            };
            if let (Some(kind), None) = (energy, self.env.lookup(scope, &single.name)) {
                return Some(vec![(String::new(), Probe::Energy { kind })]);
            }
        }
        let segs = match self.env.segs(scope, path) {
            Ok(s) => s,
            Err(d) => {
                self.error(scope, d);
                return None;
            }
        };
        let (r, rest) = match self.env.resolve(scope, &segs, path.span) {
            Ok(x) => x,
            Err(d) => {
                self.error(scope, d);
                return None;
            }
        };
        let d = match r {
            Ref::Decl(d) => d,
            _ => {
                self.error(
                    scope,
                    Diagnostic::error(Code::E0212, format!("`{}` is not something the model can output", path.text()))
                        .at(path.span, "not a body, beam or joint")
                        .hint("outputs name a body, a beam point or a joint quantity, e.g. `bob.position.x`, `link.force`, `rotor.lag[1].angle`, or `kinetic_energy`"),
                );
                return None;
            }
        };
        let name = self.env.decls[d].name.clone();
        match self.built[d]? {
            Built::Body(b) => self.body_probes(scope, path, b, &name, &rest),
            Built::Beam(bi) => self.beam_probes(scope, path, bi, &name, &rest),
            Built::Joint(j) => self.joint_probes(scope, path, j, &name, &rest),
            Built::Ground(_) => {
                self.error(
                    scope,
                    Diagnostic::error(
                        Code::E0212,
                        format!("ground `{name}` has no output quantities"),
                    )
                    .at(path.span, "a ground does not move")
                    .hint("output a body's position, velocity or acceleration, or a joint's force"),
                );
                None
            }
            _ => {
                self.error(
                    scope,
                    Diagnostic::error(Code::E0212, format!("`{name}` has no output quantities"))
                        .at(path.span, "not a body, beam or joint")
                        .hint("output a body, a beam point or a joint quantity"),
                );
                None
            }
        }
    }
}
