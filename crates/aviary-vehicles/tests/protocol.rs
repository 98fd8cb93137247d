//! The MAVLink backend against the simulated vehicles, both in this process but talking
//! MAVLink 2 over real loopback sockets: refusals carry the autopilot's reason, a
//! failsafe RTL becomes the matching exception, UDP works, and signing is enforced.
// These tests talk to `aviary vehicles` in real time (its own clock is the wall's).
#![allow(clippy::disallowed_methods, clippy::disallowed_types)]

use std::time::Duration;

use aviary_api::trace::AutopilotAction;
use aviary_api::{
    Backend, BuiltinException, BuiltinSignal, CallEnd, DroneEvent, DroneId, Function, FunctionCall,
    Value,
};
use aviary_mavlink::Tuning;
use aviary_vehicles::{Behaviour, Listen, Options};
use aviary_world::World;

fn world(text: &str) -> World {
    let mut sources = aviary_diagnostics::SourceMap::new();
    let file = sources.add("t.world.toml", text);
    let (world, diagnostics) = aviary_world::parse_world(file, text);
    world.unwrap_or_else(|| panic!("{diagnostics:?}"))
}

fn scout(address: &str, extra: &str) -> String {
    format!(
        "[site]\nname = \"t\"\norigin = {{ lat = 46.6, lon = 14.2, alt = 400.0 }}\n\n\
         [drones.scout]\nhome = [0, 0]\nmavlink = \"{address}\"\n{extra}"
    )
}

fn quick() -> Tuning {
    Tuning {
        connect_timeout: Duration::from_secs(3),
        arm_timeout: Duration::from_secs(1),
        arm_retry: Duration::from_millis(200),
        ..Tuning::default()
    }
}

/// A call as the engine reads it.
fn fc(function: Function, args: &[Value]) -> FunctionCall {
    FunctionCall::new(function, args).unwrap_or_else(|e| panic!("{function}: {e}"))
}

async fn call(backend: &dyn Backend, function: Function, args: &[Value]) -> CallEnd {
    let pending = backend.call(DroneId(0), &fc(function, args));
    tokio::time::timeout(Duration::from_secs(30), pending.end.wait())
        .await
        .expect("the call ends")
        .expect("answered")
}

#[tokio::test]
async fn arming_refused_by_pre_arm_checks_says_why() {
    let behaviour = Behaviour { prearm_time: 1e9, ..Behaviour::default() };
    let vehicles = aviary_vehicles::serve(
        &world(&scout("tcp:x:1", "")),
        Listen::Tcp("127.0.0.1:0".parse().unwrap()),
        Options { speed: 10.0, behaviour, ..Options::default() },
    )
    .await
    .unwrap();
    let backend =
        aviary_mavlink::connect(&world(&scout(&format!("tcp:{}", vehicles.address), "")), quick())
            .await
            .unwrap();
    match call(&backend, Function::Arm, &[]).await {
        CallEnd::Failed(f) => {
            assert_eq!(f.exception, BuiltinException::CommandFailed);
            assert!(f.reason.contains("PreArm: GPS: waiting for 3D fix"), "{}", f.reason);
        }
        other => panic!("{other:?}"),
    }
    vehicles.stop();
}

#[tokio::test]
async fn a_battery_failsafe_rtl_raises_battery_critical() {
    let faults = "\n[[faults]]\ndrone = \"scout\"\nat = 80\nkind = \"battery_critical\"\n";
    let vehicles = aviary_vehicles::serve(
        &world(&scout("tcp:x:1", faults)),
        Listen::Tcp("127.0.0.1:0".parse().unwrap()),
        Options { speed: 10.0, ..Options::default() },
    )
    .await
    .unwrap();
    let backend =
        aviary_mavlink::connect(&world(&scout(&format!("tcp:{}", vehicles.address), "")), quick())
            .await
            .unwrap();
    let mut events = backend.events().unwrap();
    let armed = call(&backend, Function::Arm, &[]).await;
    assert_eq!(armed, CallEnd::Done, "{:?}", events.try_recv());
    let hover = backend.call(DroneId(0), &fc(Function::Hover, &[Value::Number(60.0)]));
    async fn next(events: &mut tokio::sync::mpsc::UnboundedReceiver<DroneEvent>) -> DroneEvent {
        tokio::time::timeout(Duration::from_secs(20), events.recv())
            .await
            .expect("an event")
            .expect("open")
    }
    // What the autopilot did is said as it is seen, then the fault it stands for.
    match next(&mut events).await {
        DroneEvent::Autopilot { drone: DroneId(0), action, reason } => {
            assert_eq!(action, AutopilotAction::ReturnHome);
            assert!(reason.contains("switched to RTL by itself"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    let event = next(&mut events).await;
    match event {
        DroneEvent::Fault { drone: DroneId(0), failure } => {
            assert_eq!(failure.exception, BuiltinException::BatteryCritical);
            assert!(
                failure.reason.contains("switched to RTL by itself")
                    && failure.reason.contains("Battery 1 is critical"),
                "{}",
                failure.reason
            );
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        hover.end.wait().await.unwrap(),
        CallEnd::Interrupted,
        "a fault ends the drone's calls"
    );
    vehicles.stop();
}

#[tokio::test]
async fn take_off_and_land_over_udp() {
    let vehicles = aviary_vehicles::serve(
        &world(&scout("tcp:x:1", "")),
        Listen::Udp("127.0.0.1:0".parse().unwrap()),
        Options { speed: 10.0, ..Options::default() },
    )
    .await
    .unwrap();
    let backend = aviary_mavlink::connect(
        &world(&scout(&format!("udpout:{}", vehicles.address), "")),
        quick(),
    )
    .await
    .unwrap();
    assert_eq!(call(&backend, Function::Arm, &[]).await, CallEnd::Done);
    assert_eq!(call(&backend, Function::TakeOff, &[Value::Number(5.0)]).await, CallEnd::Done);
    let t = backend.telemetry(DroneId(0));
    assert!(
        (t.position[2] - 5.0).abs() <= 0.5 && t.state == aviary_api::FlightState::Flying,
        "{t:?}"
    );
    assert_eq!(call(&backend, Function::Land, &[]).await, CallEnd::Done);
    assert_eq!(backend.telemetry(DroneId(0)).state, aviary_api::FlightState::Landed);
    assert_eq!(call(&backend, Function::Disarm, &[]).await, CallEnd::Done);
    vehicles.stop();
}

#[tokio::test]
async fn signed_links_take_only_the_right_key() {
    let key = aviary_mavlink::signing_key("correct horse battery staple");
    let options = Options { speed: 10.0, signing_key: Some(key), ..Options::default() };
    let vehicles = aviary_vehicles::serve(
        &world(&scout("tcp:x:1", "")),
        Listen::Tcp("127.0.0.1:0".parse().unwrap()),
        options,
    )
    .await
    .unwrap();
    let address = format!("tcp:{}", vehicles.address);
    let right = world(&scout(&address, "signing_key = \"correct horse battery staple\"\n"));
    let backend = aviary_mavlink::connect(&right, quick()).await.expect("the right key connects");
    assert_eq!(call(&backend, Function::Arm, &[]).await, CallEnd::Done);
    let wrong = world(&scout(&address, "signing_key = \"wrong\"\n"));
    let err =
        aviary_mavlink::connect(&wrong, quick()).await.err().expect("a wrong key hears nothing");
    assert!(err.contains("no answer"), "{err}");
    vehicles.stop();
}

#[tokio::test]
async fn pause_holds_resume_goes_on_and_abort_stops() {
    let vehicles = aviary_vehicles::serve(
        &world(&scout("tcp:x:1", "")),
        Listen::Tcp("127.0.0.1:0".parse().unwrap()),
        Options { speed: 5.0, ..Options::default() },
    )
    .await
    .unwrap();
    let backend =
        aviary_mavlink::connect(&world(&scout(&format!("tcp:{}", vehicles.address), "")), quick())
            .await
            .unwrap();
    assert_eq!(call(&backend, Function::Arm, &[]).await, CallEnd::Done);
    assert_eq!(call(&backend, Function::TakeOff, &[Value::Number(5.0)]).await, CallEnd::Done);
    let far = Value::Position(aviary_api::Point { x: 300.0, y: 0.0, z: None });
    let flight = backend.call(DroneId(0), &fc(Function::FlyToPosition, &[far]));
    tokio::time::sleep(Duration::from_secs(2)).await;
    backend.interrupt(flight.id, aviary_api::Interrupt::Pause);
    // Braking from 10 m/s and coming back to where it was paused takes a few seconds.
    tokio::time::sleep(Duration::from_secs(3)).await;
    let held = backend.telemetry(DroneId(0)).position;
    tokio::time::sleep(Duration::from_secs(1)).await;
    let still = backend.telemetry(DroneId(0)).position;
    assert!(held[0] > 1.0 && (still[0] - held[0]).abs() < 0.5, "paused: {held:?} then {still:?}");
    backend.interrupt(flight.id, aviary_api::Interrupt::Resume);
    tokio::time::sleep(Duration::from_secs(2)).await;
    let moved = backend.telemetry(DroneId(0)).position;
    assert!(moved[0] > still[0] + 1.0, "resumed: {still:?} then {moved:?}");
    backend.interrupt(flight.id, aviary_api::Interrupt::Abort);
    assert_eq!(flight.end.wait().await.unwrap(), CallEnd::Interrupted);
    tokio::time::sleep(Duration::from_secs(2)).await;
    let stopped = backend.telemetry(DroneId(0)).position;
    tokio::time::sleep(Duration::from_secs(1)).await;
    let after = backend.telemetry(DroneId(0)).position;
    assert!(
        stopped[0] < 290.0 && (after[0] - stopped[0]).abs() < 0.5,
        "aborted: {stopped:?} then {after:?}"
    );
    vehicles.stop();
}

#[tokio::test]
async fn a_vehicle_that_goes_and_comes_back_raises_lost_then_restored() {
    let scout_world = world(&scout("tcp:x:1", ""));
    let tcp = Listen::Tcp("127.0.0.1:0".parse().unwrap());
    let options = Options { speed: 5.0, ..Options::default() };
    let first = aviary_vehicles::serve(&scout_world, tcp, options).await.unwrap();
    let address = first.address;
    let backend = aviary_mavlink::connect(&world(&scout(&format!("tcp:{address}"), "")), quick())
        .await
        .unwrap();
    let mut events = backend.events().unwrap();
    first.stop();
    let lost = tokio::time::timeout(Duration::from_secs(6), events.recv())
        .await
        .expect("an event")
        .unwrap();
    assert!(
        matches!(&lost, DroneEvent::Fault { failure, .. } if failure.exception == BuiltinException::ConnectionLost),
        "{lost:?}"
    );
    assert!(!backend.telemetry(DroneId(0)).link);
    match call(&backend, Function::Arm, &[]).await {
        CallEnd::Failed(f) => assert!(f.reason.contains("no link"), "{}", f.reason),
        other => panic!("{other:?}"),
    }
    // The same port again: the backend opens the connection anew and hears HEARTBEAT.
    let second = aviary_vehicles::serve(&scout_world, Listen::Tcp(address), options).await.unwrap();
    let back = tokio::time::timeout(Duration::from_secs(6), events.recv())
        .await
        .expect("an event")
        .unwrap();
    assert_eq!(
        back,
        DroneEvent::Signal { drone: DroneId(0), signal: BuiltinSignal::ConnectionRestored }
    );
    assert!(backend.telemetry(DroneId(0)).link);
    assert_eq!(call(&backend, Function::Arm, &[]).await, CallEnd::Done);
    second.stop();
}

#[tokio::test]
async fn the_battery_rule_signals_low_then_raises_critical_once() {
    // 10.3 % at the start: just above what a drone 10 m up at home needs plus 10 %.
    let text = scout("tcp:x:1", "battery = 10.3\n");
    let vehicles = aviary_vehicles::serve(
        &world(&text),
        Listen::Tcp("127.0.0.1:0".parse().unwrap()),
        Options { speed: 5.0, ..Options::default() },
    )
    .await
    .unwrap();
    let backend = aviary_mavlink::connect(
        &world(&scout(&format!("tcp:{}", vehicles.address), "battery = 10.3\n")),
        quick(),
    )
    .await
    .unwrap();
    let mut events = backend.events().unwrap();
    assert_eq!(call(&backend, Function::Arm, &[]).await, CallEnd::Done);
    let _climb = backend.call(DroneId(0), &fc(Function::TakeOff, &[Value::Number(10.0)]));
    let mut seen = Vec::new();
    let until = tokio::time::Instant::now() + Duration::from_secs(10);
    while let Ok(Some(e)) = tokio::time::timeout_at(until, events.recv()).await {
        seen.push(e);
    }
    let names: Vec<&str> = seen
        .iter()
        .filter_map(|e| match e {
            DroneEvent::Signal { signal, .. } => Some(signal.name()),
            DroneEvent::Fault { failure, .. } => Some(failure.exception.name()),
            DroneEvent::Detected { .. } => Some("Detected"),
            DroneEvent::Autopilot { .. } => None,
        })
        .collect();
    // The vehicle's own battery failsafe (RTL) comes too: still one exception, and the
    // autopilot's return is recorded as what it did on its own.
    assert_eq!(names, ["BatteryLow", "BatteryCritical"], "{seen:?}");
    let on_its_own: Vec<AutopilotAction> = seen
        .iter()
        .filter_map(|e| match e {
            DroneEvent::Autopilot { action, .. } => Some(*action),
            _ => None,
        })
        .collect();
    assert_eq!(on_its_own, [AutopilotAction::ReturnHome], "{seen:?}");
    vehicles.stop();
}

#[tokio::test]
async fn a_crash_raises_drone_lost() {
    // At 10× real time the crash comes 12 s after the vehicles start: after connect (which
    // waits up to 2.5 s for parameters a vehicle may not serve), arming and the take-off.
    let faults = "\n[[faults]]\ndrone = \"scout\"\nat = 120\nkind = \"crash\"\n";
    let vehicles = aviary_vehicles::serve(
        &world(&scout("tcp:x:1", faults)),
        Listen::Tcp("127.0.0.1:0".parse().unwrap()),
        Options { speed: 10.0, ..Options::default() },
    )
    .await
    .unwrap();
    let backend =
        aviary_mavlink::connect(&world(&scout(&format!("tcp:{}", vehicles.address), "")), quick())
            .await
            .unwrap();
    let mut events = backend.events().unwrap();
    assert_eq!(call(&backend, Function::Arm, &[]).await, CallEnd::Done);
    assert_eq!(call(&backend, Function::TakeOff, &[Value::Number(10.0)]).await, CallEnd::Done);
    let hover = backend.call(DroneId(0), &fc(Function::Hover, &[Value::Number(300.0)]));
    match tokio::time::timeout(Duration::from_secs(15), events.recv())
        .await
        .expect("an event")
        .unwrap()
    {
        DroneEvent::Fault { drone: DroneId(0), failure } => {
            assert_eq!(failure.exception, BuiltinException::DroneLost);
            assert!(
                failure.reason.contains("MAV_STATE_EMERGENCY") && failure.reason.contains("Crash"),
                "{}",
                failure.reason
            );
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(hover.end.wait().await.unwrap(), CallEnd::Interrupted);
    vehicles.stop();
}
