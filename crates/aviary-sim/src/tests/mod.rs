//! Tests of the physics core (plain) and of the backend (on `aviary_clock`'s runtime).

mod air;
mod backend;
mod envelope;
mod flight;
mod landing;
mod link;
mod no_fly;
mod randomness;
mod reach_box;
mod remainder;
mod rules;
mod separation;
mod sky;
mod start;

pub(crate) use aviary_api::{BuiltinException, Function};
use aviary_api::{CallEnd, CallId, DroneEvent, DroneId, FunctionCall, Point, Telemetry, Value};
use aviary_diagnostics::FileId;
use aviary_world::{parse_world, World};

use crate::{Fleet, Report};

pub(crate) const DT: f64 = 0.05;

/// A world with a 1 km square geofence, 120 m ceiling, and the given drones and extras.
pub(crate) fn world(extra: &str) -> World {
    let text = format!(
        "[site]\ngeofence = [[-1000, -1000], [1000, -1000], [1000, 1000], [-1000, 1000]]\nmax_altitude = 120.0\n\n{extra}"
    );
    let (world, diags) = parse_world(FileId(0), &text);
    assert!(diags.is_empty(), "{diags:#?}");
    world.expect("a world")
}

/// One drone `d` at the origin with a thermal sensor and a Body payload.
pub(crate) fn one_drone() -> World {
    world(
        r#"
[drones.d]
home = [0, 0]
sensors = ["camera", "thermal"]
payload = ["Body"]

[sensors.thermal]
detects = ["Body"]
range = 20.0

[[targets]]
kind = "Body"
at = [100, 10]

[[targets]]
kind = "Body"
at = [100, 50]

[[targets]]
kind = "Body"
at = [300, 0]
"#,
    )
}

/// A call as the engine reads it: the arguments must fit the function's signature.
pub(crate) fn fc(f: Function, args: &[Value]) -> FunctionCall {
    FunctionCall::new(f, args).unwrap_or_else(|e| panic!("{f}: {e}"))
}

pub(crate) fn num(x: f64) -> Value {
    Value::Number(x)
}

pub(crate) fn pos(x: f64, y: f64) -> Value {
    Value::Position(Point::flat(x, y))
}

pub(crate) fn pos3(x: f64, y: f64, z: f64) -> Value {
    Value::Position(Point { x, y, z: Some(z) })
}

pub(crate) fn sym(s: &str) -> Value {
    Value::Symbol(s.to_owned())
}

/// A call that must start (not end at once).
pub(crate) fn start(fleet: &mut Fleet, drone: usize, f: Function, args: &[Value]) -> CallId {
    let (id, end) = fleet.call(DroneId(drone), &fc(f, args));
    assert_eq!(end, None, "{f} ended at once");
    id
}

/// A call that must end at once, with this end.
pub(crate) fn instant(fleet: &mut Fleet, drone: usize, f: Function, args: &[Value]) -> CallEnd {
    fleet.call(DroneId(drone), &fc(f, args)).1.unwrap_or_else(|| panic!("{f} did not end at once"))
}

/// The exception of a refused call.
pub(crate) fn refused(
    fleet: &mut Fleet,
    drone: usize,
    f: Function,
    args: &[Value],
) -> (BuiltinException, String) {
    match instant(fleet, drone, f, args) {
        CallEnd::Failed(failure) => (failure.exception, failure.reason),
        other => panic!("{f} was not refused: {other:?}"),
    }
}

/// What stepping until `call` ends saw.
pub(crate) struct Run {
    pub end: CallEnd,
    /// Seconds from the first step to the end.
    pub took: f64,
    /// Telemetry of every drone after each step.
    pub samples: Vec<Telemetry>,
    pub events: Vec<DroneEvent>,
}

/// Steps until `call` ends (at most `limit` seconds), recording drone `drone`.
pub(crate) fn run_until(fleet: &mut Fleet, drone: usize, call: CallId, limit: f64) -> Run {
    let t0 = fleet.time();
    let mut samples = vec![fleet.telemetry(DroneId(drone)).unwrap()];
    let mut events = Vec::new();
    while fleet.time() - t0 < limit {
        let mut ended = None;
        for report in fleet.step(DT) {
            match report {
                Report::Ended { call: c, end } if c == call => ended = Some(end),
                Report::Ended { .. } => {}
                Report::Event(e) => events.push(e),
            }
        }
        samples.push(fleet.telemetry(DroneId(drone)).unwrap());
        if let Some(end) = ended {
            return Run { end, took: fleet.time() - t0, samples, events };
        }
    }
    panic!("call {call:?} did not end within {limit} s");
}

/// Steps `seconds`, returning the events.
pub(crate) fn run_for(fleet: &mut Fleet, seconds: f64) -> Vec<Report> {
    let steps = (seconds / DT).round() as usize;
    (0..steps).flat_map(|_| fleet.step(DT)).collect()
}

/// Arms drone 0 and takes it off to `alt`.
pub(crate) fn airborne(world: &World, alt: f64) -> Fleet {
    let mut fleet = Fleet::new(world);
    assert_eq!(instant(&mut fleet, 0, Function::Arm, &[]), CallEnd::Done);
    let id = start(&mut fleet, 0, Function::TakeOff, &[num(alt)]);
    assert_eq!(run_until(&mut fleet, 0, id, 120.0).end, CallEnd::Done);
    fleet
}
