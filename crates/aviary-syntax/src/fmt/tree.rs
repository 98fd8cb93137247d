//! The items of the tree, each printed as its lines.

use super::expr::{expr_text, names, verbatim, write_args, write_expr};
use super::{Last, Printer};
use crate::ast::*;

impl Printer<'_> {
    pub(super) fn file(&mut self, file: &SourceFile) {
        let mut previous: Option<&Item> = None;
        for item in &file.items {
            if let Some(prev) = previous {
                // Exactly one blank line between top-level items; USE lines may be adjacent.
                self.force_blank = !matches!((prev, item), (Item::Use(_), Item::Use(_)));
            }
            self.item(item);
            previous = Some(item);
        }
    }

    fn item(&mut self, item: &Item) {
        match item {
            Item::Use(u) => {
                let text = format!("USE \"{}\"", u.path);
                self.line(0, &text, Last::Code, u.span.start as usize, u.span.end as usize);
            }
            Item::Mission(m) => {
                let text = format!("MISSION {}:", m.name.name);
                self.line(
                    0,
                    &text,
                    Last::Header,
                    m.span.start as usize,
                    m.body.header_end as usize,
                );
                self.body(&m.body, 1, m.span.start);
            }
            Item::Capability(c) => self.capability(c, 0),
        }
    }

    fn capability(&mut self, c: &Capability, depth: usize) {
        let mut text = format!("CAPABILITY {}", c.name.name);
        if !c.actors.is_empty() {
            text.push_str(" BY ");
            text.push_str(&names(&c.actors));
        }
        if !c.params.is_empty() {
            text.push_str(" WITH ");
            text.push_str(&names(&c.params));
        }
        text.push(':');
        let header_end =
            c.params.last().or(c.actors.last()).map_or(c.name.span.end, |i| i.span.end) as usize;
        self.line(depth, &text, Last::Header, c.span.start as usize, header_end);
        for section in &c.sections {
            self.section(section, depth + 1);
        }
        if let Some(last) = c.sections.last() {
            self.flush_body_end(c.span.start as usize, section_span(last).end as usize, depth + 1);
        }
    }

    fn section(&mut self, section: &Section, depth: usize) {
        match section {
            Section::Requirements { conditions, body_header_end, span } => {
                self.line(
                    depth,
                    "REQUIREMENTS:",
                    Last::Header,
                    span.start as usize,
                    *body_header_end as usize,
                );
                for c in conditions {
                    let text = expr_text(c, self.source);
                    self.line(
                        depth + 1,
                        &text,
                        Last::Code,
                        c.span.start as usize,
                        c.span.end as usize,
                    );
                }
                if let Some(last) = conditions.last() {
                    self.flush_body_end(span.start as usize, last.span.end as usize, depth + 1);
                }
            }
            Section::Defaults { entries, body_header_end, span } => {
                self.line(
                    depth,
                    "DEFAULTS:",
                    Last::Header,
                    span.start as usize,
                    *body_header_end as usize,
                );
                for e in entries {
                    let text = format!("{}: {}", e.name.name, expr_text(&e.value, self.source));
                    self.line(
                        depth + 1,
                        &text,
                        Last::Code,
                        e.span.start as usize,
                        e.span.end as usize,
                    );
                }
                if let Some(last) = entries.last() {
                    self.flush_body_end(span.start as usize, last.span.end as usize, depth + 1);
                }
            }
            Section::Perform { name, body, span } => {
                let text = match name {
                    Some(name) => format!("PERFORM {}:", name.name),
                    None => "PERFORM:".to_string(),
                };
                self.line(
                    depth,
                    &text,
                    Last::Header,
                    span.start as usize,
                    body.header_end as usize,
                );
                self.body(body, depth + 1, span.start);
            }
            Section::Exceptions { handlers, body_header_end, span } => {
                self.line(
                    depth,
                    "EXCEPTIONS:",
                    Last::Header,
                    span.start as usize,
                    *body_header_end as usize,
                );
                for h in handlers {
                    self.exception_handler(h, depth + 1);
                }
                if let Some(last) = handlers.last() {
                    self.flush_body_end(span.start as usize, last.span.end as usize, depth + 1);
                }
            }
        }
    }

    /// The items of a body whose header starts at `header`.
    fn body(&mut self, body: &Body, depth: usize, header: u32) {
        for item in &body.items {
            self.stmt(item, depth);
        }
        if let Some(last) = body.items.last() {
            self.flush_body_end(header as usize, stmt_span(last).end as usize, depth);
        }
    }

    fn stmt(&mut self, stmt: &Stmt, depth: usize) {
        let span = stmt_span(stmt);
        let (start, end) = (span.start as usize, span.end as usize);
        match stmt {
            Stmt::Block(b) => {
                let text = match &b.name {
                    Some(name) => format!("{} {}:", b.kind.as_str(), name.name),
                    None => format!("{}:", b.kind.as_str()),
                };
                self.line(depth, &text, Last::Header, start, b.body.header_end as usize);
                self.body(&b.body, depth + 1, span.start);
            }
            Stmt::Statement(s) => {
                let mut text = String::new();
                for actor in &s.actors {
                    text.push_str(&actor.name);
                    text.push(' ');
                }
                text.push_str(&s.capability.name);
                if let Some(tag) = &s.tag {
                    text.push('-');
                    text.push_str(&tag.name);
                }
                write_args(&mut text, &s.args, self.source);
                self.line(depth, &text, Last::Code, start, end);
            }
            Stmt::Leash(l) => {
                let mut text = format!("{}-{} {}", l.capability.name, l.tag.name, l.action.name);
                write_args(&mut text, &l.args, self.source);
                self.line(depth, &text, Last::Code, start, end);
            }
            Stmt::Api(a) => {
                let mut text = format!("{}.{}(", a.actor.name, a.function.name);
                for (i, arg) in a.args.iter().enumerate() {
                    if i > 0 {
                        text.push_str(", ");
                    }
                    write_expr(&mut text, arg, self.source);
                }
                text.push(')');
                self.line(depth, &text, Last::Code, start, end);
            }
            Stmt::Requirement(r) => {
                let mut text =
                    format!("{} {}", r.kind.as_str(), expr_text(&r.condition, self.source));
                match &r.body {
                    Some(body) => {
                        text.push(':');
                        self.line(depth, &text, Last::Header, start, body.header_end as usize);
                        self.body(body, depth + 1, span.start);
                    }
                    None => self.line(depth, &text, Last::Code, start, end),
                }
            }
            Stmt::For(f) => self.for_block(f, depth),
            Stmt::Any(a) => {
                let mut text = String::from("ANY ");
                if let Some(count) = &a.count {
                    text.push_str(&expr_text(count, self.source));
                    text.push(' ');
                }
                text.push_str(&format!("{} IN {}", a.alias.name, a.group.name));
                if let Some(c) = &a.condition {
                    text.push_str(" WHERE ");
                    text.push_str(&expr_text(c, self.source));
                }
                if let Some(p) = &a.nearest {
                    text.push_str(" NEAREST TO ");
                    text.push_str(&expr_text(p, self.source));
                }
                if let Some(t) = &a.within {
                    text.push_str(" WITHIN ");
                    text.push_str(&expr_text(t, self.source));
                }
                text.push(':');
                self.line(depth, &text, Last::Header, start, a.body.header_end as usize);
                self.body(&a.body, depth + 1, span.start);
            }
            Stmt::Signal(r) => {
                let mut text = format!("SIGNAL {}", r.name.name);
                write_args(&mut text, &r.args, self.source);
                self.line(depth, &text, Last::Code, start, end);
            }
            Stmt::Throw(r) => {
                let mut text = format!("THROW EXCEPTION {}", r.name.name);
                write_args(&mut text, &r.args, self.source);
                self.line(depth, &text, Last::Code, start, end);
            }
            Stmt::Handler(h) => {
                let mut text = String::new();
                if let Some(mode) = h.mode {
                    text.push_str(mode.as_str());
                    text.push(' ');
                }
                text.push_str("ON ");
                if h.every {
                    text.push_str("EVERY ");
                }
                text.push_str(&h.signal.name);
                handler_tail(&mut text, &h.by, &h.bindings, h.one_at_a_time.is_some());
                self.line(depth, &text, Last::Header, start, h.body.header_end as usize);
                self.body(&h.body, depth + 1, span.start);
            }
            Stmt::ExceptionHandler(h) => self.exception_handler(h, depth),
            Stmt::If(chain) => self.if_chain(chain, depth),
            Stmt::OperatorSignals(o) => {
                let text = format!("OPERATOR SIGNAL {}", names(&o.names));
                self.line(depth, &text, Last::Code, start, end);
            }
            Stmt::Let(l) => {
                let text = format!("LET {} = {}", l.name.name, expr_text(&l.value, self.source));
                self.line(depth, &text, Last::Code, start, end);
            }
            Stmt::Allow(a) => {
                let text = format!("ALLOW {} \"{}\"", a.code.name, a.reason);
                self.line(depth, &text, Last::Code, start, end);
            }
            Stmt::StopBlock(s) => {
                let text = format!("{} ABORT", s.block.name);
                self.line(depth, &text, Last::Code, start, end);
            }
            // Only in trees with errors, which are never formatted: the text as written.
            Stmt::Error(span) => {
                let text = verbatim(self.source, span.start as usize, span.end as usize);
                self.line(depth, &text, Last::Code, start, end);
            }
        }
    }

    fn exception_handler(&mut self, h: &ExceptionHandler, depth: usize) {
        let mut text = format!("ON EXCEPTION {}", h.exception.name);
        handler_tail(&mut text, &h.by, &h.bindings, false);
        self.line(depth, &text, Last::Header, h.span.start as usize, h.body.header_end as usize);
        self.body(&h.body, depth + 1, h.span.start);
    }

    fn if_chain(&mut self, chain: &IfChain, depth: usize) {
        let mut previous_end = None;
        for (i, (condition, body)) in chain.branches.iter().enumerate() {
            let keyword = if i == 0 { "IF" } else { "ELSE IF" };
            let text = format!("{keyword} {}:", expr_text(condition, self.source));
            let start = match previous_end {
                // `ELSE IF` starts the first line after the previous branch's body.
                Some(end) => self.next_line_start(end).min(condition.span.start as usize),
                None => chain.span.start as usize,
            };
            self.line(depth, &text, Last::Header, start, body.header_end as usize);
            self.body(body, depth + 1, start as u32);
            previous_end = Some(body_end(body));
        }
        if let Some(body) = &chain.otherwise {
            let start = previous_end.map_or(chain.span.start as usize, |end| {
                self.next_line_start(end).min(body.header_end as usize)
            });
            self.line(depth, "ELSE:", Last::Header, start, body.header_end as usize);
            self.body(body, depth + 1, start as u32);
        }
    }

    fn for_block(&mut self, f: &ForBlock, depth: usize) {
        let mut tail = format!("AS {}", f.alias.name);
        if !f.params.is_empty() {
            tail.push_str(" WITH ");
            tail.push_str(&names(&f.params));
        }
        tail.push(':');
        let start = f.span.start as usize;
        let header_end = f.body.header_end as usize;
        if f.instances.len() <= 1 {
            let mut text = format!("{} FOR ", f.kind.as_str());
            if let Some(instance) = f.instances.first() {
                text.push_str(&self.instance(instance));
                text.push(' ');
            }
            text.push_str(&tail);
            self.line(depth, &text, Last::Header, start, header_end);
        } else {
            let text = format!("{} FOR", f.kind.as_str());
            self.line(depth, &text, Last::Header, start, start);
            self.in_header = true;
            for (i, instance) in f.instances.iter().enumerate() {
                let mut text = self.instance(instance);
                if i + 1 < f.instances.len() {
                    text.push_str(" AND");
                }
                self.line(
                    depth + 1,
                    &text,
                    Last::Header,
                    instance.span.start as usize,
                    instance.span.end as usize,
                );
            }
            self.line(depth + 1, &tail, Last::Header, f.alias.span.start as usize, header_end);
            self.in_header = false;
        }
        self.body(&f.body, depth + 1, f.span.start);
    }

    fn instance(&self, instance: &Instance) -> String {
        let mut text = instance.actor.name.clone();
        if !instance.values.is_empty() {
            text.push_str(" WITH ");
            super::expr::write_list(&mut text, &instance.values, self.source);
        }
        text
    }
}

fn handler_tail(text: &mut String, by: &Option<Ident>, bindings: &[Ident], one_at_a_time: bool) {
    if let Some(by) = by {
        text.push_str(" BY ");
        text.push_str(&by.name);
    }
    if !bindings.is_empty() {
        text.push_str(" WITH ");
        text.push_str(&names(bindings));
    }
    if one_at_a_time {
        text.push_str(" ONE AT A TIME");
    }
    text.push(':');
}

fn body_end(body: &Body) -> usize {
    body.items.last().map_or(body.header_end, |s| stmt_span(s).end) as usize
}

fn section_span(section: &Section) -> aviary_diagnostics::Span {
    match section {
        Section::Requirements { span, .. }
        | Section::Defaults { span, .. }
        | Section::Perform { span, .. }
        | Section::Exceptions { span, .. } => *span,
    }
}

pub(super) fn stmt_span(stmt: &Stmt) -> aviary_diagnostics::Span {
    stmt.span()
}
