//! Warnings for what the model file declares and never uses (W0201, W0202), silent for the
//! names a failed declaration wrote. Contract: reads the scopes and what was built; must not
//! build entities or report errors.

use super::{Builder, Built};
use crate::diagnostics::{Code, Diagnostic};
use crate::model::scope::elaborate::{unused_bindings, Elaborated};
use crate::model::scope::env::{BindingKind, Named};
use crate::model::*;
use crate::source::SourceId;
use crate::syntax::ast::Item;
use std::collections::HashSet;

impl Builder<'_> {
    /// Marks as used every name written in a declaration of the model file that failed (the
    /// innermost item holding a label of an error): a param whose only user failed was not
    /// forgotten, and "never used" would be a second report of one mistake.
    pub(super) fn excuse_failed(&mut self, items: &[Item], main: SourceId) {
        let spans: Vec<Span> = self
            .sink
            .diagnostics
            .iter()
            .filter(|d| d.is_error())
            .flat_map(|d| d.labels.iter().map(|l| l.span))
            .filter(|s| s.source == main)
            .collect();
        if spans.is_empty() {
            return;
        }
        let mut names = HashSet::new();
        failed_names(items, &spans, &mut names);
        for b in &mut self.env.bindings {
            if b.span.source == main && names.contains(&b.name) {
                b.used = true;
            }
        }
    }

    /// Warnings for what the model file declares and never uses.
    pub(super) fn unused(&mut self, main: SourceId, out: &Elaborated) {
        let mut warnings = Vec::new();
        for b in unused_bindings(&self.env) {
            if b.span.source != main {
                continue;
            }
            let (code, what, hint) = match b.kind {
                BindingKind::Param => (
                    Code::W0201,
                    "param",
                    "remove it, or use it in a property or an output",
                ),
                BindingKind::Let => (Code::W0202, "let", "remove it, or use it"),
                BindingKind::Function => (
                    Code::W0202,
                    "function",
                    "remove it, or use it in a load or a prescribed motion",
                ),
                _ => continue,
            };
            warnings.push(
                Diagnostic::warning(code, format!("{what} `{}` is never used", b.name))
                    .at(b.span, "declared here")
                    .hint(hint),
            );
        }
        for (d, decl) in self.env.decls.iter().enumerate() {
            if decl.used || decl.name_span.source != main {
                continue;
            }
            if let Some(Built::Section(_)) = self.built[d] {
                warnings.push(
                    Diagnostic::warning(
                        Code::W0202,
                        format!("section `{}` is never used", decl.name),
                    )
                    .at(decl.name_span, "declared here")
                    .hint("remove it, or give it to a beam: `section = NAME`"),
                );
            }
        }
        for (name, span) in &out.local_components {
            let defined = self.env.scopes.iter().any(|s| {
                s.names.get(name).map(|n| matches!(n, Named::Component(c, _) if c.name.span == *span && out.instantiated.contains(&c.span))).unwrap_or(false)
            });
            if !defined {
                warnings.push(
                    Diagnostic::warning(
                        Code::W0202,
                        format!("component `{name}` is never instantiated"),
                    )
                    .at(*span, "declared here")
                    .hint(format!(
                        "remove it, or instantiate it: `NAME = {name}(...)`"
                    )),
                );
            }
        }
        warnings.sort_by_key(|d| d.labels.first().map(|l| l.span.start));
        for w in warnings {
            self.sink.push(w);
        }
    }
}

/// Collects the names written in the innermost items that contain one of `spans`; whether
/// any item did.
fn failed_names(items: &[Item], spans: &[Span], names: &mut HashSet<String>) -> bool {
    let mut any = false;
    for item in items {
        let outer = item.span();
        if !spans
            .iter()
            .any(|s| outer.start <= s.start && s.end <= outer.end)
        {
            continue;
        }
        any = true;
        let inside = match item {
            Item::For { items, .. } => failed_names(items, spans, names),
            Item::If {
                then, otherwise, ..
            } => failed_names(then, spans, names) | failed_names(otherwise, spans, names),
            Item::Component(c) => failed_names(&c.items, spans, names),
            _ => false,
        };
        if !inside {
            names.extend(written_names(item));
        }
    }
    any
}

/// Every name an item writes (declared or used), read from its syntax tree.
pub(in crate::model) fn written_names(item: &Item) -> Vec<String> {
    let Ok(text) = serde_json::to_string(item) else {
        return Vec::new();
    };
    text.split("\"name\":\"")
        .skip(1)
        .filter_map(|part| part.split('"').next())
        .map(str::to_string)
        .collect()
}
