//! Resumable coverage, from the trace: a `Sweep` cut short (a fault of the world, an
//! ABORT leash) leaves what it had not flown as its drone's `remaining`, and another
//! drone that sweeps it flies just that: together the two fly every lane of the field
//! once, lane by lane (`aviary_test_support::lanes`, on telemetry at every step of the
//! simulator). The same for the rest of a `FollowPath`.

use aviary_api::trace::{CallStatus, Event, Shown};
use aviary_api::{sweep, Function, Point, Remainder};
use aviary_engine::{RunOptions, Status};
use aviary_test_support::trace::is;
use aviary_test_support::{harness, lanes};

/// The harness world's `Field`.
const FIELD: [[f64; 2]; 4] = [[100.0, 100.0], [200.0, 100.0], [200.0, 200.0], [100.0, 200.0]];

/// Telemetry at every step of the simulator (0.05 s).
fn run(mission: &str, world: &str) -> harness::Run {
    let options = RunOptions { telemetry_hz: Some(20.0), ..RunOptions::default() };
    harness::run_with(mission, world, &options)
}

fn with_fault(fault: &str) -> String {
    format!("{}\n[[faults]]\ndrone = \"a\"\n{fault}\n", harness::WORLD)
}

fn tracks(r: &harness::Run, drones: &[&str]) -> Vec<(String, Vec<[f64; 3]>)> {
    lanes::tracks(&r.trace, drones)
}

/// An `api_done`: when, how it ended, where its drone was, and the metres it left.
struct Done {
    t: f64,
    status: CallStatus,
    position: [f64; 3],
    left: Option<f64>,
}

/// The `api_done` of `actor`'s `function` calls, in order.
fn done(r: &harness::Run, actor: &str, function: Function) -> Vec<Done> {
    r.trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::ApiDone { actor: a, function: f, status, position, left, .. }
                if a == actor && *f == function =>
            {
                Some(Done { t: e.t, status: *status, position: *position, left: *left })
            }
            _ => None,
        })
        .collect()
}

/// The `api_call` of `actor`'s first `function` call: when, and its values.
fn call<'r>(r: &'r harness::Run, actor: &str, function: Function) -> (f64, &'r [Shown<'static>]) {
    r.trace
        .iter()
        .find_map(|e| match &e.event {
            Event::ApiCall { actor: a, function: f, args, .. } if a == actor && *f == function => {
                Some((e.t, &args[..]))
            }
            _ => None,
        })
        .unwrap_or_else(|| panic!("{actor} makes no {function:?} call"))
}

/// What a value says was left.
fn remainder<'v>(v: &'v Shown) -> &'v Remainder {
    match v {
        Shown::Remainder(left) => left,
        other => panic!("not what a path left: {other:?}"),
    }
}

fn xy(p: [f64; 3]) -> [f64; 2] {
    [p[0], p[1]]
}

const SPRAY: &str =
    "CAPABILITY Spray BY drone WITH field:\n    PERFORM:\n        drone.Sweep(field, 20m)\n";

/// Lane by lane: `a`'s lanes, then the one it was on shared (`a` then `b`), then `b`'s.
fn handed_over(r: &harness::Run) {
    let lanes = sweep::lanes(&FIELD, 20.0);
    let owners = lanes::each_lane_once(&lanes, &tracks(r, &["a", "b"]));
    let a = ["a".to_string()];
    let b = ["b".to_string()];
    let shared = owners
        .iter()
        .position(|o| o.len() == 2)
        .unwrap_or_else(|| panic!("a lane left half flown: {owners:?}"));
    assert!(owners[..shared].iter().all(|o| o == &a), "{owners:?}");
    assert_eq!(owners[shared], ["a", "b"]);
    assert!(owners[shared + 1..].iter().all(|o| o == &b), "{owners:?}");
    assert!(shared > 0 && shared + 1 < lanes.len(), "cut half way: {owners:?}");
}

#[test]
fn a_sweep_cut_by_a_link_loss_is_finished_by_another_drone_every_lane_once() {
    let mission = format!(
        "{SPRAY}\nMISSION Handover:\n    PARALLEL Fields:\n        SEQUENTIAL First:\n            a TakeOff WITH 20m\n            a Spray WITH Field\n            a ReturnHome\n        ON EXCEPTION ConnectionLost BY a:\n            b TakeOff WITH 20m\n            b Spray WITH a.remaining\n            b ReturnHome\n"
    );
    let r = run(&mission, &with_fault("at = 50.0\nkind = \"link_loss\"\nduration = 600.0"));
    assert_eq!(r.outcome.status, Status::Ok, "{:?}", r.outcome.reason);
    let cut = &done(&r, "a", Function::Sweep)[0];
    assert_eq!(cut.status, CallStatus::Interrupted);
    assert_eq!(cut.t, 50.0);
    let whole: f64 = sweep::lawnmower(&FIELD, 20.0)
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .sum();
    let left = cut.left.expect("how much it left");
    assert!(left > 0.0 && left < whole, "{left} of {whole}");
    // The handler starts at the fault, and b's sweep is given just the lanes left, the
    // first from where a stopped.
    let (_, args) = call(&r, "b", Function::Sweep);
    let Remainder::Lanes { lanes, spacing } = remainder(&args[0]) else { panic!("{args:?}") };
    assert_eq!(*spacing, 20.0);
    assert_eq!(lanes[0][0], xy(cut.position), "from where a stopped");
    let b_done = &done(&r, "b", Function::Sweep)[0];
    assert_eq!(b_done.status, CallStatus::Ok);
    assert!(b_done.left.is_none(), "a sweep that finished leaves nothing");
    handed_over(&r);
}

#[test]
fn an_abort_leash_leaves_the_rest_and_the_drone_that_takes_it_over_flies_only_that() {
    let mission = format!(
        "{SPRAY}\nMISSION Handover:\n    SEQUENTIAL Fields:\n        PARALLEL Work:\n            SEQUENTIAL First:\n                a TakeOff WITH 20m\n                a Spray-S1 WITH Field\n                a ReturnHome\n            SEQUENTIAL Control:\n                WAITFOR ELAPSED >= 50s\n                Spray-S1 ABORT\n        b TakeOff WITH 20m\n        b Spray WITH a.remaining\n        b ReturnHome\n"
    );
    let r = run(&mission, harness::WORLD);
    assert_eq!(r.outcome.status, Status::Ok, "{:?}", r.outcome.reason);
    let cut = &done(&r, "a", Function::Sweep)[0];
    assert_eq!((cut.status, cut.t), (CallStatus::Aborted, 50.0));
    assert!(cut.left.unwrap() > 0.0);
    handed_over(&r);
}

#[test]
fn a_handler_in_the_capability_reads_what_is_left_at_once_and_sends_it_on() {
    let mission = "CAPABILITY Spray BY drone WITH field:\n    PERFORM:\n        drone.Sweep(field, 20m)\n    EXCEPTIONS:\n        ON EXCEPTION ConnectionLost:\n            SIGNAL Field_Left WITH drone.remaining\n\nMISSION Handover:\n    PARALLEL Fields:\n        SEQUENTIAL First:\n            a TakeOff WITH 20m\n            a Spray WITH Field\n        ON Field_Left WITH rest:\n            b TakeOff WITH 20m\n            b Spray WITH rest\n            b ReturnHome\n";
    let r = run(mission, &with_fault("at = 50.0\nkind = \"link_loss\"\nduration = 600.0"));
    assert_eq!(r.outcome.status, Status::Ok, "{:?}", r.outcome.reason);
    let signal = r.first(is::signal("Field_Left"));
    assert_eq!(signal.t, 50.0);
    let cut = &done(&r, "a", Function::Sweep)[0];
    let Event::Signal { args, .. } = &signal.event else { unreachable!() };
    let Remainder::Lanes { lanes, .. } = remainder(&args[0]) else { panic!("{args:?}") };
    assert_eq!(lanes[0][0], xy(cut.position));
    handed_over(&r);
}

#[test]
fn the_rest_of_a_follow_path_is_flown_from_where_it_stopped() {
    let mission = "CAPABILITY Round BY drone:\n    PERFORM:\n        drone.FollowPath((100, 0), (100, 100, 30), (0, 100))\n\nCAPABILITY Round_On BY drone WITH from:\n    PERFORM:\n        drone.FollowPath(from.remaining)\n\nMISSION Rounds:\n    PARALLEL Work:\n        SEQUENTIAL First:\n            a TakeOff WITH 20m\n            a Round\n        ON EXCEPTION ConnectionLost BY a:\n            b TakeOff WITH 20m\n            b Round_On WITH a\n            b ReturnHome\n";
    let r = run(mission, &with_fault("at = 28.0\nkind = \"link_loss\"\nduration = 600.0"));
    assert_eq!(r.outcome.status, Status::Ok, "{:?}", r.outcome.reason);
    let cut = &done(&r, "a", Function::FollowPath)[0];
    assert_eq!(cut.status, CallStatus::Interrupted);
    let (_, args) = call(&r, "b", Function::FollowPath);
    let Remainder::Points(points) = remainder(&args[0]) else { panic!("a path left: {args:?}") };
    assert_eq!([points[0].x, points[0].y], xy(cut.position), "from where a stopped");
    assert_eq!(points.last().unwrap(), &Point { x: 0.0, y: 100.0, z: Some(30.0) });
    // b flies through every point left, at the heights the path gave.
    let b = r.positions("b");
    for p in points {
        let p = [p.x, p.y];
        assert!(b.iter().any(|(_, q)| (q[0] - p[0]).hypot(q[1] - p[1]) < 1e-6), "b passed {p:?}");
    }
    let end = &done(&r, "b", Function::FollowPath)[0];
    assert_eq!(end.position, [0.0, 100.0, 30.0]);
}

#[test]
fn what_a_finished_sweep_leaves_is_nothing_and_sweeping_it_ends_at_once() {
    let mission = format!(
        "{SPRAY}\nMISSION Twice:\n    a TakeOff WITH 20m\n    a Spray WITH Field\n    b TakeOff WITH 20m\n    b Spray WITH a.remaining\n"
    );
    let r = run(&mission, harness::WORLD);
    assert_eq!(r.outcome.status, Status::Ok, "{:?}", r.outcome.reason);
    let (t, args) = call(&r, "b", Function::Sweep);
    assert_eq!(remainder(&args[0]), &Remainder::Nothing);
    let b_done = &done(&r, "b", Function::Sweep)[0];
    assert_eq!((b_done.status, b_done.t), (CallStatus::Ok, t));
}

#[test]
fn a_drone_the_operator_sends_home_leaves_the_rest_of_its_sweep() {
    use aviary_engine::DroneAction;
    use harness::Ask;
    let mission = format!(
        "{SPRAY}\nMISSION Handover:\n    PARALLEL Fields:\n        SEQUENTIAL First:\n            a TakeOff WITH 20m\n            a Spray WITH Field\n            a ReturnHome\n        SEQUENTIAL Second:\n            WAITFOR ELAPSED >= 60s\n            b TakeOff WITH 20m\n            b Spray WITH a.remaining\n            b ReturnHome\n"
    );
    let (compiled, world) = harness::compile(&mission, harness::WORLD);
    let options = RunOptions { telemetry_hz: Some(20.0), ..RunOptions::default() };
    let home = Ask::drone("a", DroneAction::ReturnHome);
    let (r, answers) = harness::run_compiled(
        &compiled,
        &world,
        &options,
        vec![(50.0, home)],
        harness::Path::AsUsersRun,
    );
    assert_eq!(answers, vec![Ok(())]);
    assert_eq!(r.outcome.status, Status::Ok, "{:?}", r.outcome.reason);
    let cut = &done(&r, "a", Function::Sweep)[0];
    assert_eq!((cut.status, cut.t), (CallStatus::Aborted, 50.0));
    assert!(cut.left.unwrap() > 0.0);
    handed_over(&r);
}

#[test]
fn in_a_for_the_alias_of_an_exception_handler_names_the_drone_whose_sweep_was_cut() {
    let mission = format!(
        "{SPRAY}\nMISSION Handover:\n    PARALLEL FOR a WITH Field AS d WITH field:\n        SEQUENTIAL Work:\n            d TakeOff WITH 20m\n            d Spray WITH field\n            d ReturnHome\n        ON EXCEPTION ConnectionLost BY d:\n            b TakeOff WITH 20m\n            b Spray WITH d.remaining\n            b ReturnHome\n"
    );
    let r = run(&mission, &with_fault("at = 50.0\nkind = \"link_loss\"\nduration = 600.0"));
    assert_eq!(r.outcome.status, Status::Ok, "{:?}", r.outcome.reason);
    handed_over(&r);
}
