//! [`connect`]: from a world's `mavlink =` drones to a [`MavlinkBackend`], with each
//! vehicle heard, its facts read and applied, its telemetry streams asked for, and its
//! home checked against the world's before anything flies.

use parking_lot::Mutex;
use std::collections::BTreeMap;
use std::sync::Arc;

use aviary_api::flight::Descent;
use aviary_api::DroneId;
use aviary_clock::Instant;
use aviary_world::{Drone, World};
use mavlink::dialects::ardupilotmega::MavCmd;
use tokio::sync::mpsc;

use crate::carried::Carrier;
use crate::drone::{Craft, Doing};
use crate::facts::{self, Facts};
use crate::vehicle::Vehicle;
use crate::{battery, bindings, link, link_keys, signing_key, MavlinkBackend, Origin, Tuning};

/// Connects to every MAVLink drone of `world`, and flies each with its vehicle's facts
/// ([`MavlinkBackend::facts`]). Errors are sentences for the operator: an unreachable
/// address, a vehicle that never sends HEARTBEAT, two drones on one system id. An
/// `agent:NAME` address is one of them here: it needs [`connect_through`] a carrier.
pub async fn connect(world: &World, tuning: Tuning) -> Result<MavlinkBackend, String> {
    connect_through(world, tuning, None).await
}

/// [`connect`], with the world's `agent:NAME` addresses reached through `carrier`.
pub async fn connect_through(
    world: &World,
    tuning: Tuning,
    carrier: Option<&dyn Carrier>,
) -> Result<MavlinkBackend, String> {
    let bound = bindings(world);
    let origin = origin(world)?;
    let mut links = BTreeMap::new();
    for (address, key) in link_keys(world, &bound)? {
        let link = link::Link::open(&address, key.as_deref().map(signing_key), carrier).await?;
        links.insert(address, link);
    }
    let (events_tx, events_rx) = mpsc::unbounded_channel();
    let (alarms_tx, alarms_rx) = mpsc::unbounded_channel();
    let mut vehicles = Vec::new();
    for (i, address, system, _) in &bound {
        let link = Arc::clone(&links[address]);
        let v = Arc::new(Vehicle::new(
            DroneId(*i),
            world.drones[*i].name.clone(),
            *system,
            origin,
            world.targets.clone(),
            events_tx.clone(),
            alarms_tx.clone(),
        ));
        link.add(Arc::clone(&v));
        vehicles.push((DroneId(*i), link, v));
    }
    hear_all(&vehicles, tuning).await?;
    let all = read_facts(&vehicles, tuning).await;
    let crafts = crafts(world, vehicles, &all, tuning);
    for c in crafts.iter().flatten() {
        request_streams(c, tuning.position_hz);
    }
    for c in crafts.iter().flatten() {
        c.wait_for(tuning.ready_timeout, "", |c| c.fix().is_some()).await.map_err(|_| {
            format!("drone `{}` sends HEARTBEAT but no position within {} s (GLOBAL_POSITION_INT was asked for {} a second): has it a GPS fix?", c.name, tuning.ready_timeout.as_secs(), tuning.position_hz)
        })?;
    }
    // One deadline for all: the vehicles boot side by side.
    let homes_by = aviary_clock::Instant::now() + tuning.home_wait;
    for c in crafts.iter().flatten() {
        check_home(c, tuning, homes_by).await?;
    }
    Ok(MavlinkBackend::new(
        crafts,
        all,
        world.sensors.clone(),
        (events_tx, events_rx),
        alarms_rx,
        tuning.heartbeat_timeout,
    ))
}

/// A world drone's vehicle, on its link.
type Bound = (DroneId, Arc<link::Link>, Arc<Vehicle>);

/// Where the world's frame sits on the Earth. It must be pinned: without an origin, local
/// metres would be sent as if the site were at 0°N 0°E.
fn origin(world: &World) -> Result<Origin, String> {
    let Some(g) = world.site.origin.as_ref() else {
        return Err("a world with MAVLink drones needs `origin = { lat, lon, alt }` in [site]: where the local frame sits on the Earth".into());
    };
    Ok(g.origin())
}

/// Waits for each vehicle's first HEARTBEAT, each within the connect timeout.
async fn hear_all(vehicles: &[Bound], tuning: Tuning) -> Result<(), String> {
    for (_, link, v) in vehicles {
        let by = Instant::now() + tuning.connect_timeout;
        while v.seen().heartbeat.is_none() {
            if Instant::now() >= by {
                return Err(format!(
                    "no answer: waited {} s for a HEARTBEAT from system {} (drone `{}`) on {}; is the vehicle on, and is its system id right?",
                    tuning.connect_timeout.as_secs(),
                    v.system,
                    v.name,
                    link.address
                ));
            }
            aviary_clock::sleep(tuning.poll).await;
        }
    }
    Ok(())
}

/// The facts of all vehicles at once, within one wait; by drone.
async fn read_facts(vehicles: &[Bound], tuning: Tuning) -> Vec<Facts> {
    let until = Instant::now() + tuning.facts_wait;
    let mut reads = tokio::task::JoinSet::new();
    for (i, link, v) in vehicles {
        let (i, link, v) = (*i, Arc::clone(link), Arc::clone(v));
        reads.spawn(async move { facts::read(i.0, &link, &v, until).await });
    }
    let mut all: Vec<Facts> = Vec::new();
    while let Some(done) = reads.join_next().await {
        all.extend(done.ok());
    }
    all.sort_by_key(|f| f.drone);
    all
}

/// Every MAVLink drone as the backend flies it, by drone index: the world's drone with
/// its vehicle's facts applied, when it has any.
fn crafts(
    world: &World,
    vehicles: Vec<Bound>,
    all: &[Facts],
    tuning: Tuning,
) -> Vec<Option<Arc<Craft>>> {
    let mut crafts: Vec<Option<Arc<Craft>>> = vec![None; world.drones.len()];
    let airspace = Arc::new(aviary_route::Airspace::of(world));
    for (i, link, v) in vehicles {
        let mut d = world.drones[i.0].clone();
        let landing = match all.iter().find(|f| f.drone == i.0) {
            Some(f) => {
                f.apply(&mut d);
                f.landing(&d)
            }
            None => d.descent(),
        };
        let craft = craft(&d, landing, (link, v), world, Arc::clone(&airspace), tuning);
        crafts[i.0] = Some(Arc::new(craft));
    }
    crafts
}

/// One drone as the backend flies it: `d` is the world's drone with its vehicle's facts
/// applied, `landing` how the vehicle comes down.
fn craft(
    d: &Drone,
    landing: Descent,
    (link, v): (Arc<link::Link>, Arc<Vehicle>),
    world: &World,
    airspace: Arc<aviary_route::Airspace>,
    tuning: Tuning,
) -> Craft {
    Craft {
        name: d.name.clone(),
        link,
        v,
        max_speed: d.max_speed,
        acceleration: d.acceleration,
        battery: battery::Figures {
            return_speed: d.return_speed,
            descent: landing,
            loiter: d.return_loiter,
            endurance: d.endurance,
            capacity: d.battery_capacity,
            flight_current: d.flight_current,
        },
        home: [d.home[0], d.home[1]],
        sensors: d.sensors.to_vec(),
        payload: d.payload.to_vec(),
        fence: world.site.geofence.clone(),
        max_altitude: world.site.max_altitude,
        airspace,
        return_altitude: d.return_altitude,
        streaming: false.into(),
        carrying: Mutex::new(None),
        doing: Mutex::new(Doing::Other),
        speed: Mutex::new(None),
        level: Mutex::new(None),
        flying_to: Mutex::new(None),
        targeted: Mutex::new(None),
        tuning,
    }
}

/// Before anything flies, the vehicle must stand where the world puts it: its home
/// (HOME_POSITION), or on the ground where it stands (which is where ArduPilot and PX4
/// set home), within [`Tuning::home_tolerance`] of the drone's `home`. Otherwise the
/// world's places, areas and fence would be flown at an offset: the run is refused with
/// the distance and the coordinates to write.
async fn check_home(
    c: &Arc<Craft>,
    tuning: Tuning,
    by: aviary_clock::Instant,
) -> Result<(), String> {
    // HOME_POSITION was asked for with the streams; a moment for its first one.
    let _ = c
        .wait_for(tuning.home_wait.min(std::time::Duration::from_secs(2)), "", |c| {
            c.v.seen().home.is_some()
        })
        .await;
    if c.v.seen().armed {
        // Already flying: only its home says where it started.
        let left = by.saturating_duration_since(aviary_clock::Instant::now());
        let _ = c.wait_for(left, "", |c| c.v.seen().home.is_some()).await;
    }
    let (home, how) = {
        let seen = c.v.seen();
        match (seen.home, seen.fix) {
            (Some(h), _) => ([h[0], h[1]], "its home (HOME_POSITION)"),
            (None, Some(f)) if !seen.armed => {
                ([f.pos[0], f.pos[1]], "where it stands on the ground")
            }
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
