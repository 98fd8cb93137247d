//! `aviary run --serve`: starting the operator API for a compiled mission, with the
//! kinds its arguments must have, and saying plainly how far it can be reached.

use std::net::SocketAddr;

use aviary_engine::Controller;
use aviary_ir::Mission;
use aviary_server::{Kinds, Options, Server};

/// Where and how to serve.
pub struct Serve {
    pub address: SocketAddr,
    /// `--allow-host`: names the server answers to besides loopback and its address.
    pub allowed_hosts: Vec<String>,
}

/// The kinds an operator's leash arguments and signal values must have.
pub fn kinds(mission: &Mission) -> Kinds {
    let mut kinds = Kinds::default();
    for c in &mission.capabilities {
        kinds.capability(
            &c.name,
            c.params.iter().cloned().zip(c.param_kinds.iter().copied()).collect(),
        );
    }
    for (name, values) in mission.signals.iter().zip(&mission.signal_values) {
        kinds.signal(name, values.clone());
    }
    kinds
}

/// Starts the server and prints where it is and its token (on standard error, which the
/// operator reads; nothing else ever prints or logs the token).
pub fn start(serve: &Serve, mission: &Mission, controller: Controller) -> Result<Server, String> {
    let options = Options { kinds: kinds(mission), allowed_hosts: serve.allowed_hosts.clone() };
    let server = aviary_server::start(serve.address, controller, options)?;
    let shown = match server.address.ip().is_unspecified() {
        // A wildcard address is no place to connect to; loopback reaches it from here.
        true => SocketAddr::new(std::net::Ipv4Addr::LOCALHOST.into(), server.address.port()),
        false => server.address,
    };
    eprintln!("aviary: operator API on http://{shown}  token {}", server.token);
    if !server.address.ip().is_loopback() {
        eprintln!(
            "aviary: warning: the operator API listens on {} and can be reached from other machines. Every call, reads and the event \
             stream included, now needs the token, but plain HTTP carries it and the fleet's positions unencrypted: put it behind a \
             TLS reverse proxy (docs/OPERATOR_API.md) for use beyond this machine, or serve on loopback.",
            server.address
        );
    }
    Ok(server)
}
