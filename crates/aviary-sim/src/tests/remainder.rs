//! Where a `Sweep` or `FollowPath` stops (`Backend::stopped`), and a remainder flown: the
//! simulator reports the point of the contract's path it was flying to, so that what is
//! left (`aviary_api::coverage::left`) starts where the drone stopped.

use std::sync::Arc;

use aviary_api::coverage::{self, Remainder};
use aviary_api::{sweep, CallEnd, Interrupt, Progress};

use super::*;

const FIELD: [[f64; 2]; 4] = [[100.0, 100.0], [300.0, 100.0], [300.0, 200.0], [100.0, 200.0]];

fn field() -> Vec<Value> {
    vec![Value::Area(FIELD.to_vec()), num(20.0)]
}

#[test]
fn an_aborted_sweep_stops_on_its_lane_and_leaves_the_rest_from_there() {
    let w = one_drone();
    let mut fleet = airborne(&w, 20.0);
    let id = start(&mut fleet, 0, Function::Sweep, &field());
    // To the field (about 140 m), the first lane (200 m) and into the second.
    run_for(&mut fleet, 50.0);
    assert_eq!(fleet.interrupt(id, Interrupt::Abort), Some(CallEnd::Interrupted));
    let here = fleet.telemetry(DroneId(0)).unwrap().position;
    let Some(Progress { next, at }) = fleet.stopped(DroneId(0)) else { panic!("no stop noted") };
    assert_eq!(at, here);
    let lanes = sweep::lanes(&FIELD, 20.0);
    let left = coverage::left(&fc(Function::Sweep, &field()), fleet.stopped(DroneId(0))).unwrap();
    let Remainder::Lanes { lanes: left_lanes, .. } = &left else { panic!("{left:?}") };
    // It was on a lane: what is left of it starts where the drone is.
    assert!(sweep::points(&lanes)[next].1 .1, "on a lane, not a turn");
    let begun = left_lanes[0];
    assert!((begun[0][0] - here[0]).abs() < 1e-9 && (begun[0][1] - here[1]).abs() < 1e-9);
    assert_eq!(left_lanes[1..], lanes[lanes.len() - left_lanes.len() + 1..]);

    // The same drone flies what is left: it starts where it stopped and ends where the
    // whole sweep would have.
    let again =
        start(&mut fleet, 0, Function::Sweep, &[Value::Remainder(Arc::new(left)), num(20.0)]);
    assert_eq!(fleet.stopped(DroneId(0)), None, "a motion call forgets the last stop");
    let run = run_until(&mut fleet, 0, again, 500.0);
    assert_eq!(run.end, CallEnd::Done);
    let end = fleet.telemetry(DroneId(0)).unwrap().position;
    let last = *sweep::lawnmower(&FIELD, 20.0).last().unwrap();
    assert_eq!([end[0], end[1]], last);
    assert!(run.samples.iter().all(|t| (t.position[2] - 20.0).abs() < 1e-9));
}

#[test]
fn a_fault_notes_the_stop_and_a_refused_sweep_none() {
    let w = world(
        "[drones.d]\nhome = [0, 0]\n\n[[faults]]\ndrone = \"d\"\nat = 40.0\nkind = \"link_loss\"\nduration = 100.0\n",
    );
    let mut fleet = airborne(&w, 20.0);
    let id = start(&mut fleet, 0, Function::Sweep, &field());
    let run = run_until(&mut fleet, 0, id, 100.0);
    assert_eq!(run.end, CallEnd::Interrupted);
    let stop = fleet.stopped(DroneId(0)).expect("noted at the fault");
    assert_eq!(stop.at, run.samples.last().unwrap().position);
    assert!(stop.next > 0);

    let mut fleet = airborne(&one_drone(), 20.0);
    let wide = [Value::Area(vec![[0.0, 0.0], [5000.0, 0.0], [5000.0, 10.0]]), num(20.0)];
    assert_eq!(
        refused(&mut fleet, 0, Function::Sweep, &wide).0,
        BuiltinException::GeofenceViolation
    );
    assert_eq!(fleet.stopped(DroneId(0)), None, "refused before it moved");
}

#[test]
fn a_remainder_at_another_spacing_or_of_a_path_is_refused_and_nothing_left_is_done_at_once() {
    let mut fleet = airborne(&one_drone(), 20.0);
    let lanes = Remainder::lanes(sweep::lanes(&FIELD, 20.0), 20.0);
    let (e, why) =
        refused(&mut fleet, 0, Function::Sweep, &[Value::Remainder(Arc::new(lanes)), num(15.0)]);
    assert_eq!(e, BuiltinException::CommandFailed);
    assert!(why.contains("20 m apart"), "{why}");
    let path = Remainder::points(vec![Point::flat(10.0, 10.0)]);
    let (_, why) =
        refused(&mut fleet, 0, Function::Sweep, &[Value::Remainder(Arc::new(path)), num(20.0)]);
    assert!(why.contains("FollowPath"), "{why}");
    let nothing = Value::Remainder(Arc::new(Remainder::Nothing));
    assert_eq!(
        instant(&mut fleet, 0, Function::Sweep, &[nothing.clone(), num(20.0)]),
        CallEnd::Done
    );
    assert_eq!(instant(&mut fleet, 0, Function::FollowPath, &[nothing]), CallEnd::Done);
}

#[test]
fn a_follow_path_stopped_leaves_its_rest_and_flying_it_goes_on_from_there() {
    let mut fleet = airborne(&one_drone(), 20.0);
    let points = [pos(100.0, 0.0), pos3(100.0, 100.0, 30.0), pos(0.0, 100.0)];
    let id = start(&mut fleet, 0, Function::FollowPath, &points);
    run_for(&mut fleet, 20.0);
    fleet.interrupt(id, Interrupt::Abort);
    let here = fleet.telemetry(DroneId(0)).unwrap().position;
    let left =
        coverage::left(&fc(Function::FollowPath, &points), fleet.stopped(DroneId(0))).unwrap();
    let Remainder::Points(rest) = &left else { panic!("{left:?}") };
    assert_eq!([rest[0].x, rest[0].y], [here[0], here[1]]);
    assert_eq!(rest.last().map(|p| (p.x, p.y, p.z)), Some((0.0, 100.0, Some(30.0))));
    let again = start(&mut fleet, 0, Function::FollowPath, &[Value::Remainder(Arc::new(left))]);
    assert_eq!(run_until(&mut fleet, 0, again, 200.0).end, CallEnd::Done);
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, [0.0, 100.0, 30.0]);
}
