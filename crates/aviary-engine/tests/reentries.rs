//! An exception handler is re-entered at most `RunOptions::max_handler_reentries` times
//! at one instant (docs/LANGUAGE.md, section 12): a handler whose body fails at once
//! would otherwise take its own exception again for ever, and the engine, never waiting,
//! would not even hear Ctrl-C. Past the limit the handler is passed over and the exception
//! goes on outward. Time passing between two rounds starts the count again.

use aviary_api::trace::Event;
use aviary_test_support::harness;
use aviary_test_support::trace::is;

use aviary_engine::{Record, RunOptions, Status};
use harness::{run_with, WORLD};

const PING: &str = "CAPABILITY Ping BY d:\n    PERFORM:\n        d.StartStreaming()\n        d.StopStreaming()\n\n";

fn limited(reentries: usize) -> RunOptions {
    RunOptions { max_handler_reentries: reentries, ..RunOptions::default() }
}

/// The exceptions of a run: (handler, skipped), in order.
fn exceptions(r: &harness::Run) -> Vec<(String, String)> {
    r.trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::Exception { handler, skipped, .. } => Some((
                handler.as_deref().unwrap_or("").to_string(),
                skipped.as_deref().unwrap_or("").to_string(),
            )),
            _ => None,
        })
        .collect()
}

#[test]
fn the_limit_is_how_many_times_a_handler_is_entered_again() {
    let mission = "MISSION M:\n    SEQUENTIAL S:\n        THROW EXCEPTION X\n        ON EXCEPTION X:\n            THROW EXCEPTION X\n";
    for limit in [0, 1, 5] {
        let r = run_with(mission, WORLD, &limited(limit));
        assert_eq!(r.outcome.status, Status::Failed);
        let all = exceptions(&r);
        assert_eq!(all.len(), limit + 2, "the first entry, {limit} more, and the one passed over");
        assert!(all[..=limit].iter().all(|(h, s)| h == "S/ON EXCEPTION X" && s.is_empty()));
        let why = format!(
            "S/ON EXCEPTION X, line 4, re-entered {limit} times at t = 0 s without time passing"
        );
        assert_eq!(all[limit + 1], (String::new(), why.clone()));
        assert_eq!(
            r.outcome.reason.as_deref(),
            Some(format!("unhandled exception X on the mission; its handler {why}, so it did not take it again").as_str())
        );
    }
}

#[test]
fn a_handler_that_catches_again_after_time_has_passed_is_not_cut_off() {
    // Each round hovers a second, then fails: the handler takes its own exception again
    // every second, far more often than the limit, and the mission ends when it stops.
    let mission = format!(
        "{PING}MISSION M:\n    SEQUENTIAL S:\n        c TakeOff\n        c Ping\n        ON EXCEPTION CommandFailed:\n            STARTIF ELAPSED < 20s:\n                c Hover WITH 1s\n                c Ping\n    a TakeOff\n"
    );
    let r = run_with(&mission, WORLD, &limited(2));
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let times: Vec<f64> = r
        .find(is::exception("CommandFailed"))
        .iter()
        .map(|e| {
            let Event::Exception { handled, skipped, .. } = &e.event else { unreachable!() };
            assert!(*handled);
            assert!(skipped.is_none());
            e.t
        })
        .collect();
    assert!(times.len() > 10, "{times:?}");
    assert!(times.windows(2).all(|w| w[1] >= w[0] + 0.99), "a second apart: {times:?}");
    assert_eq!(r.ends("TakeOff", "a")[0].status, Status::Ok, "and the mission goes on");
}

#[test]
fn a_handler_passed_over_leaves_the_exception_to_the_handlers_around_it() {
    let mission = format!(
        "{PING}MISSION M:\n    SEQUENTIAL Outer:\n        SEQUENTIAL Inner:\n            c Ping\n            ON EXCEPTION CommandFailed:\n                c Ping\n        b Hover WITH 1s\n        ON EXCEPTION CommandFailed:\n            a TakeOff\n    b TakeOff\n"
    );
    let r = run_with(&mission, WORLD, &limited(3));
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let all = exceptions(&r);
    assert_eq!(all.len(), 5);
    assert_eq!(
        all[4],
        (
            "Outer/ON EXCEPTION CommandFailed".to_string(),
            "Inner/ON EXCEPTION CommandFailed, line 10, re-entered 3 times at t = 0 s without time passing".to_string()
        )
    );
    assert!(matches!(
        r.first(is::block_end("Inner")).event,
        Event::BlockEnd { status: Status::Aborted, .. }
    ));
    assert_eq!(r.ends("TakeOff", "a")[0].status, Status::Ok, "the outer handler runs");
    assert!(
        r.index(is::end_of("TakeOff")) < r.index(is::start_of("Hover")),
        "in place of Inner, and Outer goes on with its next item"
    );
    assert_eq!(r.ends("TakeOff", "b")[0].status, Status::Ok, "and the mission goes on");
}

#[test]
fn handlers_that_throw_to_each_other_are_cut_off_at_the_first_past_the_limit() {
    let mission = "MISSION M:\n    SEQUENTIAL S:\n        THROW EXCEPTION X\n        ON EXCEPTION X:\n            THROW EXCEPTION Y\n        ON EXCEPTION Y:\n            THROW EXCEPTION X\n";
    let r = run_with(mission, WORLD, &limited(4));
    assert_eq!(r.outcome.status, Status::Failed);
    let all = exceptions(&r);
    // X, Y, X, Y, ...: X's handler is entered 5 times, Y's 5, and the sixth X is passed over.
    assert_eq!(all.len(), 11, "{}", r.dump());
    let reason = r.outcome.reason.unwrap_or_default();
    assert!(
        reason.ends_with("its handler S/ON EXCEPTION X, line 4, re-entered 4 times at t = 0 s without time passing, so it did not take it again"),
        "{reason}"
    );
}

#[test]
fn a_capabilitys_own_handler_is_bound_alike() {
    let mission = format!(
        "{PING}CAPABILITY Careful BY d:\n    PERFORM:\n        d Ping\n    EXCEPTIONS:\n        ON EXCEPTION CommandFailed:\n            d Ping\n\nMISSION M:\n    c Careful\n    ON EXCEPTION CommandFailed:\n        a TakeOff\n"
    );
    let r = run_with(&mission, WORLD, &limited(2));
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let all = exceptions(&r);
    assert_eq!(all.len(), 4, "{}", r.dump());
    assert_eq!(all[3].0, "M/ON EXCEPTION CommandFailed");
    assert_eq!(
        all[3].1,
        "Careful/ON EXCEPTION CommandFailed, line 10, re-entered 2 times at t = 0 s without time passing"
    );
    assert_eq!(r.ends("Careful", "c")[0].status, Status::Failed);
}

#[test]
fn exceptions_of_many_branches_at_one_instant_are_not_re_entries() {
    // Ten throws at once, each its own first entry of the handler: none is a re-entry.
    let branches: String =
        (0..10).map(|_| "        SEQUENTIAL:\n            THROW EXCEPTION X\n").collect();
    let mission =
        format!("MISSION M:\n    PARALLEL P:\n{branches}        ON EXCEPTION X:\n            SIGNAL Caught\n");
    let r = run_with(&mission, WORLD, &limited(1));
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    assert_eq!(r.find(is::signal("Caught")).len(), 10);
    assert!(exceptions(&r).iter().all(|(h, s)| h == "P/ON EXCEPTION X" && s.is_empty()));
}

/// With MAVLink drones the clock is the wall clock, which moves between any two readings:
/// there a round "at one instant" is one in which the engine did not wait.
#[test]
fn the_bound_holds_with_the_wall_clock() {
    let (done, outcome) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mission = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/rules/a_handler_re_entered_at_one_instant_is_passed_over.mission"
        ))
        .unwrap();
        let (mission, world) = harness::compile(&mission, WORLD);
        let runtime = tokio::runtime::Builder::new_current_thread().enable_time().build().unwrap();
        let (outcome, events) = runtime.block_on(async {
            let sim = aviary_sim::SimBackend::start(&world, aviary_sim::SimOptions::default());
            let mut events = 0usize;
            let mut sink = |_: &Record| events += 1;
            let outcome =
                aviary_engine::run(&mission, &*sim, &mut sink, &RunOptions::default()).await;
            sim.shutdown().await;
            (outcome, events)
        });
        let _ = done.send((outcome, events));
    });
    let (outcome, events) = outcome
        .recv_timeout(std::time::Duration::from_secs(60))
        .expect("the run ends: it does not loop at one instant");
    assert_eq!(outcome.status, Status::Failed);
    let reason = outcome.reason.unwrap_or_default();
    assert!(
        reason.contains(
            "its handler S/ON EXCEPTION CommandFailed, line 9, re-entered 100 times at t = "
        ),
        "{reason}"
    );
    assert!(events < 1000, "{events} events");
}

#[test]
fn a_body_that_fails_twice_at_once_is_bound_in_all_not_per_branch() {
    // `team FlyCircle` on the ground: a's and b's both fail at once, so each round starts
    // two more. Counted along each chain of rounds, that would be 2^100 of them.
    let mission = format!(
        "{PING}MISSION M:\n    SEQUENTIAL S:\n        c Ping\n        ON EXCEPTION CommandFailed:\n            team FlyCircle WITH center=North, radius=30m\n"
    );
    let r = harness::run(&mission);
    assert_eq!(r.outcome.status, Status::Failed);
    let handled =
        r.trace.iter().filter(|e| matches!(e.event, Event::Exception { handled: true, .. }));
    assert_eq!(handled.count(), 1 + aviary_engine::MAX_HANDLER_REENTRIES);
    let reason = r.outcome.reason.unwrap_or_default();
    assert!(reason.contains("re-entered 100 times at t = 0 s without time passing"), "{reason}");
}
