//! Every claim a pre-flight note (N303) or the firings' warning (W203) makes, held to a
//! simulated run: each test checks the mission, asserts the finding it gets, flies it,
//! and asserts from the trace (order and times) what the finding says.
//!
//! N303 at a statement alone under an `ON EVERY`: "a firing that reaches it while another
//! firing's runs waits until that one ends"; "the firings take the drone one at a time,
//! first come, first served". N303 at a handler's statement after the flow's `SIGNAL`:
//! "may wait"; "whichever starts first holds the drone; the other waits until it ends";
//! "the flow goes first when its statement follows the SIGNAL directly". W203 between two
//! statements of one `ON EVERY`: "another firing's statement may take the drone between
//! this firing's statements"; with `ONE AT A TIME` nothing is reported and each firing
//! runs whole.

use aviary_api::trace::{Event, Params, Shown};
use aviary_api::Point;
use aviary_diagnostics::{Code, Diagnostic};
use aviary_test_support::harness::{self, Run};
use aviary_test_support::trace::{actor, is};

/// An activity's values.
type Args = Params<'static>;

const WORLD: &str = include_str!("fixtures/world.toml");

/// The pre-flight findings of `mission` on the fixtures' world.
fn findings(mission: &str) -> Vec<Diagnostic> {
    let (compiled, world) = harness::compile(mission, WORLD);
    aviary_verify::verify(&compiled, &world)
        .diagnostics
        .into_iter()
        .filter(|d| Code::PREFLIGHT.contains(&d.code) && d.code != Code::LowReserve)
        .collect()
}

fn fly(mission: &str) -> Run {
    harness::run_in(mission, WORLD)
}

/// The line (from 1) of each finding of `code`, in order.
fn lines(mission: &str, found: &[Diagnostic], code: Code) -> Vec<usize> {
    found
        .iter()
        .filter(|d| d.code == code)
        .map(|d| mission[..d.primary.span.start as usize].lines().count().max(1))
        .collect()
}

/// The activities of `capability` on `actor`: (start index, end index, start, end, args).
fn activities<'r>(
    r: &'r Run,
    capability: &str,
    actor: &str,
) -> Vec<(usize, usize, f64, f64, &'r Args)> {
    let mut open: Vec<(usize, f64, &Args)> = Vec::new();
    let mut out = Vec::new();
    for (i, e) in r.trace.iter().enumerate() {
        let t = e.t;
        match &e.event {
            Event::CapabilityStart { capability: c, actor: a, args, .. }
                if c == capability && a == actor =>
            {
                open.push((i, t, args))
            }
            Event::CapabilityEnd { capability: c, actor: a, .. }
                if c == capability && a == actor =>
            {
                let (si, st, args) = open.remove(0);
                out.push((si, i, st, t, args));
            }
            _ => {}
        }
    }
    assert!(open.is_empty(), "every activity ends:\n{}", r.dump());
    out.sort_by_key(|a| a.0);
    out
}

/// A place of the fixtures' world, as an activity's value shows it.
fn at(x: f64, y: f64) -> Shown<'static> {
    Shown::Position(Point { x, y, z: None })
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 0.11
}

/// Activities that never overlap: each starts once the one before has ended.
fn one_at_a_time(acts: &[(usize, usize, f64, f64, &Args)]) {
    for w in acts.windows(2) {
        assert!(w[1].0 > w[0].1, "an activity starts only after the one before ended: {acts:?}");
    }
}

/// Three finds, the second and third while the first delivery flies.
const FINDS: &str = "MISSION Finds:
    PARALLEL Search:
        SEQUENTIAL Reports:
            SIGNAL Found WITH North
            scout1 Hover WITH 10s
            SIGNAL Found WITH East
            SIGNAL Found WITH South
        ON EVERY Found WITH location:
            carrier FlyTo WITH location
";

#[test]
fn a_firing_that_reaches_the_statement_while_another_runs_waits_until_it_ends() {
    let found = findings(FINDS);
    assert_eq!(lines(FINDS, &found, Code::CommandsQueue), [9], "{found:#?}");
    assert!(lines(FINDS, &found, Code::CommandsMayCollide).is_empty(), "{found:#?}");
    assert!(found[0].message.contains(
        "a firing that reaches it while another firing's runs waits until that one ends"
    ));

    let r = fly(FINDS);
    let flights = activities(&r, "FlyTo", "carrier");
    assert_eq!(flights.len(), 3, "{}", r.dump());
    one_at_a_time(&flights);
    // The second and third firings start at 10 s, while the first flight runs: they wait.
    let starts: Vec<f64> = r.find(is::handler_start("Found")).iter().map(|e| e.t).collect();
    assert!(close(starts[1], 10.0) && close(starts[2], 10.0), "{starts:?}");
    assert!(flights[0].3 > 10.0, "the first flight was still running: {flights:?}");
    assert!(close(flights[1].2, flights[0].3), "the next starts when it ends: {flights:?}");
    assert!(close(flights[2].2, flights[1].3), "{flights:?}");
    // First come, first served: in the order the firings asked.
    let targets: Vec<&Shown> = flights.iter().map(|f| f.4.get("target").unwrap()).collect();
    assert_eq!(targets, [&at(0.0, 300.0), &at(300.0, 0.0), &at(0.0, -300.0)]);
}

#[test]
fn the_every_firing_fixture_takes_the_carrier_one_firing_at_a_time() {
    let mission = include_str!("fixtures/n303_every_firing.mission");
    let found = findings(mission);
    assert_eq!(lines(mission, &found, Code::CommandsQueue), [9], "{found:#?}");
    let r = fly(mission);
    let deliveries = activities(&r, "Deliver", "carrier");
    assert_eq!(deliveries.len(), r.find(is::signal("Found")).len(), "one per find");
    assert!(deliveries.len() >= 2, "{}", r.dump());
    one_at_a_time(&deliveries);
}

#[test]
fn the_flow_after_the_signal_goes_first_and_the_handler_waits_until_it_ends() {
    let mission = include_str!("fixtures/n303_after_signal.mission");
    let found = findings(mission);
    assert_eq!(lines(mission, &found, Code::CommandsQueue), [9], "{found:#?}");
    let r = fly(mission);
    let flights = activities(&r, "FlyTo", "scout1");
    assert_eq!(flights.len(), 2, "{}", r.dump());
    let (flow, handler) = (flights[0], flights[1]);
    assert_eq!(flow.4.get("target"), Some(&at(300.0, 0.0)), "the flow's FlyTo East goes first");
    let signal = r.t(is::signal("Ready"));
    assert!(close(flow.2, signal), "at once after the SIGNAL: {flow:?}");
    assert!(close(r.t(is::handler_start("Ready")), signal), "the handler starts");
    assert!(close(handler.2, flow.3), "and its FlyTo waits until the flow's ends: {flights:?}");
    one_at_a_time(&flights);
}

/// When the flow's statement does not follow the SIGNAL directly, whichever starts first
/// holds the drone: here the handler's, and the flow's waits until it ends.
#[test]
fn when_the_handler_starts_first_the_flow_waits_until_it_ends() {
    let mission = "MISSION AfterSignal:
    PARALLEL Start:
        SEQUENTIAL Launch:
            scout1 TakeOff
            SIGNAL Ready
            WAITFOR ELAPSED > 10s
            scout1 FlyTo WITH East
        ON Ready:
            scout1 FlyTo WITH North
    scout1 ReturnHome
";
    let found = findings(mission);
    assert_eq!(lines(mission, &found, Code::CommandsQueue), [9], "{found:#?}");
    let r = fly(mission);
    let flights = activities(&r, "FlyTo", "scout1");
    assert_eq!(flights[0].4.get("target"), Some(&at(0.0, 300.0)), "the handler's goes first");
    assert!(flights[0].3 > 10.0, "and still flies when the flow wants scout1: {flights:?}");
    assert!(close(flights[1].2, flights[0].3), "the flow's waits until it ends: {flights:?}");
}

const FIRES: &str = "MISSION Fires:
    PARALLEL Watch:
        SEQUENTIAL Reports:
            SIGNAL Fire_Spotted WITH North
            SIGNAL Fire_Spotted WITH East
        ON EVERY Fire_Spotted WITH where:
            carrier TakeOff WITH 20m
            carrier FlyToAndPatrol WITH where
            carrier ReturnHome
";

#[test]
fn another_firing_takes_the_drone_between_this_firings_statements() {
    let found = findings(FIRES);
    assert_eq!(lines(FIRES, &found, Code::CommandsMayCollide), [8, 9], "{found:#?}");
    assert!(lines(FIRES, &found, Code::CommandsQueue).is_empty(), "{found:#?}");
    assert!(found.iter().all(|d| d.help.as_deref().is_some_and(|h| h.contains("ONE AT A TIME"))));
    let r = fly(FIRES);
    // The second firing's TakeOff comes between the first's TakeOff and its patrol.
    let takeoffs = activities(&r, "TakeOff", "carrier");
    assert_eq!(takeoffs.len(), 2, "{}", r.dump());
    assert!(r.find(is::start_of("FlyToAndPatrol")).is_empty());
    assert_eq!(actor(&r.first(is::exception("CommandFailed")).event), Some("carrier"));
}

#[test]
fn one_at_a_time_firings_never_meet_and_nothing_is_reported() {
    let mission = FIRES.replace("WITH where:", "WITH where ONE AT A TIME:");
    assert!(findings(&mission).is_empty(), "{:#?}", findings(&mission));
    let r = fly(&mission);
    assert_eq!(r.outcome.status, aviary_engine::Status::Ok, "{}", r.dump());
    let mut all: Vec<(usize, usize, f64, f64, &Args)> = ["TakeOff", "FlyToAndPatrol", "ReturnHome"]
        .iter()
        .flat_map(|c| activities(&r, c, "carrier"))
        .collect();
    all.sort_by_key(|a| a.0);
    assert_eq!(all.len(), 6);
    one_at_a_time(&all);
    let order: Vec<&str> = all
        .iter()
        .map(|a| match &r.trace[a.0].event {
            Event::CapabilityStart { capability, .. } => &**capability,
            _ => unreachable!(),
        })
        .collect();
    assert_eq!(
        order,
        ["TakeOff", "FlyToAndPatrol", "ReturnHome", "TakeOff", "FlyToAndPatrol", "ReturnHome"]
    );
}
