//! `/api/lsp`: the editor's language server over a real WebSocket, against the real router
//! served on a loopback socket. Refused without the token; with it, `initialize`, then a
//! mission opened gets its diagnostics; a frame that is no JSON-RPC message gets a parse
//! error and the socket lives on; `shutdown` and `exit` end the server, which closes the
//! socket.

#![cfg(unix)]

use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};

use aviary_check::{NoFiles, SourceProvider};
use aviary_station::{FilesFor, Folder, Lsp, Mode};
use serde_json::{json, Value};
use tungstenite::client::IntoClientRequest;
use tungstenite::{Message, WebSocket};

const TOKEN: &str = "00112233445566778899aabbccddeeff";

/// The paper's mission and world in a folder of their own.
fn folder(name: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("station_lsp_{name}"));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(&root).unwrap();
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    for file in ["search_and_rescue.mission", "search_and_rescue.world.toml"] {
        std::fs::copy(examples.join(file), root.join(file)).unwrap();
    }
    std::fs::canonicalize(root).unwrap()
}

/// A station of `root` served on a loopback port of its own, for the test's lifetime.
fn serve(root: &Path) -> SocketAddr {
    let std_listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    std_listener.set_nonblocking(true).unwrap();
    let bound = std_listener.local_addr().unwrap();
    let files: FilesFor =
        Box::new(|_: &Path| Ok(Box::new(NoFiles) as Box<dyn SourceProvider + Send>));
    let mode = Mode::Folder { folder: Folder::new(root).unwrap(), files };
    let lsp = Lsp::new(aviary_lsp::Config::open_documents_only);
    let app = aviary_station::router(mode, bound, TOKEN.into(), &[], Value::Null, Some(lsp));
    std::thread::spawn(move || {
        let runtime = tokio::runtime::Builder::new_multi_thread().enable_all().build().unwrap();
        runtime.block_on(async move {
            let listener = tokio::net::TcpListener::from_std(std_listener).unwrap();
            axum::serve(listener, app).await.unwrap();
        });
    });
    bound
}

/// Opens `/api/lsp` offering `protocols`: the socket, or the status it was refused with.
fn open(at: SocketAddr, protocols: &str) -> Result<WebSocket<TcpStream>, u16> {
    opened(at, protocols).map(|(socket, _)| socket)
}

/// The socket and the protocol the station chose.
fn opened(at: SocketAddr, protocols: &str) -> Result<(WebSocket<TcpStream>, String), u16> {
    let mut request = format!("ws://{at}/api/lsp").into_client_request().unwrap();
    if !protocols.is_empty() {
        request.headers_mut().insert("Sec-WebSocket-Protocol", protocols.parse().unwrap());
    }
    let stream = TcpStream::connect(at).unwrap();
    stream.set_read_timeout(Some(std::time::Duration::from_secs(60))).unwrap();
    match tungstenite::client(request, stream) {
        Ok((socket, response)) => {
            let chosen = response.headers().get("sec-websocket-protocol");
            Ok((socket, chosen.and_then(|p| p.to_str().ok()).unwrap_or("").to_string()))
        }
        Err(tungstenite::HandshakeError::Failure(tungstenite::Error::Http(response))) => {
            Err(response.status().as_u16())
        }
        Err(e) => panic!("the handshake failed otherwise: {e}"),
    }
}

fn with_token() -> String {
    format!("aviary, aviary.bearer.{TOKEN}")
}

fn send(socket: &mut WebSocket<TcpStream>, message: Value) {
    socket.send(Message::text(message.to_string())).unwrap();
}

/// The next JSON-RPC message the server sends that `wanted` accepts (others are skipped).
fn until(socket: &mut WebSocket<TcpStream>, wanted: impl Fn(&Value) -> bool) -> Value {
    loop {
        match socket.read().expect("the socket is open") {
            Message::Text(text) => {
                let message: Value = serde_json::from_str(text.as_str()).expect("a frame is JSON");
                assert_eq!(message["jsonrpc"], "2.0", "{message}");
                if wanted(&message) {
                    return message;
                }
            }
            Message::Close(frame) => panic!("the socket closed: {frame:?}"),
            _ => {}
        }
    }
}

fn did_open(socket: &mut WebSocket<TcpStream>, uri: &str, language: &str, text: &str) {
    let document = json!({ "uri": uri, "languageId": language, "version": 1, "text": text });
    send(
        socket,
        json!({ "jsonrpc": "2.0", "method": "textDocument/didOpen", "params": { "textDocument": document } }),
    );
}

#[test]
fn the_socket_needs_the_token_even_on_loopback() {
    let at = serve(&folder("token"));
    assert_eq!(open(at, "").err(), Some(401), "no token");
    assert_eq!(open(at, "aviary").err(), Some(401), "no token among the protocols");
    assert_eq!(open(at, "aviary, aviary.bearer.0123").err(), Some(401), "a wrong token");
    let (_, protocol) = opened(at, &with_token()).expect("the token opens it");
    assert_eq!(protocol, "aviary", "the page's protocol is chosen, never the token's");
}

#[test]
fn a_mission_opened_gets_its_diagnostics_and_a_malformed_frame_an_error() {
    let root = folder("diagnostics");
    let at = serve(&root);
    let mut socket = open(at, &with_token()).expect("the socket opens");

    send(
        &mut socket,
        json!({ "jsonrpc": "2.0", "id": 1, "method": "initialize", "params": { "capabilities": {} } }),
    );
    let init = until(&mut socket, |m| m["id"] == 1);
    assert!(init["result"]["capabilities"]["hoverProvider"].as_bool().unwrap_or(false), "{init}");
    assert!(init["result"]["capabilities"]["completionProvider"].is_object(), "{init}");
    send(&mut socket, json!({ "jsonrpc": "2.0", "method": "initialized", "params": {} }));

    // Not JSON, JSON but no message, and a binary frame: each answered, none fatal.
    for bad in [Message::text("{not json"), Message::text("[1, 2]"), Message::binary(vec![0u8, 1])]
    {
        socket.send(bad).unwrap();
        let error = until(&mut socket, |m| m.get("error").is_some());
        assert_eq!(error["error"]["code"], -32700, "{error}");
        assert!(error["id"].is_null(), "{error}");
    }

    let mission = std::fs::read_to_string(root.join("search_and_rescue.mission")).unwrap();
    let world = std::fs::read_to_string(root.join("search_and_rescue.world.toml")).unwrap();
    let broken = mission.replacen("FlyTo WITH BuildingA", "FlyTo WITH Nowhere", 1);
    let line = broken.lines().position(|l| l.contains("Nowhere")).unwrap();
    let uri = format!("file://{}/search_and_rescue.mission", root.display());
    did_open(
        &mut socket,
        &format!("file://{}/search_and_rescue.world.toml", root.display()),
        "toml",
        &world,
    );
    did_open(&mut socket, &uri, "aviary", &broken);
    let published = until(&mut socket, |m| {
        m["method"] == "textDocument/publishDiagnostics"
            && m["params"]["uri"] == uri.as_str()
            && m["params"]["diagnostics"].as_array().is_some_and(|d| !d.is_empty())
    });
    let diagnostics = published["params"]["diagnostics"].as_array().unwrap();
    let unknown = diagnostics
        .iter()
        .find(|d| d["message"].as_str().unwrap_or("").contains("Nowhere"))
        .unwrap_or_else(|| panic!("the unknown place is reported: {published}"));
    assert_eq!(unknown["range"]["start"]["line"], line, "on its line: {unknown}");
    assert_eq!(unknown["severity"], 1, "an error: {unknown}");

    // The socket lived on through the bad frames: a request is still answered.
    let hover =
        json!({ "textDocument": { "uri": uri }, "position": { "line": line, "character": 4 } });
    send(
        &mut socket,
        json!({ "jsonrpc": "2.0", "id": 2, "method": "textDocument/hover", "params": hover }),
    );
    let answer = until(&mut socket, |m| m["id"] == 2);
    assert!(answer.get("error").is_none(), "{answer}");

    // `shutdown`, `exit`: the server ends, and the station closes the socket.
    send(&mut socket, json!({ "jsonrpc": "2.0", "id": 3, "method": "shutdown" }));
    until(&mut socket, |m| m["id"] == 3);
    send(&mut socket, json!({ "jsonrpc": "2.0", "method": "exit" }));
    loop {
        match socket.read() {
            Ok(Message::Close(frame)) => {
                assert_eq!(frame.map(|f| u16::from(f.code)), Some(1000), "a normal close");
                break;
            }
            Ok(_) => {}
            Err(e) => panic!("the socket ended without a close frame: {e}"),
        }
    }
}

#[test]
fn a_few_servers_at_once_and_another_is_refused_until_one_closes() {
    let at = serve(&folder("limit"));
    let mut open_now: Vec<_> =
        (0..aviary_station::MAX_LSP_SOCKETS).map(|_| open(at, &with_token()).unwrap()).collect();
    assert_eq!(open(at, &with_token()).err(), Some(503), "one more is refused");
    let mut first = open_now.remove(0);
    first.close(None).unwrap();
    // Its server ends once the station sees the close: then a new socket opens.
    let _ = first.read();
    let reopened = (0..100).find_map(|_| {
        std::thread::sleep(std::time::Duration::from_millis(50));
        open(at, &with_token()).ok()
    });
    assert!(reopened.is_some(), "a socket opens again once one closed");
}

/// A mission named outside the station's folder: the server reads nothing of the disk for
/// it, not even the world file beside it, so nothing of that file reaches the page.
#[test]
fn nothing_beside_a_mission_outside_the_folder_is_read() {
    let root = folder("outside");
    let outside = root.with_file_name("station_lsp_outside_secret");
    let _ = std::fs::remove_dir_all(&outside);
    std::fs::create_dir_all(&outside).unwrap();
    // A world whose error would quote the file.
    std::fs::write(outside.join("probe.world.toml"), "[site]\nsecret = \"the-hidden-text\"\n")
        .unwrap();
    let at = serve(&root);
    let mut socket = open(at, &with_token()).expect("the socket opens");
    send(
        &mut socket,
        json!({ "jsonrpc": "2.0", "id": 1, "method": "initialize", "params": { "capabilities": {} } }),
    );
    until(&mut socket, |m| m["id"] == 1);
    send(&mut socket, json!({ "jsonrpc": "2.0", "method": "initialized", "params": {} }));
    let uri = format!("file://{}/probe.mission", outside.display());
    did_open(&mut socket, &uri, "aviary", "MISSION Probe:\n    a TakeOff\n");
    let published = until(&mut socket, |m| {
        m["method"] == "textDocument/publishDiagnostics" && m["params"]["uri"] == uri.as_str()
    });
    let text = published.to_string();
    assert!(!text.contains("hidden-text") && !text.contains("probe.world.toml"), "{text}");
    // Checked as a mission with no world: its drone is unknown to it.
    assert!(text.contains("N302") || text.contains("no world"), "{text}");
}
