//! Values (arguments, with `+` and `-` between them) and conditions (comparisons, NOT,
//! AND, OR).

use aviary_diagnostics::{Code, Span};

use super::{Parser, MAX_DEPTH};
use crate::ast::*;
use crate::token::{Keyword, TokenKind};

const UNIT_WORDS: &[&str] = &["m", "km", "s", "min", "h", "deg"];
/// Spelled-out units after a number: reported with the unit to write instead.
const SPELLED_UNITS: &[&str] = &[
    "sec", "secs", "second", "seconds", "mins", "minute", "minutes", "hr", "hrs", "hour", "hours",
    "meter", "meters", "metre", "metres", "kmh", "kph", "mps", "degree", "degrees",
];

impl Parser<'_> {
    fn expr(&mut self, kind: ExprKind, start: Span) -> Expr {
        Expr {
            kind,
            span: Span::new(start.start as usize, (self.last_end as usize).max(start.end as usize)),
        }
    }

    fn error_expr(&mut self, what: &str, help: Option<&str>) -> Expr {
        let span = self.span();
        self.expected(what, help);
        Expr { kind: ExprKind::Error, span }
    }

    /// Guards recursion; past the limit the rest of the expression is reported and skipped.
    fn deeper<T>(&mut self, f: impl FnOnce(&mut Self) -> T, fallback: impl FnOnce(Span) -> T) -> T {
        if self.depth >= MAX_DEPTH {
            let span = self.span();
            let d = self
                .error(
                    Code::NestingTooDeep,
                    span,
                    format!("an expression nested more than {MAX_DEPTH} levels deep"),
                )
                .with_help("write the condition more simply");
            self.report(d);
            // Skip the rest, but keep a header's final `:` so the body still reads.
            while !self.at_line_end() && !self.at_header_colon() {
                self.bump();
            }
            return fallback(span);
        }
        self.depth += 1;
        let out = f(self);
        self.depth -= 1;
        out
    }

    /// At the `:` that ends a header line.
    fn at_header_colon(&self) -> bool {
        self.at(TokenKind::Colon) && matches!(self.peek_at(1), TokenKind::Newline | TokenKind::Eof)
    }

    /// A value: terms joined by `+` and `-` (`where + (20m, 0m)`), left to right.
    pub(super) fn value(&mut self) -> Expr {
        let first = self.term();
        self.sum_from(first)
    }

    /// The rest of a sum after its first term. Each operator counts against `MAX_DEPTH`,
    /// as AND and OR do, since the tree of `a + b + c ...` is as deep as the chain is long.
    fn sum_from(&mut self, first: Expr) -> Expr {
        let base = self.depth;
        let mut left = first;
        loop {
            let op = match self.peek() {
                TokenKind::Plus => ArithOp::Add,
                TokenKind::Minus => ArithOp::Sub,
                _ => break,
            };
            let too_long = format!("a sum of more than {MAX_DEPTH} parts");
            // A value may end a header: its `:` is kept for the header.
            if !self.link_deeper(
                &too_long,
                "give parts of the sum names of their own with LET",
                true,
            ) {
                break;
            }
            self.bump();
            let right = self.term();
            let span = left.span.to(right.span);
            left = Expr { kind: ExprKind::Arith(Box::new(left), op, Box::new(right)), span };
        }
        self.depth = base;
        left
    }

    /// A call of a form of `N` values (`OFFSET(p, d, b)`, `MIDPOINT(a, b)`), its name and
    /// `(` next: the values, `,` between them and `)`, made into the expression `make`
    /// says; what is missing is reported with the form to write.
    fn fixed_call<const N: usize>(
        &mut self,
        start: Span,
        form: &str,
        make: impl FnOnce([Box<Expr>; N]) -> ExprKind,
    ) -> Expr {
        self.bump();
        self.bump();
        self.deeper(
            |p| {
                let mut values = Vec::with_capacity(N);
                for i in 0..N {
                    if i > 0 && p.eat(TokenKind::Comma).is_none() {
                        let help = format!("write `{form}`");
                        return p.error_expr(&format!("`,` and {}", ordinal_value(i)), Some(&help));
                    }
                    values.push(Box::new(p.value()));
                }
                if p.eat(TokenKind::RParen).is_none() {
                    let help = format!("write `{form}`");
                    return p.error_expr(&format!("`)` to close {form}"), Some(&help));
                }
                match <[Box<Expr>; N]>::try_from(values) {
                    Ok(values) => p.expr(make(values), start),
                    Err(_) => Expr { kind: ExprKind::Error, span: start },
                }
            },
            |span| Expr { kind: ExprKind::Error, span },
        )
    }

    /// A term of a value: a literal, coordinates, a name, `a.b`, `distance(a, b)`,
    /// `OFFSET(p, d, b)`, `MIDPOINT(a, b)`, `GEO(...)`.
    fn term(&mut self) -> Expr {
        let start = self.span();
        match self.peek() {
            TokenKind::Number => self.number(false),
            TokenKind::Minus if self.peek_at(1) == TokenKind::Number => {
                self.bump();
                let mut e = self.number(true);
                e.span = start.to(e.span);
                e
            }
            TokenKind::String => {
                let t = self.bump();
                let raw = self.text_of(t.span);
                let inner = raw.strip_prefix('"').map(|r| r.strip_suffix('"').unwrap_or(r)).unwrap_or(raw);
                Expr { kind: ExprKind::String(inner.to_string()), span: t.span }
            }
            TokenKind::Keyword(k @ (Keyword::True | Keyword::False)) => {
                let t = self.bump();
                Expr { kind: ExprKind::Bool(k == Keyword::True), span: t.span }
            }
            TokenKind::LParen => self.deeper(
                |p| {
                    p.bump();
                    let first = p.value();
                    p.coordinates(first, start)
                },
                |span| Expr { kind: ExprKind::Error, span },
            ),
            TokenKind::Ident => self.name_value(),
            _ => self.error_expr("a value", Some("a value is a number with its unit (20m), a name, a string, or coordinates (x, y)")),
        }
    }

    /// After `(` and a first element: the rest of `(x, y)` or `(x, y, z)`.
    fn coordinates(&mut self, first: Expr, start: Span) -> Expr {
        let mut parts = vec![first];
        while self.eat(TokenKind::Comma).is_some() {
            parts.push(self.value());
        }
        if self.eat(TokenKind::RParen).is_none() {
            return self.error_expr("`)` to close the coordinates", None);
        }
        let e = self.expr(ExprKind::Coordinates(parts), start);
        if let ExprKind::Coordinates(parts) = &e.kind {
            if !(2..=3).contains(&parts.len()) {
                let d = self
                    .error(
                        Code::Syntax,
                        e.span,
                        format!("coordinates have 2 or 3 numbers, not {}", parts.len()),
                    )
                    .with_help("write `(x, y)` or `(x, y, z)` in metres");
                self.report(d);
            }
        }
        e
    }

    fn name_value(&mut self) -> Expr {
        let start = self.span();
        let word = self.text_of(start);
        let call = self.peek_at(1) == TokenKind::LParen;
        match word {
            "ELAPSED" => {
                self.bump();
                return self.expr(ExprKind::Elapsed, start);
            }
            "RECEIVED" if call => {
                self.bump();
                self.bump();
                let Some(signal) = self.ident() else {
                    return self.error_expr("a signal name", Some("write `RECEIVED(SignalName)`"));
                };
                if self.eat(TokenKind::RParen).is_none() {
                    return self.error_expr("`)` after the signal name", None);
                }
                return self.expr(ExprKind::Received(signal), start);
            }
            "distance" if call => {
                self.bump();
                self.bump();
                return self.deeper(
                    |p| {
                        let a = p.value();
                        if p.eat(TokenKind::Comma).is_none() {
                            return p.error_expr(
                                "`,` and a second place",
                                Some("write `distance(a, b)`"),
                            );
                        }
                        let b = p.value();
                        if p.eat(TokenKind::RParen).is_none() {
                            return p.error_expr("`)` to close distance(a, b)", None);
                        }
                        p.expr(ExprKind::Distance(Box::new(a), Box::new(b)), start)
                    },
                    |span| Expr { kind: ExprKind::Error, span },
                );
            }
            "OFFSET" if call => {
                return self.fixed_call(
                    start,
                    "OFFSET(position, distance, bearing)",
                    |[a, d, b]| ExprKind::Offset(a, d, b),
                );
            }
            "MIDPOINT" if call => {
                return self.fixed_call(start, "MIDPOINT(a, b)", |[a, b]| ExprKind::Midpoint(a, b));
            }
            "GEO" if call => {
                self.bump();
                self.bump();
                let mut parts = Vec::new();
                loop {
                    parts.push(self.value());
                    if self.eat(TokenKind::Comma).is_none() {
                        break;
                    }
                }
                if self.eat(TokenKind::RParen).is_none() {
                    return self.error_expr("`)` to close GEO(...)", None);
                }
                let e = self.expr(ExprKind::Geo(parts), start);
                if let ExprKind::Geo(parts) = &e.kind {
                    if !(2..=3).contains(&parts.len()) {
                        let d = self
                            .error(
                                Code::Syntax,
                                e.span,
                                "GEO takes latitude, longitude and an optional altitude",
                            )
                            .with_help("write `GEO(46.61, 14.26)`");
                        self.report(d);
                    }
                }
                return e;
            }
            _ => {}
        }
        let Some(name) = self.ident() else { return self.error_expr("a name", None) };
        if self.at(TokenKind::Dot) {
            self.bump();
            let Some(field) = self.ident() else {
                return self.error_expr(
                    &format!("a field after `{}.`", name.name),
                    Some("for example `drone.battery`"),
                );
            };
            return self.expr(ExprKind::Path(name, field), start);
        }
        Expr { span: name.span, kind: ExprKind::Name(name) }
    }

    fn number(&mut self, negative: bool) -> Expr {
        let t = self.bump();
        let text = self.text_of(t.span);
        let split = text.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(text.len());
        let (digits, unit_text) = text.split_at(split);
        let digits = if negative { format!("-{digits}") } else { digits.to_string() };
        let value = match digits.parse::<f64>() {
            Ok(v) if v.is_finite() => v,
            _ => {
                let d = self
                    .error(
                        Code::InvalidNumber,
                        t.span,
                        format!("`{}` is not a number that can be used", shorten(text)),
                    )
                    .with_help("write a number such as 20 or 2.5");
                self.report(d);
                return Expr { kind: ExprKind::Error, span: t.span };
            }
        };
        let mut span = t.span;
        let mut unit = None;
        if !unit_text.is_empty() {
            let unit_span = Span::new(t.span.start as usize + split, t.span.end as usize);
            unit = self.unit(unit_text, unit_span);
        } else if self.peek() == TokenKind::Ident
            && (UNIT_WORDS.contains(&self.text_of(self.span()))
                || SPELLED_UNITS.contains(&self.text_of(self.span()).to_ascii_lowercase().as_str()))
        {
            // `20 m` reads as `20m`; fmt writes it glued.
            let first = self.bump().span;
            let mut unit_span = first;
            if self.at(TokenKind::Slash) && self.peek_at(1) == TokenKind::Ident {
                self.bump();
                unit_span = first.to(self.bump().span);
            }
            let written = self.text_of(unit_span).replace(' ', "");
            unit = self.unit(&written, unit_span);
            span = span.to(unit_span);
        }
        Expr { kind: ExprKind::Number { digits, value, unit }, span }
    }

    fn unit(&mut self, text: &str, span: Span) -> Option<Unit> {
        if let Some(u) = Unit::parse(text) {
            return Some(u);
        }
        let known: Vec<&str> = Unit::ALL.iter().map(|u| u.as_str()).collect();
        let suggestion = match text.to_ascii_lowercase().as_str() {
            "sec" | "secs" | "second" | "seconds" => Some("s"),
            "mins" | "minute" | "minutes" => Some("min"),
            "hr" | "hrs" | "hour" | "hours" => Some("h"),
            "meter" | "meters" | "metre" | "metres" | "M" => Some("m"),
            "kmh" | "kph" => Some("km/h"),
            "mps" => Some("m/s"),
            "degree" | "degrees" => Some("deg"),
            lower if Unit::parse(lower).is_some() => Unit::parse(lower).map(|u| u.as_str()),
            _ => None,
        };
        let help = match suggestion {
            Some(s) => format!("write `{s}`; the units are {}", known.join(" ")),
            None => format!("the units are {}", known.join(" ")),
        };
        let d =
            self.error(Code::UnknownUnit, span, format!("unknown unit `{text}`")).with_help(help);
        self.report(d);
        None
    }

    /// A condition: OR of AND of NOT of comparisons.
    pub(super) fn condition(&mut self) -> Expr {
        self.deeper(|p| p.or_expr(), |span| Expr { kind: ExprKind::Error, span })
    }

    fn or_expr(&mut self) -> Expr {
        let base = self.depth;
        let mut left = self.and_expr();
        while self.at_keyword(Keyword::Or) && self.chain_deeper() {
            self.bump();
            let right = self.and_expr();
            let span = left.span.to(right.span);
            left = Expr {
                kind: ExprKind::Binary(Box::new(left), BinaryOp::Or, Box::new(right)),
                span,
            };
        }
        self.depth = base;
        left
    }

    fn and_expr(&mut self) -> Expr {
        let base = self.depth;
        let mut left = self.not_expr();
        while self.at_keyword(Keyword::And) && self.chain_deeper() {
            self.bump();
            let right = self.not_expr();
            let span = left.span.to(right.span);
            left = Expr {
                kind: ExprKind::Binary(Box::new(left), BinaryOp::And, Box::new(right)),
                span,
            };
        }
        self.depth = base;
        left
    }

    /// One more operator in an AND/OR chain. The tree of `a AND b AND c ...` is as deep
    /// as the chain is long, so each operator counts against `MAX_DEPTH` like a
    /// parenthesis (the caller restores the depth). Past the bound the rest of the line
    /// is reported and skipped.
    fn chain_deeper(&mut self) -> bool {
        let too_long = format!("a condition that joins more than {MAX_DEPTH} parts with AND or OR");
        let help = "split the condition: give parts of it their own WAITFOR, STARTIF or IF";
        self.link_deeper(&too_long, help, false)
    }

    /// One more link of a chain of operators (AND, OR, `+`, `-`), which nests the tree one
    /// level deeper: false, reported as `too_long` with `help` and the rest of the line
    /// skipped (up to a header's `:` when `keep_colon`), past `MAX_DEPTH`.
    fn link_deeper(&mut self, too_long: &str, help: &str, keep_colon: bool) -> bool {
        if self.depth >= MAX_DEPTH {
            let span = self.span();
            let d = self.error(Code::NestingTooDeep, span, too_long).with_help(help);
            self.report(d);
            let at_end = |p: &Self| p.at_line_end() || (keep_colon && p.at_header_colon());
            while !at_end(self) {
                self.bump();
            }
            return false;
        }
        self.depth += 1;
        true
    }

    fn not_expr(&mut self) -> Expr {
        let start = self.span();
        if self.eat_keyword(Keyword::Not).is_some() {
            let inner = self.deeper(|p| p.not_expr(), |span| Expr { kind: ExprKind::Error, span });
            return self.expr(ExprKind::Not(Box::new(inner)), start);
        }
        self.comparison()
    }

    fn comparison(&mut self) -> Expr {
        let left = self.operand();
        let op = match self.peek() {
            TokenKind::Eq => BinaryOp::Eq,
            TokenKind::Ne => BinaryOp::Ne,
            TokenKind::Lt => BinaryOp::Lt,
            TokenKind::Le => BinaryOp::Le,
            TokenKind::Gt => BinaryOp::Gt,
            TokenKind::Ge => BinaryOp::Ge,
            _ => return left,
        };
        self.bump();
        let right = self.operand();
        let span = left.span.to(right.span);
        Expr { kind: ExprKind::Binary(Box::new(left), op, Box::new(right)), span }
    }

    /// A value, or a parenthesised condition; `(a, b)` stays coordinates.
    fn operand(&mut self) -> Expr {
        if !self.at(TokenKind::LParen) {
            return self.value();
        }
        let start = self.span();
        let first = self.deeper(
            |p| {
                p.bump();
                let inner = p.or_expr();
                if p.at(TokenKind::Comma) {
                    return p.coordinates(inner, start);
                }
                if p.eat(TokenKind::RParen).is_none() {
                    // Inside went wrong and was reported: one error is enough.
                    if inner.kind == ExprKind::Error {
                        return inner;
                    }
                    return p.error_expr("`)`", None);
                }
                p.expr(ExprKind::Paren(Box::new(inner)), start)
            },
            |span| Expr { kind: ExprKind::Error, span },
        );
        if first.kind == ExprKind::Error {
            return first;
        }
        self.sum_from(first)
    }
}

/// `a second value`, `a third value`: what comes after the `i`th comma of a form.
fn ordinal_value(i: usize) -> &'static str {
    match i {
        1 => "a second value",
        2 => "a third value",
        _ => "another value",
    }
}

/// A long literal, cut to a readable length for messages.
fn shorten(text: &str) -> String {
    if text.chars().count() <= 24 {
        return text.to_string();
    }
    format!("{}...", text.chars().take(20).collect::<String>())
}
