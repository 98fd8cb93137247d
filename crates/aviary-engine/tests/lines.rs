//! A line of the world file (`[lines]`) flown by `FollowPath`, from the trace: the drone
//! passes through each of its points in order, at the height a point gives.

use aviary_engine::{RunOptions, Status};
use aviary_test_support::harness;

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
    let start = r.first("capability_start", "capability", "FollowPath");
    assert_eq!(
        start["args"]["path"],
        serde_json::json!({"points": [[0.0, 50.0], [150.0, 50.0, 40.0], [150.0, 250.0]]})
    );
    let positions = r.positions("a");
    let times = passes(&positions, &[[0.0, 50.0], [150.0, 50.0], [150.0, 250.0]], 1.0);
    assert!(times.iter().all(Option::is_some), "{times:?}");
    // At the second point it is at that point's height, and keeps it to the third.
    let at = |t: f64| positions.iter().find(|(u, _)| *u >= t).map(|(_, p)| p[2]).unwrap();
    assert!((at(times[1].unwrap()) - 40.0).abs() < 1.0, "{positions:?}");
    assert!((at(times[2].unwrap()) - 40.0).abs() < 1.0);
}
