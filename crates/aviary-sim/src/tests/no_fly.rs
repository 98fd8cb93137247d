//! No-fly zones: transits go around them, work that would enter one is refused, and no
//! sample of a flight lies inside one.

use aviary_api::{CallEnd, Value};

use super::*;
use crate::geom::contains;

/// A square zone in the way east of the origin, and one up to 40 m north of it.
fn zoned() -> World {
    world(
        r#"
[no_fly.Fire]
polygon = [[100, -50], [200, -50], [200, 50], [100, 50]]

[no_fly.Corridor]
polygon = [[-300, 200], [300, 200], [300, 260], [-300, 260]]
up_to = 40

[drones.d]
home = [0, 0]
"#,
    )
}

/// Every sample's ground point outside the zones that hold at its height.
fn outside_zones(w: &World, run: &Run) {
    for t in &run.samples {
        let p = [t.position[0], t.position[1]];
        for z in &w.no_fly {
            assert!(
                !(z.holds_at(t.position[2]) && contains(&z.polygon, p)),
                "{p:?} at {} m is inside {}",
                t.position[2],
                z.name
            );
        }
    }
}

#[test]
fn a_flight_across_a_zone_goes_around_it_and_ends_where_asked() {
    let w = zoned();
    let mut fleet = airborne(&w, 20.0);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(300.0, 0.0)]);
    let run = run_until(&mut fleet, 0, id, 200.0);
    assert_eq!(run.end, CallEnd::Done);
    outside_zones(&w, &run);
    let end = fleet.telemetry(DroneId(0)).unwrap().position;
    assert!((end[0] - 300.0).abs() < 1e-9 && end[1].abs() < 1e-9, "{end:?}");
    // Around, not through: it left the line y = 0 by the zone's half-width and the margin.
    let widest = run.samples.iter().map(|t| t.position[1].abs()).fold(0.0, f64::max);
    assert!(widest >= 50.0 + aviary_route::MARGIN * 0.99, "{widest}");
    // And longer than the straight flight (30 s and the braking) by the detour's legs.
    assert!(run.took > 30.0 + 10.0 / 3.0, "{}", run.took);
}

#[test]
fn a_zone_below_the_flight_is_flown_over_and_one_at_its_height_is_gone_around() {
    let w = zoned();
    let mut fleet = airborne(&w, 50.0);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(0.0, 400.0)]);
    let run = run_until(&mut fleet, 0, id, 200.0);
    assert_eq!(run.end, CallEnd::Done);
    // Straight over the corridor at 50 m.
    assert!(run.samples.iter().all(|t| t.position[0].abs() < 1e-9));
    let mut fleet = airborne(&w, 30.0);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(0.0, 400.0)]);
    let run = run_until(&mut fleet, 0, id, 400.0);
    assert_eq!(run.end, CallEnd::Done);
    outside_zones(&w, &run);
    assert!(run.samples.iter().any(|t| t.position[0].abs() > 300.0));
}

#[test]
fn work_inside_a_zone_is_refused_before_the_drone_moves() {
    let w = zoned();
    let mut fleet = airborne(&w, 20.0);
    let (exception, reason) = refused(&mut fleet, 0, Function::FlyToPosition, &[pos(150.0, 0.0)]);
    assert_eq!(exception, BuiltinException::GeofenceViolation);
    assert_eq!(reason, "(150.0, 0.0) is inside the no-fly zone `Fire`");
    let (_, reason) = refused(&mut fleet, 0, Function::Orbit, &[pos(150.0, 0.0), num(60.0)]);
    assert_eq!(reason, "a circle of 60.0 m around (150.0, 0.0) enters the no-fly zone `Fire`");
    let field = Value::Area(vec![[150.0, 0.0], [250.0, 0.0], [250.0, 100.0], [150.0, 100.0]]);
    let (_, reason) = refused(&mut fleet, 0, Function::Sweep, &[field, num(20.0)]);
    assert_eq!(reason, "the area swept enters the no-fly zone `Fire`");
    // Climbing over the corridor from below it passes through it.
    let (_, reason) = refused(&mut fleet, 0, Function::FollowPath, &[pos3(0.0, 230.0, 60.0)]);
    assert!(reason.contains("climb above it first"), "{reason}");
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, [0.0, 0.0, 20.0]);
    // An orbit around the whole zone is allowed, and flown outside it.
    let id = start(&mut fleet, 0, Function::Orbit, &[pos(150.0, 0.0), num(120.0)]);
    let run = run_until(&mut fleet, 0, id, 400.0);
    assert_eq!(run.end, CallEnd::Done);
    outside_zones(&w, &run);
}

#[test]
fn coming_down_into_a_zone_is_refused_and_the_way_home_goes_around() {
    let w = zoned();
    let mut fleet = airborne(&w, 50.0);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(0.0, 230.0)]);
    assert_eq!(run_until(&mut fleet, 0, id, 200.0).end, CallEnd::Done);
    let (exception, reason) = refused(&mut fleet, 0, Function::DescendTo, &[num(30.0)]);
    assert_eq!(exception, BuiltinException::GeofenceViolation);
    assert_eq!(
        reason,
        "coming down to 30.0 m at (0.0, 230.0) enters the no-fly zone `Corridor` (up to 40.0 m)"
    );
    let (_, reason) = refused(&mut fleet, 0, Function::Land, &[]);
    assert!(reason.contains("enters the no-fly zone `Corridor`"), "{reason}");
    // Past the fire, then home: the way home goes around it.
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(300.0, 0.0)]);
    assert_eq!(run_until(&mut fleet, 0, id, 300.0).end, CallEnd::Done);
    let id = start(&mut fleet, 0, Function::ReturnToLaunch, &[]);
    let run = run_until(&mut fleet, 0, id, 400.0);
    assert_eq!(run.end, CallEnd::Done);
    outside_zones(&w, &run);
    assert!(run.samples.iter().any(|t| t.position[1].abs() > 50.0));
}

/// A path cut short while its drone flies a detour's corner: the point it was flying to
/// is the path's next point, not the corner, so what it left starts where it stopped and
/// goes on with the path's own points (the corners are the route's, made again by
/// whoever flies the rest).
#[test]
fn a_path_cut_on_a_detour_leaves_its_own_points_not_the_corners() {
    use aviary_api::coverage::{self, Remainder};
    use aviary_api::Interrupt;
    let w = zoned();
    let mut fleet = airborne(&w, 20.0);
    // To (50, 0), then across the fire to (300, 0): its second leg goes around the zone.
    let args = [pos(50.0, 0.0), pos(300.0, 0.0)];
    let id = start(&mut fleet, 0, Function::FollowPath, &args);
    // Into the detour: off the line y = 0, not yet at (300, 0).
    let mut t = 0.0;
    loop {
        run_for(&mut fleet, 0.5);
        t += 0.5;
        let p = fleet.telemetry(DroneId(0)).unwrap().position;
        if p[1].abs() > 20.0 && p[0] > 100.0 {
            break;
        }
        assert!(t < 60.0, "the detour was never flown: {p:?}");
    }
    assert_eq!(fleet.interrupt(id, Interrupt::Abort), Some(CallEnd::Interrupted));
    let stop = fleet.stopped(DroneId(0)).expect("noted at the abort");
    assert_eq!(stop.next, 1, "flying to the path's second point, by a corner of the detour");
    let left = coverage::left(&fc(Function::FollowPath, &args), Some(stop)).unwrap();
    let Remainder::Points(points) = &left else { panic!("{left:?}") };
    let flat: Vec<[f64; 2]> = points.iter().map(|p| [p.x, p.y]).collect();
    let here = fleet.telemetry(DroneId(0)).unwrap().position;
    assert_eq!(flat, [[here[0], here[1]], [300.0, 0.0]]);

    // Flown on, the rest goes around the zone again and ends where the path ends.
    let again =
        start(&mut fleet, 0, Function::FollowPath, &[Value::Remainder(std::sync::Arc::new(left))]);
    let run = run_until(&mut fleet, 0, again, 200.0);
    assert_eq!(run.end, CallEnd::Done);
    outside_zones(&w, &run);
    let end = fleet.telemetry(DroneId(0)).unwrap().position;
    assert!((end[0] - 300.0).abs() < 1e-9 && end[1].abs() < 1e-9, "{end:?}");
}
