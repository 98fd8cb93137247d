//! Backends made of the simulator's and MAVLink's: `mixed.rs`, a fleet whose drones are
//! each flown by one or the other, behind one `Backend` for the engine.
//!
//! The one crate that names both backends: the simulator and `aviary-mavlink` know nothing
//! of each other, and the engine knows neither.

mod mixed;

pub use mixed::{live_runtime, Mixed};
