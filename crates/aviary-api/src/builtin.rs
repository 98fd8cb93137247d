//! The built-in signals and exceptions (docs/LANGUAGE.md, sections 16 and 17): what the
//! middle layer raises on a drone without being asked. Closed sets, as the functions are:
//! a backend raises one of these variants, never a name, so the compiler resolves each
//! one to the mission's id once and the engine looks nothing up at run time.

use crate::Kind;

/// A signal the middle layer raises on an actor.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BuiltinSignal {
    /// A find of a sensor whose detection the actor's activity started; it carries the
    /// kind and where. A backend reports it as [`crate::DroneEvent::Detected`].
    Detected,
    BatteryLow,
    ConnectionRestored,
}

impl BuiltinSignal {
    pub const ALL: [BuiltinSignal; 3] =
        [BuiltinSignal::Detected, BuiltinSignal::BatteryLow, BuiltinSignal::ConnectionRestored];

    /// The name a mission hears it by.
    pub fn name(self) -> &'static str {
        match self {
            BuiltinSignal::Detected => "Detected",
            BuiltinSignal::BatteryLow => "BatteryLow",
            BuiltinSignal::ConnectionRestored => "ConnectionRestored",
        }
    }

    /// The values it carries, with their kinds (`ON Detected WITH kind, location`).
    pub fn values(self) -> &'static [(&'static str, Kind)] {
        match self {
            BuiltinSignal::Detected => &[("kind", Kind::Symbol), ("location", Kind::Position)],
            BuiltinSignal::BatteryLow | BuiltinSignal::ConnectionRestored => &[],
        }
    }

    pub fn from_name(name: &str) -> Option<BuiltinSignal> {
        BuiltinSignal::ALL.into_iter().find(|s| s.name() == name)
    }
}

/// An exception the middle layer raises: a fault of the drone, or a call it refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BuiltinException {
    BatteryCritical,
    ConnectionLost,
    DroneLost,
    MotorFailure,
    PositionLost,
    GeofenceViolation,
    CommandFailed,
    RequirementNotMet,
    Timeout,
    /// An `ANY` found no drone free and fit in time, or too few are left in the mission.
    NoDroneAvailable,
}

impl BuiltinException {
    pub const ALL: [BuiltinException; 10] = [
        BuiltinException::BatteryCritical,
        BuiltinException::ConnectionLost,
        BuiltinException::DroneLost,
        BuiltinException::MotorFailure,
        BuiltinException::PositionLost,
        BuiltinException::GeofenceViolation,
        BuiltinException::CommandFailed,
        BuiltinException::RequirementNotMet,
        BuiltinException::Timeout,
        BuiltinException::NoDroneAvailable,
    ];

    /// The name a mission handles it by (`ON EXCEPTION BatteryCritical`).
    pub fn name(self) -> &'static str {
        match self {
            BuiltinException::BatteryCritical => "BatteryCritical",
            BuiltinException::ConnectionLost => "ConnectionLost",
            BuiltinException::DroneLost => "DroneLost",
            BuiltinException::MotorFailure => "MotorFailure",
            BuiltinException::PositionLost => "PositionLost",
            BuiltinException::GeofenceViolation => "GeofenceViolation",
            BuiltinException::CommandFailed => "CommandFailed",
            BuiltinException::RequirementNotMet => "RequirementNotMet",
            BuiltinException::Timeout => "Timeout",
            BuiltinException::NoDroneAvailable => "NoDroneAvailable",
        }
    }

    pub fn from_name(name: &str) -> Option<BuiltinException> {
        BuiltinException::ALL.into_iter().find(|e| e.name() == name)
    }

    /// A fault of the drone itself (its battery, link, motors, position, the fence),
    /// which the operator must see even when the mission handles it; the others say
    /// that a call or a choice could not be made.
    pub fn is_drone_fault(self) -> bool {
        match self {
            BuiltinException::BatteryCritical
            | BuiltinException::ConnectionLost
            | BuiltinException::DroneLost
            | BuiltinException::MotorFailure
            | BuiltinException::PositionLost
            | BuiltinException::GeofenceViolation => true,
            BuiltinException::CommandFailed
            | BuiltinException::RequirementNotMet
            | BuiltinException::Timeout
            | BuiltinException::NoDroneAvailable => false,
        }
    }
}

/// What a leash can tell any activity, whatever its capability (docs/LANGUAGE.md,
/// section 14): the words the checker, the compiler, the engine and the operator server
/// all read, spelt here once. A named `PERFORM` section is the capability's own, so it is
/// not one of these.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BuiltinLeash {
    Abort,
    Pause,
    Resume,
}

impl BuiltinLeash {
    pub const ALL: [BuiltinLeash; 3] =
        [BuiltinLeash::Abort, BuiltinLeash::Pause, BuiltinLeash::Resume];

    /// The word a mission (and the trace, and the operator) writes: `ABORT`.
    pub fn as_str(self) -> &'static str {
        match self {
            BuiltinLeash::Abort => "ABORT",
            BuiltinLeash::Pause => "PAUSE",
            BuiltinLeash::Resume => "RESUME",
        }
    }

    /// The action a word names, or `None` for anything else (a section's name).
    pub fn parse(word: &str) -> Option<BuiltinLeash> {
        BuiltinLeash::ALL.into_iter().find(|a| a.as_str() == word)
    }
}

impl std::fmt::Display for BuiltinLeash {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::fmt::Display for BuiltinSignal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::fmt::Display for BuiltinException {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_is_listed_once_and_spelt_as_its_variant() {
        for (i, s) in BuiltinSignal::ALL.iter().enumerate() {
            assert_eq!(*s as usize, i, "{s:?}");
            assert_eq!(format!("{s:?}"), s.name());
            assert_eq!(BuiltinSignal::from_name(s.name()), Some(*s));
        }
        for (i, e) in BuiltinException::ALL.iter().enumerate() {
            assert_eq!(*e as usize, i, "{e:?}");
            assert_eq!(format!("{e:?}"), e.name());
            assert_eq!(BuiltinException::from_name(e.name()), Some(*e));
        }
        assert_eq!(BuiltinException::from_name("Nope"), None);
        for (i, a) in BuiltinLeash::ALL.iter().enumerate() {
            assert_eq!(*a as usize, i, "{a:?}");
            assert_eq!(format!("{a:?}").to_uppercase(), a.as_str());
            assert_eq!(BuiltinLeash::parse(a.as_str()), Some(*a));
        }
        assert_eq!(BuiltinLeash::parse("Abort"), None);
        assert_eq!(BuiltinLeash::parse("Widen"), None);
    }
}
