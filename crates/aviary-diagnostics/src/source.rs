use std::ops::Range;
use std::sync::OnceLock;

use codespan_reporting::files::{Error, Files};

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
#[derive(Default)]
pub struct SourceMap {
    files: Texts,
}

/// The texts, as codespan reads them: `SimpleFiles`, but each text's line starts are
/// found the first time a position in it is asked for. A world file of 100,000 drones
/// has half a million lines (4 MiB of starts) and most runs render nothing from it.
#[derive(Default)]
pub(crate) struct Texts(Vec<Text>);

struct Text {
    name: String,
    text: String,
    line_starts: OnceLock<Vec<usize>>,
}

impl Text {
    fn line_starts(&self) -> &[usize] {
        self.line_starts
            .get_or_init(|| codespan_reporting::files::line_starts(&self.text).collect())
    }

    /// As `SimpleFile::line_start`.
    fn line_start(&self, line_index: usize) -> Result<usize, Error> {
        let starts = self.line_starts();
        match line_index.cmp(&starts.len()) {
            std::cmp::Ordering::Less => Ok(starts[line_index]),
            std::cmp::Ordering::Equal => Ok(self.text.len()),
            std::cmp::Ordering::Greater => {
                Err(Error::LineTooLarge { given: line_index, max: starts.len() - 1 })
            }
        }
    }
}

impl Texts {
    fn add(&mut self, name: String, text: String) -> usize {
        self.0.push(Text { name, text, line_starts: OnceLock::new() });
        self.0.len() - 1
    }

    fn get(&self, id: usize) -> Result<&Text, Error> {
        self.0.get(id).ok_or(Error::FileMissing)
    }
}

impl<'a> Files<'a> for Texts {
    type FileId = usize;
    type Name = &'a str;
    type Source = &'a str;

    fn name(&'a self, id: usize) -> Result<&'a str, Error> {
        Ok(&self.get(id)?.name)
    }

    fn source(&'a self, id: usize) -> Result<&'a str, Error> {
        Ok(&self.get(id)?.text)
    }

    fn line_index(&'a self, id: usize, byte_index: usize) -> Result<usize, Error> {
        let starts = self.get(id)?.line_starts();
        Ok(starts.binary_search(&byte_index).unwrap_or_else(|next_line| next_line - 1))
    }

    fn line_range(&'a self, id: usize, line_index: usize) -> Result<Range<usize>, Error> {
        let text = self.get(id)?;
        Ok(text.line_start(line_index)?..text.line_start(line_index + 1)?)
    }
}

impl SourceMap {
    pub fn new() -> SourceMap {
        SourceMap::default()
    }
    pub fn add(&mut self, name: impl Into<String>, text: impl Into<String>) -> FileId {
        FileId(self.files.add(name.into(), text.into()) as u32)
    }
    /// Every file, in the order they were added.
    pub fn ids(&self) -> impl Iterator<Item = FileId> {
        (0..self.files.0.len() as u32).map(FileId)
    }
    pub fn name(&self, file: FileId) -> &str {
        self.files.get(file.0 as usize).map(|f| f.name.as_str()).unwrap_or("<unknown>")
    }
    pub fn text(&self, file: FileId) -> &str {
        self.files.get(file.0 as usize).map(|f| f.text.as_str()).unwrap_or("")
    }
    pub fn line_col(&self, file: FileId, offset: u32) -> LineCol {
        let id = file.0 as usize;
        let offset = clamp_to_char(self.text(file), offset as usize);
        let line = self.files.line_index(id, offset).unwrap_or(0);
        let column = self.files.column_number(id, line, offset).unwrap_or(1);
        LineCol { line: line + 1, column }
    }
    pub(crate) fn files(&self) -> &Texts {
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

#[cfg(test)]
mod tests {
    use codespan_reporting::files::SimpleFiles;

    use super::*;

    /// Lines as `SimpleFiles` finds them, for every offset and line, past the end too.
    #[test]
    fn texts_find_lines_as_simple_files_do() {
        let sources = ["", "x", "foo\nbar\r\n\nbaz", "\n\n", "a\n", "é\nü\r\n"];
        let (mut ours, mut theirs) = (Texts::default(), SimpleFiles::new());
        for (i, text) in sources.iter().enumerate() {
            ours.add(format!("f{i}"), text.to_string());
            theirs.add(format!("f{i}"), text.to_string());
        }
        for (id, text) in sources.iter().enumerate() {
            for at in 0..=text.len() + 1 {
                assert_eq!(
                    ours.line_index(id, at).ok(),
                    theirs.line_index(id, at).ok(),
                    "{text:?} at {at}"
                );
            }
            for line in 0..text.len() + 3 {
                assert_eq!(
                    ours.line_range(id, line).ok(),
                    theirs.line_range(id, line).ok(),
                    "{text:?} line {line}"
                );
            }
            assert_eq!(ours.source(id).ok(), theirs.source(id).ok());
        }
        assert!(ours.source(sources.len()).is_err() && ours.line_index(sources.len(), 0).is_err());
    }
}
