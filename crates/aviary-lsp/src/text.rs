//! Byte offsets and the protocol's positions: a line and a column counted in UTF-16 code
//! units (the protocol's default encoding, and the only one every client speaks).

use lsp_types::{Position, Range};

/// Where each line of a text starts.
pub struct LineIndex<'a> {
    text: &'a str,
    starts: Vec<usize>,
}

impl<'a> LineIndex<'a> {
    pub fn new(text: &'a str) -> LineIndex<'a> {
        let mut starts = vec![0];
        starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        LineIndex { text, starts }
    }

    /// The position of the byte `offset` (clamped to the text and to a character's start).
    pub fn position(&self, offset: usize) -> Position {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.starts.partition_point(|&s| s <= offset) - 1;
        let column: usize = self.text[self.starts[line]..offset].chars().map(char::len_utf16).sum();
        Position { line: line as u32, character: column as u32 }
    }

    pub fn range(&self, span: aviary_diagnostics::Span) -> Range {
        Range { start: self.position(span.start as usize), end: self.position(span.end as usize) }
    }

    /// The byte offset of `position`: a column past the end of its line is the line's
    /// end, a line past the last is the text's end, and a column inside a character
    /// (half a surrogate pair) is that character's start.
    pub fn offset(&self, position: Position) -> usize {
        let Some(&start) = self.starts.get(position.line as usize) else {
            return self.text.len();
        };
        let end = self.starts.get(position.line as usize + 1).map_or(self.text.len(), |&e| e - 1);
        let mut units = 0u32;
        for (i, c) in self.text[start..end].char_indices() {
            units += c.len_utf16() as u32;
            if units > position.character {
                return start + i;
            }
        }
        end
    }
}

/// The byte offset of `position` in `text`, and its line's text up to it (what completion
/// and signature help read the context from).
pub fn line_before(text: &str, position: Position) -> (usize, &str) {
    let offset = LineIndex::new(text).offset(position);
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    (offset, &text[line_start..offset])
}

/// A word of the language (a name, a keyword, a code such as `E107`) that covers or
/// ends at `offset`, with its byte range.
pub fn word_at(text: &str, offset: usize) -> Option<(usize, usize)> {
    let is_word = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let offset = offset.min(text.len());
    let bytes = text.as_bytes();
    let mut start = offset;
    while start > 0 && is_word(bytes[start - 1] as char) {
        start -= 1;
    }
    let mut end = offset;
    while end < bytes.len() && is_word(bytes[end] as char) {
        end += 1;
    }
    (start < end).then_some((start, end))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_count_utf16_units() {
        // `é` is 2 bytes and 1 unit; `😀` is 4 bytes and 2 units.
        let text = "ab\n// é😀x\nlast";
        let index = LineIndex::new(text);
        let x = text.find('x').unwrap();
        assert_eq!(index.position(x), Position { line: 1, character: 6 });
        assert_eq!(index.offset(Position { line: 1, character: 6 }), x);
        // Inside the surrogate pair: the emoji's start.
        let emoji = text.find('😀').unwrap();
        assert_eq!(index.offset(Position { line: 1, character: 5 }), emoji);
        // Past the end of a line, and past the last line.
        assert_eq!(index.offset(Position { line: 0, character: 99 }), 2);
        assert_eq!(index.offset(Position { line: 9, character: 0 }), text.len());
        assert_eq!(index.position(text.len()), Position { line: 2, character: 4 });
        // Inside a character: its start.
        assert_eq!(index.position(emoji + 1), index.position(emoji));
    }

    #[test]
    fn round_trips_every_boundary() {
        let text = "MISSION M:\n    // ünïcödé 𝄞 text\n    d TakeOff\n";
        let index = LineIndex::new(text);
        for (i, _) in text.char_indices() {
            assert_eq!(index.offset(index.position(i)), i, "at {i}");
        }
    }

    #[test]
    fn words() {
        assert_eq!(word_at("a FlyTo WITH", 4), Some((2, 7)));
        assert_eq!(word_at("a FlyTo WITH", 7), Some((2, 7)));
        assert_eq!(word_at("a  b", 2), None);
    }
}
