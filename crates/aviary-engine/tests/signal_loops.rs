//! A cycle of signals at one instant (docs/LANGUAGE.md, section 11): an `ON EVERY` whose
//! firing raises, at once, a signal that starts it again (itself, through another
//! handler, through an exception's handler) would go round for ever without time
//! passing, the trace growing without end and the engine, never waiting, deaf to
//! Ctrl-C. It is bound as exception handlers are (`RunOptions::max_handler_reentries`):
//! past the limit the mission fails with the reason, and the fleet goes home.
//!
//! Every run here is made on a thread of its own with a sink that gives up after
//! [`ENDLESS`] events, and waited for a bounded time: a loop that is not bound fails the
//! test instead of filling the memory.

use std::sync::mpsc;
use std::time::Duration;

use aviary_api::trace::{CallStatus, Event};
use aviary_api::Function;
use aviary_engine::{OperatorAction, Outcome, Record, RunOptions, Status, MAX_HANDLER_REENTRIES};
use aviary_test_support::harness::{self, WORLD};
use aviary_test_support::trace::Trace;

/// More events than any of these missions makes when it is bound: a run past it is
/// taken as endless.
const ENDLESS: usize = 200_000;

/// The mission of a rule: `tests/rules/NAME.mission`.
fn fixture(name: &str) -> String {
    let path = format!("{}/tests/rules/{name}.mission", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Runs `mission` in the harness's world with `options` on the simulated clock, or on the
/// wall clock with `wall` (a plain tokio runtime, where `aviary_clock` is real time); its
/// outcome and trace, or a panic if it does not end.
fn bounded(mission: &str, options: RunOptions, wall: bool) -> (Outcome, Vec<Record<'static>>) {
    let (mission, world) = harness::compile(mission, WORLD);
    let (done, ended) = mpsc::channel();
    std::thread::spawn(move || {
        let run = async {
            let sim = aviary_sim::SimBackend::start(&world, aviary_sim::SimOptions::default());
            let mut trace = Vec::new();
            let mut sink = |r: &Record| {
                assert!(trace.len() < ENDLESS, "more than {ENDLESS} events: the run does not end");
                trace.push(Trace::line(r));
            };
            let outcome = aviary_engine::run(&mission, &*sim, &mut sink, &options).await;
            sim.shutdown().await;
            (outcome, trace)
        };
        let run = if wall {
            tokio::runtime::Builder::new_current_thread()
                .enable_time()
                .build()
                .unwrap()
                .block_on(run)
        } else {
            harness::simulated_runtime().block_on(run)
        };
        let _ = done.send(run);
    });
    ended
        .recv_timeout(Duration::from_secs(120))
        .expect("the run ends (it does not loop at one instant)")
}

fn limited(reentries: usize) -> RunOptions {
    RunOptions { max_handler_reentries: reentries, ..RunOptions::default() }
}

/// How many times the handler at `path` started.
fn starts(trace: &[Record], path: &str) -> usize {
    trace
        .iter()
        .filter(|e| matches!(&e.event, Event::HandlerStart { handler, .. } if handler == path))
        .count()
}

/// Whether a `ReturnToLaunch` (by `actor`, or by any drone) ended ok.
fn brought_home(trace: &[Record], actor: Option<&str>) -> bool {
    trace.iter().any(|e| {
        matches!(&e.event, Event::ApiDone {
            function: Function::ReturnToLaunch, status: CallStatus::Ok, actor: a, ..
        } if actor.is_none_or(|actor| a == actor))
    })
}

/// The mission failed with `reason`, said in the trace's `mission_end` as well, and `a`,
/// in the air when the loop began, was brought home.
fn failed_and_home(outcome: &Outcome, trace: &[Record], reason: &str) {
    assert_eq!(outcome.status, Status::Failed);
    assert_eq!(outcome.reason.as_deref(), Some(reason));
    let end = trace.last().expect("a trace");
    let Event::MissionEnd { status, reason: said } = &end.event else { panic!("{end:?}") };
    assert_eq!((*status, said.as_deref()), (Status::Failed, Some(reason)));
    let home = brought_home(trace, Some("a"));
    assert!(home, "the drone in the air was brought home");
}

#[test]
fn an_on_every_that_raises_its_own_signal_at_once_ends_the_mission() {
    let mission = fixture("an_on_every_that_raises_its_own_signal_at_once_ends_the_mission");
    for limit in [0, 3, MAX_HANDLER_REENTRIES] {
        let (outcome, trace) = bounded(&mission, limited(limit), false);
        failed_and_home(
            &outcome,
            &trace,
            &format!("a cycle of signals at one instant: P/ON X, line 7, started again {limit} times at t = 4.35 s by what its own firings raised, without time passing"),
        );
        assert_eq!(starts(&trace, "P/ON X"), limit + 1, "the first firing and {limit} more");
    }
}

#[test]
fn handlers_that_raise_each_others_signal_at_once_end_the_mission() {
    let mission = fixture("handlers_that_raise_each_others_signal_at_once_end_the_mission");
    let (outcome, trace) = bounded(&mission, RunOptions::default(), false);
    // X, Y, X, Y, ...: X's handler is started again 100 times, and the next is refused.
    failed_and_home(
        &outcome,
        &trace,
        "a cycle of signals at one instant: P/ON X, line 6, started again 100 times at t = 4.35 s by what its own firings raised, without time passing",
    );
    assert_eq!(starts(&trace, "P/ON X"), 101);
    assert_eq!(starts(&trace, "P/ON Y"), 101);
}

#[test]
fn a_one_at_a_time_handler_that_raises_its_signal_twice_ends_the_mission() {
    let mission = fixture("a_one_at_a_time_handler_that_raises_its_signal_twice_ends_the_mission");
    let (outcome, trace) = bounded(&mission, RunOptions::default(), false);
    failed_and_home(
        &outcome,
        &trace,
        "a cycle of signals at one instant: P/ON X, line 6, started again 100 times at t = 4.35 s by what its own firings raised, without time passing",
    );
    // Every firing raises two: the count grows by two a firing, and nothing starts once
    // the mission has failed (the firings still waiting their turn are dropped).
    assert_eq!(starts(&trace, "P/ON X"), 51);
}

#[test]
fn a_signal_handler_and_an_exception_handler_in_a_cycle_end_the_mission() {
    let mission = fixture("a_signal_handler_and_an_exception_handler_in_a_cycle_end_the_mission");
    let (outcome, trace) = bounded(&mission, RunOptions::default(), false);
    failed_and_home(
        &outcome,
        &trace,
        "a cycle of signals at one instant: P/ON X, line 6, started again 100 times at t = 4.35 s by what its own firings raised, without time passing",
    );
    assert_eq!(starts(&trace, "P/ON X"), 101);
}

#[test]
fn firings_of_many_signals_at_one_instant_are_not_re_entries() {
    // 150 signals at once, each its own first firing, each raising Y once: no firing is
    // started by what a firing of the same handler raised.
    let signals: String = (0..150).map(|_| "        SIGNAL X\n").collect();
    let mission = format!(
        "MISSION M:\n    PARALLEL P:\n{signals}        ON EVERY X:\n            SIGNAL Y\n        ON EVERY Y:\n            SIGNAL Z\n"
    );
    let (outcome, trace) = bounded(&mission, limited(1), false);
    assert_eq!(outcome.status, Status::Ok, "{outcome:?}");
    assert_eq!(starts(&trace, "P/ON Y"), 150);
}

#[test]
fn a_handler_that_raises_its_signal_again_after_time_has_passed_is_not_cut_off() {
    // Each firing waits a second, then raises X again: far more firings than the limit,
    // each at an instant of its own.
    let mission = "MISSION M:\n    PARALLEL P:\n        SIGNAL X\n        ON EVERY X:\n            a Hover WITH 1s\n            STARTIF ELAPSED < 20s:\n                SIGNAL X\n";
    let (outcome, trace) = bounded(mission, limited(2), false);
    assert_eq!(outcome.status, Status::Ok, "{outcome:?}");
    assert!(starts(&trace, "P/ON X") > 10);
}

/// With MAVLink drones the clock is the wall clock: there "at one instant" is without the
/// engine waiting in between.
#[test]
fn the_bound_holds_with_the_wall_clock() {
    let mission = fixture("an_on_every_that_raises_its_own_signal_at_once_ends_the_mission");
    let (outcome, trace) = bounded(&mission, RunOptions::default(), true);
    assert_eq!(outcome.status, Status::Failed);
    let reason = outcome.reason.unwrap_or_default();
    assert!(
        reason.starts_with(
            "a cycle of signals at one instant: P/ON X, line 7, started again 100 times at t = "
        ),
        "{reason}"
    );
    assert_eq!(starts(&trace, "P/ON X"), 101);
}

/// A mission busy at one instant for a long time (here 2,000 cycles, each cut off after
/// 100 rounds: 200,000 firings without the engine waiting once) still hears a stop from
/// outside (`Controller::interrupt`, as Ctrl-C or SIGTERM sends it) at once, and brings
/// the fleet home.
#[test]
fn an_interrupt_is_heard_by_a_mission_that_never_waits() {
    let signals: String = (0..2_000).map(|_| "        SIGNAL X\n").collect();
    let mission = format!(
        "MISSION Busy:\n    a TakeOff\n    PARALLEL P:\n{signals}        ON EVERY X:\n            SIGNAL X\n"
    );
    let (mission, world) = harness::compile(&mission, WORLD);
    let (outcome, trace) = harness::simulated_runtime().block_on(async {
        let sim = aviary_sim::SimBackend::start(&world, aviary_sim::SimOptions::default());
        let (controller, controls) = aviary_engine::Controller::new();
        let mut trace = Vec::new();
        let mut sink = |r: &Record| {
            // The stop comes in the middle of the instant, as a signal from the OS would.
            if trace.len() == 1_000 {
                controller.interrupt("interrupted by SIGTERM".into());
            }
            assert!(trace.len() < ENDLESS, "more than {ENDLESS} events: the stop was not heard");
            trace.push(Trace::line(r));
        };
        let outcome = aviary_engine::run_controlled(
            &mission,
            &*sim,
            &mut sink,
            &RunOptions::default(),
            controls,
        )
        .await;
        sim.shutdown().await;
        (outcome, trace)
    });
    assert_eq!(outcome.status, Status::Aborted);
    assert_eq!(outcome.reason.as_deref(), Some("interrupted by SIGTERM"));
    assert!(trace.len() < 1_100, "heard at once: {} events", trace.len());
    let abort = trace
        .iter()
        .filter(|e| matches!(e.event, Event::Operator { action: OperatorAction::Abort, .. }));
    assert_eq!(abort.count(), 1, "one abort, written as the operator's");
    let home = brought_home(&trace, None);
    assert!(home, "the drone in the air was brought home");
}
