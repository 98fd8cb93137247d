//! Aborts never race (the bug class of BehaviorTree.CPP #83 and #1031): an aborted
//! activity stops its drone at once, gives its claims back at once, a queued activity
//! that is aborted never starts, and nothing it started keeps running.

use aviary_engine::{RunOptions, Status};
use aviary_test_support::harness;
use harness::{run, run_with, WORLD};

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 0.11
}

fn with_telemetry(mission: &str) -> harness::Run {
    run_with(mission, WORLD, &RunOptions { telemetry_hz: Some(10.0), ..RunOptions::default() })
}

#[test]
fn pause_holds_the_drone_and_resume_goes_on() {
    let r = with_telemetry(
        "MISSION M:\n    PARALLEL:\n        a FlyTo-F1 WITH Far\n        SEQUENTIAL:\n            b Hover WITH 10s\n            FlyTo-F1 PAUSE\n            b Hover WITH 10s\n            FlyTo-F1 RESUME\n",
    );
    assert_eq!(r.outcome.status, Status::Ok);
    let held: Vec<[f64; 3]> = r
        .positions("a")
        .into_iter()
        .filter(|(t, _)| *t > 10.2 && *t < 19.9)
        .map(|(_, p)| p)
        .collect();
    assert!(held.len() > 50);
    assert!(held.iter().all(|p| *p == held[0]), "paused: the drone holds its position");
    let fly = r.ends("FlyTo", "a")[0];
    assert_eq!(fly["status"], "ok", "resumed, it arrives");
    let arrived = r
        .trace
        .iter()
        .rfind(|e| e["event"] == "api_done" && e["function"] == "FlyToPosition")
        .unwrap();
    assert!((arrived["position"][1].as_f64().unwrap() - 400.0).abs() < 0.6);
}

#[test]
fn abort_stops_the_drone_and_frees_the_resource_at_once() {
    let r = with_telemetry(
        "MISSION M:\n    PARALLEL:\n        a FlyTo-F1 WITH Far\n        a Hover WITH 1s\n        SEQUENTIAL:\n            b Hover WITH 20s\n            FlyTo-F1 ABORT\n",
    );
    assert_eq!(r.ends("FlyTo", "a")[0]["status"], "aborted");
    let aborted_at = r.ends("FlyTo", "a")[0]["t"].as_f64().unwrap();
    assert!(close(aborted_at, 20.0));
    // The Hover waiting for a's motion starts in the same instant the claim is given back.
    let hover = r
        .trace
        .iter()
        .find(|e| {
            e["event"] == "capability_start" && e["actor"] == "a" && e["capability"] == "Hover"
        })
        .unwrap();
    assert_eq!(hover["t"].as_f64().unwrap(), aborted_at);
    // The flight call was interrupted, not left running: a stays where it was stopped.
    let interrupted = r
        .trace
        .iter()
        .find(|e| e["event"] == "api_done" && e["function"] == "FlyToPosition")
        .unwrap();
    assert_eq!(interrupted["status"], "aborted");
    let after: Vec<[f64; 3]> = r
        .positions("a")
        .into_iter()
        .filter(|(t, _)| *t > aborted_at + 0.1 && *t < aborted_at + 1.0)
        .map(|(_, p)| p)
        .collect();
    assert!(
        after.windows(2).all(|w| w[0] == w[1]),
        "the drone hovers where the abort found it: {after:?}"
    );
}

#[test]
fn a_queued_activity_that_is_aborted_never_starts_and_holds_nothing() {
    let r = run(
        "MISSION M:\n    PARALLEL:\n        a Hover WITH 10s\n        a Hover-Queued WITH 5s\n        SEQUENTIAL:\n            b Hover WITH 3s\n            Hover-Queued ABORT\n            a FlyTo WITH North\n",
    );
    let queued =
        r.trace.iter().find(|e| e["event"] == "capability_end" && e["tag"] == "Queued").unwrap();
    assert_eq!(queued["status"], "aborted");
    assert!(close(queued["t"].as_f64().unwrap(), 3.0));
    assert!(
        !r.trace
            .iter()
            .any(|e| e["event"] == "api_call" && e["actor"] == "a" && e["args"][0] == 5.0),
        "its body never ran"
    );
    // FlyTo then queues behind the first Hover only, and starts when it ends.
    let fly = r
        .trace
        .iter()
        .find(|e| e["event"] == "capability_start" && e["capability"] == "FlyTo")
        .unwrap();
    assert!(close(fly["t"].as_f64().unwrap(), 10.0), "{}", r.dump());
}

#[test]
fn abort_in_the_instant_a_call_ends_is_clean() {
    // The abort and the arrival of the 5 s hover fall on the same tick.
    let r = run("MISSION M:\n    PARALLEL:\n        a Hover-H WITH 5s\n        SEQUENTIAL:\n            b Hover WITH 5s\n            Hover-H ABORT\n            a Hover WITH 1s\n");
    assert_eq!(r.outcome.status, Status::Ok);
    let h = r.trace.iter().find(|e| e["event"] == "capability_end" && e["tag"] == "H").unwrap();
    assert!(h["status"] == "ok" || h["status"] == "aborted");
    assert_eq!(
        r.find("capability_end", "actor", "a").len(),
        2,
        "both of a's activities end exactly once"
    );
    let second = r
        .trace
        .iter()
        .filter(|e| e["event"] == "capability_start" && e["actor"] == "a")
        .nth(1)
        .unwrap();
    assert!(close(second["t"].as_f64().unwrap(), 5.0));
}

#[test]
fn an_abort_section_runs_after_the_activity_stopped() {
    let r = run(
        "CAPABILITY Watch BY d:\n    PERFORM:\n        d.Hover(100s)\n    PERFORM ABORT:\n        SIGNAL Stopped\n\nMISSION M:\n    PARALLEL:\n        a Watch-W\n        SEQUENTIAL:\n            b Hover WITH 2s\n            Watch-W ABORT\n    ON Stopped:\n        c Hover WITH 1s\n",
    );
    let end = r.index("capability_end", "capability", "Watch");
    let stopped = r.index("signal", "name", "Stopped");
    assert!(stopped < end, "the section runs as part of ending the activity");
    assert_eq!(r.trace[end]["status"], "aborted");
    assert!(close(r.t("capability_start", "actor", "c"), 2.0));
}

#[test]
fn a_custom_section_runs_on_the_running_activity_with_its_arguments() {
    let r = run(
        "CAPABILITY Watch BY d WITH note:\n    PERFORM:\n        d.Hover(10s)\n    PERFORM Report:\n        SIGNAL Noted WITH note\n\nMISSION M:\n    PARALLEL:\n        a Watch-W WITH note=\"first\"\n        SEQUENTIAL:\n            b Hover WITH 2s\n            Watch-W Report WITH note=\"second\"\n    ON Noted WITH what:\n        c Hover WITH 1s\n",
    );
    let noted = r.first("signal", "name", "Noted");
    assert_eq!(noted["args"][0], "second");
    assert_eq!(noted["actor"], "a", "raised by the activity's actor");
    assert!(close(noted["t"].as_f64().unwrap(), 2.0));
    assert_eq!(r.ends("Watch", "a")[0]["status"], "ok");
}

#[test]
fn requirements_are_checked_at_start() {
    let r = run(
        "CAPABILITY Picky BY d:\n    REQUIREMENTS:\n        d.altitude > 5m\n    PERFORM:\n        d.Hover(1s)\n\nMISSION M:\n    SEQUENTIAL:\n        a Picky\n    ON EXCEPTION RequirementNotMet BY a:\n        b Hover WITH 1s\n",
    );
    assert_eq!(r.ends("Picky", "a")[0]["status"], "failed");
    let e = r.first("exception", "name", "RequirementNotMet");
    assert_eq!((e["actor"].as_str(), e["handled"].as_bool()), (Some("a"), Some(true)));
    assert_eq!(r.find("capability_start", "actor", "b").len(), 1);
    assert_eq!(r.outcome.status, Status::Ok);
}
