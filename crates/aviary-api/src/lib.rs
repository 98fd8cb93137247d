//! The middle layer between missions and drones (the paper's API wrapper).
//!
//! The contract is typed: the middle-layer functions are the closed enum [`Function`],
//! the built-in signals and exceptions [`BuiltinSignal`] and [`BuiltinException`], and
//! the trace's events [`trace::Event`]. The [`Descriptor`] the checker reads (functions
//! with typed parameters, telemetry, built-ins) is derived from those enums.
//!
//! At run time a backend implements [`Backend`]: the engine starts calls, interrupts
//! them, reads telemetry and receives drone events through it, and never learns which
//! backend it drives.
//!
//! Invariant: this crate knows no engine, no backend and no syntax. Every name the
//! contract gives (a function, a built-in, a kind of event) is a variant, matched
//! exhaustively where it is acted on, so adding one is a compile error wherever it is
//! not handled yet; text exists only where a mission is read and where a trace line is
//! written or read.

// A pure stage: no unsafe code, and no panic on any input (tests may unwrap).
#![forbid(unsafe_code)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

pub mod arith;
mod builtin;
mod call;
pub mod coverage;
pub mod flight;
mod function;
pub mod geo;
pub mod geometry;
mod kind;
mod names;
pub mod operator;
mod runtime;
pub mod show;
pub mod sweep;
pub mod trace;

pub use builtin::{BuiltinException, BuiltinLeash, BuiltinSignal};
pub use call::{CallOf, Flown, FunctionCall, Place, Planned, PlannedCall, Region, Stage, Waypoint};
pub use coverage::{Progress, Remainder};
pub use function::{Function, Param, Signature};
pub use geometry::centroid;
pub use kind::Kind;
pub use names::Names;
pub use runtime::*;

/// How many times a handler may be started again at one instant by what its own runs led
/// to (docs/LANGUAGE.md, sections 11 and 12): a rule of the language, so the engine
/// (`RunOptions::max_handler_reentries`, its default), the plan's estimate and the
/// checker's messages (W206, W209) share it. Between two rounds at one instant no drone
/// has moved and no time has passed, so a handler started again this often is going
/// round in a loop; the trace of one cut off here stays under a megabyte.
pub const MAX_HANDLER_REENTRIES: usize = 100;

/// A part of a drone that one activity at a time may command (docs/LANGUAGE.md, section 6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Resource {
    Motion,
    Camera,
    Detection,
    Payload,
}

impl Resource {
    pub fn as_str(self) -> &'static str {
        match self {
            Resource::Motion => "motion",
            Resource::Camera => "camera",
            Resource::Detection => "detection",
            Resource::Payload => "payload",
        }
    }
}

/// What a backend offers: the functions with their signatures, the telemetry with its
/// kinds, and the built-in signals and exceptions. Derived from the contract's closed sets
/// ([`Function`], [`BuiltinSignal`], [`BuiltinException`]), so the checker, the compiler
/// and the backends read one list.
#[derive(Clone, Debug, PartialEq)]
pub struct Descriptor {
    pub functions: Vec<Signature>,
    pub telemetry: Vec<(&'static str, Kind)>,
    pub signals: Vec<BuiltinSignal>,
    pub exceptions: Vec<BuiltinException>,
}

impl Descriptor {
    pub fn function(&self, name: &str) -> Option<&Signature> {
        self.functions.iter().find(|f| f.name() == name)
    }
    pub fn telemetry(&self, field: &str) -> Option<Kind> {
        self.telemetry.iter().find(|(n, _)| *n == field).map(|&(_, k)| k)
    }
    pub fn signal(&self, name: &str) -> Option<BuiltinSignal> {
        self.signals.iter().copied().find(|s| s.name() == name)
    }
    pub fn is_exception(&self, name: &str) -> bool {
        self.exceptions.iter().any(|e| e.name() == name)
    }

    /// The functions of docs/LANGUAGE.md, section 19, which every backend offers, with the
    /// telemetry and the built-ins: the one descriptor, built once, that the checker, the
    /// compiler and the editors read (no backend offers another).
    pub fn standard() -> &'static Descriptor {
        static STANDARD: std::sync::LazyLock<Descriptor> =
            std::sync::LazyLock::new(Descriptor::build);
        &STANDARD
    }

    fn build() -> Descriptor {
        use Kind::*;
        Descriptor {
            functions: Function::ALL.map(Function::signature).into(),
            telemetry: vec![
                ("position", Position),
                ("altitude", Length),
                ("speed", Speed),
                ("heading", Angle),
                ("battery", Ratio),
                ("state", Symbol),
                ("link", Symbol),
                ("wind", Speed),
                ("payload", Symbol),
                // Not read from the backend's telemetry: the engine keeps what each drone's
                // last Sweep or FollowPath left (docs/LANGUAGE.md, section 18).
                ("remaining", Remainder),
            ],
            signals: BuiltinSignal::ALL.into(),
            exceptions: BuiltinException::ALL.into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_set_covers_language_section_4() {
        let d = Descriptor::standard();
        for name in [
            "Arm",
            "Disarm",
            "TakeOff",
            "Land",
            "ReturnToLaunch",
            "FlyToPosition",
            "DescendTo",
            "AscendTo",
            "Hover",
            "Orbit",
            "Sweep",
            "FollowPath",
            "StartStreaming",
            "StopStreaming",
            "StartDetection",
            "StopDetection",
            "LoadPayload",
            "ReleasePayload",
        ] {
            assert!(d.function(name).is_some(), "{name} missing");
        }
        for field in
            ["position", "altitude", "speed", "heading", "battery", "state", "link", "remaining"]
        {
            assert!(d.telemetry(field).is_some(), "{field} missing");
        }
        assert_eq!(
            d.function("FlyToPosition").map(|f| f.signature()).as_deref(),
            Some("FlyToPosition(pos[, speed])")
        );
        assert_eq!(d.function("FlyToPosition").map(|f| f.required()), Some(1));
    }
}
