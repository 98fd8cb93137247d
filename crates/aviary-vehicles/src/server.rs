//! The sockets: a TCP listener (any number of ground stations) or a UDP socket (every
//! peer that has sent a datagram), and the pacing task that steps the simulation at
//! `speed` times real time and sends each vehicle's telemetry.

use std::net::SocketAddr;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use aviary_mavlink::mavlink::dialects::ardupilotmega::{MavFrame, MavMessage, MavSeverity};
use aviary_mavlink::mavlink::{self, AsyncMavlinkReader, MavHeader, SigningConfig, SigningData};
use tokio::net::{TcpListener, UdpSocket};
use tokio::sync::broadcast;

use crate::autopilot::{ack, text, Autopilot, Out};

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

pub(crate) fn lock(ap: &Shared) -> MutexGuard<'_, Autopilot> {
    ap.lock().unwrap_or_else(|p| p.into_inner())
}

/// One message from a ground station: what the vehicles answer. SET_MODE and
/// REQUEST_DATA_STREAM are deprecated, but pymavlink's `set_mode` and older ground
/// stations still send them, and ArduPilot still takes them.
#[allow(deprecated)]
fn dispatch(ap: &Shared, msg: &MavMessage) -> Vec<Out> {
    let mut ap = lock(ap);
    let target = match msg {
        MavMessage::COMMAND_LONG(c) => c.target_system,
        MavMessage::COMMAND_INT(c) => c.target_system,
        MavMessage::SET_MODE(m) => m.target_system,
        MavMessage::SET_POSITION_TARGET_GLOBAL_INT(t) => t.target_system,
        MavMessage::REQUEST_DATA_STREAM(r) => r.target_system,
        _ => return Vec::new(),
    };
    // A vehicle whose radio is down (a world `link_loss` fault) hears nothing.
    let Some(i) = ap.index(target).filter(|i| ap.link(*i)) else {
        return Vec::new();
    };
    let system = ap.copters[i].system;
    let answer = |command, (result, why): (_, Option<String>)| {
        let mut out = Vec::new();
        if let Some(why) = why {
            out.push(text(system, MavSeverity::MAV_SEVERITY_WARNING, &why));
        }
        out.push(ack(system, command, result));
        out
    };
    match msg {
        MavMessage::COMMAND_LONG(c) => {
            let p = [
                c.param1, c.param2, c.param3, c.param4, c.param5, c.param6, c.param7,
            ];
            let r = ap.command(i, c.command, p, None);
            answer(c.command, r)
        }
        MavMessage::COMMAND_INT(c) => {
            let relative =
                matches!(c.frame, MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT) || c.frame as u32 == 6;
            let at = relative.then_some((c.x, c.y, c.z));
            let r = ap.command(
                i,
                c.command,
                [c.param1, c.param2, c.param3, c.param4, 0.0, 0.0, 0.0],
                at,
            );
            answer(c.command, r)
        }
        MavMessage::SET_MODE(m) => {
            let r = ap.set_mode(i, m.custom_mode);
            answer(
                aviary_mavlink::mavlink::dialects::ardupilotmega::MavCmd::MAV_CMD_DO_SET_MODE,
                r,
            )
        }
        MavMessage::SET_POSITION_TARGET_GLOBAL_INT(t) => {
            // Ignored outside GUIDED or on the ground, silently, as ArduCopter does.
            let _ = ap.goto(i, t.lat_int, t.lon_int, f64::from(t.alt));
            Vec::new()
        }
        MavMessage::REQUEST_DATA_STREAM(r) => {
            if r.start_stop == 1
                && r.req_message_rate > 0
                && matches!(r.req_stream_id as u32, 0 | 6)
            {
                ap.position_hz = f64::from(r.req_message_rate).clamp(0.2, 50.0);
            }
            Vec::new()
        }
        _ => Vec::new(),
    }
}

/// Steps the simulation in real time × `speed` (whole physics ticks, so the simulator
/// behaves as in `aviary run`) and sends HEARTBEAT and the status messages once a second
/// and positions at the asked rate, of wall time.
pub(crate) async fn pace(ap: Shared, out: broadcast::Sender<Out>, tick: f64, speed: f64) {
    let period = Duration::from_millis(10);
    let mut every = tokio::time::interval(period);
    every.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let start = tokio::time::Instant::now();
    let (mut ticks, mut next_beat, mut next_pos) = (0u64, 0.0, 0.0);
    loop {
        every.tick().await;
        let wall = start.elapsed().as_secs_f64();
        let mut ap = lock(&ap);
        while (ticks as f64 + 1.0) * tick <= wall * speed {
            for o in ap.step(tick) {
                let _ = out.send(o);
            }
            ticks += 1;
        }
        let n = ap.copters.len();
        let up: Vec<bool> = (0..n).map(|i| ap.link(i)).collect();
        if wall >= next_beat {
            next_beat = wall + 1.0;
            for i in (0..n).filter(|i| up[*i]) {
                let system = ap.copters[i].system;
                let _ = out.send(Out {
                    system,
                    msg: ap.heartbeat(i),
                });
                for msg in ap.status(i) {
                    let _ = out.send(Out { system, msg });
                }
            }
        }
        if wall >= next_pos {
            next_pos = wall + 1.0 / ap.position_hz;
            for i in (0..n).filter(|i| up[*i]) {
                if let Some(msg) = ap.position(i) {
                    let _ = out.send(Out {
                        system: ap.copters[i].system,
                        msg,
                    });
                }
            }
        }
    }
}

fn signing(key: Option<[u8; 32]>) -> Option<SigningData> {
    key.map(|k| SigningData::from_config(SigningConfig::new(k, 0, true, false)))
}

fn header(system: u8, sequence: &mut u8) -> MavHeader {
    *sequence = sequence.wrapping_add(1);
    MavHeader {
        system_id: u32::from(system),
        component_id: 1,
        sequence: *sequence,
    }
}

/// Tasks a stopped server must end too (each client's reader and writer), so that its
/// connections close as a killed process's would.
/// The next message to send; `None` once the server is gone. A client too slow to keep
/// up skips what it missed rather than falling further behind.
async fn next(rx: &mut broadcast::Receiver<Out>) -> Option<Out> {
    loop {
        match rx.recv().await {
            Ok(o) => return Some(o),
            Err(broadcast::error::RecvError::Lagged(_)) => continue,
            Err(_) => return None,
        }
    }
}

pub(crate) type Clients = Arc<Mutex<Vec<tokio::task::AbortHandle>>>;

pub(crate) async fn tcp(
    listener: TcpListener,
    ap: Shared,
    out: broadcast::Sender<Out>,
    key: Option<[u8; 32]>,
    clients: Clients,
) {
    while let Ok((stream, _)) = listener.accept().await {
        let _ = stream.set_nodelay(true);
        let (read, mut write) = stream.into_split();
        let (ap, mut rx) = (Arc::clone(&ap), out.subscribe());
        let out = out.clone();
        let sign = Arc::new(signing(key));
        let sign_w = Arc::clone(&sign);
        let writer = tokio::spawn(async move {
            let mut seq = 0u8;
            loop {
                let Some(o) = next(&mut rx).await else { return };
                let h = header(o.system, &mut seq);
                if mavlink::write_v2_msg_async_signed(
                    &mut write,
                    h,
                    &o.msg,
                    sign_w.as_ref().as_ref(),
                )
                .await
                .is_err()
                {
                    return;
                }
            }
        });
        let writer_handle = writer.abort_handle();
        let reader = tokio::spawn(async move {
            let mut reader = AsyncMavlinkReader::new(read);
            loop {
                match reader
                    .read_any_message_signed::<MavMessage>(sign.as_ref().as_ref())
                    .await
                {
                    Ok((_, msg)) => {
                        for o in dispatch(&ap, &msg) {
                            let _ = out.send(o);
                        }
                    }
                    Err(mavlink::error::MessageReadError::Io(_)) => break,
                    Err(_) => {}
                }
            }
            writer.abort();
        });
        let mut all = clients.lock().unwrap_or_else(|p| p.into_inner());
        all.retain(|h| !h.is_finished());
        all.extend([writer_handle, reader.abort_handle()]);
    }
}

pub(crate) async fn udp(
    socket: UdpSocket,
    ap: Shared,
    out: broadcast::Sender<Out>,
    key: Option<[u8; 32]>,
    clients: Clients,
) {
    let socket = Arc::new(socket);
    let peers: Arc<Mutex<Vec<SocketAddr>>> = Arc::default();
    let sign = Arc::new(signing(key));
    let (mut rx, sender, to, sign_w) = (
        out.subscribe(),
        Arc::clone(&socket),
        Arc::clone(&peers),
        Arc::clone(&sign),
    );
    let writer = tokio::spawn(async move {
        let mut seq = 0u8;
        loop {
            let Some(o) = next(&mut rx).await else { return };
            let mut buf = Vec::new();
            let h = header(o.system, &mut seq);
            if mavlink::write_v2_msg_async_signed(&mut buf, h, &o.msg, sign_w.as_ref().as_ref())
                .await
                .is_err()
            {
                continue;
            }
            let peers = to.lock().unwrap_or_else(|p| p.into_inner()).clone();
            for p in peers {
                let _ = sender.send_to(&buf, p).await;
            }
        }
    });
    clients
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .push(writer.abort_handle());
    let mut buf = vec![0u8; 65_536];
    loop {
        let Ok((n, from)) = socket.recv_from(&mut buf).await else {
            continue;
        };
        {
            let mut peers = peers.lock().unwrap_or_else(|p| p.into_inner());
            if !peers.contains(&from) {
                peers.push(from);
            }
        }
        let mut reader = AsyncMavlinkReader::new(&buf[..n]);
        while let Ok((_, msg)) = reader
            .read_any_message_signed::<MavMessage>(sign.as_ref().as_ref())
            .await
        {
            for o in dispatch(&ap, &msg) {
                let _ = out.send(o);
            }
        }
    }
}
