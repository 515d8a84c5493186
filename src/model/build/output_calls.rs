//! Output functions: quantities derived from several entities.
//!
//! `output zeta = multiblade(rotor.lag, azimuth = rotor.drive)` gives the multiblade (Coleman)
//! coordinates of the angles of a family of revolute joints (THEORY §9.1), one column per
//! coordinate: `zeta_0`, `zeta_1c`, `zeta_1s`, ..., `zeta_d`. `output cm =
//! center_of_mass(rotor)` gives the centre of mass of a body, a beam, a component instance or
//! a family of them (`cm.x`, `cm.y`, `cm.z`; `.velocity`, `.acceleration` and one component
//! may follow the call). Arguments are references, positional or named.
//!
//! Contract: resolves the arguments and builds the probes; must not compute the coordinates (the
//! runtime does).

use super::{Builder, Built};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::model::scope::env::{Member, Ref, ScopeId, Seg};
use crate::model::*;
use crate::syntax::ast::{Ident, OutputArg, OutputCall};

/// The output functions and their parameters, in positional order.
const FUNCTIONS: &[(&str, &[&str])] = &[
    ("multiblade", &["blades", "azimuth"]),
    ("center_of_mass", &["of"]),
];

const MULTIBLADE_EXAMPLE: &str = "`output zeta = multiblade(rotor.lag, azimuth = rotor.drive)`";

impl Builder<'_> {
    /// The probes of an output function, with their column suffixes.
    pub(super) fn call_probes(
        &mut self,
        scope: ScopeId,
        call: &OutputCall,
    ) -> Option<Vec<(String, Probe)>> {
        let name = call.function.name.as_str();
        let Some((function, params)) = FUNCTIONS.iter().find(|f| f.0 == name) else {
            let names = FUNCTIONS.iter().map(|f| f.0);
            let list = "multiblade(JOINTS, azimuth = JOINT), center_of_mass(BODY or INSTANCE)";
            let hint = match did_you_mean(name, names) {
                Some(s) => format!("did you mean `{s}`? Output functions: {list}"),
                None => format!("output functions: {list}"),
            };
            self.error(
                scope,
                Diagnostic::error(Code::E0225, format!("unknown output function `{name}`"))
                    .at(call.function.span, "not an output function")
                    .hint(hint),
            );
            return None;
        };
        let args = self.bind(scope, call, function, params)?;
        match *function {
            "multiblade" => self.multiblade(scope, call, args[0], args[1]),
            _ => self.center_of_mass(scope, call, args[0]),
        }
    }

    /// The column name of an unnamed output function: `multiblade` is named after its
    /// blades (`rotor.lag`, giving `rotor.lag_0`, ...), `center_of_mass` as written
    /// (`center_of_mass(rotor)`, giving `center_of_mass(rotor).x`, ...).
    pub(super) fn call_column(&mut self, scope: ScopeId, call: &OutputCall) -> String {
        let written = |b: &mut Self, a: &OutputArg| {
            b.written(scope, &a.value)
                .unwrap_or_else(|| a.value.text().replace("[..]", ""))
        };
        let first = call.args.first();
        match (call.function.name.as_str(), first) {
            ("multiblade", Some(a)) => written(self, a),
            (f, _) => {
                let args: Vec<String> = call.args.iter().map(|a| written(self, a)).collect();
                let mut out = format!("{f}({})", args.join(", "));
                for c in &call.components {
                    out.push('.');
                    out.push_str(&c.name);
                }
                out
            }
        }
    }

    /// Binds the arguments to the parameters: positional ones in order, then named ones.
    fn bind<'c>(
        &mut self,
        scope: ScopeId,
        call: &'c OutputCall,
        function: &str,
        params: &[&str],
    ) -> Option<Vec<Option<&'c OutputArg>>> {
        let mut bound: Vec<Option<&OutputArg>> = vec![None; params.len()];
        let mut ok = true;
        let signature = format!("`{function}({})`", params.join(", "));
        let mut named_seen = false;
        for (i, a) in call.args.iter().enumerate() {
            let slot = match &a.name {
                None if named_seen => {
                    self.arg_error(
                        scope,
                        a.span,
                        format!("a positional argument of `{function}` follows a named one"),
                        "positional arguments come first".to_string(),
                        format!("name it, or move it before the named ones: {signature}"),
                    );
                    ok = false;
                    continue;
                }
                None if i >= params.len() => {
                    self.arg_error(
                        scope,
                        a.span,
                        format!(
                            "`{function}` takes {} argument{}",
                            params.len(),
                            if params.len() == 1 { "" } else { "s" }
                        ),
                        "one too many".to_string(),
                        format!("the parameters are {signature}"),
                    );
                    ok = false;
                    continue;
                }
                None => i,
                Some(n) => {
                    named_seen = true;
                    match params.iter().position(|p| *p == n.name) {
                        Some(k) => k,
                        None => {
                            let hint = match did_you_mean(&n.name, params.iter().copied()) {
                                Some(s) => {
                                    format!("did you mean `{s}`? The parameters are {signature}")
                                }
                                None => format!("the parameters are {signature}"),
                            };
                            self.arg_error(
                                scope,
                                n.span,
                                format!("`{function}` has no parameter `{}`", n.name),
                                "unknown parameter".to_string(),
                                hint,
                            );
                            ok = false;
                            continue;
                        }
                    }
                }
            };
            if bound[slot].is_some() {
                self.arg_error(
                    scope,
                    a.span,
                    format!("`{}` of `{function}` is given twice", params[slot]),
                    "given again here".to_string(),
                    format!("give each argument once: {signature}"),
                );
                ok = false;
                continue;
            }
            bound[slot] = Some(a);
        }
        ok.then_some(bound)
    }

    pub(super) fn arg_error(
        &mut self,
        scope: ScopeId,
        span: Span,
        msg: String,
        label: String,
        hint: String,
    ) {
        self.error(
            scope,
            Diagnostic::error(Code::E0225, msg)
                .at(span, label)
                .hint(hint),
        );
    }

    /// `multiblade(BLADES, azimuth = JOINT)`: one column per multiblade coordinate.
    fn multiblade(
        &mut self,
        scope: ScopeId,
        call: &OutputCall,
        blades: Option<&OutputArg>,
        azimuth: Option<&OutputArg>,
    ) -> Option<Vec<(String, Probe)>> {
        let joints = match blades {
            Some(a) => self.blade_family(scope, a),
            None => {
                self.arg_error(
                    scope,
                    call.span,
                    "`multiblade` needs the blades' joints".to_string(),
                    "no blades".to_string(),
                    format!("name the family of the blades' revolute hinges: {MULTIBLADE_EXAMPLE}"),
                );
                None
            }
        };
        let psi = match azimuth {
            Some(a) => self.azimuth_joint(scope, a),
            None => {
                self.error(
                    scope,
                    Diagnostic::error(Code::E0227, "`multiblade` needs the rotor azimuth")
                        .at(call.span, "no `azimuth`")
                        .hint(format!(
                            "add `azimuth = JOINT`, the revolute joint the rotor turns on: {MULTIBLADE_EXAMPLE}"
                        )),
                );
                None
            }
        };
        if let Some(c) = call.components.first() {
            let seg = segment(c);
            self.error(
                scope,
                Diagnostic::error(
                    Code::E0212,
                    format!("`{}` is not an output quantity of `multiblade`", c.name),
                )
                .at(seg.span, "unknown quantity")
                .hint("`multiblade` writes every coordinate as a column of its own (`NAME_0`, `NAME_1c`, `NAME_1s`, ..., `NAME_d`); remove the component"),
            );
            return None;
        }
        let (joints, azimuth) = (joints?, psi?);
        let n = joints.len();
        Some(
            Coleman::all(n)
                .into_iter()
                .map(|coordinate| {
                    (
                        format!("_{}", coordinate.suffix()),
                        Probe::Multiblade {
                            blades: joints.clone(),
                            azimuth,
                            coordinate,
                        },
                    )
                })
                .collect(),
        )
    }

    /// The joints of `multiblade`'s first argument: a family of at least two revolute joints
    /// with consecutive indices, optionally followed by `.angle`.
    fn blade_family(&mut self, scope: ScopeId, a: &OutputArg) -> Option<Vec<usize>> {
        let path = &a.value;
        let (mut text, r, rest) = self.resolve_arg(scope, a)?;
        let bad = |msg: String, label: &str, hint: String| {
            Diagnostic::error(Code::E0226, msg)
                .at(path.span, label.to_string())
                .hint(hint)
        };
        match rest.as_slice() {
            [] => {}
            [q] if q.name.name == "angle" && q.index.is_none() && q.arg.is_none() => {
                text = text.trim_end_matches(".angle").to_string();
            }
            [q, ..] => {
                let keep = path.segments.len().saturating_sub(rest.len());
                let family = path.segments[..keep]
                    .iter()
                    .map(|s| s.name.name.as_str())
                    .collect::<Vec<_>>()
                    .join(".");
                let d = Diagnostic::error(
                    Code::E0226,
                    format!(
                        "multiblade coordinates are of the joints' angles, not `{}`",
                        q.name.name
                    ),
                )
                .at(q.span, "not `angle`")
                .hint(format!(
                    "name the family alone, `{family}`, or its angle, `{family}.angle`"
                ));
                return self.fail(scope, d);
            }
        }
        let members = match r {
            Ref::Family(m) => m,
            Ref::Decl(d) if self.is_joint(d) => {
                let name = self.env.decls[d].name.clone();
                let family = name.rsplit_once('[').map(|x| x.0).unwrap_or(&name).to_string();
                return self.fail(
                    scope,
                    bad(
                        format!("`{name}` is one joint, not the family of every blade's joint"),
                        "one joint",
                        format!("name the whole family without an index, `{family}`: {MULTIBLADE_EXAMPLE}"),
                    ),
                );
            }
            _ => {
                return self.fail(
                    scope,
                    bad(
                        format!("`{text}` is not a family of revolute joints"),
                        "not the blades' joints",
                        format!("the first argument names the blades' hinges, declared in a loop as `joint lag[i] = revolute(...)`: {MULTIBLADE_EXAMPLE}"),
                    ),
                )
            }
        };
        if members.len() < 2 {
            return self.fail(
                scope,
                bad(
                    format!(
                        "`{text}` has {} member{}; multiblade coordinates need at least 2 blades",
                        members.len(),
                        if members.len() == 1 { "" } else { "s" }
                    ),
                    "fewer than 2 blades",
                    "multiblade coordinates describe a rotor of 2 or more blades; output a single blade's `angle` instead".to_string(),
                ),
            );
        }
        if let Some(w) = members.windows(2).find(|w| w[1].0 != w[0].0 + 1) {
            return self.fail(
                scope,
                bad(
                    format!("`{text}` has no member {}: blade k must be member k", w[0].0 + 1),
                    "indices not consecutive",
                    "multiblade coordinates take blade k at azimuth psi + 2 pi k / N, so the family's indices must run without gaps".to_string(),
                ),
            );
        }
        let mut joints = Vec::new();
        for (i, m) in members {
            let joint = match m {
                Member::Decl(d) => match self.built[d] {
                    Some(Built::Joint(j)) => Some(j),
                    _ => None,
                },
                Member::Instance(_) => None,
            };
            match joint {
                Some(j) if matches!(self.joints[j].kind, JointKind::Revolute { .. }) => {
                    joints.push(j)
                }
                // Not built: its own error has been reported.
                None if matches!(m, Member::Decl(d) if self.is_joint(d)) => return None,
                other => {
                    let what = match other {
                        Some(j) => format!("a {} joint", self.joints[j].kind.name()),
                        None => "not a joint".to_string(),
                    };
                    return self.fail(
                        scope,
                        bad(
                            format!("`{text}[{i}]` is {what}; multiblade coordinates need revolute joints"),
                            "not a family of revolute joints",
                            "the blades' coordinates are the angles of their revolute hinges".to_string(),
                        ),
                    );
                }
            }
        }
        Some(joints)
    }

    /// The joint of `multiblade`'s `azimuth`: a revolute joint, optionally with `.angle`.
    fn azimuth_joint(&mut self, scope: ScopeId, a: &OutputArg) -> Option<usize> {
        let path = &a.value;
        let (text, r, rest) = self.resolve_arg(scope, a)?;
        let other = match rest.as_slice() {
            [] => None,
            [q] if q.name.name == "angle" && q.index.is_none() && q.arg.is_none() => None,
            [q, ..] => Some(q.name.name.clone()),
        };
        let joint = match r {
            Ref::Decl(d) => match self.built[d] {
                Some(Built::Joint(j)) => Some(j),
                // Not built: its own error has been reported.
                None if self.is_joint(d) => return None,
                _ => None,
            },
            _ => None,
        };
        let message = match (joint, &r) {
            (Some(j), _) if matches!(self.joints[j].kind, JointKind::Revolute { .. }) => {
                match other {
                    None => return Some(j),
                    Some(q) => format!(
                        "the azimuth is the angle of `{}`, not its `{q}`",
                        self.joints[j].name
                    ),
                }
            }
            (Some(j), _) => format!(
                "the azimuth `{text}` is a {} joint; it must be a revolute joint",
                self.joints[j].kind.name()
            ),
            (None, Ref::Family(_)) => {
                format!("the azimuth `{text}` is a family; it must be one revolute joint")
            }
            _ => format!("the azimuth `{text}` is not a joint; it must be a revolute joint"),
        };
        self.fail(
            scope,
            Diagnostic::error(Code::E0227, message)
            .at(path.span, "not a revolute joint")
            .hint(format!(
                "the azimuth psi is the angle of the revolute joint the rotor turns on: {MULTIBLADE_EXAMPLE}"
            )),
        )
    }

    /// Whether declaration `d` is a joint (built or not).
    fn is_joint(&self, d: usize) -> bool {
        self.env.decls[d].item_kind() == Some("joint")
    }

    /// Reports `d` and gives up on this output.
    /// An argument's path as written (indices evaluated) and what it resolves to; a family
    /// named without an index stays whole.
    pub(super) fn resolve_arg(
        &mut self,
        scope: ScopeId,
        a: &OutputArg,
    ) -> Option<(String, Ref, Vec<Seg>)> {
        let path = &a.value;
        let text = self.written(scope, path).unwrap_or_else(|| path.text());
        let segs = match self.env.segs(scope, path) {
            Ok(s) => s,
            Err(d) => return self.fail(scope, d),
        };
        match self.env.resolve_family(scope, &segs, path.span) {
            Ok((r, rest)) => Some((text, r, rest)),
            Err(d) => self.fail(scope, d),
        }
    }

    pub(super) fn fail<T>(&mut self, scope: ScopeId, d: Diagnostic) -> Option<T> {
        self.error(scope, d);
        None
    }
}

/// A word after an output function's call, as a path segment.
pub(super) fn segment(c: &Ident) -> Seg {
    Seg {
        name: c.clone(),
        index: None,
        arg: None,
        span: c.span,
    }
}
