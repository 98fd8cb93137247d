//! Turns physical lines into logical lines with NEWLINE, INDENT and DEDENT tokens.
//!
//! Two things join physical lines (docs/LANGUAGE.md, section 2): a header that starts with MISSION,
//! CAPABILITY, SEQUENTIAL, PARALLEL or ON and does not end in `:` continues over the
//! deeper lines after it up to one that ends in `:`; and inside `( )` a line break is
//! free. Both only ever join lines indented deeper than the first, and a header joins
//! only when such a `:` line is found, so a forgotten colon is reported at its header
//! instead of swallowing the body.

use aviary_diagnostics::{Code, Diagnostic, FileId, Span};

use crate::lexer::{Lexed, RawToken};
use crate::token::{Keyword, Token, TokenKind};

pub struct Layout {
    pub tokens: Vec<Token>,
    /// Where each logical line's first token starts, in order.
    pub line_starts: Vec<u32>,
}

pub fn layout(
    file: FileId,
    lexed: &Lexed,
    text_len: usize,
    diagnostics: &mut Vec<Diagnostic>,
) -> Layout {
    let lines = &lexed.lines;
    let line_tokens = |i: usize| -> &[RawToken] {
        let start = lines[i].first_token as usize;
        let end = lines.get(i + 1).map_or(lexed.tokens.len(), |l| l.first_token as usize);
        &lexed.tokens[start..end]
    };
    let mut out = Layout {
        tokens: Vec::with_capacity(lexed.tokens.len() + lines.len() * 2),
        line_starts: Vec::new(),
    };
    let mut stack: Vec<u32> = vec![0];
    let mut i = 0;
    while i < lines.len() {
        let indent = lines[i].indent;
        let first = line_tokens(i)[0];
        let last_line = logical_end(i, lines.len(), indent, |k| lines[k].indent, &line_tokens);

        let top = *stack.last().unwrap_or(&0);
        if indent > top {
            stack.push(indent);
            out.tokens.push(Token {
                kind: TokenKind::Indent,
                span: Span::point(first.span.start as usize),
            });
        } else if indent < top && !stack.contains(&indent) {
            // Between two levels: reported, and read as a line of the current block,
            // so that the lines after it, at the right depth, read as written.
            {
                let expected: Vec<String> = stack.iter().map(|l| l.to_string()).collect();
                diagnostics.push(
                    Diagnostic::new(
                        Code::InconsistentDedent,
                        file,
                        Span::new(first.span.start as usize, first.span.end as usize),
                        format!("this line is indented {indent} spaces, which matches no enclosing block"),
                    )
                    .label("ambiguous dedent")
                    .with_help(format!("indent it to the level of a block it belongs to: {} spaces", expected.join(" or "))),
                );
            }
        } else {
            while *stack.last().unwrap_or(&0) > indent {
                stack.pop();
                out.tokens.push(Token {
                    kind: TokenKind::Dedent,
                    span: Span::point(first.span.start as usize),
                });
            }
        }
        out.line_starts.push(first.span.start);
        let mut end = first.span.end;
        for k in i..=last_line {
            for t in line_tokens(k) {
                out.tokens.push(Token { kind: t.kind, span: t.span });
                end = t.span.end;
            }
        }
        out.tokens.push(Token { kind: TokenKind::Newline, span: Span::point(end as usize) });
        i = last_line + 1;
    }
    let at = Span::point(text_len);
    while stack.len() > 1 {
        stack.pop();
        out.tokens.push(Token { kind: TokenKind::Dedent, span: at });
    }
    out.tokens.push(Token { kind: TokenKind::Eof, span: at });
    out
}

/// The last physical line of the logical line that starts at line `i`.
fn logical_end<'t>(
    i: usize,
    count: usize,
    indent: u32,
    indent_of: impl Fn(usize) -> u32,
    tokens_of: &impl Fn(usize) -> &'t [RawToken],
) -> usize {
    let first = tokens_of(i);
    let header = matches!(
        first[0].kind,
        TokenKind::Keyword(
            Keyword::Mission
                | Keyword::Capability
                | Keyword::Sequential
                | Keyword::Parallel
                | Keyword::On
        )
    );
    let ends_in_colon = |k: usize| tokens_of(k).last().map(|t| t.kind) == Some(TokenKind::Colon);
    let mut depth = paren_delta(first);
    let wants_header = header && !ends_in_colon(i);
    if depth <= 0 && !wants_header {
        return i;
    }
    let mut k = i + 1;
    while k < count && indent_of(k) > indent && continues(tokens_of(k - 1), tokens_of(k)) {
        depth += paren_delta(tokens_of(k));
        if depth <= 0 && (!wants_header || ends_in_colon(k)) {
            return k;
        }
        k += 1;
    }
    i
}

fn paren_delta(tokens: &[RawToken]) -> i32 {
    tokens.iter().fold(0, |d, t| match t.kind {
        TokenKind::LParen => d + 1,
        TokenKind::RParen => d - 1,
        _ => d,
    })
}

/// Whether `line` may continue the header whose previous line is `before`: a line that
/// starts a construct never does, except `ON ...` after a lone `SEQUENTIAL`/`PARALLEL`.
fn continues(before: &[RawToken], line: &[RawToken]) -> bool {
    let after_mode = matches!(
        before.last().map(|t| t.kind),
        Some(TokenKind::Keyword(Keyword::Sequential | Keyword::Parallel))
    );
    !starts_construct(line[0].kind)
        || (after_mode && line[0].kind == TokenKind::Keyword(Keyword::On))
}

/// A line that starts with one of these is a construct of its own, never a continuation.
fn starts_construct(kind: TokenKind) -> bool {
    use Keyword::*;
    matches!(
        kind,
        TokenKind::Keyword(
            Mission
                | Capability
                | Sequential
                | Parallel
                | On
                | Signal
                | Throw
                | StartIf
                | WaitFor
                | DoWhile
                | If
                | Else
                | Requirements
                | Defaults
                | Perform
                | Exceptions
                | Use
        )
    )
}
