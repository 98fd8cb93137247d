//! The lowering: from a checked program and its world to the compiled mission
//! (`aviary_ir::Mission`), which the engine runs.
//!
//! It belongs to the front end: it reads the syntax tree, the checker's `Program` and the
//! world, and writes the IR, so the IR and the engine need none of them.
//!
//! Invariant: no IO; `compile` takes a checked program and never panics.

// A pure stage: no unsafe code, and no panic on any input (tests may unwrap).
#![forbid(unsafe_code)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod compile;

pub use compile::compile;
