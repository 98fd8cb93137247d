//! The plan costs a flight across a no-fly zone along the route the simulator flies: the
//! detour's metres and seconds are in the estimate.

use aviary_api::geometry::dist;
use aviary_test_support::harness;

const ZONE: &str = r#"
[no_fly.Fire_Front]
polygon = [[100, -50], [200, -50], [200, 50], [100, 50]]
"#;

const WORLD: &str = r#"
[site]
geofence = [[-500, -500], [500, -500], [500, 500], [-500, 500]]

[drones.scout]
home = [0, 0]
"#;

const MISSION: &str = "MISSION Across:
    scout TakeOff WITH 20m
    scout FlyTo WITH (300, 0)
    scout ReturnHome
";

fn plan(world: &str) -> aviary_verify::Plan {
    let (_, mut checked) = harness::check(MISSION, world);
    let (_, verified) = aviary_verify::preflight(&mut checked).expect("the mission checks");
    verified.plan
}

#[test]
fn the_plan_flies_the_detour_out_and_back() {
    let zoned = format!("{WORLD}{ZONE}");
    let (straight, around) = (plan(WORLD), plan(&zoned));
    let (world, _) = aviary_world::parse_world(aviary_diagnostics::FileId(0), &zoned);
    let space = aviary_route::Airspace::of(&world.expect("a world"));
    let way = space.route([0.0, 0.0], [300.0, 0.0], 20.0).expect("a way");
    let mut from = [0.0, 0.0];
    let mut detour = -300.0;
    for p in &way {
        detour += dist(from, *p);
        from = *p;
    }
    assert!(way.len() > 1 && detour > 20.0, "{way:?}");
    // Out and home again: the route is the same both ways (a square, symmetric).
    let extra = around.drones[0].distance - straight.drones[0].distance;
    assert!((extra - 2.0 * detour).abs() < 1e-6, "{extra} m more, the detour is {detour} m");
    assert!(around.drones[0].flight_time > straight.drones[0].flight_time + 2.0 * detour / 10.0);

    // And the simulator takes as long as the plan says, within 2%.
    let run = harness::run_in(MISSION, &zoned);
    let landed = run.trace.last().map(|e| e.t).expect("a mission end");
    let planned = around.mission_time;
    assert!((landed - planned).abs() <= 0.02 * planned, "flown in {landed} s, planned {planned} s");
}
