//! Asking vehicles for their facts over their links, with retries and a deadline: a
//! vehicle that is off, silent, or serves no parameters costs a bounded wait and leaves
//! the world's figures.

use std::sync::Arc;
use std::time::Duration;

use aviary_api::DroneId;
use aviary_clock::Instant;
use aviary_world::World;
use mavlink::dialects::ardupilotmega::{
    MavCmd, MavMessage, COMMAND_LONG_DATA, PARAM_REQUEST_READ_DATA,
};
use tokio::sync::mpsc;

use super::{table, Facts};
use crate::link::Link;
use crate::vehicle::Vehicle;
use crate::Origin;

/// Unanswered requests are sent again this often (a request or its answer may be lost).
const ASK_EVERY: Duration = Duration::from_secs(1);
/// A vehicle that has answered no parameter by then serves none (`aviary vehicles`
/// does not): waiting longer would only delay every run.
const SILENT: Duration = Duration::from_millis(2500);
/// How often the answers are looked at.
const POLL: Duration = Duration::from_millis(50);

/// Reads the facts of vehicle `v` on `link`: its HEARTBEAT (for its autopilot), then
/// every parameter of its autopilot's table by name, and its charge, until all are in or
/// `until`.
pub(crate) async fn read(drone: usize, link: &Link, v: &Vehicle, until: Instant) -> Facts {
    while v.seen().heartbeat.is_none() {
        if Instant::now() >= until {
            return Facts::unheard(drone, &v.name, &link.address, v.system, "no HEARTBEAT".into());
        }
        aviary_clock::sleep(POLL).await;
    }
    let flavour = v.flavour();
    let table = table(flavour);
    let started = Instant::now();
    let mut asked: Option<Instant> = None;
    loop {
        let (missing, charge_known) = {
            let seen = v.seen();
            let missing: Vec<&'static str> = table
                .iter()
                .filter(|p| !seen.params.contains_key(p.name))
                .map(|p| p.name)
                .collect();
            let charge_known = seen.battery.is_some() || seen.battery_reported;
            (missing, charge_known)
        };
        let answered = table.len() - missing.len();
        let now = Instant::now();
        let silent = answered == 0 && now.duration_since(started) >= SILENT;
        if (missing.is_empty() && charge_known) || now >= until || silent {
            break;
        }
        if asked.is_none_or(|t| now.duration_since(t) >= ASK_EVERY) {
            asked = Some(now);
            for name in &missing {
                link.send(&MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
                    param_index: -1,
                    target_system: v.system,
                    target_component: 1,
                    param_id: (*name).into(),
                }))
                .await;
            }
            if !charge_known {
                // SYS_STATUS (id 1) once, now: the streams are asked for later, at connect.
                link.send(&MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
                    command: MavCmd::MAV_CMD_REQUEST_MESSAGE,
                    param1: 1.0,
                    target_system: v.system,
                    target_component: 1,
                    ..COMMAND_LONG_DATA::default()
                }))
                .await;
            }
        }
        aviary_clock::sleep(POLL).await;
    }
    let seen = v.seen();
    Facts::answered_by(
        drone,
        &v.name,
        &link.address,
        v.system,
        flavour,
        &seen.params,
        seen.battery.map(|b| b * 100.0),
    )
}

/// Asks every MAVLink drone of `world` for its facts, all at once, and gives up on each
/// after `wait`: for `aviary check --plan`, which flies nothing. An address that cannot
/// be reached, or a vehicle that does not answer, gives [`Facts::unheard`]. A world
/// whose bindings cannot work (two drones on one system id) is an error.
pub async fn ask(world: &World, wait: Duration) -> Result<Vec<Facts>, String> {
    let until = Instant::now() + wait;
    let bound = crate::bindings(world);
    let links = crate::link_keys(world, &bound)?;
    let origin = world
        .site
        .origin
        .as_ref()
        .map_or(Origin { lat: 0.0, lon: 0.0, alt: 0.0 }, aviary_world::Geo::origin);
    // Nobody listens: asking flies nothing, so nothing is detected or raised.
    let (events, _) = mpsc::unbounded_channel();
    let (alarms, _) = mpsc::unbounded_channel();
    let mut tasks = tokio::task::JoinSet::new();
    for (address, key) in links {
        let drones: Vec<(usize, String, u8)> = bound
            .iter()
            .filter(|b| b.1 == address)
            .map(|(i, _, system, _)| (*i, world.drones[*i].name.clone(), *system))
            .collect();
        let (events, alarms) = (events.clone(), alarms.clone());
        tasks.spawn(async move {
            let key = key.as_deref().map(crate::signing_key);
            let opened = aviary_clock::timeout_at(until, Link::open(&address, key, None)).await;
            let link = match opened {
                Ok(Ok(link)) => link,
                Ok(Err(why)) => {
                    return drones
                        .iter()
                        .map(|(i, n, s)| Facts::unheard(*i, n, &address, *s, why.clone()))
                        .collect()
                }
                Err(_) => {
                    return drones
                        .iter()
                        .map(|(i, n, s)| {
                            Facts::unheard(*i, n, &address, *s, "no connection".into())
                        })
                        .collect()
                }
            };
            let mut reads = tokio::task::JoinSet::new();
            for (i, name, system) in drones {
                let v = Arc::new(Vehicle::new(
                    DroneId(i),
                    name,
                    system,
                    origin,
                    Vec::new(),
                    events.clone(),
                    alarms.clone(),
                ));
                link.add(Arc::clone(&v));
                let link = Arc::clone(&link);
                reads.spawn(async move { read(i, &link, &v, until).await });
            }
            let mut out = Vec::new();
            while let Some(done) = reads.join_next().await {
                out.extend(done.ok());
            }
            out
        });
    }
    let mut out: Vec<Facts> = Vec::new();
    while let Some(done) = tasks.join_next().await {
        out.extend(done.unwrap_or_default());
    }
    out.sort_by_key(|f| f.drone);
    Ok(out)
}
