//! Closed-form solutions of output channels: `exact phi = Omega * t`.
//!
//! Contract: each declaration names one output channel (its CSV column) and gives a scalar
//! function of time with that channel's dimension, built by the same evaluator as loads and
//! prescribed motions. Nothing in a run uses it; `mbd study --reference exact` compares the
//! channel with it. Reports unknown channels (E0405), a second solution for one channel
//! (E0406) and values that are not scalar functions of time (E0407).

use super::Builder;
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::model::eval::units::Dim;
use crate::model::eval::Value;
use crate::model::scope::env::ScopeId;
use crate::model::*;
use crate::syntax::ast::{Item, Path};
use std::collections::HashMap;

impl Builder<'_> {
    pub(super) fn exacts(
        &mut self,
        items: &[(Item, ScopeId)],
        outputs: &[OutputChannel],
    ) -> Vec<ExactReference> {
        let mut out = Vec::new();
        let mut seen: HashMap<String, Span> = HashMap::new();
        for (item, scope) in items {
            let Item::Exact {
                channel,
                value,
                span,
            } = item
            else {
                continue;
            };
            let scope = *scope;
            // The value first: its own errors are reported whatever the channel.
            let v = self.value(scope, value);
            let Some(column) = self.channel(scope, channel, outputs) else {
                continue;
            };
            if let Some(first) = seen.get(&column.column) {
                let d = Diagnostic::error(
                    Code::E0406,
                    format!("channel `{}` has two exact solutions", column.column),
                )
                .at(*span, "second exact solution")
                .at(*first, "first declared here")
                .hint("a channel has one closed-form solution: remove one of them");
                self.error(scope, d);
                continue;
            }
            seen.insert(column.column.clone(), *span);
            let Some(v) = v else {
                continue;
            };
            let f = match &v {
                Value::Scalar { value, .. } => crate::runtime::timefn::TimeFn::constant(*value),
                Value::Signal { parts, .. } if parts.len() == 1 && parts[0].has_arc() => {
                    let d = Diagnostic::error(
                        Code::E0401,
                        format!(
                            "the exact solution of `{}` cannot depend on `span`",
                            column.column
                        ),
                    )
                    .at(value.span, "this varies along a beam")
                    .hint(super::values::SPAN_HINT);
                    self.error(scope, d);
                    continue;
                }
                Value::Signal { parts, .. } if parts.len() == 1 => parts[0].clone(),
                _ => {
                    let d = Diagnostic::error(
                        Code::E0407,
                        format!(
                            "the exact solution of `{}` must be a scalar function of time, found {}",
                            column.column,
                            v.kind_name()
                        ),
                    )
                    .at(value.span, format!("this is {}", v.kind_name()))
                    .hint("a channel holds one number per time: write a scalar expression of `t`; for a vector quantity, output one component (`output fy = link.force.y`) and give its solution");
                    self.error(scope, d);
                    continue;
                }
            };
            if let Some(dim) = channel_dim(&self.joints, &column.probe) {
                if v.dim() != dim {
                    let d = Diagnostic::error(
                        Code::E0202,
                        format!(
                            "channel `{}` is {}, its exact solution {}",
                            column.column,
                            dim.describe(),
                            v.dim().describe()
                        ),
                    )
                    .at(value.span, format!("this is {}", v.dim().describe()))
                    .at(column.span, "the channel is declared here")
                    .hint(super::unit_hint(dim.into(), false));
                    self.error(scope, d);
                    continue;
                }
            }
            out.push(ExactReference {
                column: column.column.clone(),
                f,
                span: *span,
            });
        }
        out
    }

    /// The output channel a path names: its column as written with indices evaluated
    /// (`rotor.lag[1].angle`), or, for an indexed name, the column a loop's `output zeta[i]`
    /// makes (`zeta1`).
    fn channel<'o>(
        &mut self,
        scope: ScopeId,
        path: &Path,
        outputs: &'o [OutputChannel],
    ) -> Option<&'o OutputChannel> {
        let segs = match self.env.segs(scope, path) {
            Ok(s) => s,
            Err(d) => {
                self.error(scope, d);
                return None;
            }
        };
        let written = segs
            .iter()
            .map(|s| match (s.index, &s.arg) {
                (Some((i, _)), _) => format!("{}[{i}]", s.name.name),
                (None, Some((Value::Scalar { value, .. }, _))) => {
                    format!("{}({value})", s.name.name)
                }
                _ => s.name.name.clone(),
            })
            .collect::<Vec<_>>()
            .join(".");
        let looped = match segs.as_slice() {
            [s] => s.index.map(|(i, _)| format!("{}{i}", s.name.name)),
            _ => None,
        };
        if let Some(c) = outputs
            .iter()
            .find(|c| c.column == written || Some(&c.column) == looped.as_ref())
        {
            return Some(c);
        }
        let names: Vec<&str> = outputs.iter().map(|c| c.column.as_str()).collect();
        let hint = match (did_you_mean(&written, names.iter().copied()), names.len()) {
            (_, 0) => "the model declares no outputs; declare the channel first, e.g. `output phi = root.angle`".to_string(),
            (Some(s), _) => format!("did you mean `{s}`? The channels are: {}", names.join(", ")),
            (None, _) => format!(
                "`exact` names an output channel (a CSV column); the channels are: {}",
                names.join(", ")
            ),
        };
        self.error(
            scope,
            Diagnostic::error(
                Code::E0405,
                format!("`exact {written}` names no output channel"),
            )
            .at(path.span, "not an output channel")
            .hint(hint),
        );
        None
    }
}

/// The physical dimension of what a probe measures (`None` where it varies by row, as for
/// a joint's constraint violation).
pub fn channel_dim(joints: &[Joint], probe: &Probe) -> Option<Dim> {
    let body = |q: BodyQuantity| match q {
        BodyQuantity::Position => Dim::LENGTH,
        BodyQuantity::Velocity => Dim::VELOCITY,
        BodyQuantity::Acceleration => Dim::ACCELERATION,
        BodyQuantity::AngularVelocity => Dim::NONE.over(Dim::TIME),
        BodyQuantity::AngularAcceleration => Dim::NONE.over(Dim::TIME).over(Dim::TIME),
        BodyQuantity::Rotation | BodyQuantity::Crv => Dim::NONE,
    };
    match probe {
        Probe::Body { quantity, .. } | Probe::Point { quantity, .. } => Some(body(*quantity)),
        Probe::Energy { .. } => Some(Dim::FORCE.times(Dim::LENGTH)),
        Probe::CenterOfMass { quantity, .. } => Some(body(*quantity)),
        // Angles are dimensionless, and so are their multiblade coordinates.
        Probe::Multiblade { .. } => Some(Dim::NONE),
        Probe::Joint {
            joint, quantity, ..
        } => {
            let prismatic = matches!(
                joints.get(*joint).map(|j| &j.kind),
                Some(JointKind::Prismatic { .. })
            );
            match (quantity, prismatic) {
                (JointQuantity::Force, _) => Some(Dim::FORCE),
                (JointQuantity::Moment, _) => Some(Dim::FORCE.times(Dim::LENGTH)),
                (JointQuantity::Angle, false) => Some(Dim::NONE),
                (JointQuantity::Angle, true) => Some(Dim::LENGTH),
                (JointQuantity::Rate, false) => Some(Dim::NONE.over(Dim::TIME)),
                (JointQuantity::Rate, true) => Some(Dim::VELOCITY),
                (JointQuantity::Violation, _) => None,
            }
        }
    }
}
