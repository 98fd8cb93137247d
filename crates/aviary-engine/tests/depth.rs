//! Capability calls nest at most `RunOptions::max_call_depth` deep: a recursion the
//! checker lets through (behind a condition) ends in a language exception, never in a
//! stack overflow. The limit is small here so the test thread's stack holds it.

use aviary_api::trace::Event;
use aviary_engine::{RunOptions, Status};
use aviary_test_support::harness;
use aviary_test_support::trace::is;
use harness::{run_with, WORLD};

/// Calls itself for as long as the battery is above 1%, which it stays: no time passes.
const RECURSES: &str = "MISSION M:\n    a Rec\n\nCAPABILITY Rec BY d:\n    PERFORM:\n        IF d.battery > 1%:\n            d Rec\n";

fn limited(depth: usize) -> RunOptions {
    RunOptions { max_call_depth: depth, ..RunOptions::default() }
}

#[test]
fn a_recursion_past_the_limit_raises_command_failed_and_the_mission_ends() {
    let r = run_with(RECURSES, WORLD, &limited(40));
    assert_eq!(r.outcome.status, Status::Failed);
    let reason = r.outcome.reason.clone().unwrap_or_default();
    assert!(reason.contains("unhandled exception CommandFailed on a: calling `Rec` would nest capability calls 41 deep, past the limit of 40"), "{reason}");
    // The 40 that started, and not one more; each ends, failed, as the exception unwinds.
    assert_eq!(r.find(is::start_of("Rec")).len(), 40);
    assert_eq!(r.ends("Rec", "a").len(), 40);
    assert!(r.ends("Rec", "a").iter().all(|e| e.status == Status::Failed), "{}", r.dump());
    let exception = r.first(is::exception("CommandFailed"));
    let Event::Exception { actor, handled, .. } = &exception.event else { unreachable!() };
    assert_eq!(actor.as_deref(), Some("a"));
    assert!(!handled);
    let end = r.trace.last().expect("events");
    let Event::MissionEnd { status, .. } = end.event else { panic!("{}", r.dump()) };
    assert_eq!(status, Status::Failed);
}

#[test]
fn a_handler_can_catch_the_limit_and_the_mission_goes_on() {
    let mission = format!(
        "{}\n",
        RECURSES.replace("MISSION M:\n    a Rec\n", "MISSION M:\n    SEQUENTIAL Try:\n        a Rec\n        ON EXCEPTION CommandFailed BY a:\n            b TakeOff\n    c TakeOff\n")
    );
    let r = run_with(&mission, WORLD, &limited(25));
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    assert!(matches!(
        r.first(is::exception("CommandFailed")).event,
        Event::Exception { handled: true, .. }
    ));
    assert_eq!(r.ends("TakeOff", "b").len(), 1);
    assert_eq!(r.ends("TakeOff", "c").len(), 1);
}

#[test]
fn a_chain_exactly_as_deep_as_the_limit_runs() {
    let n = 30;
    let mut mission = String::from("MISSION M:\n    a C0\n");
    for i in 0..n {
        let body = if i + 1 < n { format!("d C{}", i + 1) } else { "d.Hover(1s)".to_string() };
        mission.push_str(&format!("\nCAPABILITY C{i} BY d:\n    PERFORM:\n        {body}\n"));
    }
    let r = run_with(&mission, WORLD, &limited(n));
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    assert_eq!(r.ends(&format!("C{}", n - 1), "a").len(), 1);
    assert!(r.find(is::exception("CommandFailed")).is_empty());
}
