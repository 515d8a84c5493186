//! Diagnostics as plain data, rendered at the edge.
//!
//! Contract: every stage reports [`Diagnostic`] values (a registered [`Code`], a message, labelled
//! spans, a hint). Nothing here does IO; `render` turns them into text (miette's graphical report,
//! without colour when asked) or JSON for editors and scripts.

mod codes;
mod render;

pub use codes::{explain, Code, ALL_CODES};
pub use render::{render_human, render_json};

use crate::source::Span;
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Error,
    Warning,
}

/// A span with a short text shown under it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Label {
    pub span: Span,
    pub text: String,
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnostic {
    pub code: Code,
    pub severity: Severity,
    pub message: String,
    /// The first label is the primary one.
    pub labels: Vec<Label>,
    pub hint: Option<String>,
    /// The loop iterations the diagnostic was raised in, innermost first; turned into labels
    /// by [`merge_repeats`], which reports a mistake repeated by a loop once.
    #[serde(skip)]
    pub iterations: Vec<Iteration>,
}

/// One iteration of a `for` loop: the loop's header (`for i in 0..4`), its variable, the
/// variable's value and the number of iterations.
#[derive(Clone, Debug, PartialEq)]
pub struct Iteration {
    pub header: Span,
    pub var: String,
    pub value: i64,
    pub count: i64,
}

impl Diagnostic {
    /// An error: `code` is an error code (`E...`); warnings are built by [`Diagnostic::warning`].
    pub fn error(code: Code, message: impl Into<String>) -> Diagnostic {
        debug_assert!(
            !code.is_warning(),
            "{} is a warning code: use Diagnostic::warning",
            code.as_str()
        );
        Diagnostic::new(code, message)
    }

    /// A warning: `code` is a warning code (`W...`).
    pub fn warning(code: Code, message: impl Into<String>) -> Diagnostic {
        debug_assert!(code.is_warning(), "{} is not a warning code", code.as_str());
        Diagnostic::new(code, message)
    }

    /// The severity is the code's, known from the registry (`Code::is_warning`).
    fn new(code: Code, message: impl Into<String>) -> Diagnostic {
        Diagnostic {
            code,
            severity: if code.is_warning() {
                Severity::Warning
            } else {
                Severity::Error
            },
            message: message.into(),
            labels: Vec::new(),
            hint: None,
            iterations: Vec::new(),
        }
    }

    /// Attach the primary (or a further) labelled span.
    pub fn at(mut self, span: Span, text: impl Into<String>) -> Diagnostic {
        self.labels.push(Label {
            span,
            text: text.into(),
        });
        self
    }

    pub fn hint(mut self, hint: impl Into<String>) -> Diagnostic {
        self.hint = Some(hint.into());
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    pub fn primary_span(&self) -> Option<Span> {
        self.labels.first().map(|l| l.span)
    }
}

/// Collects diagnostics of a stage; early stages report every error they find.
#[derive(Debug, Default)]
pub struct Sink {
    pub diagnostics: Vec<Diagnostic>,
}

impl Sink {
    pub fn push(&mut self, d: Diagnostic) {
        self.diagnostics.push(d);
    }

    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(|d| d.is_error())
    }
}

/// How many diagnostics of one code a person is shown; the rest are counted
/// ([`summarize`]). JSON output lists every one.
pub const SHOWN_PER_CODE: usize = 10;

/// The diagnostics to show a person, at most `per_code` of each code in their order, and one
/// line for each code with more: `... and 19,990 more W0201 warnings`.
pub fn summarize(diagnostics: &[Diagnostic], per_code: usize) -> (Vec<&Diagnostic>, Vec<String>) {
    let mut seen: Vec<(Code, Severity, usize)> = Vec::new();
    let mut shown = Vec::new();
    for d in diagnostics {
        let k = match seen.iter().position(|s| s.0 == d.code) {
            Some(k) => k,
            None => {
                seen.push((d.code, d.severity, 0));
                seen.len() - 1
            }
        };
        seen[k].2 += 1;
        if seen[k].2 <= per_code {
            shown.push(d);
        }
    }
    let more = seen
        .into_iter()
        .filter(|s| s.2 > per_code)
        .map(|(code, severity, count)| {
            let n = count - per_code;
            let kind = match severity {
                Severity::Error => "error",
                Severity::Warning => "warning",
            };
            format!(
                "... and {} more {} {kind}{}",
                thousands(n),
                code.as_str(),
                if n == 1 { "" } else { "s" }
            )
        })
        .collect();
    (shown, more)
}

/// `19990` as `19,990`.
fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Reports each mistake once. Diagnostics with the same code and the same labelled spans are
/// one mistake (a loop body repeats its text; a marker argument used twice repeats its error):
/// the first is kept, with a label at each loop's header naming the iterations that hit it
/// ("in all 3 iterations of this loop"). Indices that differ between the messages are shown as
/// `[..]`; where the messages differ otherwise (a distance), the label says whose is shown.
pub fn merge_repeats(diagnostics: Vec<Diagnostic>) -> Vec<Diagnostic> {
    type Key = (Code, Vec<Span>, Option<String>);
    let mut index: std::collections::HashMap<Key, usize> = std::collections::HashMap::new();
    let mut groups: Vec<Vec<Diagnostic>> = Vec::new();
    for d in diagnostics {
        // Without a span, only the message tells two mistakes apart.
        let spans: Vec<Span> = d.labels.iter().map(|l| l.span).collect();
        let message = spans.is_empty().then(|| d.message.clone());
        let key = (d.code, spans, message);
        match index.get(&key) {
            Some(&g) => groups[g].push(d),
            None => {
                index.insert(key, groups.len());
                groups.push(vec![d]);
            }
        }
    }
    groups.into_iter().map(merge_group).collect()
}

fn merge_group(group: Vec<Diagnostic>) -> Diagnostic {
    let mut loops: Vec<(Span, String, i64, Vec<i64>)> = Vec::new();
    for it in group.iter().flat_map(|d| &d.iterations) {
        match loops.iter_mut().find(|l| l.0 == it.header) {
            Some(l) => l.3.push(it.value),
            None => loops.push((it.header, it.var.clone(), it.count, vec![it.value])),
        }
    }
    let mut d = group[0].clone();
    let mut shown_first = false;
    if group.iter().any(|g| g.message != d.message) {
        let skeleton = without_indices(&d.message);
        if group
            .iter()
            .all(|g| without_indices(&g.message) == skeleton)
        {
            d.message = skeleton;
        } else {
            shown_first = true;
        }
    }
    let first = std::mem::take(&mut d.iterations);
    for (header, var, count, mut values) in loops {
        values.sort_unstable();
        values.dedup();
        let mut text = match values.as_slice() {
            // A loop of one iteration adds nothing to know.
            _ if count == 1 => continue,
            [v] => format!("in the iteration `{var} = {v}` of this loop"),
            _ if values.len() as i64 == count => {
                format!("in all {count} iterations of this loop")
            }
            _ => {
                let shown: Vec<String> = values.iter().take(6).map(|v| v.to_string()).collect();
                let more = if values.len() > 6 { ", ..." } else { "" };
                format!(
                    "in {} of the {count} iterations of this loop (`{var}` = {}{more})",
                    values.len(),
                    shown.join(", ")
                )
            }
        };
        if let (true, true, Some(f)) = (
            shown_first,
            values.len() > 1,
            first.iter().find(|f| f.header == header),
        ) {
            text.push_str(&format!("; the message is that of `{var} = {}`", f.value));
        }
        d = d.at(header, text);
    }
    d
}

/// The message with every bracketed whole number written `[..]`: `bob[2]` -> `bob[..]`.
fn without_indices(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(i) = rest.find('[') {
        out.push_str(&rest[..i]);
        let after = &rest[i + 1..];
        match after.find(']') {
            Some(j) if j > 0 && after[..j].chars().all(|c| c.is_ascii_digit() || c == '-') => {
                out.push_str("[..]");
                rest = &after[j + 1..];
            }
            _ => {
                out.push('[');
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// The closest candidate by edit distance, if it is close enough to be a likely typo.
pub fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let limit = (name.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .map(|c| (edit_distance(name, c), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for i in 1..=a.len() {
        cur[0] = i;
        for j in 1..=b.len() {
            let sub = prev[j - 1] + usize::from(a[i - 1] != b[j - 1]);
            cur[j] = sub.min(prev[j] + 1).min(cur[j - 1] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_are_elided_only_where_bracketed_numbers_are() {
        assert_eq!(without_indices("mass of `bob[12]`"), "mass of `bob[..]`");
        assert_eq!(without_indices("[kg*m^2]"), "[kg*m^2]");
        assert_eq!(without_indices("a[1][2] b[x] c["), "a[..][..] b[x] c[");
    }

    #[test]
    fn did_you_mean_finds_close_names_only() {
        assert_eq!(did_you_mean("lenght", ["length", "mass"]), Some("length"));
        assert_eq!(did_you_mean("velocity", ["at", "mass"]), None);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }
}
