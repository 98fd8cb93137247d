//! The operator steers one drone (`Control::Drone`, src/steer.rs): hold and resume its
//! activities, send it home or land it out of the mission; each an `operator` event in
//! the trace, at its time and before what it does; refusals say why.

use aviary_api::trace::{CallStatus, Event, Record};
use aviary_api::Function;
use aviary_engine::{Control, DroneAction, OperatorAction, Outcome, RunOptions, Status};
use aviary_test_support::harness;
use aviary_test_support::trace::{is, Trace};
use harness::{Ask, Path};

/// The harness's world, with more far places, so that drones flying far do not meet at
/// the end.
fn world() -> String {
    harness::WORLD.replace(
        "Far = [0, 400]\n",
        "Far = [0, 400]\nFarEast = [200, 400]\nFarWest = [-200, 400]\n",
    )
}

fn run(mission: &str, controls: Vec<(f64, Ask)>) -> (Outcome, Trace, Vec<Result<(), String>>) {
    run_on(mission, &world(), controls, Path::AsUsersRun)
}

fn run_on(
    mission: &str,
    world: &str,
    controls: Vec<(f64, Ask)>,
    path: Path,
) -> (Outcome, Trace, Vec<Result<(), String>>) {
    let (compiled, world) = harness::compile(mission, world);
    let options = RunOptions { telemetry_hz: Some(10.0), ..RunOptions::default() };
    let (run, answers) = harness::run_compiled(&compiled, &world, &options, controls, path);
    (run.outcome, run.trace, answers)
}

fn drone(name: &str, action: DroneAction) -> Ask {
    Ask::drone(name, action)
}

use DroneAction::{Hold, Land, Resume, ReturnHome};

fn t(e: &Record) -> f64 {
    e.t
}

/// Telemetry positions of `actor` strictly between two times.
fn positions(trace: &Trace, actor: &str, from: f64, to: f64) -> Vec<[f64; 3]> {
    trace
        .positions(actor)
        .into_iter()
        .filter(|(t, _)| *t > from && *t < to)
        .map(|(_, p)| p)
        .collect()
}

fn still(trace: &Trace, actor: &str, from: f64, to: f64) -> bool {
    let held = positions(trace, actor, from, to);
    held.len() > 10 && held.iter().all(|p| *p == held[0])
}

fn moving(trace: &Trace, actor: &str, from: f64, to: f64) -> bool {
    let seen = positions(trace, actor, from, to);
    seen.len() > 10 && seen.windows(2).all(|w| w[0] != w[1])
}

/// The index of the first event for which `is` holds.
fn index(trace: &Trace, is: impl Fn(&Event) -> bool) -> usize {
    trace.index(is)
}

/// `(t, action, drone)` of every `operator` event, in order.
fn operator_events(trace: &Trace) -> Vec<(f64, OperatorAction, Option<String>)> {
    trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::Operator { action, drone } => {
                Some((t(e), *action, drone.as_ref().map(|d| d.to_string())))
            }
            _ => None,
        })
        .collect()
}

/// The `api_call` (`done` false) or `api_done` (`done` true) of `function` by `actor`.
fn call(done: bool, actor: &str, function: Function) -> impl Fn(&Event) -> bool + '_ {
    move |e| match e {
        Event::ApiCall { actor: a, function: f, .. } => !done && a == actor && *f == function,
        Event::ApiDone { actor: a, function: f, .. } => done && a == actor && *f == function,
        _ => false,
    }
}

/// How an `api_done` ended, and where its drone was.
fn done_at(e: &Record) -> (CallStatus, [f64; 3]) {
    match &e.event {
        Event::ApiDone { status, position, .. } => (*status, *position),
        other => panic!("not an api_done: {other:?}"),
    }
}

const TWO_FLY: &str =
    "MISSION M:\n    PARALLEL:\n        a FlyTo WITH Far\n        b FlyTo WITH FarEast\n";

#[test]
fn a_held_drone_stays_put_while_the_others_fly_on_and_goes_on_when_resumed() {
    let (outcome, trace, answers) =
        run(TWO_FLY, vec![(10.0, drone("a", Hold)), (20.0, drone("a", Resume))]);
    assert_eq!(answers, [Ok(()), Ok(())]);
    assert_eq!(outcome.status, Status::Ok, "{:?}", outcome.reason);
    assert!(still(&trace, "a", 10.05, 19.95), "a holds where it is");
    assert!(moving(&trace, "b", 10.05, 19.95), "b flies on");
    assert!(moving(&trace, "a", 20.05, 25.0), "a goes on after the resume");
    assert_eq!(
        operator_events(&trace),
        [
            (10.0, OperatorAction::Hold, Some("a".into())),
            (20.0, OperatorAction::Resume, Some("a".into()))
        ]
    );
    let (fly_a, fly_b) = (trace.ends("FlyTo", "a"), trace.ends("FlyTo", "b"));
    assert_eq!((fly_a[0].status, fly_b[0].status), (Status::Ok, Status::Ok));
    // Ten seconds held, and a stop and a start: a arrives that much later than unheld.
    let (alone, unheld, _) = run(TWO_FLY, vec![]);
    assert_eq!(alone.status, Status::Ok);
    let late = fly_a[0].t - unheld.ends("FlyTo", "a")[0].t;
    assert!((10.0..13.0).contains(&late), "a arrives {late} s later than unheld");
}

#[test]
fn an_activity_that_starts_while_its_drone_is_held_starts_held_on_either_path() {
    // Ping's calls end at once (an instant activity, src/instant.rs); it starts at 18 s,
    // while b is held, and makes its first call only when b is resumed.
    let mission = "CAPABILITY Ping BY d:\n    PERFORM:\n        d.StartStreaming()\n        d.StopStreaming()\n\nMISSION M:\n    PARALLEL:\n        a FlyTo WITH Far\n        SEQUENTIAL:\n            WAITFOR ELAPSED >= 18s\n            b Ping\n";
    let controls = || vec![(15.0, drone("b", Hold)), (25.0, drone("b", Resume))];
    let users = run_on(mission, &world(), controls(), Path::AsUsersRun);
    let general = run_on(mission, &world(), controls(), Path::GeneralOnly);
    assert_eq!((&users.0, &users.1), (&general.0, &general.1), "the same trace both ways");
    let (outcome, trace, _) = users;
    assert_eq!(outcome.status, Status::Ok);
    let start = &trace[index(&trace, is::start_of("Ping"))];
    assert!((t(start) - 18.0).abs() < 0.11, "{start:?}");
    let call = &trace[index(&trace, is::call(Function::StartStreaming))];
    assert_eq!(t(call), 25.0, "held until the resume");
    assert!(moving(&trace, "a", 15.05, 24.95), "a is not held");
}

#[test]
fn a_hold_and_a_pause_of_the_mission_are_apart() {
    let (outcome, trace, answers) = run(
        TWO_FLY,
        vec![
            (10.0, Control::Pause.into()),
            (12.0, drone("a", Hold)),
            (15.0, Control::Resume.into()),
            (20.0, drone("a", Resume)),
        ],
    );
    assert_eq!(answers, [Ok(()), Ok(()), Ok(()), Ok(())]);
    assert_eq!(outcome.status, Status::Ok);
    assert!(still(&trace, "b", 10.05, 14.95) && still(&trace, "a", 10.05, 19.95));
    assert!(moving(&trace, "b", 15.05, 19.95), "resuming the mission lets b go on, not a");
    assert!(moving(&trace, "a", 20.05, 25.0), "resuming a lets it go on");
    let actions: Vec<(OperatorAction, Option<String>)> =
        operator_events(&trace).into_iter().map(|(_, a, d)| (a, d)).collect();
    assert_eq!(
        actions,
        [
            (OperatorAction::Pause, None),
            (OperatorAction::Hold, Some("a".into())),
            (OperatorAction::Resume, None),
            (OperatorAction::Resume, Some("a".into())),
        ]
    );
}

#[test]
fn holding_one_drone_of_a_group_activity_holds_the_activity() {
    let mission = "CAPABILITY Pair BY x, y:\n    PERFORM:\n        PARALLEL:\n            x FlyTo WITH Far\n            y FlyTo WITH FarEast\n\nMISSION M:\n    PARALLEL:\n        a b Pair\n        c FlyTo WITH FarWest\n";
    let (outcome, trace, answers) =
        run(mission, vec![(10.0, drone("b", Hold)), (20.0, drone("b", Resume))]);
    assert_eq!(answers, [Ok(()), Ok(())]);
    assert_eq!(outcome.status, Status::Ok);
    assert!(
        still(&trace, "a", 10.05, 19.95) && still(&trace, "b", 10.05, 19.95),
        "the pair is held whole"
    );
    assert!(moving(&trace, "c", 10.05, 19.95));
    assert_eq!(trace.ends("Pair", "a b")[0].status, Status::Ok);
}

#[test]
fn sending_a_drone_home_aborts_its_activities_and_the_mission_goes_on_with_the_rest() {
    let mission = "MISSION M:\n    PARALLEL:\n        SEQUENTIAL:\n            a FlyTo-F1 WITH Far\n            a Hover WITH 5s\n        b FlyTo WITH FarEast\n";
    let (outcome, trace, answers) = run(mission, vec![(10.0, drone("a", ReturnHome))]);
    for e in trace.iter().filter(|e| !matches!(e.event, Event::Telemetry { .. })) {
        println!("{}", serde_json::to_string(e).unwrap());
    }
    assert_eq!(answers, [Ok(())]);
    assert_eq!(outcome.status, Status::Ok, "{:?}", outcome.reason);
    assert_eq!(operator_events(&trace), [(10.0, OperatorAction::ReturnHome, Some("a".into()))]);
    let said = index(&trace, |e| matches!(e, Event::Operator { .. }));
    let fly_end = index(&trace, |e| {
        matches!(e, Event::CapabilityEnd { capability, actor, .. }
            if capability == "FlyTo" && actor == "a")
    });
    let cut = index(&trace, call(true, "a", Function::FlyToPosition));
    let hover = index(&trace, is::end_of("Hover"));
    let home = index(&trace, call(false, "a", Function::ReturnToLaunch));
    let ended = |i: usize| match trace[i].event {
        Event::CapabilityEnd { status, .. } => status,
        _ => unreachable!(),
    };
    assert_eq!(ended(fly_end), Status::Aborted);
    assert_eq!(done_at(&trace[cut]).0, CallStatus::Aborted);
    assert_eq!(ended(hover), Status::Aborted, "a later activity of a ends at once");
    assert!(said < fly_end && fly_end < cut && cut < hover && hover < home, "in this order");
    assert!([fly_end, cut, hover, home].iter().all(|i| t(&trace[*i]) == 10.0), "all at once");
    assert!(
        !trace.iter().any(|e| call(false, "a", Function::Hover)(&e.event)),
        "the later activity did not fly"
    );
    let back = &trace[index(&trace, call(true, "a", Function::ReturnToLaunch))];
    assert_eq!(done_at(back), (CallStatus::Ok, [0.0, 0.0, 0.0]));
    let fly_b = trace.ends("FlyTo", "b");
    assert_eq!(fly_b[0].status, Status::Ok);
    assert!(fly_b[0].t > t(back), "b carries on after a is home");
    // Out of the mission: it is not sent home again at the end.
    let returns =
        trace.iter().filter(|e| call(false, "a", Function::ReturnToLaunch)(&e.event)).count();
    assert_eq!(returns, 1);
}

#[test]
fn landing_a_drone_brings_it_down_where_it_is() {
    let (outcome, trace, answers) = run(TWO_FLY, vec![(15.0, drone("a", Land))]);
    assert_eq!(answers, [Ok(())]);
    assert_eq!(outcome.status, Status::Ok, "{:?}", outcome.reason);
    let at = positions(&trace, "a", 14.9, 15.05)[0];
    let landed = &trace[index(&trace, call(true, "a", Function::Land))];
    let (status, p) = done_at(landed);
    assert_eq!(status, CallStatus::Ok);
    assert!(at[2] > 5.0, "a was in the air: {at:?}");
    assert_eq!((p[0], p[1], p[2]), (at[0], at[1], 0.0));
    assert_eq!(trace.ends("FlyTo", "a")[0].status, Status::Aborted);
    assert_eq!(trace.ends("FlyTo", "b")[0].status, Status::Ok);
    assert!(!trace.iter().any(|e| {
        let rtl = |done| call(done, "a", Function::ReturnToLaunch)(&e.event);
        rtl(false) || rtl(true)
    }));
}

#[test]
fn a_drone_on_its_way_home_can_still_be_landed() {
    let (outcome, trace, answers) =
        run(TWO_FLY, vec![(10.0, drone("a", ReturnHome)), (14.0, drone("a", Land))]);
    assert_eq!(answers, [Ok(()), Ok(())]);
    assert_eq!(outcome.status, Status::Ok, "{:?}", outcome.reason);
    let cut = &trace[index(&trace, call(true, "a", Function::ReturnToLaunch))];
    assert_eq!((done_at(cut).0, t(cut)), (CallStatus::Aborted, 14.0));
    let land = index(&trace, call(false, "a", Function::Land));
    assert_eq!(t(&trace[land]), 14.0);
    let landed = done_at(&trace[index(&trace, call(true, "a", Function::Land))]);
    assert_eq!(landed.0, CallStatus::Ok);
    assert_ne!(landed.1, [0.0, 0.0, 0.0], "down where it was, not home");
}

#[test]
fn a_withdrawn_drones_fault_is_its_way_downs_and_no_handler_takes_it() {
    let world =
        format!("{}\n[[faults]]\ndrone = \"a\"\nat = 12\nkind = \"battery_critical\"\n", world());
    let mission = "MISSION M:\n    PARALLEL:\n        a FlyTo WITH Far\n        b FlyTo WITH FarEast\n        ON EXCEPTION BatteryCritical BY a:\n            c Hover WITH 1s\n";
    let (outcome, trace, _) =
        run_on(mission, &world, vec![(10.0, drone("a", ReturnHome))], Path::AsUsersRun);
    let fault = &trace[index(&trace, |e| matches!(e, Event::Exception { .. }))];
    let Event::Exception { handled, during, .. } = &fault.event else { unreachable!() };
    assert_eq!((*handled, during.as_deref(), t(fault)), (false, Some("return home"), 12.0));
    assert!(!trace.iter().any(|e| is::start_by("c")(&e.event)), "no handler ran");
    assert_eq!(outcome.status, Status::Ok, "the mission goes on and ends ok");
    assert!(
        outcome
            .reason
            .as_deref()
            .is_some_and(|r| r.contains("BatteryCritical on a on its way down")),
        "{:?}",
        outcome.reason
    );
}

#[test]
fn the_operator_is_told_why_a_drone_control_is_refused() {
    let three = format!("{TWO_FLY}        c FlyTo WITH North\n");
    let (outcome, _, answers) = run(
        &three,
        vec![
            (1.0, drone("d", Hold)),
            (1.0, drone("tower", Hold)),
            (1.0, drone("a", Resume)),
            (2.0, drone("a", Hold)),
            (2.0, drone("a", Hold)),
            (3.0, Control::Pause.into()),
            (3.0, drone("b", Resume)),
            (4.0, Control::Resume.into()),
            (5.0, drone("a", Land)),
            (5.0, drone("a", Resume)),
            (5.0, drone("a", ReturnHome)),
            (5.0, drone("a", Land)),
            (6.0, drone("b", ReturnHome)),
            (6.0, drone("b", Hold)),
            (600.0, drone("b", Land)),
        ],
    );
    assert_eq!(outcome.status, Status::Ok);
    let refused = |i: usize| answers[i].clone().expect_err("refused");
    assert_eq!(refused(0), "no drone is called `d`: did you mean `a`?");
    assert_eq!(refused(1), "no drone is called `tower`: the fleet is a, b, c");
    assert_eq!(refused(2), "a is not held: there is nothing of it to resume");
    assert_eq!(answers[3], Ok(()));
    assert_eq!(refused(4), "a is already held: resume it to let its activities go on");
    assert_eq!(
        refused(6),
        "b is not held: there is nothing of it to resume; the whole mission is paused: resume the mission instead"
    );
    assert_eq!(answers[8], Ok(()), "a held drone can be landed");
    for i in [9, 10, 11] {
        assert_eq!(
            refused(i),
            "a is landing or has landed, out of the mission (the operator landed it): it takes no more orders"
        );
    }
    assert_eq!(answers[12], Ok(()));
    assert_eq!(
        refused(13),
        "b is on its way home, out of the mission (the operator sent it): it takes no more orders but land"
    );
    assert_eq!(refused(14), "the mission has ended", "after the end");
}

#[test]
fn a_hold_reaches_an_activity_inside_another() {
    // At 2 s, a is taking off: the standard FlyTo calls TakeOff, an activity inside it.
    let (outcome, trace, answers) =
        run(TWO_FLY, vec![(2.0, drone("a", Hold)), (8.0, drone("a", Resume))]);
    assert_eq!(answers, [Ok(()), Ok(())]);
    assert_eq!(outcome.status, Status::Ok);
    assert!(still(&trace, "a", 2.05, 7.95), "a holds its climb");
    let climbed = |actor: &str, at: f64| positions(&trace, actor, at - 0.05, at + 0.05)[0][2];
    assert!(climbed("b", 4.0) > climbed("a", 4.0) + 3.0, "b climbs on");
    let takeoff = trace.ends("TakeOff", "a");
    assert_eq!(takeoff[0].status, Status::Ok);
    assert!(takeoff[0].t > 8.0, "it ends after the resume: {:?}", takeoff[0]);
}

#[test]
fn a_statement_that_names_a_drone_out_of_the_mission_ends_at_once_for_that_drone() {
    // `team Hover` is one activity per drone of the group; `a b Pair` is one of both.
    let mission = "CAPABILITY Pair BY x, y:\n    PERFORM:\n        x Hover WITH 2s\n        y Hover WITH 2s\n\nMISSION M:\n    c FlyTo WITH North\n    PARALLEL:\n        team TakeOff\n        c Hover WITH 20s\n    team Hover WITH 3s\n    a b Pair\n";
    let (outcome, trace, answers) = run(mission, vec![(1.0, drone("b", Land))]);
    assert_eq!(answers, [Ok(())]);
    assert_eq!(outcome.status, Status::Ok, "{:?}", outcome.reason);
    let status = |capability: &str, actor: &str| {
        trace.ends(capability, actor).iter().map(|e| e.status).collect::<Vec<_>>()
    };
    assert_eq!(status("TakeOff", "b"), [Status::Aborted]);
    assert_eq!(status("Hover", "b"), [Status::Aborted]);
    assert_eq!(status("Pair", "a b"), [Status::Aborted]);
    assert_eq!(status("TakeOff", "a"), [Status::Ok]);
    assert_eq!(status("Hover", "a"), [Status::Ok], "a's own instance of `team Hover` flies");
    for capability in ["TakeOff", "Hover", "Pair"] {
        let start = index(&trace, |e| {
            matches!(e, Event::CapabilityStart { capability: c, actor, .. }
                if c == capability && actor.contains('b'))
        });
        let end = index(&trace, |e| {
            matches!(e, Event::CapabilityEnd { capability: c, actor, .. }
                if c == capability && actor.contains('b'))
        });
        assert_eq!((end, t(&trace[end])), (start + 1, t(&trace[start])), "{capability}: at once");
    }
    assert!(
        !trace.iter().any(|e| matches!(&e.event, Event::ApiCall { actor, .. } if actor == "b")),
        "b, on the ground, never flew"
    );
}

#[test]
fn a_drone_taken_out_while_an_abort_section_runs_for_it_still_goes_home_at_once() {
    // At 8 s a leash aborts Patrol inside Outer; its `PERFORM ABORT:` section starts
    // Wait on a, an activity of its own (a statement of the section). At 10 s the
    // operator sends a home: Outer and Wait are aborted, and Wait, inside Outer, is
    // dropped with it, never to end: the way down does not wait for it.
    let mission = "CAPABILITY Wait BY d:\n    PERFORM:\n        WAITFOR ELAPSED >= 30s\n\nCAPABILITY Patrol BY drone:\n    PERFORM:\n        drone FlyTo WITH Far\n    PERFORM ABORT:\n        drone Wait\n\nCAPABILITY Outer BY drone:\n    PERFORM:\n        drone Patrol-P1\n\nMISSION M:\n    PARALLEL:\n        a Outer\n        SEQUENTIAL:\n            WAITFOR ELAPSED >= 8s\n            Patrol-P1 ABORT\n        b FlyTo WITH FarEast\n";
    let (outcome, trace, answers) = run(mission, vec![(10.0, drone("a", ReturnHome))]);
    assert_eq!(answers, [Ok(())]);
    assert_eq!(outcome.status, Status::Ok, "{:?}", outcome.reason);
    let wait = &trace[index(&trace, is::start_of("Wait"))];
    assert_eq!(t(wait), 8.0, "the section runs");
    let outer = &trace[index(&trace, is::end_of("Outer"))];
    let Event::CapabilityEnd { status, .. } = outer.event else { unreachable!() };
    assert_eq!((status, t(outer)), (Status::Aborted, 10.0));
    let home = &trace[index(&trace, call(false, "a", Function::ReturnToLaunch))];
    assert_eq!(t(home), 10.0, "sent home at once");
    let back = &trace[index(&trace, call(true, "a", Function::ReturnToLaunch))];
    assert_eq!(done_at(back).0, CallStatus::Ok);
}
