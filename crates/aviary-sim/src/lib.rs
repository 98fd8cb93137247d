//! The built-in multirotor simulator, and the default backend of `aviary run`.
//!
//! Two layers:
//! - [`Fleet`], the physics core: every drone of a [`aviary_world::World`], advanced by
//!   [`Fleet::step`]`(dt)`. Calls start with [`Fleet::call`], are paused, resumed or
//!   aborted with [`Fleet::interrupt`], and end (with the drone events) in the [`Report`]s
//!   that `step` returns.
//! - [`SimBackend`], the [`aviary_api::Backend`] the engine drives: the core behind a
//!   mutex, stepped by one tokio task every [`SimOptions::tick`] seconds of tokio time,
//!   answering calls through their oneshot channels and sending drone events.
//!
//! # Invariants
//! - Deterministic: the same world and the same calls, made between the same steps, give
//!   the same telemetry, call ends and events, bit for bit. No randomness, no hash-map
//!   iteration, drones and targets always in world-file order.
//! - The physics core is pure: nothing async, no clock, no IO. Simulated time is the sum
//!   of the steps.
//! - No wall clock, unless [`SimOptions::speed`] is set: then the driver only *waits* on
//!   the wall clock to pace itself; what happens does not depend on it.
//!
//! # Model (and what it leaves out)
//! - Each drone is a point mass, landed and disarmed at its home (on the ground, z = 0;
//!   a home's z is ignored) at the start.
//! - A move is a chain of legs flown from rest to rest: straight lines over the ground at
//!   up to the speed asked (at most `max_speed`) with, at the same time, a vertical move at
//!   up to `climb_rate`; each axis follows a trapezoidal speed profile (accelerate and
//!   brake at most `acceleration`). A path (`Sweep`, `FollowPath`, `ReturnToLaunch`) stops
//!   at each corner. Orbits fly clockwise at up to `max_speed`, slow enough that the
//!   centripetal acceleration stays within half of `acceleration`.
//! - A pause or an abort stops the drone at once, where it is; it then hovers.
//! - No wind, no sensor noise, no collision avoidance or separation between drones (the
//!   safety work adds separation later), no terrain: the ground is z = 0 everywhere.
//! - The battery drains only in the air, linearly in time (`1 / endurance` of a full
//!   battery per second, whatever the drone does).
//! - Sensors see every target of their kinds within their range of the drone's ground
//!   point, whatever the altitude, checked along the way flown in each step.
//!
//! # Functions
//! `Arm`/`Disarm` (landed only), `TakeOff(alt)` (armed; or, in the air, a climb or
//! descent to `alt`), `Land` (lands and disarms), `ReturnToLaunch` (climbs to at least
//! 10 m, or the site's `max_altitude` if lower, flies home and lands; done at once when
//! landed at home), `FlyToPosition(pos[, speed])` (a position without z keeps the
//! altitude), `DescendTo(alt)`/`AscendTo(alt)` (either direction), `Hover(duration)`
//! (also on the ground, as a wait), `Orbit(center, radius[, laps])` (from the nearest point
//! of the circle, at the current altitude), `Sweep(area, spacing)` (see [`sweep`]),
//! `FollowPath(points...)`, `StartStreaming`/`StopStreaming` (need a `camera`),
//! `StartDetection(kind)`/`StopDetection(kind)` (need a sensor that detects the kind),
//! `LoadPayload(kind)` (a kind the drone lists, nothing carried, landed or below 5 m;
//! takes [`LOAD_TIME`] = 2 s) and `ReleasePayload()` (logged in [`Fleet::releases`]).
//! `FlyToPosition`, `DescendTo`, `AscendTo`, `Orbit`, `Sweep` and `FollowPath` need the
//! drone in the air (`CommandFailed`: "take off first"); a target altitude is taken as
//! given (a position with z = 0 flies down to the ground). A motion whose target or path
//! leaves the geofence, or goes above `max_altitude`, is refused at once with
//! `GeofenceViolation` and the drone does not move. A second motion call while one is in
//! progress is refused (`CommandFailed`); the engine serialises calls per resource, so
//! that does not happen.
//!
//! # Battery and faults
//! With `need` = (distance home / `max_speed` + altitude / `climb_rate`) / `endurance`,
//! `BatteryLow` is signalled once when the charge falls under `2 × need + 10 %`, and
//! `BatteryCritical` raised once under `need + 10 %` (ending the drone's calls in
//! progress `Interrupted`); at zero the drone falls (`Lost`, `DroneLost`). The world's
//! `[[faults]]` fire at their time in simulated seconds (see the `faults` module).
//!
//! # Driver
//! [`SimBackend::start`] spawns the driver; it ends at its next tick after
//! [`SimBackend::stop`] (or [`SimBackend::shutdown`], which also waits for it), or once
//! the last `Arc<SimBackend>` is dropped. Simulated time equals tokio time since the start
//! (as long as the runtime keeps up, as it does with a paused clock).

mod args;
mod backend;
mod battery;
mod calls;
mod drone;
mod faults;
mod fleet;
mod geom;
mod motion;
mod profile;
mod sensors;
pub mod sweep;
#[cfg(test)]
mod tests;

pub use backend::{SimBackend, SimOptions};

/// What the simulator offers: the standard middle layer (LANGUAGE.md §4). The checker
/// reads this before a run, so a function the simulator added would be known to it.
pub fn descriptor() -> aviary_api::Descriptor {
    aviary_api::Descriptor::standard()
}
pub use calls::{LOAD_MAX_ALTITUDE, LOAD_TIME, RETURN_ALTITUDE};
pub use fleet::{Fleet, Release, Report};
