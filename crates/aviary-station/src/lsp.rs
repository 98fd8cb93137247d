//! `GET /api/lsp`: the language server of `aviary lsp` (aviary-lsp) over a WebSocket, for
//! the page's editor. One server per socket, on a blocking thread, spoken to through
//! `lsp_server::Connection::memory()`; each text frame is one JSON-RPC message, without
//! the `Content-Length` header of stdio.
//!
//! Invariants: a frame that is not a JSON-RPC message is answered with a parse error
//! (-32700) and the socket lives on; either side's end ends the other (the page's close
//! drops the server's input, so its loop ends; the server's end closes the socket); at
//! most [`MAX_SOCKETS`] servers at once, each holding the documents its page opened.

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::sync::Arc;

use aviary_server::error;
use axum::extract::ws::rejection::WebSocketUpgradeRejection;
use axum::extract::ws::{CloseFrame, Message as Frame, WebSocket, WebSocketUpgrade};
use axum::extract::State;
use axum::http::StatusCode;
use axum::response::Response;
use lsp_server::{Connection, Message};

use crate::{Mode, Station};

/// How many language servers a station runs at once: one per page's editor, so a few
/// operators' pages; one more socket is refused (503) until one closes.
pub const MAX_SOCKETS: usize = 4;

/// The largest frame taken: a `didOpen` of the largest file the station opens, escaped.
const MAX_FRAME: usize = 3 * crate::dir::MAX_FILE_BYTES as usize;

/// Makes the language server's configuration for one socket: the command line's, as
/// `aviary lsp` has it (its disk provider and `--use-root`s).
#[derive(Clone)]
pub struct Lsp(Arc<dyn Fn() -> aviary_lsp::Config + Send + Sync>);

impl Lsp {
    pub fn new(make: impl Fn() -> aviary_lsp::Config + Send + Sync + 'static) -> Lsp {
        Lsp(Arc::new(make))
    }
}

impl std::fmt::Debug for Lsp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Lsp(..)")
    }
}

/// The route: a socket to a language server of its own, if the station has one to give.
pub(crate) async fn socket(
    State(station): State<Arc<Station>>,
    ws: Result<WebSocketUpgrade, WebSocketUpgradeRejection>,
) -> Response {
    let Some(lsp) = station.lsp.clone() else {
        return error(
            StatusCode::NOT_FOUND,
            "this station has no language server: `aviary gcs DIR` serves one beside its editor",
        );
    };
    let ws = match ws {
        Ok(ws) => ws,
        Err(rejection) => {
            return error(
                rejection.status(),
                format!("{}: open it as a WebSocket", rejection.body_text()),
            )
        }
    };
    if station.lsp_sockets.fetch_add(1, Ordering::SeqCst) >= MAX_SOCKETS {
        station.lsp_sockets.fetch_sub(1, Ordering::SeqCst);
        return error(
            StatusCode::SERVICE_UNAVAILABLE,
            format!("the station runs {MAX_SOCKETS} language servers already: close another page's editor"),
        );
    }
    let mut config = (lsp.0)();
    if let Mode::Folder { folder, .. } = &station.mode {
        config = within(config, folder.root().to_path_buf());
    }
    let failed = station.clone();
    // A browser that offered `aviary` (beside its token) must get it back, or it drops the socket.
    ws.protocols(["aviary"])
        .max_message_size(MAX_FRAME)
        .on_failed_upgrade(move |_| {
            failed.lsp_sockets.fetch_sub(1, Ordering::SeqCst);
        })
        .on_upgrade(move |socket| async move {
            bridge(socket, config).await;
            station.lsp_sockets.fetch_sub(1, Ordering::SeqCst);
        })
}

/// The configuration, reading from disk only for missions inside the station's folder
/// (`root`), as the page names files only there.
fn within(mut config: aviary_lsp::Config, root: PathBuf) -> aviary_lsp::Config {
    let disk = config.disk;
    config.disk = Box::new(move |mission: &Path| {
        if mission.starts_with(&root) && !mission.components().any(|c| c.as_os_str() == "..") {
            disk(mission)
        } else {
            Err(format!(
                "{} is outside the station's folder {}: the station reads no file there",
                mission.display(),
                root.display()
            ))
        }
    });
    config
}

/// Carries frames to the server and its messages back until either side ends, then waits
/// for the server's thread.
async fn bridge(mut socket: WebSocket, config: aviary_lsp::Config) {
    let (server, client) = Connection::memory();
    let served = tokio::task::spawn_blocking(move || aviary_lsp::run(server, config));
    let Connection { sender: to_server, receiver: from_server } = client;
    // The server's messages, from its blocking channel onto this task.
    let (out, mut outgoing) = tokio::sync::mpsc::channel::<Message>(64);
    let forwarded = tokio::task::spawn_blocking(move || {
        while let Ok(m) = from_server.recv() {
            if out.blocking_send(m).is_err() {
                break;
            }
        }
    });
    loop {
        tokio::select! {
            frame = socket.recv() => match frame {
                Some(Ok(Frame::Text(text))) => match serde_json::from_str::<Message>(text.as_str()) {
                    // The channel is unbounded: a send never blocks, and fails only when the
                    // server has ended.
                    Ok(m) => if to_server.send(m).is_err() { break },
                    Err(e) => {
                        if socket.send(Frame::Text(parse_error(&e.to_string()).into())).await.is_err() {
                            break;
                        }
                    }
                },
                Some(Ok(Frame::Binary(_))) => {
                    let answer = parse_error("a binary frame: send each JSON-RPC message as one text frame");
                    if socket.send(Frame::Text(answer.into())).await.is_err() {
                        break;
                    }
                }
                Some(Ok(Frame::Ping(_) | Frame::Pong(_))) => {}
                Some(Ok(Frame::Close(_))) | Some(Err(_)) | None => break,
            },
            message = outgoing.recv() => match message {
                Some(m) => {
                    let Some(text) = framed(&m) else { continue };
                    if socket.send(Frame::Text(text.into())).await.is_err() {
                        break;
                    }
                }
                None => {
                    let close = CloseFrame { code: 1000, reason: "the language server ended".into() };
                    let _ = socket.send(Frame::Close(Some(close))).await;
                    break;
                }
            },
        }
    }
    // The page is gone or the server ended: without its input the server's loop ends.
    drop(to_server);
    drop(outgoing);
    match served.await {
        Ok(Ok(())) => {}
        // A page that closes before `initialize`, or without `shutdown`, is no error.
        Ok(Err(why)) => eprintln!("aviary gcs: a language server ended: {why}"),
        Err(e) => eprintln!("aviary gcs: a language server's thread failed: {e}"),
    }
    let _ = forwarded.await;
}

/// A message of the server as one frame: its JSON with `"jsonrpc": "2.0"`, which
/// lsp-server adds only when it writes to stdio.
fn framed(message: &Message) -> Option<String> {
    match serde_json::to_value(message) {
        Ok(serde_json::Value::Object(mut fields)) => {
            fields.insert("jsonrpc".into(), "2.0".into());
            Some(serde_json::Value::Object(fields).to_string())
        }
        Ok(other) => {
            eprintln!("aviary gcs: a language server message that is no JSON object: {other}");
            None
        }
        Err(e) => {
            eprintln!("aviary gcs: a language server message that is not JSON: {e}");
            None
        }
    }
}

/// JSON-RPC's answer to a frame that is not a message: a response without an id.
fn parse_error(why: &str) -> String {
    #[derive(serde::Serialize)]
    struct Unanswerable {
        jsonrpc: &'static str,
        id: Option<lsp_server::RequestId>,
        error: lsp_server::ResponseError,
    }
    let message: String = why.chars().take(300).collect();
    let error = lsp_server::ResponseError {
        code: lsp_server::ErrorCode::ParseError as i32,
        message: format!("not a JSON-RPC message: {message}"),
        data: None,
    };
    serde_json::to_string(&Unanswerable { jsonrpc: "2.0", id: None, error }).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn a_message_is_framed_as_json_rpc() {
        let m = Message::Notification(lsp_server::Notification::new("x".into(), json!({})));
        let framed: serde_json::Value = serde_json::from_str(&framed(&m).unwrap()).unwrap();
        assert_eq!(framed, json!({ "jsonrpc": "2.0", "method": "x", "params": {} }));
    }

    #[test]
    fn a_parse_error_is_json_rpc() {
        let answer: serde_json::Value =
            serde_json::from_str(&parse_error("expected value")).unwrap();
        assert_eq!(answer["error"]["code"], -32700);
        assert!(answer["id"].is_null());
        assert_eq!(answer["jsonrpc"], "2.0");
    }

    #[test]
    fn the_disk_is_read_only_for_missions_in_the_folder() {
        let config =
            within(aviary_lsp::Config::open_documents_only(), PathBuf::from("/srv/missions"));
        assert!((config.disk)(Path::new("/srv/missions/a.mission")).is_ok());
        let outside = (config.disk)(Path::new("/etc/a.mission")).err().unwrap();
        assert!(outside.contains("outside the station's folder"), "{outside}");
        assert!((config.disk)(Path::new("/srv/missions/../a.mission")).is_err());
    }
}
