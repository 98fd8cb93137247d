//! A line of the world file (`[lines]`) flown by `FollowPath`, from the trace: the drone
//! passes through each of its points in order, at the height a point gives.

use aviary_api::trace::{Event, Shown};
use aviary_api::{Point, Remainder};
use aviary_engine::{RunOptions, Status};
use aviary_test_support::harness;
use aviary_test_support::trace::is;

/// Telemetry at every step of the simulator (0.05 s).
fn run(mission: &str, world: &str) -> harness::Run {
    let options = RunOptions { telemetry_hz: Some(20.0), ..RunOptions::default() };
    harness::run_with(mission, world, &options)
}

fn world() -> String {
    format!("{}\n[lines]\nPipeline = [[0, 50], [150, 50, 40], [150, 250]]\n", harness::WORLD)
}

/// The first time the drone comes within `within` metres (over the ground) of each
/// point, in order; `None` for a point it never reached after the one before.
fn passes(positions: &[(f64, [f64; 3])], points: &[[f64; 2]], within: f64) -> Vec<Option<f64>> {
    let mut from = 0;
    points
        .iter()
        .map(|p| {
            let i = positions[from..]
                .iter()
                .position(|(_, q)| (q[0] - p[0]).hypot(q[1] - p[1]) <= within)?;
            from += i;
            Some(positions[from].0)
        })
        .collect()
}

#[test]
fn a_line_is_flown_through_its_points_in_order() {
    let mission = "MISSION Along:\n    a TakeOff WITH 20m\n    a FollowPath WITH Pipeline\n    a ReturnHome\n";
    let r = run(mission, &world());
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let start = r.first(is::start_of("FollowPath"));
    let Event::CapabilityStart { args, .. } = &start.event else { unreachable!() };
    let path = Remainder::Points(vec![
        Point { x: 0.0, y: 50.0, z: None },
        Point { x: 150.0, y: 50.0, z: Some(40.0) },
        Point { x: 150.0, y: 250.0, z: None },
    ]);
    assert_eq!(args.get("path"), Some(&Shown::Remainder(std::borrow::Cow::Owned(path))));
    let positions = r.positions("a");
    let times = passes(&positions, &[[0.0, 50.0], [150.0, 50.0], [150.0, 250.0]], 1.0);
    assert!(times.iter().all(Option::is_some), "{times:?}");
    // At the second point it is at that point's height, and keeps it to the third.
    let at = |t: f64| positions.iter().find(|(u, _)| *u >= t).map(|(_, p)| p[2]).unwrap();
    assert!((at(times[1].unwrap()) - 40.0).abs() < 1.0, "{positions:?}");
    assert!((at(times[2].unwrap()) - 40.0).abs() < 1.0);
}

/// The speed over the ground between telemetry samples, with the time of each.
fn ground_speeds(positions: &[(f64, [f64; 3])]) -> Vec<(f64, f64)> {
    positions
        .windows(2)
        .filter(|w| w[1].0 > w[0].0)
        .map(|w| {
            let (a, b) = (w[0].1, w[1].1);
            (w[1].0, (b[0] - a[0]).hypot(b[1] - a[1]) / (w[1].0 - w[0].0))
        })
        .collect()
}

/// The fastest the drone went over the ground from `from` to `to` (mission time).
fn fastest(r: &harness::Run, from: f64, to: f64) -> f64 {
    let speeds = ground_speeds(&r.positions("a"));
    speeds.iter().filter(|(t, _)| *t > from && *t <= to).map(|(_, v)| *v).fold(0.0, f64::max)
}

/// From the start of `capability` to its end.
fn span_of(r: &harness::Run, capability: &str) -> (f64, f64) {
    let start = r.t(is::start_of(capability));
    let end = r.t(is::end_of(capability));
    (start, end)
}

#[test]
fn follow_path_and_fly_to_keep_the_speed_asked_for() {
    let mission = "MISSION Slow:\n    a TakeOff WITH 20m\n    a FollowPath WITH Pipeline, speed=3m/s\n    a FlyTo WITH Home, speed=2m/s\n    a Land\n";
    let r = run(mission, &world());
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let (s, e) = span_of(&r, "FollowPath");
    let top = fastest(&r, s, e);
    assert!((top - 3.0).abs() < 0.05, "FollowPath at {top} m/s, asked 3 m/s");
    // Most of the way at that speed: the legs are long, the turns short.
    let speeds = ground_speeds(&r.positions("a"));
    let during: Vec<f64> =
        speeds.iter().filter(|(t, _)| *t > s && *t <= e).map(|(_, v)| *v).collect();
    let cruising = during.iter().filter(|v| (**v - 3.0).abs() < 0.05).count();
    assert!(cruising * 10 > during.len() * 8, "{cruising} of {} samples at 3 m/s", during.len());
    let (s, e) = span_of(&r, "FlyTo");
    let top = fastest(&r, s, e);
    assert!((top - 2.0).abs() < 0.05, "FlyTo at {top} m/s, asked 2 m/s");
    // The trace says what was asked.
    let start = r.first(is::start_of("FlyTo"));
    let Event::CapabilityStart { args, .. } = &start.event else { unreachable!() };
    assert_eq!(args.get("speed"), Some(&Shown::Number(2.0)));
}

#[test]
fn without_a_speed_or_above_max_speed_a_drone_flies_at_its_own() {
    // The harness world's drones fly at 10 m/s (the default max_speed).
    let mission = "MISSION Fast:\n    a TakeOff WITH 20m\n    a FollowPath WITH Pipeline\n    a FlyTo WITH Home, speed=50m/s\n    a Land\n";
    let r = run(mission, &world());
    assert_eq!(r.outcome.status, Status::Ok, "{}", r.dump());
    let (s, e) = span_of(&r, "FollowPath");
    assert!((fastest(&r, s, e) - 10.0).abs() < 0.05);
    let (s, e) = span_of(&r, "FlyTo");
    assert!((fastest(&r, s, e) - 10.0).abs() < 0.05, "clamped to max_speed");
}
