//! Source texts and spans.
//!
//! Contract: a [`Span`] is small and `Copy`; it names a byte range of one text held by a
//! [`SourceMap`]. Stages after `lower` never see spans: they report entity indices, and the
//! provenance table maps those back to spans at the edge.

use serde::Serialize;

/// Index of a text in the [`SourceMap`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Default)]
pub struct SourceId(pub u32);

/// A byte range `[start, end)` in one source text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Default)]
pub struct Span {
    pub source: SourceId,
    pub start: u32,
    pub end: u32,
}

impl Span {
    pub fn new(source: SourceId, start: usize, end: usize) -> Span {
        Span {
            source,
            start: start as u32,
            end: end as u32,
        }
    }

    /// The smallest span covering both (they must be in the same source).
    pub fn to(self, other: Span) -> Span {
        Span {
            source: self.source,
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }

    pub fn len(&self) -> usize {
        (self.end - self.start) as usize
    }

    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }
}

/// One named text: a model file, or a command-line argument such as a `--set` value.
#[derive(Clone, Debug)]
pub struct SourceFile {
    pub name: String,
    pub text: String,
    /// The byte offset of each line's start, built once (line and column lookups, the
    /// windows diagnostics render, in time independent of where in the file they are).
    line_starts: Vec<usize>,
}

impl SourceFile {
    /// The 0-based line holding byte `offset`.
    pub fn line_of(&self, offset: usize) -> usize {
        self.line_starts
            .partition_point(|&s| s <= offset)
            .saturating_sub(1)
    }

    /// The byte range of lines `from..to` (0-based, clamped), their line ends included.
    pub fn lines(&self, from: usize, to: usize) -> std::ops::Range<usize> {
        let at = |l: usize| self.line_starts.get(l).copied().unwrap_or(self.text.len());
        at(from)..at(to)
    }
}

/// Every text a compilation has read. Diagnostics render against it.
#[derive(Clone, Debug, Default)]
pub struct SourceMap {
    files: Vec<SourceFile>,
}

impl SourceMap {
    pub fn new() -> SourceMap {
        SourceMap::default()
    }

    pub fn add(&mut self, name: impl Into<String>, text: impl Into<String>) -> SourceId {
        let text: String = text.into();
        let line_starts = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        self.files.push(SourceFile {
            name: name.into(),
            text,
            line_starts,
        });
        SourceId((self.files.len() - 1) as u32)
    }

    pub fn get(&self, id: SourceId) -> Option<&SourceFile> {
        self.files.get(id.0 as usize)
    }

    pub fn text(&self, id: SourceId) -> &str {
        self.get(id).map(|f| f.text.as_str()).unwrap_or("")
    }

    pub fn snippet(&self, span: Span) -> &str {
        self.text(span.source)
            .get(span.start as usize..span.end as usize)
            .unwrap_or("")
    }

    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, source: SourceId, offset: u32) -> (usize, usize) {
        let Some(file) = self.get(source) else {
            return (1, 1);
        };
        let offset = (offset as usize).min(file.text.len());
        let line = file.line_of(offset);
        let start = file.line_starts[line];
        let col = file
            .text
            .get(start..offset)
            .map_or(0, |l| l.chars().count())
            + 1;
        (line + 1, col)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_and_columns_come_from_the_index() {
        let mut m = SourceMap::new();
        let id = m.add("f", "ab\nçd\n\nlast");
        let f = m.get(id).expect("added");
        assert_eq!(m.line_col(id, 0), (1, 1));
        assert_eq!(m.line_col(id, 2), (1, 3));
        assert_eq!(m.line_col(id, 3), (2, 1));
        // Columns count characters: `ç` is two bytes.
        assert_eq!(m.line_col(id, 5), (2, 2));
        assert_eq!(m.line_col(id, 7), (3, 1));
        assert_eq!(m.line_col(id, 8), (4, 1));
        assert_eq!(m.line_col(id, 100), (4, 5));
        assert_eq!(f.line_of(8), 3);
        assert_eq!(&f.text[f.lines(1, 3)], "çd\n\n");
        assert_eq!(&f.text[f.lines(3, 9)], "last");
    }
}
