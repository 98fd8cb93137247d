//! A panic in a request handler is answered with an error, and the server lives on; a
//! slow request does not hold a quick one.

use lsp_server::{Connection, Message, Notification, Request, RequestId};
use serde_json::json;

fn answer(
    client: &Connection,
    id: i32,
    method: &str,
    params: serde_json::Value,
) -> serde_json::Value {
    let request = Request::new(RequestId::from(id), method.to_string(), params);
    client.sender.send(Message::Request(request)).unwrap();
    loop {
        match client.receiver.recv_timeout(std::time::Duration::from_secs(60)).unwrap() {
            Message::Response(r) => return serde_json::to_value(r).unwrap(),
            _ => continue,
        }
    }
}

/// A server on a thread of its own, initialized (request 1), with its client.
fn started() -> (Connection, std::thread::JoinHandle<Result<(), String>>) {
    let (server, client) = Connection::memory();
    let thread = std::thread::Builder::new()
        .stack_size(aviary_check::STACK)
        .spawn(move || crate::run(server, crate::Config::open_documents_only()))
        .unwrap();
    answer(&client, 1, "initialize", json!({ "capabilities": {} }));
    client
        .sender
        .send(Message::Notification(Notification::new("initialized".into(), json!({}))))
        .unwrap();
    (client, thread)
}

#[test]
fn a_panicking_handler_is_answered_with_an_error_and_the_server_lives_on() {
    let (client, thread) = started();
    let failed = answer(&client, 2, "aviary/panic", json!({}));
    assert_eq!(failed["error"]["code"], -32603, "{failed}");
    assert!(failed["error"]["message"].as_str().unwrap().contains("a handler's bug, on purpose"));
    // Still answering: a document opened now is checked and hovered.
    let uri = "untitled:panic.mission";
    let text = "MISSION M:\n    d TakeOff\n";
    let open = json!({ "textDocument": { "uri": uri, "languageId": "aviary", "version": 1, "text": text } });
    client
        .sender
        .send(Message::Notification(Notification::new("textDocument/didOpen".into(), open)))
        .unwrap();
    let hover = answer(
        &client,
        3,
        "textDocument/hover",
        json!({ "textDocument": { "uri": uri }, "position": { "line": 1, "character": 8 } }),
    );
    let shown = hover["result"]["contents"]["value"].as_str().unwrap();
    assert!(shown.contains("CAPABILITY TakeOff BY drone WITH alt"), "{shown}");
    let bye = answer(&client, 4, "shutdown", serde_json::Value::Null);
    assert_eq!(bye["result"], serde_json::Value::Null);
    client
        .sender
        .send(Message::Notification(Notification::new("exit".into(), serde_json::Value::Null)))
        .unwrap();
    thread.join().unwrap().unwrap();
}

#[test]
fn the_benchmark_times_each_edit_to_its_diagnostics() {
    let mission = include_str!("../../../examples/search_and_rescue.mission");
    let world = include_str!("../../../examples/search_and_rescue.world.toml");
    let timings = crate::bench::edits(mission, world, 4).unwrap();
    assert_eq!(timings.edits.len(), 4);
    assert_eq!(timings.errors, 0);
    // The paper's mission says five notes (N303 four times, N301 once).
    assert_eq!(timings.diagnostics, 5);
}

#[test]
fn a_slow_request_does_not_hold_a_quick_one() {
    let (client, thread) = started();
    let uri = "untitled:slow.mission";
    let open = json!({ "textDocument": { "uri": uri, "languageId": "aviary", "version": 1, "text": "MISSION M:\n    d TakeOff\n" } });
    client
        .sender
        .send(Message::Notification(Notification::new("textDocument/didOpen".into(), open)))
        .unwrap();
    let hover =
        json!({ "textDocument": { "uri": uri }, "position": { "line": 1, "character": 8 } });
    // Answered once the document is checked, so the next two start at once.
    answer(&client, 2, "textDocument/hover", hover.clone());
    let send = |id: i32, method: &str, params: serde_json::Value| {
        let r = Request::new(RequestId::from(id), method.to_string(), params);
        client.sender.send(Message::Request(r)).unwrap();
    };
    // `aviary/slow` (a test build's) takes 1.5 s; the hover sent after it comes first.
    let began = std::time::Instant::now();
    send(3, "aviary/slow", json!({}));
    send(4, "textDocument/hover", hover);
    let mut order = Vec::new();
    while order.len() < 2 {
        let m = client.receiver.recv_timeout(std::time::Duration::from_secs(60)).unwrap();
        if let Message::Response(r) = m {
            order.push((r.id, began.elapsed()));
        }
    }
    assert_eq!(order[0].0, RequestId::from(4), "{order:?}");
    assert_eq!(order[1].0, RequestId::from(3), "{order:?}");
    assert!(order[0].1 < std::time::Duration::from_millis(1500), "{order:?}");
    assert!(order[1].1 >= std::time::Duration::from_millis(1500), "{order:?}");
    answer(&client, 5, "shutdown", serde_json::Value::Null);
    client
        .sender
        .send(Message::Notification(Notification::new("exit".into(), serde_json::Value::Null)))
        .unwrap();
    thread.join().unwrap().unwrap();
}
