//! One MAVLink connection (one `mavlink =` address of the world), shared by every vehicle
//! on it: messages are routed to vehicles by system id. A lost TCP connection is opened
//! again every second, so a link that comes back is noticed (`ConnectionRestored`). An
//! `agent:NAME` address is carried ([`crate::carried`]): its frames come and go through
//! the run's carrier, and a silent agent is a silent link, watched as any other.

use parking_lot::Mutex;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::Arc;
use std::time::Duration;

use mavlink::dialects::ardupilotmega::{
    MavAutopilot, MavMessage, MavModeFlag, MavState, MavType, HEARTBEAT_DATA,
};
use mavlink::error::MessageReadError;
use mavlink::{AsyncMavConnection, MavHeader};

use crate::carried::{agent_of, CarriedConn, Carrier};
use crate::vehicle::Vehicle;

/// A link's connection: a socket's, or an agent's frames.
enum Conn {
    Socket(mavlink::AsyncConnection<MavMessage>),
    Carried(CarriedConn),
}

impl Conn {
    async fn recv(&self) -> Result<(MavHeader, MavMessage), MessageReadError> {
        match self {
            Conn::Socket(c) => c.recv().await,
            Conn::Carried(c) => c.recv().await,
        }
    }

    async fn send(&self, header: &MavHeader, msg: &MavMessage) {
        let _ = match self {
            Conn::Socket(c) => c.send(header, msg).await,
            Conn::Carried(c) => c.send(header, msg),
        };
    }
}

/// The ground station's ids: 255 is the usual GCS system, 190 MAV_COMP_ID_MISSIONPLANNER.
pub const GCS_SYSTEM: u8 = 255;
pub const GCS_COMPONENT: u8 = 190;
/// Messages from other components (cameras, gimbals) carry no vehicle state.
pub(crate) const AUTOPILOT_COMPONENT: u8 = 1;
const REOPEN_EVERY: Duration = Duration::from_secs(1);
const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);

/// A world address (`tcp:HOST:PORT`, `udp:HOST:PORT`, ...) as the mavlink crate spells it.
/// `tcp` connects out to a vehicle (SITL listens on TCP 5760); `udp` listens, as
/// MAVProxy's and pymavlink's `udp:` do (a vehicle or MAVProxy `--out` sends to it);
/// `udpout` sends first (to `aviary vehicles --listen udp:...`).
pub fn crate_address(address: &str) -> Result<String, String> {
    let Some((scheme, rest)) = address.split_once(':') else {
        return Err(format!("`{address}` is not SCHEME:HOST:PORT"));
    };
    let scheme = match scheme {
        "tcp" | "tcpout" => "tcpout",
        "tcpin" => "tcpin",
        "udp" | "udpin" => "udpin",
        "udpout" => "udpout",
        "udpbcast" => "udpbcast",
        "agent" => {
            return Err(format!(
                "`{address}` is a vehicle behind an agent, reached on Zenoh: `aviary run --zenoh [CONFIG]` flies it (docs/DISTRIBUTED.md)"
            ))
        }
        "serial" => {
            return Err(format!(
                "`{address}`: serial links are not built in (the serial transport needs libudev); \
                 bridge the port to TCP or UDP, e.g. with `mavproxy.py --master=/dev/ttyUSB0 --out=udp:127.0.0.1:14550`"
            ))
        }
        other => return Err(format!("`{address}` has unknown scheme `{other}`")),
    };
    Ok(format!("{scheme}:{rest}"))
}

pub struct Link {
    /// As the world wrote it, for messages.
    pub address: String,
    /// The mavlink crate's address; `None` for an agent's, which is not opened again.
    target: Option<String>,
    conn: Mutex<Option<Arc<Conn>>>,
    vehicles: Mutex<BTreeMap<u8, Arc<Vehicle>>>,
    signing: Option<[u8; 32]>,
    sequence: AtomicU8,
}

impl Link {
    /// Opens the connection (an unreachable address is an error, said plainly) and
    /// starts the reader and the ground station's heartbeat. An `agent:NAME` address is
    /// opened through `carrier`.
    pub async fn open(
        address: &str,
        signing: Option<[u8; 32]>,
        carrier: Option<&dyn Carrier>,
    ) -> Result<Arc<Link>, String> {
        let target = match (agent_of(address), carrier) {
            (Some(_), Some(_)) => None,
            _ => Some(crate_address(address)?),
        };
        let link = Arc::new(Link {
            address: address.to_owned(),
            target,
            conn: Mutex::new(None),
            vehicles: Mutex::new(BTreeMap::new()),
            signing,
            sequence: AtomicU8::new(0),
        });
        let conn = match (agent_of(address), carrier) {
            (Some(agent), Some(carrier)) => {
                // The carrier bounds its own wait, and says what it looked for.
                let frames = carrier.open(agent).await?;
                let signing =
                    link.signing.map(|key| mavlink::SigningData::from_config(signing_config(key)));
                Arc::new(Conn::Carried(CarriedConn::new(frames, signing)))
            }
            _ => link
                .connect()
                .await
                .map_err(|e| format!("cannot reach the MAVLink address `{address}`: {e}"))?,
        };
        *link.slot() = Some(conn.clone());
        tokio::spawn(read(Arc::downgrade(&link), conn));
        tokio::spawn(heartbeat(Arc::downgrade(&link)));
        Ok(link)
    }

    fn slot(&self) -> parking_lot::MutexGuard<'_, Option<Arc<Conn>>> {
        self.conn.lock()
    }

    async fn connect(&self) -> Result<Arc<Conn>, String> {
        let Some(target) = &self.target else {
            return Err("an agent's link is not opened again".into());
        };
        let open = mavlink::connect_async::<MavMessage>(target);
        let mut conn = match aviary_clock::timeout(CONNECT_TIMEOUT, open).await {
            Ok(Ok(c)) => c,
            Ok(Err(e)) => return Err(e.to_string()),
            Err(_) => return Err(format!("no answer within {} s", CONNECT_TIMEOUT.as_secs())),
        };
        conn.set_protocol_version(mavlink::MavlinkVersion::V2);
        conn.set_allow_recv_any_version(true);
        if let Some(key) = self.signing {
            conn.setup_signing(Some(signing_config(key)));
        }
        Ok(Arc::new(Conn::Socket(conn)))
    }

    pub fn add(&self, vehicle: Arc<Vehicle>) {
        self.vehicles.lock().insert(vehicle.system, vehicle);
    }

    fn vehicle(&self, system: u32) -> Option<Arc<Vehicle>> {
        let system = u8::try_from(system).ok()?;
        self.vehicles.lock().get(&system).cloned()
    }

    /// Sends one message as the ground station. Without a connection (it is being
    /// opened again) the message is dropped: commands retry, and waits time out.
    pub async fn send(&self, msg: &MavMessage) {
        let conn = self.slot().clone();
        let Some(conn) = conn else { return };
        let header = MavHeader {
            system_id: u32::from(GCS_SYSTEM),
            component_id: GCS_COMPONENT,
            sequence: self.sequence.fetch_add(1, Ordering::Relaxed),
        };
        conn.send(&header, msg).await;
    }
}

/// Sign what we send; take only signed messages (a replayed or forged command from
/// elsewhere on the link is dropped).
fn signing_config(key: [u8; 32]) -> mavlink::SigningConfig {
    mavlink::SigningConfig::new(key, 0, true, false)
}

async fn read(link: std::sync::Weak<Link>, mut conn: Arc<Conn>) {
    loop {
        match conn.recv().await {
            Ok((header, msg)) => {
                let Some(link) = link.upgrade() else { return };
                if header.component_id == AUTOPILOT_COMPONENT {
                    if let Some(v) = link.vehicle(header.system_id) {
                        v.observe(&msg);
                    }
                }
            }
            // A message of an unknown kind, or a bad checksum: skip it.
            Err(MessageReadError::Parse(_)) => {}
            Err(_) => {
                // The connection is gone (the vehicle's end closed). Open it again until
                // it answers; the heartbeat watchdog meanwhile raises ConnectionLost. An
                // agent's carrier closes only as the run ends.
                loop {
                    let Some(l) = link.upgrade() else { return };
                    if l.target.is_none() {
                        return;
                    }
                    *l.slot() = None;
                    aviary_clock::sleep(REOPEN_EVERY).await;
                    if let Ok(c) = l.connect().await {
                        *l.slot() = Some(c.clone());
                        conn = c;
                        break;
                    }
                }
            }
        }
    }
}

/// The ground station's HEARTBEAT, once a second: autopilots watch it (GCS failsafe).
async fn heartbeat(link: std::sync::Weak<Link>) {
    let msg = MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: 0,
        mavtype: MavType::MAV_TYPE_GCS,
        autopilot: MavAutopilot::MAV_AUTOPILOT_INVALID,
        base_mode: MavModeFlag::empty(),
        system_status: MavState::MAV_STATE_ACTIVE,
        mavlink_version: 3,
    });
    let mut every = aviary_clock::interval(Duration::from_secs(1));
    loop {
        every.tick().await;
        let Some(link) = link.upgrade() else { return };
        link.send(&msg).await;
    }
}

#[cfg(test)]
mod tests {
    use super::crate_address;

    #[test]
    fn world_addresses_map_to_the_crate_s() {
        assert_eq!(crate_address("tcp:127.0.0.1:5760").unwrap(), "tcpout:127.0.0.1:5760");
        assert_eq!(crate_address("udp:0.0.0.0:14550").unwrap(), "udpin:0.0.0.0:14550");
        assert_eq!(crate_address("udpout:10.0.0.2:14555").unwrap(), "udpout:10.0.0.2:14555");
        assert!(crate_address("serial:/dev/ttyUSB0:57600").unwrap_err().contains("libudev"));
        assert!(crate_address("agent:field1").unwrap_err().contains("`aviary run --zenoh"));
    }
}
