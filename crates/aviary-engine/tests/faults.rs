//! One end-to-end test per fault kind of the world file: the built-in exception it
//! raises, the handler that takes it, and the other drones carrying on.

use aviary_api::trace::{CallStatus, Event, Record, Shown};
use aviary_api::{Function, Point};
use aviary_engine::Status;
use aviary_test_support::harness;
use aviary_test_support::trace::{actor, is};

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 0.11
}

fn with_fault(fault: &str) -> String {
    format!("{}\n[[faults]]\ndrone = \"a\"\n{fault}\n", harness::WORLD)
}

/// An exception's actor and whether a handler took it.
fn taken<'e>(e: &'e Record<'static>) -> (Option<&'e str>, bool) {
    match &e.event {
        Event::Exception { actor, handled, .. } => (actor.as_deref(), *handled),
        other => panic!("not an exception: {other:?}"),
    }
}

/// `a` flies far away; `b` hovers on its own for 30 s.
const BUSY: &str = "        a FlyTo WITH Far\n        b Hover WITH 30s\n";

#[test]
fn a_crash_is_drone_lost_and_the_others_carry_on() {
    let r = harness::run_in(
        &format!("MISSION M:\n    PARALLEL:\n{BUSY}    ON EXCEPTION DroneLost BY a:\n        c Hover WITH 1s\n"),
        &with_fault("at = 8.0\nkind = \"crash\""),
    );
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let e = r.first(is::exception("DroneLost"));
    assert_eq!(taken(e), (Some("a"), true));
    assert!(close(e.t, 8.0));
    assert!(close(r.t(is::start_by("c")), 8.0), "the handler runs at once");
    assert_eq!(r.ends("FlyTo", "a")[0].status, Status::Failed, "the crashed drone's activity ends");
    assert_eq!(r.ends("Hover", "b")[0].status, Status::Ok);
    assert!(
        r.find(is::call(Function::ReturnToLaunch)).iter().all(|e| actor(&e.event) != Some("a")),
        "a lost drone is not sent home"
    );
}

#[test]
fn an_unhandled_crash_fails_the_mission_and_sends_the_others_home() {
    let r = harness::run_in(
        "MISSION M:\n    PARALLEL:\n        a FlyTo WITH Far\n        b FlyTo WITH North\n",
        &with_fault("at = 8.0\nkind = \"crash\""),
    );
    assert_eq!(r.outcome.status, Status::Failed);
    assert!(
        r.outcome.reason.as_deref().unwrap().starts_with("unhandled exception DroneLost on a"),
        "{:?}",
        r.outcome.reason
    );
    let home = r
        .find(is::done(Function::ReturnToLaunch))
        .into_iter()
        .find(|e| actor(&e.event) == Some("b"))
        .expect("b is sent home");
    assert!(matches!(home.event, Event::ApiDone { status: CallStatus::Ok, .. }));
    let last = r.trace.last().unwrap();
    assert!(matches!(last.event, Event::MissionEnd { status: Status::Failed, .. }), "{last:?}");
}

#[test]
fn a_motor_failure_reaches_the_capability_flying_the_drone() {
    let r = harness::run_in(
        "CAPABILITY Deliver BY d:\n    PERFORM:\n        d FlyTo WITH Far\n    EXCEPTIONS:\n        ON EXCEPTION MotorFailure:\n            SIGNAL Down WITH d\n\nMISSION M:\n    PARALLEL:\n        a Deliver\n        b Hover WITH 30s\n    ON Down WITH who:\n        c Hover WITH 1s\n",
        &with_fault("at = 10.0\nkind = \"motor_failure\""),
    );
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let e = r.first(is::exception("MotorFailure"));
    let Event::Exception { handler, .. } = &e.event else { unreachable!() };
    assert_eq!(handler.as_deref(), Some("Deliver/ON EXCEPTION MotorFailure"));
    let Event::Signal { args, .. } = &r.first(is::signal("Down")).event else { unreachable!() };
    assert_eq!(args[0].as_str(), Some("a"));
    assert!(close(r.t(is::start_by("c")), 10.0));
    assert_eq!(r.ends("Hover", "b")[0].status, Status::Ok);
}

#[test]
fn a_gps_loss_is_position_lost() {
    let r = harness::run_in(
        &format!("MISSION M:\n    PARALLEL:\n{BUSY}    ON EXCEPTION PositionLost BY a:\n        c Hover WITH 1s\n"),
        &with_fault("at = 6.0\nkind = \"gps_loss\"\nduration = 4.0"),
    );
    let e = r.first(is::exception("PositionLost"));
    assert_eq!(taken(e), (Some("a"), true));
    assert!(close(r.t(is::start_by("c")), 6.0));
    assert_eq!(r.ends("Hover", "b")[0].status, Status::Ok);
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
}

#[test]
fn a_link_loss_is_connection_lost_and_its_return_is_connection_restored() {
    let r = harness::run_in(
        &format!("MISSION M:\n    PARALLEL:\n{BUSY}    ON EXCEPTION ConnectionLost BY a:\n        c Hover WITH 1s\n    ON ConnectionRestored BY a:\n        a FlyTo WITH North\n"),
        &with_fault("at = 6.0\nkind = \"link_loss\"\nduration = 3.0"),
    );
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let lost = r.first(is::exception("ConnectionLost"));
    assert!(close(lost.t, 6.0));
    let restored = r.first(is::signal("ConnectionRestored"));
    assert_eq!(actor(&restored.event), Some("a"));
    assert!(close(restored.t, 9.0), "when the link is back");
    let north = Shown::Position(Point { x: 0.0, y: 100.0, z: None });
    let again = r
        .trace
        .iter()
        .find(|e| {
            matches!(&e.event, Event::CapabilityStart { actor, capability, args, .. }
                if actor == "a" && capability == "FlyTo" && args.get("target") == Some(&north))
        })
        .expect("a flies again");
    assert!(close(again.t, 9.0));
    assert_eq!(r.ends("Hover", "b")[0].status, Status::Ok);
}

#[test]
fn a_geofence_refusal_is_geofence_violation() {
    // The target comes with a signal, so only the run knows it (`aviary check` reports
    // the flights it can see before take-off: E124).
    let r = harness::run(
        "MISSION M:\n    SEQUENTIAL:\n        a TakeOff\n        SIGNAL Go WITH (5000, 0)\n    ON Go WITH spot:\n        a FlyTo WITH spot\n    ON EXCEPTION GeofenceViolation BY a:\n        a ReturnHome\n",
    );
    let e = r.first(is::exception("GeofenceViolation"));
    assert!(taken(e).1);
    let Event::ApiDone { status, position, .. } = r.first(is::done(Function::FlyToPosition)).event
    else {
        unreachable!()
    };
    assert_eq!(status, CallStatus::Failed);
    assert!(position[0].abs() < 0.01, "refused before it was sent: the drone did not move");
    assert_eq!(r.outcome.status, Status::Ok);
}
