//! Distributed loads: `distributed_force NAME on BEAM = (x, y, z) N/m` and
//! `distributed_torque NAME on BEAM = (x, y, z) N*m/m`, functions of the time `t` and of the
//! arc length `span` along the beam, in inertial components or in the section's axes
//! (`follower`).
//! Contract: builds `DistributedLoad`s on built beams; must not lower them.

use super::{Builder, Built, View};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::eval::units::{Dim, Quantity};
use crate::model::scope::env::Ref;
use crate::model::*;
use crate::syntax::ast::MarkerRef;

/// Force per length and torque per length.
const FORCE_PER_LENGTH: Quantity =
    Quantity::new(Dim::new(1, 0, -2), "a force per length", "N/m", "120 N/m");
const TORQUE_PER_LENGTH: Quantity =
    Quantity::new(Dim::FORCE, "a torque per length", "N*m/m", "3 N*m/m");

impl Builder<'_> {
    pub(super) fn distributed_load(&mut self, v: &View) -> Option<Built> {
        let force = v.kind.name == "distributed_force";
        let (k, want, unit) = if force {
            ("distributed_force", FORCE_PER_LENGTH, "N/m")
        } else {
            ("distributed_torque", TORQUE_PER_LENGTH, "N*m/m")
        };
        let example = format!("{k} NAME on BEAM = (x, y, z) {unit}");
        if !self.shape(v, 0, true, true, &["follower"], &example) {
            return None;
        }
        if let Some(b) = &v.block {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0224, format!("a {k} takes no block"))
                    .at(b.span, "here")
                    .hint(format!("write `{example}`")),
            );
        }
        let (on, value) = (v.on.clone()?, v.value.clone()?);
        let beam = self.beam_of(v.scope, &on, k);
        self.span_allowed = true;
        let parts = self.signal(v.scope, &value, want, &format!("{k} `{}`", v.name), true);
        self.span_allowed = false;
        let (beam, parts) = (beam?, parts?);
        let [a, b, c]: [TimeFn; 3] = parts.try_into().ok()?;
        self.distributed.push(DistributedLoad {
            name: v.name.clone(),
            span: v.span,
            kind: if force {
                LoadKind::Force
            } else {
                LoadKind::Torque
            },
            beam,
            value: [a, b, c],
            follower: Self::has_flag(v, "follower"),
        });
        Some(Built::Distributed(self.distributed.len() - 1))
    }

    /// The elastic beam a distributed load names (`on blade`), as a whole.
    fn beam_of(&mut self, scope: usize, m: &MarkerRef, kind: &str) -> Option<usize> {
        let segs = match self.env.segs(scope, &m.path) {
            Ok(s) => s,
            Err(d) => {
                self.error(scope, d);
                return None;
            }
        };
        let (r, rest, _) = match self.env.resolve_marker(scope, &segs, m.path.span) {
            Ok(x) => x,
            Err(d) => {
                self.error(scope, d);
                return None;
            }
        };
        let built = match r {
            Ref::Decl(d) => self.built[d],
            _ => None,
        };
        let what = match built {
            Some(Built::Beam(bi)) if rest.is_empty() && m.offset.is_none() => return Some(bi),
            Some(Built::Beam(_)) => "a point on a beam",
            Some(Built::Body(_)) => "a rigid body",
            None if matches!(r, Ref::Decl(d) if self.failed(d)) => return None,
            _ => "not a beam",
        };
        let hint = if what == "a rigid body" {
            "a distributed load acts along an elastic `beam`; on a rigid body apply its resultant as a `force` at a marker"
        } else {
            "name the whole beam (`on blade`); the load acts along all of it, and `span` (its arc length) shapes it"
        };
        self.error(
            scope,
            Diagnostic::error(
                Code::E0222,
                format!("a {kind} acts on a beam, and `{}` is {what}", m.path.text()),
            )
            .at(m.span, "a beam is needed here")
            .hint(hint),
        );
        None
    }

    /// Whether declaration `d` is an entity whose own declaration failed (and was reported).
    fn failed(&self, d: usize) -> bool {
        self.built[d].is_none()
            && !matches!(
                &*self.env.decls[d].item,
                crate::syntax::ast::Item::Joint { .. }
            )
            && self.env.decls[d].item_kind().is_some()
    }
}
