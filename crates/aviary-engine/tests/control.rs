//! Live control of a running mission, as the operator API and Ctrl-C use it.

use aviary_api::trace::{Event, Shown};
use aviary_api::{Function, Value};
use aviary_engine::{Control, OperatorAction, Outcome, RunOptions, Status};
use aviary_test_support::harness;
use aviary_test_support::trace::{actor, is, Trace};
use harness::{Ask, Path};

/// Runs `mission`, sending each control at its mission time; returns the outcome, the
/// trace and the engine's answers.
fn run_with_controls(
    mission: &str,
    controls: Vec<(f64, Ask)>,
) -> (Outcome, Trace, Vec<Result<(), String>>) {
    run_with_controls_on(mission, controls, Path::AsUsersRun)
}

fn run_with_controls_on(
    mission: &str,
    controls: Vec<(f64, Ask)>,
    path: Path,
) -> (Outcome, Trace, Vec<Result<(), String>>) {
    let (compiled, world) = harness::compile(mission, harness::WORLD);
    let options = RunOptions { telemetry_hz: Some(10.0), ..RunOptions::default() };
    let (run, answers) = harness::run_compiled(&compiled, &world, &options, controls, path);
    (run.outcome, run.trace, answers)
}

fn positions(trace: &Trace, actor: &str, from: f64, to: f64) -> Vec<[f64; 3]> {
    trace
        .positions(actor)
        .into_iter()
        .filter(|(t, _)| *t > from && *t < to)
        .map(|(_, p)| p)
        .collect()
}

/// `(t, action, drone)` of every `operator` event, in order.
fn operator_events(trace: &Trace) -> Vec<(f64, OperatorAction, Option<&str>)> {
    trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::Operator { action, drone } => Some((e.t, *action, drone.as_deref())),
            _ => None,
        })
        .collect()
}

#[test]
fn an_operator_leash_pauses_and_resumes_by_tag() {
    let (outcome, trace, answers) = run_with_controls(
        "MISSION M:\n    a FlyTo-F1 WITH Far\n",
        vec![
            (10.0, Ask::leash("FlyTo", "F1", "PAUSE")),
            (20.0, Ask::leash("FlyTo", "F1", "RESUME")),
        ],
    );
    assert_eq!(outcome.status, Status::Ok);
    assert_eq!(answers, [Ok(()), Ok(())]);
    let held = positions(&trace, "a", 10.2, 19.9);
    assert!(
        held.len() > 50 && held.iter().all(|p| *p == held[0]),
        "paused by the operator, a holds"
    );
    let leashes: Vec<&str> = trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::Leash { action, .. } => Some(&**action),
            _ => None,
        })
        .collect();
    assert_eq!(leashes, ["PAUSE", "RESUME"]);
}

#[test]
fn operator_controls_that_cannot_apply_are_refused_with_a_reason() {
    let (_, _, answers) = run_with_controls(
        "MISSION M:\n    a FlyTo-F1 WITH North\n    ON Go:\n        b Hover WITH 1s\n",
        vec![
            (1.0, Ask::leash("FlyTo", "F9", "PAUSE")),
            (1.0, Ask::leash("Fly", "F1", "PAUSE")),
            (1.0, Ask::leash("FlyTo", "F1", "Widen")),
            (1.0, Ask::Signal { name: "Nobody".into(), args: vec![] }),
            (1.0, Ask::leash("FlyT0", "F1", "PAUSE")),
            (1.0, Ask::leash("FlyTo", "F1", "PAUES")),
        ],
    );
    assert_eq!(
        answers[0],
        Err("no statement starts an activity tagged FlyTo-F9 (running now: FlyTo-F1): did you mean `FlyTo-F1`?".to_string())
    );
    assert_eq!(answers[1], Err("no capability is called Fly (running now: FlyTo-F1)".to_string()));
    assert_eq!(answers[2], Err("FlyTo has no section PERFORM Widen".to_string()));
    assert_eq!(
        answers[3],
        Err("the mission declares no signal an operator may raise, so not Nobody: it would need `OPERATOR SIGNAL Nobody` in its MISSION body".to_string())
    );
    assert_eq!(
        answers[4],
        Err("no capability is called FlyT0 (running now: FlyTo-F1): did you mean `FlyTo`?"
            .to_string())
    );
    assert_eq!(
        answers[5],
        Err("FlyTo has no section PERFORM PAUES: did you mean `PAUSE`?".to_string())
    );
}

#[test]
fn an_operator_signal_is_heard_by_the_mission() {
    let (outcome, trace, answers) = run_with_controls(
        "MISSION M:\n    OPERATOR SIGNAL Go, Stop\n    PARALLEL:\n        a Hover WITH 10s\n        ON Go WITH what:\n            b Hover WITH 1s\n        ON Halt:\n            b Hover WITH 1s\n        ON Stop:\n            SIGNAL Halt\n",
        vec![
            (7.0, Ask::Signal { name: "Go".into(), args: vec![Value::Text("now".into())] }),
            // Heard by the mission, but not declared: the operator may not raise it.
            (7.0, Ask::Signal { name: "Halt".into(), args: vec![] }),
            (7.0, Ask::Signal { name: "Sotp".into(), args: vec![] }),
        ],
    );
    assert_eq!(
        answers,
        [
            Ok(()),
            Err("the mission does not declare Halt as an operator signal: it declares Go, Stop"
                .to_string()),
            Err("the mission does not declare Sotp as an operator signal: did you mean `Stop`? It declares Go, Stop".to_string()),
        ]
    );
    let signals = trace.find(|e| matches!(e, Event::Signal { .. }));
    assert_eq!(signals.len(), 1, "only Go was raised");
    assert_eq!(outcome.status, Status::Ok);
    let Event::Signal { actor, args, .. } = &signals[0].event else { unreachable!() };
    assert_eq!((actor, args.first()), (&None, Some(&Shown::Text("now".into()))));
    assert_eq!(trace.t(is::start_by("b")), 7.0);
}

#[test]
fn pausing_the_mission_holds_every_drone_and_resuming_goes_on() {
    let (outcome, trace, _) = run_with_controls(
        "MISSION M:\n    PARALLEL:\n        a FlyTo WITH Far\n        b FlyTo WITH Field\n",
        vec![(15.0, Control::Pause.into()), (25.0, Control::Resume.into())],
    );
    assert_eq!(outcome.status, Status::Ok);
    for drone in ["a", "b"] {
        let held = positions(&trace, drone, 15.2, 24.9);
        assert!(
            held.len() > 50 && held.iter().all(|p| *p == held[0]),
            "{drone} holds while the mission is paused"
        );
    }
    assert_eq!(
        operator_events(&trace),
        [(15.0, OperatorAction::Pause, None), (25.0, OperatorAction::Resume, None)],
        "each written when the operator did it, for the whole mission"
    );
}

#[test]
fn an_activity_started_while_the_mission_is_paused_starts_held_on_either_path() {
    // Ping's calls end at once (an instant activity, src/instant.rs); it starts at 18 s,
    // inside the pause, and makes its first call only at the resume.
    let mission = "CAPABILITY Ping BY d:\n    PERFORM:\n        d.StartStreaming()\n        d.StopStreaming()\n\nMISSION M:\n    PARALLEL:\n        a FlyTo WITH Far\n        SEQUENTIAL:\n            WAITFOR ELAPSED >= 18s\n            b Ping\n";
    let controls = || vec![(15.0, Control::Pause.into()), (25.0, Control::Resume.into())];
    let (outcome, trace, _) = run_with_controls(mission, controls());
    let general = run_with_controls_on(mission, controls(), Path::GeneralOnly);
    assert_eq!((&outcome, &trace), (&general.0, &general.1), "the same trace both ways");
    let start = trace.first(is::start_of("Ping"));
    let call = trace.first(is::call(Function::StartStreaming));
    assert!((start.t - 18.0).abs() < 0.11, "{start:?}");
    assert_eq!(call.t, 25.0, "held until the resume");
    assert_eq!(outcome.status, Status::Ok);
}

#[test]
fn aborting_the_mission_sends_the_fleet_home() {
    let (outcome, trace, _) = run_with_controls(
        "MISSION M:\n    PARALLEL:\n        a FlyTo WITH Far\n        b FlyTo WITH Field\n",
        vec![(12.0, Control::Abort { reason: "aborted by the operator".into() }.into())],
    );
    assert_eq!(outcome.status, Status::Aborted);
    assert_eq!(outcome.reason.as_deref(), Some("aborted by the operator"));
    let said = trace.iter().position(|e| matches!(e.event, Event::Operator { .. })).unwrap();
    assert_eq!(operator_events(&trace)[0], (12.0, OperatorAction::Abort, None));
    assert!(
        trace[said + 1..].iter().all(|e| !matches!(e.event, Event::CapabilityStart { .. })),
        "written before what it does"
    );
    let home: Vec<&str> = trace
        .find(is::done(Function::ReturnToLaunch))
        .iter()
        .map(|e| actor(&e.event).unwrap())
        .collect();
    assert!(home.contains(&"a") && home.contains(&"b"), "both drones were sent home: {home:?}");
    let last = trace.last().unwrap();
    assert!(matches!(last.event, Event::MissionEnd { status: Status::Aborted, .. }), "{last:?}");
    let aborted = trace.find(is::end_of("FlyTo")).len();
    assert_eq!(
        aborted, 0,
        "the activities were cut off with the mission: no end is invented for them"
    );
}

#[test]
fn a_lost_backend_ends_the_mission_at_once_without_commanding_anyone() {
    let (outcome, trace, _) = run_with_controls(
        "MISSION M:\n    a FlyTo WITH Far\n",
        vec![(
            10.0,
            Control::BackendLost { reason: "the simulator stopped: its task panicked".into() }
                .into(),
        )],
    );
    assert_eq!(outcome.status, Status::Failed);
    let last = trace.last().unwrap();
    let Event::MissionEnd { reason, .. } = &last.event else { panic!("{last:?}") };
    assert_eq!(reason.as_deref(), Some("the simulator stopped: its task panicked"));
    assert_eq!(last.t, 10.0, "at once");
    assert!(trace.find(is::call(Function::ReturnToLaunch)).is_empty(), "nobody can be commanded");
}
