//! The benchmarks' inputs: `generate`, large missions and worlds of any size, written in
//! the language, for `aviary bench` and for the tests of the other crates (a
//! dev-dependency there). Text only: a generator knows no crate of the pipeline.
//!
//! Invariant: no IO; the output is a function of the arguments only.

// A pure crate: no unsafe code, and no panic on any input (tests may unwrap).
#![forbid(unsafe_code)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

pub mod generate;
