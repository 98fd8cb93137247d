//! The time from an edit to its diagnostics, through the protocol (`aviary bench lsp`):
//! a server in this process, a mission and its world opened as documents, then edits
//! that alternately add and remove a comment line in the middle of the mission, each
//! timed from its `didChange` to the `publishDiagnostics` for its version.

use std::time::{Duration, Instant};

use lsp_server::{Connection, Message, Notification, Request, RequestId};
use serde_json::json;

/// What the edits took.
pub struct Timings {
    /// Each edit's time to its diagnostics, in order.
    pub edits: Vec<Duration>,
    /// The diagnostics of the mission after the last edit, and how many are errors (a
    /// mission with errors is not checked whole: a benchmark of one would time less).
    pub diagnostics: usize,
    pub errors: usize,
}

fn expect_response(client: &Connection, id: i32) -> Result<(), String> {
    loop {
        match client.receiver.recv_timeout(Duration::from_secs(600)) {
            Ok(Message::Response(r)) if r.id == RequestId::from(id) => return Ok(()),
            Ok(_) => {}
            Err(e) => return Err(format!("the server did not answer: {e}")),
        }
    }
}

/// Opens `mission` (with `world` beside it) in a server and times `runs` edits.
pub fn edits(mission: &str, world: &str, runs: usize) -> Result<Timings, String> {
    let (server, client) = Connection::memory();
    let thread = std::thread::Builder::new()
        .name("aviary-lsp".into())
        .stack_size(aviary_check::STACK)
        .spawn(move || crate::run(server, crate::Config::open_documents_only()))
        .map_err(|e| e.to_string())?;
    let send = |m: Message| client.sender.send(m).map_err(|e| e.to_string());
    let notify = |method: &str, params: serde_json::Value| {
        send(Message::Notification(Notification::new(method.to_string(), params)))
    };
    send(Message::Request(Request::new(
        1.into(),
        "initialize".into(),
        json!({ "capabilities": {} }),
    )))?;
    expect_response(&client, 1)?;
    notify("initialized", json!({}))?;
    let folder = "/nonexistent/aviary-bench-lsp";
    let uri = format!("file://{folder}/large.mission");
    let open = |uri: &str, language: &str, text: &str| {
        notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": uri, "languageId": language, "version": 1, "text": text } }),
        )
    };
    open(&format!("file://{folder}/large.world.toml"), "toml", world)?;
    open(&uri, "aviary", mission)?;
    let middle = mission.lines().count() as u32 / 2;
    let mut timings = Timings { edits: Vec::with_capacity(runs), diagnostics: 0, errors: 0 };
    for run in 0..runs {
        let version = run as i32 + 2;
        let start = json!({ "line": middle, "character": 0 });
        let change = if run % 2 == 0 {
            json!({ "range": { "start": start, "end": start }, "text": "// an edit\n" })
        } else {
            json!({ "range": { "start": start, "end": { "line": middle + 1, "character": 0 } }, "text": "" })
        };
        let began = Instant::now();
        notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": uri, "version": version }, "contentChanges": [change] }),
        )?;
        loop {
            let m = client
                .receiver
                .recv_timeout(Duration::from_secs(600))
                .map_err(|e| e.to_string())?;
            let Message::Notification(n) = m else { continue };
            if n.params["uri"] == uri.as_str() && n.params["version"] == version {
                timings.edits.push(began.elapsed());
                let all = n.params["diagnostics"].as_array().cloned().unwrap_or_default();
                timings.errors = all.iter().filter(|d| d["severity"] == 1).count();
                timings.diagnostics = all.len();
                break;
            }
        }
    }
    send(Message::Request(Request::new(2.into(), "shutdown".into(), serde_json::Value::Null)))?;
    expect_response(&client, 2)?;
    notify("exit", serde_json::Value::Null)?;
    thread.join().map_err(|_| "the server panicked".to_string())??;
    Ok(timings)
}
