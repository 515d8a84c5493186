//! Joints, springs and dampers, loads, and initial motion.

use super::{add, cross, dot, norm, scale, sub, Builder, Built, View};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::model::eval::units::{self, Dim, Quantity};
use crate::model::scope::env::{Member, Ref};
use crate::model::*;
use crate::syntax::ast::{Item, MarkerRef};

const RATE: Dim = Dim::new(0, 0, -1);

/// The joint kinds, for "did you mean".
const JOINTS: &[&str] = &[
    "revolute",
    "spherical",
    "fixed",
    "prismatic",
    "universal",
    "cylindrical",
    "distance",
];

/// A property's expression, if it is one (not a block).
fn prop_expr(p: &crate::syntax::ast::Prop) -> Option<&crate::syntax::ast::Expr> {
    match &p.value {
        crate::syntax::ast::PropValue::Expr(e) => Some(e),
        crate::syntax::ast::PropValue::Block(_) => None,
    }
}

impl Builder<'_> {
    /// W0203 if the angle `e` of `what` is a bare number (`value`: its constant value, `None`
    /// for a function of time).
    pub(super) fn angle_unit(
        &mut self,
        scope: usize,
        e: Option<&crate::syntax::ast::Expr>,
        value: Option<f64>,
        what: &str,
    ) {
        if let Some(d) = e.and_then(|e| self.env.bare_angle(scope, e, value, what)) {
            self.error(scope, d);
        }
    }

    /// Resolves the two markers of a connection and rejects one that connects nothing.
    fn pair(
        &mut self,
        scope: usize,
        what: &str,
        name: &str,
        markers: &[MarkerRef],
        span: Span,
    ) -> Option<[Marker; 2]> {
        if markers.len() != 2 {
            self.error(
                scope,
                Diagnostic::error(
                    Code::E0224,
                    format!(
                        "{what} `{name}` connects 2 markers, found {}",
                        markers.len()
                    ),
                )
                .at(markers.first().map(|m| m.span).unwrap_or(span), "here")
                .hint(format!("write `({}, {})`", "a", "b")),
            );
            return None;
        }
        let a = self.marker(scope, &markers[0]);
        let b = self.marker(scope, &markers[1]);
        let (a, b) = (a?, b?);
        let same = match (a.attach, b.attach) {
            (Attach::Ground { .. }, Attach::Ground { .. }) => {
                self.error(
                    scope,
                    Diagnostic::error(
                        Code::E0305,
                        format!("{what} `{name}` connects the ground to the ground"),
                    )
                    .at(markers[0].span, "fixed")
                    .at(markers[1].span, "fixed too")
                    .hint("connect at least one body"),
                );
                return None;
            }
            (Attach::Body { body: x }, Attach::Body { body: y }) => x == y,
            (Attach::BeamNode { beam: x, node: i }, Attach::BeamNode { beam: y, node: j }) => {
                x == y && i == j
            }
            _ => false,
        };
        if same {
            self.error(
                scope,
                Diagnostic::error(
                    Code::E0301,
                    format!("{what} `{name}` connects `{}` to itself", a.text),
                )
                .at(markers[0].span, "this marker")
                .at(markers[1].span, "and this one are on the same body")
                .hint("connect the body to another body or to ground"),
            );
            return None;
        }
        Some([a, b])
    }

    pub(super) fn joint(&mut self, d: usize) {
        let decl = &self.env.decls[d];
        let (scope, qname) = (decl.scope, decl.name.clone());
        let Item::Joint {
            kind,
            markers,
            block,
            span,
            ..
        } = &*decl.item.clone()
        else {
            return;
        };
        let props: &[&'static str] = match kind.name.as_str() {
            "revolute" => &[
                "axis",
                "spring",
                "damper",
                "rest_angle",
                "angle",
                "rate",
                "torque",
            ],
            "prismatic" => &["axis", "spring", "damper", "displacement", "speed", "force"],
            "cylindrical" => &["axis"],
            "universal" => &["axis1", "axis2"],
            "spherical" | "fixed" => &[],
            "distance" => &["length"],
            other => {
                let hint = match did_you_mean(other, JOINTS.iter().copied()) {
                    Some(s) => format!("did you mean `{s}`? Joints: {}", JOINTS.join(", ")),
                    None => format!("joints: {}", JOINTS.join(", ")),
                };
                self.error(
                    scope,
                    Diagnostic::error(Code::E0211, format!("unknown joint kind `{other}`"))
                        .at(kind.span, "not a joint kind")
                        .hint(hint),
                );
                return;
            }
        };
        let of = format!("a {} joint", kind.name);
        let p = self.props(scope, Some(block), props, &of);
        let Some(pair) = self.pair(scope, "joint", &qname, markers, *span) else {
            return;
        };
        let gap = sub(pair[1].position, pair[0].position);
        let size = 1.0f64
            .max(norm(pair[0].position))
            .max(norm(pair[1].position));
        let axis = |this: &mut Self, key: &str| {
            this.required(scope, &p, key, kind.span, &format!("joint `{qname}`"), "z")
                .and_then(|e| this.direction(scope, e, &format!("`{key}`")))
        };
        let coincide = |this: &mut Self, along: Option<[f64; 3]>| {
            let off = match along {
                Some(n) => sub(gap, scale(n, dot(gap, n))),
                None => gap,
            };
            if norm(off) > 1e-8 * size {
                let what = if along.is_some() {
                    "off its axis by"
                } else {
                    "apart by"
                };
                this.error(
                    scope,
                    Diagnostic::error(Code::E0310, format!("the markers of joint `{qname}` are {what} {:.6} m at the start", norm(off)))
                        .at(markers[0].span, format!("at ({:.4}, {:.4}, {:.4})", pair[0].position[0], pair[0].position[1], pair[0].position[2]))
                        .at(markers[1].span, format!("at ({:.4}, {:.4}, {:.4})", pair[1].position[0], pair[1].position[1], pair[1].position[2]))
                        .hint("place the bodies so the joint's points coincide (or lie on its axis), or move a marker with `body @ (x, y, z)`"),
                );
                return false;
            }
            true
        };
        let scalar = |this: &mut Self, key: &str, dim: Quantity| match this.expr(scope, p.get(key))
        {
            Some(e) => this.scalar(scope, e, dim, &format!("`{key}`")),
            None => Some(0.0),
        };
        let signal = |this: &mut Self, key: &str, dim: Quantity| match this.expr(scope, p.get(key))
        {
            Some(e) => this
                .signal(scope, e, dim, &format!("`{key}`"), false)
                .map(|mut v| Some(v.remove(0))),
            None => Some(None),
        };
        let kind = match kind.name.as_str() {
            "revolute" | "prismatic" => {
                let rev = kind.name == "revolute";
                let Some(n) = axis(self, "axis") else { return };
                if !coincide(self, if rev { None } else { Some(n) }) {
                    return;
                }
                let (kdim, cdim, qdim): (Quantity, Quantity, Quantity) = if rev {
                    (
                        units::TORSIONAL_STIFFNESS,
                        Dim::new(1, 2, -1).into(),
                        units::ANGLE,
                    )
                } else {
                    (
                        Dim::new(1, 0, -2).into(),
                        Dim::new(1, 0, -1).into(),
                        Dim::LENGTH.into(),
                    )
                };
                let spring = scalar(self, "spring", kdim);
                let damper = scalar(self, "damper", cdim);
                let rest = if rev {
                    scalar(self, "rest_angle", units::ANGLE)
                } else {
                    Some(0.0)
                };
                let (pos_key, rate_key, load_key) = if rev {
                    ("angle", "rate", "torque")
                } else {
                    ("displacement", "speed", "force")
                };
                let position = signal(self, pos_key, qdim);
                let rate = signal(self, rate_key, qdim.dim.over(Dim::TIME).into());
                let load = signal(
                    self,
                    load_key,
                    if rev {
                        units::TORQUE
                    } else {
                        Dim::FORCE.into()
                    },
                );
                let (
                    Some(spring),
                    Some(damper),
                    Some(rest),
                    Some(position),
                    Some(rate),
                    Some(load),
                ) = (spring, damper, rest, position, rate, load)
                else {
                    return;
                };
                if rev {
                    let rest_expr = p.get("rest_angle").and_then(|q| prop_expr(q));
                    self.angle_unit(scope, rest_expr, Some(rest), "`rest_angle`");
                    let f = position.as_ref().map(|f| f.as_constant());
                    let angle_expr = p.get("angle").and_then(|q| prop_expr(q));
                    self.angle_unit(scope, angle_expr, f.flatten(), "the prescribed `angle`");
                }
                let drives: Vec<&str> = [
                    (pos_key, position.is_some()),
                    (rate_key, rate.is_some()),
                    (load_key, load.is_some()),
                ]
                .iter()
                .filter(|x| x.1)
                .map(|x| x.0)
                .collect();
                if drives.len() > 1 {
                    let mut d = Diagnostic::error(
                        Code::E0404,
                        format!("joint `{qname}` is driven twice: {}", drives.join(" and ")),
                    );
                    for k in &drives {
                        if let Some(q) = p.get(k) {
                            d = d.at(q.span(), "drive");
                        }
                    }
                    self.error(
                        scope,
                        d.hint(format!("prescribe the motion (`{pos_key}` or `{rate_key}`) or apply a load (`{load_key}`), not several: a prescribed joint takes whatever load it needs")),
                    );
                    return;
                }
                if let Some(f) = &position {
                    let f0 = f.eval(0.0);
                    if f0.abs() > 1e-12 {
                        self.error(
                            scope,
                            Diagnostic::error(Code::E0404, format!("the prescribed {pos_key} of `{qname}` is {f0} at t = 0"))
                                .at(p.get(pos_key).map(|q| q.span()).unwrap_or(*span), "not zero at the start")
                                .hint(format!("joint {pos_key}s are measured from the initial configuration; subtract the initial value, or place the bodies at it")),
                        );
                        return;
                    }
                }
                let drive = match (position, rate) {
                    (Some(f), _) => Drive::Position { f },
                    (_, Some(f)) => Drive::Rate { f },
                    _ => Drive::Free,
                };
                if rev {
                    JointKind::Revolute {
                        axis: n,
                        spring,
                        damper,
                        rest_angle: rest,
                        drive,
                        torque: load,
                    }
                } else {
                    JointKind::Prismatic {
                        axis: n,
                        spring,
                        damper,
                        drive,
                        force: load,
                    }
                }
            }
            "cylindrical" => {
                let Some(n) = axis(self, "axis") else { return };
                if !coincide(self, Some(n)) {
                    return;
                }
                JointKind::Cylindrical { axis: n }
            }
            "universal" => {
                let a = axis(self, "axis1");
                let b = axis(self, "axis2");
                let (Some(a), Some(b)) = (a, b) else { return };
                if dot(a, b).abs() > 1e-9 {
                    self.error(
                        scope,
                        Diagnostic::error(Code::E0303, format!("the axes of universal joint `{qname}` are not perpendicular"))
                            .at(p.get("axis2").map(|q| q.span()).unwrap_or(*span), format!("angle {:.3} deg between the axes", dot(a, b).clamp(-1.0, 1.0).acos().to_degrees()))
                            .hint("a universal joint's cross has perpendicular arms; parallel axes would leave it a revolute joint with a redundant constraint"),
                    );
                    return;
                }
                if !coincide(self, None) {
                    return;
                }
                JointKind::Universal {
                    axis_a: a,
                    axis_b: b,
                }
            }
            "spherical" => {
                if !coincide(self, None) {
                    return;
                }
                JointKind::Spherical
            }
            "fixed" => {
                if !coincide(self, None) {
                    return;
                }
                JointKind::Fixed
            }
            _ => {
                let d0 = norm(gap);
                let length = match self.expr(scope, p.get("length")) {
                    Some(e) => {
                        let Some(l) = self.scalar(scope, e, Dim::LENGTH, "`length`") else {
                            return;
                        };
                        if l <= 0.0 {
                            self.error(
                                scope,
                                Diagnostic::error(Code::E0303, format!("distance joint `{qname}` has a non-positive length"))
                                    .at(e.span, "must be positive")
                                    .hint("a distance joint keeps two points a positive distance apart; use a spherical joint to make them coincide"),
                            );
                            return;
                        }
                        l
                    }
                    None => {
                        if d0 < 1e-12 {
                            self.error(
                                scope,
                                Diagnostic::error(Code::E0303, format!("distance joint `{qname}` starts with coincident markers"))
                                    .at(*span, "zero initial distance, no `length` given")
                                    .hint("give `length = ...`, or place the bodies apart: a zero-length link has no direction"),
                            );
                            return;
                        }
                        d0
                    }
                };
                JointKind::Distance { length }
            }
        };
        self.joints.push(Joint {
            name: qname,
            span: *span,
            kind,
            markers: pair,
        });
        self.built[d] = Some(Built::Joint(self.joints.len() - 1));
    }

    pub(super) fn spring(&mut self, v: &View) -> Option<Built> {
        let k = v.kind.name.as_str();
        let torsional = k.starts_with("torsional");
        let damper_only = k.ends_with("damper");
        let example = format!(
            "{k} NAME(a, b) {{ {} }}",
            if damper_only {
                "damping = ..."
            } else {
                "stiffness = ..."
            }
        );
        if !self.shape(v, 2, false, false, &[], &example) {
            return None;
        }
        let known: &[&'static str] = match (torsional, damper_only) {
            (false, false) => &["stiffness", "damping", "length"],
            (true, false) => &["stiffness", "damping"],
            (_, true) => &["damping"],
        };
        let p = self.props(v.scope, v.block.as_ref(), known, &format!("a {k}"));
        let pair = self.pair(v.scope, k, &v.name, &v.markers, v.span);
        let (kdim, cdim): (Quantity, Quantity) = if torsional {
            (units::TORSIONAL_STIFFNESS, Dim::new(1, 2, -1).into())
        } else {
            (Dim::new(1, 0, -2).into(), Dim::new(1, 0, -1).into())
        };
        let get = |this: &mut Self, key: &str, dim: Quantity, required: bool| match this
            .expr(v.scope, p.get(key))
        {
            Some(e) => this.scalar(v.scope, e, dim, &format!("`{key}`")),
            None => {
                if required && !p.contains_key(key) {
                    this.missing(
                        v.scope,
                        v.name_span,
                        key,
                        &format!("{k} `{}`", v.name),
                        if key == "damping" {
                            "10 N*s/m"
                        } else {
                            "1000 N/m"
                        },
                    );
                    return None;
                }
                Some(0.0)
            }
        };
        let stiffness = get(self, "stiffness", kdim, !damper_only);
        let damping = get(self, "damping", cdim, damper_only);
        let pair = pair?;
        let (stiffness, damping) = (stiffness?, damping?);
        if stiffness < 0.0 || damping < 0.0 {
            self.error(
                v.scope,
                Diagnostic::error(
                    Code::E0213,
                    format!("{k} `{}` has a negative coefficient", v.name),
                )
                .at(v.name_span, "here")
                .hint("stiffness and damping are non-negative"),
            );
            return None;
        }
        let d0 = norm(sub(pair[1].position, pair[0].position));
        let length = match self.expr(v.scope, p.get("length")) {
            Some(e) => self.scalar(v.scope, e, Dim::LENGTH, "`length`")?,
            None => d0,
        };
        if !torsional && d0 < 1e-12 && length == 0.0 {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0303, format!("{k} `{}` starts with coincident markers", v.name))
                    .at(v.span, "zero length: the force has no direction")
                    .hint("place the markers apart; to tie two points together elastically use a joint with a spring, or a `torsional_spring`"),
            );
            return None;
        }
        self.springs.push(Spring {
            name: v.name.clone(),
            span: v.span,
            kind: if torsional {
                SpringKind::Torsional
            } else {
                SpringKind::Linear
            },
            stiffness,
            damping,
            length,
            markers: pair,
        });
        Some(Built::Spring(self.springs.len() - 1))
    }

    pub(super) fn load(&mut self, v: &View) -> Option<Built> {
        let k = v.kind.name.as_str();
        let example = format!(
            "{k} NAME on MARKER = (x, y, z) {}",
            if k == "force" { "N" } else { "N*m" }
        );
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
        let marker = self.marker(v.scope, &on);
        let dim = if k == "force" {
            Dim::FORCE.into()
        } else {
            units::TORQUE
        };
        let parts = self.signal(v.scope, &value, dim, &format!("{k} `{}`", v.name), true);
        let (marker, parts) = (marker?, parts?);
        if let Attach::Ground { .. } = marker.attach {
            self.error(
                v.scope,
                Diagnostic::error(Code::E0306, format!("{k} `{}` acts on the ground", v.name))
                    .at(on.span, "the ground does not move")
                    .hint("apply it to a body; a reaction on the ground needs no declaration"),
            );
            return None;
        }
        let [a, b, c]: [TimeFn; 3] = parts.try_into().ok()?;
        self.loads.push(Load {
            name: v.name.clone(),
            span: v.span,
            kind: if k == "force" {
                LoadKind::Force
            } else {
                LoadKind::Torque
            },
            marker,
            value: [a, b, c],
            follower: Self::has_flag(v, "follower"),
        });
        Some(Built::Load(self.loads.len() - 1))
    }

    /// `initial spin of PATH = rate about AXIS through POINT`, `initial velocity of PATH = v`:
    /// adds a rigid motion to every body and beam node of an instance, to one body or beam, or
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
        // Which bodies and beams it moves.
        let segs = match self.env.segs(scope, target) {
            Ok(s) => s,
            Err(d) => return self.error(scope, d),
        };
        // What it moves: a body, a beam, an instance, or every member of a family of them.
        let not_movable = |this: &mut Self| {
            this.error(
                scope,
                Diagnostic::error(
                    Code::E0222,
                    "initial motion applies to a body, a beam or a component instance",
                )
                .at(target.span, "not a body, beam or instance")
                .hint("name a body (`hub`), a beam, an instance (`rotor`), or a family of them (`blade`)"),
            )
        };
        let members = match self.env.resolve_family(scope, &segs, target.span) {
            Ok((_, rest)) if !rest.is_empty() => return not_movable(self),
            Ok((Ref::Instance(s), _)) => vec![Member::Instance(s)],
            Ok((Ref::Decl(d), _)) => vec![Member::Decl(d)],
            Ok((Ref::Family(m), _)) => m.into_iter().map(|x| x.1).collect(),
            Ok(_) => return not_movable(self),
            Err(d) => return self.error(scope, d),
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
                Member::Decl(d) if self.failed_within(&self.env.decls[d].name) => return,
                Member::Decl(_) => return not_movable(self),
            }
        }
        let (w, v, p) = if spin {
            let rate = self.scalar(scope, value, RATE, "the spin rate");
            let axis = match about {
                Some(e) => self.direction(scope, e, "the spin axis"),
                None => {
                    self.missing(scope, *span, "about AXIS", "`initial spin`", "z");
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
            let (Some(rate), Some(axis), Some(point)) = (rate, axis, point) else {
                return;
            };
            (scale(axis, rate), [0.0; 3], point)
        } else {
            if let Some(e) = about.as_ref().or(through.as_ref()) {
                return self.error(
                    scope,
                    Diagnostic::error(Code::E0224, "`initial velocity` takes no axis")
                        .at(e.span, "here")
                        .hint("write `initial velocity of PATH = (vx, vy, vz) m/s`"),
                );
            }
            let Some(v) = self.vector(scope, value, Dim::VELOCITY, "the initial velocity") else {
                return;
            };
            ([0.0; 3], v, [0.0; 3])
        };
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
                b.velocity = add(b.velocity, add(v, cross(w, sub(b.position, p))));
                if b.kind == BodyKind::Rigid {
                    b.angular_velocity = add(b.angular_velocity, w);
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
                        add(v, cross(w, sub(b.initial_nodes[k], p))),
                    );
                    b.angular_velocities[k] = add(b.angular_velocities[k], w);
                }
                moved += 1;
            }
        }
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
}
