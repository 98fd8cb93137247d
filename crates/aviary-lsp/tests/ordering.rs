//! How requests and checks are ordered: a request waits for the check of the edits sent
//! before it, a held request can be cancelled, `shutdown` is answered after the rest (that no request waits for another is
//! tested in the crate, with a request only a test build answers). And
//! the standard library's file, opened in the editor, is read as the library.

mod support;

use std::path::Path;
use std::time::Duration;

use lsp_server::{Connection, Message, Notification, Request, RequestId};
use serde_json::{json, Value};
use support::{std_file, uri, Client};

fn fixture(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

/// A server on a thread, spoken to without the helper's request-and-wait.
fn raw_server() -> (Connection, std::thread::JoinHandle<Result<(), String>>) {
    let (server, client) = Connection::memory();
    let thread = std::thread::Builder::new()
        .stack_size(aviary_check::STACK)
        .spawn(move || {
            let config = aviary_lsp::Config {
                std_file: Some(std_file()),
                ..aviary_lsp::Config::open_documents_only()
            };
            aviary_lsp::run(server, config)
        })
        .unwrap();
    let send = |m| client.sender.send(m).unwrap();
    send(Message::Request(Request::new(
        0.into(),
        "initialize".into(),
        json!({ "capabilities": {} }),
    )));
    assert!(matches!(client.receiver.recv().unwrap(), Message::Response(_)));
    send(Message::Notification(Notification::new("initialized".into(), json!({}))));
    (client, thread)
}

fn request(client: &Connection, id: i32, method: &str, params: Value) {
    let r = Request::new(RequestId::from(id), method.into(), params);
    client.sender.send(Message::Request(r)).unwrap();
}

fn notify(client: &Connection, method: &str, params: Value) {
    client.sender.send(Message::Notification(Notification::new(method.into(), params))).unwrap();
}

/// The messages the server sends until the responses to `ids` have all come, in order.
fn until_answered(client: &Connection, ids: &[i32]) -> Vec<Message> {
    let mut left: Vec<RequestId> = ids.iter().map(|&i| RequestId::from(i)).collect();
    let mut out = Vec::new();
    while !left.is_empty() {
        let m = client.receiver.recv_timeout(Duration::from_secs(60)).expect("an answer");
        if let Message::Response(r) = &m {
            left.retain(|id| *id != r.id);
        }
        out.push(m);
    }
    out
}

fn bye(client: Connection, thread: std::thread::JoinHandle<Result<(), String>>) {
    request(&client, 999, "shutdown", Value::Null);
    until_answered(&client, &[999]);
    notify(&client, "exit", Value::Null);
    thread.join().unwrap().unwrap();
}

/// A mission whose check takes a while: the paper's mission with many more handlers.
fn long_mission() -> String {
    let mut text = std::fs::read_to_string(fixture("search_and_rescue.mission")).unwrap();
    let end = text.find("\nCAPABILITY").unwrap();
    let mut more = String::new();
    for i in 0..3000 {
        more.push_str(&format!(
            "        ON Extra_{i}:\n            video_drone1 FlyTo WITH BuildingA\n        SIGNAL Extra_{i}\n"
        ));
    }
    text.insert_str(end, &more);
    text
}

#[test]
fn a_request_after_an_edit_waits_for_its_check_and_can_be_cancelled_meanwhile() {
    let (client, thread) = raw_server();
    let path = fixture("search_and_rescue.mission");
    let doc = uri(&path);
    let text = long_mission();
    notify(
        &client,
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": doc, "languageId": "aviary", "version": 1, "text": text } }),
    );
    // BuildingA on line 12 becomes BuildingB; a hover there right after names the new one.
    let line = 11;
    let column = text.lines().nth(line).unwrap().find("BuildingA").unwrap();
    let at = |c: usize| json!({ "line": line, "character": c });
    notify(
        &client,
        "textDocument/didChange",
        json!({ "textDocument": { "uri": doc, "version": 2 },
                "contentChanges": [{ "range": { "start": at(column + 8), "end": at(column + 9) }, "text": "B" }] }),
    );
    let hover = json!({ "textDocument": { "uri": doc }, "position": at(column + 3) });
    request(&client, 1, "textDocument/hover", hover.clone());
    // Cancelled while the check of so long a mission runs: answered as cancelled.
    request(&client, 2, "textDocument/hover", hover);
    notify(&client, "$/cancelRequest", json!({ "id": 2 }));
    let messages = until_answered(&client, &[1, 2]);
    let mut published_version_2 = None;
    let mut answers = Vec::new();
    for (i, m) in messages.iter().enumerate() {
        match m {
            Message::Notification(n)
                if n.method == "textDocument/publishDiagnostics" && n.params["version"] == 2 =>
            {
                published_version_2 = Some(i);
            }
            Message::Response(r) => answers.push((i, serde_json::to_value(r).unwrap())),
            _ => {}
        }
    }
    let (cancelled_at, cancelled) = answers.iter().find(|(_, r)| r["id"] == 2).unwrap();
    assert_eq!(cancelled["error"]["code"], -32800, "{cancelled}");
    let (hover_at, hovered) = answers.iter().find(|(_, r)| r["id"] == 1).unwrap();
    let published = published_version_2.expect("the edit's diagnostics");
    // The cancel is answered before the check ends; the hover after it, on the new text.
    assert!(cancelled_at < &published && &published < hover_at, "{messages:?}");
    let shown = hovered["result"]["contents"]["value"].as_str().unwrap();
    assert!(shown.contains("BuildingB"), "{shown}");
    bye(client, thread);
}

/// A client that sends `shutdown` right after its requests (as a page that closes does)
/// gets every answer first, the one held for a long check included.
#[test]
fn shutdown_is_answered_after_every_request_before_it() {
    let (client, thread) = raw_server();
    let doc = uri(&fixture("search_and_rescue.mission"));
    let text = long_mission();
    notify(
        &client,
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": doc, "languageId": "aviary", "version": 1, "text": text } }),
    );
    let at = json!({ "textDocument": { "uri": doc }, "position": { "line": 11, "character": 30 } });
    request(&client, 1, "textDocument/hover", at.clone());
    request(&client, 2, "textDocument/documentSymbol", json!({ "textDocument": { "uri": doc } }));
    request(&client, 999, "shutdown", Value::Null);
    let answered: Vec<Value> = until_answered(&client, &[999])
        .into_iter()
        .filter_map(|m| match m {
            Message::Response(r) => Some(r.id.to_string().parse().unwrap()),
            _ => None,
        })
        .collect();
    assert_eq!(answered.len(), 3, "{answered:?}");
    assert_eq!(answered[2], json!(999), "shutdown last: {answered:?}");
    notify(&client, "exit", Value::Null);
    thread.join().unwrap().unwrap();
}

#[test]
fn the_standard_library_file_opened_is_read_as_the_library() {
    let mut client = Client::start();
    let path = fixture("search_and_rescue.mission");
    let text = std::fs::read_to_string(&path).unwrap();
    client.open(&uri(&path), &text);
    client.sync();
    // Go to FlyCircle's definition, and the editor opens the file it names.
    let found = client.request(
        "textDocument/definition",
        json!({ "textDocument": { "uri": uri(&path) }, "position": { "line": 13, "character": 28 } }),
    );
    let std = uri(&std_file());
    assert_eq!(found["result"][0]["uri"], std.as_str(), "{found}");
    client.open(&std, aviary_check::STD_SOURCE);
    client.sync();
    let published = client.take_published();
    let of_std: Vec<&Value> = published.iter().filter(|p| p["uri"] == std.as_str()).collect();
    assert!(of_std.iter().all(|p| p["diagnostics"] == json!([])), "{of_std:?}");
    // In it: FlyCircle's own FlyTo goes to FlyTo, in the same file; hover shows its
    // signature.
    let lines: Vec<&str> = aviary_check::STD_SOURCE.lines().collect();
    let line = lines.iter().position(|l| l.starts_with("CAPABILITY FlyCircle")).unwrap();
    let (use_line, use_text) =
        lines.iter().enumerate().skip(line).find(|(_, l)| l.contains(" FlyTo ")).unwrap();
    let character = use_text.find("FlyTo").unwrap() + 2;
    let at = json!({ "textDocument": { "uri": std }, "position": { "line": use_line, "character": character } });
    let def = client.request("textDocument/definition", at.clone());
    let flyto = lines.iter().position(|l| l.starts_with("CAPABILITY FlyTo ")).unwrap();
    assert_eq!(def["result"][0]["uri"], std.as_str(), "{def}");
    assert_eq!(def["result"][0]["range"]["start"]["line"], flyto, "{def}");
    let hover = client.request("textDocument/hover", at);
    let shown = hover["result"]["contents"]["value"].as_str().unwrap();
    assert!(shown.contains("CAPABILITY FlyTo BY drone WITH target"), "{shown}");
    client.shutdown();
}
