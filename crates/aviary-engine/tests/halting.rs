//! Aborts never race (the bug class of BehaviorTree.CPP #83 and #1031): an aborted
//! activity stops its drone at once, gives its claims back at once, a queued activity
//! that is aborted never starts, and nothing it started keeps running.

use aviary_api::trace::{CallStatus, Event, Record, Shown};
use aviary_api::Function;
use aviary_engine::{RunOptions, Status};
use aviary_test_support::harness;
use aviary_test_support::trace::{actor, is};
use harness::{run, run_with, WORLD};

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 0.11
}

/// The `capability_end` of the activity tagged `tag`, with its status.
fn end_tagged<'r>(r: &'r harness::Run, tag: &str) -> (&'r Record<'static>, Status) {
    r.trace
        .iter()
        .find_map(|e| match &e.event {
            Event::CapabilityEnd { tag: Some(t), status, .. } if t == tag => Some((e, *status)),
            _ => None,
        })
        .unwrap()
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
    assert_eq!(fly.status, Status::Ok, "resumed, it arrives");
    let arrived = r.trace.iter().rfind(|e| is::done(Function::FlyToPosition)(&e.event)).unwrap();
    let Event::ApiDone { position, .. } = arrived.event else { unreachable!() };
    assert!((position[1] - 400.0).abs() < 0.6);
}

#[test]
fn abort_stops_the_drone_and_frees_the_resource_at_once() {
    let r = with_telemetry(
        "MISSION M:\n    PARALLEL:\n        a FlyTo-F1 WITH Far\n        a Hover WITH 1s\n        SEQUENTIAL:\n            b Hover WITH 20s\n            FlyTo-F1 ABORT\n",
    );
    assert_eq!(r.ends("FlyTo", "a")[0].status, Status::Aborted);
    let aborted_at = r.ends("FlyTo", "a")[0].t;
    assert!(close(aborted_at, 20.0));
    // The Hover waiting for a's motion starts in the same instant the claim is given back.
    let hover = r
        .trace
        .iter()
        .find(|e| {
            matches!(&e.event, Event::CapabilityStart { actor, capability, .. }
                if actor == "a" && capability == "Hover")
        })
        .unwrap();
    assert_eq!(hover.t, aborted_at);
    // The flight call was interrupted, not left running: a stays where it was stopped.
    let interrupted = r.first(is::done(Function::FlyToPosition));
    assert!(matches!(interrupted.event, Event::ApiDone { status: CallStatus::Aborted, .. }));
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
    let (queued, status) = end_tagged(&r, "Queued");
    assert_eq!(status, Status::Aborted);
    assert!(close(queued.t, 3.0));
    assert!(
        !r.trace.iter().any(|e| matches!(&e.event, Event::ApiCall { actor, args, .. }
            if actor == "a" && args.first() == Some(&Shown::Number(5.0)))),
        "its body never ran"
    );
    // FlyTo then queues behind the first Hover only, and starts when it ends.
    let fly = r.first(is::start_of("FlyTo"));
    assert!(close(fly.t, 10.0), "{}", r.dump());
}

#[test]
fn abort_in_the_instant_a_call_ends_is_clean() {
    // The abort and the arrival of the 5 s hover fall on the same tick.
    let r = run("MISSION M:\n    PARALLEL:\n        a Hover-H WITH 5s\n        SEQUENTIAL:\n            b Hover WITH 5s\n            Hover-H ABORT\n            a Hover WITH 1s\n");
    assert_eq!(r.outcome.status, Status::Ok);
    let (_, h) = end_tagged(&r, "H");
    assert!(h == Status::Ok || h == Status::Aborted);
    assert_eq!(
        r.find(|e| matches!(e, Event::CapabilityEnd { actor, .. } if actor == "a")).len(),
        2,
        "both of a's activities end exactly once"
    );
    let second = r.find(is::start_by("a"))[1];
    assert!(close(second.t, 5.0));
}

#[test]
fn an_abort_section_runs_after_the_activity_stopped() {
    let r = run(
        "CAPABILITY Watch BY d:\n    PERFORM:\n        d.Hover(100s)\n    PERFORM ABORT:\n        SIGNAL Stopped\n\nMISSION M:\n    PARALLEL:\n        a Watch-W\n        SEQUENTIAL:\n            b Hover WITH 2s\n            Watch-W ABORT\n    ON Stopped:\n        c Hover WITH 1s\n",
    );
    let end = r.index(is::end_of("Watch"));
    let stopped = r.index(is::signal("Stopped"));
    assert!(stopped < end, "the section runs as part of ending the activity");
    assert!(matches!(r.trace[end].event, Event::CapabilityEnd { status: Status::Aborted, .. }));
    assert!(close(r.t(is::start_by("c")), 2.0));
}

#[test]
fn a_custom_section_runs_on_the_running_activity_with_its_arguments() {
    let r = run(
        "CAPABILITY Watch BY d WITH note:\n    PERFORM:\n        d.Hover(10s)\n    PERFORM Report:\n        SIGNAL Noted WITH note\n\nMISSION M:\n    PARALLEL:\n        a Watch-W WITH note=\"first\"\n        SEQUENTIAL:\n            b Hover WITH 2s\n            Watch-W Report WITH note=\"second\"\n    ON Noted WITH what:\n        c Hover WITH 1s\n",
    );
    let noted = r.first(is::signal("Noted"));
    let Event::Signal { args, actor, .. } = &noted.event else { unreachable!() };
    assert_eq!(args[0].as_str(), Some("second"));
    assert_eq!(actor.as_deref(), Some("a"), "raised by the activity's actor");
    assert!(close(noted.t, 2.0));
    assert_eq!(r.ends("Watch", "a")[0].status, Status::Ok);
}

#[test]
fn requirements_are_checked_at_start() {
    let r = run(
        "CAPABILITY Picky BY d:\n    REQUIREMENTS:\n        d.altitude > 5m\n    PERFORM:\n        d.Hover(1s)\n\nMISSION M:\n    SEQUENTIAL:\n        a Picky\n    ON EXCEPTION RequirementNotMet BY a:\n        b Hover WITH 1s\n",
    );
    assert_eq!(r.ends("Picky", "a")[0].status, Status::Failed);
    let e = r.first(is::exception("RequirementNotMet"));
    let Event::Exception { handled, .. } = e.event else { unreachable!() };
    assert_eq!((actor(&e.event), handled), (Some("a"), true));
    assert_eq!(r.find(is::start_by("b")).len(), 1);
    assert_eq!(r.outcome.status, Status::Ok);
}
