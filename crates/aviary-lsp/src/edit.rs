//! Formatting (`aviary fmt`'s `aviary_syntax::format`), document symbols, folding ranges
//! and the code actions of every "did you mean".

// Each statement is named in the outline and the folding ranges: a new one is a compile
// error here, not one left out of both.
#![deny(clippy::wildcard_enum_match_arm)]

use aviary_diagnostics::{FileId, Span};
use aviary_syntax::ast::{Body, Item, Section, Stmt};
use lsp_types::{
    CodeAction, CodeActionKind, CodeActionOrCommand, CodeActionParams, DocumentFormattingParams,
    DocumentSymbol, DocumentSymbolParams, DocumentSymbolResponse, FoldingRange, FoldingRangeParams,
    SymbolKind, TextEdit, WorkspaceEdit,
};

use crate::analysis::Analysis;
use crate::diag::{uri_of, Ranges};
use crate::text::LineIndex;
use crate::Server;

/// The whole document in the canonical layout, as one edit; nothing for a file with
/// syntax errors (which `aviary fmt` never rewrites either) or already formatted.
pub fn format(server: &Server, p: DocumentFormattingParams) -> Option<Vec<TextEdit>> {
    let key = crate::uri::key(&p.text_document.uri);
    if crate::analysis::is_world(&key) {
        return None;
    }
    let doc = server.docs().get(&key)?;
    let parse = aviary_syntax::parse(FileId(0), &doc.text);
    if parse.has_errors() {
        return None;
    }
    let formatted = aviary_syntax::format(&parse.tree, &doc.text, &parse.line_starts);
    if formatted == doc.text {
        return Some(Vec::new());
    }
    let lines = LineIndex::new(&doc.text);
    let range = lines.range(Span::new(0, doc.text.len()));
    Some(vec![TextEdit { range, new_text: formatted }])
}

#[allow(deprecated)] // `DocumentSymbol::deprecated`, which the type still has.
fn symbol(
    name: String,
    detail: Option<String>,
    kind: SymbolKind,
    range: lsp_types::Range,
    selection: lsp_types::Range,
    children: Vec<DocumentSymbol>,
) -> DocumentSymbol {
    DocumentSymbol {
        name,
        detail,
        kind,
        tags: None,
        deprecated: None,
        range,
        selection_range: selection,
        children: (!children.is_empty()).then_some(children),
    }
}

pub fn symbols(server: &Server, p: DocumentSymbolParams) -> Option<DocumentSymbolResponse> {
    let (_, a, file) = server.lookup(&p.text_document.uri)?;
    let mut ranges = Ranges::new(a);
    let mut out = Vec::new();
    if a.world_file == Some(file) {
        let w = a.world.as_ref()?;
        let mut add = |name: &str, span: Span, kind: SymbolKind, detail: &str| {
            let r = ranges.range(file, span);
            out.push(symbol(name.to_string(), Some(detail.to_string()), kind, r, r, Vec::new()));
        };
        w.places.iter().for_each(|x| add(&x.name, x.span, SymbolKind::CONSTANT, "place"));
        w.areas.iter().for_each(|x| add(&x.name, x.span, SymbolKind::STRUCT, "area"));
        w.drones.iter().for_each(|x| add(&x.name, x.span, SymbolKind::OBJECT, "drone"));
        return Some(DocumentSymbolResponse::Nested(out));
    }
    let tree = a.tree(file)?;
    for item in &tree.items {
        match item {
            Item::Use(u) => {
                let r = ranges.range(file, u.span);
                out.push(symbol(
                    u.path.clone(),
                    Some("USE".into()),
                    SymbolKind::FILE,
                    r,
                    r,
                    Vec::new(),
                ));
            }
            Item::Mission(m) => {
                let children = body_symbols(&m.body, file, &mut ranges);
                out.push(symbol(
                    m.name.name.clone(),
                    Some("MISSION".into()),
                    SymbolKind::MODULE,
                    ranges.range(file, m.span),
                    ranges.range(file, m.name.span),
                    children,
                ));
            }
            Item::Capability(c) => {
                let mut children = Vec::new();
                for s in &c.sections {
                    if let Section::Perform { body, .. } = s {
                        children.extend(body_symbols(body, file, &mut ranges));
                    }
                }
                let params: Vec<&str> = c.params.iter().map(|p| p.name.as_str()).collect();
                let detail = if params.is_empty() {
                    "CAPABILITY".to_string()
                } else {
                    format!("CAPABILITY WITH {}", params.join(", "))
                };
                out.push(symbol(
                    c.name.name.clone(),
                    Some(detail),
                    SymbolKind::FUNCTION,
                    ranges.range(file, c.span),
                    ranges.range(file, c.name.span),
                    children,
                ));
            }
        }
    }
    Some(DocumentSymbolResponse::Nested(out))
}

/// Named blocks and handlers, nested as they are.
fn body_symbols(body: &Body, file: FileId, ranges: &mut Ranges<'_>) -> Vec<DocumentSymbol> {
    let mut out = Vec::new();
    for s in &body.items {
        let mut inner = Vec::new();
        s.for_each_body(|b| inner.extend(body_symbols(b, file, ranges)));
        let named = match s {
            Stmt::Block(b) => b.name.as_ref().map(|n| {
                (n.name.clone(), b.kind.as_str().to_string(), SymbolKind::NAMESPACE, b.span, n.span)
            }),
            Stmt::Handler(h) => Some((
                format!("ON {}", h.signal.name),
                "handler".to_string(),
                SymbolKind::EVENT,
                h.span,
                h.signal.span,
            )),
            Stmt::ExceptionHandler(h) => Some((
                format!("ON EXCEPTION {}", h.exception.name),
                "exception handler".to_string(),
                SymbolKind::EVENT,
                h.span,
                h.exception.span,
            )),
            Stmt::For(f) => Some((
                format!("FOR … AS {}", f.alias.name),
                f.kind.as_str().to_string(),
                SymbolKind::NAMESPACE,
                f.span,
                f.alias.span,
            )),
            Stmt::Statement(_)
            | Stmt::Leash(_)
            | Stmt::Api(_)
            | Stmt::Requirement(_)
            | Stmt::Signal(_)
            | Stmt::Throw(_)
            | Stmt::If(_)
            | Stmt::OperatorSignals(_)
            | Stmt::Any(_)
            | Stmt::Let(_)
            | Stmt::Allow(_)
            | Stmt::StopBlock(_)
            | Stmt::Error(_) => None,
        };
        match named {
            Some((name, detail, kind, span, sel)) => {
                let (r, sr) = (ranges.range(file, span), ranges.range(file, sel));
                out.push(symbol(name, Some(detail), kind, r, sr, inner));
            }
            None => out.extend(inner),
        }
    }
    out
}

pub fn folding(server: &Server, p: FoldingRangeParams) -> Option<Vec<FoldingRange>> {
    let (_, a, file) = server.lookup(&p.text_document.uri)?;
    let tree = a.tree(file)?;
    let lines = LineIndex::new(a.sources.text(file));
    let mut spans = Vec::new();
    for item in &tree.items {
        match item {
            Item::Use(_) => {}
            Item::Mission(m) => {
                spans.push(m.span);
                body_spans(&m.body, &mut spans);
            }
            Item::Capability(c) => {
                spans.push(c.span);
                for s in &c.sections {
                    match s {
                        Section::Perform { body, span, .. } => {
                            spans.push(*span);
                            body_spans(body, &mut spans);
                        }
                        Section::Requirements { span, .. } | Section::Defaults { span, .. } => {
                            spans.push(*span)
                        }
                        Section::Exceptions { handlers, span, .. } => {
                            spans.push(*span);
                            for h in handlers {
                                spans.push(h.span);
                                body_spans(&h.body, &mut spans);
                            }
                        }
                    }
                }
            }
        }
    }
    let mut out: Vec<FoldingRange> = Vec::new();
    for span in spans {
        let (start, end) =
            (lines.position(span.start as usize).line, lines.position(span.end as usize).line);
        // A span that ends after its last line's newline ends on the line before.
        let end =
            if a.sources.text(file).get(..span.end as usize).is_some_and(|t| t.ends_with('\n')) {
                end.saturating_sub(1)
            } else {
                end
            };
        if end > start && !out.iter().any(|f| f.start_line == start && f.end_line == end) {
            out.push(FoldingRange { start_line: start, end_line: end, ..FoldingRange::default() });
        }
    }
    Some(out)
}

/// The spans of the statements in `body` that fold, nested ones included, outer first.
fn body_spans(body: &Body, out: &mut Vec<Span>) {
    aviary_syntax::visit::for_each_stmt(body, |s| {
        let span = match s {
            Stmt::Block(b) => Some(b.span),
            Stmt::For(f) => Some(f.span),
            Stmt::Handler(h) => Some(h.span),
            Stmt::ExceptionHandler(h) => Some(h.span),
            Stmt::If(i) => Some(i.span),
            Stmt::Requirement(r) => r.body.as_ref().map(|_| r.span),
            Stmt::Any(a) => Some(a.span),
            Stmt::Statement(_)
            | Stmt::Leash(_)
            | Stmt::Api(_)
            | Stmt::Signal(_)
            | Stmt::Throw(_)
            | Stmt::OperatorSignals(_)
            | Stmt::Let(_)
            | Stmt::Allow(_)
            | Stmt::StopBlock(_)
            | Stmt::Error(_) => None,
        };
        out.extend(span);
    });
}

/// The name a "did you mean `X`?" help offers.
pub fn suggestion(help: &str) -> Option<&str> {
    let rest = &help[help.find("did you mean `")? + "did you mean `".len()..];
    Some(&rest[..rest.find("`?")?])
}

/// A quick fix for each diagnostic in the range whose help offers a name: the name at
/// fault replaced by the one offered.
pub fn code_actions(server: &Server, p: CodeActionParams) -> Option<Vec<CodeActionOrCommand>> {
    let (_, a, file) = server.lookup(&p.text_document.uri)?;
    let lines = LineIndex::new(a.sources.text(file));
    let (from, to) = (lines.offset(p.range.start) as u32, lines.offset(p.range.end) as u32);
    let mut out = Vec::new();
    let mut ranges = Ranges::new(a);
    for d in &a.diagnostics {
        let span = d.primary.span;
        if d.primary.file != file || span.end < from || span.start > to {
            continue;
        }
        let Some(name) = d.help.as_deref().and_then(suggestion) else { continue };
        let Some(edit) = replacement(a, file, span, name, &mut ranges) else { continue };
        let uri = uri_of(a, file, server.docs())?;
        let mut ranges_d = Ranges::new(a);
        let diagnostic = crate::diag::to_lsp(d, &mut ranges_d, server.docs());
        out.push(CodeActionOrCommand::CodeAction(CodeAction {
            title: format!(
                "Replace `{}` with `{name}`",
                a.sources.text(file).get(span.range()).unwrap_or("")
            ),
            kind: Some(CodeActionKind::QUICKFIX),
            diagnostics: Some(vec![diagnostic]),
            edit: Some(WorkspaceEdit {
                changes: Some([(uri, vec![edit])].into_iter().collect()),
                ..WorkspaceEdit::default()
            }),
            is_preferred: Some(true),
            ..CodeAction::default()
        }));
    }
    Some(out)
}

/// The edit that puts `name` in place of the name at `span`, which is one word: a name,
/// or a tagged activity (`FlyCircle-C1`, whose span and suggestion both hold the tag).
fn replacement(
    a: &Analysis,
    file: FileId,
    span: Span,
    name: &str,
    ranges: &mut Ranges<'_>,
) -> Option<TextEdit> {
    let written = a.sources.text(file).get(span.range())?;
    if written.is_empty() || written.contains(char::is_whitespace) {
        return None;
    }
    Some(TextEdit { range: ranges.range(file, span), new_text: name.to_string() })
}
