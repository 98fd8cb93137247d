//! A client of the language server in the same process: real JSON-RPC messages over
//! `lsp_server::Connection::memory()`, the server on a thread of its own.

#![allow(dead_code)]

use std::path::Path;
use std::thread::JoinHandle;

use lsp_server::{Connection, Message, Notification, Request, RequestId};
use serde_json::{json, Value};

pub struct Client {
    connection: Connection,
    next_id: i32,
    server: Option<JoinHandle<Result<(), String>>>,
    /// Notifications that came while waiting for a response.
    pub notifications: Vec<Notification>,
}

impl Client {
    /// Starts a server that reads only open documents (and the world beside a mission on
    /// disk) and has the standard library in [`std_file`], and initializes it.
    pub fn start() -> Client {
        let (server_side, client_side) = Connection::memory();
        let server = std::thread::Builder::new()
            .stack_size(aviary_check::STACK)
            .spawn(move || {
                let config = aviary_lsp::Config {
                    std_file: Some(std_file()),
                    ..aviary_lsp::Config::open_documents_only()
                };
                aviary_lsp::run(server_side, config)
            })
            .expect("a thread for the server");
        let mut client = Client {
            connection: client_side,
            next_id: 0,
            server: Some(server),
            notifications: Vec::new(),
        };
        let init = client.request(
            "initialize",
            json!({ "processId": null, "rootUri": null, "capabilities": {} }),
        );
        assert!(
            init.get("result").is_some_and(|r| r["capabilities"]["hoverProvider"] == true),
            "{init}"
        );
        client.notify("initialized", json!({}));
        client
    }

    pub fn notify(&mut self, method: &str, params: Value) {
        let n = Notification::new(method.to_string(), params);
        self.connection.sender.send(Message::Notification(n)).expect("the server is listening");
    }

    /// Sends a request and waits for its response (as JSON: `result` or `error`); the
    /// notifications that come meanwhile are kept in `notifications`.
    pub fn request(&mut self, method: &str, params: Value) -> Value {
        self.next_id += 1;
        let id = RequestId::from(self.next_id);
        let r = Request::new(id.clone(), method.to_string(), params);
        self.connection.sender.send(Message::Request(r)).expect("the server is listening");
        loop {
            let m = self
                .connection
                .receiver
                .recv_timeout(std::time::Duration::from_secs(60))
                .expect("an answer within a minute");
            match m {
                Message::Response(resp) if resp.id == id => {
                    return serde_json::to_value(resp).expect("a response is JSON");
                }
                Message::Notification(n) => self.notifications.push(n),
                other => panic!("unexpected message {other:?}"),
            }
        }
    }

    /// The diagnostics published since the last call, in order.
    pub fn take_published(&mut self) -> Vec<Value> {
        std::mem::take(&mut self.notifications)
            .into_iter()
            .filter(|n| n.method == "textDocument/publishDiagnostics")
            .map(|n| n.params)
            .collect()
    }

    /// Waits for the next notifications by making a request that every server answers.
    pub fn sync(&mut self) {
        let _ = self.request("aviary/sync", json!({}));
    }

    pub fn open(&mut self, uri: &str, text: &str) {
        let language = if uri.ends_with(".toml") { "toml" } else { "aviary" };
        self.notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": uri, "languageId": language, "version": 1, "text": text } }),
        );
    }

    pub fn shutdown(mut self) {
        let answer = self.request("shutdown", Value::Null);
        assert_eq!(answer["result"], Value::Null, "{answer}");
        self.notify("exit", Value::Null);
        let server = self.server.take().expect("started");
        server.join().expect("the server thread ends").expect("the server ends cleanly");
    }
}

/// The standard library's text in a file, as `aviary lsp` writes it for go to definition.
pub fn std_file() -> std::path::PathBuf {
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("std/standard.mission");
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    if std::fs::read_to_string(&path).ok().as_deref() != Some(aviary_check::STD_SOURCE) {
        std::fs::write(&path, aviary_check::STD_SOURCE).unwrap();
    }
    path
}

/// The `file:` URI of a path (no character of the fixtures' paths needs escaping).
pub fn uri(path: &Path) -> String {
    format!("file://{}", path.display())
}
