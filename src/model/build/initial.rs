//! Initial motion: `initial spin of PATH = rate about AXIS through POINT` and `initial
//! velocity of PATH = v` add a rigid motion to every body and beam node they name.
//! Contract: runs after every body and beam is built and changes only their velocities;
//! must not build entities.

use super::{add, cross, scale, sub, Builder, Built};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::model::eval::units::Dim;
use crate::model::scope::env::{Member, Ref};
use crate::model::*;
use crate::syntax::ast::{Expr, Item, Path};

const RATE: Dim = Dim::new(0, 0, -1);

/// A rigid motion: angular velocity `w`, plus velocity `v`, about the point `p`.
struct Rigid {
    w: [f64; 3],
    v: [f64; 3],
    p: [f64; 3],
}

impl Builder<'_> {
    /// Adds a rigid motion to every body and beam node of an instance, to one body or beam, or
    /// to every member of a family of them (`blade`, declared in a loop).
    pub(super) fn initial(&mut self, item: &Item, scope: usize) {
        let Item::Initial {
            what,
            target,
            value,
            about,
            through,
            span,
        } = item
        else {
            return;
        };
        let spin = match what.name.as_str() {
            "spin" => true,
            "velocity" => false,
            other => {
                let hint = match did_you_mean(other, ["spin", "velocity"]) {
                    Some(s) => format!("did you mean `{s}`?"),
                    None => "write `initial spin of PATH = rate about AXIS through POINT` or `initial velocity of PATH = (vx, vy, vz) m/s`".to_string(),
                };
                self.error(
                    scope,
                    Diagnostic::error(Code::E0211, format!("unknown initial motion `{other}`"))
                        .at(what.span, "not `spin` or `velocity`")
                        .hint(hint),
                );
                return;
            }
        };
        let Some(prefixes) = self.moved_prefixes(scope, target) else {
            return;
        };
        let motion = if spin {
            self.spin(scope, value, about.as_ref(), through.as_ref(), *span)
        } else {
            self.velocity(scope, value, about.as_ref().or(through.as_ref()))
        };
        let Some(motion) = motion else {
            return;
        };
        let moved = self.add_motion(&prefixes, &motion);
        let failed = prefixes
            .iter()
            .any(|p| self.failed_within(p.trim_end_matches('.')));
        if moved == 0 && !failed {
            self.error(
                scope,
                Diagnostic::error(Code::E0222, "this initial motion moves no body")
                    .at(target.span, "contains no bodies or beams")
                    .hint("name an instance that declares bodies, or a body"),
            );
        }
    }

    /// The qualified names (or instance prefixes) of what `target` moves: a body, a beam, an
    /// instance, or every member of a family of them. `None` once an error is reported.
    fn moved_prefixes(&mut self, scope: usize, target: &Path) -> Option<Vec<String>> {
        let segs = match self.env.segs(scope, target) {
            Ok(s) => s,
            Err(d) => {
                self.error(scope, d);
                return None;
            }
        };
        let members = match self.env.resolve_family(scope, &segs, target.span) {
            Ok((_, rest)) if !rest.is_empty() => return self.not_movable(scope, target),
            Ok((Ref::Instance(s), _)) => vec![Member::Instance(s)],
            Ok((Ref::Decl(d), _)) => vec![Member::Decl(d)],
            Ok((Ref::Family(m), _)) => m.into_iter().map(|x| x.1).collect(),
            Ok(_) => return self.not_movable(scope, target),
            Err(d) => {
                self.error(scope, d);
                return None;
            }
        };
        let mut prefixes = Vec::new();
        for m in members {
            match m {
                Member::Instance(s) => prefixes.push(self.env.scopes[s].prefix.clone()),
                Member::Decl(d)
                    if matches!(self.built[d], Some(Built::Body(_)) | Some(Built::Beam(_))) =>
                {
                    prefixes.push(self.env.decls[d].name.clone())
                }
                // A body that failed to build: its error has been reported.
                Member::Decl(d) if self.failed_within(&self.env.decls[d].name) => return None,
                Member::Decl(_) => return self.not_movable(scope, target),
            }
        }
        Some(prefixes)
    }

    fn not_movable(&mut self, scope: usize, target: &Path) -> Option<Vec<String>> {
        self.error(
            scope,
            Diagnostic::error(
                Code::E0222,
                "initial motion applies to a body, a beam or a component instance",
            )
            .at(target.span, "not a body, beam or instance")
            .hint(
                "name a body (`hub`), a beam, an instance (`rotor`), or a family of them (`blade`)",
            ),
        );
        None
    }

    fn spin(
        &mut self,
        scope: usize,
        value: &Expr,
        about: Option<&Expr>,
        through: Option<&Expr>,
        span: Span,
    ) -> Option<Rigid> {
        let rate = self.scalar(scope, value, RATE, "the spin rate");
        let axis = match about {
            Some(e) => self.direction(scope, e, "the spin axis"),
            None => {
                self.missing(scope, span, "about AXIS", "`initial spin`", "z");
                None
            }
        };
        let point = match through {
            Some(e) => self.vector(
                scope,
                e,
                Dim::LENGTH,
                "the point the spin axis goes through",
            ),
            None => Some([0.0; 3]),
        };
        let (rate, axis, point) = (rate?, axis?, point?);
        Some(Rigid {
            w: scale(axis, rate),
            v: [0.0; 3],
            p: point,
        })
    }

    fn velocity(&mut self, scope: usize, value: &Expr, axis: Option<&Expr>) -> Option<Rigid> {
        if let Some(e) = axis {
            self.error(
                scope,
                Diagnostic::error(Code::E0224, "`initial velocity` takes no axis")
                    .at(e.span, "here")
                    .hint("write `initial velocity of PATH = (vx, vy, vz) m/s`"),
            );
            return None;
        }
        let v = self.vector(scope, value, Dim::VELOCITY, "the initial velocity")?;
        Some(Rigid {
            w: [0.0; 3],
            v,
            p: [0.0; 3],
        })
    }

    /// Adds the motion to the bodies and beams named by `prefixes`; how many it moved.
    fn add_motion(&mut self, prefixes: &[String], m: &Rigid) -> usize {
        let inside = |name: &str| {
            prefixes.iter().any(|prefix| {
                name == prefix
                    || (prefix.ends_with('.') && name.starts_with(prefix.as_str()))
                    || name.starts_with(&format!("{prefix}."))
            })
        };
        let mut moved = 0;
        for i in 0..self.bodies.len() {
            if inside(&self.env.decls[self.body_decl[i]].name) {
                let b = &mut self.bodies[i];
                b.velocity = add(b.velocity, add(m.v, cross(m.w, sub(b.position, m.p))));
                if b.kind == BodyKind::Rigid {
                    b.angular_velocity = add(b.angular_velocity, m.w);
                }
                moved += 1;
            }
        }
        for i in 0..self.beams.len() {
            if inside(&self.env.decls[self.beam_decl[i]].name) {
                let b = &mut self.beams[i];
                for k in 0..b.nodes.len() {
                    b.velocities[k] = add(
                        b.velocities[k],
                        add(m.v, cross(m.w, sub(b.initial_nodes[k], m.p))),
                    );
                    b.angular_velocities[k] = add(b.angular_velocities[k], m.w);
                }
                moved += 1;
            }
        }
        moved
    }
}
