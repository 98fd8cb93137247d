//! The middle layer between missions and drones (the paper's API wrapper).
//!
//! A backend describes what it offers with a [`Descriptor`]: its functions with typed
//! parameters and the drone resource each one uses, the telemetry it reports, and the
//! built-in signals and exceptions it raises. The checker reads only the descriptor, so
//! a backend that adds a function teaches the checker about it.
//!
//! At run time a backend implements [`Backend`]: the engine starts calls, interrupts
//! them, reads telemetry and receives drone events through it, and never learns which
//! backend it drives.
//!
//! Invariant: this crate knows no engine, no backend and no syntax.

// A pure stage: no unsafe code, and no panic on any input (tests may unwrap).
#![forbid(unsafe_code)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

pub mod flight;
pub mod geo;
pub mod geometry;
mod kind;
mod names;
mod runtime;
pub mod show;
pub mod sweep;

pub use geometry::centroid;
pub use kind::Kind;
pub use names::Names;
pub use runtime::*;

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

#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    pub name: &'static str,
    pub kind: Kind,
    pub optional: bool,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Function {
    pub name: &'static str,
    pub params: Vec<Param>,
    /// The last parameter repeats (`FollowPath(points...)`).
    pub variadic: bool,
    pub resource: Option<Resource>,
    pub summary: &'static str,
}

impl Function {
    pub fn required(&self) -> usize {
        self.params.iter().filter(|p| !p.optional).count()
    }
    /// `FlyToPosition(pos[, speed])`, for messages.
    pub fn signature(&self) -> String {
        let mut out = format!("{}(", self.name);
        for (i, p) in self.params.iter().enumerate() {
            let sep = if i == 0 { "" } else { ", " };
            if p.optional {
                out.push_str(&format!("[{sep}{}]", p.name));
            } else {
                out.push_str(&format!("{sep}{}", p.name));
            }
        }
        if self.variadic {
            out.push_str("...");
        }
        out.push(')');
        out
    }
}

/// A signal the middle layer raises on an actor, with the values it carries.
#[derive(Clone, Debug, PartialEq)]
pub struct BuiltinSignal {
    pub name: &'static str,
    pub values: Vec<(&'static str, Kind)>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Descriptor {
    pub functions: Vec<Function>,
    pub telemetry: Vec<(&'static str, Kind)>,
    pub signals: Vec<BuiltinSignal>,
    pub exceptions: Vec<&'static str>,
}

impl Descriptor {
    pub fn function(&self, name: &str) -> Option<&Function> {
        self.functions.iter().find(|f| f.name == name)
    }
    pub fn telemetry(&self, field: &str) -> Option<Kind> {
        self.telemetry.iter().find(|(n, _)| *n == field).map(|&(_, k)| k)
    }
    pub fn signal(&self, name: &str) -> Option<&BuiltinSignal> {
        self.signals.iter().find(|s| s.name == name)
    }
    pub fn is_exception(&self, name: &str) -> bool {
        self.exceptions.contains(&name)
    }
    /// A backend's own functions join the standard set.
    pub fn extend(&mut self, functions: impl IntoIterator<Item = Function>) {
        for f in functions {
            self.functions.retain(|g| g.name != f.name);
            self.functions.push(f);
        }
    }

    /// The functions of docs/LANGUAGE.md, section 19, which every backend offers.
    pub fn standard() -> Descriptor {
        use Kind::*;
        use Resource::*;
        let p = |name, kind| Param { name, kind, optional: false };
        let opt = |name, kind| Param { name, kind, optional: true };
        let f = |name, params: Vec<Param>, resource, summary| Function {
            name,
            params,
            variadic: false,
            resource,
            summary,
        };
        let mut functions = vec![
            f("Arm", vec![], Some(Motion), "arm the motors"),
            f("Disarm", vec![], Some(Motion), "disarm the motors (landed only)"),
            f(
                "TakeOff",
                vec![p("alt", Length)],
                Some(Motion),
                "climb from the ground to an altitude",
            ),
            f("Land", vec![], Some(Motion), "land where the drone is"),
            f("ReturnToLaunch", vec![], Some(Motion), "fly home and land"),
            f(
                "FlyToPosition",
                vec![p("pos", Position), opt("speed", Speed)],
                Some(Motion),
                "fly to a position",
            ),
            f("DescendTo", vec![p("alt", Length)], Some(Motion), "descend to an altitude"),
            f("AscendTo", vec![p("alt", Length)], Some(Motion), "climb to an altitude"),
            f("Hover", vec![p("duration", Duration)], Some(Motion), "hold position for a time"),
            f(
                "Orbit",
                vec![p("center", Position), p("radius", Length), opt("laps", Number)],
                Some(Motion),
                "circle a point",
            ),
            f(
                "Sweep",
                vec![p("area", Area), p("spacing", Length)],
                Some(Motion),
                "fly a lawnmower path over an area",
            ),
            f("StartStreaming", vec![], Some(Camera), "start the video stream"),
            f("StopStreaming", vec![], Some(Camera), "stop the video stream"),
            f(
                "StartDetection",
                vec![p("kind", Symbol)],
                Some(Detection),
                "start detecting a kind of target",
            ),
            f(
                "StopDetection",
                vec![p("kind", Symbol)],
                Some(Detection),
                "stop detecting a kind of target",
            ),
            f(
                "LoadPayload",
                vec![p("kind", Symbol)],
                Some(Payload),
                "load a payload (landed or below 5 m)",
            ),
            f("ReleasePayload", vec![], Some(Payload), "release the payload carried"),
        ];
        functions.push(Function {
            name: "FollowPath",
            params: vec![p("points", Position)],
            variadic: true,
            resource: Some(Motion),
            summary: "fly through positions in order",
        });
        Descriptor {
            functions,
            telemetry: vec![
                ("position", Position),
                ("altitude", Length),
                ("speed", Speed),
                ("heading", Angle),
                ("battery", Ratio),
                ("state", Symbol),
                ("link", Symbol),
            ],
            signals: vec![
                BuiltinSignal {
                    name: "Detected",
                    values: vec![("kind", Symbol), ("location", Position)],
                },
                BuiltinSignal { name: "BatteryLow", values: vec![] },
                BuiltinSignal { name: "ConnectionRestored", values: vec![] },
            ],
            exceptions: vec![
                "BatteryCritical",
                "ConnectionLost",
                "DroneLost",
                "MotorFailure",
                "PositionLost",
                "GeofenceViolation",
                "CommandFailed",
                "RequirementNotMet",
                "Timeout",
            ],
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
        for field in ["position", "altitude", "speed", "heading", "battery", "state", "link"] {
            assert!(d.telemetry(field).is_some(), "{field} missing");
        }
        assert_eq!(
            d.function("FlyToPosition").map(|f| f.signature()).as_deref(),
            Some("FlyToPosition(pos[, speed])")
        );
        assert_eq!(d.function("FlyToPosition").map(|f| f.required()), Some(1));
    }

    #[test]
    fn a_backend_function_replaces_one_of_the_same_name() {
        let mut d = Descriptor::standard();
        let before = d.functions.len();
        d.extend([Function {
            name: "Winch",
            params: vec![],
            variadic: false,
            resource: Some(Resource::Payload),
            summary: "",
        }]);
        d.extend([Function {
            name: "Land",
            params: vec![],
            variadic: false,
            resource: Some(Resource::Motion),
            summary: "soft",
        }]);
        assert_eq!(d.functions.len(), before + 1);
        assert_eq!(d.function("Land").map(|f| f.summary), Some("soft"));
    }
}
