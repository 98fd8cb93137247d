//! The `fuzz_lsp` target: arbitrary bytes as the frames a page's editor sends the station's
//! language server (`GET /api/lsp`, one JSON-RPC message a text frame), here one frame a
//! line. Each line is read as the station reads a frame (a line that is no message is
//! answered there with -32700 and never reaches the server), and the messages go to
//! `aviary_lsp::run` over an in-memory connection, as the station's bridge sends them;
//! then the input ends, as when the page closes. Properties: no panic anywhere, a handler's
//! caught by the server included; the server ends once its input does (no hang); every
//! message it sends can be framed; and once it has answered `shutdown`, it has answered
//! every request sent before it.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Once;
use std::time::{Duration, Instant};

use lsp_server::{Connection, Message, RequestId};

/// How long the server may take to end after its input: far more than any input needs.
const DEADLINE: Duration = Duration::from_secs(60);

/// Set by any panic on any thread, caught or not: the server catches its handlers'
/// panics and answers with an error, which would hide a bug from AFL.
static PANICKED: AtomicBool = AtomicBool::new(false);

fn note_panics() {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            PANICKED.store(true, Ordering::SeqCst);
            previous(info);
        }));
    });
}

pub fn lsp(data: &[u8]) {
    note_panics();
    let (server, client) = Connection::memory();
    // The station's own stack for a language server's thread (a check of a deep mission
    // recurses).
    let served = std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(move || aviary_lsp::run(server, aviary_lsp::Config::open_documents_only()))
        .expect("the server's thread");
    let Connection { sender, receiver } = client;
    // The requests sent before the first `shutdown`, and that one's id.
    let mut asked: Vec<RequestId> = Vec::new();
    let mut shutdown: Option<RequestId> = None;
    for line in data.split(|b| *b == b'\n') {
        let Ok(message) = serde_json::from_slice::<Message>(line) else { continue };
        if let (Message::Request(r), None) = (&message, &shutdown) {
            match r.method == "shutdown" {
                true => shutdown = Some(r.id.clone()),
                false => asked.push(r.id.clone()),
            }
        }
        if sender.send(message).is_err() {
            break; // the server ended (`exit`)
        }
    }
    drop(sender);
    let mut answered: Vec<RequestId> = Vec::new();
    let start = Instant::now();
    loop {
        match receiver.recv_timeout(Duration::from_millis(50)) {
            Ok(message) => {
                let framed =
                    serde_json::to_value(&message).expect("a message the server sends is JSON");
                assert!(framed.is_object(), "a message the server sends is an object: {framed}");
                if let Message::Response(r) = message {
                    answered.push(r.id);
                }
            }
            Err(crossbeam_channel::RecvTimeoutError::Disconnected) => break,
            Err(crossbeam_channel::RecvTimeoutError::Timeout) => {
                if served.is_finished() && receiver.is_empty() {
                    break;
                }
                assert!(
                    start.elapsed() < DEADLINE,
                    "the language server did not end with its input"
                );
            }
        }
    }
    // `Err` is an ending the station reports (a page that closed before `initialize`).
    let _ = served.join().expect("the language server's thread does not panic");
    assert!(!PANICKED.load(Ordering::SeqCst), "a panic in the language server (see above)");
    if shutdown.is_some_and(|id| answered.contains(&id)) {
        for id in asked {
            let i = answered.iter().position(|a| *a == id);
            let i = i.unwrap_or_else(|| panic!("request {id} was not answered before shutdown"));
            answered.swap_remove(i);
        }
    }
}
