//! The ground station: one web page, served over HTTP beside the operator API, where an
//! operator loads a mission and its world, checks them, flies them and watches and steers
//! the flight on a map, a fleet grid, the block tree and a log (`docs/GCS.md`).
//!
//! Three ways to serve it ([`Mode`]): `aviary gcs DIR` (the missions and worlds of a
//! folder, each flown from the page), `aviary run --serve` (one run, started from the
//! command line) and `aviary replay TRACE` (a recorded trace, played back on the page). The page and the code it loads
//! are embedded in the binary (`assets.rs`); the operator API of the flight in progress
//! is `aviary_server`'s, reached through the same address, behind the same [`Gate`]:
//! one token for the station's lifetime.
//!
//! Invariants: every request passes the gate (Host, Origin; the token for anything that
//! changes something, and for reading beyond loopback); the page names files only inside
//! the station's folder (`dir.rs`); no page loads anything from another site.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod assets;
pub mod campaign;
pub mod checking;
mod dir;
mod flight;
mod lsp;
pub mod replay;
pub mod report;
mod routes;
mod tiles;
pub mod tree;
mod wire;

use std::net::SocketAddr;
use std::path::Path;
use std::sync::Arc;

use parking_lot::Mutex;

use aviary_check::SourceProvider;
use aviary_engine::Controller;
use aviary_server::{Bounds, Feed, Gate, Kinds};
use serde_json::Value;

use crate::wire::{RunShown, VehiclePlan};

pub use dir::{refused_name, Access, Folder, Listing};
pub use lsp::{Lsp, MAX_SOCKETS as MAX_LSP_SOCKETS};

/// How the station finds the files a mission `USE`s: the command line's provider, made
/// for a mission file (its folder, and the `--use-root`s).
pub type FilesFor =
    Box<dyn Fn(&Path) -> Result<Box<dyn SourceProvider + Send>, String> + Send + Sync>;

/// What the station serves.
pub enum Mode {
    /// `aviary gcs DIR`: the folder's missions and worlds, flown from the page.
    Folder { folder: Folder, files: FilesFor },
    /// `aviary run --serve`: the one run the command line flies.
    Run,
    /// `aviary replay`: a recorded trace, each line an event (read and checked by the
    /// caller, `replay::read`).
    Replay { name: String, trace: String },
}

impl Mode {
    fn name(&self) -> &'static str {
        match self {
            Mode::Folder { .. } => "station",
            Mode::Run => "run",
            Mode::Replay { .. } => "replay",
        }
    }
}

/// The flight whose operator API the station serves now.
pub(crate) struct Run {
    pub router: axum::Router,
    pub mission: String,
    pub tree: Value,
    /// Where its trace is written, for a flight from the page.
    pub trace: Option<String>,
    /// With MAVLink drones, the plan made again with the vehicles' figures: `None` until
    /// they answered, then its warnings (`vehicle_plan` of `/api/station`).
    pub vehicle_plan: VehiclePlan,
}

pub(crate) struct Station {
    pub mode: Mode,
    pub gate: Arc<Gate>,
    run: Mutex<Option<Run>>,
    /// A flight from the page is under way: the next waits for its end.
    pub flying: std::sync::atomic::AtomicBool,
    /// The world of the flight or trace shown, as the map draws it.
    map: Mutex<Value>,
    /// The language server for the page's editor (`/api/lsp`), if the station has one.
    pub lsp: Option<Lsp>,
    /// Its sockets open now (`lsp::MAX_SOCKETS` at most).
    pub lsp_sockets: std::sync::atomic::AtomicUsize,
}

impl Station {
    /// Serves the operator API of a run of `mission` from now on (the last one's goes);
    /// its events go to the feed returned. `bounds` are where its world lets the operator
    /// send a drone, `tree` is what the page shows of the mission, `trace` where its trace
    /// is written, if the station writes it.
    pub fn start_run(
        &self,
        controller: Controller,
        mission: &aviary_ir::Mission,
        bounds: Bounds,
        tree: Value,
        trace: Option<String>,
    ) -> Feed {
        let (router, feed) = aviary_server::router_behind(
            self.gate.clone(),
            controller,
            Kinds::of(mission).within(bounds),
        );
        let vehicle_plan = VehiclePlan::None;
        *self.run.lock() =
            Some(Run { router, mission: mission.name.clone(), tree, trace, vehicle_plan });
        feed
    }

    /// Serves a run that flies on another machine: `router` answers its operator API's
    /// calls, `mission` and `tree` are what the page shows of it.
    pub fn watch(&self, router: axum::Router, mission: String, tree: Value) {
        let vehicle_plan = VehiclePlan::None;
        *self.run.lock() = Some(Run { router, mission, tree, trace: None, vehicle_plan });
    }

    /// The run's plan with the vehicles' figures: `Due` from the start of a flight with
    /// MAVLink drones, then what it says.
    pub(crate) fn set_vehicle_plan(&self, plan: VehiclePlan) {
        if let Some(run) = self.run.lock().as_mut() {
            run.vehicle_plan = plan;
        }
    }

    pub fn set_map(&self, map: Value) {
        *self.map.lock() = map;
    }

    pub fn map(&self) -> Value {
        self.map.lock().clone()
    }

    /// The routes of the flight in progress (or the last one), and what the page shows of it.
    pub fn run(&self) -> Option<(axum::Router, RunShown)> {
        self.run.lock().as_ref().map(|r| {
            let shown = RunShown {
                mission: r.mission.clone(),
                tree: r.tree.clone(),
                trace: r.trace.clone(),
                vehicle_plan: r.vehicle_plan.clone(),
            };
            (r.router.clone(), shown)
        })
    }
}

/// Where and for whom to serve.
#[derive(Clone, Debug)]
pub struct Options {
    pub address: SocketAddr,
    /// `--allow-host`: names to answer to besides loopback and the bound address.
    pub allowed_hosts: Vec<String>,
    /// The language server of the page's editor (`/api/lsp`): `aviary lsp`'s, made by the
    /// command line; none, and the editor checks only with the Check button.
    pub lsp: Option<Lsp>,
}

/// A station being served.
pub struct Serving {
    pub address: SocketAddr,
    pub token: String,
    station: Arc<Station>,
}

impl Serving {
    /// The address to open in a browser: loopback for a wildcard bind.
    pub fn url(&self) -> String {
        let shown = match self.address.ip().is_unspecified() {
            true => SocketAddr::new(std::net::Ipv4Addr::LOCALHOST.into(), self.address.port()),
            false => self.address,
        };
        format!("http://{shown}/")
    }

    /// Whether other machines can reach it.
    pub fn beyond_loopback(&self) -> bool {
        self.station.gate.beyond_loopback()
    }

    /// For `aviary run --serve`: the operator API of the run, and where its events go.
    /// `map` is what the page shows of its world, `bounds` where the world lets the
    /// operator send a drone.
    pub fn serve_run(
        &self,
        controller: Controller,
        mission: &aviary_ir::Mission,
        bounds: Bounds,
        map: Value,
    ) -> Feed {
        self.station.set_map(map);
        self.station.start_run(controller, mission, bounds, tree::of(mission, None), None)
    }
}

impl Serving {
    /// For `aviary gcs --zenoh`: a run on another machine, whose operator API `router`
    /// reaches (behind this station's [`Serving::gate`]). `mission`, `tree` and `map` are
    /// what the page shows of it, as the run gives them.
    pub fn serve_remote(&self, router: axum::Router, mission: String, tree: Value, map: Value) {
        self.station.set_map(map);
        self.station.watch(router, mission, tree);
    }

    /// Who may call this station: the routes of a run it serves stand behind it too.
    pub fn gate(&self) -> Arc<Gate> {
        self.station.gate.clone()
    }
}

/// The routes of a station in `mode` bound at `bound`, without a socket: what [`serve`]
/// serves, and what the `fuzz_station` target drives request by request.
pub fn router(
    mode: Mode,
    bound: SocketAddr,
    token: String,
    allowed_hosts: &[String],
    map: Value,
    lsp: Option<Lsp>,
) -> axum::Router {
    routes::router(station(mode, bound, token, allowed_hosts, map, lsp))
}

fn station(
    mode: Mode,
    bound: SocketAddr,
    token: String,
    allowed_hosts: &[String],
    map: Value,
    lsp: Option<Lsp>,
) -> Arc<Station> {
    Arc::new(Station {
        mode,
        gate: Arc::new(Gate::new(bound, token, allowed_hosts)),
        run: Mutex::new(None),
        flying: Default::default(),
        map: Mutex::new(map),
        lsp,
        lsp_sockets: Default::default(),
    })
}

/// Binds `options.address` and serves the station in `mode`, on a thread of its own.
pub fn serve(options: &Options, mode: Mode, map: Value) -> Result<Serving, String> {
    let token = aviary_server::new_token()?;
    let mut made = None;
    let address = aviary_server::serve(options.address, "ground station", |bound| {
        let s =
            station(mode, bound, token.clone(), &options.allowed_hosts, map, options.lsp.clone());
        made = Some(s.clone());
        routes::router(s)
    })?;
    let station = made.ok_or("the station was not made")?;
    Ok(Serving { address, token, station })
}
