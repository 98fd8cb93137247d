//! Signature help (a capability's `WITH` parameters in a statement, a middle-layer
//! function's in `drone.Function(`) and semantic tokens (every name the index knows, and
//! the comments).

use lsp_types::{
    ParameterInformation, ParameterLabel, SemanticToken, SemanticTokenModifier, SemanticTokenType,
    SemanticTokens, SemanticTokensLegend, SemanticTokensParams, SemanticTokensResult,
    SignatureHelp, SignatureHelpParams, SignatureInformation,
};

use crate::hover::{capability, describe};
use crate::index::Sym;
use crate::text::{line_before, LineIndex};
use crate::Server;

/// The arguments written so far after `open` in `before`: how many commas at depth 0,
/// and the name of the one being written if it is named (`radius=`).
fn argument_at(args: &str) -> (usize, Option<&str>) {
    let mut depth = 0i32;
    let mut index = 0;
    let mut start = 0;
    for (i, c) in args.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            ',' if depth == 0 => {
                index += 1;
                start = i + 1;
            }
            _ => {}
        }
    }
    let current = args[start..].trim_start();
    let named = current.split_once('=').map(|(n, _)| n.trim()).filter(|n| !n.is_empty());
    (index, named)
}

pub fn signature_help(server: &Server, p: SignatureHelpParams) -> Option<SignatureHelp> {
    let at = p.text_document_position_params;
    let (_, a, file) = server.lookup(&at.text_document.uri)?;
    let text = a.sources.text(file);
    let (_, before) = line_before(text, at.position);
    let api = aviary_api::Descriptor::standard();
    // `drone.Function(args`: the innermost open parenthesis after a function's name.
    if let Some(open) = before.rfind('(') {
        let head = &before[..open];
        let name = head.rsplit(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).next()?;
        let closed = before[open..].contains(')');
        if let (Some(f), false) = (api.function(name), closed) {
            let (index, _) = argument_at(&before[open + 1..]);
            let params: Vec<ParameterInformation> = f
                .params
                .iter()
                .map(|x| ParameterInformation {
                    label: ParameterLabel::Simple(x.name.to_string()),
                    documentation: Some(lsp_types::Documentation::String(
                        x.kind.describe().to_string(),
                    )),
                })
                .collect();
            let last = params.len().saturating_sub(1);
            let active = if f.variadic { index.min(last) } else { index };
            return Some(help(f.signature(), f.summary.to_string(), params, active));
        }
    }
    // `actors Capability[-Tag] WITH args`.
    let (head, args) = before.split_once(" WITH ")?;
    let cap_word = head.split_whitespace().last()?;
    let cap_name = cap_word.split('-').next().unwrap_or(cap_word);
    let c = a.program.as_ref()?.capability(cap_name)?;
    let (index, named) = argument_at(args);
    let active = match named {
        Some(n) => c.params.iter().position(|x| x.name == n)?,
        None => index,
    };
    let params: Vec<ParameterInformation> = c
        .params
        .iter()
        .map(|x| {
            let sym = Sym::Param { capability: cap_name.to_string(), name: x.name.clone() };
            ParameterInformation {
                label: ParameterLabel::Simple(x.name.clone()),
                documentation: Some(lsp_types::Documentation::String(describe(a, &sym))),
            }
        })
        .collect();
    let names: Vec<&str> = c.params.iter().map(|x| x.name.as_str()).collect();
    let label = format!("{cap_name} WITH {}", names.join(", "));
    Some(help(label, capability(a, c), params, active))
}

fn help(
    label: String,
    doc: String,
    params: Vec<ParameterInformation>,
    active: usize,
) -> SignatureHelp {
    SignatureHelp {
        signatures: vec![SignatureInformation {
            label,
            documentation: Some(lsp_types::Documentation::MarkupContent(
                lsp_types::MarkupContent { kind: lsp_types::MarkupKind::Markdown, value: doc },
            )),
            parameters: Some(params),
            active_parameter: Some(active as u32),
        }],
        active_signature: Some(0),
        active_parameter: Some(active as u32),
    }
}

/// The token types, in the legend's order.
const TYPES: &[SemanticTokenType] = &[
    SemanticTokenType::FUNCTION,
    SemanticTokenType::PARAMETER,
    SemanticTokenType::EVENT,
    SemanticTokenType::ENUM_MEMBER,
    SemanticTokenType::STRUCT,
    SemanticTokenType::VARIABLE,
    SemanticTokenType::NAMESPACE,
    SemanticTokenType::TYPE,
    SemanticTokenType::COMMENT,
];

pub fn legend() -> SemanticTokensLegend {
    SemanticTokensLegend {
        token_types: TYPES.to_vec(),
        token_modifiers: vec![SemanticTokenModifier::DECLARATION],
    }
}

fn type_of(sym: &Sym) -> u32 {
    match sym {
        Sym::Capability(_) => 0,
        Sym::Param { .. } => 1,
        Sym::Signal(_) | Sym::Exception(_) => 2,
        Sym::Place(_) => 3,
        Sym::Area(_) => 4,
        Sym::Drone(_) | Sym::Local { .. } => 5,
        Sym::Group(_) => 6,
        Sym::Tag(_) => 7,
    }
}

pub fn semantic_tokens(server: &Server, p: SemanticTokensParams) -> Option<SemanticTokensResult> {
    let (_, a, file) = server.lookup(&p.text_document.uri)?;
    let text = a.sources.text(file);
    let lines = LineIndex::new(text);
    // (start, end, type, modifiers), one line each.
    let mut spans: Vec<(usize, usize, u32, u32)> = a
        .occurrences
        .iter()
        .filter(|o| o.file == file && o.span.start < o.span.end)
        .map(|o| {
            (o.span.start as usize, o.span.end as usize, type_of(&o.sym), u32::from(o.definition))
        })
        .collect();
    if let Some(tree) = a.tree(file) {
        for c in &tree.comments {
            let (start, end) = (c.span.start as usize, c.span.end as usize);
            // A block comment over several lines: one token per line.
            let mut from = start;
            while from < end {
                let to = text[from..end].find('\n').map_or(end, |i| from + i);
                if to > from {
                    spans.push((from, to, 8, 0));
                }
                from = to + 1;
            }
        }
    }
    spans.sort_unstable();
    spans.dedup_by_key(|s| s.0);
    let mut data = Vec::new();
    let (mut line, mut column) = (0u32, 0u32);
    for (start, end, kind, modifiers) in spans {
        let (s, e) = (lines.position(start), lines.position(end));
        if s.line != e.line {
            continue;
        }
        let delta_line = s.line - line;
        let delta_start = if delta_line == 0 { s.character - column } else { s.character };
        data.push(SemanticToken {
            delta_line,
            delta_start,
            length: e.character - s.character,
            token_type: kind,
            token_modifiers_bitset: modifiers,
        });
        (line, column) = (s.line, s.character);
    }
    Some(SemanticTokensResult::Tokens(SemanticTokens { result_id: None, data }))
}
