//! A fleet built from a borrowed world and one that takes its world fly alike.

use super::*;

/// Three drones of two makes, a fault, a sensor and a target.
fn three_drones() -> World {
    world(
        r#"
[drones.a]
home = [0, 0]
sensors = ["thermal"]
[drones.b]
home = [30, 0]
max_speed = 5.0
[drones.c]
home = [60, 0]
sensors = ["thermal"]

[sensors.thermal]
detects = ["Body"]
range = 20.0

[[targets]]
kind = "Body"
at = [0, 100]

[[faults]]
drone = "b"
at = 20.0
kind = "crash"
"#,
    )
}

/// Takes off and flies every drone north, then steps 60 s: every report and telemetry.
fn fly(mut fleet: Fleet) -> Vec<String> {
    let mut seen = Vec::new();
    for d in 0..fleet.len() {
        seen.push(format!("{:?}", fleet.call(DroneId(d), &fc(Function::Arm, &[]))));
        seen.push(format!("{:?}", fleet.call(DroneId(d), &fc(Function::TakeOff, &[num(10.0)]))));
    }
    for step in 0..1200 {
        if step == 200 {
            for d in 0..fleet.len() {
                seen.push(format!(
                    "{:?}",
                    fleet.call(DroneId(d), &fc(Function::StartDetection, &[sym("Body")]))
                ));
                seen.push(format!(
                    "{:?}",
                    fleet.call(
                        DroneId(d),
                        &fc(Function::FlyToPosition, &[pos(d as f64 * 30.0, 150.0)])
                    )
                ));
            }
        }
        seen.extend(fleet.step(DT).iter().map(|r| format!("{r:?}")));
        seen.extend((0..fleet.len()).map(|d| format!("{:?}", fleet.telemetry(DroneId(d)))));
    }
    seen
}

#[test]
fn a_fleet_that_takes_its_world_flies_as_one_built_from_it() {
    let world = three_drones();
    let built = fly(Fleet::new(&world));
    let taken = fly(Fleet::from_world(world));
    assert!(built.iter().any(|r| r.contains("DroneLost")), "the fault fires");
    assert!(built.iter().any(|r| r.contains("Detected")), "the target is found");
    assert_eq!(built, taken);
}

#[test]
fn a_fleet_that_takes_its_world_keeps_the_drones_where_the_world_had_them() {
    // Vec's in-place collect: no second buffer of drones while the world's is alive.
    // Fails if a `SimDrone` grows larger than a world's `Drone`.
    let world = three_drones();
    let buffer = world.drones.as_ptr() as usize;
    let fleet = Fleet::from_world(world);
    assert_eq!(fleet.drones.as_ptr() as usize, buffer);
    assert_eq!(fleet.len(), 3);
}
