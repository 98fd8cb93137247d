//! The benchmarks: `generate`, large missions and worlds of any size, written in the
//! language (for `aviary bench` and for the tests of the other crates, a dev-dependency
//! there), and the benchmarks `aviary bench` runs on them, each a function that writes
//! its report to the `Write` it is given: [`parse()`] (the front end), [`front()`] (all of
//! `aviary check`), [`w()`] (the engine, W(N, K)) and [`swarm()`] (the simulator) and [`campaign()`] (`aviary test`, many seeds at once). The
//! scale benchmarks fly through `aviary_pipeline::fly`, the pipeline of `aviary run`, so
//! they measure what a user runs.
//!
//! Invariants: the generators' output is a function of their arguments only; a
//! benchmark reads no file and writes only to the `Write` it is given. The one thing it
//! reads of the system is its own peak memory (`/proc/self/status`, [`stages::peak_rss`]).

// No unsafe code, and no panic on any input (tests may unwrap).
#![forbid(unsafe_code)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod campaign;
mod front;
pub mod generate;
mod parse;
pub mod stages;
mod swarm;
mod w;

use std::time::Duration;

pub use campaign::{campaign, PAPER_MISSION, PAPER_WORLD};
pub use front::{front, Shape};
pub use parse::parse;
pub use swarm::swarm;
pub use w::w;

/// Why a benchmark stopped short, or said it failed.
#[derive(Debug)]
pub enum Error {
    /// The arguments are wrong (`aviary` exits 2).
    Usage(String),
    /// The benchmark could not do its work: a generated mission with errors, a run that
    /// did not start (`aviary` exits 1).
    Failed(String),
    /// The report, written whole, says the work was not all done (`ok=false`; `aviary`
    /// exits 1, with nothing more to say).
    NotOk,
    /// The report could not be written.
    Write(std::io::Error),
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Error {
        Error::Write(e)
    }
}

/// What to print instead of running: `--emit` (the mission) wins over `--emit-world`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Emit {
    Nothing,
    Mission,
    World,
}

impl Emit {
    pub fn of(mission: bool, world: bool) -> Emit {
        match (mission, world) {
            (true, _) => Emit::Mission,
            (false, true) => Emit::World,
            (false, false) => Emit::Nothing,
        }
    }
}

/// MB here is 10^6 bytes.
pub(crate) const MB: f64 = 1_000_000.0;

pub(crate) fn rate(bytes: usize, time: Duration) -> f64 {
    bytes as f64 / MB / time.as_secs_f64().max(1e-9)
}

pub(crate) fn median(times: &mut [Duration]) -> Duration {
    times.sort_unstable();
    let n = times.len();
    if n % 2 == 1 {
        times[n / 2]
    } else {
        (times[n / 2 - 1] + times[n / 2]) / 2
    }
}
