use codespan_reporting::files::{Files, SimpleFiles};

/// Which source a span points into.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct FileId(pub u32);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LineCol {
    /// 1-based.
    pub line: usize,
    /// 1-based, in characters.
    pub column: usize,
}

/// Every source text a run has seen, by id: mission files, USEd files, the standard
/// library and world files. Texts are kept so that any later stage can render a span.
pub struct SourceMap {
    files: SimpleFiles<String, String>,
}

impl Default for SourceMap {
    fn default() -> SourceMap {
        SourceMap { files: SimpleFiles::new() }
    }
}

impl SourceMap {
    pub fn new() -> SourceMap {
        SourceMap::default()
    }
    pub fn add(&mut self, name: impl Into<String>, text: impl Into<String>) -> FileId {
        FileId(self.files.add(name.into(), text.into()) as u32)
    }
    pub fn name(&self, file: FileId) -> &str {
        self.files.get(file.0 as usize).map(|f| f.name().as_str()).unwrap_or("<unknown>")
    }
    pub fn text(&self, file: FileId) -> &str {
        self.files.get(file.0 as usize).map(|f| f.source().as_str()).unwrap_or("")
    }
    pub fn line_col(&self, file: FileId, offset: u32) -> LineCol {
        let id = file.0 as usize;
        let offset = clamp_to_char(self.text(file), offset as usize);
        let line = self.files.line_index(id, offset).unwrap_or(0);
        let column = self.files.column_number(id, line, offset).unwrap_or(1);
        LineCol { line: line + 1, column }
    }
    pub(crate) fn files(&self) -> &SimpleFiles<String, String> {
        &self.files
    }
}

/// A span may point into the middle of a character only through a bug elsewhere;
/// rendering must still not panic, so move it back to a boundary.
pub(crate) fn clamp_to_char(text: &str, mut offset: usize) -> usize {
    offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    offset
}
