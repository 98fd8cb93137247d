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

/// What the bridge needs of the world, kept from the time it is read.
pub struct Seen {
    /// Where the world lets an operator send a drone.
    bounds: Bounds,
    /// What a station draws of it.
    map: serde_json::Value,
    /// Where its frame sits on the Earth, for ROS 2's fixes.
    origin: Option<aviary_api::geo::Origin>,
}

impl Seen {
    pub fn of(world: &aviary_world::World) -> Seen {
        Seen {
            bounds: Bounds::of(world),
            map: aviary_station::checking::map_of(world),
            origin: world.site.origin.as_ref().map(aviary_world::Geo::origin),
        }
    }
}

/// Starts the bridge on the run's `session`; says where on standard error.
pub fn start(
    session: aviary_zenoh::Session,
    zenoh: &Zenoh,
    mission: &Mission,
    Seen { bounds, map, origin }: Seen,
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
    let shown = serde_json::json!({
        "mission": mission.name,
        "tree": aviary_station::tree::of(mission, None),
        "map": map,
    });
    let ros = zenoh.ros.map(|domain| aviary_zenoh::ros::Ros { domain, origin });
    let api = Api { router, bound, feed: feed.clone(), mission: shown, ros };
    let bridge = Bridge::start(session, keys, api)?;
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
    // A name or an address that cannot work is said before anything joins the network.
    let checked = aviary_zenoh::AgentKeys::new(name)
        .and_then(|_| aviary_mavlink::link::crate_address(mavlink))
        .and_then(|_| aviary_zenoh::config(config));
    let session = match checked.and_then(aviary_zenoh::open) {
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

/// A client of the run under `prefix` (`--zenoh [CONFIG] --zenoh-prefix KEY`).
pub fn client(
    config: Option<&std::path::Path>,
    prefix: &str,
) -> Result<aviary_zenoh::Client, String> {
    let keys = aviary_zenoh::Keys::new(prefix)?;
    aviary_zenoh::Client::open(aviary_zenoh::config(config)?, keys)
}

/// `aviary gcs --zenoh [CONFIG] --zenoh-prefix KEY [--token TOKEN]`: the ground station of
/// a run on another machine, served until Ctrl-C.
pub fn station(
    client: aviary_zenoh::Client,
    token: Option<String>,
    serve: &crate::serve::Serve,
) -> u8 {
    let watched = || -> Result<aviary_station::Serving, String> {
        let shown = aviary_zenoh::remote::shown(&client)?;
        let prefix = client.keys().prefix().to_string();
        let options = aviary_station::Options {
            address: serve.address,
            allowed_hosts: serve.allowed_hosts.clone(),
            lsp: None,
        };
        let serving =
            aviary_station::serve(&options, aviary_station::Mode::Run, serde_json::Value::Null)?;
        let router = aviary_zenoh::remote::router(client, token.clone(), serving.gate())?;
        serving.serve_remote(router, shown.mission, shown.tree, shown.map);
        crate::serve::announce(&serving);
        use std::io::Write;
        let _ = writeln!(
            std::io::stderr(),
            "aviary: watching the run under {prefix}/ on Zenoh{}; Ctrl-C stops",
            if token.is_some() {
                " (and steering it with its token)"
            } else {
                " (without its token: watching only)"
            }
        );
        Ok(serving)
    };
    match watched() {
        Ok(_serving) => loop {
            // The station serves on its own thread until the process ends.
            std::thread::park();
        },
        Err(why) => {
            eprintln!("aviary: {why}");
            2
        }
    }
}
