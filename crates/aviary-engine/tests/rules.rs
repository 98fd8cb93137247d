//! One trace-based test per rule of the language's semantics (docs/LANGUAGE.md), asserting
//! order and timing, on the built-in simulator with a simulated clock (so every time below is
//! simulated seconds). The missions are files, `tests/rules/*.mission`, and each one's
//! whole trace is a snapshot (`tests/snapshots/rules__traces@*.snap`), taken with a
//! handler re-entered at most [`SNAPSHOT_REENTRIES`] times at one instant.

use aviary_api::trace::{CallStatus, Event, EventKind, Shown};
use aviary_api::Function;
use aviary_engine::{RunOptions, Status, MAX_HANDLER_REENTRIES};
use aviary_test_support::harness;
use aviary_test_support::trace::{actor, is};
use harness::run;

/// `RunOptions::max_handler_reentries` in the snapshots: a handler cut off by the bound
/// shows whole in a few lines. No other rule comes near it.
const SNAPSHOT_REENTRIES: usize = 3;

/// The mission of a rule: `tests/rules/NAME.mission`.
fn fixture(name: &str) -> String {
    let path = format!("{}/tests/rules/{name}.mission", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// The world a rule flies in: `tests/rules/NAME.world.toml` beside its mission when the
/// rule needs one of its own (a drone's battery, a fault), else the harness's.
fn world_of(mission: &std::path::Path) -> String {
    let own = mission.with_extension("world.toml");
    match std::fs::read_to_string(&own) {
        Ok(world) => world,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => harness::WORLD.to_string(),
        Err(e) => panic!("{}: {e}", own.display()),
    }
}

/// A rule's mission flown in its world, as the snapshots fly it.
fn run_rule(name: &str) -> harness::Run {
    let path = format!("{}/tests/rules/{name}.mission", env!("CARGO_MANIFEST_DIR"));
    harness::run_in(&fixture(name), &world_of(std::path::Path::new(&path)))
}

/// Every rule's whole trace, one event a line: the order and the time of every event, so
/// that a change in what a rule does shows, event by event, in review. The tests below
/// say which of those facts are the rule.
#[test]
fn traces() {
    insta::glob!("rules/*.mission", |path| {
        let mission = std::fs::read_to_string(path).expect("read the fixture");
        let options =
            RunOptions { max_handler_reentries: SNAPSHOT_REENTRIES, ..RunOptions::default() };
        let r = harness::run_with(&mission, &world_of(path), &options);
        insta::assert_snapshot!(format!("outcome: {:?}\n{}", r.outcome.status, r.dump()));
    });
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 0.11
}

#[test]
fn sequential_runs_children_one_after_another() {
    let r = run(&fixture("sequential_runs_children_one_after_another"));
    assert_eq!(r.outcome.status, Status::Ok);
    let a_end = r.ends("Hover", "a")[0].t;
    let b_start = r.t(is::start_by("b"));
    assert!(close(a_end, 5.0), "{a_end}");
    assert!(b_start >= a_end && close(b_start, 5.0), "b starts when a has finished: {b_start}");
    assert!(close(r.t(is::block_end("S")), 8.0));
}

#[test]
fn parallel_starts_all_at_once_and_ends_with_the_last() {
    let r = run(&fixture("parallel_starts_all_at_once_and_ends_with_the_last"));
    assert_eq!(r.t(is::start_by("a")), 0.0);
    assert_eq!(r.t(is::start_by("b")), 0.0);
    assert!(close(r.t(is::block_end("P")), 5.0));
}

#[test]
fn on_fires_once_and_on_every_each_time() {
    let r = run(&fixture("on_fires_once_and_on_every_each_time"));
    assert_eq!(r.find(is::signal("Ping")).len(), 3);
    assert_eq!(r.find(is::start_by("b")).len(), 1, "ON takes the first signal only");
    let c: Vec<f64> = r.find(is::start_by("c")).iter().map(|e| e.t).collect();
    assert_eq!(c.len(), 3, "ON EVERY takes each");
    assert!(close(c[0], 0.0) && close(c[1], 1.0) && close(c[2], 2.0), "{c:?}");
    assert!(close(r.t(is::block_end("P")), 3.0), "the block waits for its started handlers");
}

#[test]
fn a_burst_of_signals_starts_its_handlers_one_after_another_in_signal_order() {
    // Twelve signals in one instant; each handler takes off its drone after a wait
    // (most of them wait: tasks pile up) and the first one's signal wakes a waiting handler.
    let raise: String = (1..=12).map(|i| format!("        SIGNAL Ping WITH {i}s\n")).collect();
    let mission = format!(
        "MISSION M:\n    PARALLEL P:\n{raise}        WAITFOR RECEIVED(Pong)\n    ON EVERY Ping WITH i:\n        STARTIF i = 1s:\n            SIGNAL Pong\n        WAITFOR ELAPSED >= i\n    ON Pong:\n        WAITFOR RECEIVED(Pong)\n"
    );
    let r = run(&mission);
    let starts: Vec<(usize, f64)> = r
        .trace
        .iter()
        .enumerate()
        .filter(|(_, e)| matches!(&e.event, Event::HandlerStart { signal, .. } if signal == "Ping"))
        .map(|(at, e)| (at, e.t))
        .collect();
    let signals: Vec<usize> = r
        .trace
        .iter()
        .enumerate()
        .filter(|(_, e)| is::signal("Ping")(&e.event))
        .map(|(at, _)| at)
        .collect();
    assert_eq!(starts.len(), 12);
    assert!(starts.iter().all(|(_, t)| *t == 0.0), "all in the instant of their signals");
    assert!(
        signals.iter().max() < starts.iter().map(|(at, _)| at).min(),
        "raised in one poll of the block, then started"
    );
    let ends: Vec<f64> = r
        .trace
        .iter()
        .filter(|e| matches!(&e.event, Event::HandlerEnd { signal, .. } if signal == "Ping"))
        .map(|e| e.t)
        .collect();
    assert_eq!(ends.len(), 12);
    assert!(ends.windows(2).all(|w| w[0] <= w[1]), "in signal order: {ends:?}");
    assert!(close(ends[11], 12.0), "each waits its own time, concurrently: {ends:?}");
    assert_eq!(r.find(is::handler_start("Pong")).len(), 1);
    assert_eq!(r.dump(), run(&mission).dump(), "the same interleaving every time");
}

#[test]
fn sequential_on_waits_for_the_signalling_block_and_parallel_on_does_not() {
    let r = run(&fixture("sequential_on_waits_for_the_signalling_block_and_parallel_on_does_not"));
    let signaller_end = r.t(is::block_end("Signaller"));
    assert!(close(signaller_end, 4.0));
    assert_eq!(r.t(is::start_by("c")), 0.0, "PARALLEL ON starts at once");
    let b = r.t(is::start_by("b"));
    assert!(b >= signaller_end, "SEQUENTIAL ON starts when the signalling block has ended: {b}");
    assert!(r.index(is::block_end("Signaller")) < r.index(is::start_by("b")), "in causal order");
}

#[test]
fn a_handler_outside_the_signals_subtree_never_fires() {
    let r = run(&fixture("a_handler_outside_the_signals_subtree_never_fires"));
    assert_eq!(r.find(is::signal("Ping")).len(), 1, "the signal is recorded");
    assert!(r.find(is::start_by("b")).is_empty(), "but B does not hear it");
    assert!(r.find(is::handler_start("Ping")).is_empty());
}

#[test]
fn by_filters_on_the_signalling_actor() {
    let r = run(&fixture("by_filters_on_the_signalling_actor"));
    let pings = r.find(is::signal("Ping"));
    assert_eq!(pings.len(), 2);
    assert_eq!(r.find(is::handler_start("Ping")).len(), 1);
    assert_eq!(actor(&r.first(is::handler_start("Ping")).event), Some("b"));
    assert_eq!(r.find(is::start_by("c")).len(), 1);
}

#[test]
fn an_exception_aborts_the_throwing_actor_and_no_other() {
    let r = run(&fixture("an_exception_aborts_the_throwing_actor_and_no_other"));
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let e = r.first(is::exception("Broken"));
    let Event::Exception { handled, actor, handler, .. } = &e.event else { unreachable!() };
    assert!(*handled);
    assert_eq!(actor.as_deref(), Some("a"));
    assert_eq!(handler.as_deref(), Some("P/ON EXCEPTION Broken"));
    assert_eq!(r.ends("Boom", "a")[0].status, Status::Failed);
    assert!(close(r.ends("Boom", "a")[0].t, 1.0), "aborted when it threw");
    assert!(r.ends("Hover", "a").is_empty(), "the rest of a's sequential chain is aborted");
    let b: Vec<Status> = r.ends("Hover", "b").iter().map(|e| e.status).collect();
    assert_eq!(b, [Status::Ok, Status::Ok], "b goes on");
    assert!(close(r.t(is::start_by("c")), 1.0), "the handler starts at once");
}

#[test]
fn a_capability_handles_its_own_exceptions_first() {
    let r = run(&fixture("a_capability_handles_its_own_exceptions_first"));
    let Event::Exception { handler, .. } = &r.first(is::exception("Broken")).event else {
        unreachable!()
    };
    assert_eq!(handler.as_deref(), Some("Careful/ON EXCEPTION Broken"));
    assert!(r.find(is::start_by("c")).is_empty(), "the outer handler is not needed");
    let careful = r.ends("Careful", "a")[0];
    assert_eq!(careful.status, Status::Ok);
    assert!(close(careful.t, 3.0), "its handler took the place of the rest: 1 s + 2 s");
    assert!(close(r.t(is::start_by("b")), 3.0));
}

#[test]
fn two_motion_capabilities_on_one_drone_queue() {
    let r = run(&fixture("two_motion_capabilities_on_one_drone_queue"));
    let starts: Vec<f64> = r.find(is::start_by("a")).iter().map(|e| e.t).collect();
    let ends: Vec<f64> = r.ends("Hover", "a").iter().map(|e| e.t).collect();
    assert_eq!(starts[0], 0.0);
    assert!(close(starts[1], 3.0), "the second waits for the motion resource: {starts:?}");
    assert!(close(ends[1], 5.0));
    assert_eq!(r.t(is::start_by("b")), 0.0, "another drone does not wait");
}

#[test]
fn waitfor_startif_and_dowhile() {
    let r = run(&fixture("waitfor_startif_and_dowhile"));
    assert!(close(r.t(is::start_by("a")), 2.0), "WAITFOR ends when Go is raised");
    assert_eq!(r.find(is::start_by("b")).len(), 1, "STARTIF with a false condition skips its body");
    let rounds = r.find(is::start_by("c")).len();
    assert_eq!(rounds, 3, "DOWHILE checks before each round: 2 s, 3 s, 4 s, then stops at 5 s");
}

#[test]
fn groups_and_for_instances() {
    let r = run(&fixture("groups_and_for_instances"));
    assert_eq!(r.t(is::start_by("a")), 0.0);
    assert!(close(r.t(is::start_by("b")), 1.0), "SEQUENTIAL FOR runs instances one after another");
    let second: Vec<f64> = r
        .trace
        .iter()
        .filter(|e| {
            matches!(&e.event, Event::CapabilityStart { args, .. }
                if args.get("duration") == Some(&Shown::Number(2.0)))
        })
        .map(|e| e.t)
        .collect();
    assert_eq!(second.len(), 2, "a group as actor means each member");
    assert!(close(second[0], 2.0) && close(second[1], 2.0), "in parallel: {second:?}");
}

#[test]
fn an_unhandled_exception_fails_the_mission_and_sends_the_fleet_home() {
    let r = run(&fixture("an_unhandled_exception_fails_the_mission_and_sends_the_fleet_home"));
    assert_eq!(r.outcome.status, Status::Failed);
    assert!(r.outcome.reason.as_deref().unwrap_or("").contains("Broken"), "{:?}", r.outcome.reason);
    assert!(matches!(
        r.first(is::exception("Broken")).event,
        Event::Exception { handled: false, .. }
    ));
    assert!(r.find(is::start_by("b")).is_empty());
    let rtl = r.trace.iter().position(|e| {
        matches!(&e.event, Event::ApiCall { function: Function::ReturnToLaunch, actor, .. }
            if actor == "a")
    });
    assert!(rtl.is_some(), "the drone in the air is sent home");
    let end = r.trace.last().unwrap();
    assert!(matches!(end.event, Event::MissionEnd { status: Status::Failed, .. }), "{end:?}");
}

#[test]
fn leashes_pause_resume_and_abort_an_activity() {
    let r = run(&fixture("leashes_pause_resume_and_abort_an_activity"));
    let actions: Vec<&str> = r
        .trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::Leash { action, .. } => Some(&**action),
            _ => None,
        })
        .collect();
    assert_eq!(
        actions,
        ["PAUSE", "RESUME", "ABORT", "ABORT"],
        "every leash is recorded, even one on an ended activity"
    );
    let fly = r.ends("FlyTo", "a")[0];
    assert_eq!(fly.status, Status::Aborted);
    assert!(close(fly.t, 25.0));
    assert_eq!(r.outcome.status, Status::Ok, "an aborted activity does not change the outcome");
}

#[test]
fn the_same_mission_gives_the_same_trace() {
    let mission = "MISSION M:\n    PARALLEL P:\n        a FlyTo WITH Field\n        SEQUENTIAL:\n            b TakeOff\n            b FlyCircle WITH center=North, radius=30m\n        SEQUENTIAL:\n            c TakeOff\n            SIGNAL Up\n        ON Up:\n            c FlyTo WITH Far\n";
    let (first, second) = (run(mission), run(mission));
    assert_eq!(first.outcome.status, Status::Ok, "{}", first.dump());
    assert_eq!(first.trace, second.trace);
    assert!(first.trace.len() > 20);
}

#[test]
fn a_failed_command_is_an_exception_of_its_actor() {
    let r = run(&fixture("a_failed_command_is_an_exception_of_its_actor"));
    let e = r.first(is::exception("CommandFailed"));
    let Event::Exception { actor, args, .. } = &e.event else { unreachable!() };
    assert_eq!(actor.as_deref(), Some("b"));
    assert_eq!(args[0].as_str(), Some("b is on the ground: take off first"));
    assert_eq!(r.ends("FlyCircle", "b")[0].status, Status::Failed);
    assert!(r.find(is::start_by("c")).is_empty(), "nothing starts after the failure");
    assert!(r.find(is::signal("Up")).is_empty());
    assert_eq!(r.outcome.status, Status::Failed);
}

#[test]
fn several_actors_bind_in_order_and_one_actor_capabilities_run_once_each() {
    let r = run(&fixture("several_actors_bind_in_order_and_one_actor_capabilities_run_once_each"));
    let pair = r.first(is::start_of("Pair"));
    assert_eq!(actor(&pair.event), Some("a b"));
    let hovers: Vec<(String, f64)> = r
        .trace
        .iter()
        .filter(|e| is::call(Function::Hover)(&e.event))
        .map(|e| (actor(&e.event).unwrap().to_string(), e.t))
        .collect();
    assert_eq!(hovers[0].0, "a", "lead is a");
    assert_eq!(hovers[1].0, "b", "wing is b");
    assert!(close(hovers[1].1, 2.0));
    // Hover has one actor: `a c Hover` runs it once for each, in parallel.
    let last: Vec<f64> =
        r.trace.iter().filter(|e| is::start_of("Hover")(&e.event)).map(|e| e.t).collect();
    assert_eq!(last.len(), 2);
    assert!(close(last[0], 3.0) && last[0] == last[1], "{last:?}");
}

#[test]
fn a_drone_fault_reaches_the_capability_that_was_flying_it() {
    let world = format!(
        "{}\n[[faults]]\ndrone = \"a\"\nat = 5.0\nkind = \"battery_critical\"\n",
        harness::WORLD
    );
    let r = harness::run_in(
        "CAPABILITY Deliver BY d:\n    PERFORM:\n        d TakeOff WITH 20m\n        d.FlyToPosition(Far)\n    EXCEPTIONS:\n        ON EXCEPTION BatteryCritical:\n            d.ReturnToLaunch()\n\nMISSION M:\n    PARALLEL:\n        a Deliver\n        b Hover WITH 10s\n",
        &world,
    );
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let e = r.first(is::exception("BatteryCritical"));
    let Event::Exception { actor, handled, handler, .. } = &e.event else { unreachable!() };
    assert_eq!((actor.as_deref(), *handled), (Some("a"), true));
    assert_eq!(handler.as_deref(), Some("Deliver/ON EXCEPTION BatteryCritical"));
    assert!(close(e.t, 5.0));
    let rtl = r
        .trace
        .iter()
        .find(|e| {
            matches!(&e.event, Event::ApiCall { function: Function::ReturnToLaunch, actor, .. }
                if actor == "a")
        })
        .unwrap();
    assert!(close(rtl.t, 5.0), "the handler starts at once");
    assert_eq!(r.find(is::exception("BatteryCritical")).len(), 1, "one fault, one exception");
    assert_eq!(r.ends("Hover", "b")[0].status, Status::Ok, "the other drone carries on");
}

#[test]
fn for_aliases_read_attributes_and_telemetry() {
    let world = harness::WORLD
        .replace("[drones.b]\n", "[drones.b]\nrole = \"scout\"\n")
        .replace("[drones.a]\n", "[drones.a]\nrole = \"carrier\"\n");
    let r = harness::run_in(
        "MISSION M:\n    PARALLEL FOR team AS d:\n        IF d.role = \"scout\" AND d.state = Landed:\n            d Hover WITH 1s\n        ELSE:\n            d Hover WITH 2s\n",
        &world,
    );
    let durations: Vec<(String, f64)> = r
        .trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::CapabilityStart { actor, args, .. } => {
                Some((actor.to_string(), args.get("duration").unwrap().as_number().unwrap()))
            }
            _ => None,
        })
        .collect();
    assert_eq!(durations, [("a".to_string(), 2.0), ("b".to_string(), 1.0)]);
}

/// What a drone does not have (an attribute the world gives another drone only) reads no
/// value: it equals nothing, `FALSE` included, differs from everything, is not true, and
/// a signal that carries it shows `null` (docs/LANGUAGE.md, "No value").
#[test]
fn an_attribute_a_drone_does_not_have_reads_no_value() {
    let world = harness::WORLD.replace("[drones.a]\n", "[drones.a]\narmed = true\n");
    let r = harness::run_in(
        "MISSION M:\n    PARALLEL FOR team AS d:\n        IF d.armed = FALSE:\n            SIGNAL Equal_False WITH d\n        IF d.armed != TRUE:\n            SIGNAL Not_True WITH d\n        IF d.armed:\n            SIGNAL Armed WITH d\n        IF NOT d.armed:\n            SIGNAL Not_Armed WITH d\n        SIGNAL Read WITH d.armed\n",
        &world,
    );
    assert_eq!(r.outcome.status, Status::Ok, "{:?}", r.outcome.reason);
    let raised = |name: &str| -> Vec<String> {
        r.find(is::signal(name))
            .iter()
            .filter_map(|e| match &e.event {
                Event::Signal { args, .. } => {
                    args.first().and_then(Shown::as_str).map(str::to_string)
                }
                _ => None,
            })
            .collect()
    };
    assert_eq!(raised("Equal_False"), Vec::<String>::new(), "no value is not FALSE");
    assert_eq!(raised("Not_True"), ["b"], "no value differs from TRUE");
    assert_eq!(raised("Armed"), ["a"]);
    assert_eq!(raised("Not_Armed"), ["b"], "no value is not true");
    let read: Vec<Shown> = r
        .find(is::signal("Read"))
        .iter()
        .filter_map(|e| match &e.event {
            Event::Signal { args, .. } => args.first().cloned(),
            _ => None,
        })
        .collect();
    assert_eq!(read, [Shown::Bool(true), Shown::Null]);
}

/// Branches of a `PARALLEL` block that wake at one instant go on in the order they are
/// written, and so raise their signals in that order: for a small block (polled in index
/// order) and a large one (polled as woken: they were woken in that order). The engine
/// defines this order (`join.rs`), not a size private to futures-util.
#[test]
fn parallel_branches_woken_at_one_instant_go_on_in_written_order() {
    for n in [3, 30, 31, 80] {
        let mut mission = String::from("MISSION M:\n    PARALLEL:\n");
        for i in 0..n {
            mission += &format!(
                "        SEQUENTIAL:\n            WAITFOR ELAPSED >= 1s\n            SIGNAL S{i}\n"
            );
        }
        let r = run(&mission);
        assert_eq!(r.outcome.status, Status::Ok);
        let raised: Vec<String> = r
            .trace
            .iter()
            .filter_map(|e| match &e.event {
                Event::Signal { name, .. } => Some(name.to_string()),
                _ => None,
            })
            .collect();
        let written: Vec<String> = (0..n).map(|i| format!("S{i}")).collect();
        assert_eq!(raised, written, "{n} branches");
        assert!(r
            .trace
            .iter()
            .filter(|e| matches!(e.event, Event::Signal { .. }))
            .all(|e| close(e.t, 1.0)));
    }
}

/// A branch that another's `SIGNAL` wakes goes on at the signal, before the branches the
/// clock woke at that instant and written after the signal's: with 30 branches, and with
/// 31, past the size at which the engine joins branches another way (docs/LANGUAGE.md,
/// section 4, "Order at one instant").
#[test]
fn a_branch_a_signal_wakes_goes_on_at_the_signal_whatever_the_number_of_branches() {
    for n in [30, 31] {
        let mut mission = String::from(
            "MISSION M:\n    PARALLEL:\n        SEQUENTIAL:\n            WAITFOR ELAPSED >= 1s\n            SIGNAL Go\n        SEQUENTIAL:\n            WAITFOR RECEIVED(Go)\n            SIGNAL First\n",
        );
        for i in 2..n {
            mission += &format!(
                "        SEQUENTIAL:\n            WAITFOR ELAPSED >= 1s\n            SIGNAL S{i}\n"
            );
        }
        let r = run(&mission);
        assert_eq!(r.outcome.status, Status::Ok);
        let raised: Vec<String> = r
            .trace
            .iter()
            .filter_map(|e| match &e.event {
                Event::Signal { name, .. } => Some(name.to_string()),
                _ => None,
            })
            .collect();
        let others = (2..n).map(|i| format!("S{i}"));
        let expected: Vec<String> =
            ["Go".to_string(), "First".to_string()].into_iter().chain(others).collect();
        assert_eq!(raised, expected, "{n} branches");
        assert!(r
            .trace
            .iter()
            .filter(|e| matches!(e.event, Event::Signal { .. }))
            .all(|e| close(e.t, 1.0)));
    }
}

#[test]
fn a_handler_re_entered_at_one_instant_is_passed_over() {
    // `c` has no camera: `c Ping` fails as it starts, in the handler's body as in the
    // block's, and the handler takes its own exception again at the same instant.
    let r = run(&fixture("a_handler_re_entered_at_one_instant_is_passed_over"));
    assert_eq!(r.outcome.status, Status::Failed, "the run ends, failed");
    let exceptions = r.find(is::exception("CommandFailed"));
    let handled = exceptions
        .iter()
        .filter(|e| matches!(e.event, Event::Exception { handled: true, .. }))
        .count();
    assert_eq!(handled, 1 + MAX_HANDLER_REENTRIES, "entered once, then re-entered to the limit");
    let last = exceptions.last().unwrap();
    let Event::Exception { handled: last_handled, skipped, .. } = &last.event else {
        unreachable!()
    };
    assert!(!last_handled, "past the limit nothing else takes it");
    let why = "S/ON EXCEPTION CommandFailed, line 9, re-entered 100 times at t = 0 s without time passing";
    assert_eq!(skipped.as_deref(), Some(why));
    assert!(exceptions[..handled]
        .iter()
        .all(|e| matches!(e.event, Event::Exception { skipped: None, .. })));
    let reason = r.outcome.reason.as_deref().unwrap_or("");
    assert_eq!(
        reason,
        format!("unhandled exception CommandFailed on c: c has no camera; its handler {why}, so it did not take it again")
    );
    assert!(r.find(is::start_by("a")).is_empty(), "nothing new starts");
    assert!(r.trace.iter().all(|e| e.t == 0.0), "all of it at the one instant");
    assert!(matches!(r.trace.last().unwrap().event, Event::MissionEnd { .. }));
}

#[test]
fn a_drones_signals_are_heard_where_its_work_is() {
    let r = run_rule("a_drones_signals_are_heard_where_its_work_is");
    assert_eq!(r.outcome.status, Status::Ok);
    let low = r.index(|e| {
        matches!(e, Event::Signal { name, actor: Some(a), .. } if name == "BatteryLow" && a == "a")
    });
    let inner = r.index(handler_start("Patrol/ON BatteryLow"));
    let outer = r.index(handler_start("P/ON BatteryLow"));
    let t = r.trace[low].t;
    // While the PERFORM itself flies its Orbit: the call is in flight then.
    let orbit = r.first(is::call(Function::Orbit)).t;
    let orbit_done = r.first(is::done(Function::Orbit));
    assert!(orbit < t && t <= orbit_done.t, "{t}");
    assert!(
        matches!(orbit_done.event, Event::ApiDone { status: CallStatus::Aborted, .. }),
        "the outer handler's leash stopped it"
    );
    assert!(low < inner && inner < outer, "the PERFORM's handler first, then outward");
    for i in [inner, outer] {
        assert_eq!(r.trace[i].t, t, "at the signal's instant");
    }
    assert!(r.find(is::signal("Tired")).len() == 1);
    assert!(r.find(is::signal("Never")).is_empty(), "b's block does not hold a's work");
}

#[test]
fn a_drones_signal_while_its_perform_waits_is_heard_there() {
    let r = run_rule("a_drones_signal_while_its_perform_waits_is_heard_there");
    assert_eq!(r.outcome.status, Status::Ok);
    let t = r.t(is::signal("BatteryLow"));
    let took_off = r.trace.iter().find(|e| is::done(Function::TakeOff)(&e.event));
    let took_off = took_off.expect("took off").t;
    assert!(took_off < t, "no call in flight: the PERFORM waits");
    assert_eq!(r.t(handler_start("Stay/ON BatteryLow")), t);
    assert_eq!(r.t(is::call(Function::ReturnToLaunch)), t, "the wait ends at once");
}

#[test]
fn connection_restored_is_heard_in_the_perform_that_caught_the_loss() {
    let r = run_rule("connection_restored_is_heard_in_the_perform_that_caught_the_loss");
    assert_eq!(r.outcome.status, Status::Ok);
    let lost = r.first(is::exception("ConnectionLost"));
    let Event::Exception { handler, .. } = &lost.event else { unreachable!() };
    assert_eq!(handler.as_deref(), Some("Watch/ON EXCEPTION ConnectionLost"));
    assert!(close(lost.t, 30.0));
    let back = r.t(is::signal("ConnectionRestored"));
    assert!(close(back, 35.0), "{back}");
    assert_eq!(r.t(handler_start("Watch/ON ConnectionRestored")), back);
    let watch = r.ends("Watch", "a")[0];
    assert_eq!(watch.status, Status::Ok);
    assert_eq!(watch.t, back, "the caught loss's wait ends then");
}

/// A rule's run with telemetry every 0.1 s, to follow where the drone is.
fn run_rule_watched(mission: &str) -> harness::Run {
    let options = RunOptions { telemetry_hz: Some(10.0), ..RunOptions::default() };
    harness::run_with(mission, harness::WORLD, &options)
}

fn apart(p: [f64; 3], q: [f64; 3]) -> f64 {
    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
}

/// The times of the calls of `function` by `a`: (made, done, status).
fn calls_of(r: &harness::Run, function: Function) -> Vec<(f64, f64, CallStatus)> {
    let made = r.find(is::call(function));
    let done = r.find(is::done(function));
    made.into_iter()
        .zip(done)
        .map(|(m, d)| {
            let Event::ApiDone { status, .. } = d.event else { unreachable!() };
            (m.t, d.t, status)
        })
        .collect()
}

/// The `handler_start` of the handler at `path`.
fn handler_start(path: &str) -> impl Fn(&Event) -> bool + '_ {
    move |e| matches!(e, Event::HandlerStart { handler, .. } if handler == path)
}

#[test]
fn a_leash_section_holds_the_body_while_it_runs() {
    let mission = fixture("a_leash_section_holds_the_body_while_it_runs");
    let r = run_rule_watched(&mission);
    assert_eq!(r.outcome.status, Status::Ok);
    assert!(r.find(is::exception("CommandFailed")).is_empty(), "the section may fly");
    let leash = r.t(|e| matches!(e, Event::Leash { action, .. } if action == "Check"));
    let fly = calls_of(&r, Function::FlyToPosition);
    let hover = calls_of(&r, Function::Hover);
    assert_eq!(fly.len(), 1);
    assert_eq!((fly[0].0, fly[0].2), (leash, CallStatus::Ok), "the section flies at once");
    let section_end = hover[0].1;
    let orbit = &calls_of(&r, Function::Orbit)[0];
    assert_eq!(orbit.2, CallStatus::Ok);
    assert!(orbit.0 < leash && orbit.1 > section_end, "the body's orbit spans the section");

    // Held where the leash came: the drone leaves the circle for the spot and is back at
    // that point after the section, then goes on along the circle to the orbit's end.
    let track = r.positions("a");
    let at = |t: f64| track.iter().find(|(s, _)| *s >= t - 1e-9).expect("a point").1;
    let held = at(leash);
    let on_circle = |p: [f64; 3]| ((p[0]).hypot(p[1] - 100.0) - 50.0).abs() < 0.5;
    assert!(track.iter().any(|(t, p)| *t > leash && *t < section_end && p[0].hypot(p[1]) < 0.01));
    let back = track
        .iter()
        .find(|(t, p)| *t >= section_end && apart(*p, held) < 0.5)
        .expect("back where the body was held")
        .0;
    assert!(
        track.iter().filter(|(t, _)| *t > back + 0.5 && *t < orbit.1).all(|(_, p)| on_circle(*p)),
        "then along the circle again"
    );

    // The orbit took longer by the time away from it (the section and the way back), and
    // a few seconds more to stop and to speed up again on the arc: none of it was flown
    // twice, none skipped.
    let alone = run_rule_watched(&mission.replace("            Patrol-P1 Check\n", ""));
    let orbit_alone = &calls_of(&alone, Function::Orbit)[0];
    let longer = (orbit.1 - orbit.0) - (orbit_alone.1 - orbit_alone.0);
    let away = back - leash;
    assert!(away <= longer && longer < away + 4.0, "{longer} s longer, {away} s away");
}

#[test]
fn a_pause_during_a_section_holds_it_too_and_a_second_section_waits_its_turn() {
    let name = "a_pause_during_a_section_holds_it_too_and_a_second_section_waits_its_turn";
    let r = run_rule_watched(&fixture(name));
    assert_eq!(r.outcome.status, Status::Ok);
    let leashes: Vec<f64> =
        r.trace.iter().filter(|e| matches!(e.event, Event::Leash { .. })).map(|e| e.t).collect();
    let [first, pause, second, resume] = leashes[..] else { panic!("{leashes:?}") };
    let fly = calls_of(&r, Function::FlyToPosition);
    let hover = calls_of(&r, Function::Hover);
    assert_eq!((fly.len(), hover.len()), (2, 2));
    assert_eq!(fly[0].0, first);
    // The pause holds the first section's flight: not a metre between PAUSE and RESUME.
    let track = r.positions("a");
    let still: Vec<[f64; 3]> =
        track.iter().filter(|(t, _)| *t >= pause + 0.1 && *t <= resume).map(|(_, p)| *p).collect();
    assert!(still.len() > 50 && still.iter().all(|p| apart(*p, still[0]) < 1e-9), "{still:?}");
    assert!(fly[0].1 > resume, "it goes on after the RESUME");
    // The second section waits for the first, asked though it was while the first ran.
    assert!(second < fly[0].1);
    assert_eq!(fly[1].0, hover[0].1, "its turn comes as the first one ends");
    // The body waits for both.
    let orbit = &calls_of(&r, Function::Orbit)[0];
    assert!(orbit.1 > hover[1].1 && orbit.2 == CallStatus::Ok);
}

#[test]
fn an_area_where_a_position_is_expected_is_its_centroid() {
    let r = run(&fixture("an_area_where_a_position_is_expected_is_its_centroid"));
    assert_eq!(r.outcome.status, Status::Ok);
    let done = |f: Function| match &r.first(is::done(f)).event {
        Event::ApiDone { args, status, position, .. } => (args, *status, *position),
        _ => unreachable!(),
    };
    let (args, _, position) = done(Function::FlyToPosition);
    let corners = match &args[0] {
        Shown::Area(corners) => Some(corners.len()),
        _ => None,
    };
    assert_eq!(corners, Some(4), "the area itself is passed");
    assert_eq!(position, [150.0, 150.0, 20.0], "to its centroid");
    assert_eq!(done(Function::Sweep).1, CallStatus::Ok);
    // The circle is flown around the centroid: it ends on it, 20 m out.
    let p = done(Function::Orbit).2;
    let (x, y) = (p[0], p[1]);
    assert!(((x - 150.0).hypot(y - 150.0) - 20.0).abs() < 1e-6, "{p:?}");
}

/// The firings of handler `path`, paired in trace order: (start index, end index, start
/// time, end time). Right for firings that do not overlap, which is what the caller then
/// asserts.
fn firings(r: &harness::Run, path: &str) -> Vec<(usize, usize, f64, f64)> {
    let at = |event: EventKind| -> Vec<(usize, f64)> {
        r.trace
            .iter()
            .enumerate()
            .filter(|(_, e)| match &e.event {
                Event::HandlerStart { handler, .. } if event == EventKind::HandlerStart => {
                    handler == path
                }
                Event::HandlerEnd { handler, .. } if event == EventKind::HandlerEnd => {
                    handler == path
                }
                _ => false,
            })
            .map(|(i, e)| (i, e.t))
            .collect()
    };
    let (starts, ends) = (at(EventKind::HandlerStart), at(EventKind::HandlerEnd));
    assert_eq!(starts.len(), ends.len(), "every firing ends:\n{}", r.dump());
    starts.iter().zip(&ends).map(|(&(si, st), &(ei, et))| (si, ei, st, et)).collect()
}

/// Each firing's events lie between its start and its end, and the next firing starts
/// after the one before has ended (in trace order, at the same instant).
fn one_after_another(r: &harness::Run, path: &str) -> Vec<(usize, usize, f64, f64)> {
    let f = firings(r, path);
    for w in f.windows(2) {
        let ((_, end, _, t_end), (start, _, t_start, _)) = (w[0], w[1]);
        assert!(start > end, "a firing starts only after the one before ended:\n{}", r.dump());
        assert!(close(t_start, t_end), "and at once: {t_start} after {t_end}");
    }
    f
}

#[test]
fn on_every_firings_interleave_on_one_drone() {
    // What ONE AT A TIME is for: without it, two firings take turns on drone a statement
    // by statement, and the second firing's TakeOff comes while a is in the air.
    let r = run(&fixture("on_every_firings_interleave_on_one_drone"));
    assert_eq!(r.outcome.status, Status::Failed);
    let takeoffs: Vec<usize> = r
        .trace
        .iter()
        .enumerate()
        .filter(|(_, e)| is::start_of("TakeOff")(&e.event))
        .map(|(i, _)| i)
        .collect();
    assert_eq!(takeoffs.len(), 2, "{}", r.dump());
    let first_takeoff_end = r.index(is::end_of("TakeOff"));
    assert!(takeoffs[1] > first_takeoff_end, "the second waits for the first");
    assert!(
        r.find(is::start_of("FlyTo")).is_empty(),
        "and gets a before the first firing's FlyTo:\n{}",
        r.dump()
    );
    let e = r.first(is::exception("CommandFailed"));
    assert_eq!(actor(&e.event), Some("a"));
}

#[test]
fn one_at_a_time_runs_firings_one_after_another() {
    let r = run(&fixture("one_at_a_time_runs_firings_one_after_another"));
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let f = one_after_another(&r, "P/ON Go");
    assert_eq!(f.len(), 3, "no firing is dropped");
    assert_eq!(f[0].2, 0.0, "the first starts at once");
    // Inside each firing: its three statements, in order, and nothing of another firing.
    let targets = ["[0.0,100.0]", "[0.0,400.0]", "[50.0,50.0]"];
    for (&(start, end, _, _), target) in f.iter().zip(targets) {
        let caps: Vec<String> = r.trace[start..end]
            .iter()
            .filter_map(|e| match &e.event {
                Event::CapabilityStart { capability, args, .. } => {
                    Some(format!("{capability} {}", serde_json::to_string(args).unwrap()))
                }
                _ => None,
            })
            .collect();
        assert_eq!(caps.len(), 3, "{caps:?}");
        assert!(caps[0].starts_with("TakeOff"), "{caps:?}");
        assert_eq!(
            caps[1],
            format!("FlyTo {{\"target\":{target},\"speed\":0.0}}"),
            "in signal order"
        );
        assert!(caps[2].starts_with("ReturnHome"), "{caps:?}");
    }
    // Never two activities of the drone at once: each capability ends before the next starts.
    let mut running = 0;
    for e in r.trace.iter() {
        match &e.event {
            Event::CapabilityStart { actor, .. } if actor == "a" => running += 1,
            Event::CapabilityEnd { actor, .. } if actor == "a" => running -= 1,
            _ => {}
        }
        assert!(running <= 2, "TakeOff and FlyTo may nest their own calls, no more");
    }
    assert!(
        r.find(|e| matches!(e, Event::Exception { actor: Some(a), .. } if a == "a")).is_empty(),
        "{}",
        r.dump()
    );
}

#[test]
fn one_at_a_time_firings_that_come_later_wait_in_order() {
    let r = run(&fixture("one_at_a_time_firings_that_come_later_wait_in_order"));
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let signals: Vec<f64> = r.find(is::signal("Go")).iter().map(|e| e.t).collect();
    assert!(close(signals[0], 0.0) && close(signals[1], 1.0) && close(signals[2], 2.0));
    // 3 s + 3 s, then 2 s + 2 s, then 1 s + 1 s: each waits for the one before.
    let f = one_after_another(&r, "P/ON Go");
    let times: Vec<(f64, f64)> = f.iter().map(|&(_, _, s, e)| (s, e)).collect();
    let expected = [(0.0, 6.0), (6.0, 10.0), (10.0, 12.0)];
    for (got, want) in times.iter().zip(expected) {
        assert!(close(got.0, want.0) && close(got.1, want.1), "{times:?}");
    }
    let hovers: Vec<f64> = r
        .trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::CapabilityStart { actor, args, .. } if actor == "a" => {
                Some(args.get("duration").unwrap().as_number().unwrap())
            }
            _ => None,
        })
        .collect();
    assert_eq!(hovers, [3.0, 2.0, 1.0], "in the order of the signals");
}

#[test]
fn sequential_on_every_one_at_a_time_starts_after_the_block_then_in_turn() {
    let r = run(&fixture("sequential_on_every_one_at_a_time_starts_after_the_block_then_in_turn"));
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    assert!(close(r.t(is::block_end("Raise")), 2.0));
    let f = one_after_another(&r, "P/ON Go");
    let times: Vec<(f64, f64)> = f.iter().map(|&(_, _, s, e)| (s, e)).collect();
    let expected = [(2.0, 8.0), (8.0, 12.0), (12.0, 14.0)];
    for (got, want) in times.iter().zip(expected) {
        assert!(close(got.0, want.0) && close(got.1, want.1), "{times:?}");
    }
    let hovers: Vec<f64> = r
        .trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::CapabilityStart { actor, args, .. } if actor == "b" => {
                Some(args.get("duration").unwrap().as_number().unwrap())
            }
            _ => None,
        })
        .collect();
    assert_eq!(hovers, [3.0, 2.0, 1.0], "in the order of the signals");
}

#[test]
fn payload_reads_the_kind_carried_and_nothing_before_or_after() {
    let r = run(&fixture("payload_reads_the_kind_carried_and_nothing_before_or_after"));
    assert_eq!(r.outcome.status, Status::Ok);
    // Only the Hover between LoadPayload and ReleasePayload, once the load is done.
    let hovers = r.ends("Hover", "a");
    assert_eq!(hovers.len(), 1);
    assert_eq!(hovers[0].args.get("duration").and_then(Shown::as_number), Some(2.0));
    let loaded = r.t(is::done(Function::LoadPayload));
    assert!(close(hovers[0].t - 2.0, loaded));
    // After the release `a` reads nothing: the ELSE runs.
    let released = r.t(is::done(Function::ReleasePayload));
    assert!(close(r.ends("Hover", "b")[0].t - 3.0, released));
}

/// Each `(start, end)` of `capability` on `actor`, in order.
fn spans_of(r: &harness::Run, capability: &str, actor: &str) -> Vec<(f64, f64)> {
    let starts = r.trace.iter().filter_map(|e| match &e.event {
        Event::CapabilityStart { capability: c, actor: a, .. } if c == capability && a == actor => {
            Some(e.t)
        }
        _ => None,
    });
    starts.zip(r.ends(capability, actor).iter().map(|e| e.t)).collect()
}

#[test]
fn any_takes_the_nearest_free_drone() {
    let r = run_rule("any_takes_the_nearest_free_drone");
    assert_eq!(r.outcome.status, Status::Ok);
    assert_eq!(actor(&r.first(is::start_of("FlyTo")).event), Some("near"));
    // The second ANY looks while the first holds `near`: the next nearest.
    assert_eq!(actor(&r.first(is::start_of("Hover")).event), Some("middle"));
    assert!(r.find(is::start_by("far")).is_empty(), "far is never taken");
    assert!(close(r.t(is::start_of("Hover")), 0.0), "no wait: both at once");
}

#[test]
fn two_any_never_hold_one_drone_at_once() {
    let r = run_rule("two_any_never_hold_one_drone_at_once");
    assert_eq!(r.outcome.status, Status::Ok);
    for drone in ["far", "middle"] {
        let spans = spans_of(&r, "Hover", drone);
        for pair in spans.windows(2) {
            assert!(pair[1].0 >= pair[0].1, "{drone} held twice at once: {spans:?}");
        }
    }
    // The third request waits for the first drone let go: `far`, at the end of its 10 s.
    let third = r
        .trace
        .iter()
        .find(|e| {
            matches!(&e.event, Event::CapabilityStart { args, .. }
                if args.get("duration") == Some(&Shown::Number(5.0)))
        })
        .expect("the third ANY ran");
    assert_eq!(actor(&third.event), Some("far"));
    assert!(close(third.t, 10.0), "{third:?}");
    assert!(spans_of(&r, "Hover", "near").len() == 1, "near, excluded by WHERE, did only its own");
}

#[test]
fn any_within_raises_no_drone_available_on_time() {
    let r = run_rule("any_within_raises_no_drone_available_on_time");
    assert_eq!(r.outcome.status, Status::Ok);
    let e = r.first(is::exception("NoDroneAvailable"));
    let Event::Exception { handled, args, .. } = &e.event else { unreachable!() };
    assert!(close(e.t, 8.0), "{e:?}");
    assert!(*handled);
    assert!(args[0].as_str().unwrap().contains("within 8 s"), "{e:?}");
    // The aborted block's later statement never runs; the handler does.
    assert!(r.find(is::start_of("Hover")).is_empty());
    assert!(close(r.t(is::signal("Gave_Up")), 8.0));
}

#[test]
fn any_two_runs_its_body_once_for_each() {
    let r = run_rule("any_two_runs_its_body_once_for_each");
    assert_eq!(r.outcome.status, Status::Ok);
    let done: Vec<&str> =
        r.find(is::signal("Done")).iter().map(|e| actor(&e.event).unwrap()).collect();
    assert_eq!(done, ["far", "middle"], "the two nearest to Home, each once");
    // `far`'s own statement waits for the ANY's Hover, and the later ANY takes `far` again
    // once both let it go.
    let far = spans_of(&r, "Hover", "far");
    assert_eq!(far.len(), 3, "{far:?}");
    assert!(close(far[1].0, 3.0) && close(far[2].0, 4.0), "{far:?}");
}

/// Where `actor` was when its `FlyToPosition` number `i` was done (the trace says).
fn at_end_of_fly_to(r: &harness::Run, actor: &str, i: usize) -> [f64; 3] {
    let done: Vec<[f64; 3]> =
        r.trace
            .iter()
            .filter_map(|e| match &e.event {
                Event::ApiDone {
                    actor: a, function: Function::FlyToPosition, position, ..
                } if a == actor => Some(*position),
                _ => None,
            })
            .collect();
    done[i]
}

/// How far apart over the ground.
fn ground(p: [f64; 3], q: [f64; 3]) -> f64 {
    (p[0] - q[0]).hypot(p[1] - q[1])
}

#[test]
fn two_drones_sent_beside_one_find_end_apart() {
    let r = run(&fixture("two_drones_sent_beside_one_find_end_apart"));
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let (a, b) = (at_end_of_fly_to(&r, "a", 0), at_end_of_fly_to(&r, "b", 0));
    let c = at_end_of_fly_to(&r, "c", 0);
    assert!((ground(a, b) - 40.0).abs() < 0.5, "{a:?} {b:?}");
    assert!(
        (ground(a, c) - 20.0).abs() < 0.5 && (a[0] - c[0] - 20.0).abs() < 0.5,
        "a east of the find"
    );
    assert!((ground(b, c) - 20.0).abs() < 0.5 && (c[0] - b[0] - 20.0).abs() < 0.5, "b west of it");
    // At the find's height: the offsets keep it.
    assert!((a[2] - c[2]).abs() < 0.5 && (b[2] - c[2]).abs() < 0.5, "{a:?} {b:?} {c:?}");
}

#[test]
fn a_let_keeps_the_value_it_took() {
    let r = run(&fixture("a_let_keeps_the_value_it_took"));
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    // `there` is where `a` stood after its take-off, though `a` flew on to (100, 0).
    let b = at_end_of_fly_to(&r, "b", 0);
    assert!(ground(b, [0.0, 0.0, 0.0]) < 0.5 && (b[2] - 20.0).abs() < 0.5, "{b:?}");
    // `beside` was taken as the PARALLEL started, with `a` at (100, 0).
    let c = at_end_of_fly_to(&r, "c", 0);
    assert!(ground(c, [50.0, 0.0, 0.0]) < 0.5, "{c:?}");
    // `above` is `there` 10 m higher.
    let a = at_end_of_fly_to(&r, "a", 1);
    assert!(ground(a, [0.0, 0.0, 0.0]) < 0.5 && (a[2] - 30.0).abs() < 0.5, "{a:?}");
}

#[test]
fn a_stopped_block_ends_at_once_and_frees_its_drones() {
    let r = run(&fixture("a_stopped_block_ends_at_once_and_frees_its_drones"));
    assert_eq!(r.outcome.status, Status::Ok, "a stopped block does not change the outcome");
    let stops = r.find(|e| matches!(e, Event::Leash { block: true, .. }));
    assert_eq!(stops.len(), 2, "each stop is recorded, the second with nothing to stop");
    assert!(stops.iter().all(|e| matches!(&e.event, Event::Leash { capability, action, .. }
        if capability == "Valley_Search" && action == "ABORT")));
    let at = stops[0].t;
    assert!(close(at, 15.0), "{at}");
    // Its running statements end aborted at the instant of the stop, its waits too.
    let fly = r.ends("FlyTo", "a")[0];
    assert_eq!((fly.status, fly.t), (Status::Aborted, at));
    for block in ["Sweep_And_Watch", "Valley_Search"] {
        let end = r.first(is::block_end(block));
        let Event::BlockEnd { status, .. } = end.event else { unreachable!() };
        assert_eq!((status, end.t), (Status::Aborted, at));
    }
    // Its later statements never start.
    assert!(r.find(is::start_of("ReturnHome")).is_empty(), "{}", r.dump());
    // The handler's orders take the drone at once: no wait for the block's statement.
    let starts = r.find(is::start_of("FlyTo"));
    assert_eq!(starts.len(), 2);
    assert_eq!(starts[1].t, at);
    let Event::CapabilityStart { args, .. } = &starts[1].event else { unreachable!() };
    let north = Shown::Position(aviary_api::Point { x: 0.0, y: 100.0, z: None });
    assert_eq!(args.get("target"), Some(&north), "North");
    assert_eq!(r.ends("Land", "a")[0].status, Status::Ok);
}

#[test]
fn any_two_lets_each_go_as_its_own_body_ends() {
    let r = run_rule("any_two_lets_each_go_as_its_own_body_ends");
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let far = spans_of(&r, "Hover", "far");
    assert_eq!(far.len(), 2, "{far:?}");
    assert!(close(far[0].1, 1.0), "{far:?}");
    // Taken again at once, while middle's body still runs (to 5 s).
    assert!(close(far[1].0, 1.0), "far is let go when its own body ends: {far:?}");
    assert!(close(spans_of(&r, "Hover", "middle")[0].1, 5.0));
}

#[test]
fn any_with_no_drone_left_raises_at_once() {
    let r = run_rule("any_with_no_drone_left_raises_at_once");
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let e = r.first(is::exception("NoDroneAvailable"));
    let Event::Exception { args, .. } = &e.event else { unreachable!() };
    assert!(close(e.t, 3.0), "at once, not after a wait: {e:?}");
    assert!(args[0].as_str().unwrap().contains("only 0 of them"), "{e:?}");
    assert!(r.find(is::start_of("Land")).is_empty());
}
