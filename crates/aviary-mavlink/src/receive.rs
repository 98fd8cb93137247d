//! What the ground station makes of the bytes that come from a vehicle, without a socket:
//! the link's reading (frames, skipping what is not MAVLink, fails its checksum or is of
//! an unknown kind) and one vehicle's observing of its autopilot's messages
//! ([`Vehicle::observe`](crate::vehicle::Vehicle::observe)), detection included. The fuzz
//! target `fuzz_link` drives it with untrusted bytes.

use aviary_api::{DroneEvent, Failure};
use aviary_world::Target;
use mavlink::dialects::ardupilotmega::MavMessage;
use mavlink::error::MessageReadError;
use mavlink::MavlinkReader;
use tokio::sync::mpsc;

use crate::link::AUTOPILOT_COMPONENT;
use crate::vehicle::{Activation, Fix, Vehicle};
use aviary_api::geo::Origin;

/// What was believed of the vehicle once every frame was read.
#[derive(Debug)]
pub struct Heard {
    /// Messages taken from the vehicle's autopilot (system 1, component 1).
    pub messages: usize,
    pub fix: Option<Fix>,
    pub battery: Option<f64>,
    pub odometer: f64,
    pub flight_time: f64,
    /// Drone events sent to the engine (detections, signals).
    pub events: usize,
    /// Exceptions raised (`PositionLost`, a failsafe's).
    pub alarms: Vec<Failure>,
}

/// Reads `bytes` as a link reads them, for a vehicle (system 1) about `origin`, looking
/// for `targets` with a sensor of `range` metres.
pub fn hear(bytes: &[u8], origin: Origin, targets: Vec<Target>, range: f64) -> Heard {
    let (events_tx, mut events) = mpsc::unbounded_channel::<DroneEvent>();
    let (alarms_tx, mut alarms) = mpsc::unbounded_channel();
    let mut kinds: Vec<String> = targets.iter().map(|t| t.kind.clone()).collect();
    kinds.sort();
    kinds.dedup();
    let n = targets.len();
    let vehicle = Vehicle::new(
        aviary_api::DroneId(0),
        "heard".into(),
        1,
        origin,
        targets,
        events_tx,
        alarms_tx,
    );
    for kind in kinds {
        vehicle.seen().detecting.push(Activation { kind, range, found: vec![false; n] });
    }
    let mut reader = MavlinkReader::new(bytes);
    let mut messages = 0;
    loop {
        match reader.read_any_message::<MavMessage>() {
            Ok((header, msg)) => {
                if header.component_id == AUTOPILOT_COMPONENT && header.system_id == 1 {
                    vehicle.observe(&msg);
                    messages += 1;
                }
            }
            Err(MessageReadError::Parse(_)) => {}
            Err(_) => break,
        }
    }
    let seen = vehicle.seen();
    let mut heard = Heard {
        messages,
        fix: seen.fix,
        battery: seen.battery,
        odometer: seen.odometer,
        flight_time: seen.flight_time,
        events: 0,
        alarms: Vec::new(),
    };
    drop(seen);
    while events.try_recv().is_ok() {
        heard.events += 1;
    }
    while let Ok((_, failure)) = alarms.try_recv() {
        heard.alarms.push(failure);
    }
    heard
}
