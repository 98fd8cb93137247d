//! The sockets: a TCP listener (any number of ground stations) or a UDP socket (`udp`),
//! each client with its own queue (`client`), and the pacing task that steps the
//! simulation at `speed` times real time and fills every client's queue with the streams
//! it asked for.
// The vehicles pace themselves in real time, as a SITL does: tokio's timer, not the run's clock.
#![allow(clippy::disallowed_methods, clippy::disallowed_types)]

use parking_lot::Mutex;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use aviary_mavlink::mavlink::dialects::ardupilotmega::MavMessage;
use aviary_mavlink::mavlink::{self, AsyncMavlinkReader, MAVLinkMessageRaw, Message};
use aviary_mavlink::mavlink::{SigningConfig, SigningData};
use tokio::io::AsyncRead;
use tokio::net::{TcpListener, TcpStream};
use tokio::time::Instant;

use crate::autopilot::{Autopilot, Out, Reply, To};
use crate::client::{Client, Registry, Sequences};
use crate::dispatch::{dispatch, dispatch_unparsed};
use crate::wire::{unparsed_command, Wire};

/// Where to listen: `tcp:HOST:PORT` or `udp:HOST:PORT` (port 0: any free one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Listen {
    Tcp(SocketAddr),
    Udp(SocketAddr),
}

pub fn parse_listen(text: &str) -> Result<Listen, String> {
    let bad = || {
        format!("`{text}` is not an address to listen on: write tcp:127.0.0.1:5760 or udp:127.0.0.1:14550")
    };
    let (scheme, rest) = text.split_once(':').ok_or_else(bad)?;
    let addr: SocketAddr = rest.parse().map_err(|_| bad())?;
    match scheme {
        "tcp" | "tcpin" => Ok(Listen::Tcp(addr)),
        "udp" | "udpin" => Ok(Listen::Udp(addr)),
        _ => Err(bad()),
    }
}

pub(crate) type Shared = Arc<Mutex<Autopilot>>;

/// Steps the simulation in real time × `speed` (whole physics ticks, so the simulator
/// behaves as in `aviary run`), tells every client what happened, and queues each client
/// the streams that are due for it, at the rates it asked for, of the vehicles' own time:
/// as a SITL run faster than real time (ArduPilot's `--speedup`, PX4's speed factor)
/// sends its heartbeat once a second of its own clock, so more often by the wall's.
pub(crate) async fn pace(ap: Shared, clients: Arc<Registry>, tick: f64, speed: f64) {
    let mut every = tokio::time::interval(Duration::from_millis(10));
    every.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let start = Instant::now();
    let mut ticks = 0u64;
    loop {
        every.tick().await;
        let wall = start.elapsed().as_secs_f64();
        let mut ap = ap.lock();
        let mut events = Vec::new();
        while (ticks as f64 + 1.0) * tick <= wall * speed {
            events.extend(ap.step(tick));
            ticks += 1;
        }
        tell(&ap, &clients.all(), events, ticks as f64 * tick);
    }
}

/// Tells each client what happened (`events`) and queues it the streams due for it at
/// `time` seconds of the vehicles' clock, at the rates it asked for. A vehicle whose
/// radio is down says nothing.
pub(crate) fn tell(ap: &Autopilot, clients: &[Arc<Client>], mut events: Vec<Out>, time: f64) {
    let up: Vec<usize> = (0..ap.copters.len()).filter(|i| ap.link(*i)).collect();
    events.retain(|e: &Out| up.iter().any(|i| ap.copters[*i].system == e.system));
    for c in clients {
        for e in &events {
            c.event(e.clone());
        }
        let mut schedule = c.schedule.lock();
        for &i in &up {
            let system = ap.copters[i].system;
            for &(id, hz) in ap.streams() {
                if !schedule.due(system, id, hz, time) {
                    continue;
                }
                if let Some(msg) = ap.message(i, id) {
                    let o = Out { system, msg: msg.into() };
                    if id == 0 {
                        c.heartbeat(o);
                    } else {
                        c.telemetry(o);
                    }
                }
            }
        }
    }
}

pub(crate) fn signing(key: Option<[u8; 32]>) -> Option<SigningData> {
    key.map(|k| SigningData::from_config(SigningConfig::new(k, 0, true, false)))
}

/// What a raw frame from `client` asks, answered: to `client`, or to every client.
fn receive(ap: &Shared, client: &Client, clients: &Registry, raw: &MAVLinkMessageRaw) {
    let from = (u8::try_from(raw.system_id()).unwrap_or(0), raw.component_id());
    let replies = {
        let mut ap = ap.lock();
        match MavMessage::parse(raw.version(), raw.message_id(), raw.payload()) {
            Ok(msg) => dispatch(&mut ap, client, from, &msg),
            Err(_) => match unparsed_command(raw.message_id(), raw.payload()) {
                Some(u) => dispatch_unparsed(&ap, from, u),
                None => Vec::new(),
            },
        }
    };
    route(replies, client, clients);
}

fn route(replies: Vec<Reply>, asker: &Client, clients: &Registry) {
    let everyone = if replies.iter().any(|r| r.to == To::All) { clients.all() } else { Vec::new() };
    for r in replies {
        match r.to {
            To::Asker => asker.event(r.out),
            To::All => {
                for c in &everyone {
                    c.event(r.out.clone());
                }
            }
        }
    }
}

/// Reads frames until the source ends (a TCP connection closed, a datagram read).
pub(crate) async fn read_all<R: AsyncRead + Unpin>(
    source: R,
    sign: Option<&SigningData>,
    ap: &Shared,
    client: &Client,
    clients: &Registry,
) {
    let mut reader = AsyncMavlinkReader::new(source);
    loop {
        match reader.read_any_raw_message_signed::<Wire>(sign).await {
            Ok(raw) => receive(ap, client, clients, &raw),
            Err(mavlink::error::MessageReadError::Io(_)) => return,
            // A frame that is not MAVLink, fails its checksum or its signature: skipped.
            Err(_) => {}
        }
    }
}

pub(crate) fn frame(
    sequences: &mut Sequences,
    o: &Out,
    sign: Option<&SigningData>,
) -> Option<Vec<u8>> {
    let mut buf = Vec::with_capacity(64);
    let header = sequences.header(o.system);
    // Writing into a Vec cannot fail.
    mavlink::write_v2_msg_signed(&mut buf, header, &o.msg, sign).ok().map(|_| buf)
}

pub(crate) async fn tcp(
    listener: TcpListener,
    ap: Shared,
    clients: Arc<Registry>,
    key: Option<[u8; 32]>,
) {
    let sign = Arc::new(signing(key));
    let mut backoff = Duration::from_millis(10);
    loop {
        match listener.accept().await {
            Ok((stream, _)) => {
                backoff = Duration::from_millis(10);
                connection(stream, Arc::clone(&ap), Arc::clone(&clients), Arc::clone(&sign));
            }
            Err(e) => {
                // Out of file descriptors, a connection reset before it was taken: the
                // listener is still good. Say so, give the system a moment, go on.
                eprintln!("aviary vehicles: cannot accept a connection: {e}; trying again");
                tokio::time::sleep(backoff).await;
                backoff = (backoff * 2).min(Duration::from_secs(1));
            }
        }
    }
}

fn connection(
    stream: TcpStream,
    ap: Shared,
    clients: Arc<Registry>,
    sign: Arc<Option<SigningData>>,
) {
    let _ = stream.set_nodelay(true);
    let (read, mut write) = stream.into_split();
    let client = Arc::new(Client::new());
    clients.add(Arc::clone(&client));
    let (c, sign_w) = (Arc::clone(&client), Arc::clone(&sign));
    let writer = tokio::spawn(async move {
        let mut sequences = Sequences::new();
        loop {
            let o = c.next().await;
            let Some(bytes) = frame(&mut sequences, &o, sign_w.as_ref().as_ref()) else {
                continue;
            };
            if tokio::io::AsyncWriteExt::write_all(&mut write, &bytes).await.is_err() {
                return;
            }
        }
    });
    let writer_handle = writer.abort_handle();
    let c = Arc::clone(&client);
    let reader = tokio::spawn(async move {
        read_all(read, sign.as_ref().as_ref(), &ap, &c, &clients).await;
        writer.abort();
        clients.remove(c.id);
    });
    let mut tasks = client.tasks.lock();
    tasks.extend([writer_handle, reader.abort_handle()]);
}
