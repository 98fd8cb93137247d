//! `aviary run --zenoh`: the run's operator API behind a router of its own, carried on
//! Zenoh by `aviary_zenoh`, with the token printed once (the station's, when `--serve`
//! serves one too). And `aviary agent`, the other end of a world's `agent:NAME` drones.

use std::net::{Ipv4Addr, SocketAddr};

use aviary_engine::Controller;
use aviary_ir::Mission;
use aviary_server::{Bounds, Feed, Kinds};
use aviary_zenoh::{Api, Bridge, Keys};

use crate::run::Zenoh;

/// The run's session, opened before its vehicles connect: the world's `agent:NAME`
/// drones are reached on it too.
pub fn open(zenoh: &Zenoh) -> Result<aviary_zenoh::Session, String> {
    aviary_zenoh::open(aviary_zenoh::config(zenoh.config.as_deref())?)
}

/// Starts the bridge on the run's `session`; says where on standard error.
pub fn start(
    session: aviary_zenoh::Session,
    zenoh: &Zenoh,
    mission: &Mission,
    bounds: Bounds,
    controller: Controller,
    token: Option<String>,
) -> Result<(Bridge, Feed), String> {
    let keys = zenoh.keys.clone().unwrap_or_else(|| Keys::of_mission(&mission.name));
    let shared_token = token.is_some();
    let token = match token {
        Some(token) => token,
        None => aviary_server::new_token()?,
    };
    // A router no socket reaches: the bridge hands it each query as a request from this
    // machine, so reading needs no token (what it reads is published anyway) and every
    // control call does.
    let bound = SocketAddr::from((Ipv4Addr::LOCALHOST, 0));
    let options = aviary_server::Options {
        kinds: Kinds::of(mission).within(bounds),
        allowed_hosts: Vec::new(),
    };
    let (router, feed) = aviary_server::router(bound, token.clone(), controller, options);
    let prefix = keys.prefix().to_string();
    let bridge = Bridge::start(session, keys, Api { router, bound, feed: feed.clone() })?;
    use std::io::Write;
    let _ = writeln!(
        std::io::stderr(),
        "aviary: on Zenoh under {prefix}/: events, telemetry/DRONE, state; operator API {prefix}/api/CALL  token {}",
        if shared_token { "(the same)".to_string() } else { token }
    );
    Ok((bridge, feed))
}

/// `aviary agent --name NAME --mavlink ADDRESS [--zenoh CONFIG]`, until Ctrl-C.
pub fn agent(name: &str, mavlink: &str, config: Option<&std::path::Path>) -> u8 {
    let session = match aviary_zenoh::config(config).and_then(aviary_zenoh::open) {
        Ok(session) => session,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    let runtime = match tokio::runtime::Builder::new_multi_thread().enable_all().build() {
        Ok(runtime) => runtime,
        Err(e) => {
            eprintln!("aviary: cannot start the runtime: {e}");
            return 2;
        }
    };
    match runtime.block_on(aviary_zenoh::agent::serve(session, name, mavlink)) {
        Ok(()) => 0,
        Err(why) => {
            eprintln!("aviary: {why}");
            2
        }
    }
}
