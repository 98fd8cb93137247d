//! The server's loop: one thread takes the client's messages in order, keeps the open
//! documents' texts, and hands out the work.
//!
//! - A check runs on a thread of its own, over a copy of the documents. Edits that come
//!   while it runs are applied at once and checked together by the next check, which
//!   starts when this one ends: at most one check runs, and the last edit is always
//!   checked.
//! - A request runs on a thread of its own, over the last checked [`Server`]: no request
//!   waits for another. A request waits only for the check of the edits that came before
//!   it (it is held, and started when that check is published), so it is never answered
//!   from a text older than the one it names. `$/cancelRequest` answers a held request.
//!   `shutdown` is answered after every request before it.
//! - A panic in a check or a request is caught and written to stderr; a request is
//!   answered with an error; the server lives on.

use std::collections::BTreeSet;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Arc;

use crossbeam_channel::{select, Receiver, Sender};
use lsp_server::{Connection, ErrorCode, Message, Notification, Request, RequestId, Response};
use lsp_types::notification::Notification as _;
use lsp_types::{notification as note, Uri};

use crate::overlay::{Doc, Docs};
use crate::{panic_text, send, Config, Server};

/// A request's thread: a handler walks a tree the parser keeps within 64 levels, so it
/// needs far less than a check, which follows capability calls (`aviary_check::STACK`);
/// many requests may be in flight at once.
const REQUEST_STACK: usize = 64 << 20;

/// A check's result: the server it made, the edits it saw, and its diagnostics.
struct Checked {
    server: Option<Server>,
    edits: u64,
    publish: Vec<Notification>,
    published: BTreeSet<String>,
}

struct Loop {
    connection: Connection,
    config: Arc<Config>,
    /// The documents as the client has them now.
    docs: Docs,
    /// How many edits have come.
    edits: u64,
    /// The last checked server, and the edits it saw.
    checked: Arc<Server>,
    checked_edits: u64,
    /// Whether a check runs.
    checking: bool,
    /// The URIs last published with diagnostics (the running check has them).
    published: Option<BTreeSet<String>>,
    /// Requests that wait for a check.
    held: Vec<Request>,
    /// The threads of the requests started, until they are seen to have ended.
    running: Vec<std::thread::JoinHandle<()>>,
    results: (Sender<Checked>, Receiver<Checked>),
}

pub fn run(connection: Connection, config: Config) -> Result<(), String> {
    let capabilities = serde_json::to_value(crate::capabilities()).map_err(|e| e.to_string())?;
    connection.initialize(capabilities).map_err(|e| e.to_string())?;
    let config = Arc::new(config);
    let empty = Server::new(config.clone(), Docs::new());
    let mut state = Loop {
        connection,
        config,
        docs: Docs::new(),
        edits: 0,
        checked: Arc::new(empty),
        checked_edits: 0,
        checking: false,
        published: Some(BTreeSet::new()),
        held: Vec::new(),
        running: Vec::new(),
        results: crossbeam_channel::unbounded(),
    };
    loop {
        let results = state.results.1.clone();
        select! {
            recv(state.connection.receiver) -> message => {
                let Ok(message) = message else { return Ok(()) };
                if !state.message(message)? {
                    return Ok(());
                }
            }
            recv(results) -> checked => {
                if let Ok(checked) = checked {
                    state.done(checked)?;
                }
            }
        }
    }
}

impl Loop {
    /// Handles one message from the client; `false` once it has said `exit`.
    fn message(&mut self, message: Message) -> Result<bool, String> {
        match message {
            Message::Request(request) => {
                if request.method
                    == <lsp_types::request::Shutdown as lsp_types::request::Request>::METHOD
                {
                    // Every request before it is answered first.
                    self.settle()?;
                }
                if self.connection.handle_shutdown(&request).map_err(|e| e.to_string())? {
                    return Ok(false);
                }
                if self.checked_edits == self.edits {
                    self.start(request);
                } else {
                    self.held.push(request);
                }
            }
            Message::Notification(n) if n.method == note::Cancel::METHOD => self.cancel(n),
            Message::Notification(n) => {
                let method = n.method.clone();
                let changed = catch_unwind(AssertUnwindSafe(|| notification(&mut self.docs, n)))
                    .unwrap_or_else(|panic| {
                        eprintln!("aviary lsp: {method} panicked: {}", panic_text(&panic));
                        false
                    });
                if changed {
                    self.edits += 1;
                    self.check();
                }
            }
            Message::Response(_) => {}
        }
        Ok(true)
    }

    /// Starts a check of the documents as they are now, unless one runs.
    fn check(&mut self) {
        if self.checking {
            return;
        }
        let Some(published) = self.published.take() else { return };
        self.checking = true;
        let docs = self.docs.clone();
        let edits = self.edits;
        let config = self.config.clone();
        let results = self.results.0.clone();
        let spawned = std::thread::Builder::new()
            .name("aviary-lsp-check".into())
            .stack_size(aviary_check::STACK)
            .spawn(move || {
                let mut published = published;
                let outcome = catch_unwind(AssertUnwindSafe(|| {
                    let mut server = Server::new(config, docs);
                    let publish = server.analyse(&mut published);
                    (server, publish)
                }));
                let checked = match outcome {
                    Ok((server, publish)) => {
                        Checked { server: Some(server), edits, publish, published }
                    }
                    Err(panic) => {
                        eprintln!("aviary lsp: a check panicked: {}", panic_text(&panic));
                        Checked { server: None, edits, publish: Vec::new(), published }
                    }
                };
                let _ = results.send(checked);
            });
        if let Err(e) = spawned {
            // Nothing checked: the requests that wait go on with the last check.
            eprintln!("aviary lsp: no thread for a check: {e}");
            let nothing =
                Checked { server: None, edits, publish: Vec::new(), published: BTreeSet::new() };
            let _ = self.results.0.send(nothing);
        }
    }

    /// A check has ended: its diagnostics are sent, the requests that waited for it
    /// start, and the edits that came meanwhile are checked.
    fn done(&mut self, checked: Checked) -> Result<(), String> {
        self.checking = false;
        self.published = Some(checked.published);
        if let Some(server) = checked.server {
            self.checked = Arc::new(server);
        }
        self.checked_edits = checked.edits;
        for p in checked.publish {
            send(&self.connection, Message::Notification(p))?;
        }
        if self.checked_edits == self.edits {
            for request in std::mem::take(&mut self.held) {
                self.start(request);
            }
        } else {
            self.check();
        }
        Ok(())
    }

    /// Before `shutdown`: waits for the checks of every edit, so that the requests held
    /// for them start, and then for every request in flight to be answered.
    fn settle(&mut self) -> Result<(), String> {
        while self.checking {
            let checked = self.results.1.recv().map_err(|e| e.to_string())?;
            self.done(checked)?;
        }
        for running in std::mem::take(&mut self.running) {
            let _ = running.join();
        }
        Ok(())
    }

    /// Answers `request` on a thread of its own, over the last checked server.
    fn start(&mut self, request: Request) {
        self.running.retain(|r| !r.is_finished());
        let server = self.checked.clone();
        let sender = self.connection.sender.clone();
        let id = request.id.clone();
        let spawned = std::thread::Builder::new()
            .name("aviary-lsp-request".into())
            .stack_size(REQUEST_STACK)
            .spawn(move || {
                let _ = sender.send(Message::Response(server.request(request)));
            });
        match spawned {
            Ok(running) => self.running.push(running),
            Err(e) => {
                let why = format!("aviary lsp: no thread for the request: {e}");
                let _ = self.connection.sender.send(Message::Response(Response::new_err(
                    id,
                    ErrorCode::InternalError as i32,
                    why,
                )));
            }
        }
    }

    /// `$/cancelRequest`: a held request is answered as cancelled; one that runs ends
    /// as it would.
    fn cancel(&mut self, n: Notification) {
        let Ok(p) = serde_json::from_value::<lsp_types::CancelParams>(n.params) else { return };
        let id: RequestId = match p.id {
            lsp_types::NumberOrString::Number(n) => n.into(),
            lsp_types::NumberOrString::String(s) => s.into(),
        };
        if let Some(i) = self.held.iter().position(|r| r.id == id) {
            self.held.remove(i);
            let answer = Response::new_err(
                id,
                ErrorCode::RequestCanceled as i32,
                "cancelled by the client".into(),
            );
            let _ = self.connection.sender.send(Message::Response(answer));
        }
    }
}

/// Applies a notification of the documents' texts; says whether they changed.
fn notification(docs: &mut Docs, n: Notification) -> bool {
    match n.method.as_str() {
        note::DidOpenTextDocument::METHOD => {
            let Ok(p) = serde_json::from_value::<lsp_types::DidOpenTextDocumentParams>(n.params)
            else {
                return false;
            };
            let d = p.text_document;
            docs.insert(
                crate::uri::key(&d.uri),
                Doc { uri: d.uri, text: d.text, version: d.version },
            );
        }
        note::DidChangeTextDocument::METHOD => {
            let Ok(p) = serde_json::from_value::<lsp_types::DidChangeTextDocumentParams>(n.params)
            else {
                return false;
            };
            let Some(doc) = docs.get_mut(&crate::uri::key(&p.text_document.uri)) else {
                return false;
            };
            for change in p.content_changes {
                apply(&mut doc.text, change);
            }
            doc.version = p.text_document.version;
        }
        note::DidCloseTextDocument::METHOD => {
            let Ok(p) = serde_json::from_value::<lsp_types::DidCloseTextDocumentParams>(n.params)
            else {
                return false;
            };
            docs.remove(&crate::uri::key(&p.text_document.uri));
        }
        note::DidSaveTextDocument::METHOD | note::DidChangeWatchedFiles::METHOD => {}
        _ => return false,
    }
    true
}

/// Applies one change to a document's text: a range's replacement, or the whole text.
fn apply(text: &mut String, change: lsp_types::TextDocumentContentChangeEvent) {
    match change.range {
        Some(range) => {
            let index = crate::text::LineIndex::new(text);
            let start = index.offset(range.start);
            let end = index.offset(range.end).max(start);
            text.replace_range(start..end, &change.text);
        }
        None => *text = change.text,
    }
}

pub(crate) fn publish(
    uri: Uri,
    diagnostics: Vec<lsp_types::Diagnostic>,
    version: Option<i32>,
) -> Notification {
    let params = lsp_types::PublishDiagnosticsParams { uri, diagnostics, version };
    Notification::new(note::PublishDiagnostics::METHOD.to_string(), params)
}
