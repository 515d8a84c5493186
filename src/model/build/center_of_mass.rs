//! `center_of_mass(OF)`: the centre of mass of a body, a beam, a component instance (every
//! body and beam declared in it, recursively) or a family of them, each with the concentrated
//! masses it carries. The runtime weighs each mass centre as its element's inertial forces do
//! (a rigid body's `x + R eta`, a beam's section mass at the inertial quadrature points).
//!
//! Contract: resolves the call to bodies and beams and builds `Probe::CenterOfMass` channels; must
//! not weigh the masses (the runtime does).

use super::output_calls::segment;
use super::probes::AXES;
use super::{Builder, Built};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::scope::env::{Member, Ref, ScopeId, Seg};
use crate::model::*;
use crate::syntax::ast::{OutputArg, OutputCall};

/// What may follow `center_of_mass(...)`.
const CM_Q: &[&str] = &["x", "y", "z", "position", "velocity", "acceleration"];

impl Builder<'_> {
    /// `center_of_mass(X)`: the mass-weighted mean of the mass centres of the bodies and beams
    /// X names.
    pub(super) fn center_of_mass(
        &mut self,
        scope: ScopeId,
        call: &OutputCall,
        of: Option<&OutputArg>,
    ) -> Option<Vec<(String, Probe)>> {
        let Some(a) = of else {
            self.arg_error(
                scope,
                call.span,
                "`center_of_mass` needs what to weigh".to_string(),
                "no argument".to_string(),
                "name a body, a beam or a component instance: `output cm = center_of_mass(rotor)`"
                    .to_string(),
            );
            return None;
        };
        let (bodies, beams) = self.massive(scope, a)?;
        let mass: f64 = bodies.iter().map(|&b| self.bodies[b].mass).sum::<f64>()
            + beams
                .iter()
                .map(|&b| {
                    let beam = &self.beams[b];
                    beam.section.mass_per_length * beam.length
                        + beam.point_masses.iter().map(|p| p.1).sum::<f64>()
                })
                .sum::<f64>();
        let text = self
            .written(scope, &a.value)
            .unwrap_or_else(|| a.value.text());
        if mass.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            let d = Diagnostic::error(
                Code::E0228,
                format!("`{text}` has no mass, so it has no centre of mass"),
            )
            .at(a.value.span, "massless");
            return self.fail(
                scope,
                d.hint("name a body, a beam or an instance that has mass; a massless hub is held by its joints and has none"),
            );
        }
        let comps: Vec<Seg> = call.components.iter().map(segment).collect();
        let (quantity, rest) = match comps.first().map(|c| c.name.name.as_str()) {
            None | Some("x" | "y" | "z") => (BodyQuantity::Position, &comps[..]),
            Some("position") => (BodyQuantity::Position, &comps[1..]),
            Some("velocity") => (BodyQuantity::Velocity, &comps[1..]),
            Some("acceleration") => (BodyQuantity::Acceleration, &comps[1..]),
            Some(_) => {
                return self.bad_quantity(scope, &comps[0], "`center_of_mass`", CM_Q);
            }
        };
        self.components(scope, rest, &AXES, |component| Probe::CenterOfMass {
            bodies: bodies.clone(),
            beams: beams.clone(),
            quantity,
            component,
        })
    }

    /// The bodies and beams an argument of `center_of_mass` names.
    fn massive(&mut self, scope: ScopeId, a: &OutputArg) -> Option<(Vec<usize>, Vec<usize>)> {
        let path = &a.value;
        let (text, r, rest) = self.resolve_arg(scope, a)?;
        let not_massive = |what: String| {
            Diagnostic::error(
                Code::E0228,
                format!("`{text}` is {what}, not a body, a beam or a component instance"),
            )
            .at(path.span, "nothing to weigh")
            .hint("`center_of_mass` takes a body, a beam, a component instance (every body declared in it) or a family of them: `center_of_mass(rotor)`")
        };
        if let Some(q) = rest.first() {
            let d = not_massive(format!("a quantity (`.{}`)", q.name.name));
            return self.fail(scope, d);
        }
        let members: Vec<Member> = match r {
            Ref::Decl(d) => vec![Member::Decl(d)],
            Ref::Instance(s) => vec![Member::Instance(s)],
            Ref::Family(m) => m.into_iter().map(|x| x.1).collect(),
            Ref::Binding(_) | Ref::Builtin(_) => {
                return self.fail(scope, not_massive("a value".to_string()))
            }
            Ref::Component(c) => {
                return self.fail(
                    scope,
                    not_massive(format!("component `{}` (a definition)", c.name.name)),
                )
            }
        };
        let (mut bodies, mut beams) = (Vec::new(), Vec::new());
        for m in members {
            match m {
                Member::Decl(d) => match self.built[d] {
                    Some(Built::Body(b)) => bodies.push(b),
                    Some(Built::Beam(b)) => beams.push(b),
                    None if self.env.decls[d].item_kind().is_some_and(|k| {
                        matches!(k, "point_mass" | "rigid" | "rigid_rod" | "beam")
                    }) =>
                    {
                        // Its own error has been reported.
                        return None;
                    }
                    _ => {
                        let kind = self.env.decls[d].item_kind().unwrap_or("a declaration");
                        let what = if kind == "joint" {
                            "a joint".to_string()
                        } else {
                            format!("a `{kind}`")
                        };
                        return self.fail(scope, not_massive(what));
                    }
                },
                Member::Instance(s) => {
                    let prefix = self.env.scopes[s].prefix.clone();
                    if self.failed_within(prefix.trim_end_matches('.')) {
                        // Its bodies' errors have been reported.
                        return None;
                    }
                    let inside = |name: &str| name.starts_with(&prefix);
                    for (i, &d) in self.body_decl.iter().enumerate() {
                        if inside(&self.env.decls[d].name) {
                            bodies.push(i);
                        }
                    }
                    for (i, &d) in self.beam_decl.iter().enumerate() {
                        if inside(&self.env.decls[d].name) {
                            beams.push(i);
                        }
                    }
                }
            }
        }
        bodies.sort_unstable();
        bodies.dedup();
        beams.sort_unstable();
        beams.dedup();
        if bodies.is_empty() && beams.is_empty() {
            let d = Diagnostic::error(
                Code::E0228,
                format!("`{text}` declares no bodies or beams, so it has no centre of mass"),
            )
            .at(path.span, "nothing to weigh")
            .hint("name an instance that declares bodies, a body or a beam");
            return self.fail(scope, d);
        }
        Some((bodies, beams))
    }
}
