//! The items of a body: blocks, statements, calls, signals, handlers, conditions.

use aviary_diagnostics::{Code, Span};

use super::Parser;
use crate::ast::*;
use crate::token::{Keyword, TokenKind};

impl Parser<'_> {
    pub(super) fn stmt(&mut self) -> Option<Stmt> {
        self.fix_keyword_case();
        let start = self.span();
        let stmt = match self.peek() {
            TokenKind::Keyword(k @ (Keyword::Sequential | Keyword::Parallel)) => {
                return self.sequential_or_parallel(k, start);
            }
            TokenKind::Keyword(Keyword::On) => {
                if self.peek_at(1) == TokenKind::Keyword(Keyword::Exception) {
                    return self.exception_handler().map(Stmt::ExceptionHandler);
                }
                self.handler(None, start)
            }
            TokenKind::Keyword(Keyword::Signal) => {
                self.bump();
                self.raise(start).map(Stmt::Signal)?
            }
            TokenKind::Keyword(Keyword::Throw) => {
                self.bump();
                if self.eat_keyword(Keyword::Exception).is_none() {
                    let span = self.span();
                    let d = self
                        .error(Code::Syntax, span, "expected EXCEPTION after THROW")
                        .with_help("write `THROW EXCEPTION Name`");
                    self.report(d);
                }
                self.raise(start).map(Stmt::Throw)?
            }
            TokenKind::Keyword(k @ (Keyword::StartIf | Keyword::WaitFor | Keyword::DoWhile)) => {
                let kind = match k {
                    Keyword::StartIf => RequirementKind::StartIf,
                    Keyword::WaitFor => RequirementKind::WaitFor,
                    _ => RequirementKind::DoWhile,
                };
                self.requirement(kind)
            }
            TokenKind::Keyword(Keyword::If) => self.if_chain(),
            TokenKind::Keyword(
                k @ (Keyword::Else
                | Keyword::Requirements
                | Keyword::Defaults
                | Keyword::Perform
                | Keyword::Exceptions
                | Keyword::Mission
                | Keyword::Capability
                | Keyword::Use),
            ) => {
                self.misplaced(k, start);
                return None;
            }
            TokenKind::TaggedName => self.leash(),
            TokenKind::Ident if self.peek_at(1) == TokenKind::Dot => self.api_call(),
            // `OPERATOR` is a word only before `SIGNAL` at the start of a line: a drone or
            // capability called `OPERATOR` stays what it was.
            TokenKind::Ident
                if self.text_of(start).eq_ignore_ascii_case("OPERATOR")
                    && self.peek_at(1) == TokenKind::Keyword(Keyword::Signal) =>
            {
                self.operator_signals()
            }
            // `ANY` is a word only at the start of a header: a drone or capability called
            // `ANY` stays what it was (a statement never ends in `:`).
            TokenKind::Ident if self.text_of(start) == "ANY" && self.line_ends_in_colon() => {
                self.any_block()
            }
            // `LET` is a word only before `name =` at the start of a line, as `OPERATOR`
            // is: a drone or capability called `LET` stays what it was.
            TokenKind::Ident
                if self.text_of(start).eq_ignore_ascii_case("LET")
                    && self.peek_at(1) == TokenKind::Ident
                    && self.peek_at(2) == TokenKind::Eq =>
            {
                self.let_stmt()
            }
            // `ALLOW` is a word only before a diagnostic's code at the start of a line: a
            // drone or capability called `ALLOW` stays what it was.
            TokenKind::Ident
                if self.text_of(start).eq_ignore_ascii_case("ALLOW")
                    && self.peek_at(1) == TokenKind::Ident
                    && looks_like_code(self.text_of(self.span_at(1))) =>
            {
                self.allow()
            }
            // `Name ABORT`: a block stopped (a leash names a tagged capability instead).
            TokenKind::Ident
                if matches!(
                    self.peek_at(1),
                    TokenKind::Keyword(Keyword::Abort | Keyword::Pause | Keyword::Resume)
                ) =>
            {
                self.stop_block()
            }
            TokenKind::Ident => self.statement(),
            TokenKind::Unknown => {
                self.recover_line();
                return None;
            }
            _ => {
                let d = self
                    .error(
                        Code::Syntax,
                        start,
                        format!("expected a statement, found {}", self.peek().describe()),
                    )
                    .with_help(
                        "a statement names actors and a capability: `drone FlyTo WITH Home`",
                    );
                self.report(d);
                self.recover_line();
                return None;
            }
        };
        Some(stmt)
    }

    /// SEQUENTIAL or PARALLEL: a block, a FOR block, or a handler whose body runs so.
    fn sequential_or_parallel(&mut self, k: Keyword, start: Span) -> Option<Stmt> {
        let kind =
            if k == Keyword::Sequential { BlockKind::Sequential } else { BlockKind::Parallel };
        Some(match self.peek_at(1) {
            TokenKind::Keyword(Keyword::For) => self.for_block(kind),
            TokenKind::Keyword(Keyword::On) => {
                self.bump();
                if self.peek_at(1) == TokenKind::Keyword(Keyword::Exception) {
                    let span = start.to(self.span());
                    let d = self
                        .error(Code::Syntax, span, format!("`{} ON EXCEPTION` is not a form", k.as_str()))
                        .with_help("an exception handler always starts at once: write `ON EXCEPTION Name:`");
                    self.report(d);
                    return self.exception_handler().map(Stmt::ExceptionHandler);
                }
                self.handler(Some(kind), start)
            }
            _ => self.block(kind),
        })
    }

    /// A keyword that cannot start a statement here (ELSE without IF, a capability
    /// section, a top-level item): reported, and its line skipped.
    fn misplaced(&mut self, k: Keyword, start: Span) {
        let d = match k {
            Keyword::Else => self
                .error(Code::MisplacedItem, start, "ELSE without an IF before it")
                .with_help("ELSE must follow the body of an IF, at the IF's indentation"),
            Keyword::Requirements | Keyword::Defaults | Keyword::Perform | Keyword::Exceptions => self
                .error(Code::MisplacedItem, start, format!("{} is a capability section, and is not allowed here", k.as_str()))
                .with_help("sections stand directly under `CAPABILITY Name BY drone:`, indented by 4 spaces"),
            _ => self
                .error(Code::MisplacedItem, start, format!("{} inside a block", k.as_str()))
                .with_help(format!(
                    "{} starts in the first column, outside every other definition",
                    k.as_str()
                )),
        };
        self.report(d);
        self.recover_line();
    }

    /// The end of a one-line item: anything left on the line is an error.
    fn end_line(&mut self, what: &str) {
        // An unknown character was reported by the lexer already.
        if !self.at_line_end() && !self.at(TokenKind::Unknown) {
            let span = self.span();
            let d = self
                .error(
                    Code::Syntax,
                    span,
                    format!(
                        "expected the end of the line after {what}, found {}",
                        self.peek().describe()
                    ),
                )
                .with_help("one statement per line; separate arguments with `,`");
            self.report(d);
        }
        self.skip_line();
    }

    fn block(&mut self, kind: BlockKind) -> Stmt {
        let start = self.bump().span;
        let name = self.ident();
        let body = if self.header_colon(start, &format!("the {} header", kind.as_str())) {
            self.body(&format!("the {} block", kind.as_str()))
        } else {
            self.recover_body()
        };
        Stmt::Block(Block {
            kind,
            name,
            body,
            span: Span::new(start.start as usize, self.last_end as usize),
        })
    }

    fn statement(&mut self) -> Stmt {
        let start = self.span();
        let mut names: Vec<(TokenKind, Span)> = Vec::new();
        while matches!(self.peek(), TokenKind::Ident | TokenKind::TaggedName) {
            if self.peek() == TokenKind::Ident
                && self.text_of(self.span()).eq_ignore_ascii_case("with")
            {
                let span = self.span();
                let d = self
                    .error(Code::KeywordCase, span, "keywords are written in upper case: `WITH`")
                    .with_help("write `WITH`");
                self.report(d);
                self.tokens[self.pos].kind = TokenKind::Keyword(Keyword::With);
                break;
            }
            let t = self.bump();
            names.push((t.kind, t.span));
        }
        // `FlyCircle - C1`: a tag must be glued to its name.
        let mut spaced_tag = None;
        if self.at(TokenKind::Minus) && self.peek_at(1) == TokenKind::Ident {
            if let Some(&(TokenKind::Ident, name)) = names.last() {
                let tag = self.span_at(1);
                let d = self
                    .error(
                        Code::SpacedTag,
                        name.to(tag),
                        "an activity tag is glued to its capability's name",
                    )
                    .with_help(format!(
                        "write `{}-{}`, without spaces",
                        self.text_of(name),
                        self.text_of(tag)
                    ));
                self.report(d);
                self.bump();
                self.bump();
                spaced_tag = Some(tag);
            }
        }
        if names.len() == 1 && spaced_tag.is_some() {
            let (_, name) = names[0];
            return self.leash_rest(
                self.ident_at(name),
                self.ident_at(spaced_tag.unwrap_or_default()),
                start,
            );
        }
        if let Some(&(_, span)) =
            names[..names.len().saturating_sub(1)].iter().find(|(k, _)| *k == TokenKind::TaggedName)
        {
            let d = self
                .error(
                    Code::Syntax,
                    span,
                    "an activity tag belongs on the capability, the last name before WITH",
                )
                .with_help("write the actors first, then `Capability-Tag`");
            self.report(d);
        }
        if names.len() < 2 {
            let (_, span) = names.first().copied().unwrap_or((TokenKind::Ident, start));
            let word = self.text_of(span).to_string();
            let mut d =
                self.error(Code::Syntax, span, format!("`{word}` alone is not a statement"));
            d = if matches!(self.peek(), TokenKind::Colon) {
                d.with_help("block headers start with SEQUENTIAL, PARALLEL, ON, IF, STARTIF, WAITFOR or DOWHILE")
            } else {
                d.with_help(format!("name the actor that does it first: `drone {word}`"))
            };
            self.report(d);
            self.recover_line();
            return Stmt::Error(Span::new(start.start as usize, self.last_end as usize));
        }
        let (cap_kind, cap_span) = names.pop().unwrap_or((TokenKind::Ident, start));
        let (capability, mut tag) = if cap_kind == TokenKind::TaggedName {
            self.split_tag(cap_span)
        } else {
            (self.ident_at(cap_span), None)
        };
        if let Some(t) = spaced_tag {
            tag = Some(self.ident_at(t));
        }
        let actors = names.into_iter().map(|(_, s)| self.ident_at(s)).collect();
        let args = self.args_after_names();
        self.end_line("the statement");
        Stmt::Statement(Statement {
            actors,
            capability,
            tag,
            args,
            span: Span::new(start.start as usize, self.last_end as usize),
        })
    }

    /// `WITH args`, or nothing; values without WITH are the paper's form, reported.
    fn args_after_names(&mut self) -> Vec<Arg> {
        if self.eat_keyword(Keyword::With).is_some() {
            return self.args();
        }
        if matches!(
            self.peek(),
            TokenKind::Number | TokenKind::String | TokenKind::LParen | TokenKind::Minus
        ) {
            let span = self.span();
            let d = self
                .error(Code::ArgumentsWithoutWith, span, "arguments follow WITH")
                .with_help(format!(
                    "write `WITH {}`",
                    self.text_of(Span::new(span.start as usize, self.line_end_offset())).trim()
                ));
            self.report(d);
            return self.args();
        }
        Vec::new()
    }

    pub(super) fn ident_at(&self, span: Span) -> Ident {
        Ident { name: self.text_of(span).to_string(), span }
    }

    fn split_tag(&self, span: Span) -> (Ident, Option<Ident>) {
        let text = self.text_of(span);
        let dash = text.find('-').unwrap_or(text.len());
        let name = Span::new(span.start as usize, span.start as usize + dash);
        let tag =
            Span::new((span.start as usize + dash + 1).min(span.end as usize), span.end as usize);
        (self.ident_at(name), Some(self.ident_at(tag)))
    }

    fn leash(&mut self) -> Stmt {
        let start = self.span();
        let token = self.bump();
        let (capability, tag) = self.split_tag(token.span);
        let tag = tag.unwrap_or_else(|| self.ident_at(Span::point(token.span.end as usize)));
        self.leash_rest(capability, tag, start)
    }

    fn leash_rest(&mut self, capability: Ident, tag: Ident, start: Span) -> Stmt {
        let action = match self.peek() {
            TokenKind::Keyword(k @ (Keyword::Abort | Keyword::Pause | Keyword::Resume)) => {
                let t = self.bump();
                Ident { name: k.as_str().to_string(), span: t.span }
            }
            TokenKind::Ident => self.ident().unwrap_or_else(|| self.ident_at(start)),
            _ => {
                self.expected(
                    "what to do with the activity",
                    Some(&format!(
                        "write `{}-{} PAUSE` (or ABORT, RESUME, or a PERFORM section's name)",
                        capability.name, tag.name
                    )),
                );
                self.recover_line();
                return Stmt::Error(Span::new(start.start as usize, self.last_end as usize));
            }
        };
        let args = if self.eat_keyword(Keyword::With).is_some() { self.args() } else { Vec::new() };
        self.end_line("the leash call");
        Stmt::Leash(LeashCall {
            capability,
            tag,
            action,
            args,
            span: Span::new(start.start as usize, self.last_end as usize),
        })
    }

    fn api_call(&mut self) -> Stmt {
        let start = self.span();
        let actor = self.ident().unwrap_or_else(|| self.ident_at(start));
        self.bump(); // `.`
        let Some(function) = self.ident() else {
            self.expected(
                "the name of a middle-layer function after `.`",
                Some("write `drone.Land()`"),
            );
            self.recover_line();
            return Stmt::Error(Span::new(start.start as usize, self.last_end as usize));
        };
        let mut args = Vec::new();
        if self.eat(TokenKind::LParen).is_some() {
            if self.eat(TokenKind::RParen).is_none() {
                loop {
                    args.push(self.value());
                    if self.eat(TokenKind::Comma).is_none() {
                        break;
                    }
                }
                if self.eat(TokenKind::RParen).is_none() {
                    self.expected("`)` to close the call", None);
                    self.recover_line();
                    return Stmt::Error(Span::new(start.start as usize, self.last_end as usize));
                }
            }
        } else {
            let span = self.span();
            let d = self
                .error(
                    Code::Syntax,
                    span,
                    format!("`{}.{}` needs parentheses", actor.name, function.name),
                )
                .with_help(format!(
                    "write `{}.{}()`, with the arguments inside",
                    actor.name, function.name
                ));
            self.report(d);
        }
        self.end_line("the API call");
        Stmt::Api(ApiCall {
            actor,
            function,
            args,
            span: Span::new(start.start as usize, self.last_end as usize),
        })
    }

    pub(super) fn args(&mut self) -> Vec<Arg> {
        let mut args = Vec::new();
        loop {
            if self.at_line_end() {
                self.expected(
                    "an argument after WITH or `,`",
                    Some("write the arguments on the same line: `WITH center=Home, radius=50m`"),
                );
                break;
            }
            let name = if self.peek() == TokenKind::Ident && self.peek_at(1) == TokenKind::Eq {
                let n = self.ident();
                self.bump();
                n
            } else {
                None
            };
            let value = self.value();
            let failed = value.kind == ExprKind::Error;
            args.push(Arg { name, value });
            if failed || self.eat(TokenKind::Comma).is_none() {
                break;
            }
        }
        // Most lists have one or two arguments; a vector grows to four at its first push.
        args.shrink_to_fit();
        args
    }

    fn raise(&mut self, start: Span) -> Option<Raise> {
        let Some(name) = self.ident() else {
            self.expected("a name", Some("write `SIGNAL Name` or `THROW EXCEPTION Name`, optionally followed by `WITH values`"));
            self.recover_line();
            return None;
        };
        let args = if self.eat_keyword(Keyword::With).is_some() { self.args() } else { Vec::new() };
        self.end_line("the signal");
        Some(Raise { name, args, span: Span::new(start.start as usize, self.last_end as usize) })
    }

    fn requirement(&mut self, kind: RequirementKind) -> Stmt {
        let start = self.bump().span;
        let condition = self.condition();
        let what = format!("the {} header", kind.as_str());
        let body = if self.at(TokenKind::Colon) {
            self.bump();
            self.paper_condition_form(&condition, kind.as_str());
            Some(self.body(kind.as_str()))
        } else if kind == RequirementKind::WaitFor {
            self.end_line("the WAITFOR condition");
            None
        } else {
            if self.header_colon(start, &what) {
                Some(self.body(kind.as_str()))
            } else {
                Some(self.recover_body())
            }
        };
        Stmt::Requirement(Requirement {
            kind,
            condition,
            body,
            span: Span::new(start.start as usize, self.last_end as usize),
        })
    }

    /// The paper writes `IF type:Body`; here it is `IF type = Body:`.
    fn paper_condition_form(&mut self, condition: &Expr, keyword: &str) {
        if let (ExprKind::Name(name), TokenKind::Ident) = (&condition.kind, self.peek()) {
            let value = self.text_of(self.span()).to_string();
            let span = condition.span.to(self.span());
            let d = self
                .error(
                    Code::PaperForm,
                    span,
                    format!("`{keyword} {}:{value}` is the paper's form", name.name),
                )
                .with_help(format!("write `{keyword} {} = {value}:`", name.name));
            self.report(d);
            while !self.at_line_end() {
                self.bump();
            }
        }
    }

    fn if_chain(&mut self) -> Stmt {
        let start = self.bump().span;
        let mut branches = Vec::new();
        let condition = self.condition();
        let body = self.if_body(start, "IF", &condition);
        branches.push((condition, body));
        let mut otherwise = None;
        while self.at_keyword(Keyword::Else) {
            let else_span = self.bump().span;
            if self.eat_keyword(Keyword::If).is_some() {
                let condition = self.condition();
                let body = self.if_body(else_span, "ELSE IF", &condition);
                branches.push((condition, body));
            } else {
                let body = if self.header_colon(else_span, "ELSE") {
                    self.body("ELSE")
                } else {
                    self.recover_body()
                };
                otherwise = Some(body);
                break;
            }
        }
        Stmt::If(IfChain {
            branches,
            otherwise,
            span: Span::new(start.start as usize, self.last_end as usize),
        })
    }

    fn if_body(&mut self, start: Span, keyword: &str, condition: &Expr) -> Body {
        if self.at(TokenKind::Colon) {
            self.bump();
            self.paper_condition_form(condition, keyword);
            return self.body(keyword);
        }
        if self.header_colon(start, &format!("the {keyword} header")) {
            self.body(keyword)
        } else {
            self.recover_body()
        }
    }

    fn for_block(&mut self, kind: BlockKind) -> Stmt {
        let start = self.bump().span;
        self.bump(); // FOR
        let mut instances = Vec::new();
        loop {
            if self.at_keyword(Keyword::As) && !instances.is_empty() {
                let span = self.span();
                let d = self
                    .error(Code::Syntax, span, "AND is followed by AS, not by another instance")
                    .with_help("remove the last AND");
                self.report(d);
                break;
            }
            let Some(actor) = self.ident() else {
                self.expected(
                    "an actor or group for the FOR",
                    Some("write `PARALLEL FOR a WITH x AND b WITH y AS d WITH p:`"),
                );
                self.recover_line();
                return Stmt::Error(Span::new(start.start as usize, self.last_end as usize));
            };
            let mut values = Vec::new();
            if self.eat_keyword(Keyword::With).is_some() {
                loop {
                    values.push(self.value());
                    if self.eat(TokenKind::Comma).is_none() {
                        break;
                    }
                }
            }
            let span = Span::new(actor.span.start as usize, self.last_end as usize);
            instances.push(Instance { actor, values, span });
            if self.eat_keyword(Keyword::And).is_none() {
                break;
            }
        }
        if self.eat_keyword(Keyword::As).is_none() {
            self.expected(
                "AS and the alias for each instance",
                Some("write `... AS drone:` to name the actor of each instance"),
            );
            self.recover_line();
            return Stmt::Error(Span::new(start.start as usize, self.last_end as usize));
        }
        let alias = self.ident().unwrap_or_else(|| {
            self.expected("the alias after AS", None);
            Ident { name: String::new(), span: Span::point(self.last_end as usize) }
        });
        let params = if self.eat_keyword(Keyword::With).is_some() {
            self.name_list("a parameter name after WITH")
        } else {
            Vec::new()
        };
        let body = if self.header_colon(start, "the FOR header") {
            self.body("the FOR block")
        } else {
            self.recover_body()
        };
        Stmt::For(ForBlock {
            kind,
            instances,
            alias,
            params,
            body,
            span: Span::new(start.start as usize, self.last_end as usize),
        })
    }

    /// Whether the logical line from here ends in `:`.
    fn line_ends_in_colon(&self) -> bool {
        let end = (self.pos..self.tokens.len())
            .find(|&i| matches!(self.tokens[i].kind, TokenKind::Newline | TokenKind::Eof))
            .unwrap_or(self.pos);
        end > self.pos && self.tokens[end - 1].kind == TokenKind::Colon
    }

    /// A word of a header that is no keyword elsewhere (`IN`, `WHERE`), upper case.
    fn eat_word(&mut self, word: &str) -> Option<Span> {
        (self.at(TokenKind::Ident) && self.text_of(self.span()) == word).then(|| self.bump().span)
    }

    /// `ANY [k] d IN group [WHERE c] [NEAREST TO p] [WITHIN t]:` and its body. The clauses
    /// after the group may come in any order, each once.
    fn any_block(&mut self) -> Stmt {
        const FORM: &str = "write `ANY d IN group WHERE condition NEAREST TO place WITHIN 5min:` (WHERE, NEAREST TO and WITHIN may each be left out)";
        let start = self.bump().span;
        let count = self.at(TokenKind::Number).then(|| self.value());
        let Some(alias) = self.ident() else {
            self.expected("the name of the chosen drone after ANY", Some(FORM));
            self.recover_line();
            return Stmt::Error(Span::new(start.start as usize, self.last_end as usize));
        };
        let group = match self.eat_word("IN") {
            Some(_) => self.ident(),
            None => None,
        };
        let Some(group) = group else {
            self.expected("IN and the group to choose from", Some(FORM));
            self.recover_line();
            return Stmt::Error(Span::new(start.start as usize, self.last_end as usize));
        };
        let (mut condition, mut nearest, mut within) = (None, None, None);
        loop {
            let (word, slot) = if let Some(w) = self.eat_word("WHERE") {
                let c = self.condition();
                (w, condition.replace(c))
            } else if let Some(w) = self.eat_word("NEAREST") {
                if self.eat_word("TO").is_none() {
                    self.expected("TO after NEAREST", Some("write `NEAREST TO Depot`"));
                }
                let p = self.value();
                (w, nearest.replace(p))
            } else if let Some(w) = self.eat_word("WITHIN") {
                let t = self.value();
                (w, within.replace(t))
            } else {
                break;
            };
            if slot.is_some() {
                let text = self.text_of(word).to_string();
                let d = self
                    .error(Code::Syntax, word, format!("{text} is written twice in one ANY header"))
                    .with_help(format!("keep one {text}; join conditions with AND"));
                self.report(d);
            }
        }
        let body = if self.header_colon(start, "the ANY header") {
            self.body("the ANY block")
        } else {
            self.recover_body()
        };
        Stmt::Any(Box::new(AnyBlock {
            count,
            alias,
            group,
            condition,
            nearest,
            within,
            body,
            span: Span::new(start.start as usize, self.last_end as usize),
        }))
    }

    /// Handler headers: `BY actor` and `WITH a, b` after the name.
    fn handler_tail(&mut self) -> (Option<Ident>, Vec<Ident>) {
        let by = if self.eat_keyword(Keyword::By).is_some() {
            let by = self.ident();
            if by.is_none() {
                self.expected("an actor after BY", None);
            }
            by
        } else {
            None
        };
        let bindings = if self.eat_keyword(Keyword::With).is_some() {
            self.name_list("a name to bind after WITH")
        } else {
            Vec::new()
        };
        (by, bindings)
    }

    /// `ONE AT A TIME` before a handler header's `:`, if it is there: its span. The four
    /// words are words of the language only here, so a drone called `ONE` stays one.
    fn one_at_a_time(&mut self) -> Option<Span> {
        const WORDS: [&str; 4] = ["ONE", "AT", "A", "TIME"];
        if !(self.at(TokenKind::Ident) && self.text_of(self.span()).eq_ignore_ascii_case("ONE")) {
            return None;
        }
        let start = self.span();
        let fits = |p: &Self, i: usize, exact: bool| {
            p.peek_at(i) == TokenKind::Ident && {
                let word = p.text_of(p.span_at(i));
                if exact {
                    word == WORDS[i]
                } else {
                    word.eq_ignore_ascii_case(WORDS[i])
                }
            }
        };
        if !(0..WORDS.len()).all(|i| fits(self, i, false)) {
            // `ONE AT TIME`, `ONE BY ONE`: the phrase misspelt. Up to the `:` is skipped,
            // so the body is still read.
            let mut end = start;
            while !matches!(self.peek(), TokenKind::Colon | TokenKind::Newline | TokenKind::Eof) {
                end = self.bump().span;
            }
            let d = self
                .error(Code::Syntax, start.to(end), "expected `ONE AT A TIME` before the `:`")
                .with_help("write `ONE AT A TIME:` at the end of an `ON EVERY` header to run its firings one after another");
            self.report(d);
            return Some(start.to(end));
        }
        let exact = (0..WORDS.len()).all(|i| fits(self, i, true));
        let mut end = start;
        for _ in WORDS {
            end = self.bump().span;
        }
        let span = start.to(end);
        if !exact {
            let d = self
                .error(
                    Code::KeywordCase,
                    span,
                    "the words of the language are written in upper case: `ONE AT A TIME`",
                )
                .with_help("write `ONE AT A TIME`");
            self.report(d);
        }
        Some(span)
    }

    /// `OPERATOR SIGNAL Name, Name`.
    /// `LET name = value`.
    fn let_stmt(&mut self) -> Stmt {
        let start = self.bump().span; // LET
        if self.text_of(start) != "LET" {
            let d = self
                .error(
                    Code::KeywordCase,
                    start,
                    "the words of the language are written in upper case: `LET`",
                )
                .with_help("write `LET name = value`");
            self.report(d);
        }
        let t = self.bump(); // the name
        let name = self.ident_at(t.span);
        self.bump(); // =
        let value = if self.at_line_end() { self.error_value_after_let() } else { self.value() };
        let span = Span::new(start.start as usize, self.last_end as usize);
        if value.kind == ExprKind::Error {
            self.skip_line();
        } else {
            self.end_line("the LET's value");
        }
        Stmt::Let(Let { name, value, span })
    }

    fn error_value_after_let(&mut self) -> Expr {
        let span = self.span();
        self.expected(
            "a value after `=`",
            Some("write `LET name = value`, such as `LET east = OFFSET(where, 20m, 90deg)`"),
        );
        Expr { kind: ExprKind::Error, span }
    }

    fn operator_signals(&mut self) -> Stmt {
        let start = self.bump().span; // OPERATOR
        if self.text_of(start) != "OPERATOR" {
            let d = self
                .error(
                    Code::KeywordCase,
                    start,
                    "the words of the language are written in upper case: `OPERATOR`",
                )
                .with_help("write `OPERATOR SIGNAL Name`");
            self.report(d);
        }
        self.bump(); // SIGNAL
        if !self.at(TokenKind::Ident) {
            self.expected(
                "the name of a signal the operator may raise",
                Some("write `OPERATOR SIGNAL Pause_Inspection` (several names separated by `,`)"),
            );
            self.recover_line();
            return Stmt::Error(Span::new(start.start as usize, self.last_end as usize));
        }
        let names = self.name_list("a signal's name after `,`");
        if self.at_keyword(Keyword::With) {
            let span = self.span();
            let d = self
                .error(Code::Syntax, span, "an operator signal is declared by its name only")
                .with_help("the values the operator sends are those its handlers bind: `ON Go WITH where:`");
            self.report(d);
            self.skip_line();
        } else {
            self.end_line("the OPERATOR SIGNAL line");
        }
        Stmt::OperatorSignals(OperatorSignals {
            names,
            span: Span::new(start.start as usize, self.last_end as usize),
        })
    }

    /// `ALLOW W203 "reason"`.
    fn allow(&mut self) -> Stmt {
        let start = self.bump().span; // ALLOW
        if self.text_of(start) != "ALLOW" {
            let d = self
                .error(
                    Code::KeywordCase,
                    start,
                    "the words of the language are written in upper case: `ALLOW`",
                )
                .with_help("write `ALLOW W203 \"why the warning is expected\"`");
            self.report(d);
        }
        let code = self.ident().unwrap_or_else(|| self.ident_at(start));
        let Some(reason) = self.eat(TokenKind::String).map(|t| t.span) else {
            let span = self.span();
            let d = self
                .error(Code::Syntax, span.to(code.span), format!("`ALLOW {}` needs a reason", code.name))
                .with_help(format!(
                    "say in quotes why the warning is expected: `ALLOW {} \"the drone is made free first\"`",
                    code.name
                ));
            self.report(d);
            self.recover_line();
            return Stmt::Error(Span::new(start.start as usize, self.last_end as usize));
        };
        let raw = self.text_of(reason);
        let reason_text = raw
            .strip_prefix('"')
            .map(|r| r.strip_suffix('"').unwrap_or(r))
            .unwrap_or(raw)
            .trim()
            .to_string();
        if reason_text.is_empty() {
            let d = self
                .error(Code::Syntax, reason, "an ALLOW's reason is empty")
                .with_help("say why the warning is expected, for the next reader of the mission");
            self.report(d);
        }
        self.end_line("the ALLOW line");
        Stmt::Allow(Allow {
            code,
            reason: reason_text,
            span: Span::new(start.start as usize, self.last_end as usize),
        })
    }

    /// `Block_Name ABORT`; `PAUSE` and `RESUME` are a leash's only.
    fn stop_block(&mut self) -> Stmt {
        let start = self.span();
        let block = self.ident().unwrap_or_else(|| self.ident_at(start));
        let action = self.bump();
        if action.kind != TokenKind::Keyword(Keyword::Abort) {
            let word = self.text_of(action.span).to_string();
            let d = self
                .error(Code::Syntax, action.span, format!("a block cannot be told {word}: only ABORT stops a block"))
                .with_help(format!(
                    "write `{} ABORT` to end the block, or {word} a tagged activity inside it: `Capability-Tag {word}`",
                    block.name
                ));
            self.report(d);
            self.recover_line();
            return Stmt::Error(Span::new(start.start as usize, self.last_end as usize));
        }
        self.end_line("the block's ABORT");
        Stmt::StopBlock(StopBlock {
            block,
            span: Span::new(start.start as usize, self.last_end as usize),
        })
    }

    fn handler(&mut self, mode: Option<BlockKind>, start: Span) -> Stmt {
        self.bump(); // ON
        let every = self.eat_keyword(Keyword::Every).is_some();
        let Some(signal) = self.ident() else {
            self.expected("the name of the signal to handle", Some("write `ON SignalName:`"));
            self.recover_line();
            return Stmt::Error(Span::new(start.start as usize, self.last_end as usize));
        };
        let (by, bindings) = self.handler_tail();
        let mut one_at_a_time = self.one_at_a_time();
        if let (Some(span), false) = (one_at_a_time, every) {
            let d = self
                .error(Code::OneAtATimeNotEvery, span, "`ONE AT A TIME` orders the firings of an `ON EVERY`, and a plain `ON` fires once")
                .with_help(format!("write `ON EVERY {}` to handle every signal one firing after another, or leave `ONE AT A TIME` out", signal.name));
            self.report(d);
            one_at_a_time = None;
        }
        let body = if self.header_colon(start, "a handler's header") {
            self.body("the handler")
        } else {
            self.recover_body()
        };
        Stmt::Handler(Handler {
            mode,
            every,
            signal,
            by,
            bindings,
            one_at_a_time,
            body,
            span: Span::new(start.start as usize, self.last_end as usize),
        })
    }

    pub(super) fn exception_handler(&mut self) -> Option<ExceptionHandler> {
        let start = self.bump().span; // ON
        self.bump(); // EXCEPTION
        let Some(exception) = self.ident() else {
            self.expected(
                "the name of the exception to handle",
                Some("write `ON EXCEPTION BatteryCritical:`"),
            );
            self.recover_line();
            return None;
        };
        let (by, bindings) = self.handler_tail();
        if let Some(span) = self.one_at_a_time() {
            let d = self
                .error(Code::OneAtATimeNotEvery, span, "`ONE AT A TIME` orders the firings of an `ON EVERY`; an exception handler starts at once")
                .with_help("leave `ONE AT A TIME` out: an `ON EXCEPTION` takes the place of the work the exception aborted, so there is nothing to wait for");
            self.report(d);
        }
        let body = if self.header_colon(start, "an exception handler's header") {
            self.body("the handler")
        } else {
            self.recover_body()
        };
        Some(ExceptionHandler {
            exception,
            by,
            bindings,
            body,
            span: Span::new(start.start as usize, self.last_end as usize),
        })
    }
}

/// Whether `word` is written as a diagnostic's code: a letter and three digits (`W203`).
fn looks_like_code(word: &str) -> bool {
    let b = word.as_bytes();
    b.len() == 4 && b[0].is_ascii_alphabetic() && b[1..].iter().all(u8::is_ascii_digit)
}
