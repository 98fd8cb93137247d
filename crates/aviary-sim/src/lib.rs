//! The built-in multirotor simulator, and the default backend of `aviary run`.
//!
//! Two layers:
//! - [`Fleet`], the physics core: every drone of a [`aviary_world::World`], advanced by
//!   [`Fleet::step`]`(dt)`. Calls start with [`Fleet::call`], are paused, resumed or
//!   aborted with [`Fleet::interrupt`], and end (with the drone events) in the [`Report`]s
//!   that `step` returns.
//! - [`SimBackend`], the [`aviary_api::Backend`] the engine drives: the core behind a
//!   mutex, stepped by one tokio task every [`SimOptions::tick`] seconds of the run's clock,
//!   answering calls through their oneshot channels and sending drone events.
//!
//! # Invariants
//! - Deterministic: the same world, seed ([`Fleet::seeded`]; 0 unless given) and calls,
//!   made between the same steps, give the same telemetry, call ends and events, bit for
//!   bit. No randomness but the chances the world asks for, drawn from the seed in streams
//!   of their own (the `luck` module); no hash-map iteration; drones and targets always in
//!   world-file order. A world that asks for no chance runs the same whatever the seed.
//! - The physics core is pure: nothing async, no clock, no IO. Simulated time is the sum
//!   of the steps.
//! - No wall clock: a paced run (`--speed`, a live run's [`Pace`]) only *waits* on it,
//!   through its runtime's clock (`aviary_clock`); what happens does not depend on it.
//!
//! # Model (and what it leaves out)
//! - Each drone is a point mass, landed and disarmed at its home (on the ground, z = 0;
//!   a home's z is ignored) at the start.
//! - A move is a chain of legs flown from rest to rest: straight lines over the ground at
//!   up to the speed asked (at most `max_speed`) with, at the same time, a vertical move at
//!   up to `climb_rate` (up; `takeoff_speed` from the ground) or `descent_rate` (down),
//!   and a landing's last
//!   `land_speed_below` metres at `land_speed`; each axis follows a trapezoidal speed profile (accelerate and
//!   brake at most `acceleration`). A path (`Sweep`, `FollowPath`, `ReturnToLaunch`) stops
//!   at each corner. Orbits fly clockwise at up to `max_speed`, slow enough that the
//!   centripetal acceleration stays within half of `acceleration`.
//! - A pause or an abort stops the drone at once, where it is; it then hovers.
//! - No wind, no sensor noise, no obstacles, no terrain: the ground is z = 0 everywhere.
//!   Drones keep their separation from each other (below), nothing else. The world's
//!   `[air]` adds wind with Dryden gusts, a radio's reach with relays, GPS noise, a
//!   detection chance that falls with range, spread capacities and random faults (the
//!   `air` module; docs/CAMPAIGNS.md, "The models"); without it, none of them.
//! - The battery drains only in the air, linearly in time (`1 / endurance` of a full
//!   battery per second, whatever the drone does; in a wind, more with the airspeed).
//! - Sensors see every target of their kinds within their range of the drone's ground
//!   point, whatever the altitude, checked along the way flown in each step; a sensor with
//!   a `probability` below 1 finds each with that chance, drawn once as it comes within
//!   range (the `sensors` module).
//!
//! # Functions
//! `Arm`/`Disarm` (landed only), `TakeOff(alt)` (armed; or, in the air, a climb or
//! descent to `alt`), `Land` (lands and disarms), `ReturnToLaunch` (climbs to at least
//! `return_altitude`, or the site's `max_altitude` if lower, flies home at
//! `return_speed`, waits
//! `return_loiter` above home and lands; done at once when
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
//! # No-fly zones
//! A transit (`FlyToPosition`, the way to an orbit's circle or a sweep's first lane, each
//! leg of `FollowPath`, the way home of `ReturnToLaunch` and of the return after a link
//! loss) is the route of `aviary_route` (the one planner, shared with the checker, the plan
//! and the MAVLink backend): its legs go around the zones that hold at the lower of the
//! transit's two heights, at the planner's margin, and it is the one straight leg of
//! before when no zone is in the way. What a function flies by itself (an orbit's circle,
//! a sweep's lanes) must keep out of the zones, and a move straight down (`DescendTo`,
//! `Land`) must not come down into one: else the call is refused with
//! `GeofenceViolation`, as is a transit with no way around.
//!
//! # Separation
//! No two drones *in the air* (taking off, flying or landing, and above the ground; a
//! landed or lost drone does not count) are ever closer than `[site] min_separation`
//! (default 5 m; 0 turns this off), in 3-D Euclidean distance, after any step. Exactly
//! `min_separation` apart is allowed, so drones take off side by side from homes that far
//! apart. Two layers run for each drone, in world-file order, every tick before it moves:
//! - the priority planner (the `avoid` module). The drone predicts its own path and the
//!   paths of the drones before it in the world file (higher priority), 6 s ahead. When
//!   they would come too close, it gives way: it slows or stops on its path (when the
//!   others are moving on), or climbs or descends to pass above or below them (within its
//!   climb rate and acceleration, 2 m above the ground and `max_altitude`), and comes back
//!   to its own altitude once clear. Its ground track never changes, and a leg does not
//!   end while the drone is off its altitude, so every call still ends exactly at its
//!   target, only later. Priority is fixed and the choice deterministic, so there is no
//!   "after you" dance: in a head-on or crossing encounter both drones arrive.
//! - the safety filter (the `separation` module). A move is kept only if the drone's
//!   stopping envelope (where it could still get to when braking hard) stays
//!   `min_separation` clear of every other drone's; otherwise it brakes instead, which
//!   only shrinks its envelope. By induction, this gives the guarantee above whatever the
//!   planner chose. It is what holds back a higher-priority drone in the rare case that a
//!   lower-priority one cannot get out of its way in time (two drones side by side at
//!   exactly `min_separation` that set off towards each other). A drone held back for 3 s
//!   then gives way to every drone near it, whatever the priority, until it is clear.
//!
//! Drones whose predicted paths and envelopes never come within `min_separation` of each
//! other fly exactly, bit for bit, as with no separation. The cost grows with the number
//! of pairs of drones in the air, plus a few short predictions for each pair that is near.
//!
//! Limits: the planner resolves head-on, crossing, converging and overtaking encounters
//! (and random crowds of up to a dozen drones in a 60 m square, in the tests), but it
//! does not search for a way around, and a drone never leaves its ground track or backs
//! up. A drone with no free altitude to pass at (boxed in by others, or between the
//! ceiling and the floor) waits where it is; so do two drones that must pass each other
//! in height on vertical paths closer than `min_separation` (one landing at its home
//! while the other climbs beside it). A target within `min_separation` of a drone that
//! stays there cannot be reached (two drones sent to the same point): the call waits
//! nearby (or above it) until that drone leaves. A drone about to take off under another
//! one waits on the ground. The filter may make a drone brake harder than its plan would
//! (never beyond `acceleration` per axis).
//!
//! No such wait is endless: a motion call held back by separation for `[site]
//! separation_timeout` seconds (default 30) of simulated time ends `Failed` with the
//! exception `Timeout` ("b waited 30 s for a to make room", naming the nearest drone in
//! the air, when there is one within `2 × min_separation + 1` m), and the drone stops where
//! it is and hovers (or stays on the ground, for a take-off). *Held back*: in a tick in
//! which the planner has the drone give way or the filter makes it brake, its call gets no
//! nearer its end than the nearest it has been (legs left, then the 3-D distance to the
//! end of the current leg, the arc left on an orbit, the time left of a hover); a tick that
//! gets nearer than ever resets the clock, and so does a pause. The short yields of
//! ordinary encounters (passing above, slowing, a few seconds stopped) never come near
//! it. A task the drone flies on its own, with no call (a return after a link loss, an
//! emergency landing), is not timed.
//!
//! # Battery and faults
//! With `need` = the time home (`aviary_api::flight::time_home`: the distance at
//! `max_speed`, the wait above home and the landing) / `endurance`,
//! `BatteryLow` is signalled once when the charge falls under `2 × need + 10 %`, and
//! `BatteryCritical` raised once under `need + 10 %` (ending the drone's calls in
//! progress `Interrupted`); at zero the drone falls (`Lost`, `DroneLost`). The world's
//! `[[faults]]` fire at their time in simulated seconds (see the `faults` module), or, for
//! a fault whose `at` is a range, at a time drawn uniformly from it. Under
//! link loss a drone holds (and refuses commands); if the link is still lost after
//! `[site] link_loss_rtl_after` seconds (default 10) it returns to launch on its own and
//! lands, and keeps at that after the link is back (`ConnectionRestored`) until it has
//! landed or a new motion command replaces it.
//!
//! # Driver
//! [`SimBackend::start`] spawns the driver; it ends at its next tick after
//! [`SimBackend::stop`] (or [`SimBackend::shutdown`], which also waits for it), or once
//! the last `Arc<SimBackend>` is dropped. Simulated time equals the run's clock since the
//! start (as long as the runtime keeps up, as it does on `aviary_clock`'s virtual clock).
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod air;
mod args;
mod avoid;
mod backend;
mod battery;
mod calls;
mod clearance;
mod drone;
mod faults;
mod fleet;
mod geom;
mod grid;
mod legs;
mod motion;
mod nearby;
mod pace;
mod profile;
mod randomness;
mod reach_box;
mod sensors;
mod separation;
mod step;
mod step_view;
pub mod sweep;
#[cfg(test)]
mod tests;

pub use backend::{SimBackend, SimOptions};
pub use pace::{Pace, Source as PaceSource};

pub use aviary_api::flight::{LOAD_MAX_ALTITUDE, LOAD_TIME};
pub use fleet::{Fleet, Release, Report};
