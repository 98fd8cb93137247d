//! Typing faster than a check: edits sent one after another without waiting are all
//! applied in order, and the last diagnostics published are those of the last version.

mod support;

use std::path::Path;

use serde_json::json;
use support::{uri, Client};

#[test]
fn quick_edits_are_applied_in_order_and_the_last_version_is_published() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/typos.mission");
    let text = std::fs::read_to_string(&path).unwrap();
    let uri = uri(&path);
    let mut client = Client::start();
    client.open(&uri, &text);
    // Line 4 (from 0: 3) holds `BuildingZ` at column 28: delete it, then type `BuildingB`
    // one character at a time.
    let line = 3;
    let column = text.lines().nth(line).unwrap().find("BuildingZ").unwrap();
    let at = |c: usize| json!({ "line": line, "character": c });
    let mut changes =
        vec![json!({ "range": { "start": at(column), "end": at(column + 9) }, "text": "" })];
    for (i, c) in "BuildingB".chars().enumerate() {
        changes.push(json!({ "range": { "start": at(column + i), "end": at(column + i) }, "text": c.to_string() }));
    }
    let last = changes.len() as i32 + 1;
    for (i, change) in changes.into_iter().enumerate() {
        client.notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": uri, "version": i + 2 }, "contentChanges": [change] }),
        );
    }
    client.sync();
    let published = client.take_published();
    let final_publish = published.iter().rev().find(|p| p["uri"] == uri.as_str()).unwrap();
    assert_eq!(final_publish["version"], last, "{published:#?}");
    let on_line: Vec<&serde_json::Value> = final_publish["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|d| d["range"]["start"]["line"] == line)
        .collect();
    assert!(on_line.is_empty(), "{on_line:#?}");
    // The server's text is the typed one: the place is now BuildingB.
    let hover = client.request(
        "textDocument/hover",
        json!({ "textDocument": { "uri": uri }, "position": at(column + 3) }),
    );
    let shown = hover["result"]["contents"]["value"].as_str().unwrap();
    assert!(shown.contains("BuildingB\n```\nplace at (-200, 150)"), "{shown}");
    client.shutdown();
}
