//! The syntax of `.mission` files: lexer, layout (indentation), a parser that never
//! fails, the syntax tree, and the canonical formatter.
//!
//! Invariants: no IO; `parse` returns a tree for every input, plus diagnostics; every
//! node carries the span of its source text; recursion is bounded by `MAX_DEPTH`.

// A pure stage: no unsafe code, and no panic on any input (tests may unwrap).
#![forbid(unsafe_code)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

pub mod ast;
mod fmt;
mod layout;
mod lexer;
mod parser;
pub mod token;
pub mod visit;

use aviary_diagnostics::{Code, Diagnostic, FileId, Span};

pub use fmt::format;
pub use parser::{MAX_DEPTH, MAX_ERRORS};

/// A parsed file: the tree (possibly partial) and what was wrong.
#[derive(Debug)]
pub struct Parse {
    pub tree: ast::SourceFile,
    pub diagnostics: Vec<aviary_diagnostics::Diagnostic>,
    /// Where each logical line starts; the formatter uses it to place comments.
    pub line_starts: Vec<u32>,
}

impl Parse {
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(|d| d.is_error())
    }
}

/// Parses mission text. Never fails and never panics.
pub fn parse(file: FileId, text: &str) -> Parse {
    let mut diagnostics = Vec::new();
    if let Some(nul) = text.find('\0') {
        diagnostics.push(
            Diagnostic::new(
                Code::BinaryFile,
                file,
                Span::new(nul, nul + 1),
                "this file holds binary data, not mission text",
            )
            .label("NUL byte")
            .with_help("check that this is the .mission file you meant"),
        );
        return Parse { tree: ast::SourceFile::default(), diagnostics, line_starts: Vec::new() };
    }
    let lexed = lexer::lex(file, text, &mut diagnostics);
    let layout = layout::layout(file, &lexed, text.len(), &mut diagnostics);
    let mut tree = parser::parse_tokens(file, text, layout.tokens, &mut diagnostics);
    tree.comments = lexed.comments;
    tree.line_offsets =
        std::iter::once(0).chain(text.match_indices('\n').map(|(at, _)| at as u32 + 1)).collect();
    if tree.items.is_empty() && !diagnostics.iter().any(|d| d.is_error()) {
        diagnostics.push(
            Diagnostic::new(Code::EmptyFile, file, Span::point(0), "this file has no MISSION and no CAPABILITY")
                .with_help("a mission file holds `MISSION Name:` with its blocks, and any `CAPABILITY` definitions"),
        );
    }
    aviary_diagnostics::sort(&mut diagnostics);
    Parse { tree, diagnostics, line_starts: layout.line_starts }
}

/// Reads one value by the language's rules for literals and names: a number with its
/// unit (`20m`, `-3.5km`, `2min`), coordinates `(x, y)` or `(x, y, z)`, a name (a symbol
/// or a place), a string in quotes, `TRUE` or `FALSE`. Errors are what was wrong, the
/// first one first. Never panics.
pub fn parse_value(text: &str) -> Result<ast::Expr, Vec<Diagnostic>> {
    let file = FileId::default();
    let mut diagnostics = Vec::new();
    // Leading blanks would read as an indented line.
    let text = text.trim();
    if text.contains(['\n', '\r', '\0']) {
        return Err(vec![Diagnostic::new(
            Code::Syntax,
            file,
            Span::point(0),
            "a value is one line of text",
        )]);
    }
    let lexed = lexer::lex(file, text, &mut diagnostics);
    let layout = layout::layout(file, &lexed, text.len(), &mut diagnostics);
    let value = parser::parse_value_tokens(file, text, layout.tokens, &mut diagnostics);
    match diagnostics.iter().any(Diagnostic::is_error) || matches!(value.kind, ast::ExprKind::Error)
    {
        false => Ok(value),
        true if diagnostics.is_empty() => {
            Err(vec![Diagnostic::new(Code::Syntax, file, value.span, "not a value")])
        }
        true => Err(diagnostics),
    }
}

/// Decodes bytes first: text that is not UTF-8 is reported where it stops being UTF-8,
/// and is not parsed further (its meaning would be a guess).
pub fn parse_bytes(file: FileId, bytes: &[u8]) -> (String, Parse) {
    match decode(bytes) {
        (text, None) => {
            let parse = parse(file, &text);
            (text, parse)
        }
        (text, Some(at)) => {
            let parse = Parse {
                tree: ast::SourceFile::default(),
                diagnostics: vec![invalid_utf8(file, at)],
                line_starts: Vec::new(),
            };
            (text, parse)
        }
    }
}

/// The text of some bytes, and where they stop being UTF-8 if they do (the text is
/// then decoded lossily, for display only).
pub fn decode(bytes: &[u8]) -> (String, Option<usize>) {
    match std::str::from_utf8(bytes) {
        Ok(text) => (text.to_string(), None),
        Err(e) => (String::from_utf8_lossy(bytes).into_owned(), Some(e.valid_up_to())),
    }
}

/// As [`decode`], taking the bytes: valid UTF-8 becomes the text without a copy (a large
/// world's file is megabytes).
pub fn decode_owned(bytes: Vec<u8>) -> (String, Option<usize>) {
    match String::from_utf8(bytes) {
        Ok(text) => (text, None),
        Err(e) => {
            let at = e.utf8_error().valid_up_to();
            (String::from_utf8_lossy(e.as_bytes()).into_owned(), Some(at))
        }
    }
}

pub fn invalid_utf8(file: FileId, at: usize) -> Diagnostic {
    Diagnostic::new(
        Code::InvalidUtf8,
        file,
        Span::new(at, at + 1),
        "this file is not valid UTF-8 text",
    )
    .label("the first byte that is not UTF-8")
    .with_help("save the file as UTF-8")
}
