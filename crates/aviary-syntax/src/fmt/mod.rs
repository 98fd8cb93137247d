//! The canonical formatter: what `aviary fmt` writes.
//!
//! It is only called on a file that parsed without errors, and then it changes layout,
//! never meaning: the tree of its output equals the input's tree with spans ignored, and
//! formatting its output again gives the same text. It never panics, whatever the tree.
//!
//! # Layout
//! - 4 spaces of indentation per level, one item per line, LF line endings, exactly one
//!   newline at the end of the file, no trailing spaces.
//! - Single spaces between words; `, ` between list items; `name=value` for named
//!   arguments (no spaces around `=`); single spaces around condition operators
//!   (`drone.battery > 25%`, `NOT x`, `a AND b`); `(x, y)`, `GEO(lat, lon)`,
//!   `distance(a, b)`, `OFFSET(p, d, b)`, `MIDPOINT(a, b)`, `RECEIVED(S)`, `LET x = v`,
//!   single spaces around `+` and `-` between values (`where + (20m, 0m)`), `drone.DescendTo(3m)`, `drone.Land()`. Numbers are
//!   printed as written (sign included) with the unit glued on (`20 m` becomes `20m`);
//!   parentheses stay exactly where the source has them.
//! - Headers end in `:` and their body follows one level deeper. `ELSE IF c:` and
//!   `ELSE:` stand at the indentation of their `IF`. Capability sections stand one level
//!   under `CAPABILITY`, their conditions, defaults (`name: value`) and handlers one more.
//! - A `FOR` with one instance is one line (`PARALLEL FOR a WITH x AS d WITH p:`). With two
//!   or more it is the paper's form: `PARALLEL FOR` alone, then one line per instance
//!   (`a WITH x AND`, the last without `AND`), then `AS d WITH p:`, all one level deeper
//!   than the header, which is also the body's level.
//!
//! # Blank lines
//! One blank line wherever the source has one or more between two items or comments,
//! inside bodies too; never two in a row; none right after a header line, nor inside a
//! multi-line `FOR` header; exactly one between top-level items (two `USE` lines may stay
//! adjacent). The blank line that separates two top-level items goes before the comments
//! that lead into the second one.
//!
//! # Comments
//! Every comment is kept, with its text unchanged (except that a `//` comment loses its
//! trailing white space and the lines of a `/* */` comment lose theirs, so CRLF becomes
//! LF). A comment is *trailing* when code stands before it on its source line, and
//! *own-line* otherwise.
//! - A trailing comment stays at the end of the printed line that holds that code,
//!   after a single space (`drone Land // home`). Trailing comments inside a construct
//!   printed on one line (a header or a value written over several lines) move to the end
//!   of that line. A line that already ends in a `//` comment (or a multi-line `/* */`)
//!   takes no second one: the comment goes on its own line below, as an own-line comment.
//! - An own-line comment is printed on its own line before the next item, at that item's
//!   indentation. After the last item of a body, an own-line comment indented deeper than
//!   the line of that body's header stays at the end of that body, at the body's
//!   indentation; one indented less moves out to the enclosing body that it is indented
//!   deeper than (or to the top level). Comments keep their order, so a comment after one
//!   that moved out moves out too.
//! - Own-line comments inside a header printed on one line (a header over several source
//!   lines, a value broken inside parentheses) follow that line, at the indentation of the
//!   next item. Inside a multi-line `FOR` header they stay between the instance lines.
//!
//! # How comments are placed
//! Each printed line knows where its source starts; before printing it, every comment
//! that starts earlier in the source is printed (trailing ones onto the line printed
//! last, if it can take one). At the end of each body, the comments up to the next
//! logical line of code (from `line_starts`) that belong to the body are printed. Since
//! the output puts each comment where this rule puts it back, formatting is idempotent.

mod expr;
mod tree;

use crate::ast::{CommentKind, SourceFile};

/// Formats a file that parsed without errors; see the module documentation.
pub fn format(file: &SourceFile, source: &str, line_starts: &[u32]) -> String {
    let mut printer = Printer::new(file, source, line_starts);
    printer.file(file);
    printer.finish()
}

/// What the last printed line was.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Last {
    Nothing,
    Header,
    Code,
    Comment,
}

struct CommentInfo {
    start: usize,
    end: usize,
    kind: CommentKind,
    /// Code stands before it on its source line.
    trailing: bool,
    /// The indentation of its source line.
    column: u32,
}

struct Printer<'a> {
    source: &'a str,
    line_starts: &'a [u32],
    comments: Vec<CommentInfo>,
    /// The first comment not printed yet.
    next: usize,
    lines: Vec<String>,
    last: Last,
    /// The last line can take a trailing comment.
    open: bool,
    /// Where in the source the text printed so far ends.
    source_end: usize,
    /// The next new line is preceded by a blank line (between top-level items).
    force_blank: bool,
    /// Inside a multi-line header: no blank lines.
    in_header: bool,
}

impl<'a> Printer<'a> {
    fn new(file: &SourceFile, source: &'a str, line_starts: &'a [u32]) -> Printer<'a> {
        let bytes = source.as_bytes();
        let mut comments: Vec<CommentInfo> = Vec::with_capacity(file.comments.len());
        for c in &file.comments {
            let start = (c.span.start as usize).min(bytes.len());
            let end = (c.span.end as usize).clamp(start, bytes.len());
            let line_start = physical_line_start(bytes, start);
            // Code before it on its line: a non-blank byte that no earlier comment covers.
            let mut trailing = false;
            let mut pos = line_start;
            let mut earlier =
                comments.iter().rev().take_while(|e| e.end > line_start).collect::<Vec<_>>();
            earlier.reverse();
            let mut k = 0;
            while pos < start {
                if let Some(e) = earlier.get(k) {
                    if e.end <= pos {
                        k += 1;
                        continue;
                    }
                    if e.start <= pos {
                        pos = e.end;
                        continue;
                    }
                }
                if !bytes[pos].is_ascii_whitespace() {
                    trailing = true;
                    break;
                }
                pos += 1;
            }
            comments.push(CommentInfo {
                start,
                end,
                kind: c.kind,
                trailing,
                column: indentation(bytes, line_start),
            });
        }
        Printer {
            source,
            line_starts,
            comments,
            next: 0,
            lines: Vec::new(),
            last: Last::Nothing,
            open: false,
            source_end: 0,
            force_blank: false,
            in_header: false,
        }
    }

    fn finish(mut self) -> String {
        self.flush_before(usize::MAX, 0);
        while self.lines.last().is_some_and(|l| l.is_empty()) {
            self.lines.pop();
        }
        let mut out = self.lines.join("\n");
        out.push('\n');
        out
    }

    /// Prints one line of code at `depth`, for the source text from `start` to `end`,
    /// after the comments that come before `start`.
    fn line(&mut self, depth: usize, text: &str, kind: Last, start: usize, end: usize) {
        self.flush_before(start, depth);
        self.blank_before(start);
        self.lines.push(indented(depth, text));
        self.last = kind;
        self.open = true;
        self.source_end = self.source_end.max(end);
    }

    fn blank_before(&mut self, start: usize) {
        let wanted = match self.last {
            Last::Nothing => false,
            _ if self.force_blank => true,
            Last::Header => false,
            _ => !self.in_header && self.blank_in_source(self.source_end, start),
        };
        if wanted {
            self.lines.push(String::new());
        }
        self.force_blank = false;
    }

    /// Whether the source has a blank line between `from` and `to`.
    fn blank_in_source(&self, from: usize, to: usize) -> bool {
        let bytes = self.source.as_bytes();
        let to = to.min(bytes.len());
        let mut after_newline = false;
        for &b in bytes.get(from..to).unwrap_or(&[]) {
            match b {
                b'\n' if after_newline => return true,
                b'\n' => after_newline = true,
                b' ' | b'\t' | b'\r' => {}
                _ => after_newline = false,
            }
        }
        false
    }

    /// Prints every comment that starts before `at`, own-line ones at `depth`.
    fn flush_before(&mut self, at: usize, depth: usize) {
        while self.comments.get(self.next).is_some_and(|c| c.start < at) {
            self.comment(depth);
        }
    }

    /// After the last item of a body whose header starts at `header` and whose items end
    /// at `last_end`: the comments that belong to the end of that body (trailing, or
    /// indented deeper than the header's line), up to the next line of code.
    fn flush_body_end(&mut self, header: usize, last_end: usize, depth: usize) {
        let column = indentation(
            self.source.as_bytes(),
            physical_line_start(self.source.as_bytes(), header),
        );
        let next_code = self.next_line_start(last_end);
        while self
            .comments
            .get(self.next)
            .is_some_and(|c| c.start < next_code && (c.trailing || c.column > column))
        {
            self.comment(depth);
        }
    }

    /// Prints the next comment: at the end of the last line when it trails code and that
    /// line can take it, else on a line of its own at `depth`.
    fn comment(&mut self, depth: usize) {
        let Some(c) = self.comments.get(self.next) else { return };
        self.next += 1;
        let (start, end, kind, trailing) = (c.start, c.end, c.kind, c.trailing);
        let text = comment_text(self.source.get(start..end).unwrap_or(""), kind);
        let attach = trailing && self.open && matches!(self.last, Last::Header | Last::Code);
        match self.lines.last_mut() {
            Some(line) if attach => {
                line.push(' ');
                line.push_str(&text);
                if kind == CommentKind::Line || text.contains('\n') {
                    self.open = false;
                }
            }
            _ => {
                self.blank_before(start);
                self.lines.push(indented(depth, &text));
                self.last = Last::Comment;
                self.open = false;
            }
        }
        self.source_end = self.source_end.max(end);
    }

    /// The start of the first logical line at or after `pos` (the end of the text if none).
    fn next_line_start(&self, pos: usize) -> usize {
        let i = self.line_starts.partition_point(|&s| (s as usize) < pos);
        self.line_starts.get(i).map_or(self.source.len(), |&s| s as usize)
    }
}

fn indented(depth: usize, text: &str) -> String {
    let mut line = " ".repeat(depth * 4);
    line.push_str(text);
    line
}

fn physical_line_start(bytes: &[u8], pos: usize) -> usize {
    let pos = pos.min(bytes.len());
    bytes[..pos].iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1)
}

/// Columns of leading white space of the line that starts at `line_start` (a tab counts
/// 4, as in the lexer).
fn indentation(bytes: &[u8], line_start: usize) -> u32 {
    let mut columns = 0;
    for &b in bytes.get(line_start..).unwrap_or(&[]) {
        match b {
            b' ' => columns += 1,
            b'\t' => columns += 4,
            _ => break,
        }
    }
    columns
}

/// A comment's text, without trailing white space on any of its lines.
fn comment_text(raw: &str, kind: CommentKind) -> String {
    match kind {
        CommentKind::Line => raw.trim_end().to_string(),
        CommentKind::Block => raw.split('\n').map(str::trim_end).collect::<Vec<_>>().join("\n"),
    }
}
