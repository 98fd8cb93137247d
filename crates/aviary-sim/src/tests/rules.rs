//! What each function accepts and refuses.

use aviary_api::{CallEnd, DroneEvent, FlightState, Interrupt, Value};

use super::*;
use crate::LOAD_TIME;

#[test]
fn takeoff_needs_arming_and_flights_need_the_air() {
    let w = one_drone();
    let mut fleet = Fleet::new(&w);
    let (exception, reason) = refused(&mut fleet, 0, Function::TakeOff, &[num(10.0)]);
    assert_eq!(exception, BuiltinException::CommandFailed);
    assert!(reason.contains("not armed"), "{reason}");
    let (_, reason) = refused(&mut fleet, 0, Function::FlyToPosition, &[pos(10.0, 0.0)]);
    assert!(reason.contains("take off first"), "{reason}");
    // A value of the wrong kind is refused as the call is read (`FunctionCall::new`); a
    // number that is not finite, by the simulator.
    assert!(aviary_api::FunctionCall::new(Function::TakeOff, &[sym("high")]).is_err());
    let (exception, reason) = refused(&mut fleet, 0, Function::TakeOff, &[num(f64::NAN)]);
    assert_eq!(exception, BuiltinException::CommandFailed);
    assert!(reason.contains("finite"), "{reason}");
    assert_eq!(instant(&mut fleet, 0, Function::Land, &[]), CallEnd::Done, "landed already");
    assert_eq!(
        instant(&mut fleet, 0, Function::ReturnToLaunch, &[]),
        CallEnd::Done,
        "at home already"
    );
    assert_eq!(instant(&mut fleet, 0, Function::Arm, &[]), CallEnd::Done);
    assert_eq!(instant(&mut fleet, 0, Function::Disarm, &[]), CallEnd::Done);
    instant(&mut fleet, 0, Function::Arm, &[]);
    let id = start(&mut fleet, 0, Function::TakeOff, &[num(10.0)]);
    let (_, reason) = refused(&mut fleet, 0, Function::Hover, &[num(1.0)]);
    assert!(reason.contains("busy"), "{reason}");
    run_until(&mut fleet, 0, id, 60.0);
    assert_eq!(refused(&mut fleet, 0, Function::Arm, &[]).0, BuiltinException::CommandFailed);
    assert_eq!(refused(&mut fleet, 0, Function::Disarm, &[]).0, BuiltinException::CommandFailed);
    // In the air, TakeOff climbs or descends to the altitude.
    let id = start(&mut fleet, 0, Function::TakeOff, &[num(4.0)]);
    run_until(&mut fleet, 0, id, 60.0);
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position[2], 4.0);
    let id = start(&mut fleet, 0, Function::AscendTo, &[num(30.0)]);
    run_until(&mut fleet, 0, id, 60.0);
    let id = start(&mut fleet, 0, Function::DescendTo, &[num(12.0)]);
    run_until(&mut fleet, 0, id, 60.0);
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, [0.0, 0.0, 12.0]);
    assert_eq!(
        refused(&mut fleet, 999, Function::Hover, &[num(1.0)]).0,
        BuiltinException::CommandFailed
    );
}

#[test]
fn hover_waits_and_return_to_launch_lands_at_home_disarmed() {
    let w = one_drone();
    let mut fleet = airborne(&w, 5.0);
    let id = start(&mut fleet, 0, Function::Hover, &[num(10.0)]);
    let run = run_until(&mut fleet, 0, id, 60.0);
    assert!((run.took - 10.0).abs() < DT + 1e-9, "{}", run.took);
    let id = start(
        &mut fleet,
        0,
        Function::FollowPath,
        &[pos(50.0, 0.0), pos3(50.0, 50.0, 30.0), pos(0.0, 50.0)],
    );
    let run = run_until(&mut fleet, 0, id, 200.0);
    assert!(run.samples.iter().any(|t| t.position == [50.0, 0.0, 5.0]));
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, [0.0, 50.0, 30.0]);
    let id = start(&mut fleet, 0, Function::ReturnToLaunch, &[]);
    let run = run_until(&mut fleet, 0, id, 200.0);
    assert!(run.samples.iter().all(|t| t.position[2] <= 30.0));
    let t = fleet.telemetry(DroneId(0)).unwrap();
    assert_eq!((t.position, t.state), ([0.0, 0.0, 0.0], FlightState::Landed));
    let (_, reason) = refused(&mut fleet, 0, Function::TakeOff, &[num(10.0)]);
    assert!(reason.contains("not armed"), "landing disarms: {reason}");
    // From low down, the return climbs to 10 m first.
    let mut fleet = airborne(&w, 3.0);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(40.0, 0.0)]);
    run_until(&mut fleet, 0, id, 60.0);
    let id = start(&mut fleet, 0, Function::ReturnToLaunch, &[]);
    let run = run_until(&mut fleet, 0, id, 200.0);
    let top = run.samples.iter().map(|t| t.position[2]).fold(0.0, f64::max);
    assert_eq!(top, 10.0);
}

#[test]
fn payload_rules() {
    let w = one_drone();
    let mut fleet = Fleet::new(&w);
    let (_, reason) = refused(&mut fleet, 0, Function::LoadPayload, &[sym("Radiation")]);
    assert!(reason.contains("cannot carry Radiation"), "{reason}");
    let (_, reason) = refused(&mut fleet, 0, Function::ReleasePayload, &[]);
    assert!(reason.contains("carries nothing"), "{reason}");
    let id = start(&mut fleet, 0, Function::LoadPayload, &[sym("Body")]);
    let run = run_until(&mut fleet, 0, id, 10.0);
    assert_eq!(run.end, CallEnd::Done);
    assert!((run.took - LOAD_TIME).abs() < 1e-9);
    assert_eq!(fleet.carrying(DroneId(0)), Some("Body"));
    let (_, reason) = refused(&mut fleet, 0, Function::LoadPayload, &[sym("Body")]);
    assert!(reason.contains("already carries Body"), "{reason}");
    // Release in flight, at the drone's position, and logged.
    instant(&mut fleet, 0, Function::Arm, &[]);
    let id = start(&mut fleet, 0, Function::TakeOff, &[num(20.0)]);
    run_until(&mut fleet, 0, id, 60.0);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos3(30.0, 40.0, 3.0)]);
    run_until(&mut fleet, 0, id, 60.0);
    assert_eq!(instant(&mut fleet, 0, Function::ReleasePayload, &[]), CallEnd::Done);
    let release = &fleet.releases()[0];
    assert_eq!(
        (release.drone, release.kind.as_str(), release.position),
        (DroneId(0), "Body", [30.0, 40.0, 3.0])
    );
    assert_eq!(release.time, fleet.time());
    // Loading at 3 m is fine; at 20 m it is too high.
    let id = start(&mut fleet, 0, Function::LoadPayload, &[sym("Body")]);
    run_until(&mut fleet, 0, id, 10.0);
    instant(&mut fleet, 0, Function::ReleasePayload, &[]);
    let id = start(&mut fleet, 0, Function::AscendTo, &[num(20.0)]);
    run_until(&mut fleet, 0, id, 60.0);
    let (_, reason) = refused(&mut fleet, 0, Function::LoadPayload, &[sym("Body")]);
    assert!(reason.contains("below 5 m"), "{reason}");
    // An aborted load leaves the drone empty-handed.
    let mut fleet = Fleet::new(&w);
    let id = start(&mut fleet, 0, Function::LoadPayload, &[sym("Body")]);
    fleet.step(DT);
    assert_eq!(fleet.interrupt(id, Interrupt::Abort), Some(CallEnd::Interrupted));
    assert_eq!(fleet.carrying(DroneId(0)), None);
}

#[test]
fn geofence_and_ceiling_refuse_at_once_without_moving() {
    let w = one_drone();
    let mut fleet = airborne(&w, 20.0);
    let before = fleet.telemetry(DroneId(0)).unwrap();
    let cases: Vec<(Function, Vec<Value>)> = vec![
        (Function::FlyToPosition, vec![pos(1500.0, 0.0)]),
        (Function::FlyToPosition, vec![pos3(10.0, 0.0, 150.0)]),
        (Function::AscendTo, vec![num(121.0)]),
        (Function::TakeOff, vec![num(200.0)]),
        (Function::Orbit, vec![pos(900.0, 0.0), num(200.0)]),
        (
            Function::Sweep,
            vec![
                Value::Area(vec![[900.0, 0.0], [1100.0, 0.0], [1100.0, 100.0], [900.0, 100.0]]),
                num(20.0),
            ],
        ),
        (Function::FollowPath, vec![pos(100.0, 0.0), pos(100.0, 1200.0)]),
    ];
    for (f, args) in cases {
        let (exception, reason) = refused(&mut fleet, 0, f, &args);
        assert_eq!(exception, BuiltinException::GeofenceViolation, "{f}: {reason}");
    }
    run_for(&mut fleet, 2.0);
    let after = fleet.telemetry(DroneId(0)).unwrap();
    assert_eq!((after.position, after.speed), (before.position, 0.0));
    // A non-convex fence: the straight way across the notch is refused.
    let mut w = one_drone();
    w.site.geofence = Some(vec![
        [-10.0, -10.0],
        [100.0, -10.0],
        [100.0, 40.0],
        [40.0, 40.0],
        [40.0, 100.0],
        [-10.0, 100.0],
    ]);
    let mut fleet = airborne(&w, 20.0);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(90.0, 0.0)]);
    run_until(&mut fleet, 0, id, 60.0);
    assert_eq!(
        refused(&mut fleet, 0, Function::FlyToPosition, &[pos(0.0, 90.0)]).0,
        BuiltinException::GeofenceViolation
    );
}

#[test]
fn camera_and_sensors_are_needed() {
    let w = world(
        "[drones.plain]\nhome = [0, 0]\n[drones.cam]\nhome = [5, 0]\nsensors = [\"camera\"]\n",
    );
    let mut fleet = Fleet::new(&w);
    let (_, reason) = refused(&mut fleet, 0, Function::StartStreaming, &[]);
    assert!(reason.contains("no camera"), "{reason}");
    assert_eq!(instant(&mut fleet, 1, Function::StartStreaming, &[]), CallEnd::Done);
    assert!(fleet.streaming(DroneId(1)));
    assert_eq!(instant(&mut fleet, 1, Function::StopStreaming, &[]), CallEnd::Done);
    assert!(!fleet.streaming(DroneId(1)));
    let (_, reason) = refused(&mut fleet, 1, Function::StartDetection, &[sym("Body")]);
    assert!(reason.contains("no sensor that detects Body"), "{reason}");
}

#[test]
fn world_faults_surface_once_as_exceptions() {
    let w = world(
        r#"
[drones.a]
home = [0, 0]
[drones.b]
home = [10, 0]
[drones.c]
home = [20, 0]
[[faults]]
drone = "a"
at = 5.0
kind = "link_loss"
duration = 3.0
[[faults]]
drone = "b"
at = 6.0
kind = "crash"
[[faults]]
drone = "c"
at = 7.0
kind = "motor_failure"
"#,
    );
    let mut fleet = Fleet::new(&w);
    let mut calls = Vec::new();
    for d in 0..3 {
        instant(&mut fleet, d, Function::Arm, &[]);
        calls.push(start(&mut fleet, d, Function::TakeOff, &[num(30.0)]));
    }
    let reports = run_for(&mut fleet, 4.9);
    assert!(reports.iter().all(|r| !matches!(r, Report::Event(_))));
    let mut seen = Vec::new();
    for r in run_for(&mut fleet, 30.0) {
        match r {
            Report::Event(DroneEvent::Fault { drone, failure }) => {
                seen.push((drone.0, failure.exception.name()))
            }
            Report::Event(DroneEvent::Signal { drone, signal }) => {
                seen.push((drone.0, signal.name()))
            }
            Report::Event(DroneEvent::Autopilot { drone, action, .. }) => {
                seen.push((drone.0, action.as_str()))
            }
            Report::Ended { call, end } => assert_eq!(end, CallEnd::Interrupted, "{call:?}"),
            Report::Event(other) => panic!("{other:?}"),
        }
    }
    // Each fault once, and after it what the drone does on its own (a crash, nothing).
    assert_eq!(
        seen,
        [
            (0, "ConnectionLost"),
            (0, "hold"),
            (1, "DroneLost"),
            (2, "MotorFailure"),
            (2, "land"),
            (0, "ConnectionRestored")
        ]
    );
    assert_eq!(fleet.telemetry(DroneId(1)).unwrap().state, FlightState::Lost);
    let c = fleet.telemetry(DroneId(2)).unwrap();
    assert_eq!((c.state, c.position[2]), (FlightState::Landed, 0.0), "emergency landing");
    assert_eq!(refused(&mut fleet, 2, Function::Arm, &[]).0, BuiltinException::CommandFailed);
    assert!(fleet.telemetry(DroneId(0)).unwrap().link);
}
