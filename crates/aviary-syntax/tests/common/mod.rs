//! Helpers shared by the integration tests: the tree's identity without spans, and the
//! formatter's contract (idempotent, meaning-preserving, no comment lost).
#![allow(dead_code)]

use aviary_diagnostics::FileId;
use aviary_syntax::ast::{CommentKind, SourceFile};
use aviary_syntax::{format, parse, Parse};

/// Removes every `Span { start: N, end: N }` and the numbers of `header_end: N` and
/// `body_header_end: N` from a derived `Debug` text, leaving the tree's shape and words.
pub fn strip_spans(debug: &str) -> String {
    let bytes = debug.as_bytes();
    let mut out = String::with_capacity(debug.len());
    let mut i = 0;
    while i < bytes.len() {
        let rest = &debug[i..];
        if let Some(end) = span_at(rest) {
            out.push_str("Span");
            i += end;
            continue;
        }
        if let Some(after) = rest.strip_prefix("header_end: ") {
            let digits = after.bytes().take_while(u8::is_ascii_digit).count();
            if digits > 0 {
                out.push_str("header_end");
                i += "header_end: ".len() + digits;
                continue;
            }
        }
        let c = rest.chars().next().unwrap_or('\0');
        out.push(c);
        i += c.len_utf8().max(1);
    }
    out
}

/// The length of `Span { start: N, end: N }` at the start of `text`, if it is there.
fn span_at(text: &str) -> Option<usize> {
    let mut rest = text.strip_prefix("Span { start: ")?;
    let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
    if digits == 0 {
        return None;
    }
    rest = rest[digits..].strip_prefix(", end: ")?;
    let digits2 = rest.bytes().take_while(u8::is_ascii_digit).count();
    if digits2 == 0 {
        return None;
    }
    rest = rest[digits2..].strip_prefix(" }")?;
    Some(text.len() - rest.len())
}

/// The tree's identity: its items' `Debug` text without spans.
pub fn shape(tree: &SourceFile) -> String {
    strip_spans(&format!("{:?}", tree.items))
}

/// The texts of a file's comments in order, as the formatter prints them (no trailing
/// white space on any line).
pub fn comment_texts(tree: &SourceFile, text: &str) -> Vec<String> {
    tree.comments
        .iter()
        .map(|c| {
            let raw = text.get(c.span.range()).unwrap_or("");
            match c.kind {
                CommentKind::Line => raw.trim_end().to_string(),
                CommentKind::Block => {
                    raw.split('\n').map(str::trim_end).collect::<Vec<_>>().join("\n")
                }
            }
        })
        .collect()
}

pub fn describe_errors(parse: &Parse) -> String {
    parse
        .diagnostics
        .iter()
        .map(|d| format!("{} {:?}: {}", d.code.as_str(), d.primary.span, d.message))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Formats `text` (which must parse without errors) and checks the formatter's contract.
/// Returns the formatted text.
pub fn check_format(text: &str) -> String {
    let original = parse(FileId(0), text);
    assert!(
        !original.has_errors(),
        "the input has errors:\n{}\n--- input ---\n{text}",
        describe_errors(&original)
    );
    let formatted = format(&original.tree, text, &original.line_starts);

    let again = parse(FileId(0), &formatted);
    assert!(
        !again.has_errors(),
        "the formatted text has errors:\n{}\n--- input ---\n{text}\n--- formatted ---\n{formatted}",
        describe_errors(&again)
    );
    assert_eq!(
        shape(&original.tree),
        shape(&again.tree),
        "formatting changed the tree\n--- input ---\n{text}\n--- formatted ---\n{formatted}"
    );
    assert_eq!(
        comment_texts(&original.tree, text),
        comment_texts(&again.tree, &formatted),
        "formatting lost or changed comments\n--- input ---\n{text}\n--- formatted ---\n{formatted}"
    );
    let twice = format(&again.tree, &formatted, &again.line_starts);
    assert_eq!(formatted, twice, "formatting is not idempotent\n--- input ---\n{text}");

    assert!(
        formatted.ends_with('\n') && !formatted.ends_with("\n\n"),
        "not exactly one trailing newline:\n{formatted:?}"
    );
    // A lone CR is no line ending for the lexer (it can only be inside a comment, kept as written).
    assert!(!formatted.contains("\r\n"), "a CRLF in the output:\n{formatted:?}");
    // Blank lines inside a block comment are its text: look at the code around comments.
    let mut code = formatted.clone();
    for c in again.tree.comments.iter().rev() {
        code.replace_range(c.span.range(), "/**/");
    }
    assert!(!code.contains("\n\n\n"), "two blank lines in a row:\n{formatted}");
    for line in formatted.lines() {
        assert_eq!(line, line.trim_end(), "trailing white space in {line:?}");
    }
    formatted
}
