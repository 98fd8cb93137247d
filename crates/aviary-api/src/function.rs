//! The middle-layer functions (docs/LANGUAGE.md, section 19): a closed set, so that each
//! backend, the plan and the checker's analyses `match` on it exhaustively. A function
//! added here is a compile error wherever it is not handled yet, never an arm that
//! silently does nothing.
//!
//! The set is the whole contract: no backend adds functions of its own. A backend that
//! can do something new adds a variant here (and its [`Signature`]), and every other
//! backend must then decide what it does with it, if only refuse it. The descriptor's
//! functions are derived from this enum ([`crate::Descriptor::standard`]), so the
//! checker, the compiler and the backends read one list.

use serde::{Deserialize, Serialize};

use crate::{Kind, Resource};

/// A middle-layer function, as a mission calls it: `drone.FlyToPosition(pos)`. Written to
/// the trace by its name.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    Serialize,
    Deserialize,
    schemars::JsonSchema,
)]
pub enum Function {
    Arm,
    Disarm,
    TakeOff,
    Land,
    ReturnToLaunch,
    FlyToPosition,
    DescendTo,
    AscendTo,
    Hover,
    Orbit,
    Sweep,
    StartStreaming,
    StopStreaming,
    StartDetection,
    StopDetection,
    LoadPayload,
    ReleasePayload,
    FollowPath,
}

impl Function {
    /// Every function, in the order the descriptor lists them (and messages name them).
    pub const ALL: [Function; 18] = [
        Function::Arm,
        Function::Disarm,
        Function::TakeOff,
        Function::Land,
        Function::ReturnToLaunch,
        Function::FlyToPosition,
        Function::DescendTo,
        Function::AscendTo,
        Function::Hover,
        Function::Orbit,
        Function::Sweep,
        Function::StartStreaming,
        Function::StopStreaming,
        Function::StartDetection,
        Function::StopDetection,
        Function::LoadPayload,
        Function::ReleasePayload,
        Function::FollowPath,
    ];

    /// The name a mission calls it by.
    pub fn name(self) -> &'static str {
        match self {
            Function::Arm => "Arm",
            Function::Disarm => "Disarm",
            Function::TakeOff => "TakeOff",
            Function::Land => "Land",
            Function::ReturnToLaunch => "ReturnToLaunch",
            Function::FlyToPosition => "FlyToPosition",
            Function::DescendTo => "DescendTo",
            Function::AscendTo => "AscendTo",
            Function::Hover => "Hover",
            Function::Orbit => "Orbit",
            Function::Sweep => "Sweep",
            Function::StartStreaming => "StartStreaming",
            Function::StopStreaming => "StopStreaming",
            Function::StartDetection => "StartDetection",
            Function::StopDetection => "StopDetection",
            Function::LoadPayload => "LoadPayload",
            Function::ReleasePayload => "ReleasePayload",
            Function::FollowPath => "FollowPath",
        }
    }

    /// The function a mission names, if the middle layer has it.
    pub fn from_name(name: &str) -> Option<Function> {
        Function::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The drone resource it uses (docs/LANGUAGE.md, section 6).
    pub fn resource(self) -> Resource {
        match self {
            Function::Arm
            | Function::Disarm
            | Function::TakeOff
            | Function::Land
            | Function::ReturnToLaunch
            | Function::FlyToPosition
            | Function::DescendTo
            | Function::AscendTo
            | Function::Hover
            | Function::Orbit
            | Function::Sweep
            | Function::FollowPath => Resource::Motion,
            Function::StartStreaming | Function::StopStreaming => Resource::Camera,
            Function::StartDetection | Function::StopDetection => Resource::Detection,
            Function::LoadPayload | Function::ReleasePayload => Resource::Payload,
        }
    }

    /// Its parameters, what it uses and what it does, as the checker reads them.
    pub fn signature(self) -> Signature {
        use Kind::*;
        let p = |name, kind| Param { name, kind, optional: false };
        let opt = |name, kind| Param { name, kind, optional: true };
        let (params, summary) = match self {
            Function::Arm => (vec![], "arm the motors"),
            Function::Disarm => (vec![], "disarm the motors (landed only)"),
            Function::TakeOff => (vec![p("alt", Length)], "climb from the ground to an altitude"),
            Function::Land => (vec![], "land where the drone is"),
            Function::ReturnToLaunch => (vec![], "fly home and land"),
            Function::FlyToPosition => {
                (vec![p("pos", Position), opt("speed", Speed)], "fly to a position")
            }
            Function::DescendTo => (vec![p("alt", Length)], "descend to an altitude"),
            Function::AscendTo => (vec![p("alt", Length)], "climb to an altitude"),
            Function::Hover => (vec![p("duration", Duration)], "hold position for a time"),
            Function::Orbit => (
                vec![p("center", Position), p("radius", Length), opt("laps", Number)],
                "circle a point",
            ),
            Function::Sweep => (
                vec![p("area", Area), p("spacing", Length)],
                "fly a lawnmower path over an area (or what a Sweep left)",
            ),
            Function::StartStreaming => (vec![], "start the video stream"),
            Function::StopStreaming => (vec![], "stop the video stream"),
            Function::StartDetection => {
                (vec![p("kind", Symbol)], "start detecting a kind of target")
            }
            Function::StopDetection => (vec![p("kind", Symbol)], "stop detecting a kind of target"),
            Function::LoadPayload => {
                (vec![p("kind", Symbol)], "load a payload (landed or below 5 m)")
            }
            Function::ReleasePayload => (vec![], "release the payload carried"),
            Function::FollowPath => {
                (vec![p("points", Path)], "fly through positions (or a line) in order")
            }
        };
        let trailing = (self == Function::FollowPath).then(|| opt("speed", Speed));
        Signature {
            function: self,
            params,
            variadic: self == Function::FollowPath,
            trailing,
            summary,
        }
    }
}

impl std::fmt::Display for Function {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    pub name: &'static str,
    pub kind: Kind,
    pub optional: bool,
}

/// What the checker knows of a function: its parameters and what it does (the resource it
/// uses is [`Function::resource`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Signature {
    pub function: Function,
    pub params: Vec<Param>,
    /// The last parameter repeats (`FollowPath(points...)`).
    pub variadic: bool,
    /// An optional parameter after the repeated one (`FollowPath(points...[, speed])`),
    /// told apart from it by its kind: a last argument of this kind is this parameter.
    pub trailing: Option<Param>,
    pub summary: &'static str,
}

impl Signature {
    pub fn name(&self) -> &'static str {
        self.function.name()
    }
    /// Whether a value of kind `value` may be given for `param`: a value its kind
    /// accepts, or, for `FollowPath`'s points, what a Sweep or FollowPath left (its points
    /// are flown in its place; a parameter of a capability passed on to `FollowPath` is
    /// still a position).
    pub fn accepts(&self, param: &Param, value: Kind) -> bool {
        param.kind.accepts(value)
            || (self.function == Function::FollowPath && value == Kind::Remainder)
    }
    pub fn required(&self) -> usize {
        self.params.iter().filter(|p| !p.optional).count()
    }
    /// The parameter that argument `j` of `n` goes to, `last` being the kind of the last
    /// argument when known: a repeated parameter takes every argument from its place on,
    /// except a last one of the [`Signature::trailing`] parameter's kind.
    pub fn param_at(&self, j: usize, n: usize, last: Option<Kind>) -> Option<&Param> {
        if let Some(t) = &self.trailing {
            if j + 1 == n && j >= self.required() && last.is_some_and(|k| t.kind.accepts(k)) {
                return Some(t);
            }
        }
        self.params.get(j).or(if self.variadic { self.params.last() } else { None })
    }
    /// `FlyToPosition(pos[, speed])`, for messages.
    pub fn signature(&self) -> String {
        let mut out = format!("{}(", self.name());
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
        if let Some(t) = &self.trailing {
            out.push_str(&format!("[, {}]", t.name));
        }
        out.push(')');
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_function_is_listed_once_and_found_by_its_name() {
        for (i, f) in Function::ALL.iter().enumerate() {
            assert_eq!(Function::ALL.iter().position(|g| g == f), Some(i), "{f:?} twice");
            assert_eq!(Function::from_name(f.name()), Some(*f));
            assert_eq!(format!("{f:?}"), f.name(), "the variant is spelt as the language");
            assert_eq!(f.signature().function, *f);
        }
        assert_eq!(Function::from_name("Takeoff"), None);
        assert_eq!(Function::from_name(""), None);
    }

    #[test]
    fn a_function_is_written_by_its_name() {
        for f in Function::ALL {
            let json = serde_json::to_string(&f).unwrap();
            assert_eq!(json, format!("\"{}\"", f.name()));
            assert_eq!(serde_json::from_str::<Function>(&json).unwrap(), f);
        }
    }
}
