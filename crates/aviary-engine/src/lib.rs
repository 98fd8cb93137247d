//! The executor: runs a compiled mission on a fleet through the middle layer.
//!
//! Every block, capability instance and handler instance is its own future, polled
//! concurrently (`FuturesUnordered`) on one thread: lightweight tasks that borrow the IR
//! (tokio tasks would need `'static` copies of it).
//! Cancellation is dropping: resource claims and calls in flight are released by drop
//! guards, so an abort can never leave a claim held or a drone commanded. Time is the
//! run's clock (`aviary_clock`): in a simulated run a virtual clock that takes no real
//! time, and on one thread the same inputs give the same trace.
//!
//! Invariant: the engine knows no backend; it talks to `aviary_api::Backend` only.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod activity;
mod api;
mod arbiter;
mod cancel;
mod choose;
mod control;
mod coverage;
mod directory;
mod engine;
mod exec;
mod homing;
mod instant;
mod jobs;
mod join;
mod place;
mod registry;
mod section;
mod steer;
mod value;

use aviary_api::Backend;

pub use aviary_api::trace::{Event, EventKind, OperatorAction, Record, Status};
use aviary_ir::Mission;
pub use control::{Control, ControlRequest, Controller, Controls, DroneAction, Unknown};
pub use directory::Directory;

/// Where trace events go, in order: the typed events of `aviary_api::trace`, which a
/// sink writes as JSON (the trace file, the operator API) or reads field by field.
pub trait TraceSink {
    /// Whether this sink takes events of this kind. The engine asks once per kind as the
    /// run starts and makes an event only when its sink wants it, so a sink that keeps a
    /// few kinds spares the cost of the rest; what the mission does is the same either way.
    fn wants(&self, _kind: EventKind) -> bool {
        true
    }
    /// An event as the engine makes it, its text borrowed from the run.
    fn record(&mut self, record: &Record<'_>);
}

impl<F: FnMut(&Record<'_>)> TraceSink for F {
    fn record(&mut self, record: &Record<'_>) {
        self(record)
    }
}

#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Telemetry events per second of mission time; `None` for none.
    pub telemetry_hz: Option<f64>,
    /// How deep capability calls may nest (a capability that calls one that calls ...):
    /// a call that would go deeper raises `CommandFailed` where it stands instead of
    /// starting. Each level is a future inside its caller's, polled on the stack, so the
    /// thread that runs the engine must hold this many: about 30 KB a level in a debug
    /// build and 6 KB in release (`aviary` runs on a 1 GiB stack). A recursion the
    /// checker allows (one behind a condition) ends here, never in a stack overflow.
    pub max_call_depth: usize,
    /// How many times a handler may be re-entered at one instant: started again by an
    /// exception or a signal that one of its own instances led to at that instant (its
    /// body threw or raised at once, or a handler that its body started did), counted
    /// over everything the first exception or signal led to then. Past the limit an
    /// exception handler does not take the exception: it goes on outward as if the
    /// handler were not there, and the trace says which handler was passed over and why
    /// (docs/LANGUAGE.md, section 12). A signal's handler is not started again: the
    /// signals go round in a cycle at one instant, and the mission fails with the reason,
    /// its fleet sent home (section 11). Without it, such a handler would run for ever at
    /// one instant, the trace growing without end, and the engine's thread, never
    /// waiting, would not even read its controls.
    pub max_handler_reentries: usize,
    /// The world file the run flies in, named in its `mission_start` (a replay or a
    /// report draws that world and refuses another); `None` for a mission flown without
    /// one (the tests' own worlds).
    pub world: Option<aviary_api::trace::WorldStamp<'static>>,
}

/// The default [`RunOptions::max_call_depth`]: twice the 5,000-deep chain the CLI's tests
/// run, and 300 MB of stack in a debug build.
pub const MAX_CALL_DEPTH: usize = 10_000;

/// The default [`RunOptions::max_handler_reentries`]: the language's
/// ([`aviary_api::MAX_HANDLER_REENTRIES`]).
pub const MAX_HANDLER_REENTRIES: usize = aviary_api::MAX_HANDLER_REENTRIES;

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            telemetry_hz: None,
            max_call_depth: MAX_CALL_DEPTH,
            max_handler_reentries: MAX_HANDLER_REENTRIES,
            world: None,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    pub status: Status,
    pub reason: Option<String>,
    /// Where the unhandled exception that failed the mission was raised, if one did: the
    /// `THROW` statement, the capability call whose start failed, or the drone's
    /// middle-layer call in progress (its latest) when a fault or a refusal raised it.
    pub at: Option<aviary_ir::Origin>,
}

/// Runs `mission` to its end. Must be polled inside a tokio runtime (current-thread).
pub async fn run(
    mission: &Mission,
    backend: &dyn Backend,
    sink: &mut dyn TraceSink,
    options: &RunOptions,
) -> Outcome {
    engine::Engine::new(mission, backend, sink, options).run(options, None).await
}

/// The engine with every activity on the general path, for the tests that hold the instant
/// path to it (`tests/instant.rs`): only in builds with the `testing` feature, which only
/// the tests' support crate (a dev-dependency) turns on. An option of [`RunOptions`] would
/// let a user's run take a path that is not the one users run.
#[cfg(feature = "testing")]
pub mod testing {
    use super::*;

    /// As [`run_controlled`](super::run_controlled), on the general path only.
    pub async fn run_on_the_general_path(
        mission: &Mission,
        backend: &dyn Backend,
        sink: &mut dyn TraceSink,
        options: &RunOptions,
        controls: Option<Controls>,
    ) -> Outcome {
        let mut engine = engine::Engine::new(mission, backend, sink, options);
        engine.instant.fill(false);
        engine.run(options, controls).await
    }
}

/// As [`run`], and takes live controls (an operator, Ctrl-C) from `controls`.
pub async fn run_controlled(
    mission: &Mission,
    backend: &dyn Backend,
    sink: &mut dyn TraceSink,
    options: &RunOptions,
    controls: Controls,
) -> Outcome {
    engine::Engine::new(mission, backend, sink, options).run(options, Some(controls)).await
}
