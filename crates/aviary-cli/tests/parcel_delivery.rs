//! The parcel-delivery example as a user runs it (`aviary run
//! examples/parcel_delivery.mission --trace OUT`): two parcels leave the depot, each with
//! whichever courier is free (`ANY ... NEAREST TO Depot`); courier1's motor fails on the
//! way to the farm, and the farm's parcel goes with the nearest courier still free at
//! the depot. From the trace: who delivered what, that no courier ever carried two
//! deliveries at once, and that the one at the north hub, too far from the depot, is
//! never taken.

mod common;

use aviary_api::trace::{CallStatus, Event, Shown, Status};
use aviary_api::{Function, Point};
use aviary_test_support::trace::{actor, is, Trace};
use common::{aviary, repo, scratch};

const MISSION: &str = "examples/parcel_delivery.mission";

#[test]
fn a_failed_couriers_parcel_goes_with_the_nearest_free_courier() {
    let (code, out, err) = aviary(&["check", MISSION], &repo());
    assert_eq!(code, 0, "{out}{err}");
    assert!(!out.contains("warning"), "checks with no warning: {out}");
    let (code, out, err) = aviary(&["fmt", "--check", MISSION], &repo());
    assert_eq!(code, 0, "in canonical layout: {out}{err}");

    let trace = scratch("parcel_delivery").join("parcels.jsonl");
    let (code, out, err) =
        aviary(&["run", MISSION, "--quiet", "--trace", &trace.to_string_lossy()], &repo());
    assert_eq!(code, 0, "runs to its end: {out}{err}");
    let events = Trace::read(&trace);
    assert!(matches!(events.last().unwrap().event, Event::MissionEnd { status: Status::Ok, .. }));

    // Each Deliver: (courier, destination, start, end, status).
    let delivers: Vec<(&str, Option<&Shown>, f64, f64, Status)> = events
        .find(is::start_of("Deliver"))
        .into_iter()
        .map(|s| {
            let Event::CapabilityStart { actor: courier, args, .. } = &s.event else {
                unreachable!()
            };
            let (t, status) = events
                .iter()
                .find_map(|e| match &e.event {
                    Event::CapabilityEnd { capability, actor, status, .. }
                        if capability == "Deliver" && actor == courier && e.t >= s.t =>
                    {
                        Some((e.t, *status))
                    }
                    _ => None,
                })
                .expect("every delivery ends");
            (&**courier, args.get("destination"), s.t, t, status)
        })
        .collect();
    let place = |x: f64, y: f64| Shown::Position(Point { x, y, z: None });
    let (farm, clinic) = (place(600.0, 300.0), place(-500.0, 400.0));
    let (farm, clinic) = (Some(&farm), Some(&clinic));
    // At the start the two nearest to the depot take the parcels, in the order asked.
    assert_eq!((delivers[0].0, &delivers[0].1, delivers[0].2), ("courier1", &farm, 0.0));
    assert_eq!((delivers[1].0, &delivers[1].1, delivers[1].2), ("courier2", &clinic, 0.0));
    // courier1's motor fails at 30 s; at that instant the farm's parcel goes with the
    // nearest courier free at the depot: courier4 (courier2 is busy, courier3 at the hub).
    let failure = events.first(is::exception("MotorFailure"));
    assert_eq!((actor(&failure.event), failure.t), (Some("courier1"), 30.0));
    assert_eq!(delivers.len(), 3, "{delivers:?}");
    assert_eq!((delivers[2].0, &delivers[2].1, delivers[2].2), ("courier4", &farm, 30.0));
    assert_eq!(delivers[2].4, Status::Ok);
    // Both parcels were released at their destination, each by the courier that got there.
    let released: Vec<&str> = events
        .find(|e| {
            matches!(
                e,
                Event::ApiDone { function: Function::ReleasePayload, status: CallStatus::Ok, .. }
            )
        })
        .into_iter()
        .map(|e| actor(&e.event).unwrap())
        .collect();
    assert_eq!(released, ["courier2", "courier4"]);
    // No courier carries two deliveries at once; courier3 is never taken.
    for (i, a) in delivers.iter().enumerate() {
        for b in &delivers[i + 1..] {
            assert!(a.0 != b.0 || b.2 >= a.3, "{} held twice at once: {a:?} {b:?}", a.0);
        }
    }
    assert!(delivers.iter().all(|d| d.0 != "courier3"));
}
