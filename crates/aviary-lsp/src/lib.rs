//! `aviary lsp`: the language server. The only crate that knows JSON-RPC and the
//! protocol's types; everything it says comes from the pure front end (aviary-syntax,
//! aviary-check, aviary-world, aviary-verify), as `aviary check` and `aviary fmt` say it.
//!
//! One thread reads messages in order and answers each; a change re-checks the open
//! missions (and a world file open alone) and publishes the diagnostics of every file
//! they read (edits that came meanwhile are applied first and checked with it). A panic in a handler is caught, logged to stderr and answered with an
//! error; the server lives on.

use std::collections::{BTreeMap, BTreeSet};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use aviary_check::SourceProvider;
use lsp_server::{Connection, ErrorCode, Message, Notification, Request, Response};
use lsp_types::notification::Notification as _;
use lsp_types::request::Request as _;
use lsp_types::{notification as note, request as req, Uri};
use serde::de::DeserializeOwned;

pub mod analysis;
pub mod bench;
mod complete;
mod diag;
mod edit;
mod explain;
mod hover;
pub mod index;
mod more;
mod nav;
pub mod overlay;
pub mod text;
pub mod uri;

use analysis::Analysis;
use overlay::{Doc, Docs};

/// Reads what an open mission `USE`s from the disk, for the mission at a path.
pub type DiskFactory = dyn Fn(&Path) -> Result<Box<dyn SourceProvider>, String> + Send + Sync;

/// What the server reads beyond the open documents.
pub struct Config {
    /// The disk's provider for a mission (the CLI's `DiskProvider`).
    pub disk: Box<DiskFactory>,
    /// The `--use-root` folders, resolved.
    pub use_roots: Vec<PathBuf>,
}

impl Config {
    /// Reads no file from disk: only open documents are `USE`d.
    pub fn open_documents_only() -> Config {
        Config { disk: Box::new(|_| Ok(Box::new(aviary_check::NoFiles))), use_roots: Vec::new() }
    }
}

/// Serves over stdin and stdout until the client says `exit`.
pub fn serve_stdio(config: Config) -> Result<(), String> {
    let (connection, io) = Connection::stdio();
    run(connection, config)?;
    io.join().map_err(|e| e.to_string())
}

/// Serves over `connection` (stdio, or `Connection::memory()` in tests).
pub fn run(connection: Connection, config: Config) -> Result<(), String> {
    let capabilities = serde_json::to_value(capabilities()).map_err(|e| e.to_string())?;
    connection.initialize(capabilities).map_err(|e| e.to_string())?;
    let mut server =
        Server { config, docs: Docs::new(), analyses: BTreeMap::new(), published: BTreeSet::new() };
    // A message taken while gathering edits, to handle next.
    let mut pending = None;
    loop {
        let message = match pending.take() {
            Some(m) => m,
            None => match connection.receiver.recv() {
                Ok(m) => m,
                Err(_) => break,
            },
        };
        match message {
            Message::Request(request) => {
                if connection.handle_shutdown(&request).map_err(|e| e.to_string())? {
                    return Ok(());
                }
                let response = server.request(request);
                send(&connection, Message::Response(response))?;
            }
            Message::Notification(n) => {
                let mut changed = server.caught_notification(n);
                // The edits that came meanwhile (typing faster than a check): applied
                // together and checked once, so no request waits on stale checks.
                while let Ok(m) = connection.receiver.try_recv() {
                    match m {
                        Message::Notification(n) if is_sync(&n.method) => {
                            changed |= server.caught_notification(n);
                        }
                        other => {
                            pending = Some(other);
                            break;
                        }
                    }
                }
                if changed {
                    match catch_unwind(AssertUnwindSafe(|| server.reanalyse())) {
                        Ok(publish) => {
                            for p in publish {
                                send(&connection, Message::Notification(p))?;
                            }
                        }
                        Err(panic) => {
                            eprintln!("aviary lsp: a check panicked: {}", panic_text(&panic))
                        }
                    }
                }
            }
            Message::Response(_) => {}
        }
    }
    Ok(())
}

/// A notification of the documents' texts.
fn is_sync(method: &str) -> bool {
    [
        note::DidOpenTextDocument::METHOD,
        note::DidChangeTextDocument::METHOD,
        note::DidCloseTextDocument::METHOD,
        note::DidSaveTextDocument::METHOD,
    ]
    .contains(&method)
}

fn send(connection: &Connection, message: Message) -> Result<(), String> {
    connection.sender.send(message).map_err(|e| e.to_string())
}

fn panic_text(panic: &Box<dyn std::any::Any + Send>) -> String {
    if let Some(s) = panic.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = panic.downcast_ref::<String>() {
        s.clone()
    } else {
        "(no message)".into()
    }
}

pub fn capabilities() -> lsp_types::ServerCapabilities {
    use lsp_types::*;
    ServerCapabilities {
        position_encoding: Some(PositionEncodingKind::UTF16),
        text_document_sync: Some(TextDocumentSyncCapability::Kind(
            TextDocumentSyncKind::INCREMENTAL,
        )),
        hover_provider: Some(HoverProviderCapability::Simple(true)),
        completion_provider: Some(CompletionOptions {
            trigger_characters: Some(vec![
                ".".into(),
                " ".into(),
                "(".into(),
                ",".into(),
                "=".into(),
            ]),
            ..CompletionOptions::default()
        }),
        definition_provider: Some(OneOf::Left(true)),
        references_provider: Some(OneOf::Left(true)),
        rename_provider: Some(OneOf::Right(RenameOptions {
            prepare_provider: Some(true),
            work_done_progress_options: WorkDoneProgressOptions::default(),
        })),
        document_formatting_provider: Some(OneOf::Left(true)),
        document_symbol_provider: Some(OneOf::Left(true)),
        folding_range_provider: Some(FoldingRangeProviderCapability::Simple(true)),
        code_action_provider: Some(CodeActionProviderCapability::Simple(true)),
        signature_help_provider: Some(SignatureHelpOptions {
            trigger_characters: Some(vec!["(".into(), ",".into(), " ".into()]),
            ..SignatureHelpOptions::default()
        }),
        semantic_tokens_provider: Some(SemanticTokensServerCapabilities::SemanticTokensOptions(
            SemanticTokensOptions {
                legend: more::legend(),
                full: Some(SemanticTokensFullOptions::Bool(true)),
                ..SemanticTokensOptions::default()
            },
        )),
        ..ServerCapabilities::default()
    }
}

/// A request's failure: the protocol's code and a message.
type Failure = (ErrorCode, String);

fn params<P: DeserializeOwned>(request: &Request) -> Result<P, Failure> {
    serde_json::from_value(request.params.clone())
        .map_err(|e| (ErrorCode::InvalidParams, format!("{}: {e}", request.method)))
}

fn answer<R: serde::Serialize>(r: R) -> Result<serde_json::Value, Failure> {
    serde_json::to_value(r).map_err(|e| (ErrorCode::InternalError, e.to_string()))
}

pub(crate) struct Server {
    config: Config,
    docs: Docs,
    /// By the key of the analysed document.
    analyses: BTreeMap<String, Analysis>,
    /// The URIs last published with diagnostics, to clear those that have none now.
    published: BTreeSet<String>,
}

impl Server {
    fn request(&mut self, request: Request) -> Response {
        let id = request.id.clone();
        match catch_unwind(AssertUnwindSafe(|| self.dispatch(&request))) {
            Ok(Ok(value)) => Response::new_ok(id, value),
            Ok(Err((code, message))) => Response::new_err(id, code as i32, message),
            Err(panic) => {
                let why = panic_text(&panic);
                eprintln!("aviary lsp: {} panicked: {why}", request.method);
                Response::new_err(
                    id,
                    ErrorCode::InternalError as i32,
                    format!("aviary lsp: {} failed: {why}", request.method),
                )
            }
        }
    }

    fn dispatch(&mut self, r: &Request) -> Result<serde_json::Value, Failure> {
        match r.method.as_str() {
            req::HoverRequest::METHOD => answer(hover::hover(self, params(r)?)),
            req::Completion::METHOD => answer(complete::complete(self, params(r)?)),
            req::GotoDefinition::METHOD => answer(nav::definition(self, params(r)?)),
            req::References::METHOD => answer(nav::references(self, params(r)?)),
            req::PrepareRenameRequest::METHOD => answer(nav::prepare_rename(self, params(r)?)),
            req::Rename::METHOD => nav::rename(self, params(r)?).and_then(answer),
            req::Formatting::METHOD => answer(edit::format(self, params(r)?)),
            req::DocumentSymbolRequest::METHOD => answer(edit::symbols(self, params(r)?)),
            req::FoldingRangeRequest::METHOD => answer(edit::folding(self, params(r)?)),
            req::CodeActionRequest::METHOD => answer(edit::code_actions(self, params(r)?)),
            req::SignatureHelpRequest::METHOD => answer(more::signature_help(self, params(r)?)),
            req::SemanticTokensFullRequest::METHOD => {
                answer(more::semantic_tokens(self, params(r)?))
            }
            #[cfg(test)]
            "aviary/panic" => panic!("a handler's bug, on purpose"),
            _ => {
                Err((ErrorCode::MethodNotFound, format!("aviary lsp does not answer {}", r.method)))
            }
        }
    }

    /// [`Server::notification`], a panic caught and logged.
    fn caught_notification(&mut self, n: Notification) -> bool {
        let method = n.method.clone();
        catch_unwind(AssertUnwindSafe(|| self.notification(n))).unwrap_or_else(|panic| {
            eprintln!("aviary lsp: {method} panicked: {}", panic_text(&panic));
            false
        })
    }

    /// Handles a notification; says whether the documents changed.
    fn notification(&mut self, n: Notification) -> bool {
        match n.method.as_str() {
            note::DidOpenTextDocument::METHOD => {
                let Ok(p) =
                    serde_json::from_value::<lsp_types::DidOpenTextDocumentParams>(n.params)
                else {
                    return false;
                };
                let d = p.text_document;
                self.docs
                    .insert(uri::key(&d.uri), Doc { uri: d.uri, text: d.text, version: d.version });
            }
            note::DidChangeTextDocument::METHOD => {
                let Ok(p) =
                    serde_json::from_value::<lsp_types::DidChangeTextDocumentParams>(n.params)
                else {
                    return false;
                };
                let Some(doc) = self.docs.get_mut(&uri::key(&p.text_document.uri)) else {
                    return false;
                };
                for change in p.content_changes {
                    apply(&mut doc.text, change);
                }
                doc.version = p.text_document.version;
            }
            note::DidCloseTextDocument::METHOD => {
                let Ok(p) =
                    serde_json::from_value::<lsp_types::DidCloseTextDocumentParams>(n.params)
                else {
                    return false;
                };
                self.docs.remove(&uri::key(&p.text_document.uri));
            }
            note::DidSaveTextDocument::METHOD | note::DidChangeWatchedFiles::METHOD => {}
            _ => return false,
        }
        true
    }

    /// Checks every open mission again (and each open world file no open mission reads),
    /// and publishes every file's diagnostics: each open document's always, and an empty
    /// list for a file that had some and has none now.
    fn reanalyse(&mut self) -> Vec<Notification> {
        self.analyses.clear();
        for key in self.docs.keys() {
            if !analysis::is_world(key) {
                self.analyses.insert(key.clone(), analysis::mission(key, &self.docs, &self.config));
            }
        }
        let worlds: Vec<String> =
            self.docs.keys().filter(|k| analysis::is_world(k)).cloned().collect();
        for key in worlds {
            let read = self
                .analyses
                .values()
                .any(|a| a.world_file.is_some_and(|w| a.sources.name(w) == key));
            if !read {
                self.analyses
                    .insert(key.clone(), analysis::world_alone(&key, &self.docs, &self.config));
            }
        }
        let mut by_file = diag::by_file(self.analyses.values(), &self.docs);
        for doc in self.docs.values() {
            by_file
                .entry(doc.uri.as_str().to_string())
                .or_insert_with(|| (doc.uri.clone(), Vec::new()));
        }
        let mut out = Vec::new();
        let now: BTreeSet<String> =
            by_file.iter().filter(|(_, (_, d))| !d.is_empty()).map(|(k, _)| k.clone()).collect();
        for gone in self.published.difference(&now) {
            if by_file.contains_key(gone) {
                continue;
            }
            if let Ok(uri) = gone.parse::<Uri>() {
                out.push(publish(uri, Vec::new(), None));
            }
        }
        for (_, (uri, diagnostics)) in by_file {
            let version = self.docs.get(&uri::key(&uri)).map(|d| d.version);
            out.push(publish(uri, diagnostics, version));
        }
        self.published = now;
        out
    }

    /// The open document `uri` and the analysis that read it (its own if it is a mission).
    pub(crate) fn lookup(
        &self,
        uri: &Uri,
    ) -> Option<(&Doc, &Analysis, aviary_diagnostics::FileId)> {
        let key = uri::key(uri);
        let doc = self.docs.get(&key)?;
        if let Some(a) = self.analyses.get(&key) {
            return Some((doc, a, a.root));
        }
        self.analyses.values().find_map(|a| a.file(&key).map(|f| (doc, a, f)))
    }

    pub(crate) fn docs(&self) -> &Docs {
        &self.docs
    }
}

fn publish(
    uri: Uri,
    diagnostics: Vec<lsp_types::Diagnostic>,
    version: Option<i32>,
) -> Notification {
    let params = lsp_types::PublishDiagnosticsParams { uri, diagnostics, version };
    Notification::new(note::PublishDiagnostics::METHOD.to_string(), params)
}

/// Applies one change to a document's text: a range's replacement, or the whole text.
fn apply(text: &mut String, change: lsp_types::TextDocumentContentChangeEvent) {
    match change.range {
        Some(range) => {
            let index = text::LineIndex::new(text);
            let start = index.offset(range.start);
            let end = index.offset(range.end).max(start);
            text.replace_range(start..end, &change.text);
        }
        None => *text = change.text,
    }
}

#[cfg(test)]
mod tests;
