//! Top-level items: USE, MISSION, CAPABILITY and the sections of a capability.

use aviary_diagnostics::{Code, Span};

use super::Parser;
use crate::ast::*;
use crate::token::{Keyword, TokenKind};

impl Parser<'_> {
    pub(super) fn file(&mut self) -> SourceFile {
        let mut file = SourceFile::default();
        loop {
            self.fix_keyword_case();
            match self.peek() {
                TokenKind::Eof => break,
                TokenKind::Newline | TokenKind::Dedent => {
                    self.bump();
                }
                TokenKind::Keyword(Keyword::Use) => {
                    if let Some(u) = self.use_item() {
                        file.items.push(Item::Use(u));
                    }
                }
                TokenKind::Keyword(Keyword::Mission) => {
                    file.items.push(Item::Mission(self.mission()))
                }
                TokenKind::Keyword(Keyword::Capability) => {
                    if let Some(c) = self.capability() {
                        file.items.push(Item::Capability(c));
                    }
                }
                TokenKind::Indent => {
                    let span = self.span();
                    let d = self
                        .error(
                            Code::UnexpectedIndent,
                            span,
                            "an indented line where a MISSION, CAPABILITY or USE should start",
                        )
                        .with_help("top-level definitions start in the first column");
                    self.report(d);
                    self.skip_nested();
                }
                // The lexer reported the character; the rest of its line is skipped.
                TokenKind::Unknown => self.recover_line(),
                _ => {
                    let span = self.span();
                    let d = self
                        .error(Code::Syntax, span, format!("expected MISSION, CAPABILITY or USE, found {}", self.peek().describe()))
                        .with_help("statements belong inside a mission: put them under `MISSION Name:`, indented by 4 spaces");
                    self.report(d);
                    self.recover_line();
                }
            }
        }
        file
    }

    fn use_item(&mut self) -> Option<Use> {
        let start = self.bump().span;
        let Some(path) = self.eat(TokenKind::String).map(|t| t.span) else {
            self.expected("a quoted path after USE", Some("write `USE \"other.mission\"`"));
            self.recover_line();
            return None;
        };
        let raw = self.text_of(path);
        let inner = raw
            .strip_prefix('"')
            .map(|r| r.strip_suffix('"').unwrap_or(r))
            .unwrap_or(raw)
            .to_string();
        let span = start.to(path);
        if !self.at_line_end() {
            self.expected("the end of the line after the USE path", None);
        }
        self.skip_line();
        Some(Use { path: inner, path_span: path, span })
    }

    fn mission(&mut self) -> Mission {
        let start = self.bump().span;
        let name = self.ident().unwrap_or_else(|| {
            self.expected("the mission's name", Some("write `MISSION Name:`"));
            Ident { name: String::new(), span: Span::point(self.last_end as usize) }
        });
        let body = if self.header_colon(start, "the MISSION header") {
            self.body("the mission")
        } else {
            self.recover_body()
        };
        Mission { name, body, span: Span::new(start.start as usize, self.last_end as usize) }
    }

    /// After a broken header: the body under it is still read for its own errors.
    pub(super) fn recover_body(&mut self) -> Body {
        let header_end = self.last_end;
        let items =
            if self.at(TokenKind::Indent) { self.indented_items(|p| p.stmt()) } else { Vec::new() };
        Body { items, header_end }
    }

    /// `name (, name)*`, as in `BY a, b` or `WITH p, q`.
    pub(super) fn name_list(&mut self, what: &str) -> Vec<Ident> {
        let mut names = Vec::new();
        loop {
            match self.ident() {
                Some(name) => names.push(name),
                None => {
                    self.expected(what, None);
                    break;
                }
            }
            if self.eat(TokenKind::Comma).is_none() {
                break;
            }
        }
        names
    }

    fn capability(&mut self) -> Option<Capability> {
        let start = self.bump().span;
        let Some(name) = self.ident() else {
            self.expected("the capability's name", Some("write `CAPABILITY Name BY drone:`"));
            self.recover_line();
            return None;
        };
        let mut actors = Vec::new();
        if self.eat_keyword(Keyword::By).is_some() {
            actors = self.name_list("the name of the capability's actor after BY");
        } else {
            let span = self.span();
            let d = self
                .error(
                    Code::Syntax,
                    span,
                    format!(
                        "expected BY and the actor of `{}`, found {}",
                        name.name,
                        self.peek().describe()
                    ),
                )
                .with_help(format!(
                    "a capability names who performs it: `CAPABILITY {} BY drone:`",
                    name.name
                ));
            self.report(d);
        }
        let params = if self.eat_keyword(Keyword::With).is_some() {
            self.name_list("a parameter name after WITH")
        } else {
            Vec::new()
        };
        let mut sections = Vec::new();
        let mut header_end = self.last_end;
        if self.header_colon(start, "the CAPABILITY header") {
            header_end = self.last_end;
            if self.at_line_end() {
                self.eat(TokenKind::Newline);
            } else {
                self.expected("the end of the line", None);
                self.skip_line();
            }
            if self.at(TokenKind::Indent) {
                sections = self.indented_items(|p| p.section());
            } else {
                let d = self
                    .error(
                        Code::ExpectedBlock,
                        Span::point(header_end as usize),
                        format!("capability `{}` has no sections", name.name),
                    )
                    .with_help("add an indented `PERFORM:` section with what the capability does");
                self.report(d);
            }
        } else {
            self.recover_body();
        }
        let span = Span::new(start.start as usize, self.last_end as usize);
        self.check_sections(&name, &sections);
        Some(Capability { name, actors, params, sections, header_end, span })
    }

    fn check_sections(&mut self, name: &Ident, sections: &[Section]) {
        let rank = |s: &Section| match s {
            Section::Requirements { .. } => 0,
            Section::Defaults { .. } => 1,
            Section::Perform { name: None, .. } => 2,
            Section::Perform { .. } => 3,
            Section::Exceptions { .. } => 4,
        };
        let title = |s: &Section| match s {
            Section::Requirements { .. } => "REQUIREMENTS".to_string(),
            Section::Defaults { .. } => "DEFAULTS".to_string(),
            Section::Perform { name: None, .. } => "PERFORM".to_string(),
            Section::Perform { name: Some(n), .. } => format!("PERFORM {}", n.name),
            Section::Exceptions { .. } => "EXCEPTIONS".to_string(),
        };
        let span_of = |s: &Section| match s {
            Section::Requirements { span, .. }
            | Section::Defaults { span, .. }
            | Section::Perform { span, .. }
            | Section::Exceptions { span, .. } => *span,
        };
        let mut highest = 0;
        for (i, section) in sections.iter().enumerate() {
            let header = Span::new(
                span_of(section).start as usize,
                span_of(section).start as usize + title(section).len(),
            );
            if let Some(first) = sections[..i].iter().find(|s| title(s) == title(section)) {
                let d = self
                    .error(
                        Code::MisplacedItem,
                        header,
                        format!("a second {} section in `{}`", title(section), name.name),
                    )
                    .also(self.file, span_of(first), "the first one")
                    .with_help("merge the two sections into one");
                self.report(d);
            } else if rank(section) < highest {
                let d = self
                    .error(Code::MisplacedItem, header, format!("{} comes too late in `{}`", title(section), name.name))
                    .with_help("order the sections REQUIREMENTS, DEFAULTS, PERFORM, named PERFORM sections, EXCEPTIONS");
                self.report(d);
            }
            highest = highest.max(rank(section));
        }
        if !sections.iter().any(|s| matches!(s, Section::Perform { name: None, .. })) {
            let d = self
                .error(
                    Code::MissingPerform,
                    name.span,
                    format!("capability `{}` has no PERFORM section", name.name),
                )
                .with_help("add `PERFORM:` with the statements that start the activity");
            self.report(d);
        }
    }

    fn section(&mut self) -> Option<Section> {
        self.fix_keyword_case();
        let start = self.span();
        match self.peek() {
            TokenKind::Keyword(Keyword::Requirements) => {
                self.bump();
                Some(self.requirements(start))
            }
            TokenKind::Keyword(Keyword::Defaults) => {
                self.bump();
                Some(self.defaults(start))
            }
            TokenKind::Keyword(Keyword::Perform) => {
                self.bump();
                let name = match self.peek() {
                    TokenKind::Ident => self.ident(),
                    TokenKind::Keyword(k @ (Keyword::Abort | Keyword::Pause | Keyword::Resume)) => {
                        let t = self.bump();
                        Some(Ident { name: k.as_str().to_string(), span: t.span })
                    }
                    _ => None,
                };
                let body = if self.header_colon(start, "the PERFORM header") {
                    self.body("PERFORM")
                } else {
                    self.recover_body()
                };
                Some(Section::Perform {
                    name,
                    body,
                    span: Span::new(start.start as usize, self.last_end as usize),
                })
            }
            TokenKind::Keyword(Keyword::Exceptions) => {
                self.bump();
                let mut handlers = Vec::new();
                let mut body_header_end = self.last_end;
                if self.header_colon(start, "the EXCEPTIONS header") {
                    body_header_end = self.last_end;
                    self.skip_line();
                    if self.at(TokenKind::Indent) {
                        handlers = self.indented_items(|p| p.exception_section_item());
                    } else {
                        let d = self.error(Code::ExpectedBlock, Span::point(body_header_end as usize), "EXCEPTIONS has no handlers").with_help(
                            "add indented `ON EXCEPTION Name:` handlers, or leave the section out",
                        );
                        self.report(d);
                    }
                }
                Some(Section::Exceptions {
                    handlers,
                    body_header_end,
                    span: Span::new(start.start as usize, self.last_end as usize),
                })
            }
            _ => {
                let d = self
                    .error(Code::MisplacedItem, start, format!("expected a capability section, found {}", self.peek().describe()))
                    .with_help("a capability holds REQUIREMENTS:, DEFAULTS:, PERFORM: and EXCEPTIONS: sections; put statements under `PERFORM:`");
                self.report(d);
                self.recover_line();
                None
            }
        }
    }

    fn exception_section_item(&mut self) -> Option<ExceptionHandler> {
        if self.at_keyword(Keyword::On) && self.peek_at(1) == TokenKind::Keyword(Keyword::Exception)
        {
            return self.exception_handler();
        }
        let span = self.span();
        let d = self
            .error(
                Code::MisplacedItem,
                span,
                format!("expected `ON EXCEPTION`, found {}", self.peek().describe()),
            )
            .with_help("the EXCEPTIONS section holds only `ON EXCEPTION Name:` handlers");
        self.report(d);
        self.recover_line();
        None
    }

    fn requirements(&mut self, start: Span) -> Section {
        let mut conditions = Vec::new();
        let mut body_header_end = self.last_end;
        if self.header_colon(start, "the REQUIREMENTS header") {
            body_header_end = self.last_end;
            if !self.at_line_end() {
                // `REQUIREMENTS: drone.battery > 25%` on one line.
                conditions.push(self.condition());
            }
            self.skip_line();
            if self.at(TokenKind::Indent) {
                conditions.extend(self.indented_items(|p| {
                    let c = p.condition();
                    if !p.at_line_end() {
                        p.expected(
                            "the end of the condition",
                            Some("write one condition per line; join conditions with AND or OR"),
                        );
                    }
                    p.skip_line();
                    Some(c)
                }));
            } else if conditions.is_empty() {
                let d = self
                    .error(Code::PaperForm, Span::new(start.start as usize, body_header_end as usize), "an empty REQUIREMENTS section")
                    .with_help("leave an empty REQUIREMENTS: out; otherwise put one condition per line below it, indented");
                self.report(d);
            } else {
                let d = self
                    .error(Code::PaperForm, conditions[0].span, "a requirement on the REQUIREMENTS line")
                    .with_help("put each condition on its own line below `REQUIREMENTS:`, indented by 4 spaces");
                self.report(d);
            }
        }
        Section::Requirements {
            conditions,
            body_header_end,
            span: Span::new(start.start as usize, self.last_end as usize),
        }
    }

    fn defaults(&mut self, start: Span) -> Section {
        let mut entries = Vec::new();
        let mut body_header_end = self.last_end;
        if self.header_colon(start, "the DEFAULTS header") {
            body_header_end = self.last_end;
            if !self.at_line_end() {
                // The paper's `DEFAULTS: type:Body`.
                let shown = self
                    .text_of(Span::new(self.span().start as usize, self.line_end_offset()))
                    .trim()
                    .to_string();
                let first = self.span();
                while !self.at_line_end() {
                    if let Some(e) = self.default_entry() {
                        entries.push(e);
                    } else {
                        break;
                    }
                    self.eat(TokenKind::Comma);
                }
                let d = self
                    .error(Code::PaperForm, first, "defaults on the DEFAULTS line")
                    .with_help(format!(
                        "put each default on its own line below `DEFAULTS:`, indented: `{}`",
                        shown.replace(':', ": ").replace(":  ", ": ")
                    ));
                self.report(d);
            }
            self.skip_line();
            if self.at(TokenKind::Indent) {
                entries.extend(self.indented_items(|p| {
                    let e = p.default_entry();
                    if e.is_some() && !p.at_line_end() {
                        p.expected(
                            "the end of the line after the default",
                            Some("write one default per line: `name: value`"),
                        );
                    }
                    p.skip_line();
                    e
                }));
            } else if entries.is_empty() {
                let d = self
                    .error(
                        Code::ExpectedBlock,
                        Span::point(body_header_end as usize),
                        "DEFAULTS has no entries",
                    )
                    .with_help("add indented lines `name: value`, or leave the section out");
                self.report(d);
            }
        }
        Section::Defaults {
            entries,
            body_header_end,
            span: Span::new(start.start as usize, self.last_end as usize),
        }
    }

    pub(super) fn line_end_offset(&self) -> usize {
        let mut i = self.pos;
        while i < self.tokens.len()
            && !matches!(self.tokens[i].kind, TokenKind::Newline | TokenKind::Eof)
        {
            i += 1;
        }
        self.tokens.get(i).map_or(self.text.len(), |t| t.span.start as usize)
    }

    fn default_entry(&mut self) -> Option<DefaultEntry> {
        let Some(name) = self.ident() else {
            self.expected("a parameter name", Some("write a default as `name: value`"));
            return None;
        };
        if self.eat(TokenKind::Colon).is_none() {
            if self.at(TokenKind::Eq) {
                let span = self.span();
                let d = self
                    .error(Code::Syntax, span, "a default is written with `:`")
                    .with_help(format!("write `{}: value`", name.name));
                self.report(d);
                self.bump();
            } else {
                self.expected(
                    &format!("`:` after `{}`", name.name),
                    Some("write a default as `name: value`"),
                );
                return None;
            }
        }
        let value = self.value();
        let span = name.span.to(value.span);
        Some(DefaultEntry { name, value, span })
    }
}
