//! Go to definition, find references and rename, over the analysis's index: mission
//! files, the files they `USE` (and the other open missions that `USE` them too), and
//! the world file's keys (places, areas, drones) and `group` strings. The standard library can be gone to (its text is written to a file
//! of its own) but not edited.

use lsp_server::ErrorCode;
use lsp_types::{
    DocumentChanges, GotoDefinitionParams, GotoDefinitionResponse, Location, OneOf,
    OptionalVersionedTextDocumentIdentifier, PrepareRenameResponse, ReferenceParams, RenameParams,
    TextDocumentEdit, TextDocumentPositionParams, TextEdit, WorkspaceEdit,
};

use crate::analysis::Analysis;
use crate::diag::Ranges;
use crate::index::{self, Occurrence, Sym};
use crate::text::LineIndex;
use crate::{Failure, Server};

/// The occurrence under the cursor, with its analysis.
fn under<'a>(
    server: &'a Server,
    at: &TextDocumentPositionParams,
) -> Option<(&'a Analysis, &'a Occurrence)> {
    let (_, a, file) = server.lookup(&at.text_document.uri)?;
    let offset = LineIndex::new(a.sources.text(file)).offset(at.position);
    Some((a, index::at(&a.occurrences, file, offset as u32)?))
}

/// `a` and the other open missions' analyses that read a file in which `a` defines
/// `sym` (a library two missions `USE`): a rename or a search covers them all. A local
/// name is its file's alone; nothing is shared through the standard library, which is
/// not edited.
fn sharing<'a>(server: &'a Server, a: &'a Analysis, sym: &Sym) -> Vec<&'a Analysis> {
    let mut out = vec![a];
    if matches!(sym, Sym::Local { .. }) {
        return out;
    }
    let homes: Vec<&str> = a
        .occurrences
        .iter()
        .filter(|o| o.definition && &o.sym == sym)
        .map(|o| a.sources.name(o.file))
        .filter(|name| *name != aviary_check::STD_NAME)
        .collect();
    for b in server.analyses() {
        if !std::ptr::eq(a, b) && homes.iter().any(|name| b.file(name).is_some()) {
            out.push(b);
        }
    }
    out
}

/// The locations of the occurrences of `sym` that `keep` keeps, in every analysis of
/// `sharing`, each once.
fn locations(
    server: &Server,
    analyses: &[&Analysis],
    sym: &Sym,
    keep: impl Fn(&Occurrence) -> bool,
) -> Vec<Location> {
    let mut out: Vec<Location> = Vec::new();
    for a in analyses {
        let mut ranges = Ranges::new(a);
        for o in a.occurrences.iter().filter(|o| &o.sym == sym && keep(o)) {
            let Some(uri) = server.uri_of(a, o.file) else { continue };
            let at = Location { uri, range: ranges.range(o.file, o.span) };
            if !out.contains(&at) {
                out.push(at);
            }
        }
    }
    out
}

pub fn definition(server: &Server, p: GotoDefinitionParams) -> Option<GotoDefinitionResponse> {
    let (a, o) = under(server, &p.text_document_position_params)?;
    let defs = locations(server, &[a], &o.sym, |x| x.definition);
    (!defs.is_empty()).then_some(GotoDefinitionResponse::Array(defs))
}

pub fn references(server: &Server, p: ReferenceParams) -> Option<Vec<Location>> {
    let (a, o) = under(server, &p.text_document_position)?;
    let with_definitions = p.context.include_declaration;
    Some(locations(server, &sharing(server, a, &o.sym), &o.sym, |x| {
        with_definitions || !x.definition
    }))
}

/// Why `sym` cannot be renamed here, if it cannot.
fn refusal(a: &Analysis, sym: &Sym, all: &[&Occurrence]) -> Option<String> {
    let in_std = all.iter().any(|o| a.sources.name(o.file) == aviary_check::STD_NAME);
    let api = aviary_api::Descriptor::standard();
    match sym {
        Sym::Signal(n) if api.signal(n).is_some() => Some(format!("`{n}` is a built-in signal")),
        Sym::Exception(n) if api.is_exception(n) => Some(format!("`{n}` is a built-in exception")),
        _ if in_std => Some(format!(
            "`{}` is defined in the standard library, which cannot be edited",
            sym.name()
        )),
        // A place or area of a file the world imports: its occurrence in the world is the
        // string naming the file, which a rename must not overwrite.
        Sym::Place(n) | Sym::Area(n) => {
            let text = |o: &&&Occurrence| a.sources.text(o.file).get(o.span.range()).unwrap_or("");
            all.iter().find(|o| text(o).trim_matches(['"', '\'']) != n).map(|o| {
                format!(
                    "`{n}` is defined in a file the world imports ({}): rename it there",
                    text(&o)
                )
            })
        }
        _ => None,
    }
}

pub fn prepare_rename(
    server: &Server,
    p: TextDocumentPositionParams,
) -> Option<PrepareRenameResponse> {
    let (a, o) = under(server, &p)?;
    let all: Vec<&Occurrence> = a.occurrences.iter().filter(|x| x.sym == o.sym).collect();
    if refusal(a, &o.sym, &all).is_some() {
        return None;
    }
    Some(PrepareRenameResponse::Range(Ranges::new(a).range(o.file, o.span)))
}

fn is_name(s: &str) -> bool {
    let mut chars = s.chars();
    chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && aviary_syntax::token::Keyword::from_any_case(s).is_none()
}

pub fn rename(server: &Server, p: RenameParams) -> Result<Option<WorkspaceEdit>, Failure> {
    let Some((a, o)) = under(server, &p.text_document_position) else { return Ok(None) };
    let new = p.new_name.trim();
    if !is_name(new) {
        return Err((
            ErrorCode::InvalidParams,
            format!("`{new}` is not a name: letters, digits and `_`, not a keyword"),
        ));
    }
    let all: Vec<&Occurrence> = a.occurrences.iter().filter(|x| x.sym == o.sym).collect();
    if let Some(why) = refusal(a, &o.sym, &all) {
        return Err((ErrorCode::InvalidRequest, why));
    }
    let mut edits: Vec<TextDocumentEdit> = Vec::new();
    for at in locations(server, &sharing(server, a, &o.sym), &o.sym, |_| true) {
        let edit = OneOf::Left(TextEdit { range: at.range, new_text: new.to_string() });
        match edits.iter_mut().find(|e| e.text_document.uri == at.uri) {
            Some(e) => e.edits.push(edit),
            None => {
                let version = server.docs().get(&crate::uri::key(&at.uri)).map(|d| d.version);
                edits.push(TextDocumentEdit {
                    text_document: OptionalVersionedTextDocumentIdentifier { uri: at.uri, version },
                    edits: vec![edit],
                });
            }
        }
    }
    Ok(Some(WorkspaceEdit {
        document_changes: Some(DocumentChanges::Edits(edits)),
        ..WorkspaceEdit::default()
    }))
}
