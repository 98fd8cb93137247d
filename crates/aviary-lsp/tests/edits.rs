//! Random edit sequences on the paper's mission never crash the server, and each edit is
//! answered with a publish of the document's diagnostics, for the version edited.

mod support;

use proptest::prelude::*;
use serde_json::json;
use support::Client;

const MISSION: &str = include_str!("../../../examples/search_and_rescue.mission");

/// An edit: at a fraction of the text, delete some characters and insert a piece.
#[derive(Debug, Clone)]
struct Edit {
    at: f64,
    delete: usize,
    insert: String,
}

fn edit() -> impl Strategy<Value = Edit> {
    let pieces = prop_oneof![
        Just(String::new()),
        Just(":".to_string()),
        Just("\n".to_string()),
        Just("    ".to_string()),
        Just("\t".to_string()),
        Just("WITH ".to_string()),
        Just("ON ".to_string()),
        Just("😀é".to_string()),
        Just("/*".to_string()),
        Just("\"".to_string()),
        "[ -~]{0,12}",
    ];
    (0.0..1.0f64, 0usize..20, pieces).prop_map(|(at, delete, insert)| Edit { at, delete, insert })
}

/// The UTF-16 position of the byte `at` of `text`.
fn position(text: &str, at: usize) -> serde_json::Value {
    let before = &text[..at];
    let line = before.matches('\n').count();
    let start = before.rfind('\n').map_or(0, |i| i + 1);
    json!({ "line": line, "character": before[start..].encode_utf16().count() })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]
    #[test]
    fn random_edits_never_crash_the_server(edits in proptest::collection::vec(edit(), 1..12)) {
        let uri = "file:///nonexistent/aviary-lsp-edits/search_and_rescue.mission";
        let mut client = Client::start();
        client.open(uri, MISSION);
        let mut text = MISSION.to_string();
        for (i, e) in edits.iter().enumerate() {
            let mut start = ((text.len() as f64) * e.at) as usize;
            while !text.is_char_boundary(start) { start -= 1; }
            let mut end = (start + e.delete).min(text.len());
            while !text.is_char_boundary(end) { end += 1; }
            let range = json!({ "start": position(&text, start), "end": position(&text, end) });
            let version = i as i32 + 2;
            client.notify("textDocument/didChange", json!({
                "textDocument": { "uri": uri, "version": version },
                "contentChanges": [{ "range": range, "text": e.insert }],
            }));
            text.replace_range(start..end, &e.insert);
            // A request in the middle of typing: hover where the edit was.
            let hover = client.request("textDocument/hover", json!({ "textDocument": { "uri": uri }, "position": position(&text, start) }));
            prop_assert!(hover.get("error").is_none(), "{hover}");
            let published = client.take_published();
            prop_assert!(
                published.iter().any(|p| p["uri"] == uri && p["version"] == version),
                "no diagnostics for version {version}: {published:?}"
            );
        }
        // The server's text is the client's: formatting it answers for that text.
        let symbols = client.request("textDocument/documentSymbol", json!({ "textDocument": { "uri": uri } }));
        prop_assert!(symbols.get("error").is_none(), "{symbols}");
        client.shutdown();
    }
}
