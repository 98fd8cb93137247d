//! Recursive descent over the layout tokens. It never fails: every problem becomes a
//! diagnostic, the parser skips to the end of the line (and past an indented body it
//! cannot use), and goes on. Depth is bounded, so no input can overflow the stack.
//!
//! Written by hand, as rust-analyzer's, typst's and gleam's parsers are: error recovery
//! and exact spans matter more here than a grammar generator's brevity.

mod expr;
mod items;
mod stmt;

use aviary_diagnostics::{Code, Diagnostic, FileId, Span};

use crate::ast::{Body, Ident, SourceFile};
use crate::token::{Keyword, Token, TokenKind};

/// Blocks and expressions may nest this deep; deeper input is reported, not parsed.
pub const MAX_DEPTH: u32 = 64;
/// After this many syntax errors in one file the parser stops: more would be noise.
pub const MAX_ERRORS: usize = 100;

pub(crate) struct Parser<'a> {
    file: FileId,
    text: &'a str,
    tokens: Vec<Token>,
    pos: usize,
    depth: u32,
    last_end: u32,
    errors: usize,
    gave_up: bool,
    diagnostics: &'a mut Vec<Diagnostic>,
}

impl<'a> Parser<'a> {
    fn new(
        file: FileId,
        text: &'a str,
        tokens: Vec<Token>,
        diagnostics: &'a mut Vec<Diagnostic>,
    ) -> Parser<'a> {
        Parser {
            file,
            text,
            tokens,
            pos: 0,
            depth: 0,
            last_end: 0,
            errors: 0,
            gave_up: false,
            diagnostics,
        }
    }
}

pub(crate) fn parse_tokens(
    file: FileId,
    text: &str,
    tokens: Vec<Token>,
    diagnostics: &mut Vec<Diagnostic>,
) -> SourceFile {
    let mut parser = Parser::new(file, text, tokens, diagnostics);
    parser.file()
}

/// One value alone (`20m`, `(1, 2)`, `Body`, `"text"`), as an argument would be written:
/// what the operator's client reads from its command line. Anything after the value is
/// reported.
pub(crate) fn parse_value_tokens(
    file: FileId,
    text: &str,
    tokens: Vec<Token>,
    diagnostics: &mut Vec<Diagnostic>,
) -> crate::ast::Expr {
    let mut parser = Parser::new(file, text, tokens, diagnostics);
    let value = parser.value();
    if !parser.at_line_end() {
        parser.expected("the end of the value", Some("write one value: a number with its unit (20m), (x, y), a name, or a string in quotes"));
    }
    value
}

impl<'a> Parser<'a> {
    fn peek(&self) -> TokenKind {
        self.peek_at(0)
    }
    fn peek_at(&self, ahead: usize) -> TokenKind {
        if self.gave_up {
            return TokenKind::Eof;
        }
        self.tokens.get(self.pos + ahead).map_or(TokenKind::Eof, |t| t.kind)
    }
    fn span(&self) -> Span {
        self.span_at(0)
    }
    fn span_at(&self, ahead: usize) -> Span {
        self.tokens.get(self.pos + ahead).or(self.tokens.last()).map_or(Span::default(), |t| t.span)
    }
    fn text_of(&self, span: Span) -> &'a str {
        self.text.get(span.range()).unwrap_or("")
    }
    fn at(&self, kind: TokenKind) -> bool {
        self.peek() == kind
    }
    fn at_keyword(&self, keyword: Keyword) -> bool {
        self.peek() == TokenKind::Keyword(keyword)
    }
    fn at_line_end(&self) -> bool {
        matches!(self.peek(), TokenKind::Newline | TokenKind::Eof)
    }
    fn bump(&mut self) -> Token {
        let token = self
            .tokens
            .get(self.pos)
            .copied()
            .unwrap_or(Token { kind: TokenKind::Eof, span: Span::point(self.text.len()) });
        if token.kind != TokenKind::Eof {
            self.pos += 1;
        }
        if !matches!(
            token.kind,
            TokenKind::Newline | TokenKind::Indent | TokenKind::Dedent | TokenKind::Eof
        ) {
            self.last_end = token.span.end;
        }
        token
    }
    fn eat(&mut self, kind: TokenKind) -> Option<Token> {
        if self.at(kind) {
            Some(self.bump())
        } else {
            None
        }
    }
    fn eat_keyword(&mut self, keyword: Keyword) -> Option<Token> {
        self.eat(TokenKind::Keyword(keyword))
    }
    fn ident(&mut self) -> Option<Ident> {
        let token = self.eat(TokenKind::Ident)?;
        Some(Ident { name: self.text_of(token.span).to_string(), span: token.span })
    }

    /// Reports a problem. Past `MAX_ERRORS` the parser stops reading this file.
    fn report(&mut self, diagnostic: Diagnostic) {
        if self.gave_up {
            return;
        }
        self.errors += 1;
        if self.errors > MAX_ERRORS {
            let span = self.span();
            self.diagnostics.push(
                Diagnostic::new(
                    Code::TooManyErrors,
                    self.file,
                    span,
                    format!("more than {MAX_ERRORS} syntax errors; stopped reading here"),
                )
                .with_help("fix the errors above first; is this really a mission file?"),
            );
            self.gave_up = true;
            return;
        }
        self.diagnostics.push(diagnostic);
    }
    fn error(&mut self, code: Code, span: Span, message: impl Into<String>) -> Diagnostic {
        Diagnostic::new(code, self.file, span, message)
    }
    /// "expected X, found Y" at the current token.
    fn expected(&mut self, what: &str, help: Option<&str>) {
        let found = self.peek().describe();
        let span = self.span();
        let mut d = self.error(Code::Syntax, span, format!("expected {what}, found {found}"));
        if let Some(help) = help {
            d = d.with_help(help);
        }
        self.report(d);
    }

    /// Skips the rest of the logical line, its NEWLINE included.
    fn skip_line(&mut self) {
        while !matches!(self.peek(), TokenKind::Newline | TokenKind::Eof) {
            self.bump();
        }
        self.eat(TokenKind::Newline);
    }
    /// Skips an indented body without reading it (used past the depth limit).
    fn skip_nested(&mut self) {
        if self.eat(TokenKind::Indent).is_none() {
            return;
        }
        let mut level = 1usize;
        while level > 0 && !self.at(TokenKind::Eof) {
            match self.bump().kind {
                TokenKind::Indent => level += 1,
                TokenKind::Dedent => level -= 1,
                _ => {}
            }
        }
    }
    /// After an unusable line: skip it, and read (for its own errors) any body under it.
    fn recover_line(&mut self) {
        self.skip_line();
        if self.at(TokenKind::Indent) {
            let _ = self.indented_items(|p| p.stmt());
        }
    }

    /// The `:` that ends a header. Returns false (after reporting) when the line cannot go on.
    fn header_colon(&mut self, header_start: Span, what: &str) -> bool {
        if self.eat(TokenKind::Colon).is_some() {
            return true;
        }
        if self.at_line_end() {
            let at = Span::point(self.last_end as usize);
            let shown = self
                .text_of(Span::new(header_start.start as usize, self.last_end as usize))
                .replace('\n', " ");
            let d = self
                .error(Code::MissingColon, at, format!("{what} must end with `:`"))
                .label("`:` missing here")
                .with_help(format!("write `{}:`", collapse_spaces(&shown)));
            self.report(d);
            return true;
        }
        self.expected(&format!("`:` to end {what}"), None);
        self.skip_line();
        false
    }

    /// A body after a header's `:`: NEWLINE INDENT items DEDENT.
    fn body(&mut self, what: &str) -> Body {
        let header_end = self.last_end;
        if !self.at_line_end() {
            let span = self.span();
            let d = self
                .error(
                    Code::Syntax,
                    span,
                    format!("expected the end of the line after the `:` of {what}"),
                )
                .with_help("put the body on the lines below, indented by 4 more spaces");
            self.report(d);
            self.skip_line();
        } else {
            self.eat(TokenKind::Newline);
        }
        if !self.at(TokenKind::Indent) {
            let at = Span::point(header_end as usize);
            let d = self
                .error(Code::ExpectedBlock, at, format!("{what} has no body"))
                .label("an indented body must follow this `:`")
                .with_help("indent the lines that belong to it by 4 more spaces than the header");
            self.report(d);
            return Body { items: Vec::new(), header_end };
        }
        Body { items: self.indented_items(|p| p.stmt()), header_end }
    }

    /// INDENT item* DEDENT, with the depth bound.
    fn indented_items<T>(&mut self, mut item: impl FnMut(&mut Self) -> Option<T>) -> Vec<T> {
        self.indented_items_dyn(&mut item)
    }

    fn indented_items_dyn<T>(&mut self, item: &mut dyn FnMut(&mut Self) -> Option<T>) -> Vec<T> {
        if self.depth >= MAX_DEPTH {
            let span = self.span();
            let d = self
                .error(
                    Code::NestingTooDeep,
                    span,
                    format!("blocks are nested more than {MAX_DEPTH} levels deep"),
                )
                .with_help("split the mission into capabilities or flatter blocks");
            self.report(d);
            self.skip_nested();
            return Vec::new();
        }
        self.eat(TokenKind::Indent);
        self.depth += 1;
        let mut items = Vec::new();
        loop {
            match self.peek() {
                TokenKind::Dedent => {
                    self.bump();
                    break;
                }
                TokenKind::Eof => break,
                TokenKind::Newline => {
                    self.bump();
                }
                TokenKind::Indent => {
                    let span = self.span();
                    let d = self
                        .error(Code::UnexpectedIndent, span, "this line is indented deeper than the line before it")
                        .label("unexpected indent")
                        .with_help("indent it like its neighbours, or end the line before with `:` to open a block");
                    self.report(d);
                    items.extend(self.indented_items_dyn(item));
                }
                _ => {
                    let before = self.pos;
                    if let Some(it) = item(self) {
                        items.push(it);
                    }
                    if self.pos == before {
                        // Nothing was consumed; never loop on the same token.
                        self.bump();
                    }
                }
            }
        }
        self.depth -= 1;
        // Most bodies hold one to three statements, and a vector grows to four at its first
        // push: the slack would be a large part of the tree's memory, and the tree lives
        // until the mission is compiled.
        items.shrink_to_fit();
        items
    }

    /// A keyword written in the wrong case at the start of a header line (`Mission X:`)
    /// is reported once and read as the keyword, so the rest of the file still parses.
    fn fix_keyword_case(&mut self) {
        if self.peek() != TokenKind::Ident {
            return;
        }
        let Some(first) = Keyword::from_any_case(self.text_of(self.span())) else { return };
        let line_end = (self.pos..self.tokens.len())
            .find(|&i| matches!(self.tokens[i].kind, TokenKind::Newline | TokenKind::Eof))
            .unwrap_or(self.pos);
        let ends_in_colon =
            line_end > self.pos && self.tokens[line_end - 1].kind == TokenKind::Colon;
        let header_start = matches!(
            first,
            Keyword::Mission
                | Keyword::Capability
                | Keyword::Sequential
                | Keyword::Parallel
                | Keyword::On
                | Keyword::If
                | Keyword::Else
                | Keyword::StartIf
                | Keyword::DoWhile
                | Keyword::WaitFor
                | Keyword::Requirements
                | Keyword::Defaults
                | Keyword::Perform
                | Keyword::Exceptions
        );
        let use_line = first == Keyword::Use && self.peek_at(1) == TokenKind::String;
        if !(use_line || (header_start && ends_in_colon)) {
            return;
        }
        for i in self.pos..line_end {
            let token = self.tokens[i];
            if token.kind != TokenKind::Ident {
                continue;
            }
            let word = self.text_of(token.span);
            let structural = matches!(
                Keyword::from_any_case(word),
                Some(
                    Keyword::Every
                        | Keyword::By
                        | Keyword::With
                        | Keyword::For
                        | Keyword::And
                        | Keyword::As
                        | Keyword::Exception
                        | Keyword::If
                        | Keyword::On
                )
            );
            if i == self.pos || structural {
                if let Some(k) = Keyword::from_any_case(word) {
                    self.tokens[i].kind = TokenKind::Keyword(k);
                    let d = self
                        .error(
                            Code::KeywordCase,
                            token.span,
                            format!("keywords are written in upper case: `{}`", k.as_str()),
                        )
                        .with_help(format!("write `{}`", k.as_str()));
                    self.report(d);
                }
            }
        }
    }
}

fn collapse_spaces(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}
