//! The event stream's two forms. One event a message, as the trace file has them, for a
//! client that keeps up (`aviary ctl events`): a client that falls `BACKLOG` events
//! behind misses some and is told how many. Or batches (`?every=MS`), for a page: every
//! window, one message with the window's events in order and, of telemetry, only each
//! drone's latest. A batched client's events wait in a queue of its own, so a slow or
//! stalled page never slows the mission and never makes the server hold more than one
//! window's worth of telemetry (a sample per drone) and `QUEUE` other events; beyond
//! that the oldest are let go, and the next batch says how many.
// The operator server runs on a real-time runtime of its own: its streams' periods are real time.
#![allow(clippy::disallowed_methods, clippy::disallowed_types)]

use parking_lot::Mutex;
use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;
use std::time::Duration;

use aviary_api::operator::StreamNote;
use axum::extract::ws::{Message, WebSocket};
use tokio::sync::broadcast::error::RecvError;
use tokio::sync::{broadcast, Notify};

use crate::Line;

/// The most events (telemetry aside) a batched client may have waiting.
const QUEUE: usize = 100_000;

/// What the stream starts with: the history (`?from=start`) and how many of its oldest
/// were let go.
pub(crate) type Past = Option<(Vec<Arc<Line>>, u64)>;

/// Sends the history; `false` when the stream is over (the client left, or the mission
/// had ended).
async fn history(socket: &mut WebSocket, past: Past) -> bool {
    let Some((lines, dropped)) = past else { return true };
    if dropped > 0 {
        let note = note_line(StreamNote::HistoryDropped(dropped));
        if socket.send(Message::Text(note.into())).await.is_err() {
            return false;
        }
    }
    for line in lines {
        if socket.send(Message::Text(line.text.to_string().into())).await.is_err() {
            return false;
        }
        if line.end {
            let _ = socket.send(Message::Close(None)).await;
            return false;
        }
    }
    true
}

/// Every event from now on, one JSON text message each, until the mission ends.
pub(crate) async fn each(
    mut socket: WebSocket,
    past: Past,
    mut rx: broadcast::Receiver<Arc<Line>>,
) {
    if !history(&mut socket, past).await {
        return;
    }
    loop {
        match rx.recv().await {
            Ok(line) => {
                if socket.send(Message::Text(line.text.to_string().into())).await.is_err()
                    || line.end
                {
                    break;
                }
            }
            Err(RecvError::Lagged(missed)) => {
                let note = note_line(StreamNote::Lagged(missed));
                if socket.send(Message::Text(note.into())).await.is_err() {
                    break;
                }
            }
            Err(RecvError::Closed) => break,
        }
    }
    let _ = socket.send(Message::Close(None)).await;
}

/// What a batched client has waiting.
#[derive(Default)]
struct Waiting {
    events: VecDeque<Arc<Line>>,
    /// Each drone's latest sample, by name (in name order, so a batch is the same
    /// whatever order the samples came in).
    telemetry: BTreeMap<Box<str>, Arc<Line>>,
    dropped: u64,
    ended: bool,
}

/// Batches every `every`: the window's events, then each drone's latest telemetry, as one
/// JSON array; `{"dropped": N}` first in the array when events were let go.
pub(crate) async fn batched(
    mut socket: WebSocket,
    past: Past,
    mut rx: broadcast::Receiver<Arc<Line>>,
    every: Duration,
) {
    if !history(&mut socket, past).await {
        return;
    }
    let waiting = Arc::new(Mutex::new(Waiting::default()));
    let woken = Arc::new(Notify::new());
    // The reader drains the broadcast as fast as it comes, whatever the socket does.
    let reader = {
        let waiting = waiting.clone();
        let woken = woken.clone();
        tokio::spawn(async move {
            loop {
                let got = rx.recv().await;
                let mut w = waiting.lock();
                match got {
                    Ok(line) => {
                        let end = line.end;
                        match &line.telemetry_of {
                            Some(actor) => {
                                w.telemetry.insert(actor.clone(), line);
                            }
                            None => {
                                w.events.push_back(line);
                                if w.events.len() > QUEUE {
                                    w.events.pop_front();
                                    w.dropped += 1;
                                }
                            }
                        }
                        if end {
                            w.ended = true;
                            woken.notify_one();
                            break;
                        }
                    }
                    Err(RecvError::Lagged(missed)) => w.dropped += missed,
                    Err(RecvError::Closed) => {
                        w.ended = true;
                        woken.notify_one();
                        break;
                    }
                }
            }
        })
    };
    let mut tick = tokio::time::interval(every);
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    loop {
        tokio::select! {
            biased;
            _ = woken.notified() => {}
            _ = tick.tick() => {}
        }
        let (batch, ended) = {
            let mut w = waiting.lock();
            let taken = std::mem::take(&mut *w);
            w.ended = taken.ended;
            (taken, w.ended)
        };
        if !(batch.events.is_empty() && batch.telemetry.is_empty() && batch.dropped == 0) {
            let mut text = String::from("[");
            let mut first = true;
            let mut push = |s: &str| {
                if !first {
                    text.push(',');
                }
                first = false;
                text.push_str(s);
            };
            let note = note_line(StreamNote::Dropped(batch.dropped));
            if batch.dropped > 0 {
                push(&note);
            }
            for line in batch.events.iter().chain(batch.telemetry.values()) {
                push(&line.text);
            }
            text.push(']');
            if socket.send(Message::Text(text.into())).await.is_err() {
                break;
            }
        }
        if ended {
            break;
        }
    }
    reader.abort();
    let _ = socket.send(Message::Close(None)).await;
}

/// A note as the stream sends it: `{"lagged": 12}`.
fn note_line(note: StreamNote) -> String {
    serde_json::to_string(&note).unwrap_or_default()
}
