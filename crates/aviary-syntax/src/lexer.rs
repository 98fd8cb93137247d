//! Raw tokens, one physical line at a time. Indentation and line joining are the
//! layout pass's job; this pass only records where each line starts and how deep.

use aviary_diagnostics::{Code, Diagnostic, FileId, Span};

use crate::ast::{Comment, CommentKind};
use crate::token::{Keyword, TokenKind};

#[derive(Clone, Copy, Debug)]
pub struct RawToken {
    pub kind: TokenKind,
    pub span: Span,
}

/// A physical line that holds at least one token.
#[derive(Clone, Copy, Debug)]
pub struct PhysicalLine {
    /// Columns of leading white space (a tab counts as 4, after it was reported).
    pub indent: u32,
    pub first_token: u32,
}

pub struct Lexed {
    pub tokens: Vec<RawToken>,
    pub lines: Vec<PhysicalLine>,
    pub comments: Vec<Comment>,
}

pub fn lex(file: FileId, text: &str, diagnostics: &mut Vec<Diagnostic>) -> Lexed {
    let mut lexer = Lexer {
        file,
        text,
        bytes: text.as_bytes(),
        pos: 0,
        line_start: 0,
        line_has_token: false,
        out: Lexed { tokens: Vec::new(), lines: Vec::new(), comments: Vec::new() },
        diagnostics,
    };
    lexer.run();
    lexer.out
}

struct Lexer<'a> {
    file: FileId,
    text: &'a str,
    bytes: &'a [u8],
    pos: usize,
    line_start: usize,
    line_has_token: bool,
    out: Lexed,
    diagnostics: &'a mut Vec<Diagnostic>,
}

fn is_ident_start(b: u8) -> bool {
    b.is_ascii_alphabetic() || b == b'_'
}
fn is_ident_continue(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

impl Lexer<'_> {
    fn peek(&self, ahead: usize) -> u8 {
        self.bytes.get(self.pos + ahead).copied().unwrap_or(0)
    }

    fn run(&mut self) {
        while self.pos < self.bytes.len() {
            let b = self.bytes[self.pos];
            match b {
                b'\n' => {
                    self.pos += 1;
                    self.line_start = self.pos;
                    self.line_has_token = false;
                }
                b' ' | b'\r' | b'\t' => self.pos += 1,
                b'/' if self.peek(1) == b'/' => self.line_comment(),
                b'/' if self.peek(1) == b'*' => self.block_comment(),
                _ => self.token(),
            }
        }
    }

    fn line_comment(&mut self) {
        let start = self.pos;
        while self.pos < self.bytes.len() && self.bytes[self.pos] != b'\n' {
            self.pos += 1;
        }
        let end = trim_cr(self.bytes, start, self.pos);
        self.out.comments.push(Comment { span: Span::new(start, end), kind: CommentKind::Line });
    }

    fn block_comment(&mut self) {
        let start = self.pos;
        self.pos += 2;
        loop {
            if self.pos >= self.bytes.len() {
                self.diagnostics.push(
                    Diagnostic::new(
                        Code::UnterminatedComment,
                        self.file,
                        Span::new(start, start + 2),
                        "this comment is never closed",
                    )
                    .label("opened here")
                    .with_help("end the comment with `*/`"),
                );
                break;
            }
            if self.bytes[self.pos] == b'*' && self.peek(1) == b'/' {
                self.pos += 2;
                break;
            }
            if self.bytes[self.pos] == b'\n' {
                self.line_start = self.pos + 1;
            }
            self.pos += 1;
        }
        self.out
            .comments
            .push(Comment { span: Span::new(start, self.pos), kind: CommentKind::Block });
    }

    fn push(&mut self, kind: TokenKind, start: usize) {
        if !self.line_has_token {
            self.line_has_token = true;
            let indent = self.indentation();
            self.out.lines.push(PhysicalLine { indent, first_token: self.out.tokens.len() as u32 });
        }
        self.out.tokens.push(RawToken { kind, span: Span::new(start, self.pos) });
    }

    /// Leading white space of the current line; a tab is reported once per line.
    fn indentation(&mut self) -> u32 {
        let mut columns = 0;
        let mut reported = false;
        for (i, &b) in self.bytes[self.line_start..].iter().enumerate() {
            match b {
                b' ' => columns += 1,
                b'\t' => {
                    let at = self.line_start + i;
                    if !reported {
                        reported = true;
                        self.diagnostics.push(
                            Diagnostic::new(
                                Code::TabIndent,
                                self.file,
                                Span::new(at, at + 1),
                                "a tab in the indentation",
                            )
                            .label("tab")
                            .with_help("indent with spaces only: 4 spaces for each level"),
                        );
                    }
                    columns += 4;
                }
                _ => break,
            }
        }
        columns
    }

    fn token(&mut self) {
        let start = self.pos;
        let b = self.bytes[self.pos];
        let kind = match b {
            b if is_ident_start(b) => return self.word(),
            b'0'..=b'9' => return self.number(),
            b'"' => return self.string(),
            b':' => self.one(TokenKind::Colon),
            b',' => self.one(TokenKind::Comma),
            b'(' => self.one(TokenKind::LParen),
            b')' => self.one(TokenKind::RParen),
            b'.' => self.one(TokenKind::Dot),
            b'-' => self.one(TokenKind::Minus),
            b'+' => self.one(TokenKind::Plus),
            b'/' => self.one(TokenKind::Slash),
            b'=' if self.peek(1) == b'=' => {
                self.pos += 2;
                self.diagnostics.push(
                    Diagnostic::new(
                        Code::Syntax,
                        self.file,
                        Span::new(start, self.pos),
                        "`==` is not an operator here",
                    )
                    .with_help("compare with a single `=`, as in `type = Body`"),
                );
                TokenKind::Eq
            }
            b'=' => self.one(TokenKind::Eq),
            b'!' if self.peek(1) == b'=' => self.two(TokenKind::Ne),
            b'<' if self.peek(1) == b'=' => self.two(TokenKind::Le),
            b'>' if self.peek(1) == b'=' => self.two(TokenKind::Ge),
            b'<' => self.one(TokenKind::Lt),
            b'>' => self.one(TokenKind::Gt),
            _ => return self.unknown(),
        };
        self.push(kind, start);
    }

    fn one(&mut self, kind: TokenKind) -> TokenKind {
        self.pos += 1;
        kind
    }
    fn two(&mut self, kind: TokenKind) -> TokenKind {
        self.pos += 2;
        kind
    }

    fn word(&mut self) {
        let start = self.pos;
        while is_ident_continue(self.peek(0)) {
            self.pos += 1;
        }
        let mut kind = match Keyword::from_exact(&self.text[start..self.pos]) {
            Some(k) => TokenKind::Keyword(k),
            None => TokenKind::Ident,
        };
        // `FlyCircle-C1`: a tag glued to its name is one token.
        if kind == TokenKind::Ident && self.peek(0) == b'-' && is_ident_start(self.peek(1)) {
            self.pos += 1;
            while is_ident_continue(self.peek(0)) {
                self.pos += 1;
            }
            kind = TokenKind::TaggedName;
        }
        self.push(kind, start);
    }

    fn number(&mut self) {
        let start = self.pos;
        while self.peek(0).is_ascii_digit() {
            self.pos += 1;
        }
        if self.peek(0) == b'.' && self.peek(1).is_ascii_digit() {
            self.pos += 1;
            while self.peek(0).is_ascii_digit() {
                self.pos += 1;
            }
        }
        // A glued unit: `20m`, `5m/s`, `30km/h`, `25%`.
        if self.peek(0).is_ascii_alphabetic() || self.peek(0) == b'%' {
            while self.peek(0).is_ascii_alphanumeric()
                || self.peek(0) == b'%'
                || self.peek(0) == b'_'
            {
                self.pos += 1;
            }
            if self.peek(0) == b'/' && self.peek(1).is_ascii_alphabetic() {
                self.pos += 1;
                while self.peek(0).is_ascii_alphanumeric() {
                    self.pos += 1;
                }
            }
        }
        self.push(TokenKind::Number, start);
    }

    fn string(&mut self) {
        let start = self.pos;
        self.pos += 1;
        while self.pos < self.bytes.len()
            && self.bytes[self.pos] != b'"'
            && self.bytes[self.pos] != b'\n'
        {
            self.pos += 1;
        }
        if self.peek(0) == b'"' {
            self.pos += 1;
        } else {
            let end = trim_cr(self.bytes, start, self.pos);
            self.diagnostics.push(
                Diagnostic::new(
                    Code::UnterminatedString,
                    self.file,
                    Span::new(start, end),
                    "this string has no closing quote",
                )
                .with_help("end the string with `\"` on the same line"),
            );
            self.pos = end;
        }
        self.push(TokenKind::String, start);
    }

    /// A run of characters with no meaning is one diagnostic, not one per character.
    fn unknown(&mut self) {
        let start = self.pos;
        let first = self.text[start..].chars().next().unwrap_or('?');
        self.pos += first.len_utf8();
        while self.pos < self.bytes.len() {
            let b = self.bytes[self.pos];
            if b.is_ascii_alphanumeric() || b" \t\r\n:,().=-/\"<>_".contains(&b) {
                break;
            }
            let c = self.text[self.pos..].chars().next().unwrap_or('?');
            self.pos += c.len_utf8();
        }
        let help = if first.is_alphabetic() {
            "names use only the letters A-Z and a-z, digits and `_`".to_string()
        } else {
            "remove it; the language uses only `: , ( ) . = != < <= > >= -` between words"
                .to_string()
        };
        let shown: String = first.escape_debug().collect();
        self.diagnostics.push(
            Diagnostic::new(
                Code::UnknownCharacter,
                self.file,
                Span::new(start, self.pos),
                format!("unexpected character `{shown}`"),
            )
            .with_help(help),
        );
        self.push(TokenKind::Unknown, start);
    }
}

fn trim_cr(bytes: &[u8], start: usize, mut end: usize) -> usize {
    while end > start && bytes[end - 1] == b'\r' {
        end -= 1;
    }
    end
}
