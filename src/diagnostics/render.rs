//! Rendering diagnostics: miette's graphical report for people, JSON for tools.

use super::{Diagnostic, Severity};
use crate::source::{SourceFile, SourceMap};
use miette::{
    GraphicalReportHandler, GraphicalTheme, LabeledSpan, MietteError, MietteSpanContents,
    SourceCode, SourceSpan, SpanContents,
};
use std::fmt;

struct Report<'a> {
    diag: &'a Diagnostic,
    source: Option<Window<'a>>,
    labels: Vec<LabeledSpan>,
    help: Option<String>,
}

/// The lines of a file around a diagnostic's labels, as miette reads them: each report reads
/// only its own lines (found from the file's line index), so rendering many diagnostics costs
/// time linear in their number, not in the file's length times it.
struct Window<'a> {
    name: &'a str,
    text: &'a str,
    /// The window's first byte and 0-based line in the file.
    offset: usize,
    line: usize,
}

impl Window<'_> {
    /// Lines this far around the labels: more than the handler's context (one line).
    const AROUND: usize = 3;

    fn around<'a>(file: &'a SourceFile, spans: impl Iterator<Item = (usize, usize)>) -> Window<'a> {
        let (lo, hi) = spans.fold((usize::MAX, 0), |(lo, hi), (a, b)| (lo.min(a), hi.max(b)));
        let lo = lo.min(file.text.len());
        let from = file.line_of(lo).saturating_sub(Self::AROUND);
        let to = file.line_of(hi.max(lo).min(file.text.len())) + Self::AROUND + 1;
        let range = file.lines(from, to);
        Window {
            name: &file.name,
            text: &file.text[range.clone()],
            offset: range.start,
            line: from,
        }
    }
}

impl SourceCode for Window<'_> {
    fn read_span<'a>(
        &'a self,
        span: &SourceSpan,
        before: usize,
        after: usize,
    ) -> Result<Box<dyn SpanContents<'a> + 'a>, MietteError> {
        let start = span
            .offset()
            .saturating_sub(self.offset)
            .min(self.text.len());
        let local = SourceSpan::new(start.into(), span.len().min(self.text.len() - start));
        let inner = self.text.read_span(&local, before, after)?;
        let at = SourceSpan::new(
            (inner.span().offset() + self.offset).into(),
            inner.span().len(),
        );
        Ok(Box::new(MietteSpanContents::new_named(
            self.name.to_string(),
            inner.data(),
            at,
            inner.line() + self.line,
            inner.column(),
            inner.line_count(),
        )))
    }
}

impl fmt::Debug for Report<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.diag.message)
    }
}

impl fmt::Display for Report<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.diag.message)
    }
}

impl std::error::Error for Report<'_> {}

impl miette::Diagnostic for Report<'_> {
    fn code<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        Some(Box::new(self.diag.code.as_str()))
    }

    fn severity(&self) -> Option<miette::Severity> {
        Some(match self.diag.severity {
            Severity::Error => miette::Severity::Error,
            Severity::Warning => miette::Severity::Warning,
        })
    }

    fn help<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.help
            .as_ref()
            .map(|h| Box::new(h) as Box<dyn fmt::Display>)
    }

    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        self.source.as_ref().map(|s| s as &dyn miette::SourceCode)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        if self.labels.is_empty() {
            None
        } else {
            Some(Box::new(self.labels.iter().cloned()))
        }
    }
}

/// Renders one diagnostic as a human report. `color` selects ANSI colours.
pub fn render_human(diag: &Diagnostic, sources: &SourceMap, color: bool) -> String {
    let primary = diag.primary_span();
    let source = primary.and_then(|s| sources.get(s.source));
    let mut labels = Vec::new();
    let mut elsewhere = Vec::new();
    for (i, l) in diag.labels.iter().enumerate() {
        if Some(l.span.source) == primary.map(|p| p.source) {
            let span = SourceSpan::new((l.span.start as usize).into(), l.span.len());
            let text = if l.text.is_empty() {
                None
            } else {
                Some(l.text.clone())
            };
            labels.push(if i == 0 {
                LabeledSpan::new_primary_with_span(text, span)
            } else {
                LabeledSpan::new_with_span(text, span)
            });
        } else {
            let (line, col) = sources.line_col(l.span.source, l.span.start);
            let name = sources
                .get(l.span.source)
                .map(|f| f.name.as_str())
                .unwrap_or("?");
            elsewhere.push(format!("{name}:{line}:{col}: {}", l.text));
        }
    }
    let mut help = diag.hint.clone();
    if !elsewhere.is_empty() {
        let extra = format!("see also {}", elsewhere.join("; "));
        help = Some(match help {
            Some(h) => format!("{h}\n{extra}"),
            None => extra,
        });
    }
    let report = Report {
        diag,
        source: source.map(|f| {
            let spans = diag
                .labels
                .iter()
                .filter(|l| Some(l.span.source) == primary.map(|p| p.source))
                .map(|l| (l.span.start as usize, l.span.end as usize));
            Window::around(f, spans)
        }),
        labels,
        help,
    };
    let theme = if color {
        GraphicalTheme::unicode()
    } else {
        GraphicalTheme::unicode_nocolor()
    };
    let handler = GraphicalReportHandler::new_themed(theme)
        .with_width(100)
        .with_links(false);
    let mut out = String::new();
    if handler.render_report(&mut out, &report).is_err() {
        out = format!("{}: {}\n", diag.code.as_str(), diag.message);
    }
    out
}

/// Renders diagnostics as a JSON array: file, line, column, end, code, severity, message, hint.
pub fn render_json(diags: &[Diagnostic], sources: &SourceMap) -> String {
    let items: Vec<serde_json::Value> = diags
        .iter()
        .map(|d| {
            let (file, line, column, end_line, end_column) = match d.primary_span() {
                Some(s) => {
                    let (l, c) = sources.line_col(s.source, s.start);
                    let (el, ec) = sources.line_col(s.source, s.end);
                    let name = sources
                        .get(s.source)
                        .map(|f| f.name.clone())
                        .unwrap_or_default();
                    (Some(name), Some(l), Some(c), Some(el), Some(ec))
                }
                None => (None, None, None, None, None),
            };
            serde_json::json!({
                "file": file, "line": line, "column": column,
                "end_line": end_line, "end_column": end_column,
                "code": d.code.as_str(), "severity": d.severity,
                "message": d.message, "hint": d.hint,
                "labels": d.labels.iter().map(|l| l.text.clone()).collect::<Vec<_>>(),
            })
        })
        .collect();
    serde_json::to_string_pretty(&items).unwrap_or_else(|_| "[]".to_string())
}
