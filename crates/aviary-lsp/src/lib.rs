//! `aviary lsp`: the language server. The only crate that knows JSON-RPC and the
//! protocol's types; everything it says comes from the pure front end (aviary-syntax,
//! aviary-check, aviary-world, aviary-verify), as `aviary check` and `aviary fmt` say it.
//!
//! A change re-checks the open missions (and a world file open alone) and publishes the
//! diagnostics of every file they read; requests are answered each on a thread of its
//! own, over the last check (`serve` says how the two are ordered). A panic in a handler
//! is caught, logged to stderr and answered with an error; the server lives on.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

use std::collections::{BTreeMap, BTreeSet};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use aviary_check::SourceProvider;
use lsp_server::{Connection, ErrorCode, Message, Notification, Request, Response};
use lsp_types::request::Request as _;
use lsp_types::{request as req, Uri};
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
mod serve;
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
    /// A file holding the standard library's text (`aviary_check::STD_SOURCE`), which
    /// is compiled in: go to definition goes there. `None`: it has no file to go to.
    pub std_file: Option<PathBuf>,
}

impl Config {
    /// Reads no file from disk: only open documents are `USE`d.
    pub fn open_documents_only() -> Config {
        Config {
            disk: Box::new(|_| Ok(Box::new(aviary_check::NoFiles))),
            use_roots: Vec::new(),
            std_file: None,
        }
    }
}

/// Serves over stdin and stdout until the client says `exit`.
pub fn serve_stdio(config: Config) -> Result<(), String> {
    let (connection, io) = Connection::stdio();
    run(connection, config)?;
    io.join().map_err(|e| e.to_string())
}

/// Serves over `connection` (stdio, or `Connection::memory()` in tests and the station)
/// until the client says `exit`.
pub fn run(connection: Connection, config: Config) -> Result<(), String> {
    serve::run(connection, config)
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

/// What the server knows after a check: the documents as checked, and each open mission's
/// analysis. Requests read it, each on a thread of its own (`serve`).
pub(crate) struct Server {
    config: Arc<Config>,
    docs: Docs,
    /// By the key of the analysed document.
    analyses: BTreeMap<String, Analysis>,
}

impl Server {
    fn new(config: Arc<Config>, docs: Docs) -> Server {
        Server { config, docs, analyses: BTreeMap::new() }
    }

    fn request(&self, request: Request) -> Response {
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

    fn dispatch(&self, r: &Request) -> Result<serde_json::Value, Failure> {
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
            #[cfg(test)]
            "aviary/slow" => {
                std::thread::sleep(std::time::Duration::from_millis(1500));
                answer("slow")
            }
            _ => {
                Err((ErrorCode::MethodNotFound, format!("aviary lsp does not answer {}", r.method)))
            }
        }
    }

    /// The key of the standard library's file, if the editor was given one.
    fn std_key(&self) -> Option<String> {
        self.config.std_file.as_ref().map(|p| p.to_string_lossy().into_owned())
    }

    /// Checks every open mission (and each open world file no open mission reads), and
    /// says every file's diagnostics: each open document's always, and an empty list for
    /// a file in `published` (the files that had some) that has none now.
    fn analyse(&mut self, published: &mut BTreeSet<String>) -> Vec<Notification> {
        let std_key = self.std_key();
        for key in self.docs.keys() {
            // The standard library's file is read with every mission, not as one.
            if !analysis::is_world(key) && Some(key) != std_key.as_ref() {
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
        for gone in published.difference(&now) {
            if by_file.contains_key(gone) {
                continue;
            }
            if let Ok(uri) = gone.parse::<Uri>() {
                out.push(serve::publish(uri, Vec::new(), None));
            }
        }
        for (_, (uri, diagnostics)) in by_file {
            let version = self.docs.get(&uri::key(&uri)).map(|d| d.version);
            out.push(serve::publish(uri, diagnostics, version));
        }
        *published = now;
        out
    }

    /// The open document `uri` and the analysis that read it (its own if it is a mission;
    /// any mission's for the standard library's file).
    pub(crate) fn lookup(
        &self,
        uri: &Uri,
    ) -> Option<(&Doc, &Analysis, aviary_diagnostics::FileId)> {
        let key = uri::key(uri);
        let doc = self.docs.get(&key)?;
        if let Some(a) = self.analyses.get(&key) {
            return Some((doc, a, a.root));
        }
        let name =
            if Some(&key) == self.std_key().as_ref() { aviary_check::STD_NAME } else { &key };
        self.analyses.values().find_map(|a| a.file(name).map(|f| (doc, a, f)))
    }

    /// The URI of a file an analysis read: the open document's, its path's, and for the
    /// standard library the file it was written to.
    pub(crate) fn uri_of(&self, a: &Analysis, file: aviary_diagnostics::FileId) -> Option<Uri> {
        if a.sources.name(file) == aviary_check::STD_NAME {
            return uri::from_path(self.config.std_file.as_deref()?);
        }
        diag::uri_of(a, file, &self.docs)
    }

    pub(crate) fn docs(&self) -> &Docs {
        &self.docs
    }

    /// Every analysis: each open mission's, and each world file's read alone.
    pub(crate) fn analyses(&self) -> impl Iterator<Item = &Analysis> {
        self.analyses.values()
    }
}

#[cfg(test)]
mod tests;
