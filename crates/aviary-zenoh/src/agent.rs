//! `aviary agent`: beside an autopilot (on its companion computer, or the laptop its radio
//! is plugged into), it holds the vehicle's MAVLink link and carries it on Zenoh, a frame
//! a sample, so that a mission on another machine flies the vehicle as if it were local
//! (`mavlink = "agent:NAME"` in the mission's world).
//!
//! The agent relays; it does not fly. It reads no message but to frame it, so MAVLink 2
//! signing holds end to end between the mission and the vehicle, and the vehicle's own
//! failsafes (it stops hearing the ground station's HEARTBEAT) protect it when the
//! mission's side is cut off.
// The agent waits in real time on a runtime of its own: no run's clock is here.
#![allow(clippy::disallowed_methods)]

use std::sync::Arc;
use std::time::{Duration, Instant};

use aviary_mavlink::mavlink::dialects::ardupilotmega::MavMessage;
use aviary_mavlink::mavlink::error::MessageReadError;
use aviary_mavlink::mavlink::{self, AsyncMavConnection, MAVLinkMessageRaw, MavlinkReader};
use tokio::sync::{mpsc, Mutex};
use zenoh::pubsub::Publisher;

use crate::frames;
use crate::keys::AgentKeys;

type Conn = mavlink::AsyncConnection<MavMessage>;
type FromMission = Arc<Mutex<mpsc::Receiver<Vec<u8>>>>;

/// A lost or unreachable vehicle link is tried again this often.
const REOPEN_EVERY: Duration = Duration::from_secs(1);
/// A refused sample is said at most this often (a foreign peer may send many).
const SAY_REFUSED_EVERY: Duration = Duration::from_secs(1);

/// Serves agent `name` for the vehicle link at `address` (a world's `mavlink =` form),
/// until the process ends. Says on standard error what it holds and what it refuses.
pub async fn serve(session: zenoh::Session, name: &str, address: &str) -> Result<(), String> {
    let keys = AgentKeys::new(name)?;
    let target = aviary_mavlink::link::crate_address(address)?;
    let _alive =
        session.liveliness().declare_token(keys.alive()).await.map_err(|e| {
            format!("cannot declare agent `{name}` on Zenoh: {}", crate::reason(&e))
        })?;
    let to_mission = frames::speak(&session, keys.from_vehicle()).await?;
    let (_from_mission, from_rx) = frames::hear(&session, keys.to_vehicle()).await?;
    let from_mission: FromMission = Arc::new(Mutex::new(from_rx));
    let writer_keys = keys.to_vehicle();
    let mut said_unreachable = false;
    loop {
        let conn = match open(&target).await {
            Ok(conn) => Arc::new(conn),
            Err(why) => {
                if !said_unreachable {
                    say(&format!(
                        "agent `{name}`: cannot reach {address}: {why}; trying again every second"
                    ));
                    said_unreachable = true;
                }
                tokio::time::sleep(REOPEN_EVERY).await;
                continue;
            }
        };
        said_unreachable = false;
        say(&format!(
            "agent `{name}` carries {address} on Zenoh: {} and {}",
            keys.from_vehicle(),
            keys.to_vehicle()
        ));
        let writer = tokio::spawn(to_vehicle(
            Arc::clone(&conn),
            Arc::clone(&from_mission),
            writer_keys.clone(),
        ));
        from_vehicle(&conn, &to_mission).await;
        writer.abort();
        say(&format!("agent `{name}`: the link {address} closed; opening it again"));
        tokio::time::sleep(REOPEN_EVERY).await;
    }
}

async fn open(target: &str) -> Result<Conn, String> {
    let mut conn = mavlink::connect_async::<MavMessage>(target).await.map_err(|e| e.to_string())?;
    conn.set_protocol_version(mavlink::MavlinkVersion::V2);
    conn.set_allow_recv_any_version(true);
    Ok(conn)
}

/// Each frame the vehicle sends, published as it came, until the link closes.
async fn from_vehicle(conn: &Conn, to_mission: &Publisher<'_>) {
    loop {
        match conn.recv_raw().await {
            Ok(frame) => {
                let _ = to_mission.put(bytes(&frame).to_vec()).await;
            }
            Err(MessageReadError::Parse(_)) => {}
            Err(_) => return,
        }
    }
}

/// Each frame the mission sends, written to the vehicle. A sample that is not one
/// MAVLink frame (a foreign peer's garbage) is not written, and said.
async fn to_vehicle(conn: Arc<Conn>, from_mission: FromMission, key: String) {
    let mut from_mission = from_mission.lock().await;
    let mut refused = Refused::default();
    while let Some(sample) = from_mission.recv().await {
        let mut reader = MavlinkReader::new(sample.as_slice());
        match reader.read_any_raw_message::<MavMessage>() {
            Ok(frame) if bytes(&frame).len() == sample.len() => {
                let _ = conn.send_raw(&frame).await;
            }
            _ => refused.note(&key, sample.len()),
        }
    }
}

/// The frame as it went on the wire, signature included.
fn bytes(frame: &MAVLinkMessageRaw) -> &[u8] {
    match frame {
        MAVLinkMessageRaw::V1(f) => f.raw_bytes(),
        MAVLinkMessageRaw::V2(f) => f.raw_bytes(),
    }
}

/// Samples that were not frames, said at most once a second.
#[derive(Default)]
struct Refused {
    count: u64,
    said: Option<Instant>,
}

impl Refused {
    fn note(&mut self, key: &str, bytes: usize) {
        self.count += 1;
        if self.said.is_none_or(|at| at.elapsed() >= SAY_REFUSED_EVERY) {
            say(&format!(
                "agent: refused a sample of {bytes} bytes on {key}: not one MAVLink frame ({} refused so far)",
                self.count
            ));
            self.said = Some(Instant::now());
        }
    }
}

/// A line on standard error, for the operator; a closed standard error stops nothing.
fn say(line: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "aviary: {line}");
}
