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
// A pass says what it does with every kind of node: a new statement, expression or IR
// node is then a compile error in each pass (with clippy), not one it silently skips. An
// enum that is no language construct may be matched with `_`, allowed where it is.
#![deny(clippy::wildcard_enum_match_arm)]

mod compile;

pub use compile::compile;
