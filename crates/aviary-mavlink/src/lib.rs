//! The MAVLink 2 backend: flies ArduPilot and PX4 vehicles, and the simulated vehicles of
//! `aviary vehicles`, from the engine's middle layer.
//!
//! - [`facts::ask`] reads each vehicle's own figures (climb, descent, landing, return,
//!   battery capacity and charge), for `aviary check --plan`.
//! - [`connect`] opens every `mavlink =` address of the world (one [`link::Link`] per
//!   address, shared by the vehicles on it and routed by system id), waits for each
//!   vehicle's HEARTBEAT and first position, and asks for the telemetry streams
//!   (GLOBAL_POSITION_INT, SYS_STATUS, BATTERY_STATUS, EXTENDED_SYS_STATE, HEARTBEAT).
//! - [`MavlinkBackend`] runs each call as MAVLink exchanges (`flight`): COMMAND_LONG or
//!   COMMAND_INT with ACK, retries and timeouts, refusals as `CommandFailed` with the
//!   autopilot's STATUSTEXT; GUIDED (ArduPilot) or HOLD with DO_REPOSITION (PX4); arrival
//!   by position within [`Tuning::arrive_xy`] and [`Tuning::arrive_z`].
//! - Positions are converted about the world's `origin` (`geo`); heights are relative
//!   to home.
//!
//! This crate does network IO (it is an outer crate, like `aviary-server`); the engine
//! never names it. Detection is geometric: the world's `[[targets]]` seen by the world's
//! sensors along the track the vehicle reports (there is no camera pipeline).

mod backend;
mod craft;
pub mod facts;
mod flight;
pub mod geo;
pub mod link;
pub mod mode;
mod motion;
mod vehicle;

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use aviary_world::{Backend as Binding, World};
use mavlink::dialects::ardupilotmega::MavCmd;
use sha2::{Digest, Sha256};
use tokio::sync::mpsc;

pub use backend::MavlinkBackend;
pub use facts::Facts;
pub use geo::Origin;
pub use mavlink;

use craft::{Craft, Doing};
use vehicle::Vehicle;

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
            let aviary_world::Mavlink {
                address,
                system_id,
                signing_key,
            } = &**link;
            let n = count.entry(address.clone()).or_insert(0);
            *n = n.saturating_add(1);
            out.push((
                i,
                address.clone(),
                system_id.unwrap_or(*n),
                signing_key.clone(),
            ));
        }
    }
    out
}

/// The links the world's MAVLink drones need: each address with its signing key. Two
/// drones on one system id of an address, or one address with two keys, cannot work.
pub(crate) fn link_keys(world: &World, bound: &[(usize, String, u8, Option<String>)]) -> Result<BTreeMap<String, Option<String>>, String> {
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

/// Connects to every MAVLink drone of `world`. Errors are sentences for the operator:
/// an unreachable address, a vehicle that never sends HEARTBEAT, two drones on one
/// system id.
pub async fn connect(world: &World, tuning: Tuning) -> Result<MavlinkBackend, String> {
    let bound = bindings(world);
    // The world's frame must be pinned to the Earth: without an origin, local metres
    // would be sent as if the site were at 0°N 0°E.
    let Some(origin) = world.site.origin.as_ref().map(|g| Origin {
        lat: g.lat,
        lon: g.lon,
        alt: g.alt,
    }) else {
        return Err("a world with MAVLink drones needs `origin = { lat, lon, alt }` in [site]: where the local frame sits on the Earth".into());
    };
    let mut links: BTreeMap<String, (Arc<link::Link>, Option<String>)> = BTreeMap::new();
    let mut used: BTreeMap<(String, u8), usize> = BTreeMap::new();
    for (i, address, system, key) in &bound {
        if let Some(other) = used.insert((address.clone(), *system), *i) {
            return Err(format!(
                "drones `{}` and `{}` both use system id {system} on {address}: give each its own `system_id`",
                world.drones[other].name, world.drones[*i].name
            ));
        }
        match links.get(address) {
            Some((_, k)) if k != key => {
                return Err(format!("drone `{}` on {address} has another `signing_key` than the drones before it on that address: one link, one key", world.drones[*i].name));
            }
            Some(_) => {}
            None => {
                let link = link::Link::open(address, key.as_deref().map(signing_key)).await?;
                links.insert(address.clone(), (link, key.clone()));
            }
        }
    }
    let (events_tx, events_rx) = mpsc::unbounded_channel();
    let (alarms_tx, alarms_rx) = mpsc::unbounded_channel();
    let mut crafts: Vec<Option<Arc<Craft>>> = vec![None; world.drones.len()];
    for (i, address, system, _) in &bound {
        let d = &world.drones[*i];
        let link = Arc::clone(&links[address].0);
        let v = Arc::new(Vehicle::new(
            *i,
            d.name.clone(),
            *system,
            origin,
            world.targets.clone(),
            events_tx.clone(),
            alarms_tx.clone(),
        ));
        link.add(Arc::clone(&v));
        crafts[*i] = Some(Arc::new(Craft {
            name: d.name.clone(),
            link,
            v,
            max_speed: d.max_speed,
            climb_rate: d.climb_rate,
            acceleration: d.acceleration,
            endurance: d.endurance,
            home: [d.home[0], d.home[1]],
            sensors: d.sensors.to_vec(),
            payload: d.payload.to_vec(),
            fence: world.site.geofence.clone(),
            max_altitude: world.site.max_altitude,
            streaming: false.into(),
            carrying: Mutex::new(None),
            doing: Mutex::new(Doing::Other),
            speed: Mutex::new(None),
            level: Mutex::new(None),
            tuning,
        }));
    }
    for c in crafts.iter().flatten() {
        let what = format!(
            "a HEARTBEAT from system {} (drone `{}`) on {}",
            c.v.system, c.name, c.link.address
        );
        c.wait_for(tuning.connect_timeout, &what, |c| {
            c.v.seen().heartbeat.is_some()
        })
        .await
        .map_err(|_| {
            format!(
                "no answer: waited {} s for {what}; is the vehicle on, and is its system id right?",
                tuning.connect_timeout.as_secs()
            )
        })?;
        request_streams(c, tuning.position_hz);
    }
    for c in crafts.iter().flatten() {
        c.wait_for(tuning.ready_timeout, "", |c| c.fix().is_some()).await.map_err(|_| {
            format!("drone `{}` sends HEARTBEAT but no position within {} s (GLOBAL_POSITION_INT was asked for {} a second): has it a GPS fix?", c.name, tuning.ready_timeout.as_secs(), tuning.position_hz)
        })?;
    }
    // One deadline for all: the vehicles boot side by side.
    let homes_by = tokio::time::Instant::now() + tuning.home_wait;
    for c in crafts.iter().flatten() {
        check_home(c, tuning, homes_by).await?;
    }
    Ok(MavlinkBackend::new(
        crafts,
        world.sensors.clone(),
        (events_tx, events_rx),
        alarms_rx,
        tuning.heartbeat_timeout,
    ))
}

/// Before anything flies, the vehicle must stand where the world puts it: its home
/// (HOME_POSITION), or on the ground where it stands (which is where ArduPilot and PX4
/// set home), within [`Tuning::home_tolerance`] of the drone's `home`. Otherwise the
/// world's places, areas and fence would be flown at an offset: the run is refused with
/// the distance and the coordinates to write.
async fn check_home(c: &Arc<Craft>, tuning: Tuning, by: tokio::time::Instant) -> Result<(), String> {
    // HOME_POSITION was asked for with the streams; a moment for its first one.
    let _ = c.wait_for(tuning.home_wait.min(std::time::Duration::from_secs(2)), "", |c| c.v.seen().home.is_some()).await;
    if c.v.seen().armed {
        // Already flying: only its home says where it started.
        let left = by.saturating_duration_since(tokio::time::Instant::now());
        let _ = c.wait_for(left, "", |c| c.v.seen().home.is_some()).await;
    }
    let (home, how) = {
        let seen = c.v.seen();
        match (seen.home, seen.fix) {
            (Some(h), _) => ([h[0], h[1]], "its home (HOME_POSITION)"),
            (None, Some(f)) if !seen.armed => ([f.pos[0], f.pos[1]], "where it stands on the ground"),
            _ => return Ok(()),
        }
    };
    let off = aviary_api::geometry::dist(home, c.home);
    if off <= tuning.home_tolerance {
        return Ok(());
    }
    // + 0.0: no "-0.0" in the message.
    let home = [home[0] + 0.0, home[1] + 0.0];
    let (lat, lon) = c.v.origin().to_geodetic(home[0], home[1]);
    Err(format!(
        "drone `{}` is not where the world says: {how} is at ({:.1}, {:.1}), {off:.1} m from its world home ({:.1}, {:.1}) (more than {:.0} m). Move the vehicle (or set its home) to the world's, or write `home = [{:.1}, {:.1}]` for it in the world ({lat:.7}°, {lon:.7}°); nothing was flown",
        c.name, home[0], home[1], c.home[0], c.home[1], tuning.home_tolerance, home[0], home[1]
    ))
}

/// Asks for the telemetry streams with SET_MESSAGE_INTERVAL (in the background: a
/// vehicle that refuses one still flies, only with less telemetry).
fn request_streams(c: &Arc<Craft>, position_hz: f64) {
    let c = Arc::clone(c);
    tokio::spawn(async move {
        // Message ids: HEARTBEAT 0, SYS_STATUS 1, GLOBAL_POSITION_INT 33,
        // BATTERY_STATUS 147, EXTENDED_SYS_STATE 245, HOME_POSITION 242, FENCE_STATUS 162,
        // GPS_RAW_INT 24.
        for (id, hz) in [
            (33.0, position_hz),
            (1.0, 1.0),
            (147.0, 1.0),
            (245.0, 1.0),
            (0.0, 1.0),
            (242.0, 0.5),
            (162.0, 1.0),
            (24.0, 1.0),
        ] {
            let interval_us = (1e6 / hz) as f32;
            let _ = c
                .command(
                    MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
                    [id, interval_us, 0.0, 0.0, 0.0, 0.0, 0.0],
                )
                .await;
        }
    });
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
