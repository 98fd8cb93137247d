//! Completion by context, read from the text of the line before the cursor (a line being
//! typed rarely parses): actors, groups, tags and statement keywords at the start of a
//! statement; capabilities after actors; parameter names, places and areas after `WITH`;
//! places and areas after `name=`; signals after `ON`, `SIGNAL`, `RECEIVED(`; exceptions
//! after `ON EXCEPTION`; telemetry, attributes and middle-layer functions after `drone.`.

use aviary_syntax::ast::Item;
use aviary_syntax::token::Keyword;
use lsp_types::{
    CompletionItem, CompletionItemKind, CompletionParams, CompletionResponse, Documentation,
    MarkupContent, MarkupKind,
};

use crate::analysis::Analysis;
use crate::hover::{capability, describe};
use crate::index::Sym;
use crate::text::line_before;
use crate::Server;

/// Keywords that start a statement.
const STATEMENT_KEYWORDS: &[Keyword] = &[
    Keyword::Sequential,
    Keyword::Parallel,
    Keyword::On,
    Keyword::Signal,
    Keyword::Throw,
    Keyword::StartIf,
    Keyword::WaitFor,
    Keyword::DoWhile,
    Keyword::If,
    Keyword::Else,
];

fn is_word(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

fn item(
    label: &str,
    kind: CompletionItemKind,
    detail: &str,
    doc: Option<String>,
) -> CompletionItem {
    CompletionItem {
        label: label.to_string(),
        kind: Some(kind),
        detail: Some(detail.to_string()),
        documentation: doc.map(|value| {
            Documentation::MarkupContent(MarkupContent { kind: MarkupKind::Markdown, value })
        }),
        ..CompletionItem::default()
    }
}

pub fn complete(server: &Server, p: CompletionParams) -> Option<CompletionResponse> {
    let at = p.text_document_position;
    let (_, a, file) = server.lookup(&at.text_document.uri)?;
    let text = a.sources.text(file);
    let (offset, before) = line_before(text, at.position);
    let head = before.trim_end_matches(is_word);
    let words: Vec<&str> =
        head.split(|c: char| c.is_whitespace() || c == ',').filter(|w| !w.is_empty()).collect();
    let last = words.last().copied().unwrap_or("");
    let mut items = Vec::new();
    let in_capability = enclosing_capability(a, file, offset as u32);
    if let Some(path) = head.strip_suffix('.') {
        let actor = path.rsplit(|c: char| !is_word(c)).next().unwrap_or("");
        if !actor.is_empty() {
            telemetry(a, &mut items);
        }
    } else if head.trim_end().ends_with("RECEIVED(") {
        signals(a, &mut items);
    } else if last == "ON" || last == "EVERY" || (words.first() == Some(&"OPERATOR")) {
        signals(a, &mut items);
        if last == "ON" {
            items.push(item("EVERY", CompletionItemKind::KEYWORD, "keyword", None));
            items.push(item("EXCEPTION", CompletionItemKind::KEYWORD, "keyword", None));
        }
    } else if words.first() == Some(&"ANY") {
        any_header(a, &words, &mut items);
    } else if last == "SIGNAL" && words.len() == 1 {
        signals(a, &mut items);
    } else if last == "EXCEPTION" {
        exceptions(a, &mut items);
    } else if last == "BY" {
        actors(a, in_capability, &mut items);
    } else if head.trim_end().ends_with('=') || (words.contains(&"WITH") && is_statement(a, &words))
    {
        if !head.trim_end().ends_with('=') {
            let cap = words
                .iter()
                .position(|w| *w == "WITH")
                .and_then(|i| i.checked_sub(1))
                .map(|i| words[i]);
            let cap = cap.map(|c| c.split('-').next().unwrap_or(c)).unwrap_or("");
            params(a, cap, &mut items);
        }
        positions(a, &mut items);
    } else if words.is_empty() {
        actors(a, in_capability, &mut items);
        tags(a, &mut items);
        for k in STATEMENT_KEYWORDS {
            items.push(item(k.as_str(), CompletionItemKind::KEYWORD, "keyword", None));
        }
        if in_capability.is_none() {
            items.push(item("OPERATOR SIGNAL", CompletionItemKind::KEYWORD, "keyword", None));
        }
        items.push(item(
            "ANY",
            CompletionItemKind::KEYWORD,
            "ANY d IN group WHERE condition NEAREST TO place WITHIN time:",
            Some("a drone of a group chosen in flight, held while the body runs".into()),
        ));
        if head.is_empty() {
            for k in [Keyword::Mission, Keyword::Capability, Keyword::Use] {
                items.push(item(k.as_str(), CompletionItemKind::KEYWORD, "keyword", None));
            }
        }
    } else if words.len() == 1 && words[0].contains('-') {
        leash_actions(a, words[0], &mut items);
    } else if is_statement(a, &words) && !words.iter().any(|w| Keyword::from_exact(w).is_some()) {
        capabilities(a, &mut items);
    } else {
        for k in Keyword::ALL {
            items.push(item(k.as_str(), CompletionItemKind::KEYWORD, "keyword", None));
        }
        positions(a, &mut items);
    }
    Some(CompletionResponse::Array(items))
}

/// In an `ANY` header: the groups after `IN`, positions after `NEAREST TO`, and the
/// clauses not written yet.
fn any_header(a: &Analysis, words: &[&str], out: &mut Vec<CompletionItem>) {
    match words.last().copied().unwrap_or("") {
        "IN" => {
            for g in a.world.iter().flat_map(|w| &w.groups) {
                let doc = Some(describe(a, &Sym::Group(g.name.clone())));
                out.push(item(&g.name, CompletionItemKind::MODULE, "group", doc));
            }
        }
        "TO" => positions(a, out),
        _ if words.contains(&"IN") => {
            for clause in ["WHERE", "NEAREST TO", "WITHIN"] {
                let first = clause.split(' ').next().unwrap_or(clause);
                if !words.contains(&first) {
                    out.push(item(clause, CompletionItemKind::KEYWORD, "keyword", None));
                }
            }
        }
        _ => {}
    }
}

/// The capability the cursor is in: the last item that starts before it, if a capability
/// (the blank lines after an item belong to it while the next is typed).
fn enclosing_capability(
    a: &Analysis,
    file: aviary_diagnostics::FileId,
    offset: u32,
) -> Option<&aviary_syntax::ast::Capability> {
    let last = a.tree(file)?.items.iter().rfind(|i| item_start(i) < offset)?;
    match last {
        Item::Capability(c) => Some(c),
        _ => None,
    }
}

fn item_start(i: &Item) -> u32 {
    match i {
        Item::Use(u) => u.span.start,
        Item::Capability(c) => c.span.start,
        Item::Mission(m) => m.span.start,
    }
}

/// Whether the first words are actors: a drone, a group, or a name not a keyword.
fn is_statement(a: &Analysis, words: &[&str]) -> bool {
    let Some(first) = words.first() else { return false };
    Keyword::from_exact(first).is_none()
        && (a.world.as_ref().is_none_or(|w| {
            w.drones.iter().any(|d| d.name == *first) || w.groups.iter().any(|g| g.name == *first)
        }) || first.chars().next().is_some_and(|c| c.is_ascii_lowercase()))
}

fn actors(
    a: &Analysis,
    cap: Option<&aviary_syntax::ast::Capability>,
    out: &mut Vec<CompletionItem>,
) {
    if let Some(w) = &a.world {
        for d in &w.drones {
            out.push(item(
                &d.name,
                CompletionItemKind::VARIABLE,
                "drone",
                Some(describe(a, &Sym::Drone(d.name.clone()))),
            ));
        }
        for g in &w.groups {
            out.push(item(
                &g.name,
                CompletionItemKind::MODULE,
                "group",
                Some(describe(a, &Sym::Group(g.name.clone()))),
            ));
        }
    }
    if let Some(c) = cap {
        for actor in &c.actors {
            out.push(item(
                &actor.name,
                CompletionItemKind::VARIABLE,
                &format!("actor of {}", c.name.name),
                None,
            ));
        }
    }
}

fn capabilities(a: &Analysis, out: &mut Vec<CompletionItem>) {
    let Some(p) = &a.program else { return };
    for name in p.capability_names() {
        if let Some(c) = p.capability(name) {
            out.push(item(
                name,
                CompletionItemKind::FUNCTION,
                "capability",
                Some(capability(a, c)),
            ));
        }
    }
}

fn params(a: &Analysis, cap: &str, out: &mut Vec<CompletionItem>) {
    let Some(c) = a.program.as_ref().and_then(|p| p.capability(cap)) else { return };
    for x in &c.params {
        let sym = Sym::Param { capability: cap.to_string(), name: x.name.clone() };
        let mut it = item(
            &format!("{}=", x.name),
            CompletionItemKind::FIELD,
            &format!("parameter of {cap}"),
            Some(describe(a, &sym)),
        );
        it.insert_text = Some(format!("{}=", x.name));
        out.push(it);
    }
}

fn positions(a: &Analysis, out: &mut Vec<CompletionItem>) {
    let Some(w) = &a.world else { return };
    for x in &w.places {
        out.push(item(
            &x.name,
            CompletionItemKind::CONSTANT,
            "place",
            Some(describe(a, &Sym::Place(x.name.clone()))),
        ));
    }
    for x in &w.areas {
        out.push(item(
            &x.name,
            CompletionItemKind::STRUCT,
            "area",
            Some(describe(a, &Sym::Area(x.name.clone()))),
        ));
    }
}

fn signals(a: &Analysis, out: &mut Vec<CompletionItem>) {
    let mut names: Vec<&str> = a
        .occurrences
        .iter()
        .filter_map(|o| match &o.sym {
            Sym::Signal(n) => Some(n.as_str()),
            _ => None,
        })
        .collect();
    let api = aviary_api::Descriptor::standard();
    let builtin: Vec<&'static str> = api.signals.iter().map(|s| s.name()).collect();
    names.extend(builtin.iter().copied());
    names.sort_unstable();
    names.dedup();
    for n in names {
        out.push(item(
            n,
            CompletionItemKind::EVENT,
            "signal",
            Some(describe(a, &Sym::Signal(n.to_string()))),
        ));
    }
}

fn exceptions(a: &Analysis, out: &mut Vec<CompletionItem>) {
    let api = aviary_api::Descriptor::standard();
    let mut names: Vec<String> = api.exceptions.iter().map(|e| e.name().to_string()).collect();
    names.extend(a.occurrences.iter().filter_map(|o| match &o.sym {
        Sym::Exception(n) => Some(n.clone()),
        _ => None,
    }));
    names.sort_unstable();
    names.dedup();
    for n in names {
        out.push(item(&n, CompletionItemKind::EVENT, "exception", None));
    }
}

fn tags(a: &Analysis, out: &mut Vec<CompletionItem>) {
    let mut names: Vec<&str> = a
        .occurrences
        .iter()
        .filter_map(|o| match &o.sym {
            Sym::Tag(n) if o.definition => Some(n.as_str()),
            _ => None,
        })
        .collect();
    names.sort_unstable();
    names.dedup();
    for n in names {
        out.push(item(
            n,
            CompletionItemKind::REFERENCE,
            "activity tag (leash: PAUSE, RESUME, ABORT)",
            None,
        ));
    }
}

fn telemetry(a: &Analysis, out: &mut Vec<CompletionItem>) {
    let api = aviary_api::Descriptor::standard();
    for (name, kind) in &api.telemetry {
        out.push(item(
            name,
            CompletionItemKind::FIELD,
            "telemetry",
            Some(kind.describe().to_string()),
        ));
    }
    if let Some(w) = &a.world {
        let mut attrs: Vec<&str> =
            w.drones.iter().flat_map(|d| d.attributes.iter().map(|(k, _)| &**k)).collect();
        attrs.sort_unstable();
        attrs.dedup();
        for n in attrs {
            out.push(item(n, CompletionItemKind::PROPERTY, "attribute (world file)", None));
        }
    }
    for f in &api.functions {
        let mut it =
            item(f.name(), CompletionItemKind::METHOD, &f.signature(), Some(f.summary.to_string()));
        it.insert_text = Some(format!("{}(", f.name()));
        out.push(it);
    }
}

/// After a tagged activity at the start of a statement (`FlyCircle-C1 `): what a leash
/// may do to it, `PAUSE`, `RESUME`, `ABORT` and the capability's named `PERFORM`
/// sections.
fn leash_actions(a: &Analysis, tagged: &str, out: &mut Vec<CompletionItem>) {
    for k in [Keyword::Pause, Keyword::Resume, Keyword::Abort] {
        out.push(item(k.as_str(), CompletionItemKind::KEYWORD, "leash action", None));
    }
    let capability = tagged.split('-').next().unwrap_or(tagged);
    let Some(c) = a.program.as_ref().and_then(|p| p.capability(capability)) else { return };
    for s in &c.sections {
        if let aviary_syntax::ast::Section::Perform { name: Some(n), .. } = s {
            if Keyword::from_exact(&n.name).is_none() {
                out.push(item(
                    &n.name,
                    CompletionItemKind::METHOD,
                    &format!("PERFORM {} of {capability}", n.name),
                    None,
                ));
            }
        }
    }
}
