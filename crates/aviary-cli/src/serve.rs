//! `aviary run --serve` and `aviary gcs`: the ground station's page and the operator API,
//! with the token printed once and a plain warning of how far the server can be reached.

use std::net::SocketAddr;

use aviary_engine::Controller;
use aviary_ir::Mission;
use aviary_server::{Bounds, Feed};
use aviary_station::{Lsp, Mode, Options, Serving};

/// Where and how to serve.
pub struct Serve {
    pub address: SocketAddr,
    /// `--allow-host`: names the server answers to besides loopback and its address.
    pub allowed_hosts: Vec<String>,
}

/// The station in `mode`, announced on standard error (which the operator reads; nothing
/// else ever prints or logs the token).
/// `lsp` is the language server of the page's editor, for a folder's station.
pub fn station(
    serve: &Serve,
    mode: Mode,
    map: serde_json::Value,
    lsp: Option<Lsp>,
) -> Result<Serving, String> {
    let options =
        Options { address: serve.address, allowed_hosts: serve.allowed_hosts.clone(), lsp };
    let serving = aviary_station::serve(&options, mode, map)?;
    announce(&serving);
    Ok(serving)
}

/// Where the station is and its token: said once the station answers every call it
/// will, since a client may call as soon as it reads the first line.
pub fn announce(serving: &Serving) {
    let url = serving.url();
    // The operator API's line first, then the warning, as they always were: scripts read
    // the first line, and the operator sees the warning before anything else. A script
    // that closes standard error after the first line must not stop the run: a write that
    // fails is let go (`eprintln!` would panic).
    use std::io::Write;
    let mut err = std::io::stderr();
    let _ = writeln!(
        err,
        "aviary: operator API on {}  token {}",
        url.trim_end_matches('/'),
        serving.token
    );
    if serving.beyond_loopback() {
        let _ = writeln!(
            err,
            "aviary: warning: the operator API listens on {} (the ground station with it) and can be reached from other machines. \
             Every call, reads and the event stream included, now needs the token, but plain HTTP carries it and the fleet's \
             positions unencrypted: put it behind a TLS reverse proxy (docs/OPERATOR_API.md) for use beyond this machine, or \
             serve on loopback.",
            serving.address
        );
    }
    let _ = writeln!(err, "aviary: ground station on {url}  (the same token)");
}

/// `aviary run --serve`: the station for this one run, and where the run's events go.
pub fn start(
    serve: &Serve,
    mission: &Mission,
    bounds: Bounds,
    map: serde_json::Value,
    controller: Controller,
) -> Result<(Serving, Feed), String> {
    let options =
        Options { address: serve.address, allowed_hosts: serve.allowed_hosts.clone(), lsp: None };
    let serving = aviary_station::serve(&options, Mode::Run, serde_json::Value::Null)?;
    let feed = serving.serve_run(controller, mission, bounds, map);
    announce(&serving);
    Ok((serving, feed))
}
