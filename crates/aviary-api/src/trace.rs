//! The trace's events (docs/TRACE.md), typed: the engine makes them, and every reader
//! (the trace file, the operator API, a ground station, a replay) reads the same type.
//! JSON exists only at the edges: a [`Record`] serialises to one line of the trace file,
//! `{"t": …, "event": kind, fields…}`, byte for byte as docs/TRACE.md shows it, and
//! deserialises back from one.
//!
//! One type serves both sides, a borrowed enum whose owned form is `Record<'static>`.
//! Its text is `Cow<'a, str>` and its areas `Cow<'a, [..]>`: the engine borrows them from
//! the compiled mission and the run (a drone's name, a block's path, a value's text), so
//! making an event copies no string, and a sink that looks at a field or two matches on
//! the event and reads it where it is, with no JSON map; what is read back from a file
//! owns its text. What an event allocates is its list of values (`args`), and text made
//! for it alone (the names of an activity's several drones, an exception handler's path);
//! and an event is made only for a sink that wants its kind ([`EventKind`], asked once
//! per kind when a run starts).

pub(crate) mod shown;

use std::borrow::Cow;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::{FlightState, Function};
pub use shown::{Params, Shown};

/// One line of the trace: when, and what happened.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Record<'a> {
    /// Seconds of mission time since the start.
    #[serde(deserialize_with = "shown::number")]
    pub t: f64,
    #[serde(flatten)]
    pub event: Event<'a>,
}

/// Text an event borrows from the run, or owns once read back.
pub type Text<'a> = Cow<'a, str>;

/// The world a run flew in: its file, as the run named it, and the SHA-256 of its bytes.
/// A replay or a report of the trace draws that world, and refuses another.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct WorldStamp<'a> {
    pub file: Text<'a>,
    pub sha256: Text<'a>,
}

impl WorldStamp<'static> {
    pub fn of(file: &str, bytes: &[u8]) -> Self {
        use sha2::Digest;
        let digest = sha2::Sha256::digest(bytes);
        let sha256 = digest.iter().map(|b| format!("{b:02x}")).collect::<String>();
        WorldStamp { file: Cow::Owned(file.to_string()), sha256: Cow::Owned(sha256) }
    }
}

impl WorldStamp<'_> {
    /// Why the world file `file`, of `bytes`, is not the one this stamp names; `None`
    /// when it is (its bytes are the same, whatever its name).
    pub fn refuses(&self, file: &str, bytes: &[u8]) -> Option<String> {
        let other = WorldStamp::of(file, bytes);
        let short = |s: &str| s.get(..12).unwrap_or(s).to_string();
        (other.sha256 != self.sha256).then(|| {
            format!(
                "{file} is not the world this trace was flown in: the trace names {} (SHA-256 {}…), and {file} is another (SHA-256 {}…); give that world, or none to draw the trace alone",
                self.file,
                short(&self.sha256),
                short(&other.sha256)
            )
        })
    }
}

/// What happened (docs/TRACE.md, "Every event"). The fields are in the order the trace
/// writes them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Event<'a> {
    MissionStart {
        mission: Text<'a>,
        /// The world the run flew in, when it was flown from a world file.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        world: Option<WorldStamp<'a>>,
    },
    MissionEnd {
        status: Status,
        reason: Option<Text<'a>>,
    },
    BlockStart {
        block: Text<'a>,
    },
    /// `status` is `ok`, or `aborted` when an exception stopped the block.
    BlockEnd {
        block: Text<'a>,
        status: Status,
    },
    /// `actor`: the drone, or the names of several separated by spaces.
    CapabilityStart {
        actor: Text<'a>,
        capability: Text<'a>,
        tag: Option<Text<'a>>,
        args: Params<'a>,
        /// The line of the statement in the MISSION's file, when it is there: what
        /// identifies the statement to a page that follows the run.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        line: Option<u32>,
    },
    CapabilityEnd {
        actor: Text<'a>,
        capability: Text<'a>,
        tag: Option<Text<'a>>,
        args: Params<'a>,
        status: Status,
        /// The line of the statement in the MISSION's file, when it is there: what
        /// identifies the statement to a page that follows the run.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        line: Option<u32>,
    },
    HandlerStart {
        signal: Text<'a>,
        handler: Text<'a>,
        actor: Option<Text<'a>>,
    },
    HandlerEnd {
        signal: Text<'a>,
        handler: Text<'a>,
        actor: Option<Text<'a>>,
    },
    ApiCall {
        actor: Text<'a>,
        function: Function,
        args: Vec<Shown<'a>>,
    },
    /// `left`: for a `Sweep` or `FollowPath` that ended other than `ok`, the metres of
    /// its path it left unflown (the length of its drone's `remaining`).
    ApiDone {
        actor: Text<'a>,
        function: Function,
        args: Vec<Shown<'a>>,
        status: CallStatus,
        // A coordinate that is not finite is written null.
        #[serde(deserialize_with = "shown::coordinates")]
        #[schemars(with = "[Option<f64>; 3]")]
        position: [f64; 3],
        #[serde(default, skip_serializing_if = "Option::is_none")]
        left: Option<f64>,
    },
    /// `by`: `operator` for a signal the operator raised (an `OPERATOR SIGNAL`, through
    /// the operator API); absent for the mission's and the drones' own.
    Signal {
        name: Text<'a>,
        actor: Option<Text<'a>>,
        args: Vec<Shown<'a>>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        by: Option<RaisedBy>,
        /// The line of the statement in the MISSION's file, when it is there: what
        /// identifies the statement to a page that follows the run.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        line: Option<u32>,
    },
    /// `args` of a built-in exception: the reason, in words. `during` is `return home` for
    /// a fault after the mission's body has ended, which no handler can take. `skipped`:
    /// a handler that would have taken it and did not, and why (it was re-entered too
    /// often at one instant, docs/LANGUAGE.md section 12). `cause`: what caused it, where
    /// one exception has causes an operator tells apart (`separation`: a motion that waited
    /// for another drone to make room until it timed out).
    Exception {
        name: Text<'a>,
        actor: Option<Text<'a>>,
        args: Vec<Shown<'a>>,
        handled: bool,
        handler: Option<Text<'a>>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        during: Option<Text<'a>>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        skipped: Option<Text<'a>>,
        /// The line of the statement in the MISSION's file, when it is there: what
        /// identifies the statement to a page that follows the run.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        line: Option<u32>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        cause: Option<crate::Cause>,
    },
    /// `action`: `PAUSE`, `RESUME`, `ABORT` or a section's name.
    /// A block stopped (`Name ABORT`) is a leash on the block: `block` is `true`,
    /// `capability` holds the block's name and `tag` is empty.
    Leash {
        capability: Text<'a>,
        tag: Text<'a>,
        action: Text<'a>,
        #[serde(default, skip_serializing_if = "is_false")]
        block: bool,
        /// The line of the statement in the MISSION's file, when it is there: what
        /// identifies the statement to a page that follows the run.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        line: Option<u32>,
    },
    Detection {
        actor: Text<'a>,
        kind: Text<'a>,
        // A coordinate that is not finite is written null.
        #[serde(deserialize_with = "shown::coordinates")]
        #[schemars(with = "[Option<f64>; 3]")]
        location: [f64; 3],
    },
    Telemetry {
        actor: Text<'a>,
        // A coordinate that is not finite is written null.
        #[serde(deserialize_with = "shown::coordinates")]
        #[schemars(with = "[Option<f64>; 3]")]
        position: [f64; 3],
        // Not known (not finite): written null.
        #[serde(deserialize_with = "shown::number")]
        #[schemars(with = "Option<f64>")]
        battery: f64,
        state: FlightState,
    },
    /// The operator steered the mission (a leash or a signal of the operator is written
    /// as a `leash` or a `signal`). `drone`: the drone it applies to, or `null` for the
    /// whole mission.
    Operator {
        action: OperatorAction,
        drone: Option<Text<'a>>,
    },
    /// The drone's autopilot acted on its own, without a call of the mission (a
    /// failsafe): it held where it was, flew home or landed. `reason` says why, in words.
    Autopilot {
        actor: Text<'a>,
        action: AutopilotAction,
        reason: Text<'a>,
    },
}

/// Who raised a signal from outside the mission (`signal` events' `by`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum RaisedBy {
    /// The operator, through the operator API (`aviary ctl signal`, the station).
    Operator,
}

/// Whether a flag is unset: such a field is left out of the trace line.
fn is_false(flag: &bool) -> bool {
    !*flag
}

/// What a drone's autopilot did on its own (`autopilot` events).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum AutopilotAction {
    /// Stopped and held where it was (a lost link or position).
    Hold,
    /// Flew home and landed (a failsafe return to launch).
    ReturnHome,
    /// Landed where it was (a motor failure, a failsafe landing).
    Land,
}

impl AutopilotAction {
    /// The trace's `action`.
    pub fn as_str(self) -> &'static str {
        match self {
            AutopilotAction::Hold => "hold",
            AutopilotAction::ReturnHome => "return_home",
            AutopilotAction::Land => "land",
        }
    }
}

/// What the operator did (`operator` events).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum OperatorAction {
    /// Held every activity where it is (the whole mission).
    Pause,
    /// Undid a `pause` (without a drone) or a `hold` (of its drone).
    Resume,
    /// Ended the mission: the fleet returns home.
    Abort,
    /// Held one drone's activities where they are.
    Hold,
    /// Aborted one drone's activities and sent it home, out of the mission.
    ReturnHome,
    /// Aborted one drone's activities and landed it where it is, out of the mission.
    Land,
}

impl OperatorAction {
    /// The trace's `action`.
    pub fn as_str(self) -> &'static str {
        match self {
            OperatorAction::Pause => "pause",
            OperatorAction::Resume => "resume",
            OperatorAction::Abort => "abort",
            OperatorAction::Hold => "hold",
            OperatorAction::ReturnHome => "return_home",
            OperatorAction::Land => "land",
        }
    }
}

/// How a mission, a block or an activity ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    Ok,
    /// An exception nobody handled, a fault, a drone that did not come down.
    Failed,
    /// Stopped: by a leash, an exception elsewhere, or the operator.
    Aborted,
}

impl Status {
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Failed => "failed",
            Status::Aborted => "aborted",
        }
    }
}

/// How a middle-layer call ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum CallStatus {
    Ok,
    /// Refused: an exception follows.
    Failed,
    /// Cut by a fault of the drone.
    Interrupted,
    /// Its activity was stopped.
    Aborted,
}

/// The kinds of event, so that what a sink wants is asked once per kind when the run
/// starts, not at every event.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EventKind {
    MissionStart,
    MissionEnd,
    BlockStart,
    BlockEnd,
    CapabilityStart,
    CapabilityEnd,
    HandlerStart,
    HandlerEnd,
    ApiCall,
    ApiDone,
    Signal,
    Exception,
    Leash,
    Detection,
    Telemetry,
    Operator,
    Autopilot,
}

impl EventKind {
    /// Every kind; `ALL[k as usize] == k`.
    pub const ALL: [EventKind; 17] = [
        EventKind::MissionStart,
        EventKind::MissionEnd,
        EventKind::BlockStart,
        EventKind::BlockEnd,
        EventKind::CapabilityStart,
        EventKind::CapabilityEnd,
        EventKind::HandlerStart,
        EventKind::HandlerEnd,
        EventKind::ApiCall,
        EventKind::ApiDone,
        EventKind::Signal,
        EventKind::Exception,
        EventKind::Leash,
        EventKind::Detection,
        EventKind::Telemetry,
        EventKind::Operator,
        EventKind::Autopilot,
    ];

    /// The trace's `event`.
    pub fn as_str(self) -> &'static str {
        match self {
            EventKind::MissionStart => "mission_start",
            EventKind::MissionEnd => "mission_end",
            EventKind::BlockStart => "block_start",
            EventKind::BlockEnd => "block_end",
            EventKind::CapabilityStart => "capability_start",
            EventKind::CapabilityEnd => "capability_end",
            EventKind::HandlerStart => "handler_start",
            EventKind::HandlerEnd => "handler_end",
            EventKind::ApiCall => "api_call",
            EventKind::ApiDone => "api_done",
            EventKind::Signal => "signal",
            EventKind::Exception => "exception",
            EventKind::Leash => "leash",
            EventKind::Detection => "detection",
            EventKind::Telemetry => "telemetry",
            EventKind::Operator => "operator",
            EventKind::Autopilot => "autopilot",
        }
    }
}

impl Event<'_> {
    pub fn kind(&self) -> EventKind {
        match self {
            Event::MissionStart { .. } => EventKind::MissionStart,
            Event::MissionEnd { .. } => EventKind::MissionEnd,
            Event::BlockStart { .. } => EventKind::BlockStart,
            Event::BlockEnd { .. } => EventKind::BlockEnd,
            Event::CapabilityStart { .. } => EventKind::CapabilityStart,
            Event::CapabilityEnd { .. } => EventKind::CapabilityEnd,
            Event::HandlerStart { .. } => EventKind::HandlerStart,
            Event::HandlerEnd { .. } => EventKind::HandlerEnd,
            Event::ApiCall { .. } => EventKind::ApiCall,
            Event::ApiDone { .. } => EventKind::ApiDone,
            Event::Signal { .. } => EventKind::Signal,
            Event::Exception { .. } => EventKind::Exception,
            Event::Leash { .. } => EventKind::Leash,
            Event::Detection { .. } => EventKind::Detection,
            Event::Telemetry { .. } => EventKind::Telemetry,
            Event::Operator { .. } => EventKind::Operator,
            Event::Autopilot { .. } => EventKind::Autopilot,
        }
    }
}

#[cfg(test)]
mod tests;

/// The JSON Schema of one line of a trace, made from the types above (the file
/// docs/trace.schema.json is this, and a test holds it so): every event with its fields,
/// and no field the types do not have.
pub fn schema() -> serde_json::Value {
    let mut schema = schemars::schema_for!(Record<'static>);
    schema.insert(
        "title".into(),
        "One event of an Aviary trace (one line of the JSON Lines file)".into(),
    );
    schema.insert(
        "description".into(),
        "Values are SI (m, s, m/s); positions are [x, y, z] in the world's local frame (x east, y north, z up). Made from the types of crates/aviary-api/src/trace.rs: do not edit by hand.".into(),
    );
    // A field the types do not know is an error: a new field comes with its type.
    schema.insert("unevaluatedProperties".into(), false.into());
    schema.to_value()
}
