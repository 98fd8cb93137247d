//! The run-time half of the middle layer: values, telemetry, calls and drone events.

use serde::{Deserialize, Serialize};
use tokio::sync::{mpsc, oneshot};

use crate::{BuiltinException, BuiltinSignal};

/// A drone, by its index in the world file's order: a type of its own, so that a table
/// of the fleet (a [`typed_index_collections::TiVec`]) takes only a drone. Serialized as
/// the number it holds.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize,
)]
#[serde(transparent)]
pub struct DroneId(pub usize);

impl From<usize> for DroneId {
    fn from(i: usize) -> DroneId {
        DroneId(i)
    }
}

impl From<DroneId> for usize {
    fn from(id: DroneId) -> usize {
        id.0
    }
}

impl std::fmt::Display for DroneId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

/// A point in the world's local frame (metres: x east, y north, z up). Without `z`, a
/// flight keeps the altitude it has.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub z: Option<f64>,
}

impl Point {
    pub fn flat(x: f64, y: f64) -> Point {
        Point { x, y, z: None }
    }
}

/// A value at run time. Quantities are SI: metres, seconds, m/s, degrees, fractions.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Number(f64),
    Text(String),
    Symbol(String),
    Bool(bool),
    Position(Point),
    Area(Vec<[f64; 2]>),
    Actor(DroneId),
    /// What a drone's last `Sweep` or `FollowPath` left (`drone.remaining`); shared, since
    /// a mission passes it on as it is.
    Remainder(std::sync::Arc<crate::Remainder>),
    /// No value: what a drone reads that it does not have (an attribute the world does not
    /// give it, a wind sensor it lacks, a payload it does not carry). It equals nothing,
    /// not even itself, orders with nothing, is not true, and a trace writes it `null`.
    Absent,
}

/// What a drone is doing, as telemetry's `state` reports it (and the trace writes it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, schemars::JsonSchema)]
pub enum FlightState {
    Landed,
    TakingOff,
    Flying,
    Landing,
    /// Crashed or otherwise gone for good.
    Lost,
}

impl FlightState {
    /// The symbol a mission compares with: `drone.state = Landed`.
    pub fn as_str(self) -> &'static str {
        match self {
            FlightState::Landed => "Landed",
            FlightState::TakingOff => "TakingOff",
            FlightState::Flying => "Flying",
            FlightState::Landing => "Landing",
            FlightState::Lost => "Lost",
        }
    }
    pub fn airborne(self) -> bool {
        matches!(self, FlightState::TakingOff | FlightState::Flying | FlightState::Landing)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Telemetry {
    /// `[x, y, z]`, local metres.
    pub position: [f64; 3],
    /// Ground speed, m/s.
    pub speed: f64,
    /// Degrees clockwise from north.
    pub heading: f64,
    /// What is left, as a fraction of a full battery.
    pub battery: f64,
    pub state: FlightState,
    pub link: bool,
    /// Where the drone's GPS says it is: what a mission reads as its `position` and
    /// `altitude`. `position` plus the simulated GPS error (`[air.gps]`), the same as
    /// `position` without one; the trace keeps the true `position`.
    pub gps_position: [f64; 3],
    /// The wind at the drone, `[east, north]` m/s (where it blows to), when it carries a
    /// `wind` sensor and the backend knows the wind: `drone.wind` reads its speed.
    pub wind: Option<[f64; 2]>,
}

impl Telemetry {
    /// What a backend reports for a drone it does not know, or no longer hears from.
    pub const LOST: Telemetry = Telemetry {
        position: [0.0; 3],
        speed: 0.0,
        heading: 0.0,
        battery: 0.0,
        state: FlightState::Lost,
        link: false,
        gps_position: [0.0; 3],
        wind: None,
    };
}

/// A built-in exception (docs/LANGUAGE.md, section 17) and why it was raised.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub exception: BuiltinException,
    /// Why, for people: the trace's `reason` and the summary.
    pub reason: String,
    /// Why, for a machine, where one exception has causes an operator tells apart.
    pub cause: Option<Cause>,
}

impl Failure {
    pub fn new(exception: BuiltinException, reason: impl Into<String>) -> Failure {
        Failure { exception, reason: reason.into(), cause: None }
    }

    /// A `Timeout` of the separation between drones: a motion held back, waiting for
    /// another drone to make room, for longer than the mission lets it.
    pub fn separation(reason: impl Into<String>) -> Failure {
        let cause = Some(Cause::Separation);
        Failure { exception: BuiltinException::Timeout, reason: reason.into(), cause }
    }
}

/// What caused an exception, where the trace says it (`cause`): so that a ground station
/// tells a separation wait from a silent vehicle (both `Timeout`) by a word, not by
/// reading the reason's text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Cause {
    /// Drones kept apart: a motion waited for another drone to make room until it timed
    /// out.
    Separation,
}

/// How a call ended.
#[derive(Clone, Debug, PartialEq)]
pub enum CallEnd {
    Done,
    /// The call cannot be done: the activity that made it gets this exception.
    Failed(Failure),
    /// Stopped by [`Backend::interrupt`], or by a fault reported as a [`DroneEvent`].
    Interrupted,
}

/// A call just made: its id, and how its end comes.
pub struct PendingCall {
    pub id: CallId,
    pub end: Ending,
}

/// A call's end: known as the call is made (refused, or done at once: no channel to
/// make and poll, the common case of an instant step), or answered later by the
/// backend, which keeps the sending side and answers exactly once.
pub enum Ending {
    Now(CallEnd),
    Later(oneshot::Receiver<CallEnd>),
}

impl Ending {
    /// The call's end; `None` when the backend dropped the call without answering.
    pub async fn wait(self) -> Option<CallEnd> {
        match self {
            Ending::Now(end) => Some(end),
            Ending::Later(rx) => rx.await.ok(),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CallId(pub u64);

/// What the engine may do to a call in progress (the leashes of docs/LANGUAGE.md, section 14).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interrupt {
    /// Stop it for good; the drone holds where it is. The call ends `Interrupted`.
    Abort,
    /// Hold the drone where it is; the call stays in progress.
    Pause,
    /// Go on from where the call was paused.
    Resume,
}

/// Something a drone reports without being asked.
#[derive(Clone, Debug, PartialEq)]
pub enum DroneEvent {
    /// A target found while detection of its kind is on, once per target per activation.
    Detected { drone: DroneId, kind: String, location: [f64; 3] },
    /// A built-in signal of the drone (`BatteryLow`, `ConnectionRestored`).
    Signal { drone: DroneId, signal: BuiltinSignal },
    /// A fault (`BatteryCritical`, `ConnectionLost`, ...). Raised once; the drone's calls
    /// in progress end `Interrupted`, so the exception is never raised twice.
    Fault { drone: DroneId, failure: Failure },
    /// The drone's autopilot acted on its own (a failsafe: holding after a lost link,
    /// returning home, landing), after the fault that made it, if any. Recorded, never
    /// raised: the fault is the exception.
    Autopilot { drone: DroneId, action: crate::trace::AutopilotAction, reason: String },
}

impl DroneEvent {
    /// The drone the event is of.
    pub fn drone(&self) -> DroneId {
        match self {
            DroneEvent::Detected { drone, .. }
            | DroneEvent::Signal { drone, .. }
            | DroneEvent::Fault { drone, .. }
            | DroneEvent::Autopilot { drone, .. } => *drone,
        }
    }
}

/// A fleet of drones as the engine sees it. Implemented by the built-in simulator and by
/// real-drone backends; the engine never knows which one it drives.
pub trait Backend {
    /// Starts `call` on `drone`: a function with its arguments read
    /// ([`crate::FunctionCall::new`], against the standard descriptor's signatures,
    /// [`crate::Descriptor::standard`], which every backend offers). Whether their values
    /// can be flown (finite, inside the site's limits) is the backend's to refuse.
    fn call(&self, drone: DroneId, call: &crate::FunctionCall) -> PendingCall;
    fn interrupt(&self, call: CallId, how: Interrupt);
    fn telemetry(&self, drone: DroneId) -> Telemetry;
    /// The kind of payload drone `drone` carries now (`drone.payload`), `None` when it
    /// carries nothing or the backend does not know it. Apart from [`Telemetry`], which is
    /// `Copy` and read many times a step: this is read only when a mission asks.
    fn payload(&self, drone: DroneId) -> Option<String>;
    /// Where drone `drone`'s last `Sweep` or `FollowPath` stopped, once it ended other
    /// than done (a fault, an abort, a failure on the way): the point of its path it was
    /// flying to and where the drone was ([`crate::Progress`]; the path is the contract's,
    /// [`crate::coverage`]). `None` when that call was refused before the drone moved, or
    /// the drone's last motion call was no such call: a motion call forgets what the one
    /// before it left. The engine asks as soon as it learns the call ended, and computes
    /// what is left with [`crate::coverage::left`].
    fn stopped(&self, drone: DroneId) -> Option<crate::Progress>;
    /// The stream of drone events; taken once, by the engine.
    fn events(&self) -> Option<mpsc::UnboundedReceiver<DroneEvent>>;
}
