//! The checker's diagnostics as the protocol's: ranges in UTF-16 columns, the code, the
//! labels as related locations, the help line in the message and in `data` (where a
//! code action finds a "did you mean").

use std::collections::{BTreeMap, HashMap};

use aviary_diagnostics::{Diagnostic, FileId, Severity};
use lsp_types::{
    DiagnosticRelatedInformation, DiagnosticSeverity, Location, NumberOrString, Range, Uri,
};

use crate::analysis::Analysis;
use crate::text::LineIndex;

/// The URI of a file the analysis read: the open document's, or its path's; `None` for
/// the standard library, which is compiled in.
pub fn uri_of(analysis: &Analysis, file: FileId, docs: &crate::overlay::Docs) -> Option<Uri> {
    let name = analysis.sources.name(file);
    match docs.get(name) {
        Some(d) => Some(d.uri.clone()),
        None => crate::uri::of_key(name),
    }
}

/// Ranges in the files of one analysis, each file's line index made once.
pub struct Ranges<'a> {
    analysis: &'a Analysis,
    lines: HashMap<FileId, LineIndex<'a>>,
}

impl<'a> Ranges<'a> {
    pub fn new(analysis: &'a Analysis) -> Ranges<'a> {
        Ranges { analysis, lines: HashMap::new() }
    }
    pub fn range(&mut self, file: FileId, span: aviary_diagnostics::Span) -> Range {
        let analysis = self.analysis;
        self.lines
            .entry(file)
            .or_insert_with(|| LineIndex::new(analysis.sources.text(file)))
            .range(span)
    }
}

pub fn severity(s: Severity) -> DiagnosticSeverity {
    match s {
        Severity::Error => DiagnosticSeverity::ERROR,
        Severity::Warning => DiagnosticSeverity::WARNING,
        Severity::Note => DiagnosticSeverity::INFORMATION,
    }
}

/// One diagnostic, for the file of its primary label.
pub fn to_lsp(
    d: &Diagnostic,
    ranges: &mut Ranges<'_>,
    docs: &crate::overlay::Docs,
) -> lsp_types::Diagnostic {
    let analysis = ranges.analysis;
    let mut related = Vec::new();
    let labels = std::iter::once(&d.primary).filter(|l| !l.message.is_empty()).chain(&d.secondary);
    for label in labels {
        let Some(uri) = uri_of(analysis, label.file, docs) else { continue };
        let range = ranges.range(label.file, label.span);
        related.push(DiagnosticRelatedInformation {
            location: Location { uri, range },
            message: label.message.clone(),
        });
    }
    let mut message = d.message.clone();
    if let Some(help) = &d.help {
        message.push_str("\nhelp: ");
        message.push_str(help);
    }
    lsp_types::Diagnostic {
        range: ranges.range(d.primary.file, d.primary.span),
        severity: Some(severity(d.severity)),
        code: Some(NumberOrString::String(d.code.as_str().to_string())),
        code_description: None,
        source: Some("aviary".into()),
        message,
        related_information: (!related.is_empty()).then_some(related),
        tags: None,
        data: d.help.as_ref().and_then(|help| serde_json::to_value(Help { help }).ok()),
    }
}

/// A diagnostic's `data`: its help, for a client that shows it apart.
#[derive(serde::Serialize)]
struct Help<'a> {
    help: &'a str,
}

/// Every analysis's diagnostics by the URI of their file, each once.
pub fn by_file<'a>(
    analyses: impl Iterator<Item = &'a Analysis>,
    docs: &crate::overlay::Docs,
) -> BTreeMap<String, (Uri, Vec<lsp_types::Diagnostic>)> {
    let mut out: BTreeMap<String, (Uri, Vec<lsp_types::Diagnostic>)> = BTreeMap::new();
    for analysis in analyses {
        let mut ranges = Ranges::new(analysis);
        for d in &analysis.diagnostics {
            let Some(uri) = uri_of(analysis, d.primary.file, docs) else { continue };
            let lsp = to_lsp(d, &mut ranges, docs);
            let entry = out.entry(uri.as_str().to_string()).or_insert_with(|| (uri, Vec::new()));
            if !entry.1.contains(&lsp) {
                entry.1.push(lsp);
            }
        }
    }
    out
}
