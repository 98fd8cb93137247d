//! The simulator's drones served as MAVLink 2 vehicles: `aviary vehicles`.
//!
//! Every drone of a world becomes its own MAVLink system (its `system_id`, or its place
//! in the world: 1, 2, ...), component 1, with the behaviour of an ArduCopter-like
//! autopilot, checked against ArduCopter SITL, or of PX4 ([`Behaviour::autopilot`],
//! `aviary vehicles --autopilot px4`: `px4`, after PX4's source) (docs/REAL_DRONES.md
//! lists it all). ArduCopter's:
//! - `autopilot`, `guided`, `commands`: modes, arming with pre-arm checks, the command
//!   protocol (COMMAND_ACK addressed to the asker, the reason first as STATUSTEXT,
//!   UNSUPPORTED for anything else, `wire` for command numbers the dialect has no name
//!   for), DO_REPOSITION in every global frame ArduCopter takes, GUIDED targets.
//! - `telemetry`, `reports`: HEARTBEAT and the streams (SYS_STATUS with the health bits
//!   ground stations arm by, GPS_RAW_INT, GLOBAL_POSITION_INT, BATTERY_STATUS,
//!   EKF_STATUS_REPORT, EXTENDED_SYS_STATE, HOME_POSITION), AUTOPILOT_VERSION.
//! - `params`: the parameter protocol over what the simulated vehicle uses, under
//!   ArduCopter's names (WPNAV_SPEED settable, the rest read-only).
//! - `dispatch`: which vehicles a message is for, and who gets each answer.
//! - `client`, `server`, `udp`: one queue, one set of stream rates and one sequence per
//!   vehicle for each client (TCP connection or UDP peer); heartbeats never dropped,
//!   telemetry coalesced for a lagging client; accept errors survived, silent UDP peers
//!   expired.
//!
//! Underneath is the same [`aviary_sim::Fleet`] as `aviary run`, stepped in whole 0.05 s
//! ticks at `speed` times real time.
//!
//! PX4's (`px4`): its modes in `custom_mode` (main and sub mode), arming and auto-disarm,
//! NAV_TAKEOFF handing over to Hold, DO_REPOSITION as COMMAND_INT and COMMAND_LONG with
//! its altitude above sea level whatever the frame, DO_ORBIT, missions (the protocol and
//! the flight), its parameters bytewise, its words chunked as its STATUSTEXT stream sends
//! them.
//!
//! Not simulated (ArduCopter; PX4's list is in `px4` and docs/REAL_DRONES.md): the
//! world's no-fly zones (an autopilot does not know them: the vehicles fly a GUIDED
//! target and RTL straight, and the detour is the ground station's), missions
//! (MISSION_ITEM), fences and rally points as missions, MAVLink FTP (refused at once), RC
//! input, manual modes (STABILIZE is accepted and does nothing), more than one component
//! per vehicle. A world `link_loss` fault silences the
//! drone (no messages either way) for its duration; a `battery_critical` fault is
//! ArduCopter's battery failsafe (STATUSTEXT, then RTL); a `crash` says "Crash: ..." and
//! turns the state to EMERGENCY.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod autopilot;
mod client;
mod commands;
mod dispatch;
mod guided;
mod params;
mod px4;
mod reports;
mod server;
mod telemetry;
mod udp;
mod wire;

use parking_lot::Mutex;
use std::net::SocketAddr;
use std::sync::Arc;

use aviary_world::World;
use tokio::net::{TcpListener, UdpSocket};
use tokio::task::JoinHandle;

pub use autopilot::Behaviour;
/// Which autopilot the vehicles answer as (`Behaviour::autopilot`).
pub use aviary_mavlink::mode::Flavour;
pub use server::{parse_listen, Listen};
pub use udp::{MAX_PEERS, PEER_EXPIRY};

#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Times real time (1: real time). Tests run the paper's mission at 20.
    pub speed: f64,
    pub behaviour: Behaviour,
    /// MAVLink 2 signing: sign what is sent, take only signed messages.
    pub signing_key: Option<[u8; 32]>,
}

impl Default for Options {
    fn default() -> Options {
        Options { speed: 1.0, behaviour: Behaviour::default(), signing_key: None }
    }
}

/// A running server. Dropping it does not stop it: call [`Vehicles::stop`].
pub struct Vehicles {
    /// The address bound (with the port chosen when 0 was asked for).
    pub address: SocketAddr,
    /// Each drone's MAVLink system id, in world order.
    pub systems: Vec<u8>,
    tasks: Vec<JoinHandle<()>>,
    clients: Arc<client::Registry>,
}

/// Binds `listen` and starts serving `world`'s drones. Call inside a tokio runtime with
/// a real clock (a plain one, not `aviary_clock`'s): the vehicles pace themselves against
/// the wall clock, as a SITL does.
pub async fn serve(world: &World, listen: Listen, options: Options) -> std::io::Result<Vehicles> {
    let ap = autopilot::Autopilot::new(world, options.behaviour);
    let systems = ap.copters.iter().map(|c| c.system).collect();
    let ap = Arc::new(Mutex::new(ap));
    let speed = if options.speed.is_finite() && options.speed > 0.0 { options.speed } else { 1.0 };
    let clients = Arc::new(client::Registry::default());
    let (address, serve) = match listen {
        Listen::Tcp(addr) => {
            let listener = TcpListener::bind(addr).await?;
            let address = listener.local_addr()?;
            let task =
                server::tcp(listener, Arc::clone(&ap), Arc::clone(&clients), options.signing_key);
            (address, tokio::spawn(task))
        }
        Listen::Udp(addr) => {
            let socket = UdpSocket::bind(addr).await?;
            let address = socket.local_addr()?;
            let task = udp::udp(socket, Arc::clone(&ap), Arc::clone(&clients), options.signing_key);
            (address, tokio::spawn(task))
        }
    };
    let pace = tokio::spawn(server::pace(ap, Arc::clone(&clients), tick(), speed));
    Ok(Vehicles { address, systems, tasks: vec![pace, serve], clients })
}

/// What one ground station's `bytes` get from `world`'s vehicles, without a socket: the
/// server's own reader and dispatch answer them as a TCP connection's are, then the
/// simulation flies `seconds` (in whole ticks) with whatever was commanded, and the
/// frames sent back are returned in order, streams included. The fuzz target
/// `fuzz_vehicles` drives it with untrusted bytes.
pub async fn answer(
    world: &World,
    behaviour: Behaviour,
    bytes: &[u8],
    seconds: f64,
) -> Vec<Vec<u8>> {
    let ap = Arc::new(Mutex::new(autopilot::Autopilot::new(world, behaviour)));
    let clients = client::Registry::default();
    let me = Arc::new(client::Client::new());
    clients.add(Arc::clone(&me));
    server::read_all(bytes, None, &ap, &me, &clients).await;
    let tick = tick();
    let ticks = (seconds.clamp(0.0, 3600.0) / tick).round() as usize;
    for k in 1..=ticks {
        let mut ap = ap.lock();
        let events = ap.step(tick);
        // Streams are due by the simulated time here, as if it passed in real time.
        server::tell(&ap, &clients.all(), events, k as f64 * tick);
    }
    let mut sequences = client::Sequences::new();
    std::iter::from_fn(|| me.pop())
        .filter_map(|o| server::frame(&mut sequences, &o, None))
        .collect()
}

/// The physics tick: `aviary run`'s, so the simulator behaves as it does there.
fn tick() -> f64 {
    aviary_sim::SimOptions::default().tick
}

impl Vehicles {
    /// Stops serving: the listener, the simulation and every client's connection close,
    /// as a killed process's would.
    pub fn stop(&self) {
        for t in &self.tasks {
            t.abort();
        }
        for c in self.clients.all() {
            c.abort();
        }
    }

    /// The ground stations connected now (TCP connections, UDP peers heard lately).
    pub fn clients(&self) -> usize {
        self.clients.len()
    }
}
