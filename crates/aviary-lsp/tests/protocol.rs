//! The server through the protocol, on fixtures: each `tests/fixtures/NAME.mission` is
//! opened (its world beside it is read from disk), and each line of `NAME.script` is a
//! request or an edit; the diagnostics published and every answer are snapshotted.
//!
//! Script lines: `METHOD LINE NEEDLE` (the position is the end of NEEDLE's first
//! occurrence on LINE, from 1; `^` is the line's first non-blank), `rename LINE NEEDLE ->
//! NEW`, `change LINE OLD -> NEW` (an incremental edit), `open FILE [CONTENT_FILE]` (a
//! document opened in the editor; with CONTENT_FILE, one not on disk), `symbols-of FILE`,
//! and `formatting`, `symbols`, `folding` on the mission.

mod support;

use std::path::{Path, PathBuf};

use serde_json::{json, Value};
use support::{uri, Client};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

/// The position at the end of `needle` on line `line` (from 1) of `text`, in UTF-16 units.
fn position(text: &str, line: usize, needle: &str) -> Value {
    let l = text.lines().nth(line - 1).unwrap_or_else(|| panic!("no line {line}"));
    let end = if needle == "^" {
        l.len() - l.trim_start().len()
    } else {
        l.find(needle).unwrap_or_else(|| panic!("no `{needle}` on line {line}: {l}")) + needle.len()
    };
    let character: usize = l[..end].chars().map(char::len_utf16).sum();
    json!({ "line": line - 1, "character": character })
}

/// Completion lists are long: each item as `label (kind) detail`, and whether it has docs.
fn summarize_completion(answer: &mut Value) {
    if let Some(items) = answer["result"].as_array_mut() {
        let shown: Vec<Value> = items
            .iter()
            .map(|i| {
                let docs = if i.get("documentation").is_some() { " +docs" } else { "" };
                json!(format!(
                    "{} ({}) {}{docs}",
                    i["label"].as_str().unwrap_or(""),
                    i["kind"],
                    i["detail"].as_str().unwrap_or("")
                ))
            })
            .collect();
        answer["result"] = Value::Array(shown);
    }
}

/// Semantic tokens are relative numbers: each as `line:column text type`, with the
/// legend's names (`aviary_lsp::capabilities`).
fn decode_tokens(answer: &mut Value, text: &str) {
    let caps = serde_json::to_value(aviary_lsp::capabilities()).unwrap();
    let legend = &caps["semanticTokensProvider"]["legend"];
    let Some(data) = answer["result"]["data"].as_array() else { return };
    let numbers: Vec<u64> = data.iter().map(|n| n.as_u64().unwrap()).collect();
    let lines: Vec<&str> = text.lines().collect();
    let (mut line, mut column) = (0, 0);
    let mut shown = Vec::new();
    for t in numbers.chunks(5) {
        if t[0] > 0 {
            column = 0;
        }
        line += t[0] as usize;
        column += t[1] as usize;
        let units: Vec<u16> = lines[line].encode_utf16().collect();
        let word = String::from_utf16_lossy(&units[column..column + t[2] as usize]);
        let kind = legend["tokenTypes"][t[3] as usize].as_str().unwrap();
        let declaration = if t[4] & 1 == 1 { " declaration" } else { "" };
        shown.push(json!(format!("{}:{column} {word} {kind}{declaration}", line + 1)));
    }
    answer["result"] = Value::Array(shown);
}

fn run_fixture(path: &Path) -> String {
    let dir = fixtures();
    let name = path.file_stem().unwrap().to_string_lossy().into_owned();
    let text = std::fs::read_to_string(path).unwrap();
    let script = std::fs::read_to_string(dir.join(format!("{name}.script"))).unwrap_or_default();
    let mission_uri = uri(path);
    let mut texts = std::collections::HashMap::new();
    texts.insert(mission_uri.clone(), text.clone());
    let mut client = Client::start();
    let mut log: Vec<Value> = Vec::new();
    client.open(&mission_uri, &text);
    client.sync();
    log.push(json!({ "step": "didOpen", "published": client.take_published() }));
    let mut version = 1;
    for line in script.lines().filter(|l| !l.starts_with('#') && !l.trim().is_empty()) {
        let (method, rest) = line.split_once(' ').unwrap_or((line, ""));
        let doc = json!({ "uri": mission_uri });
        let at = |rest: &str| {
            let (n, needle) = rest.split_once(' ').unwrap_or((rest, ""));
            let n: usize = n.parse().unwrap_or_else(|_| panic!("a line number in `{line}`"));
            position(&texts[&mission_uri], n, needle)
        };
        let mut answer = match method {
            "open" => {
                let mut words = rest.split(' ');
                let file = dir.join(words.next().unwrap());
                let content = match words.next() {
                    Some(c) => std::fs::read_to_string(dir.join(c)).unwrap(),
                    None => std::fs::read_to_string(&file).unwrap(),
                };
                client.open(&uri(&file), &content);
                texts.insert(uri(&file), content);
                client.sync();
                json!(null)
            }
            "change" => {
                let (n, edit) = rest.split_once(' ').unwrap();
                let (old, new) = edit.split_once(" -> ").unwrap();
                let n: usize = n.parse().unwrap();
                let end = position(&texts[&mission_uri], n, old);
                let mut start = end.clone();
                start["character"] = json!(end["character"].as_u64().unwrap() - old.encode_utf16().count() as u64);
                version += 1;
                client.notify(
                    "textDocument/didChange",
                    json!({ "textDocument": { "uri": mission_uri, "version": version },
                            "contentChanges": [{ "range": { "start": start, "end": end }, "text": new }] }),
                );
                let t = texts.get_mut(&mission_uri).unwrap();
                let line_start: usize = t.lines().take(n - 1).map(|l| l.len() + 1).sum();
                let at = line_start + t[line_start..].find(old).unwrap();
                t.replace_range(at..at + old.len(), new);
                client.sync();
                json!(null)
            }
            "rename" => {
                let (place, new) = rest.split_once(" -> ").unwrap();
                client.request("textDocument/rename", json!({ "textDocument": doc, "position": at(place), "newName": new }))
            }
            "hover" => client.request("textDocument/hover", json!({ "textDocument": doc, "position": at(rest) })),
            "definition" => client.request("textDocument/definition", json!({ "textDocument": doc, "position": at(rest) })),
            "references" => client.request(
                "textDocument/references",
                json!({ "textDocument": doc, "position": at(rest), "context": { "includeDeclaration": true } }),
            ),
            "completion" => {
                let mut a = client.request("textDocument/completion", json!({ "textDocument": doc, "position": at(rest) }));
                summarize_completion(&mut a);
                a
            }
            "codeAction" => {
                let p = at(rest);
                client.request(
                    "textDocument/codeAction",
                    json!({ "textDocument": doc, "range": { "start": p, "end": p }, "context": { "diagnostics": [] } }),
                )
            }
            "formatting" => client.request(
                "textDocument/formatting",
                json!({ "textDocument": doc, "options": { "tabSize": 4, "insertSpaces": true } }),
            ),
            "symbols" => client.request("textDocument/documentSymbol", json!({ "textDocument": doc })),
            "symbols-of" => client.request("textDocument/documentSymbol", json!({ "textDocument": { "uri": uri(&dir.join(rest)) } })),
            "signatureHelp" => client.request("textDocument/signatureHelp", json!({ "textDocument": doc, "position": at(rest) })),
            "semanticTokens" => {
                let mut a = client.request("textDocument/semanticTokens/full", json!({ "textDocument": doc }));
                decode_tokens(&mut a, &texts[&mission_uri]);
                a
            }
            "folding" => client.request("textDocument/foldingRange", json!({ "textDocument": doc })),
            other => panic!("unknown script step `{other}`"),
        };
        if let Some(o) = answer.as_object_mut() {
            o.remove("id");
        }
        log.push(json!({ "step": line, "answer": answer, "published": client.take_published() }));
    }
    client.shutdown();
    let shown = serde_json::to_string_pretty(&log).unwrap();
    shown
        .replace(&format!("file://{}", dir.display()), "file://$FIXTURES")
        .replace(&format!("file://{}", support::std_file().display()), "file://$STD")
}

#[test]
fn fixtures_through_the_protocol() {
    insta::glob!("fixtures/*.mission", |path| {
        insta::assert_snapshot!(run_fixture(path));
    });
}
