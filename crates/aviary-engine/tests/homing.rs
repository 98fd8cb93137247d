//! The way home after the mission's body (and the failsafe's after an unhandled
//! exception): a fault on the way is still an exception, and the drone is sent again,
//! home or straight down, until it is on the ground or lost. `a` flies 400 m out, the
//! mission ends at about 48 s, and `a` is on its way back until about 95 s.

use aviary_api::trace::{CallStatus, Event, Record};
use aviary_api::Function;
use aviary_engine::Status;
use aviary_test_support::harness;
use aviary_test_support::trace::is;

const OUT: &str = "MISSION M:\n    a FlyTo WITH Far\n";

fn with_faults(faults: &[&str]) -> String {
    let mut world = harness::WORLD.to_owned();
    for f in faults {
        world.push_str(&format!("\n[[faults]]\n{f}\n"));
    }
    world
}

/// The calls made to drone `a` after `t`, in order: (function, status, t).
fn calls_after(r: &harness::Run, t: f64) -> Vec<(Function, CallStatus, f64)> {
    r.trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::ApiDone { actor, function, status, .. } if actor == "a" && e.t > t => {
                Some((*function, *status, e.t))
            }
            _ => None,
        })
        .collect()
}

fn last_position(r: &harness::Run) -> [f64; 3] {
    r.trace
        .iter()
        .rev()
        .find_map(|e| match &e.event {
            Event::ApiDone { actor, position, .. } if actor == "a" => Some(*position),
            _ => None,
        })
        .expect("a call")
}

/// An exception's actor, whether a handler took it, and when it came (`during`).
fn taken<'e>(e: &'e Record<'static>) -> (Option<&'e str>, bool, Option<&'e str>) {
    match &e.event {
        Event::Exception { actor, handled, during, .. } => {
            (actor.as_deref(), *handled, during.as_deref())
        }
        other => panic!("not an exception: {other:?}"),
    }
}

use CallStatus::{Interrupted, Ok};
use Function::{Land, ReturnToLaunch};

#[test]
fn a_battery_fault_on_the_way_home_is_recorded_and_the_drone_sent_again() {
    let r = harness::run_in(
        OUT,
        &with_faults(&["drone = \"a\"\nat = 60.0\nkind = \"battery_critical\""]),
    );
    let e = r.first(is::exception("BatteryCritical"));
    assert_eq!(taken(e), (Some("a"), false, Some("return home")));
    // The return it cut short, then a new one that brings the drone home.
    let after = calls_after(&r, 48.0);
    assert_eq!(
        after.iter().map(|c| (c.0, c.1)).collect::<Vec<_>>(),
        [(ReturnToLaunch, Interrupted), (ReturnToLaunch, Ok)],
        "{}",
        r.dump()
    );
    assert!(
        r.index(is::exception("BatteryCritical"))
            < r.index(|e| matches!(e, Event::MissionEnd { .. }))
    );
    let home = last_position(&r);
    assert!(home[0].hypot(home[1]) < 0.5 && home[2] == 0.0, "down at home: {home:?}");
    // It came down: the mission's outcome stands, and says what happened.
    assert_eq!(r.outcome.status, Status::Ok);
    assert!(
        r.outcome.reason.as_deref().is_some_and(|why| why.contains("BatteryCritical on a")),
        "{:?}",
        r.outcome.reason
    );
}

#[test]
fn a_crash_on_the_way_home_fails_the_mission() {
    let r = harness::run_in(OUT, &with_faults(&["drone = \"a\"\nat = 60.0\nkind = \"crash\""]));
    let e = r.first(is::exception("DroneLost"));
    assert_eq!((taken(e).0, taken(e).1), (Some("a"), false));
    assert_eq!(r.outcome.status, Status::Failed, "{}", r.dump());
    assert!(r.outcome.reason.as_deref().unwrap().contains("a was lost"), "{:?}", r.outcome.reason);
    assert_eq!(calls_after(&r, 60.5), [], "a lost drone is not sent again");
}

#[test]
fn a_return_cut_by_a_lost_link_is_sent_again_when_the_link_is_back() {
    // Lost at 60 s for 15 s: nothing is sent while it is lost; at 75 s it is sent home.
    let r = harness::run_in(
        OUT,
        &with_faults(&["drone = \"a\"\nat = 60.0\nkind = \"link_loss\"\nduration = 15.0"]),
    );
    assert_eq!(taken(r.first(is::exception("ConnectionLost"))).2, Some("return home"));
    let after = calls_after(&r, 60.5);
    let (function, status, t) = *after.last().expect("sent again");
    assert_eq!((function, status), (ReturnToLaunch, Ok), "{}", r.dump());
    let sent = r
        .trace
        .iter()
        .filter(|e| matches!(&e.event, Event::ApiCall { actor, .. } if actor == "a") && e.t > 60.5)
        .map(|e| e.t)
        .next()
        .unwrap();
    assert!((75.0..76.1).contains(&sent), "sent again at {sent} s, as the link came back at 75 s");
    assert!(t > sent);
    assert_eq!(r.outcome.status, Status::Ok);
    let home = last_position(&r);
    assert!(home[0].hypot(home[1]) < 0.5, "down at home: {home:?}");
}

#[test]
fn a_drone_that_lost_its_position_on_the_way_home_is_landed_where_it_is() {
    // No position for 10 s: it cannot fly home by it, so once it can move it lands.
    let r = harness::run_in(
        OUT,
        &with_faults(&["drone = \"a\"\nat = 60.0\nkind = \"gps_loss\"\nduration = 10.0"]),
    );
    assert_eq!(taken(r.first(is::exception("PositionLost"))).2, Some("return home"));
    let after = calls_after(&r, 59.9);
    assert_eq!(after.first().map(|c| c.0), Some(ReturnToLaunch), "the return it was flying");
    assert_eq!(after.last().map(|c| (c.0, c.1)), Some((Land, Ok)), "{}", r.dump());
    assert!(
        after.iter().skip(1).all(|c| c.0 == Land),
        "never sent home without a position: {after:?}"
    );
    let down = last_position(&r);
    assert!(down[2] == 0.0 && down[1] > 50.0, "landed on the way, not at home: {down:?}");
}

#[test]
fn a_fault_on_the_failsafes_own_return_is_recorded_too() {
    // b crashes unhandled at 20 s: the mission fails and a is sent home; on its way, a's
    // battery fault is an exception of its own, and it is sent again.
    let r = harness::run_in(
        "MISSION M:\n    PARALLEL:\n        a FlyTo WITH Far\n        b FlyTo WITH North\n",
        &with_faults(&[
            "drone = \"b\"\nat = 20.0\nkind = \"crash\"",
            "drone = \"a\"\nat = 25.0\nkind = \"battery_critical\"",
        ]),
    );
    assert_eq!(r.outcome.status, Status::Failed);
    let e = r.first(is::exception("BatteryCritical"));
    assert_eq!((taken(e).0, taken(e).2), (Some("a"), Some("return home")));
    let after = calls_after(&r, 20.0);
    assert_eq!(
        after.iter().map(|c| (c.0, c.1)).collect::<Vec<_>>(),
        [(ReturnToLaunch, Interrupted), (ReturnToLaunch, Ok)],
        "{}",
        r.dump()
    );
    let reason = r.outcome.reason.as_deref().unwrap();
    assert!(
        reason.starts_with("unhandled exception DroneLost on b")
            && reason.contains("BatteryCritical on a"),
        "{reason}"
    );
}
