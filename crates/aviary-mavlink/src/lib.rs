//! The MAVLink 2 backend: flies ArduPilot and PX4 vehicles, and the simulated vehicles of
//! `aviary vehicles`, from the engine's middle layer.
//!
//! - [`connect`] opens every `mavlink =` address of the world (one [`link::Link`] per
//!   address, shared by the vehicles on it and routed by system id), waits for each
//!   vehicle's HEARTBEAT, reads its [`facts`] (climb, descent, landing, return, battery
//!   capacity and charge) and flies it with them, asks for the telemetry streams
//!   (GLOBAL_POSITION_INT, SYS_STATUS, BATTERY_STATUS, EXTENDED_SYS_STATE, HEARTBEAT) and
//!   waits for its first position.
//! - [`facts::ask`] reads the facts alone, for `aviary check --plan`.
//! - [`MavlinkBackend`] runs each call as MAVLink exchanges (`flight`): COMMAND_LONG or
//!   COMMAND_INT with ACK, retries and timeouts, refusals as `CommandFailed` with the
//!   autopilot's STATUSTEXT; GUIDED (ArduPilot) or HOLD with DO_REPOSITION and ORBIT
//!   (PX4, `px4.rs`); arrival
//!   by position within [`Tuning::arrive_xy`] and [`Tuning::arrive_z`].
//! - Positions are converted about the world's `origin` (`geo`); heights are relative
//!   to home.
//!
//! This crate does network IO (it is an outer crate, like `aviary-server`); the engine
//! never names it. Detection is geometric: the world's `[[targets]]` seen by the world's
//! sensors along the track the vehicle reports (there is no camera pipeline).
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod backend;
pub mod battery;
pub mod carried;
pub mod clock;
mod connect;
mod drone;
pub mod facts;
mod failsafe;
mod functions;
pub mod link;
mod mission;
pub mod mode;
mod motion;
mod plausible;
mod px4;
pub mod receive;
mod vehicle;
mod words;

use std::collections::BTreeMap;
use std::time::Duration;

use aviary_world::{Backend as Binding, World};
use sha2::{Digest, Sha256};

pub use aviary_api::geo::Origin;
pub use backend::MavlinkBackend;
pub use carried::{Carrier, Frames};
pub use connect::{connect, connect_through};
pub use facts::Facts;
pub use mavlink;

/// Timeouts and tolerances. The defaults suit ArduCopter SITL and small real copters.
#[derive(Clone, Copy, Debug)]
pub struct Tuning {
    /// How long a command waits for its COMMAND_ACK before it is sent again.
    pub ack_timeout: Duration,
    /// How often a command is sent before it fails with `Timeout`.
    pub command_tries: u8,
    /// No HEARTBEAT for this long: `ConnectionLost`.
    pub heartbeat_timeout: Duration,
    /// How long `connect` waits for each vehicle's first HEARTBEAT and position.
    pub connect_timeout: Duration,
    /// How long a vehicle may take to become ready (MAV_STATE_STANDBY).
    pub ready_timeout: Duration,
    /// How long arming is retried while pre-arm checks fail (GPS and EKF: ~40 s on SITL).
    pub arm_timeout: Duration,
    pub arm_retry: Duration,
    /// A position target is sent again this often while the drone flies to it.
    pub resend: Duration,
    /// How often waits look at the latest telemetry.
    pub poll: Duration,
    /// Arrived: this close over the ground (m) ...
    pub arrive_xy: f64,
    /// ... and in height (m).
    pub arrive_z: f64,
    /// GLOBAL_POSITION_INT messages per second asked of each vehicle.
    pub position_hz: f64,
    /// At connect: how far (m) a vehicle's home may be from its world home ...
    pub home_tolerance: f64,
    /// ... and how long to wait for its HOME_POSITION after its first fix.
    pub home_wait: Duration,
    /// How long the vehicles' facts (parameters and charge) are waited for, all at once.
    pub facts_wait: Duration,
}

impl Default for Tuning {
    fn default() -> Tuning {
        Tuning {
            ack_timeout: Duration::from_millis(1500),
            command_tries: 3,
            heartbeat_timeout: Duration::from_secs(3),
            connect_timeout: Duration::from_secs(15),
            ready_timeout: Duration::from_secs(60),
            arm_timeout: Duration::from_secs(90),
            arm_retry: Duration::from_secs(2),
            resend: Duration::from_secs(2),
            poll: Duration::from_millis(50),
            arrive_xy: 1.0,
            arrive_z: 0.5,
            position_hz: 10.0,
            home_tolerance: 5.0,
            home_wait: Duration::from_secs(30),
            facts_wait: Duration::from_secs(5),
        }
    }
}

/// The 32-byte signing key of a `signing_key`: 64 hex digits are the key itself; any
/// other text is a passphrase, hashed with SHA-256 as MAVProxy's `signing setup` does.
pub fn signing_key(text: &str) -> [u8; 32] {
    let mut key = [0u8; 32];
    let hex = text.len() == 64 && text.bytes().all(|b| b.is_ascii_hexdigit());
    if hex {
        for (i, k) in key.iter_mut().enumerate() {
            *k = u8::from_str_radix(&text[2 * i..2 * i + 2], 16).unwrap_or(0);
        }
    } else {
        key.copy_from_slice(&Sha256::digest(text.as_bytes()));
    }
    key
}

/// The MAVLink drones of a world: (drone index, address, system id, signing key). A drone
/// without `system_id` gets 1 + its position among the drones of its address, which is
/// what `aviary vehicles` and a lone SITL (`--sysid` 1) use.
pub fn bindings(world: &World) -> Vec<(usize, String, u8, Option<String>)> {
    let mut count: BTreeMap<String, u8> = BTreeMap::new();
    let mut out = Vec::new();
    for (i, d) in world.drones.iter().enumerate() {
        if let Binding::Mavlink(link) = &d.backend {
            let aviary_world::Mavlink { address, system_id, signing_key } = &**link;
            let n = count.entry(address.clone()).or_insert(0);
            *n = n.saturating_add(1);
            out.push((i, address.clone(), system_id.unwrap_or(*n), signing_key.clone()));
        }
    }
    out
}

/// The links the world's MAVLink drones need: each address with its signing key. Two
/// drones on one system id of an address, or one address with two keys, cannot work.
pub(crate) fn link_keys(
    world: &World,
    bound: &[(usize, String, u8, Option<String>)],
) -> Result<BTreeMap<String, Option<String>>, String> {
    let mut links: BTreeMap<String, Option<String>> = BTreeMap::new();
    let mut used: BTreeMap<(String, u8), usize> = BTreeMap::new();
    for (i, address, system, key) in bound {
        if let Some(other) = used.insert((address.clone(), *system), *i) {
            return Err(format!(
                "drones `{}` and `{}` both use system id {system} on {address}: give each its own `system_id`",
                world.drones[other].name, world.drones[*i].name
            ));
        }
        match links.get(address) {
            Some(k) if k != key => {
                return Err(format!("drone `{}` on {address} has another `signing_key` than the drones before it on that address: one link, one key", world.drones[*i].name));
            }
            Some(_) => {}
            None => {
                links.insert(address.clone(), key.clone());
            }
        }
    }
    Ok(links)
}

#[cfg(test)]
mod tests {
    use super::signing_key;

    #[test]
    fn signing_keys_are_hex_or_hashed_passphrases() {
        let hex = "00".repeat(31) + "ff";
        assert_eq!(signing_key(&hex)[31], 0xff);
        assert_ne!(signing_key("correct horse"), signing_key("battery staple"));
    }
}
