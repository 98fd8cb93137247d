//! Simulated time of our own. A simulated run is one current-thread tokio runtime
//! ([`Builder`], [`Runtime`]) whose virtual [`Clock`] moves only when every task waits:
//! then it jumps to the earliest pending deadline and wakes what is due there, so
//! simulated time costs no real time. The time primitives ([`Instant`], [`sleep`],
//! [`sleep_until`], [`interval`], [`interval_at`], [`timeout`], [`timeout_at`]) mirror
//! tokio's names and semantics so that code written for `tokio::time` moves over by its
//! `use` lines, and traces stay what they were on tokio's paused clock: deadlines are
//! rounded up to whole milliseconds as tokio's timer rounds them, timers due at one
//! instant wake in the order they were registered, and a sleep spends the task's
//! cooperative budget as tokio's does.
//!
//! Pacing is the clock's own: a runtime built with a [`Reference`] never lets the clock
//! pass it (a run at `--speed`, or a live run following the vehicles' clocks), and wakes
//! in real time, every few milliseconds, to move on as the reference moves.
//!
//! Outside such a runtime (a thread of its own, a plain tokio runtime: the MAVLink
//! backend on `aviary vehicles`' tests, the operator server) the primitives are tokio's
//! real-time timer and the wall clock, so a library written against this crate works in
//! both.
//!
//! No IO: the crate knows tokio's scheduler and timer, nothing else.

#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod clock;
mod interval;
mod runtime;
mod sleep;

pub use clock::{advance, Clock};
pub use interval::{interval, interval_at, Interval};
pub use runtime::{Builder, Reference, Runtime, Speed};
pub use sleep::{sleep, sleep_until, timeout, timeout_at, Elapsed, Instant, Sleep};
