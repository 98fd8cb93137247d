//! Backends made of the simulator's and MAVLink's, and the run that chooses between them.
//! `mixed.rs`: a fleet whose drones are each flown by one or the other, behind one
//! `Backend` for the engine. `pipeline.rs`: [`fly`], a run's whole pipeline from the
//! texts of a mission and its world to the end of its flight, which `aviary run` and the
//! scale benchmarks share. `replan.rs`: the plan made again with the MAVLink vehicles'
//! own figures before they fly, which `aviary run` and the station both show.
//!
//! The one crate that names both backends: the simulator and `aviary-mavlink` know nothing
//! of each other, and the engine knows neither. No IO of its own: texts in, an outcome out.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod mixed;
pub mod pipeline;
pub mod replan;
pub mod trace_file;

pub use mixed::{live_runtime, simulated_runtime, Mixed};
pub use pipeline::fly;
