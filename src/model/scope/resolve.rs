//! Name resolution: a path to what it names, through component instances (honouring their
//! exports), indexed families, export aliases and reference arguments (`hub: marker`, resolved
//! where the instance is written, with the offsets of marker arguments collected for the
//! marker they name).
//!
//! Contract: resolves paths against scopes; must not evaluate properties or build entities.

use super::env::{builtin, secondary, BindingId, Env, Member, Named, Offset, Ref, ScopeId, Seg};
use crate::diagnostics::{did_you_mean, Code, Diagnostic};
use crate::source::Span;
use crate::syntax::ast::{Expr, ExprKind, Path};
use std::collections::BTreeMap;
use std::rc::Rc;

impl Env {
    /// Evaluates the index and argument expressions of a path in `scope`.
    pub fn segs(&mut self, scope: ScopeId, path: &Path) -> Result<Vec<Seg>, Diagnostic> {
        // Index and argument values are not markers: their paths collect no offsets.
        let was = self.offsets.take();
        let r = self.segs_inner(scope, path);
        self.offsets = was;
        r
    }

    fn segs_inner(&mut self, scope: ScopeId, path: &Path) -> Result<Vec<Seg>, Diagnostic> {
        let mut out = Vec::with_capacity(path.segments.len());
        for s in &path.segments {
            let index = match &s.index {
                Some(e) => Some((self.integer_in(scope, e, "an index")?, e.span)),
                None => None,
            };
            let arg = match &s.arg {
                Some(e) => Some((self.eval_in(scope, e)?, e.span)),
                None => None,
            };
            out.push(Seg {
                name: s.name.clone(),
                index,
                arg,
                span: s.span,
            });
        }
        Ok(out)
    }

    /// Resolves a path to what it names, returning the segments left over (a property, a
    /// marker, a quantity). Follows component arguments of reference type and export aliases.
    pub fn resolve(
        &mut self,
        scope: ScopeId,
        segs: &[Seg],
        span: Span,
    ) -> Result<(Ref, Vec<Seg>), Diagnostic> {
        self.depth += 1;
        if self.depth > 64 {
            self.depth -= 1;
            return Err(
                Diagnostic::error(Code::E0207, "this reference refers back to itself")
                    .at(span, "resolving this never ends")
                    .hint("an argument or export alias names itself, directly or through others"),
            );
        }
        let r = self.resolve_inner(scope, segs, span);
        self.depth -= 1;
        r
    }

    /// Like [`Env::resolve`], but a family named without an index (`rotor.lag`) is a
    /// [`Ref::Family`], for output functions that take every member.
    pub fn resolve_family(
        &mut self,
        scope: ScopeId,
        segs: &[Seg],
        span: Span,
    ) -> Result<(Ref, Vec<Seg>), Diagnostic> {
        let was = std::mem::replace(&mut self.families, true);
        let r = self.resolve(scope, segs, span);
        self.families = was;
        r
    }

    /// Like [`Env::resolve`], for a marker: also returns the offsets of the marker arguments
    /// it passes through (`hub = earth @ (0, 0, 1) m` named as `hub`), each to be evaluated in
    /// its scope and added to the marker's own offset.
    pub fn resolve_marker(
        &mut self,
        scope: ScopeId,
        segs: &[Seg],
        span: Span,
    ) -> Result<(Ref, Vec<Seg>, Vec<Offset>), Diagnostic> {
        let was = self.offsets.replace(Vec::new());
        let r = self.resolve(scope, segs, span);
        let offsets = std::mem::replace(&mut self.offsets, was).unwrap_or_default();
        r.map(|(r, rest)| (r, rest, offsets))
    }

    fn resolve_inner(
        &mut self,
        scope: ScopeId,
        segs: &[Seg],
        span: Span,
    ) -> Result<(Ref, Vec<Seg>), Diagnostic> {
        let Some(head) = segs.first() else {
            return Err(Diagnostic::error(Code::E0201, "empty path").at(span, "here"));
        };
        let named = match self.lookup(scope, &head.name.name) {
            Some(n) => n,
            None => {
                if let (Some(v), None) = (builtin(&head.name.name), head.index) {
                    return Ok((Ref::Builtin(v), segs[1..].to_vec()));
                }
                let candidates = self.visible(scope);
                let d =
                    Diagnostic::error(Code::E0201, format!("unknown name `{}`", head.name.name))
                        .at(head.name.span, "not declared");
                return Err(match did_you_mean(&head.name.name, candidates.iter().map(|s| s.as_str())) {
                    Some(s) => d.hint(format!("did you mean `{s}`?")),
                    None => d.hint("declare it (`param`, `let`, a body, a joint, ...) or import it with `use`; names are case-sensitive"),
                });
            }
        };
        self.follow(named, head, &segs[1..], span)
    }

    /// Continues resolution from `named` (reached by segment `seg`) with the segments `rest`.
    fn follow(
        &mut self,
        named: Named,
        seg: &Seg,
        rest: &[Seg],
        span: Span,
    ) -> Result<(Ref, Vec<Seg>), Diagnostic> {
        let r = match named {
            Named::Binding(b) => {
                if seg.index.is_some() {
                    return Err(not_indexed(seg, "a value"));
                }
                return self.follow_binding(b, seg, rest, span);
            }
            Named::Decl(d) => {
                if seg.index.is_some() {
                    return Err(not_indexed(seg, "a single declaration"));
                }
                self.decls[d].used = true;
                Ref::Decl(d)
            }
            Named::Component(c, _) => Ref::Component(c),
            Named::Instance(s) => {
                if seg.index.is_some() {
                    return Err(not_indexed(seg, "a single instance"));
                }
                return self.enter_instance(s, rest, span);
            }
            Named::Family(map) => return self.follow_family(map, seg, rest, span),
        };
        Ok((r, rest.to_vec()))
    }

    /// A value binding; a reference argument (`hub: marker`) resolves what the caller wrote,
    /// in the caller's scope, its offset collected for the marker.
    fn follow_binding(
        &mut self,
        b: BindingId,
        seg: &Seg,
        rest: &[Seg],
        span: Span,
    ) -> Result<(Ref, Vec<Seg>), Diagnostic> {
        let name = &seg.name.name;
        let is_ref = self.bindings[b]
            .ty
            .as_ref()
            .map(|t| t.0.is_reference())
            .unwrap_or(false);
        if !is_ref {
            return Ok((Ref::Binding(b), rest.to_vec()));
        }
        // A marker or body argument: resolve what the caller wrote, in the caller's scope.
        self.bindings[b].used = true;
        let (expr, bscope) = (self.bindings[b].expr.clone(), self.bindings[b].scope);
        let Some(Expr {
            kind: ExprKind::Path { path },
            ..
        }) = expr
        else {
            return Err(secondary(span));
        };
        if let Some(offset) = self.bindings[b].offset.clone() {
            let shown = format!("{} @ ...", path.text());
            if let Some(next) = rest.first() {
                return Err(Diagnostic::error(
                    Code::E0222,
                    format!("`{name}` is the point `{shown}`: it has no `{}`", next.name.name),
                )
                .at(next.span, "after a point with an offset")
                .hint("a marker passed with an offset (`@`) has no markers or quantities of its own: use it where a marker goes (a joint, a spring, a load), or pass the marker without the offset"));
            }
            match self.offsets.as_mut() {
                Some(list) => list.push((offset, bscope)),
                None => {
                    return Err(Diagnostic::error(
                        Code::E0222,
                        format!("`{name}` is the point `{shown}`, usable only as a marker"),
                    )
                    .at(span, "not used as a marker")
                    .hint("a marker argument with an offset goes where a marker goes (a joint, a spring, a load); pass it without `@` to use it here"))
                }
            }
        }
        let mut segs = self.segs(bscope, &path)?;
        segs.extend_from_slice(rest);
        self.resolve(bscope, &segs, span)
    }

    /// An indexed family: a member, or the whole family where families are wanted.
    fn follow_family(
        &mut self,
        map: Rc<BTreeMap<i64, Member>>,
        seg: &Seg,
        rest: &[Seg],
        span: Span,
    ) -> Result<(Ref, Vec<Seg>), Diagnostic> {
        let name = &seg.name.name;
        if seg.index.is_none() && self.families {
            for m in map.values() {
                if let Member::Decl(d) = m {
                    self.decls[*d].used = true;
                }
            }
            return Ok((
                Ref::Family(map.iter().map(|(k, m)| (*k, *m)).collect()),
                rest.to_vec(),
            ));
        }
        let Some((i, ispan)) = seg.index else {
            let (lo, hi) = (
                map.keys().next().copied().unwrap_or(0),
                map.keys().last().copied().unwrap_or(0),
            );
            return Err(Diagnostic::error(
                Code::E0214,
                format!("`{name}` is an indexed family; say which one"),
            )
            .at(seg.span, "no index")
            .hint(format!("write `{name}[i]` with i in {lo}..={hi}")));
        };
        let r = match map.get(&i) {
            Some(Member::Decl(d)) => {
                self.decls[*d].used = true;
                Ref::Decl(*d)
            }
            Some(Member::Instance(s)) => return self.enter_instance(*s, rest, span),
            None => {
                let keys: Vec<i64> = map.keys().copied().collect();
                let range = match (keys.first(), keys.last()) {
                    (Some(a), Some(b)) if (b - a + 1) as usize == keys.len() => {
                        format!("{a}..={b}")
                    }
                    _ => keys
                        .iter()
                        .map(|k| k.to_string())
                        .collect::<Vec<_>>()
                        .join(", "),
                };
                return Err(Diagnostic::error(
                    Code::E0214,
                    format!("index {i} is out of range for `{name}`"),
                )
                .at(ispan, "no such member")
                .hint(format!("`{name}` has indices {range}")));
            }
        };
        Ok((r, rest.to_vec()))
    }

    /// Resolves the segments after an instance name, honouring its exports.
    fn enter_instance(
        &mut self,
        s: ScopeId,
        rest: &[Seg],
        span: Span,
    ) -> Result<(Ref, Vec<Seg>), Diagnostic> {
        if self.scopes[s].failed {
            return Err(secondary(span));
        }
        let Some(next) = rest.first() else {
            return Ok((Ref::Instance(s), Vec::new()));
        };
        let key = next.name.name.clone();
        if let Some(exports) = &self.scopes[s].exports {
            match exports.get(&key) {
                None => {
                    let comp = self.scopes[s]
                        .instance
                        .clone()
                        .map(|i| i.0)
                        .unwrap_or_default();
                    let mut names: Vec<&String> = exports.keys().collect();
                    names.sort();
                    let list = names
                        .iter()
                        .map(|n| n.as_str())
                        .collect::<Vec<_>>()
                        .join(", ");
                    let code = if self.scopes[s].names.contains_key(&key) {
                        Code::E0219
                    } else {
                        Code::E0201
                    };
                    let d = Diagnostic::error(
                        code,
                        format!("component `{comp}` does not export `{key}`"),
                    )
                    .at(next.name.span, "not exported");
                    return Err(match did_you_mean(&key, names.iter().map(|n| n.as_str())) {
                        Some(m) => d.hint(format!("did you mean `{m}`? It exports: {list}")),
                        None => d.hint(format!("it exports: {list}")),
                    });
                }
                Some(Some(alias)) => {
                    let alias = alias.clone();
                    let mut segs = self.segs(s, &alias)?;
                    if let Some(i) = next.index {
                        if let Some(last) = segs.last_mut() {
                            if last.index.is_none() {
                                last.index = Some(i);
                            }
                        }
                    }
                    segs.extend_from_slice(&rest[1..]);
                    return self.resolve(s, &segs, span);
                }
                Some(None) => {}
            }
        }
        match self.scopes[s].names.get(&key).cloned() {
            Some(n) => self.follow(n, next, &rest[1..], span),
            None => {
                let comp = self.scopes[s]
                    .instance
                    .clone()
                    .map(|i| i.0)
                    .unwrap_or_default();
                let names: Vec<String> = self.scopes[s].names.keys().cloned().collect();
                let d =
                    Diagnostic::error(Code::E0201, format!("component `{comp}` has no `{key}`"))
                        .at(next.name.span, "not declared in the component");
                Err(match did_you_mean(&key, names.iter().map(|n| n.as_str())) {
                    Some(m) => d.hint(format!("did you mean `{m}`?")),
                    None => d.hint(format!("it declares: {}", names.join(", "))),
                })
            }
        }
    }
}

fn not_indexed(seg: &Seg, what: &str) -> Diagnostic {
    let name = &seg.name.name;
    Diagnostic::error(
        Code::E0214,
        format!("`{name}` is {what}, not an indexed family"),
    )
    .at(
        seg.index.map(|i| i.1).unwrap_or(seg.span),
        "index given here",
    )
    .hint(format!("write `{name}` without an index"))
}
