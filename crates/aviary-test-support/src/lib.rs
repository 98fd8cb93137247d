//! What the workspace's tests share, so that each helper is written once: the provider a
//! mission that stands alone is checked with ([`NoFiles`], `aviary_check`'s own, so that
//! non-test code such as the benchmarks and the fuzz targets uses the same one), and the
//! engine [`harness`]: a mission text checked, compiled and flown on the simulator with a
//! simulated clock (`aviary_clock`), and its trace; [`trace`], a trace (a run's, or a file's) read as typed
//! records; and [`lanes`], which drone flew which part of each lane of a sweep.
//!
//! A dev-dependency only: no crate's `[dependencies]` may name it. It names the whole
//! pipeline (the front end, the engine, the simulator), which the engine itself must
//! never depend on.

pub mod harness;
pub mod lanes;
pub mod trace;

pub use aviary_check::NoFiles;
