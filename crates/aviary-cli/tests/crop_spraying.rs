//! The crop-spraying example as a user runs it (`aviary run
//! examples/crop_spraying.mission --trace OUT --telemetry-hz 20`): sprayer2 loses its link
//! half way through East_Field, and sprayer3 later sprays just what it left. From the
//! trace, lane by lane (`aviary_test_support::lanes`, on the telemetry of every
//! sprayer): every lane of East_Field is sprayed once, none twice and none missed; the
//! lanes before the loss by sprayer2, the one it was on by sprayer2 up to where it
//! stopped and by sprayer3 from there, the rest by sprayer3.

mod common;

use aviary_api::trace::{CallStatus, Event, EventKind, Record, Shown, Status};
use aviary_api::{sweep, Function, Remainder};
use aviary_test_support::lanes;
use aviary_test_support::trace::Trace;
use common::{aviary, repo, scratch};

const MISSION: &str = "examples/crop_spraying.mission";

/// `actor`'s `Sweep` calls: when each was made, and its first value.
fn sweeps<'a>(events: &'a [Record<'static>], actor: &str) -> Vec<(f64, &'a Shown<'static>)> {
    events
        .iter()
        .filter_map(|e| match &e.event {
            Event::ApiCall { actor: a, function: Function::Sweep, args, .. } if a == actor => {
                Some((e.t, &args[0]))
            }
            _ => None,
        })
        .collect()
}

/// How `actor`'s `Sweep` calls ended: when, how, where, and the metres they left.
fn swept(events: &[Record<'static>], actor: &str) -> Vec<(f64, CallStatus, [f64; 3], Option<f64>)> {
    events
        .iter()
        .filter_map(|e| match &e.event {
            Event::ApiDone {
                actor: a, function: Function::Sweep, status, position, left, ..
            } if a == actor => Some((e.t, *status, *position, *left)),
            _ => None,
        })
        .collect()
}

/// The corners of an area given as a value.
fn corners(v: &Shown) -> Vec<[f64; 2]> {
    match v {
        Shown::Area(corners) => corners.to_vec(),
        other => panic!("not an area: {other:?}"),
    }
}

#[test]
fn the_lost_sprayers_field_is_sprayed_once_lane_by_lane() {
    let (code, out, _) = aviary(&["check", MISSION], &repo());
    assert_eq!((code, out.trim()), (0, "examples/crop_spraying.mission: ok"), "checks clean");
    let (code, out, err) = aviary(&["fmt", "--check", MISSION], &repo());
    assert_eq!(code, 0, "in canonical layout: {out}{err}");

    let trace = scratch("crop_spraying").join("crop.jsonl");
    let (code, out, err) = aviary(
        &["run", MISSION, "--quiet", "--telemetry-hz", "20", "--trace", &trace.to_string_lossy()],
        &repo(),
    );
    assert_eq!(code, 0, "runs to its end: {out}{err}");
    let events = Trace::read(&trace);
    assert!(matches!(events.last().unwrap().event, Event::MissionEnd { status: Status::Ok, .. }));

    // One link loss, handled; sprayer2's sweep cut there, with what it left.
    let lost = events.events(EventKind::Exception);
    assert_eq!(lost.len(), 1);
    let Event::Exception { name, actor, handled, .. } = &lost[0].event else { unreachable!() };
    assert_eq!((&**name, actor.as_deref()), ("ConnectionLost", Some("sprayer2")));
    assert!(*handled);
    let cut = swept(&events, "sprayer2")[0];
    assert_eq!(cut.1, CallStatus::Interrupted);
    assert!(cut.3.unwrap() > 0.0);
    let field = corners(sweeps(&events, "sprayer2")[0].1);

    // sprayer3: its own field, then nothing from sprayer1 (it finished: done at once), then
    // sprayer2's lanes left, the first from where sprayer2 stopped.
    let calls = sweeps(&events, "sprayer3");
    assert_eq!(calls.len(), 3, "its field, sprayer1's remainder, sprayer2's");
    assert_eq!(calls[1].1, &Shown::Remainder(std::borrow::Cow::Owned(Remainder::Nothing)));
    let done = swept(&events, "sprayer3");
    assert_eq!((done[1].1, done[1].0), (CallStatus::Ok, calls[1].0));
    let Shown::Remainder(handed) = calls[2].1 else { panic!("{:?}", calls[2]) };
    let Remainder::Lanes { lanes, .. } = &**handed else { panic!("{handed:?}") };
    assert_eq!(lanes[0][0], [cut.2[0], cut.2[1]]);
    assert_eq!(done[2].1, CallStatus::Ok);

    // Lane by lane, from every sprayer's track.
    let tracks = lanes::tracks(&events, &["sprayer1", "sprayer2", "sprayer3"]);
    let east = sweep::lanes(&field, 10.0);
    let owners = lanes::each_lane_once(&east, &tracks);
    let shared = owners.iter().position(|o| o.len() == 2).expect("the lane it was on");
    assert!(shared > 0, "{owners:?}");
    assert!(owners[..shared].iter().all(|o| o == &["sprayer2"]), "{owners:?}");
    assert_eq!(owners[shared], ["sprayer2", "sprayer3"]);
    assert!(owners[shared + 1..].iter().all(|o| o == &["sprayer3"]), "{owners:?}");
    // And the other fields, each by its own sprayer.
    for (d, area) in [("sprayer1", "North_Field"), ("sprayer3", "South_Field")] {
        let polygon = corners(sweeps(&events, d)[0].1);
        let owners = lanes::each_lane_once(&sweep::lanes(&polygon, 10.0), &tracks);
        assert!(owners.iter().all(|o| o == &[d]), "{area}: {owners:?}");
    }
}
