//! Text rendering goes through codespan-reporting (the renderer gleam uses); the first
//! line is ours so that it reads `path:line:col: error[CODE]: message`, the form
//! docs/DIAGNOSTICS.md describes and editors jump to.

use codespan_reporting::diagnostic as cs;
use codespan_reporting::term::{self, termcolor};

use crate::source::clamp_to_char;
use crate::{Diagnostic, Label, Severity, SourceMap, Span};

pub fn render_text(sources: &SourceMap, diagnostic: &Diagnostic, color: bool) -> String {
    let at = sources.line_col(diagnostic.primary.file, diagnostic.primary.span.start);
    let mut out = format!(
        "{}:{}:{}: {}[{}]: {}\n",
        sources.name(diagnostic.primary.file),
        at.line,
        at.column,
        diagnostic.severity.as_str(),
        diagnostic.code,
        diagnostic.message
    );
    let severity = match diagnostic.severity {
        Severity::Error => cs::Severity::Error,
        Severity::Warning => cs::Severity::Warning,
        Severity::Note => cs::Severity::Note,
    };
    let label = |style, l: &Label| {
        cs::Label::new(style, l.file.0 as usize, visible(sources.text(l.file), l.span))
            .with_message(l.message.clone())
    };
    let mut labels = vec![label(cs::LabelStyle::Primary, &diagnostic.primary)];
    labels.extend(diagnostic.secondary.iter().map(|l| label(cs::LabelStyle::Secondary, l)));
    let rich = cs::Diagnostic::new(severity)
        .with_message(&diagnostic.message)
        .with_code(diagnostic.code.as_str())
        .with_labels(labels)
        .with_notes(diagnostic.help.iter().map(|h| format!("help: {h}")).collect());
    let config = term::Config { chars: term::Chars::ascii(), ..term::Config::default() };
    let mut buffer = if color { termcolor::Buffer::ansi() } else { termcolor::Buffer::no_color() };
    if term::emit_to_write_style(&mut buffer, &config, sources.files(), &rich).is_ok() {
        let body = String::from_utf8_lossy(buffer.as_slice());
        // Our first line replaces codespan's own title line.
        out.extend(body.split_inclusive('\n').skip(1));
    }
    out
}

/// A caret needs at least one character under it; an empty span at the end stays empty.
fn visible(text: &str, span: Span) -> std::ops::Range<usize> {
    let start = clamp_to_char(text, span.start as usize);
    let mut end = clamp_to_char(text, span.end as usize).max(start);
    if end == start {
        if let Some(c) = text[start..].chars().next() {
            if c != '\n' {
                end = start + c.len_utf8();
            }
        }
    }
    start..end
}

/// A diagnostic as JSON (`aviary check --json`, the station's check): where, with
/// 1-based lines and columns, what and why.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct JsonDiagnostic {
    pub file: String,
    pub line: usize,
    pub column: usize,
    pub end_line: usize,
    pub end_column: usize,
    /// `error`, `warning` or `note`.
    pub severity: &'static str,
    pub code: &'static str,
    pub message: String,
    /// What the caret under the primary span says.
    pub label: String,
    pub help: Option<String>,
    /// The secondary labels, each where it points.
    pub related: Vec<JsonLabel>,
}

/// A label of a diagnostic, where it points.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct JsonLabel {
    pub file: String,
    pub line: usize,
    pub column: usize,
    pub end_line: usize,
    pub end_column: usize,
    pub message: String,
}

/// One JSON object per diagnostic, with 1-based lines and columns.
pub fn render_json(sources: &SourceMap, diagnostic: &Diagnostic) -> JsonDiagnostic {
    let place = |l: &Label| {
        let start = sources.line_col(l.file, l.span.start);
        let end = sources.line_col(l.file, l.span.end);
        JsonLabel {
            file: sources.name(l.file).to_string(),
            line: start.line,
            column: start.column,
            end_line: end.line,
            end_column: end.column,
            message: l.message.clone(),
        }
    };
    let primary = place(&diagnostic.primary);
    JsonDiagnostic {
        file: primary.file,
        line: primary.line,
        column: primary.column,
        end_line: primary.end_line,
        end_column: primary.end_column,
        severity: diagnostic.severity.as_str(),
        code: diagnostic.code.as_str(),
        message: diagnostic.message.clone(),
        label: primary.message,
        help: diagnostic.help.clone(),
        related: diagnostic.secondary.iter().map(place).collect(),
    }
}

impl std::fmt::Display for JsonDiagnostic {
    /// As one line of JSON.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&serde_json::to_string(self).map_err(|_| std::fmt::Error)?)
    }
}

/// `2 errors, 1 warning` (empty when there is nothing to count).
pub fn summary_line(diagnostics: &[Diagnostic]) -> String {
    let count = |s| diagnostics.iter().filter(|d| d.severity == s).count();
    let plural = |n: usize, word: &str| format!("{n} {word}{}", if n == 1 { "" } else { "s" });
    let mut parts = Vec::new();
    for (severity, word) in
        [(Severity::Error, "error"), (Severity::Warning, "warning"), (Severity::Note, "note")]
    {
        let n = count(severity);
        if n > 0 {
            parts.push(plural(n, word));
        }
    }
    parts.join(", ")
}
