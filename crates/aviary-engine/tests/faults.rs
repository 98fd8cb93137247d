//! One end-to-end test per fault kind of the world file: the built-in exception it
//! raises, the handler that takes it, and the other drones carrying on.

use aviary_engine::Status;
use aviary_test_support::harness;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 0.11
}

fn with_fault(fault: &str) -> String {
    format!("{}\n[[faults]]\ndrone = \"a\"\n{fault}\n", harness::WORLD)
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
    let e = r.first("exception", "name", "DroneLost");
    assert_eq!((e["actor"].as_str(), e["handled"].as_bool()), (Some("a"), Some(true)));
    assert!(close(e["t"].as_f64().unwrap(), 8.0));
    assert!(close(r.t("capability_start", "actor", "c"), 8.0), "the handler runs at once");
    assert_eq!(r.ends("FlyTo", "a")[0]["status"], "failed", "the crashed drone's activity ends");
    assert_eq!(r.ends("Hover", "b")[0]["status"], "ok");
    assert!(
        !r.trace.iter().any(|e| e["event"] == "api_call"
            && e["function"] == "ReturnToLaunch"
            && e["actor"] == "a"),
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
        .trace
        .iter()
        .find(|e| {
            e["event"] == "api_done" && e["function"] == "ReturnToLaunch" && e["actor"] == "b"
        })
        .expect("b is sent home");
    assert_eq!(home["status"], "ok");
    assert_eq!(r.trace.last().unwrap()["status"], "failed");
}

#[test]
fn a_motor_failure_reaches_the_capability_flying_the_drone() {
    let r = harness::run_in(
        "CAPABILITY Deliver BY d:\n    PERFORM:\n        d FlyTo WITH Far\n    EXCEPTIONS:\n        ON EXCEPTION MotorFailure:\n            SIGNAL Down WITH d\n\nMISSION M:\n    PARALLEL:\n        a Deliver\n        b Hover WITH 30s\n    ON Down WITH who:\n        c Hover WITH 1s\n",
        &with_fault("at = 10.0\nkind = \"motor_failure\""),
    );
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let e = r.first("exception", "name", "MotorFailure");
    assert_eq!(e["handler"], "Deliver/ON EXCEPTION MotorFailure");
    assert_eq!(r.first("signal", "name", "Down")["args"][0], "a");
    assert!(close(r.t("capability_start", "actor", "c"), 10.0));
    assert_eq!(r.ends("Hover", "b")[0]["status"], "ok");
}

#[test]
fn a_gps_loss_is_position_lost() {
    let r = harness::run_in(
        &format!("MISSION M:\n    PARALLEL:\n{BUSY}    ON EXCEPTION PositionLost BY a:\n        c Hover WITH 1s\n"),
        &with_fault("at = 6.0\nkind = \"gps_loss\"\nduration = 4.0"),
    );
    let e = r.first("exception", "name", "PositionLost");
    assert_eq!((e["actor"].as_str(), e["handled"].as_bool()), (Some("a"), Some(true)));
    assert!(close(r.t("capability_start", "actor", "c"), 6.0));
    assert_eq!(r.ends("Hover", "b")[0]["status"], "ok");
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
}

#[test]
fn a_link_loss_is_connection_lost_and_its_return_is_connection_restored() {
    let r = harness::run_in(
        &format!("MISSION M:\n    PARALLEL:\n{BUSY}    ON EXCEPTION ConnectionLost BY a:\n        c Hover WITH 1s\n    ON ConnectionRestored BY a:\n        a FlyTo WITH North\n"),
        &with_fault("at = 6.0\nkind = \"link_loss\"\nduration = 3.0"),
    );
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let lost = r.first("exception", "name", "ConnectionLost");
    assert!(close(lost["t"].as_f64().unwrap(), 6.0));
    let restored = r.first("signal", "name", "ConnectionRestored");
    assert_eq!(restored["actor"], "a");
    assert!(close(restored["t"].as_f64().unwrap(), 9.0), "when the link is back");
    let again = r
        .trace
        .iter()
        .find(|e| {
            e["event"] == "capability_start"
                && e["actor"] == "a"
                && e["capability"] == "FlyTo"
                && e["args"]["target"] == serde_json::json!([0.0, 100.0])
        })
        .expect("a flies again");
    assert!(close(again["t"].as_f64().unwrap(), 9.0));
    assert_eq!(r.ends("Hover", "b")[0]["status"], "ok");
}

#[test]
fn a_geofence_refusal_is_geofence_violation() {
    // The target comes with a signal, so only the run knows it (`aviary check` reports
    // the flights it can see before take-off: E124).
    let r = harness::run(
        "MISSION M:\n    SEQUENTIAL:\n        a TakeOff\n        SIGNAL Go WITH (5000, 0)\n    ON Go WITH spot:\n        a FlyTo WITH spot\n    ON EXCEPTION GeofenceViolation BY a:\n        a ReturnHome\n",
    );
    let e = r.first("exception", "name", "GeofenceViolation");
    assert_eq!(e["handled"], true);
    let refused = r
        .trace
        .iter()
        .find(|e| e["event"] == "api_done" && e["function"] == "FlyToPosition")
        .unwrap();
    assert_eq!(refused["status"], "failed");
    assert!(
        refused["position"][0].as_f64().unwrap().abs() < 0.01,
        "refused before it was sent: the drone did not move"
    );
    assert_eq!(r.outcome.status, Status::Ok);
}
