//! Go to definition, find references and rename, over the analysis's index: mission
//! files, the files they `USE`, and the world file's keys (places, areas, drones). The
//! standard library is compiled in and has no file to go to or edit.

use lsp_server::ErrorCode;
use lsp_types::{
    DocumentChanges, GotoDefinitionParams, GotoDefinitionResponse, Location, OneOf,
    OptionalVersionedTextDocumentIdentifier, PrepareRenameResponse, ReferenceParams, RenameParams,
    TextDocumentEdit, TextDocumentPositionParams, TextEdit, WorkspaceEdit,
};

use crate::analysis::Analysis;
use crate::diag::{uri_of, Ranges};
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

fn locations<'a>(
    server: &Server,
    a: &Analysis,
    of: impl Iterator<Item = &'a Occurrence>,
) -> Vec<Location> {
    let mut ranges = Ranges::new(a);
    of.filter_map(|o| {
        Some(Location {
            uri: uri_of(a, o.file, server.docs())?,
            range: ranges.range(o.file, o.span),
        })
    })
    .collect()
}

pub fn definition(server: &Server, p: GotoDefinitionParams) -> Option<GotoDefinitionResponse> {
    let (a, o) = under(server, &p.text_document_position_params)?;
    let defs =
        locations(server, a, a.occurrences.iter().filter(|x| x.definition && x.sym == o.sym));
    (!defs.is_empty()).then_some(GotoDefinitionResponse::Array(defs))
}

pub fn references(server: &Server, p: ReferenceParams) -> Option<Vec<Location>> {
    let (a, o) = under(server, &p.text_document_position)?;
    let with_definitions = p.context.include_declaration;
    Some(locations(
        server,
        a,
        a.occurrences.iter().filter(|x| x.sym == o.sym && (with_definitions || !x.definition)),
    ))
}

/// Why `sym` cannot be renamed here, if it cannot.
fn refusal(a: &Analysis, sym: &Sym, all: &[&Occurrence]) -> Option<String> {
    let in_std = all.iter().any(|o| a.sources.name(o.file) == aviary_check::STD_NAME);
    let api = aviary_api::Descriptor::standard();
    match sym {
        Sym::Group(_) => Some(
            "a group is named by each drone's `group` key in the world file: rename it there"
                .into(),
        ),
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
    let mut ranges = Ranges::new(a);
    let mut edits: Vec<TextDocumentEdit> = Vec::new();
    for x in all {
        let Some(uri) = uri_of(a, x.file, server.docs()) else { continue };
        let edit = OneOf::Left(TextEdit {
            range: ranges.range(x.file, x.span),
            new_text: new.to_string(),
        });
        match edits.iter_mut().find(|e| e.text_document.uri == uri) {
            Some(e) => {
                if !e.edits.contains(&edit) {
                    e.edits.push(edit);
                }
            }
            None => {
                let version = server.docs().get(&crate::uri::key(&uri)).map(|d| d.version);
                edits.push(TextDocumentEdit {
                    text_document: OptionalVersionedTextDocumentIdentifier { uri, version },
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
