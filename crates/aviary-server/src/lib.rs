//! The operator API: the mission's state, its live event stream, and control calls, over
//! HTTP and WebSocket (axum). A web ground station builds on it; `aviary ctl` is its
//! command-line client; `docs/OPERATOR_API.md` documents it.
//!
//! It runs on a thread and runtime of its own, in real time, beside the engine's
//! simulated clock. It knows the mission only through the trace events it is fed
//! ([`Feed::publish`]) and the [`Controller`] it sends controls with.
//!
//! Invariants: every request names this server (`Host`) and comes from no other site's
//! page (`Origin`); every control call needs the run's token, and so does reading when
//! the server is bound beyond loopback (`guard.rs`); an operator's arguments are checked
//! against the mission's kinds, and its positions against the world's limits, before it
//! hears them (`args.rs`, `bounds.rs`); every error is JSON
//! (`reply.rs`). The server binds the address it is given; the CLI gives loopback unless
//! told otherwise.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod args;
mod bounds;
mod guard;
mod openapi;
mod relay;
mod reply;
pub mod requests;
mod routes;
mod state;
mod stream;

pub use args::{Kinds, MAX_MAGNITUDE};
pub use bounds::Bounds;
pub use guard::{read_token, same_origin, token, Gate, TOKEN_PROTOCOL};
pub use openapi::{openapi, openapi_yaml, state_schema};
pub use relay::{Line, Relay};
pub use reply::{error, json_errors, BODY_LIMIT};
pub use routes::events_router;

use parking_lot::{Mutex, MutexGuard};
use std::net::SocketAddr;
use std::sync::Arc;

use aviary_api::operator::{KindName, OperatorState, SignalValues};
use aviary_api::trace::Record;
use aviary_engine::Controller;
use tokio::sync::broadcast;

use crate::state::MissionState;

pub(crate) struct Shared {
    pub gate: Arc<Gate>,
    pub controller: Controller,
    pub state: Mutex<MissionState>,
    /// The run's lines, to the event streams.
    pub relay: Arc<Relay>,
    pub kinds: Kinds,
}

/// How to serve, beyond where.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// What the mission's leash arguments and signal values must be.
    pub kinds: Kinds,
    /// Host names to answer to besides loopback and the bound address (`--allow-host`):
    /// the name a reverse proxy forwards, or this machine's name on the network.
    pub allowed_hosts: Vec<String>,
}

impl Shared {
    pub fn state(&self) -> MutexGuard<'_, MissionState> {
        self.state.lock()
    }

    /// `GET /api/state`: the state folded from the trace, and the signals the operator
    /// may raise (which the trace does not say: they are the mission's).
    pub fn document(&self) -> OperatorState {
        let mut state = self.state().document();
        state.operator_signals = self.kinds.operator_signals();
        // What each carries, so that a form can read `x, y` as the one position it takes.
        state.operator_signal_values = SignalValues(
            self.kinds
                .operator_signal_values()
                .map(|(name, kinds)| {
                    (name.to_string(), kinds.iter().map(|k| k.map(KindName::from)).collect())
                })
                .collect(),
        );
        state
    }
}

/// The engine's side: every trace event goes through here.
#[derive(Clone)]
pub struct Feed {
    shared: Arc<Shared>,
}

impl Feed {
    /// After `mission_end`: waits (at most `limit`) until every open event stream has
    /// delivered it, so that no client misses how the mission ended.
    pub fn finish(&self, limit: std::time::Duration) {
        self.shared.relay.finish(limit);
    }

    /// The operator state now, as `GET /api/state` answers it.
    pub fn document(&self) -> OperatorState {
        self.shared.document()
    }

    /// Every event from now on, as its line, for a stream of the caller's own (the Zenoh
    /// bridge's), as [`Relay::subscribe`] gives them.
    pub fn subscribe(&self) -> broadcast::Receiver<Arc<Line>> {
        self.shared.relay.subscribe()
    }

    /// The events so far (telemetry aside), and how many older ones were let go: what a
    /// stream `?from=start` begins with.
    pub fn past(&self) -> (Vec<Arc<Line>>, u64) {
        self.shared.relay.past()
    }

    /// Folds the event into the mission's state and sends it to every stream, as the
    /// line the trace file has.
    pub fn publish(&self, record: &Record) {
        self.shared.state().observe(record);
        if let Some(line) = Line::of(record) {
            self.shared.relay.push(line);
        }
    }
}

/// The routes of a server bound at `bound`, without a socket: what a server serves (`serve`), and
/// what a fuzz target or a test drives request by request.
pub fn router(
    bound: SocketAddr,
    token: String,
    controller: Controller,
    options: Options,
) -> (axum::Router, Feed) {
    let gate = Arc::new(Gate::new(bound, token, &options.allowed_hosts));
    router_behind(gate, controller, options.kinds)
}

/// The routes of one run behind a gate that may guard more: a ground station's, which
/// serves one run after another with the same token.
pub fn router_behind(
    gate: Arc<Gate>,
    controller: Controller,
    kinds: Kinds,
) -> (axum::Router, Feed) {
    let state = Mutex::new(MissionState::default());
    let shared = Arc::new(Shared { gate, controller, state, relay: Relay::new(), kinds });
    (routes::router(shared.clone()), Feed { shared })
}

/// Binds `address` and serves the routes `make` gives for the bound address, on a
/// thread and a real-time runtime of their own, until the process ends; the address
/// bound (a port 0 is a free port). `what` names the server in messages.
pub fn serve(
    address: SocketAddr,
    what: &'static str,
    make: impl FnOnce(SocketAddr) -> axum::Router,
) -> Result<SocketAddr, String> {
    let listener = std::net::TcpListener::bind(address)
        .map_err(|e| format!("cannot listen on {address}: {e}"))?;
    listener.set_nonblocking(true).map_err(|e| e.to_string())?;
    let bound = listener.local_addr().map_err(|e| e.to_string())?;
    let app = make(bound);
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
        .map_err(|e| e.to_string())?;
    std::thread::Builder::new()
        .name(format!("aviary {what}"))
        .spawn(move || {
            runtime.block_on(async move {
                match tokio::net::TcpListener::from_std(listener) {
                    Ok(listener) => {
                        if let Err(e) = axum::serve(listener, app).await {
                            eprintln!("aviary: the {what} stopped: {e}");
                        }
                    }
                    Err(e) => eprintln!("aviary: the {what} cannot start: {e}"),
                }
            })
        })
        .map_err(|e| e.to_string())?;
    Ok(bound)
}

/// A new token: 16 random bytes, in hex.
pub fn new_token() -> Result<String, String> {
    let mut bytes = [0u8; 16];
    getrandom::fill(&mut bytes).map_err(|e| format!("no randomness for the token: {e}"))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}
